#include "render/scene.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/error.h"
#include "motion/default_set.h"
#include "motion/fk.h"

namespace throng::render {
namespace {

TEST(JointRig, OneBonePerJointAndEndSite) {
  const motion::Skeleton s = motion::default_skeleton();
  const JointRig rig = make_joint_rig(s);
  rig.validate();
  const std::int32_t J = s.joint_count();
  std::int32_t end_sites = 0;
  for (std::int32_t j = 0; j < J; ++j) end_sites += s.has_end_site[static_cast<std::size_t>(j)] != 0 ? 1 : 0;
  EXPECT_EQ(rig.point_count(), J + end_sites);
  EXPECT_EQ(rig.bone_count(), J + end_sites);  // J - 1 bones to parents, the root sphere, the end sites
  for (std::int32_t j = 0; j < J; ++j) EXPECT_EQ(rig.points[static_cast<std::size_t>(j)].joint, j);
  // Every joint is the end of exactly one bone (its bone from the parent, or the root sphere).
  for (std::int32_t j = 0; j < J; ++j)
    EXPECT_EQ(std::count_if(rig.bones.begin(), rig.bones.end(), [&](const RigBone& b) { return b.to == j; }), 1) << j;
  // Limbs are thinner than the trunk; the arms are coloured as arms.
  const auto bone_to = [&](std::int32_t j) { return *std::find_if(rig.bones.begin(), rig.bones.end(), [&](const RigBone& b) { return b.to == j; }); };
  EXPECT_LT(bone_to(motion::default_joint::LeftForeArm).radius, bone_to(motion::default_joint::Spine1).radius);
  EXPECT_EQ(rig.points[motion::default_joint::LeftForeArm].part, static_cast<std::uint8_t>(anim::BodyPart::LeftArm));
  EXPECT_EQ(rig.points[motion::default_joint::RightLeg].part, static_cast<std::uint8_t>(anim::BodyPart::RightLeg));
}

TEST(JointRig, BoundingRadiusHoldsEveryPoseOfTheMotionSet) {
  const motion::Skeleton s = motion::default_skeleton();
  const JointRig rig = make_joint_rig(s);
  float widest = 0.0f;
  for (const motion::DefaultMotion& m : motion::make_default_motions(s)) {
    const motion::ModelSpaceClip ms = motion::forward_kinematics(s, m.clip);
    for (std::int32_t f = 0; f < ms.frame_count; f += 3) {
      const glm::vec3 root = ms.position(f, 0);
      for (const RigPoint& p : rig.points) {
        const std::size_t k = static_cast<std::size_t>(f) * static_cast<std::size_t>(ms.joint_count) + static_cast<std::size_t>(p.joint);
        const glm::vec3 at = ms.positions[k] + ms.rotations[k] * p.offset;
        widest = std::max(widest, glm::length(at - root));
      }
    }
  }
  EXPECT_GT(widest, 0.5f);
  EXPECT_LE(widest, rig.bounding_radius);
  EXPECT_LT(rig.bounding_radius, 3.0f);  // and not absurdly loose
}

TEST(JointRig, BadRigsNameTheField) {
  JointRig rig = make_joint_rig(motion::default_skeleton());
  rig.bones[3].to = 999;
  try {
    rig.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "rig.bones[3].to");
  }
  rig = make_joint_rig(motion::default_skeleton());
  rig.bones[0].radius = 0.0f;
  EXPECT_THROW(rig.validate(), Error);
}

TEST(CharacterPoses, SizesAreChecked) {
  const JointRig rig = make_joint_rig(motion::default_skeleton());
  const std::int32_t J = rig.joint_count;
  std::vector<glm::vec3> p(static_cast<std::size_t>(3 * J));
  std::vector<glm::quat> q(static_cast<std::size_t>(3 * J));
  std::vector<std::uint8_t> levels(15);
  CharacterPoses poses;
  poses.joint_count = J;
  poses.joint_positions = p;
  poses.joint_rotations = q;
  poses.lod_levels = levels;
  EXPECT_EQ(poses.character_count(), 3);
  poses.validate(rig);
  poses.lod_levels = Span<const std::uint8_t>(levels.data(), 3);
  poses.validate(rig);
  poses.lod_levels = Span<const std::uint8_t>(levels.data(), 4);
  EXPECT_THROW(poses.validate(rig), Error);
  poses.lod_levels = {};
  poses.joint_positions = Span<const glm::vec3>(p.data(), 3 * J - 1);
  try {
    poses.validate(rig);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "poses.joint_positions");
  }
  EXPECT_EQ(parse_render_mode("joints", "f"), RenderMode::Joints);
  EXPECT_THROW(parse_render_mode("wireframe", "f"), Error);
}

}  // namespace
}  // namespace throng::render
