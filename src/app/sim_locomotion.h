// The locomotion stage driven by the crowd simulation: every agent animated
// from its simulated velocity and heading (anim::CrowdAnimator::drive_from_map:
// speed -> w, heading -> orientation, phase advanced by the blended cadence),
// with joint LOD under the scenario's camera, the motion cache, and foot
// skating measured on some agents.
//
// One mechanism for every caller: `throng run` (LocomotionStage, a
// sim::FrameStage, with a frame per step, or per video frame with --render)
// and `throng view` / `throng view --headless` (cmd_view.cpp's
// SimulationScene) all animate through SimulationLocomotion::animate().
// Between two simulation steps agents are interpolated
// (anim::InterpolateAgentsJob), so frames faster than the steps stay smooth.
//
// Two ways to animate, chosen at construction: exact per-agent synthesis
// (anim::CrowdAnimator, the default) or locomotion through streams
// (anim::LocomotionStreams: far agents read a few shared speed-bucket
// streams, agents near the camera are synthesised; docs/streams.md).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "anim/crowd_animator.h"
#include "anim/locomotion_streams.h"
#include "app/follow_camera.h"
#include "app/locomotion_stats.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "io/scenario_yaml.h"
#include "motion/locomotion.h"
#include "sim/frame_loop.h"
#include "sim/simulation.h"

namespace throng::app {

// Agents whose feet `throng run` measures: all of them in crowds up to this
// size (the demo's), else this many spread over the crowd.
inline constexpr Index kSkatingAgents = 1000;

struct SimulationLocomotionOptions {
  // The motion set (io::load_motion_set); null = the default set.
  std::shared_ptr<const motion::BlendSpace1D> space;
  std::vector<float> lod_thresholds;  // square pixels, decreasing; empty = anim's defaults
  // Agents, evenly spread over the crowd, whose foot skating is measured:
  // every agent of a crowd up to this size.
  Index skating_agents = kSkatingAgents;
  bool streams = false;               // locomotion through streams instead of exact synthesis
  float frame_rate = 30.0f;           // streams: animation frames per simulated second (one per animate())
};

// How `throng run` animates a crowd: exact synthesis, streams, or streams
// from kStreamsFrom agents up (auto).
enum class AnimationPath : std::uint8_t { Auto, Exact, Streams };
// "auto" | "exact" | "streams"; Error naming `field` otherwise.
AnimationPath parse_animation_path(const std::string& text, const std::string& field);
// The crowd size from which auto picks streams (docs/streams.md, "In
// `throng run`"): below it exact synthesis, which streams undercut at any
// size, still costs under about 10 ms a frame on one core and keeps foot
// locking and every agent's own speed.
inline constexpr Index kStreamsFrom = 20000;
bool use_streams(AnimationPath path, Index agents);

// The scenario's motion set (its `motion` key, io/motion_set.h; the default
// set without one), loaded. Errors name the clip's file.
std::shared_ptr<const motion::BlendSpace1D> load_scenario_motion(const io::LoadedScenario& loaded);

// The scenario's camera, the one that renders and drives the LOD: its own,
// else an overview of the world and the crowd (sim::overview_camera).
Camera scenario_camera(const sim::Simulation& sim);

class SimulationLocomotion {
 public:
  SimulationLocomotion(const sim::Simulation& sim, const SimulationLocomotionOptions& options = {});
  SimulationLocomotion(const SimulationLocomotion&) = delete;
  SimulationLocomotion& operator=(const SimulationLocomotion&) = delete;

  // The exact path's animator; Error when the crowd is animated by streams.
  anim::CrowdAnimator& animator();
  const anim::CrowdAnimator& animator() const;
  bool streamed() const { return streams_ != nullptr; }
  anim::LocomotionStreams& streams() { return *streams_; }  // streamed() only
  const motion::Skeleton& skeleton() const { return space_->skeleton(); }

  // Where the agents stand now: the start of the next interpolation. Call
  // before each simulation step (or after it, for the step that follows).
  void remember(const sim::Simulation& sim);
  // One frame: agents `alpha` of the way from the remembered step to the
  // current state (1 = the current state), walking at their displacement
  // over that step (what the root moves, so strides match it), dt seconds
  // after the previous frame, joint LOD for `camera` (null: every joint).
  // moving = false shows everyone standing (a finished simulation).
  void animate(const sim::Simulation& sim, float alpha, float dt, const Camera* camera, bool moving = true);

  std::int64_t frames() const { return tally_.frames; }
  // Foot skating of the tracked agents (the path's own probe).
  void track(std::vector<Index> agents);
  motion::FootSkatingReport foot_skating() const;
  // stats.json's "locomotion" section: the path, frame timings, kernels
  // (anim.*), joint-LOD histogram and cache counters (exact) or the
  // streams' figures and sharing error (streams), foot skating (cm: mean, p95).
  nlohmann::json stats() const;

 private:
  std::shared_ptr<const motion::BlendSpace1D> space_;
  std::unique_ptr<anim::CrowdAnimator> crowd_;        // exact synthesis, or
  std::unique_ptr<anim::LocomotionStreams> streams_;  // locomotion through streams
  std::vector<float> thresholds_;
  nlohmann::json streams_json() const;

  Index tracked_ = 0;
  Index exact_frames_ = 0;  // streams: exact agents summed over the frames
  Buffer<glm::vec2> previous_positions_, shown_positions_, moved_, still_;
  Buffer<float> previous_headings_, shown_headings_;
  LocomotionTally tally_;            // over the frames
  std::int32_t skating_frames_ = 0;  // frames in the current foot-tracking window
  SkatingTally skating_;             // the measuring windows closed so far
};

// `throng run`'s locomotion stage ("anim.locomotion"). Frames: one per
// simulation step, or `fps` per simulated second (the frames of a video,
// agents interpolated between steps). After every frame `on_frame` is
// called (rendering); the camera at a time drives the LOD.
struct LocomotionStageOptions {
  SimulationLocomotionOptions locomotion;
  double fps = 0.0;                           // 0: a frame per step
  std::function<Camera(double time)> camera;  // the camera of each frame (rendering and LOD)
  bool lod = true;                            // false or no camera: every joint synthesised
  std::function<void(double time, const Camera* camera, SimulationLocomotion& animated)> on_frame;
};

class LocomotionStage final : public sim::FrameStage {
 public:
  LocomotionStage(const sim::Simulation& sim, LocomotionStageOptions options);
  std::string name() const override { return "anim.locomotion"; }
  void start(const sim::Simulation& sim, const sim::FrameInfo& frame) override;
  void after_step(const sim::Simulation& sim, const sim::FrameInfo& frame) override;
  void finish(const sim::Simulation& sim, nlohmann::json& stats) override;
  SimulationLocomotion& locomotion() { return locomotion_; }

 private:
  void frame_at(const sim::Simulation& sim, double time, float alpha, float dt);

  LocomotionStageOptions options_;
  SimulationLocomotion locomotion_;
  std::int64_t video_frames_ = 0;  // with fps: frames shown so far
  double last_time_ = 0.0;
};

}  // namespace throng::app
