// The locomotion stage as `throng run` animates the built-in plaza, per
// frame, by either path: exact per-agent synthesis (anim::CrowdAnimator:
// joint LOD under the scenario's camera, the motion cache, foot locking)
// or locomotion through streams (anim::LocomotionStreams: speed-bucket
// streams, exact synthesis near the camera, palette references for the
// renderer). Rows: app/plaza_locomotion/<path>: each iteration steps the
// simulation (not timed), then times one frame: the agents interpolated
// over that step and animated (SimulationLocomotion::animate, alpha 1:
// agents walk at their displacement over the step), as `throng run`
// animates a frame per step; app/plaza_frame/<path>: the step timed too (a
// whole frame of a run). The streams rows report the error of sharing
// (worst joint per streamed agent, cm; 10,000 agents spread over the
// crowd) on the last frame.
#include <map>
#include <memory>
#include <tuple>

#include "app/sim_locomotion.h"
#include "bench/registry.h"
#include "core/exec.h"
#include "io/scenario_yaml.h"
#include "sim/simulation.h"

namespace throng::bench {

namespace {

// A plaza of n agents in motion, built once per size and backend (routes
// are not planned: the rows time the animation).
sim::Simulation& plaza(Index n) {
  static std::map<std::tuple<Index, Backend>, std::unique_ptr<sim::Simulation>> cache;
  auto& slot = cache[{n, current_backend()}];
  if (!slot) {
    io::LoadedScenario s = io::load_builtin_scenario("plaza");
    sim::scale_agent_counts(s.spec, n);
    s.spec.planning = sim::PlanningKind::None;
    slot = io::build_simulation(s);
    slot->run(20);  // walking, not starting from rest
  }
  return *slot;
}

// with_step: the step is timed too (a whole frame of a run: simulation,
// then locomotion), else only the locomotion.
Body frame(bool streams, bool with_step) {
  return [streams, with_step](benchmark::State& state, Index n) {
    sim::Simulation& sim = plaza(n);
    app::SimulationLocomotionOptions options;
    options.streams = streams;
    options.frame_rate = 1.0f / sim.spec().dt;
    app::SimulationLocomotion locomotion(sim, options);
    const Camera camera = app::scenario_camera(sim);
    const float dt = sim.spec().dt;
    const auto step = [&] {
      locomotion.remember(sim);
      sim.step();
    };
    step();
    locomotion.animate(sim, 1.0f, dt, &camera);  // streams in use started, cache filled
    for (auto _ : state) {
      if (!with_step) state.PauseTiming();
      step();                                // a frame per step: agents change speed, bucket and stream as in a run
      if (!with_step) state.ResumeTiming();  // (Simulation::step waits for its own kernels)
      locomotion.animate(sim, 1.0f, dt, &camera);
      finish_device_work();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * n);
    if (!streams) return;
    const anim::SharingError e = locomotion.streams().sharing_error(10000);
    state.counters["sharing_max_cm"] = e.max_cm;
    state.counters["sharing_p95_cm"] = e.p95_cm;
    state.counters["sharing_mean_cm"] = e.mean_cm;
    state.counters["steady_p95_cm"] = e.steady_p95_cm;
    state.counters["steady_max_cm"] = e.steady_max_cm;
    state.counters["fading_share"] = e.agents > 0 ? static_cast<double>(e.fading) / static_cast<double>(e.agents) : 0.0;
    state.counters["retargeted_share"] =
        static_cast<double>(locomotion.streams().last_frame().retargeted) / static_cast<double>(n);
    state.counters["exact_agents"] = static_cast<double>(locomotion.streams().last_frame().exact);
    state.counters["streams_in_use"] = static_cast<double>(locomotion.streams().last_frame().streams_in_use);
  };
}

void register_locomotion(const Options& options) {
  const std::vector<Index> sizes = {10000, 100000};
  add(options, {"app/plaza_locomotion/exact", sizes, frame(false, false), true});
  add(options, {"app/plaza_locomotion/streams", sizes, frame(true, false), true});
  // The whole frame of `throng run`: the collision-free speed model's step, then the locomotion.
  add(options, {"app/plaza_frame/exact", sizes, frame(false, true), true});
  add(options, {"app/plaza_frame/streams", sizes, frame(true, true), true});
}

const bool registered = register_suite("app_locomotion", &register_locomotion);

}  // namespace

}  // namespace throng::bench
