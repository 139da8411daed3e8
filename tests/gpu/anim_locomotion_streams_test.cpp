// anim/locomotion_streams on CUDA against the CPU: a LocomotionStreams
// crowd animated for a few frames with a camera (so some agents are exact):
// the bucket/exact split (StreamBucketJob), phase and stream selection
// (StreamSelectJob), the exact path's gather, PoseJob and JointPaletteJob,
// and the sharing-error kernel.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "anim/blend_controller.h"
#include "anim/locomotion_streams.h"
#include "core/camera.h"
#include "tests/gpu/gpu_test.h"

namespace throng::anim {
namespace {

struct Result {
  std::vector<Mat3x4> palettes;
  std::vector<std::uint8_t> exact;
  std::vector<float> phases;
  std::vector<ClusterRef> clusters;
  std::vector<Index> stats;  // per frame: streamed, exact, retargeted, streams in use, running, started
  double sharing_max_cm = 0.0;
  Index sharing_agents = 0;
};

TEST(CudaLocomotionStreams, FramesMatchCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kN = 1200;
  constexpr Index kSide = 35;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> speed(0.0f, 3.0f), yaw(-3.14159f, 3.14159f);
  std::vector<glm::vec3> positions;
  std::vector<float> yaws, speeds, faster;
  for (Index i = 0; i < kN; ++i) {
    positions.emplace_back(2.0f * static_cast<float>(i % kSide), 0.0f, -2.0f * static_cast<float>(i / kSide));
    yaws.push_back(yaw(rng));
    speeds.push_back(speed(rng));
    faster.push_back(i % 3 == 0 ? speeds.back() + 0.6f : speeds.back());  // a third change bucket at frame 4
  }
  Camera camera;  // near the first rows: those agents are exact
  camera.position = glm::vec3(5.0f, 1.7f, 5.0f);
  camera.target = glm::vec3(30.0f, 0.5f, -40.0f);
  camera.width = 1280;
  camera.height = 720;
  const auto run = [&](Memory m) {
    LocomotionStreams loco(default_blend_spaces().speeds, kN);  // buffers in current_memory()
    loco.set_agents(positions, yaws, speeds);
    Result r;
    for (int frame = 0; frame < 8; ++frame) {
      if (frame == 4) loco.set_agents(positions, yaws, faster);
      const LocomotionStreamsStats& s = loco.animate(&camera);
      r.stats.insert(r.stats.end(), {s.streamed, s.exact, s.retargeted, Index{s.streams_in_use},
                                     Index{s.streams_running}, Index{s.streams_started}});
    }
    r.palettes = gpu_test::download(loco.palettes(), m);
    r.exact = gpu_test::download(loco.exact(), m);
    r.phases = gpu_test::download(loco.phases(), m);
    r.clusters = gpu_test::download(loco.crowd().cluster_refs(), m);
    const SharingError e = loco.sharing_error();
    r.sharing_max_cm = e.max_cm;
    r.sharing_agents = e.agents;
    return r;
  };
  const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_GT(cpu.stats[cpu.stats.size() - 5], 0) << "some agents are exact";
  ASSERT_GT(cpu.stats[cpu.stats.size() - 6], 0) << "some agents are streamed";

  // Exact or streamed follows a pixel-area threshold (LodJob): an agent
  // whose area is within a few roundings of it may go either way. At most 2;
  // such agents (and their palettes, clusters, phases) are left out below.
  const std::vector<std::size_t> exact_diff = gpu_test::differing(gpu.exact, cpu.exact);
  EXPECT_LE(exact_diff.size(), 2u) << "agents exact on one side only";
  if (exact_diff.empty()) {
    EXPECT_TRUE(gpu_test::bitwise_equal(gpu.stats, cpu.stats))
        << "streamed, exact, retargeted, streams in use/running/started";
    EXPECT_EQ(gpu.sharing_agents, cpu.sharing_agents);
  }
  const std::int32_t J = default_blend_spaces().speeds->joint_count();
  const std::size_t left_out = exact_diff.size();

  // Which stream and offset each cluster reads, and its transition: integer
  // decisions from bucket keys (a threshold on w) and the slot nearest a
  // phase; equal unless an agent's phase sits on a rounding boundary.
  const std::size_t stride = cpu.clusters.size() / kN;
  const std::vector<std::size_t> cluster_diff = gpu_test::differing(gpu.clusters, cpu.clusters);
  EXPECT_LE(cluster_diff.size(), stride * left_out) << "cluster refs that differ";

  // Phases: the cadence (frames per cycle over dt) times a few frames, a
  // wrap into [0, 1): a few roundings per frame over 8 frames.
  EXPECT_TRUE(gpu_test::near(gpu.phases, cpu.phases, {1e-5, 1e-5, left_out})) << "phases";
  // Palettes: world transform (positions up to ~70 m) times forward
  // kinematics of ~20 joints (SLERP, leg IK for exact agents), times the
  // inverse bind: a chain of ~100 FMA-able operations; 1e-5 relative plus
  // 2e-4 absolute (about 25 ulps at 70 m).
  EXPECT_TRUE(gpu_test::near(gpu.palettes, cpu.palettes, {1e-5, 2e-4, 12 * static_cast<std::size_t>(J) * left_out}))
      << "palettes";
  // The sharing error is a maximum over joints of distances in cm of
  // streamed against exact synthesis, both computed on the side's backend.
  if (gpu_test::tolerant())
    EXPECT_NEAR(gpu.sharing_max_cm, cpu.sharing_max_cm, 1e-3 + 1e-4 * cpu.sharing_max_cm);
  else
    EXPECT_EQ(gpu.sharing_max_cm, cpu.sharing_max_cm);
}

}  // namespace
}  // namespace throng::anim
