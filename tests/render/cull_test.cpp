#include "render/cull.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "core/buffer.h"
#include "core/error.h"
#include "core/exec.h"
#include "core/reduce.h"
#include "tests/render/scene_fixture.h"

namespace throng::render {
namespace {

using testing::TPoseCrowd;

// Characters scattered around and behind a camera at the origin.
TPoseCrowd scattered(int n, std::uint32_t seed) {
  TPoseCrowd c;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> x(-80.0f, 80.0f), yaw(-3.14f, 3.14f);
  std::uniform_int_distribution<int> level(0, 2);
  for (int i = 0; i < n; ++i) c.add({x(rng), 0.0f, x(rng)}, yaw(rng), static_cast<std::uint8_t>(level(rng)));
  return c;
}

Camera test_camera() {
  Camera cam;
  cam.width = 640;
  cam.height = 360;
  cam.position = {0.0f, 1.7f, 0.0f};
  cam.target = {10.0f, 1.0f, -20.0f};
  cam.far_plane = 60.0f;
  return cam;
}

struct Culled {
  std::vector<std::uint32_t> flags, slots;
  Index visible = 0;
};

Culled cull(const TPoseCrowd& c, const JointRig& rig, const Camera& cam, float fine_px = 40.0f, float lines_px = 4.0f) {
  const Index n = c.count();
  Buffer<std::uint32_t> flags(kDrawTiers * n), slots(kDrawTiers * n);
  CullJob job;
  job.camera = make_camera_view(cam);
  job.joint_count = rig.joint_count;
  job.bounding_radius = rig.bounding_radius;
  job.fine_min_pixels = fine_px;
  job.lines_max_pixels = lines_px;
  job.joint_positions = c.positions;
  job.tier_flags = flags.span();
  job.run();
  Culled out;
  out.visible = exclusive_scan<std::uint32_t>("test.slots", flags.span(), slots.span());
  out.flags = flags.to_vector();
  out.slots = slots.to_vector();
  return out;
}

TEST(Cull, KeepsEveryCharacterWithAPointInViewAndDropsThoseFarOutside) {
  const TPoseCrowd c = scattered(600, 7);
  const JointRig rig = make_joint_rig(c.skeleton);
  const Camera cam = test_camera();
  const Culled r = cull(c, rig, cam);
  const Index n = c.count();
  const CameraView view = make_camera_view(cam);
  // Reference: clip-space planes of projection * view (Gribb & Hartmann),
  // normalised, against the bounding sphere about the root.
  const glm::mat4 m = projection_matrix(cam) * view_matrix(cam);
  std::vector<glm::vec4> planes;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f}) {
      glm::vec4 p;
      for (int k = 0; k < 4; ++k) p[k] = m[k][3] + sign * m[k][axis];
      planes.push_back(p / glm::length(glm::vec3(p)));
    }
  int seen = 0, dropped = 0;
  for (Index i = 0; i < n; ++i) {
    int tiers = 0;
    for (int t = 0; t < kDrawTiers; ++t) tiers += static_cast<int>(r.flags[static_cast<std::size_t>(t * n + i)]);
    ASSERT_LE(tiers, 1);
    bool any_point_in_view = false;
    for (int j = 0; j < rig.joint_count; ++j) {
      const glm::vec3 px = world_to_pixel(view, c.positions[static_cast<std::size_t>(i * rig.joint_count + j)]);
      any_point_in_view |= px.z > cam.near_plane && px.z < cam.far_plane && px.x >= 0 && px.x < 640 && px.y >= 0 && px.y < 360;
    }
    const glm::vec3 root = c.positions[static_cast<std::size_t>(i * rig.joint_count)];
    bool far_outside = false;
    for (const glm::vec4& p : planes) far_outside |= glm::dot(glm::vec3(p), root) + p.w < -rig.bounding_radius;
    if (any_point_in_view) {
      EXPECT_EQ(tiers, 1) << "character " << i << " is in view but culled";
      ++seen;
    }
    if (far_outside) {
      EXPECT_EQ(tiers, 0) << "character " << i << " is outside the frustum but drawn";
      ++dropped;
    }
  }
  EXPECT_GT(seen, 20);
  EXPECT_GT(dropped, 300);
}

TEST(Cull, TiersFollowImageSize) {
  Camera cam = test_camera();
  cam.width = 160;
  cam.height = 90;
  cam.far_plane = 500.0f;
  const float focal = focal_length_pixels(cam);
  TPoseCrowd c;
  const JointRig rig = make_joint_rig(c.skeleton);
  const glm::vec3 forward = glm::normalize(cam.target - cam.position);
  // Roots on the view axis at distances giving image radii of 20, 5 and 1 px.
  for (float px : {20.0f, 5.0f, 1.0f}) {
    const glm::vec3 root = cam.position + (focal * rig.bounding_radius / px) * forward;
    const glm::vec3 rest_root = c.skeleton.offsets[0];
    c.add(root - rest_root);
  }
  const Culled r = cull(c, rig, cam, 10.0f, 2.0f);
  const Index n = 3;
  const auto tier = [&](Index i) {
    for (int t = 0; t < kDrawTiers; ++t)
      if (r.flags[static_cast<std::size_t>(t * n + i)] != 0u) return t;
    return -1;
  };
  EXPECT_EQ(tier(0), static_cast<int>(DrawTier::Fine));
  EXPECT_EQ(tier(1), static_cast<int>(DrawTier::Coarse));
  EXPECT_EQ(tier(2), static_cast<int>(DrawTier::Lines));
  EXPECT_EQ(r.visible, 3);
  EXPECT_EQ(r.slots[0], 0u);          // fine slots first,
  EXPECT_EQ(r.slots[n + 1], 1u);      // then coarse,
  EXPECT_EQ(r.slots[2 * n + 2], 2u);  // then lines
}

TEST(Pack, MatchesABruteForceAndIsThreadIndependent) {
  const TPoseCrowd c = scattered(500, 3);
  const JointRig rig = make_joint_rig(c.skeleton);
  const Index n = c.count();
  const Index P = rig.point_count();
  std::vector<std::vector<glm::vec4>> results;
  for (int threads : {1, 2, 3}) {
    ScopedExecution exec(Backend::Cpu, threads);
    const Culled r = cull(c, rig, test_camera());
    std::vector<glm::vec4> out(static_cast<std::size_t>(r.visible * P));
    PackJob job;
    job.joint_count = rig.joint_count;
    job.points = rig.points;
    job.joint_positions = c.positions;
    job.joint_rotations = c.rotations;
    job.lod_levels = c.levels;
    job.tier_flags = r.flags;
    job.slots = r.slots;
    job.out_points = out;
    job.run();
    // Brute force: walk tiers then characters in order.
    Index slot = 0;
    for (int t = 0; t < kDrawTiers; ++t)
      for (Index i = 0; i < n; ++i) {
        if (r.flags[static_cast<std::size_t>(t * n + i)] == 0u) continue;
        for (Index k = 0; k < P; ++k) {
          const RigPoint& p = rig.points[static_cast<std::size_t>(k)];
          const std::size_t joint = static_cast<std::size_t>(i * rig.joint_count + p.joint);
          const glm::vec3 want = c.positions[joint] + c.rotations[joint] * p.offset;
          const glm::vec4 got = out[static_cast<std::size_t>(slot * P + k)];
          ASSERT_LT(glm::length(glm::vec3(got) - want), 1e-5f);
          const int tag = static_cast<int>(got.w);
          ASSERT_EQ(tag & 15, c.levels[static_cast<std::size_t>(i)]);
          ASSERT_EQ(tag >> 4, i);
        }
        ++slot;
      }
    EXPECT_EQ(slot, r.visible);
    results.push_back(out);
  }
  EXPECT_EQ(std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(glm::vec4)), 0);
  EXPECT_EQ(std::memcmp(results[0].data(), results[2].data(), results[0].size() * sizeof(glm::vec4)), 0);
}

TEST(Pack, PerPartLevelsColourEachPoint) {
  TPoseCrowd c;
  c.add({0.0f, 0.0f, -10.0f});
  std::vector<std::uint8_t> levels = {1, 2, 3, 4, 5};  // left arm, right arm, torso, left leg, right leg
  const JointRig rig = make_joint_rig(c.skeleton);
  const Culled r = cull(c, rig, test_camera());
  ASSERT_EQ(r.visible, 1);
  std::vector<glm::vec4> out(static_cast<std::size_t>(rig.point_count()));
  PackJob job;
  job.joint_count = rig.joint_count;
  job.points = rig.points;
  job.joint_positions = c.positions;
  job.joint_rotations = c.rotations;
  job.lod_levels = levels;
  job.tier_flags = r.flags;
  job.slots = r.slots;
  job.out_points = out;
  job.run();
  for (std::int32_t k = 0; k < rig.point_count(); ++k)
    EXPECT_EQ(static_cast<int>(out[static_cast<std::size_t>(k)].w) & 15, 1 + rig.points[static_cast<std::size_t>(k)].part);
  job.lod_levels = Span<const std::uint8_t>(levels.data(), 3);
  EXPECT_THROW(job.run(), Error);
}

TEST(Cull, BadSpansNameTheField) {
  const TPoseCrowd c = scattered(4, 1);
  Buffer<std::uint32_t> flags(kDrawTiers * 5);
  CullJob job;
  job.joint_count = c.skeleton.joint_count();
  job.joint_positions = c.positions;
  job.tier_flags = flags.span();
  try {
    job.run();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "cull.joint_positions");
  }
}

}  // namespace
}  // namespace throng::render
