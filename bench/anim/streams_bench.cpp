// Animation streams for 10^4 to 10^6 agents: 8 shared streams of the
// default humanoid (M = 64 poses each), 3 part clusters per agent at random
// streams and offsets. Per frame: the streams' controllers write their new
// poses and every agent's palette is resolved from (stream, offset) pairs.
// Compared with exact per-agent synthesis: every agent runs the locomotion
// issue's synthesis (its speed's blend, leg IK) at its own phase, then its
// palette. And locomotion through streams as `throng run` would use it: a
// stream per speed bucket, exact synthesis near the camera.
#include <cmath>
#include <memory>
#include <vector>

#include "anim/blend_controller.h"
#include "anim/crowd_animator.h"
#include "anim/locomotion_streams.h"
#include "anim/stream_crowd.h"
#include "bench/registry.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "core/exec.h"
#include "core/random.h"
#include "motion/default_set.h"

namespace throng::bench {

namespace {

using namespace throng::anim;

constexpr float kFrameRate = 30.0f;

struct Placement {
  Buffer<glm::vec3> positions;
  Buffer<float> yaws;
  explicit Placement(Index n) {
    std::vector<glm::vec3> p(static_cast<std::size_t>(n));
    std::vector<float> y(static_cast<std::size_t>(n));
    Rng rng(5);
    for (Index i = 0; i < n; ++i) {
      p[static_cast<std::size_t>(i)] = glm::vec3(rng.uniform(-500.0, 500.0), 0.0f, rng.uniform(-500.0, 500.0));
      y[static_cast<std::size_t>(i)] = static_cast<float>(rng.uniform(-3.14159, 3.14159));
    }
    positions = Buffer<glm::vec3>(std::span<const glm::vec3>(p), current_memory());
    yaws = Buffer<float>(std::span<const float>(y), current_memory());
  }
};

const std::vector<motion::DefaultMotion>& default_motions() {
  static const std::vector<motion::DefaultMotion> m = motion::make_default_motions(motion::default_skeleton());
  return m;
}

// A fixture of one size, kept between repetitions and thread counts (its
// set-up at 10^6 agents takes seconds); one of each kind lives at a time.
template <class Fixture>
Fixture& cached(Index n) {
  static std::unique_ptr<Fixture> f;
  if (!f || f->n != n || f->backend != current_backend()) {
    f.reset();  // free the previous one's palettes first
    f = std::make_unique<Fixture>();
    f->build(n);
  }
  return *f;
}

struct StreamsFixture {
  Index n = 0;
  Backend backend = Backend::Cpu;
  std::unique_ptr<StreamCrowd> crowd;
  std::unique_ptr<Placement> placement;
  Buffer<Mat3x4> palettes;

  void build(Index count) {
    n = count;
    backend = current_backend();
    crowd = std::make_unique<StreamCrowd>(StreamCrowdConfig{kFrameRate, 1});
    const std::int32_t rig = crowd->add_rig(make_rig("humanoid", motion::default_skeleton()));
    std::vector<std::int32_t> all;
    for (const motion::DefaultMotion& m : default_motions()) {  // 8 clips: idle, walks, runs, turns
      AnimClip clip;
      clip.name = m.spec.name;
      clip.clip = std::make_shared<motion::Clip>(m.clip);
      StreamSpec spec;
      spec.name = m.spec.name;
      spec.history = 64;
      all.push_back(crowd->streams().add(crowd->rig(rig), rig, spec, std::make_unique<ClipPlayer>(clip)));
    }
    crowd->add_agents(rig, n);
    crowd->assign_random(0, n, {{all, all, all}, true}, 7);
    for (int f = 0; f < 130; ++f) crowd->step();  // dilation done: offsets spread over all 64 slots
    placement = std::make_unique<Placement>(n);
    palettes = Buffer<Mat3x4>(crowd->palette_size(), current_memory());
  }

  void counters(benchmark::State& state) const {
    const StreamMemory m = crowd->memory();
    state.counters["pose_bytes"] = static_cast<double>(m.stream_poses);
    state.counters["agent_state_bytes"] = static_cast<double>(m.agent_state);
    state.counters["palette_bytes"] = static_cast<double>(m.palettes);
  }
};

// Exact per-agent synthesis (anim::PoseJob: full skeletons, no LOD, no
// cache) at speeds drawn over 0-4.5 m/s, phases advanced by each agent's
// cadence (LocomoteJob without root motion), then the palettes.
struct ExactFixture {
  Index n = 0;
  Backend backend = Backend::Cpu;
  std::unique_ptr<Placement> placement;
  motion::BlendSpaceTables tables;
  Buffer<float> speeds, phases, blend_speeds;
  Buffer<glm::vec3> joint_positions;
  Buffer<glm::quat> joint_rotations;
  Buffer<Mat3x4> inverse_bind;
  Buffer<Mat3x4> palettes;
  std::int32_t joints = 0;

  void build(Index count) {
    n = count;
    backend = current_backend();
    const Memory mem = current_memory();
    const motion::BlendSpace1D& space = *default_blend_spaces().speeds;
    tables = motion::BlendSpaceTables(space, mem);
    joints = space.joint_count();
    const Rig rig = make_rig("humanoid", space.skeleton());
    placement = std::make_unique<Placement>(n);
    std::vector<float> v(static_cast<std::size_t>(n)), ph(v.size());
    Rng rng(9);
    for (std::size_t a = 0; a < v.size(); ++a) {
      v[a] = static_cast<float>(rng.uniform(0.0, 4.5));
      ph[a] = static_cast<float>(rng.uniform());
    }
    speeds = Buffer<float>(std::span<const float>(v), mem);
    phases = Buffer<float>(std::span<const float>(ph), mem);
    blend_speeds = Buffer<float>(std::span<const float>(v), mem);
    joint_positions = Buffer<glm::vec3>(n * joints, mem);
    joint_rotations = Buffer<glm::quat>(n * joints, mem);
    inverse_bind = Buffer<Mat3x4>(std::span<const Mat3x4>(rig.inverse_bind), mem);
    palettes = Buffer<Mat3x4>(n * joints, mem);
  }

  void frame() {
    LocomoteJob locomote;
    locomote.blend = tables.view();
    locomote.step.dt = 1.0f / kFrameRate;
    locomote.step.integrate_root = false;
    locomote.speeds = speeds.span();
    locomote.positions = placement->positions.span();
    locomote.yaws = placement->yaws.span();
    locomote.phases = phases.span();
    locomote.blend_speeds = blend_speeds.span();
    locomote.run();
    PoseJob pose;
    pose.blend = tables.view();
    pose.positions = placement->positions.span();
    pose.yaws = placement->yaws.span();
    pose.phases = phases.span();
    pose.blend_speeds = blend_speeds.span();
    pose.joint_positions = joint_positions.span();
    pose.joint_rotations = joint_rotations.span();
    pose.run();
    JointPaletteJob palette;
    palette.joint_count = joints;
    palette.joint_positions = joint_positions.span();
    palette.joint_rotations = joint_rotations.span();
    palette.inverse_bind = inverse_bind.span();
    palette.palettes = palettes.span();
    palette.run();
  }

  void counters(benchmark::State& state) const {
    const motion::BlendSpace1D& space = *default_blend_spaces().speeds;
    // The motion texture every agent samples, and per agent its state and joints.
    state.counters["pose_bytes"] = static_cast<double>(space.texture().texels_f32.size() * sizeof(float));
    state.counters["agent_state_bytes"] = static_cast<double>(n) * (sizeof(glm::vec3) + 4 * sizeof(float));
    state.counters["joint_bytes"] = static_cast<double>(n * joints) * (sizeof(glm::vec3) + sizeof(glm::quat));
    state.counters["palette_bytes"] = static_cast<double>(palettes.size() * sizeof(Mat3x4));
  }
};

// Locomotion through streams: speeds drawn over 0-4.5 m/s on a grid 1.5 m
// apart, a 1080p camera 20 m outside the crowd and 15 m up looking at its
// centre; per frame every agent is classified (exact near the camera or a
// speed bucket), the streams in use step, agents are retargeted and every
// palette is written.
struct LocomotionFixture {
  Index n = 0;
  Backend backend = Backend::Cpu;
  std::unique_ptr<LocomotionStreams> loco;
  Camera camera;

  void build(Index count) {
    n = count;
    backend = current_backend();
    loco = std::make_unique<LocomotionStreams>(default_blend_spaces().speeds, n, LocomotionStreamsConfig{});
    const auto side = static_cast<Index>(std::ceil(std::sqrt(static_cast<double>(n))));
    const float half = 0.75f * static_cast<float>(side);
    std::vector<glm::vec3> p;
    std::vector<float> y, v;
    Rng rng(4);
    for (Index i = 0; i < n; ++i) {
      p.emplace_back(1.5f * static_cast<float>(i % side) - half, 0.0f, 1.5f * static_cast<float>(i / side) - half);
      y.push_back(static_cast<float>(rng.uniform(-3.14159, 3.14159)));
      v.push_back(static_cast<float>(rng.uniform(0.0, 4.5)));
    }
    loco->set_agents(p, y, v);
    camera.position = glm::vec3(0.0f, 15.0f, half + 20.0f);
    camera.target = glm::vec3(0.0f, 0.0f, 0.0f);
    camera.fov_y = 0.87f;
    camera.far_plane = 5000.0f;
    loco->animate(&camera);  // every stream in use started
  }

  void counters(benchmark::State& state) const {
    const LocomotionStreamsStats& s = loco->last_frame();
    state.counters["streams_in_use"] = static_cast<double>(s.streams_in_use);
    state.counters["exact_agents"] = static_cast<double>(s.exact);
    state.counters["pose_bytes"] = static_cast<double>(s.pose_bytes);
    state.counters["exact_bytes"] = static_cast<double>(s.exact_bytes);
    state.counters["agent_state_bytes"] = static_cast<double>(s.agent_state_bytes);
    state.counters["palette_bytes"] = static_cast<double>(s.palette_bytes);
  }
};

void register_streams(const Options& options) {
  const std::vector<Index> sizes = {10000, 100000, 1000000};

  // One whole frame: 8 streams step (controllers write P into their
  // histories), then every agent's palette is resolved.
  add(options, {"anim/streams_frame", sizes,
                [](benchmark::State& state, Index n) {
                  StreamsFixture& f = cached<StreamsFixture>(n);
                  for (auto _ : state) {
                    f.crowd->step();
                    f.crowd->resolve(f.placement->positions.span(), f.placement->yaws.span(), f.palettes.span());
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // The step alone: 8 controllers write their poses, events reach every agent.
  add(options, {"anim/streams_step", sizes,
                [](benchmark::State& state, Index n) {
                  StreamsFixture& f = cached<StreamsFixture>(n);
                  for (auto _ : state) {
                    f.crowd->step();
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // The palettes alone.
  add(options, {"anim/streams_resolve", sizes,
                [](benchmark::State& state, Index n) {
                  StreamsFixture& f = cached<StreamsFixture>(n);
                  for (auto _ : state) {
                    f.crowd->resolve(f.placement->positions.span(), f.placement->yaws.span(), f.palettes.span());
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // Exact per-agent synthesis: every agent's blend, leg IK and palette.
  add(options, {"anim/exact_synthesis_palette", sizes,
                [](benchmark::State& state, Index n) {
                  ExactFixture& f = cached<ExactFixture>(n);
                  for (auto _ : state) {
                    f.frame();
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // Locomotion through streams, one whole frame (LocomotionStreams::animate).
  add(options, {"anim/locomotion_streams_frame", sizes,
                [](benchmark::State& state, Index n) {
                  LocomotionFixture& f = cached<LocomotionFixture>(n);
                  for (auto _ : state) {
                    f.loco->animate(&f.camera);
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});
}

const bool registered = register_suite("streams", &register_streams);

}  // namespace

}  // namespace throng::bench
