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
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "anim/locomotion.h"
#include "app/locomotion_stats.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "motion/locomotion.h"
#include "sim/frame_loop.h"
#include "sim/simulation.h"

namespace throng::app {

struct LocomotionOptions {
  std::vector<float> lod_thresholds;  // square pixels, decreasing; empty = anim's defaults
  Index skating_agents = 64;          // agents, evenly spread over the crowd, whose foot skating is measured
};

// The scenario's camera, the one that renders and drives the LOD: its own,
// else an overview of the world and the crowd (sim::overview_camera).
Camera scenario_camera(const sim::Simulation& sim);

// Nominal standing height of a character (the default mannequin's), m.
constexpr float kCharacterHeight = 1.75f;

// Median height in pixels of the active agents whose feet are in the
// picture, as a character kCharacterHeight tall standing there; 0 when none is.
float median_character_px(const Camera& camera, const sim::Simulation& sim);

// A camera that keeps the scenario camera's viewing direction and field of
// view but aims at the active agents and comes just close enough to frame
// them, eased so the view glides rather than jumps: `throng run --render`
// uses it unless told otherwise. It never stands so far that a character
// would be under `min_character_px` tall: a crowd too wide for that (the
// circle's ring of a few hundred agents) is seen in part, around the agent
// nearest its middle, rather than whole as dots; the crowd converging at the
// centre then fills the frame. As the camera of the locomotion stage it is
// also what joint LOD measures with.
class FollowCamera {
 public:
  // ease_seconds: simulated seconds to close about 63% of the way to a new framing.
  FollowCamera(const Camera& view, double ease_seconds, float min_character_px = 45.0f);
  Camera at(const sim::Simulation& sim, double t);

 private:
  Camera view_;
  glm::vec3 direction_{0.0f, 0.0f, 1.0f};  // from the target towards the camera, unit
  double ease_seconds_ = 1.0;
  float min_character_px_ = 45.0f;
  Index focus_ = -1;  // the agent aimed at when the crowd is too wide to frame whole
  Index focus_agent(const std::vector<glm::vec2>& positions, const std::vector<std::uint8_t>& flags, glm::vec2 middle);
  bool started_ = false;
  double last_t_ = 0.0;
  glm::vec3 target_{0.0f};
  float distance_ = 10.0f;
};

// Foot slides kept for the p95 of a long run (mean and max are exact).
inline constexpr std::size_t kMaxSkatingSlides = 65536;

class SimulationLocomotion {
 public:
  SimulationLocomotion(const sim::Simulation& sim, const LocomotionOptions& options = {});
  SimulationLocomotion(const SimulationLocomotion&) = delete;
  SimulationLocomotion& operator=(const SimulationLocomotion&) = delete;

  anim::CrowdAnimator& animator() { return *crowd_; }
  const anim::CrowdAnimator& animator() const { return *crowd_; }

  // Where the agents stand now: the start of the next interpolation. Call
  // before each simulation step (or after it, for the step that follows).
  void remember(const sim::Simulation& sim);
  // One frame: agents `alpha` of the way from the remembered step to the
  // current state (1 = the current state), walking at their displacement
  // over that step (what the root moves, so strides match it), dt seconds
  // after the previous frame, joint LOD for `camera` (null: every joint).
  // moving = false shows everyone standing (a finished simulation).
  const anim::FrameStats& animate(const sim::Simulation& sim, float alpha, float dt, const Camera* camera, bool moving = true);

  std::int64_t frames() const { return tally_.frames; }
  // stats.json's "locomotion" section: frame timings, kernels (anim.*),
  // joint-LOD histogram, cache counters, foot skating (cm: mean, p95).
  nlohmann::json stats() const;

 private:
  motion::BlendSpace1D space_;
  std::unique_ptr<anim::CrowdAnimator> crowd_;
  std::vector<float> thresholds_;
  Index tracked_ = 0;
  Buffer<glm::vec2> previous_positions_, shown_positions_, moved_, still_;
  Buffer<float> previous_headings_, shown_headings_;
  LocomotionTally tally_;  // over the frames
  std::int32_t skating_frames_ = 0;  // frames in the current foot-tracking window
  ThinnedSample slides_cm_{kMaxSkatingSlides};  // contacts of the windows closed so far
};

// `throng run`'s locomotion stage ("anim.locomotion"). Frames: one per
// simulation step, or `fps` per simulated second (the frames of a video,
// agents interpolated between steps). After every frame `on_frame` is
// called (rendering); the camera at a time drives the LOD.
struct LocomotionStageOptions {
  LocomotionOptions locomotion;
  double fps = 0.0;  // 0: a frame per step
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
