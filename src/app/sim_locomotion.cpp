#include "app/sim_locomotion.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "anim/between_steps.h"
#include "app/locomotion_stats.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/timing.h"
#include "sim/scenario.h"

namespace throng::app {

namespace {

// Foot tracking is measured in windows of frames: the probe keeps every
// joint of every tracked agent in every frame, so a window holds at most
// kSkatingBytes of them, and from 60 to 600 frames (a contact cut by a
// window's end counts as two shorter ones).
constexpr double kSkatingBytes = 64.0 * 1024.0 * 1024.0;

std::int32_t skating_window(Index tracked, std::int32_t joints) {
  const double per_frame = static_cast<double>(tracked) * joints * (sizeof(glm::vec3) + sizeof(glm::quat) + 1);
  return static_cast<std::int32_t>(std::clamp(kSkatingBytes / std::max(per_frame, 1.0), 60.0, 600.0));
}

// Agents whose error of sharing stats.json reports (evenly spread): the
// measure synthesises each of them exactly once more.
constexpr Index kSharingSample = 10000;

std::vector<Index> tracked_agents(Index n, Index wanted) {
  std::vector<Index> out;
  const Index k = std::min(n, wanted);
  for (Index i = 0; i < k; ++i) out.push_back(i * n / k);
  return out;
}

}  // namespace

std::shared_ptr<const motion::BlendSpace1D> load_scenario_motion(const io::LoadedScenario& loaded) {
  return std::make_shared<const motion::BlendSpace1D>(
      io::load_motion_set(loaded.motion, loaded.motion_folder(), "motion"));
}

Camera scenario_camera(const sim::Simulation& sim) {
  if (sim.spec().camera) return *sim.spec().camera;
  sim::Aabb box = sim.world().bounds();
  for (const glm::vec2& p : sim.positions()) box.add(p);
  if (box.empty()) box.add(glm::vec2(0.0f));
  return sim::overview_camera(box);
}

AnimationPath parse_animation_path(const std::string& text, const std::string& field) {
  if (text == "auto") return AnimationPath::Auto;
  if (text == "exact") return AnimationPath::Exact;
  if (text == "streams") return AnimationPath::Streams;
  throw Error("is auto, exact or streams (got '" + text + "')", at_field(field));
}

bool use_streams(AnimationPath path, Index agents) {
  return path == AnimationPath::Streams || (path == AnimationPath::Auto && agents >= kStreamsFrom);
}

SimulationLocomotion::SimulationLocomotion(const sim::Simulation& sim, const SimulationLocomotionOptions& options)
    : space_(options.space ? options.space
                           : std::make_shared<const motion::BlendSpace1D>(motion::make_default_blend_space())),
      thresholds_(options.lod_thresholds) {
  const Index n = sim.agent_count();
  anim::CrowdAnimatorConfig config;
  if (!thresholds_.empty()) config.lod_thresholds = thresholds_;
  thresholds_ = config.lod_thresholds;
  // Gait phases drawn from the scenario's seed, so neighbours do not step in unison.
  std::mt19937 rng(static_cast<std::uint32_t>(sim.spec().seed));
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> phases(static_cast<std::size_t>(n));
  for (float& p : phases) p = unit(rng);
  if (options.streams) {
    anim::LocomotionStreamsConfig streams;
    streams.frame_rate = options.frame_rate;
    streams.exact_coverage = thresholds_.front();  // exact where joint LOD would synthesise every joint
    streams.seed = sim.spec().seed;
    streams_ = std::make_unique<anim::LocomotionStreams>(space_, n, streams);
    streams_->set_phases(phases);
  } else {
    crowd_ = std::make_unique<anim::CrowdAnimator>(*space_, n, config);
    const std::vector<glm::vec2> at = sim.positions();
    const std::vector<float> headings = sim.headings();
    std::vector<glm::vec3> positions(static_cast<std::size_t>(n));
    std::vector<float> yaws(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < positions.size(); ++i) {
      positions[i] = world_from_ground(at[i]);
      yaws[i] = yaw_from_heading(headings[i]);
    }
    crowd_->place(positions, yaws, {}, phases);
  }
  tracked_ = options.skating_agents;
  const Memory m = current_memory();
  previous_positions_ = Buffer<glm::vec2>(n, m);
  shown_positions_ = Buffer<glm::vec2>(n, m);
  previous_headings_ = Buffer<float>(n, m);
  shown_headings_ = Buffer<float>(n, m);
  still_ = Buffer<glm::vec2>::zeros(n, m);
  moved_ = Buffer<glm::vec2>(n, m);
  remember(sim);
}

anim::CrowdAnimator& SimulationLocomotion::animator() {
  if (!crowd_) throw Error("the crowd is animated by streams, not by exact synthesis", at_field("locomotion.animator"));
  return *crowd_;
}

const anim::CrowdAnimator& SimulationLocomotion::animator() const {
  return const_cast<SimulationLocomotion*>(this)->animator();
}

void SimulationLocomotion::remember(const sim::Simulation& sim) {
  const Index n = sim.agent_count();
  copy_span(sim.crowd().position.span(), previous_positions_.span().subspan(0, n));
  copy_span(sim.crowd().heading.span(), previous_headings_.span().subspan(0, n));
}

void SimulationLocomotion::animate(const sim::Simulation& sim, float alpha, float dt, const Camera* camera,
                                   bool moving) {
  const auto t0 = std::chrono::steady_clock::now();
  const sim::CrowdState& c = sim.crowd();
  // Agents between the steps, moving at their displacement over the step.
  anim::InterpolateAgentsJob between;
  between.alpha = alpha;
  between.previous_positions = previous_positions_.span();
  between.positions = c.position.span();
  between.previous_headings = previous_headings_.span();
  between.headings = c.heading.span();
  between.out_positions = shown_positions_.span();
  between.out_headings = shown_headings_.span();
  between.step_seconds = sim.spec().dt;
  between.out_velocities = moved_.span();
  between.periodic = sim.world().periodic();
  between.run();
  const Span<const glm::vec2> velocities = moving ? moved_.span() : still_.span();
  if (streams_) {
    // One stream frame per call: the caller's frames must be that far apart
    // (a frame that does not move time on, the first, still takes one).
    const float rate = streams_->config().frame_rate;
    if (dt > 0.0f && std::abs(dt * rate - 1.0f) > 0.01f)
      throw Error(fmt::format("a frame of {} s, streams play {} frames a second", dt, rate),
                  at_field("locomotion.frame_rate"));
    streams_->drive_from_map(shown_positions_.span(), velocities, shown_headings_.span());
    const anim::LocomotionStreamsStats& s = streams_->animate(camera);
    anim::FrameStats frame;
    frame.characters = s.agents;
    tally_.add(frame, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    exact_frames_ += s.exact;
  } else {
    crowd_->drive_from_map(shown_positions_.span(), velocities, shown_headings_.span());
    const anim::FrameStats& s = crowd_->animate({dt, camera, false});
    tally_.add(s, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  // Foot tracking starts with the first frame that moves time on, in windows.
  const std::int32_t window = skating_window(std::min(sim.agent_count(), tracked_), space_->joint_count());
  if (dt > 0.0f && tracked_ > 0 && (skating_frames_ == 0 || skating_frames_ >= window)) {
    if (skating_frames_ > 0) skating_.add(foot_skating());
    track(tracked_agents(sim.agent_count(), tracked_));
    skating_frames_ = 0;
  }
  if (skating_frames_ > 0 || (dt > 0.0f && tracked_ > 0)) ++skating_frames_;
}

void SimulationLocomotion::track(std::vector<Index> agents) {
  if (streams_) {
    streams_->track(std::move(agents));
  } else {
    crowd_->track(std::move(agents));
  }
}

motion::FootSkatingReport SimulationLocomotion::foot_skating() const {
  return streams_ ? streams_->foot_skating() : crowd_->foot_skating();
}

nlohmann::json SimulationLocomotion::stats() const {
  nlohmann::json out;
  const std::int64_t frames = tally_.frames;
  const Index n = streams_ ? streams_->agent_count() : crowd_->count();
  out["path"] = streams_ ? "streams" : "exact";
  out["characters"] = n;
  out["joints"] = space_->joint_count();
  out["frames"] = frames;
  out["frame_ms"] = tally_.frame_ms_json();
  // The stage's kernels (anim.*): milliseconds per frame.
  nlohmann::json kernels = nlohmann::json::object();
  for (const KernelStat& k : KernelTimings::global().stats())
    if (k.name.rfind("anim.", 0) == 0)
      kernels[k.name] = {{"count", k.count},
                         {"total_ms", k.total_ms},
                         {"median_ms", k.median_ms},
                         {"ms_per_frame", frames > 0 ? k.total_ms / static_cast<double>(frames) : 0.0}};
  out["kernels"] = kernels;
  if (streams_) {
    out["streams"] = streams_json();
  } else {
    out["joints_synthesised_per_character"] =
        tally_.character_frames() > 0.0 ? static_cast<double>(tally_.joints_synthesised) / tally_.character_frames()
                                        : 0.0;
    if (nlohmann::json lod = tally_.lod_json(*crowd_, thresholds_); !lod.is_null()) out["lod"] = lod;
    if (nlohmann::json cache = tally_.cache_json(*crowd_); !cache.is_null()) out["cache"] = cache;
  }
  SkatingTally skating = skating_;
  if (skating_frames_ > 0) skating.add(foot_skating());
  out["foot_skating_cm"] = skating.json(std::min(n, tracked_));
  return out;
}

nlohmann::json SimulationLocomotion::streams_json() const {
  const anim::LocomotionStreams& loco = *streams_;
  const anim::LocomotionStreamsStats& s = loco.last_frame();
  nlohmann::json out = {
      {"bucket_width", loco.config().bucket_width},
      {"frame_rate", loco.config().frame_rate},
      {"streams", s.streams},
      {"streams_running", s.streams_running},
      {"streams_in_use", s.streams_in_use},
      {"exact_per_frame",
       tally_.frames > 0 ? static_cast<double>(exact_frames_) / static_cast<double>(tally_.frames) : 0.0},
      {"pose_bytes", s.pose_bytes},
      {"agent_state_bytes", s.agent_state_bytes},
      {"ref_bytes", s.ref_bytes}};
  // The error of sharing on the last frame: streamed agents against their
  // own exact synthesis (worst joint per agent), on a sample of the crowd.
  const anim::SharingError e = loco.sharing_error(kSharingSample);
  const auto figure = [&](double cm) { return e.agents > 0 ? nlohmann::json(cm) : nlohmann::json(); };
  out["sharing_error_cm"] = {{"agents", e.agents},
                             {"max", figure(e.max_cm)},
                             {"mean", figure(e.mean_cm)},
                             {"p95", figure(e.p95_cm)},
                             {"fading", e.fading},
                             {"steady_max", figure(e.steady_max_cm)},
                             {"steady_p95", figure(e.steady_p95_cm)}};
  return out;
}

namespace {

// The stage's options with the streams' frame rate: one animation frame per
// stage frame (a video frame, else a step).
LocomotionStageOptions checked(LocomotionStageOptions options, const sim::Simulation& sim) {
  if (!(options.fps >= 0.0) || !std::isfinite(options.fps)) throw Error("must be >= 0", at_field("locomotion.fps"));
  options.locomotion.frame_rate =
      static_cast<float>(options.fps > 0.0 ? options.fps : 1.0 / static_cast<double>(sim.spec().dt));
  return options;
}

}  // namespace

LocomotionStage::LocomotionStage(const sim::Simulation& sim, LocomotionStageOptions options)
    : options_(checked(std::move(options), sim)), locomotion_(sim, options_.locomotion) {}

void LocomotionStage::frame_at(const sim::Simulation& sim, double time, float alpha, float dt) {
  std::optional<Camera> camera;
  if (options_.camera) camera = options_.camera(time);
  locomotion_.animate(sim, alpha, dt, camera && options_.lod ? &*camera : nullptr);
  if (options_.on_frame) options_.on_frame(time, camera ? &*camera : nullptr, locomotion_);
}

void LocomotionStage::start(const sim::Simulation& sim, const sim::FrameInfo& frame) {
  locomotion_.remember(sim);
  frame_at(sim, frame.time, 1.0f, 0.0f);
  video_frames_ = 1;
  last_time_ = frame.time;
}

void LocomotionStage::after_step(const sim::Simulation& sim, const sim::FrameInfo& frame) {
  const double step = static_cast<double>(sim.spec().dt);
  if (options_.fps <= 0.0) {
    frame_at(sim, frame.time, 1.0f, static_cast<float>(frame.time - last_time_));
  } else {
    // Every video frame whose time falls in (previous step, this step].
    const double frame_dt = 1.0 / options_.fps;
    for (;;) {
      const double t = static_cast<double>(video_frames_) * frame_dt;
      if (t > frame.time + 1e-9) break;
      const double alpha = std::clamp(1.0 - (frame.time - t) / step, 0.0, 1.0);
      frame_at(sim, t, static_cast<float>(alpha), static_cast<float>(frame_dt));
      ++video_frames_;
    }
  }
  last_time_ = frame.time;
  locomotion_.remember(sim);  // the start of the next step's interpolation
}

void LocomotionStage::finish(const sim::Simulation& sim, nlohmann::json& stats) {
  stats["locomotion"] = locomotion_.stats();
  stats["locomotion"]["fps"] = options_.fps > 0.0 ? options_.fps : 1.0 / static_cast<double>(sim.spec().dt);
}

}  // namespace throng::app
