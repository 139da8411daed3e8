// The frame loop behind `throng run`: every frame is the simulation's step
// (bin, sense, steer, move: simulation.h) followed by the later stages of the
// frame in the order they were added (locomotion, LOD, pose, skinning,
// rendering, outputs). A later stage plugs in as a FrameStage without
// changes here; its time appears under its name in the kernel timings and it
// adds its own sections to stats.json in finish().
//
//   FrameLoop loop(sim);
//   loop.emplace<CrowdMetricsStage>(sim, 10);        // sim/metrics_stage.h
//   loop.emplace<io::TrajectoryWriter>(output);       // io/run_outputs.h
//   const RunResult r = loop.run(control);
//   nlohmann::json stats;  loop.finish(stats);
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "sim/simulation.h"

namespace throng::sim {

struct FrameInfo {
  std::int64_t frame = 0;  // steps done: 0 is the initial state
  double time = 0;         // simulated seconds
  bool last = false;       // no frame follows (end of run, all arrived, or interrupted)
};

// A stage of the frame after the simulation step. Host-side orchestration;
// its per-agent work goes through parallel_for like any stage. Stages read
// the crowd (sim.crowd(): positions, velocities, headings, flags) and own
// whatever state they keep across frames.
class FrameStage {
 public:
  virtual ~FrameStage() = default;
  // Timing name ("emit.trajectories") and the stats.json section it writes.
  virtual std::string name() const = 0;
  // Frame 0, the initial state, before the first step.
  virtual void start(const Simulation& sim, const FrameInfo& frame) { after_step(sim, frame); }
  virtual void after_step(const Simulation& sim, const FrameInfo& frame) = 0;
  // After the last frame, also when the run was interrupted: flush outputs
  // and add sections to stats.json.
  virtual void finish(const Simulation& sim, nlohmann::json& stats) {}
};

struct RunControl {
  std::int64_t max_steps = 0;
  bool stop_when_arrived = true;
  const std::atomic<bool>* interrupt = nullptr;  // set from a signal handler: ends after the current frame
  std::function<void(const Simulation&, const FrameInfo&)> progress;  // after every frame
};

struct RunResult {
  std::int64_t steps = 0;
  double simulated_seconds = 0;
  double wall_seconds = 0;
  bool interrupted = false;
  bool all_arrived = false;
};

class FrameLoop {
 public:
  explicit FrameLoop(Simulation& sim) : sim_(sim) {}

  // Adds a stage after those already added; the loop owns it.
  template <class Stage, class... Args>
  Stage& emplace(Args&&... args) {
    auto stage = std::make_unique<Stage>(std::forward<Args>(args)...);
    Stage& ref = *stage;
    stages_.push_back(std::move(stage));
    return ref;
  }

  // Runs frames until max_steps, all arrived (when asked) or the interrupt.
  RunResult run(const RunControl& control);
  // Calls finish() of every stage, then adds "run" and "timings" sections.
  void finish(nlohmann::json& stats);

 private:
  Simulation& sim_;
  std::vector<std::unique_ptr<FrameStage>> stages_;
  std::vector<double> stage_ms_;  // wall time per stage, same order
  RunResult result_;
};

// The "timings" section: milliseconds per simulation stage (kernels named
// "sim.<stage>..." summed: bin, sense, steer, sense_steer, move), per frame
// stage (its own wall time), per step, and every kernel from KernelTimings.
nlohmann::json timings_section(std::int64_t steps, const std::vector<std::pair<std::string, double>>& frame_stage_ms);

}  // namespace throng::sim
