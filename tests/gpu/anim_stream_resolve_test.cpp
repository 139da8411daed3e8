// anim/stream_resolve on CUDA against the CPU: a StreamCrowd of two rigs
// stepped for a few dozen frames with transitions (StreamCommandJob), a
// batch retarget (StreamRetargetJob), events (StreamEventsJob), bone
// overrides and culled clusters, then resolved into palettes
// (StreamResolveJob).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "anim/stream_crowd.h"
#include "tests/anim/stream_reference.h"
#include "tests/gpu/gpu_test.h"

namespace throng::anim {
namespace {

using namespace testing;  // stream_reference.h's rigs and clips
namespace dj = motion::default_joint;
constexpr float kFps = 30.0f;
constexpr float kDt = 1.0f / kFps;

StreamSpec spec_of(const std::string& name, std::int32_t history) {
  StreamSpec s;
  s.name = name;
  s.history = history;
  s.time_to_dilate = static_cast<float>(history) / kFps;
  return s;
}

struct Result {
  std::vector<Mat3x4> palettes;
  std::vector<std::int32_t> read_offsets;
  std::vector<ClusterRef> clusters;
  std::vector<EventMask> events;  // every frame's
  Index retargeted = 0;
};

TEST(CudaStreamCrowd, StepRetargetAndResolveMatchCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kHumans = 600, kFingered = 400, kAgents = kHumans + kFingered;
  std::vector<glm::vec3> positions;
  std::vector<float> yaws;
  for (Index a = 0; a < kAgents; ++a) {
    positions.emplace_back(0.7f * static_cast<float>(a % 40), 0.0f, -1.1f * static_cast<float>(a / 40));
    yaws.push_back(0.37f * static_cast<float>(a));
  }
  const auto run = [&](Memory m) {
    StreamCrowd crowd(StreamCrowdConfig{kFps, 7});  // its buffers in current_memory()
    const std::int32_t human = crowd.add_rig(humanoid_rig());
    const std::int32_t fingered = crowd.add_rig(make_rig("fingered", fingered_skeleton()));
    const int Jh = crowd.rig(human).joint_count(), Jf = crowd.rig(fingered).joint_count();
    EventNames& names = crowd.event_names();
    const auto left = names.intern("footstep_left"), right = names.intern("footstep_right");
    AnimClip walk_clip = default_clip("walk");
    walk_clip.events = {{0.1f, left}, {0.4f, right}};  // within the stride (about 1 s)
    StreamPool& pool = crowd.streams();
    const std::int32_t walk =
        pool.add(crowd.rig(human), human, spec_of("walk", 64), std::make_unique<ClipPlayer>(walk_clip));
    const std::int32_t wave =
        pool.add(crowd.rig(human), human, spec_of("wave", 32), std::make_unique<ClipPlayer>(wiggle_clip(Jh, 45, kDt)));
    const std::int32_t f_walk = pool.add(crowd.rig(fingered), fingered, spec_of("f_walk", 64),
                                         std::make_unique<ClipPlayer>(wiggle_clip(Jf, 50, kDt)));
    const std::int32_t f_idle = pool.add(crowd.rig(fingered), fingered, spec_of("f_idle", 16),
                                         std::make_unique<ClipPlayer>(wiggle_clip(Jf, 70, kDt, "idle"), 0.5f));
    crowd.add_agents(human, kHumans);
    crowd.add_agents(fingered, kFingered);
    crowd.assign_random(0, kHumans, {{{walk}, {walk, wave}, {walk, wave}}, true}, 11);
    crowd.assign_random(kHumans, kFingered, {{{f_walk, f_idle}, {f_walk, f_idle}, {f_idle}}, true}, 12);
    BoneOverride look;
    look.joint = dj::Head;
    look.kind = OverrideKind::LookAt;
    look.target = glm::vec3(3, 1.7f, 3);
    BoneOverride turn;
    turn.joint = dj::LeftForeArm;
    turn.rotation = glm::angleAxis(0.8f, glm::vec3(0.0f, 0.0f, 1.0f));
    turn.weight = 0.6f;
    for (Index a = 0; a < kAgents; a += 7) crowd.set_override(a, a % 2 == 0 ? look : turn);
    for (Index a = 3; a < kAgents; a += 50) crowd.set_culled(a, 1, true);

    Result r;
    for (int f = 0; f < 30; ++f) {
      if (f == 5)
        for (Index a = 0; a < kHumans; a += 2) crowd.transition_to_streamed(a, 1, a % 4 == 0 ? walk : wave, 0.4f);
      crowd.step();
      if (f == 12) {  // every agent a desired stream of its rig (some none, some out of range)
        std::vector<std::int32_t> sources, offsets;
        for (Index a = 0; a < kAgents; ++a) {
          const bool h = a < kHumans;
          sources.push_back(
              a % 11 == 0 ? kNoSource : (a % 13 == 0 ? 99 : (a % 3 == 0 ? (h ? wave : f_idle) : (h ? walk : f_walk))));
          offsets.push_back(static_cast<std::int32_t>((a * 7) % 40));
        }
        const Buffer<std::int32_t> bs = gpu_test::upload(sources, m), bo = gpu_test::upload(offsets, m);
        r.retargeted = crowd.retarget(bs.span(), bo.span(), 0.3f, 0b011u);
      }
      const std::vector<EventMask> e = gpu_test::download(crowd.agent_events(), m);
      r.events.insert(r.events.end(), e.begin(), e.end());
    }
    const Buffer<glm::vec3> bp = gpu_test::upload(positions, m);
    const Buffer<float> by = gpu_test::upload(yaws, m);
    Buffer<Mat3x4> palettes(crowd.palette_size(), m);
    Buffer<std::int32_t> read_offsets(kAgents * crowd.cluster_stride(), m);
    crowd.resolve(bp.span(), by.span(), palettes.span(), read_offsets.span());
    r.palettes = palettes.to_vector();
    r.read_offsets = read_offsets.to_vector();
    r.clusters = gpu_test::download(crowd.cluster_refs(), m);
    return r;
  };
  const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);
  // Commands, retargeting, events and offsets are integer bookkeeping on
  // the same inputs (the controllers run on the host): bitwise.
  EXPECT_GT(cpu.retargeted, 0);
  EXPECT_EQ(gpu.retargeted, cpu.retargeted);
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.clusters, cpu.clusters)) << "cluster refs";
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.events, cpu.events)) << "events";
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.read_offsets, cpu.read_offsets)) << "read offsets";
  // Palettes: per joint a chain of 3x4 products (segment transforms, hooks,
  // the world transform of characters up to ~30 m away), SLERP blends of
  // transitions and look-at rotations (acos, sqrt): ~100 FMA-able
  // operations; 1e-5 relative plus 1e-4 absolute (about 50 ulps at 30 m).
  EXPECT_TRUE(gpu_test::near(gpu.palettes, cpu.palettes, {1e-5, 1e-4})) << "palettes";
}

}  // namespace
}  // namespace throng::anim
