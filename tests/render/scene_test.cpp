#include "render/scene.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "anim/rig.h"
#include "anim/skin.h"
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
  const auto bone_to = [&](std::int32_t j) {
    return *std::find_if(rig.bones.begin(), rig.bones.end(), [&](const RigBone& b) { return b.to == j; });
  };
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
        const std::size_t k =
            static_cast<std::size_t>(f) * static_cast<std::size_t>(ms.joint_count) + static_cast<std::size_t>(p.joint);
        const glm::vec3 at = ms.positions[k] + ms.rotations[k] * p.offset;
        widest = std::max(widest, glm::length(at - root));
      }
    }
  }
  EXPECT_GT(widest, 0.5f);
  EXPECT_LE(widest, rig.bounding_radius);
  EXPECT_LT(rig.bounding_radius, 3.0f);  // and not absurdly loose
}

TEST(SkinRig, TiersOfTheMannequinShareItsJoints) {
  const motion::Skeleton s = motion::default_skeleton();
  const anim::Rig rig = anim::make_rig("humanoid", s);
  const SkinRig skin = make_skin_rig(rig);
  skin.validate();
  EXPECT_EQ(skin.joint_count, s.joint_count());
  EXPECT_EQ(skin.meshes[0].vertex_count(), rig.mesh.vertex_count());  // the rig's own mesh, fine
  EXPECT_LT(skin.meshes[1].triangle_count(), skin.meshes[0].triangle_count() / 3);
  // Far: a line per bone and end site, both ends on the same joint.
  const anim::SkinnedMesh& lines = skin.meshes[2];
  std::int32_t end_sites = 0;
  for (std::int32_t j = 0; j < s.joint_count(); ++j)
    end_sites += s.has_end_site[static_cast<std::size_t>(j)] != 0 ? 1 : 0;
  EXPECT_EQ(lines.indices.size(), 2u * static_cast<std::size_t>(s.joint_count() - 1 + end_sites));
  for (std::size_t i = 0; i < lines.indices.size(); i += 2)
    EXPECT_EQ(lines.joints[lines.indices[i]].x, lines.joints[lines.indices[i + 1]].x);
  // Styles: hands and head are skin, shins are trousers, the chest a shirt.
  const auto style_of = [&](std::int32_t joint, const std::array<std::vector<std::uint8_t>, kDrawTiers>& table) {
    for (std::int32_t v = 0; v < skin.meshes[0].vertex_count(); ++v)
      if (skin.meshes[0].joints[static_cast<std::size_t>(v)].x == joint &&
          skin.meshes[0].weights[static_cast<std::size_t>(v)].x > 0.99f)
        return static_cast<int>(table[0][static_cast<std::size_t>(v)]);
    return -1;
  };
  EXPECT_EQ(style_of(motion::default_joint::Head, skin.materials), kSkin);
  EXPECT_EQ(style_of(motion::default_joint::LeftLeg, skin.materials), kTrousers);
  EXPECT_EQ(style_of(motion::default_joint::Spine1, skin.materials), kShirt);
  EXPECT_EQ(style_of(motion::default_joint::LeftLeg, skin.parts), static_cast<int>(anim::BodyPart::LeftLeg));
  EXPECT_EQ(style_of(motion::default_joint::RightForeArm, skin.parts), static_cast<int>(anim::BodyPart::RightArm));
}

TEST(SkinRig, BoundingRadiusHoldsEverySkinnedVertexOfTheMotionSet) {
  const motion::Skeleton s = motion::default_skeleton();
  const anim::Rig rig = anim::make_rig("humanoid", s);
  const SkinRig skin = make_skin_rig(rig);
  const anim::PoseKinematics kinematics = rig.kinematics();
  std::vector<anim::Mat3x4> palette(static_cast<std::size_t>(s.joint_count()));
  float widest = 0.0f;
  for (const motion::DefaultMotion& m : motion::make_default_motions(s)) {
    for (std::int32_t f = 0; f < m.clip.frame_count; f += 5) {
      anim::Pose pose(s.joint_count());
      for (std::int32_t j = 0; j < s.joint_count(); ++j)
        pose.local[static_cast<std::size_t>(j)] = m.clip.rotation(f, j);
      pose.root = m.clip.root_positions[static_cast<std::size_t>(f)];
      kinematics.palette(pose, palette.data());
      const glm::vec3 root = anim::transform_point(palette[0], skin.bind_positions[0]);
      for (const anim::SkinnedMesh& mesh : skin.meshes) {
        std::vector<glm::vec3> out(static_cast<std::size_t>(mesh.vertex_count()));
        anim::skin_reference(mesh, palette, out, {});
        for (const glm::vec3& v : out) widest = std::max(widest, glm::length(v - root));
      }
    }
  }
  EXPECT_GT(widest, 0.5f);
  EXPECT_LE(widest, skin.bounding_radius);
  EXPECT_LT(skin.bounding_radius, 3.0f);
}

TEST(SkinRig, BadRigsNameTheField) {
  SkinRig skin = make_skin_rig(anim::make_rig("humanoid", motion::default_skeleton()));
  skin.meshes[2].indices.push_back(0);
  try {
    skin.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "skin.meshes[2].indices");
  }
  skin = make_skin_rig(anim::make_rig("humanoid", motion::default_skeleton()));
  skin.materials[1].pop_back();
  EXPECT_THROW(skin.validate(), Error);
  skin = make_skin_rig(anim::make_rig("humanoid", motion::default_skeleton()));
  skin.meshes[0].joints[5].x = 500;  // the driving joint, weighted
  try {
    skin.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field.rfind("skin.meshes[0]", 0), 0u) << e.location().field;
  }
}

TEST(CharacterPoses, FramesOrPalettesMatchTheRigs) {
  const CrowdRigs rigs = make_crowd_rigs(motion::default_skeleton());
  const std::int32_t J = rigs.joints.joint_count;
  std::vector<glm::vec3> positions(static_cast<std::size_t>(2 * J));
  std::vector<glm::quat> rotations(static_cast<std::size_t>(2 * J));
  std::vector<anim::Mat3x4> palettes(static_cast<std::size_t>(2 * J));
  std::vector<Index> offsets = {0, J};
  std::vector<float> scales = {1.0f};
  const auto field_of = [&](const CharacterPoses& p, RenderMode mode) {
    try {
      p.validate(rigs, mode);
    } catch (const Error& e) {
      return e.location().field;
    }
    return std::string("ok");
  };
  CharacterPoses frames;
  frames.joint_count = J;
  frames.joint_positions = positions;
  frames.joint_rotations = rotations;
  EXPECT_EQ(field_of(frames, RenderMode::Joints), "ok");
  EXPECT_EQ(field_of(frames, RenderMode::Skinned), "ok");
  frames.scales = scales;
  EXPECT_EQ(field_of(frames, RenderMode::Skinned), "poses.scales");
  CharacterPoses streamed;
  streamed.palettes = palettes;
  streamed.palette_offsets = offsets;
  EXPECT_EQ(streamed.character_count(), 2);
  EXPECT_EQ(field_of(streamed, RenderMode::Skinned), "ok");
  EXPECT_EQ(field_of(streamed, RenderMode::Joints), "render.mode");
  std::vector<std::int32_t> one_rig = {0};
  streamed.rigs = one_rig;
  EXPECT_EQ(field_of(streamed, RenderMode::Skinned), "poses.rigs");
  CrowdRigs joints_only{rigs.joints, {}};
  try {
    frames.scales = {};
    frames.validate(joints_only, RenderMode::Skinned);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "render.mode");
  }
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
  const CrowdRigs rigs{make_joint_rig(motion::default_skeleton()), {}};
  const std::int32_t J = rigs.joints.joint_count;
  std::vector<glm::vec3> p(static_cast<std::size_t>(3 * J));
  std::vector<glm::quat> q(static_cast<std::size_t>(3 * J));
  std::vector<std::uint8_t> levels(15);
  CharacterPoses poses;
  poses.joint_count = J;
  poses.joint_positions = p;
  poses.joint_rotations = q;
  poses.lod_levels = levels;
  EXPECT_EQ(poses.character_count(), 3);
  poses.validate(rigs, RenderMode::Joints);
  poses.lod_levels = Span<const std::uint8_t>(levels.data(), 3);
  poses.validate(rigs, RenderMode::Joints);
  poses.lod_levels = Span<const std::uint8_t>(levels.data(), 4);
  EXPECT_THROW(poses.validate(rigs, RenderMode::Joints), Error);
  poses.lod_levels = {};
  poses.joint_positions = Span<const glm::vec3>(p.data(), 3 * J - 1);
  try {
    poses.validate(rigs, RenderMode::Joints);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "poses.joint_positions");
  }
  EXPECT_EQ(parse_render_mode("joints", "f"), RenderMode::Joints);
  EXPECT_THROW(parse_render_mode("wireframe", "f"), Error);
}

}  // namespace
}  // namespace throng::render
