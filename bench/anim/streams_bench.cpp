// Animation streams for 10^4 to 10^6 agents: 8 shared streams of the
// default humanoid (M = 64 poses each), 3 part clusters per agent at random
// streams and offsets. Per frame: the streams' controllers write their new
// poses and every agent's palette is resolved from (stream, offset) pairs.
// Compared with exact per-agent evaluation: each agent samples a clip at its
// own time (a SLERP per joint) and runs forward kinematics into its palette.
#include <memory>
#include <vector>

#include "anim/stream_crowd.h"
#include "bench/registry.h"
#include "core/buffer.h"
#include "core/exec.h"
#include "motion/default_set.h"
#include "core/random.h"

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

struct ExactFixture {
  Index n = 0;
  Backend backend = Backend::Cpu;
  std::unique_ptr<Placement> placement;
  Buffer<float> times;
  Buffer<std::int32_t> parents;
  Buffer<glm::vec3> offsets;
  Buffer<Mat3x4> inverse_bind;
  Buffer<glm::quat> clip_rotations;
  Buffer<glm::vec3> clip_roots;
  Buffer<Mat3x4> palettes;
  ClipPaletteJob job;

  void build(Index count) {
    n = count;
    backend = current_backend();
    const Memory mem = current_memory();
    const Rig rig = make_rig("humanoid", motion::default_skeleton());
    const motion::Clip& clip = default_motions()[2].clip;  // walk
    placement = std::make_unique<Placement>(n);
    std::vector<float> t(static_cast<std::size_t>(n));
    Rng rng(9);
    for (float& x : t) x = static_cast<float>(rng.uniform(0.0, 10.0));
    times = Buffer<float>(std::span<const float>(t), mem);
    parents = Buffer<std::int32_t>(std::span<const std::int32_t>(rig.skeleton.parents), mem);
    offsets = Buffer<glm::vec3>(std::span<const glm::vec3>(rig.skeleton.offsets), mem);
    inverse_bind = Buffer<Mat3x4>(std::span<const Mat3x4>(rig.inverse_bind), mem);
    clip_rotations = Buffer<glm::quat>(std::span<const glm::quat>(clip.rotations), mem);
    clip_roots = Buffer<glm::vec3>(std::span<const glm::vec3>(clip.root_positions), mem);
    palettes = Buffer<Mat3x4>(n * rig.joint_count(), mem);
    job.joint_count = rig.joint_count();
    job.frame_count = clip.frame_count;
    job.frame_time = clip.frame_time;
    job.parents = parents.span();
    job.offsets = offsets.span();
    job.inverse_bind = inverse_bind.span();
    job.clip_rotations = clip_rotations.span();
    job.clip_roots = clip_roots.span();
    job.times = times.span();
    job.positions = placement->positions.span();
    job.yaws = placement->yaws.span();
    job.palettes = palettes.span();
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
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // The step alone: 8 controllers write their poses, events reach every agent.
  add(options, {"anim/streams_step", sizes,
                [](benchmark::State& state, Index n) {
                  StreamsFixture& f = cached<StreamsFixture>(n);
                  for (auto _ : state) f.crowd->step();
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // The palettes alone.
  add(options, {"anim/streams_resolve", sizes,
                [](benchmark::State& state, Index n) {
                  StreamsFixture& f = cached<StreamsFixture>(n);
                  for (auto _ : state) f.crowd->resolve(f.placement->positions.span(), f.placement->yaws.span(), f.palettes.span());
                  state.SetItemsProcessed(state.iterations() * n);
                  f.counters(state);
                },
                true});

  // Exact per-agent evaluation of a clip at each agent's own time.
  add(options, {"anim/exact_clip_palette", sizes,
                [](benchmark::State& state, Index n) {
                  ExactFixture& f = cached<ExactFixture>(n);
                  for (auto _ : state) {
                    f.job.run();
                    f.job.time_offset += 1.0f / kFrameRate;
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                  state.counters["pose_bytes"] = static_cast<double>(f.clip_rotations.size() * sizeof(glm::quat) + f.clip_roots.size() * sizeof(glm::vec3));
                  state.counters["palette_bytes"] = static_cast<double>(f.palettes.size() * sizeof(Mat3x4));
                },
                true});
}

const bool registered = register_suite("streams", &register_streams);

}  // namespace

}  // namespace throng::bench
