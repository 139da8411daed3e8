#include "render/demo_crowd.h"

#include <gtest/gtest.h>

#include <cstring>

#include "anim/lod.h"
#include "core/error.h"
#include "core/exec.h"
#include "core/ground.h"
#include "motion/default_set.h"

namespace throng::render {
namespace {

TEST(DemoCrowd, RingWalkersCircleAtTheirClipSpeed) {
  DemoCrowdSpec spec;
  spec.characters = 60;
  spec.layout = DemoLayout::Ring;
  DemoCrowd crowd(spec);
  EXPECT_EQ(crowd.character_count(), 60);
  crowd.update(2.0);
  const std::vector<glm::vec3> a(crowd.ground_positions().begin(), crowd.ground_positions().end());
  const std::vector<float> yaw(crowd.yaws().begin(), crowd.yaws().end());
  const double dt = 0.05;
  crowd.update(2.0 + dt);
  const Span<const glm::vec3> b = crowd.ground_positions();
  int moving = 0;
  for (Index i = 0; i < 60; ++i) {
    const glm::vec3 step = b[i] - a[static_cast<std::size_t>(i)];
    EXPECT_EQ(step.y, 0.0f);
    const float speed = glm::length(step) / static_cast<float>(dt);
    EXPECT_LT(speed, 7.5f);  // no faster than the fastest run
    if (speed < 0.1f) continue;  // idle
    ++moving;
    // They walk where they face: yaw = heading + pi/2 (core/ground.h).
    const glm::vec2 dir = glm::normalize(ground_from_world(b[i]) - ground_from_world(a[static_cast<std::size_t>(i)]));
    const float heading = heading_from_yaw(yaw[static_cast<std::size_t>(i)]);
    EXPECT_GT(glm::dot(dir, glm::vec2(std::cos(heading), std::sin(heading))), 0.99f) << i;
    // Counter-clockwise round the origin, seen from above.
    const glm::vec2 from = ground_from_world(a[static_cast<std::size_t>(i)]);
    EXPECT_GT(from.x * dir.y - from.y * dir.x, 0.0f);
  }
  EXPECT_GT(moving, 40);
}

TEST(DemoCrowd, PosesStandOnTheGroundAroundTheirPlace) {
  DemoCrowdSpec spec;
  spec.characters = 30;
  spec.layout = DemoLayout::Grid;
  DemoCrowd crowd(spec);
  crowd.update(1.3);
  const CharacterPoses poses = crowd.poses();
  const std::int32_t J = crowd.joint_count();
  ASSERT_EQ(poses.character_count(), 30);
  const motion::Skeleton& s = crowd.skeleton();
  for (Index c = 0; c < 30; ++c) {
    float lowest = 1e9f, highest = -1e9f;
    for (std::int32_t j = 0; j < J; ++j) {
      const glm::vec3 p = poses.joint_positions[c * J + j];
      lowest = std::min(lowest, p.y);
      highest = std::max(highest, p.y);
      EXPECT_LT(glm::length(ground_from_world(p) - ground_from_world(crowd.ground_positions()[c])), 1.2f);
    }
    EXPECT_GT(lowest, -0.05f) << c;   // ankles above the floor
    EXPECT_LT(lowest, 0.2f) << c;
    EXPECT_GT(highest, 1.4f) << c;    // head up
    // World rotations carry the bone offsets: child = parent + R(parent) * offset.
    for (std::int32_t j = 1; j < J; ++j) {
      const std::int32_t p = s.parents[static_cast<std::size_t>(j)];
      const glm::vec3 expect = poses.joint_positions[c * J + p] + poses.joint_rotations[c * J + p] * s.offsets[static_cast<std::size_t>(j)];
      EXPECT_LT(glm::length(poses.joint_positions[c * J + j] - expect), 1e-4f);
    }
  }
}

TEST(DemoCrowd, LodMasksHoldJointsAndThreadsAgree) {
  DemoCrowdSpec spec;
  spec.characters = 200;
  std::vector<std::vector<glm::vec3>> runs;
  for (int threads : {1, 2}) {
    ScopedExecution exec(Backend::Cpu, threads);
    DemoCrowd crowd(spec);
    crowd.update(0.7);
    runs.emplace_back(crowd.poses().joint_positions.begin(), crowd.poses().joint_positions.end());
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  EXPECT_EQ(std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * sizeof(glm::vec3)), 0);

  // Only the root synthesised: every other joint holds its parent's frame,
  // so the pose is the rest pose turned with the hips.
  DemoCrowd crowd(spec);
  const std::int32_t J = crowd.joint_count();
  const std::int32_t words = anim::mask_word_count(J);
  std::vector<std::uint32_t> masks(static_cast<std::size_t>(spec.characters * words), 0u);
  for (Index c = 0; c < spec.characters; ++c) masks[static_cast<std::size_t>(c * words)] = 1u;
  crowd.update(0.7, masks);
  const CharacterPoses poses = crowd.poses();
  for (Index c = 0; c < spec.characters; c += 17)
    for (std::int32_t j = 1; j < J; ++j) EXPECT_EQ(poses.joint_rotations[c * J + j], poses.joint_rotations[c * J]);
  EXPECT_THROW(crowd.update(0.7, Span<const std::uint32_t>(masks.data(), 3)), Error);
}

TEST(DemoCrowd, BadSpecsNameTheField) {
  DemoCrowdSpec spec;
  spec.characters = -1;
  try {
    DemoCrowd crowd(spec);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "demo.characters");
  }
  spec.characters = 10;
  spec.spacing = 0.0f;
  EXPECT_THROW(DemoCrowd{spec}, Error);
  EXPECT_THROW(parse_demo_layout("spiral", "--layout"), Error);
  DemoCrowdSpec empty;
  empty.characters = 0;
  DemoCrowd none(empty);
  none.update(1.0);
  EXPECT_EQ(none.poses().character_count(), 0);
}

}  // namespace
}  // namespace throng::render
