#include "render/cull.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "anim/rig.h"
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

struct Culled {
  std::vector<std::uint32_t> flags, slots;
  Index visible = 0;
};

Culled cull(const TPoseCrowd& c, const JointRig& rig, const Camera& cam, float fine_px = 40.0f, float lines_px = 4.0f) {
  const Index n = c.count();
  Buffer<std::uint32_t> flags(kDrawTiers * n), slots(kDrawTiers * n);
  CullJob job;
  job.camera = make_camera_view(cam);
  job.rigs.rig[0] = {rig.bounding_radius, glm::vec3(0.0f), rig.joint_count};
  job.joint_count = rig.joint_count;
  job.fine_min_pixels = fine_px;
  job.lines_max_pixels = lines_px;
  job.joint_positions = c.positions;
  job.group_flags = flags.span();
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
  const Camera cam = testing::street_camera();
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
      any_point_in_view |=
          px.z > cam.near_plane && px.z < cam.far_plane && px.x >= 0 && px.x < 640 && px.y >= 0 && px.y < 360;
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
  Camera cam = testing::street_camera();
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
    const Culled r = cull(c, rig, testing::street_camera());
    std::vector<glm::vec4> out(static_cast<std::size_t>(r.visible * P));
    PackJob job;
    job.joint_count = rig.joint_count;
    job.points = rig.points;
    job.joint_positions = c.positions;
    job.joint_rotations = c.rotations;
    job.lod_levels = c.levels;
    job.group_flags = r.flags;
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
  const Culled r = cull(c, rig, testing::street_camera());
  ASSERT_EQ(r.visible, 1);
  std::vector<glm::vec4> out(static_cast<std::size_t>(rig.point_count()));
  PackJob job;
  job.joint_count = rig.joint_count;
  job.points = rig.points;
  job.joint_positions = c.positions;
  job.joint_rotations = c.rotations;
  job.lod_levels = levels;
  job.group_flags = r.flags;
  job.slots = r.slots;
  job.out_points = out;
  job.run();
  for (std::int32_t k = 0; k < rig.point_count(); ++k)
    EXPECT_EQ(static_cast<int>(out[static_cast<std::size_t>(k)].w) & 15,
              1 + rig.points[static_cast<std::size_t>(k)].part);
  job.lod_levels = Span<const std::uint8_t>(levels.data(), 3);
  EXPECT_THROW(job.run(), Error);
}

// Palettes of a T-posed crowd straight from its placement: T(at) R(yaw) S(scale).
std::vector<anim::Mat3x4> rigid_palettes(const TPoseCrowd& c) {
  std::vector<anim::Mat3x4> out;
  for (std::int32_t i = 0; i < c.count(); ++i) {
    const auto I = static_cast<std::size_t>(i);
    anim::Mat3x4 m = anim::mat3x4_from(glm::angleAxis(c.yaws[I], glm::vec3(0, 1, 0)), c.places[I]);
    for (glm::vec4* r : {&m.r0, &m.r1, &m.r2}) *r = glm::vec4(glm::vec3(*r) * c.scales[I], r->w);
    for (std::int32_t j = 0; j < c.skeleton.joint_count(); ++j) out.push_back(m);
  }
  return out;
}

TEST(PalettePack, JointFramesTimesInverseBindGiveEachCharactersTransformAndThreadsAgree) {
  TPoseCrowd c;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> x(-30.0f, 30.0f), yaw(-3.14f, 3.14f), scale(0.8f, 1.25f);
  for (int i = 0; i < 300; ++i)
    c.add({x(rng), 0.0f, x(rng) - 30.0f}, yaw(rng), static_cast<std::uint8_t>(i % 3), scale(rng));
  const SkinRig skin = make_skin_rig(anim::make_rig("humanoid", c.skeleton));
  const Index n = c.count();
  const std::int32_t J = skin.joint_count;
  const std::vector<anim::Mat3x4> want = rigid_palettes(c);
  std::vector<std::vector<anim::Mat3x4>> results;
  for (int threads : {1, 2, 3}) {
    ScopedExecution exec(Backend::Cpu, threads);
    Buffer<std::uint32_t> flags(kDrawTiers * n), slots(kDrawTiers * n);
    CullJob cull;
    cull.camera = make_camera_view(testing::street_camera());
    cull.rigs.rig[0] = {skin.bounding_radius, skin.bind_positions[0], J};
    cull.joint_count = J;
    cull.joint_positions = c.positions;
    cull.scales = c.scales;
    cull.group_flags = flags.span();
    cull.run();
    const Index visible = exclusive_scan<std::uint32_t>("test.slots", flags.span(), slots.span());
    ASSERT_GT(visible, 20);
    ASSERT_LT(visible, n);
    PalettePackJob pack;
    pack.groups = draw_groups(cull, slots.span(), visible);
    EXPECT_EQ(pack.groups.visible(), visible);
    std::vector<anim::Mat3x4> out(static_cast<std::size_t>(pack.groups.matrices()));
    std::vector<glm::uvec2> tags(static_cast<std::size_t>(visible));
    pack.joint_count = J;
    pack.joint_positions = c.positions;
    pack.joint_rotations = c.rotations;
    pack.scales = c.scales;
    pack.inverse_bind = skin.inverse_bind;
    pack.lod_levels = c.levels;
    pack.group_flags = flags.span();
    pack.slots = slots.span();
    pack.out_palettes = out;
    pack.out_tags = tags;
    pack.run();
    // Slots in group order, characters in order within a group.
    const std::vector<std::uint32_t> f = flags.to_vector();
    Index slot = 0;
    for (int g = 0; g < kDrawTiers; ++g)
      for (Index i = 0; i < n; ++i) {
        if (f[static_cast<std::size_t>(g * n + i)] == 0u) continue;
        EXPECT_EQ(tags[static_cast<std::size_t>(slot)].x, static_cast<std::uint32_t>(i));
        EXPECT_EQ(tags[static_cast<std::size_t>(slot)].y,
                  0x11111u * c.levels[static_cast<std::size_t>(i)]);  // one level, every part
        for (std::int32_t j = 0; j < J; ++j) {
          const anim::Mat3x4& got = out[static_cast<std::size_t>(slot * J + j)];
          const anim::Mat3x4& w = want[static_cast<std::size_t>(i * J + j)];
          for (int r = 0; r < 3; ++r)
            ASSERT_LT(glm::length((&got.r0)[r] - (&w.r0)[r]), 2e-5f * (1.0f + glm::length((&w.r0)[r])))
                << i << " " << j;
        }
        ++slot;
      }
    EXPECT_EQ(slot, visible);
    results.push_back(out);
  }
  EXPECT_EQ(std::memcmp(results[0].data(), results[1].data(), results[0].size() * sizeof(anim::Mat3x4)), 0);
  EXPECT_EQ(std::memcmp(results[0].data(), results[2].data(), results[0].size() * sizeof(anim::Mat3x4)), 0);
}

TEST(Cull, PalettesPlaceCharactersAsTheirJointFramesDoAndPickTheirRigsGroup) {
  TPoseCrowd c;
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> x(-80.0f, 80.0f), yaw(-3.14f, 3.14f), scale(0.5f, 2.0f);
  for (int i = 0; i < 400; ++i) c.add({x(rng), 0.0f, x(rng)}, yaw(rng), 0, scale(rng));
  const SkinRig skin = make_skin_rig(anim::make_rig("humanoid", c.skeleton));
  const Index n = c.count();
  const std::int32_t J = skin.joint_count;
  const std::vector<anim::Mat3x4> palettes = rigid_palettes(c);
  std::vector<Index> offsets;
  for (Index i = 0; i < n; ++i) offsets.push_back(i * J);
  const CullRig rig{skin.bounding_radius, skin.bind_positions[0], J};

  Buffer<std::uint32_t> from_frames(kDrawTiers * n), from_palettes(2 * kDrawTiers * n);
  CullJob frames;
  frames.camera = make_camera_view(testing::street_camera());
  frames.rigs.rig[0] = rig;
  frames.fine_min_pixels = 30.0f;
  frames.lines_max_pixels = 10.0f;
  frames.joint_count = J;
  frames.joint_positions = c.positions;
  frames.scales = c.scales;
  frames.group_flags = from_frames.span();
  frames.run();
  // Every other character of rig 1 (the same bounds), and three that cannot be drawn.
  std::vector<std::int32_t> rigs(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) rigs[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(i % 2);
  CullJob streamed = frames;
  streamed.rigs.count = 2;
  streamed.rigs.rig[1] = rig;
  streamed.joint_count = 0;
  streamed.joint_positions = {};
  streamed.scales = {};
  streamed.palettes = palettes;
  streamed.palette_offsets = offsets;
  streamed.character_rigs = rigs;
  streamed.group_flags = from_palettes.span();
  std::vector<Index> broken;
  for (Index i = 0; i < n && broken.size() < 3; ++i)
    if (from_frames.to_vector()[static_cast<std::size_t>(i)] != 0u) broken.push_back(i);  // visible, fine
  ASSERT_EQ(broken.size(), 3u);
  rigs[static_cast<std::size_t>(broken[0])] = 2;                 // no such rig
  offsets[static_cast<std::size_t>(broken[1])] = n * J - J + 1;  // palette runs past the end
  offsets[static_cast<std::size_t>(broken[2])] = -1;
  streamed.run();
  const std::vector<std::uint32_t> a = from_frames.to_vector(), b = from_palettes.to_vector();
  Index visible = 0, tiers_seen[kDrawTiers] = {0, 0, 0};
  for (Index i = 0; i < n; ++i) {
    const bool is_broken = std::find(broken.begin(), broken.end(), i) != broken.end();
    const Index r = i % 2;
    for (int t = 0; t < kDrawTiers; ++t) {
      const std::uint32_t want = is_broken ? 0u : a[static_cast<std::size_t>(t * n + i)];
      EXPECT_EQ(b[static_cast<std::size_t>((r * kDrawTiers + t) * n + i)], want) << i << " tier " << t;
      EXPECT_EQ(b[static_cast<std::size_t>(((1 - r) * kDrawTiers + t) * n + i)], 0u) << i;
      visible += want;
      tiers_seen[t] += want;
    }
  }
  EXPECT_GT(visible, 20);
  EXPECT_GT(tiers_seen[0], 0);
  EXPECT_GT(tiers_seen[1], 0);
  EXPECT_GT(tiers_seen[2], 0);
}

TEST(Cull, BadSpansNameTheField) {
  const TPoseCrowd c = scattered(4, 1);
  Buffer<std::uint32_t> flags(kDrawTiers * 5);
  CullJob job;
  job.joint_count = c.skeleton.joint_count();
  job.joint_positions = c.positions;
  job.group_flags = flags.span();
  try {
    job.run();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "cull.joint_positions");
  }
}

}  // namespace
}  // namespace throng::render
