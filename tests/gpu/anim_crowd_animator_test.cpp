// anim/locomotion on CUDA against the CPU: LocomoteJob, the LOD stage,
// the motion cache's key counts and PoseJob as CrowdAnimator runs them for
// a few frames, and MapInputJob.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "anim/crowd_animator.h"
#include "core/camera.h"
#include "tests/anim/crowd_fixture.h"
#include "tests/gpu/gpu_test.h"

namespace throng::anim {
namespace {

using testing::Crowd;
using testing::kPi;
using testing::random_crowd;
const motion::BlendSpace1D& space() { return testing::default_space(); }

struct Result {
  std::vector<glm::vec3> root_p, joint_p;
  std::vector<float> yaw, phase, blend_speed;
  std::vector<glm::quat> joint_q;
  std::vector<glm::mat4x3> draw;
  std::vector<std::uint8_t> levels;
  std::vector<std::uint32_t> masks;
  std::vector<std::int32_t> evaluated;
  std::vector<Index> stats;  // per frame: joints synthesised, from cache, cycles stored
};

TEST(CudaCrowdAnimator, FramesMatchCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kN = 2000;
  const Crowd crowd = random_crowd(kN, 12);
  const Camera cam = testing::crowd_camera();
  const auto run = [&](Memory m) {
    CrowdAnimatorConfig config;
    config.draw_matrices = true;
    CrowdAnimator animator(space(), kN, config);  // buffers in current_memory()
    animator.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
    animator.set_speeds(crowd.speeds);
    Result r;
    for (int frame = 0; frame < 4; ++frame) {
      const FrameStats& s = animator.animate({1.0f / 60.0f, &cam, true});
      r.stats.insert(r.stats.end(), {s.joints_synthesised, s.from_cache, static_cast<Index>(s.cycles_stored)});
    }
    r.root_p = gpu_test::download(animator.positions(), m);
    r.yaw = gpu_test::download(animator.yaws(), m);
    r.phase = gpu_test::download(animator.phases(), m);
    r.blend_speed = gpu_test::download(animator.blend_speeds(), m);
    r.joint_p = gpu_test::download(animator.joint_positions(), m);
    r.joint_q = gpu_test::download(animator.joint_rotations(), m);
    r.draw = gpu_test::download(animator.draw_matrices(), m);
    r.levels = gpu_test::download(animator.lod_levels(), m);
    r.masks = gpu_test::download(animator.joint_masks(), m);
    r.evaluated = gpu_test::download(animator.evaluated(), m);
    return r;
  };
  const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_GT(cpu.stats[1], 0) << "some characters read the cache";

  // Root motion: four frames of a few FMA-able operations on positions of
  // up to ~45 m (blend weight, cadence, Eq. 10's displacement), phases in
  // [0, 1) and speeds in m/s: a handful of roundings each frame.
  EXPECT_TRUE(gpu_test::near(gpu.root_p, cpu.root_p, {1e-5, 1e-5})) << "root positions";
  EXPECT_TRUE(gpu_test::near_angle(gpu.yaw, cpu.yaw, 1e-5)) << "yaws";
  EXPECT_TRUE(gpu_test::near(gpu.phase, cpu.phase, {1e-5, 1e-6})) << "phases";
  EXPECT_TRUE(gpu_test::near(gpu.blend_speed, cpu.blend_speed, {1e-5, 1e-6})) << "blend speeds";

  // LOD levels and masks come from a threshold on a pixel area (projection,
  // about 20 FMA-able operations): a character whose area lies within a few
  // roundings of a threshold may take the other level. As the CPU LOD test
  // allows against its double-precision reference, at most 2 such parts;
  // their characters' joints then differ by design and are left out below.
  const std::vector<std::size_t> level_diff = gpu_test::differing(gpu.levels, cpu.levels);
  EXPECT_LE(level_diff.size(), 2u) << "LOD levels that differ";
  std::vector<std::uint8_t> borderline(kN, 0);
  for (std::size_t i : level_diff) borderline[i / kBodyPartCount] = 1;
  const std::int32_t J = space().joint_count();
  const std::size_t W = cpu.masks.size() / kN;
  std::size_t joints_left_out = 0;
  for (Index c = 0; c < kN; ++c)
    if (borderline[static_cast<std::size_t>(c)]) joints_left_out += static_cast<std::size_t>(J);
  for (Index c = 0; c < kN; ++c) {
    if (borderline[static_cast<std::size_t>(c)]) continue;
    for (std::size_t w = 0; w < W; ++w)
      ASSERT_EQ(gpu.masks[static_cast<std::size_t>(c) * W + w], cpu.masks[static_cast<std::size_t>(c) * W + w])
          << "character " << c;
    ASSERT_EQ(gpu.evaluated[static_cast<std::size_t>(c)], cpu.evaluated[static_cast<std::size_t>(c)])
        << "character " << c;
  }
  if (level_diff.empty()) {
    EXPECT_TRUE(gpu_test::bitwise_equal(gpu.stats, cpu.stats)) << "joints synthesised, from cache, cycles stored";
  }

  // World joints: blend of two clips by SLERP, leg IK (acos/atan2 of
  // lengths), then a forward-kinematics chain of ~20 quaternion products:
  // each a few roundings, with positions up to ~45 m, so 1e-4 m (about 25
  // float ulps at 45 m) and 1e-4 in quaternion components.
  // Characters at a borderline LOD level show other joints: allowed out.
  EXPECT_TRUE(gpu_test::near(gpu.joint_p, cpu.joint_p, {1e-6, 1e-4, 3 * joints_left_out})) << "joint positions";
  EXPECT_TRUE(gpu_test::near(gpu.joint_q, cpu.joint_q, {0.0, 1e-4, 4 * joints_left_out})) << "joint rotations";
  EXPECT_TRUE(gpu_test::near(gpu.draw, cpu.draw, {1e-5, 1e-4, 12 * joints_left_out})) << "draw matrices";
}

TEST(CudaMapInput, MatchesCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kN = 3000;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-60.0f, 60.0f), vel(-2.0f, 2.0f), angle(-kPi, kPi);
  std::vector<glm::vec2> p, v;
  std::vector<float> h;
  for (Index i = 0; i < kN; ++i) {
    p.emplace_back(pos(rng), pos(rng));
    v.emplace_back(vel(rng), vel(rng));
    h.push_back(angle(rng));
  }
  struct Out {
    std::vector<glm::vec3> p;
    std::vector<float> yaw, speed;
  };
  const auto run = [&](Memory m) {
    Buffer<glm::vec2> bp = gpu_test::upload(p, m), bv = gpu_test::upload(v, m);
    Buffer<float> bh = gpu_test::upload(h, m), yaw(kN, m), speed(kN, m);
    Buffer<glm::vec3> out_p(kN, m);
    MapInputJob job;
    job.map_positions = bp.span();
    job.map_velocities = bv.span();
    job.map_headings = bh.span();
    job.positions = out_p.span();
    job.yaws = yaw.span();
    job.speeds = speed.span();
    job.run();
    return Out{out_p.to_vector(), yaw.to_vector(), speed.to_vector()};
  };
  const Out cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Out gpu = gpu_test::run_on(gpu_test::device_side(), run);
  // Ground -> world is a permutation and sign change of the coordinates:
  // no arithmetic to round differently.
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.p, cpu.p)) << "positions";
  // Heading -> yaw: an offset and a wrap (FMA-able): a few roundings of 2 pi.
  EXPECT_TRUE(gpu_test::near_angle(gpu.yaw, cpu.yaw, 1e-5)) << "yaws";
  // |v| = sqrt(x*x + y*y): x*x + y*y may become one FMA; sqrt is exact-rounded on both.
  EXPECT_TRUE(gpu_test::near(gpu.speed, cpu.speed, {1e-6, 1e-7})) << "speeds";
}

}  // namespace
}  // namespace throng::anim
