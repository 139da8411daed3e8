#include "app/sim_locomotion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include "anim/between_steps.h"
#include "app/locomotion_stats.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/timing.h"
#include "sim/scenario.h"

namespace throng::app {

namespace {

// Frames of foot tracking pooled at a time: the probe keeps every tracked
// joint of every frame, so long runs are measured in windows (a contact cut
// by a window's end counts as two shorter ones).
constexpr std::int32_t kSkatingWindow = 600;

std::vector<Index> tracked_agents(Index n, Index wanted) {
  std::vector<Index> out;
  const Index k = std::min(n, wanted);
  for (Index i = 0; i < k; ++i) out.push_back(i * n / k);
  return out;
}

void copy_device(void* to, const void* from, std::size_t bytes) {
  if (bytes > 0) throng::detail::copy_bytes(to, current_memory(), from, current_memory(), bytes);
}

}  // namespace

Camera scenario_camera(const sim::Simulation& sim) {
  if (sim.spec().camera) return *sim.spec().camera;
  sim::Aabb box = sim.world().bounds();
  for (const glm::vec2& p : sim.positions()) box.add(p);
  if (box.empty()) box.add(glm::vec2(0.0f));
  return sim::overview_camera(box);
}

FollowCamera::FollowCamera(const Camera& view, double ease_seconds, float min_character_px)
    : view_(view), ease_seconds_(ease_seconds), min_character_px_(min_character_px) {
  if (!(ease_seconds > 0.0) || !std::isfinite(ease_seconds)) throw Error("must be positive seconds", at_field("camera.ease"));
  if (!(min_character_px >= 0.0f) || !std::isfinite(min_character_px))
    throw Error("must be a finite number of pixels >= 0", at_field("camera.min_character_px"));
  const glm::vec3 d = view.position - view.target;
  const float length = glm::length(d);
  if (!(length > 0.0f) || !std::isfinite(length)) throw Error("the camera's position equals its target", at_field("camera"));
  direction_ = d / length;
}

float median_character_px(const Camera& camera, const sim::Simulation& sim) {
  const CameraView v = make_camera_view(camera);
  const std::vector<glm::vec2> positions = sim.positions();
  const std::vector<std::uint8_t> flags = sim.flags();
  std::vector<float> heights;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if ((flags[i] & sim::kAgentActive) == 0) continue;
    const glm::vec3 foot = world_to_pixel(v, world_from_ground(positions[i], 0.0f));
    const glm::vec3 head = world_to_pixel(v, world_from_ground(positions[i], kCharacterHeight));
    if (foot.z <= 0.0f || head.z <= 0.0f || foot.x < 0.0f || foot.x >= v.width || foot.y < 0.0f || foot.y >= v.height) continue;
    heights.push_back(std::fabs(foot.y - head.y));
  }
  if (heights.empty()) return 0.0f;
  const auto mid = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), mid, heights.end());
  return *mid;
}

Index FollowCamera::focus_agent(const std::vector<glm::vec2>& positions, const std::vector<std::uint8_t>& flags, glm::vec2 middle) {
  // The agent nearest the middle, kept while it stays active and no other is
  // markedly nearer: on a ring every agent is about as near, and a focus
  // that hopped between them would swing the camera across the empty centre.
  Index best = -1;
  float best_d2 = INFINITY;
  for (std::size_t i = 0; i < positions.size(); ++i)
    if ((flags[i] & sim::kAgentActive) && sim::length2(positions[i] - middle) < best_d2) {
      best_d2 = sim::length2(positions[i] - middle);
      best = static_cast<Index>(i);
    }
  const auto f = static_cast<std::size_t>(focus_);
  const bool keep = focus_ >= 0 && f < positions.size() && (flags[f] & sim::kAgentActive) &&
                    std::sqrt(sim::length2(positions[f] - middle)) <= 1.25f * std::sqrt(best_d2) + 2.0f;
  if (!keep) focus_ = best;
  return focus_;
}

Camera FollowCamera::at(const sim::Simulation& sim, double t) {
  const std::vector<glm::vec2> positions = sim.positions();
  const std::vector<std::uint8_t> flags = sim.flags();
  // The box of the middle 80% of the active agents along each axis, so a few
  // stragglers do not pull the camera away from where the crowd is.
  std::vector<float> xs, ys;
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (flags[i] & sim::kAgentActive) {
      xs.push_back(positions[i].x);
      ys.push_back(positions[i].y);
    }
  sim::Aabb box;
  if (!xs.empty()) {
    const auto quantile = [](std::vector<float>& v, double q) {
      const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1) + 0.5);
      std::nth_element(v.begin(), v.begin() + k, v.end());
      return v[static_cast<std::size_t>(k)];
    };
    box.add(glm::vec2(quantile(xs, 0.1), quantile(ys, 0.1)));
    box.add(glm::vec2(quantile(xs, 0.9), quantile(ys, 0.9)));
  }
  if (box.empty()) {  // nobody left: hold the last framing
    if (!started_) return view_;
  } else {
    // A sphere holding the agents (and a character's height) fits the
    // narrower field of view; never closer than 8 m, so a lone agent is framed whole.
    const float reach = std::max(0.5f * glm::length(box.size()) + 1.0f, 4.0f);
    const float half_fov = 0.5f * std::min(view_.fov_y, 2.0f * std::atan(std::tan(0.5f * view_.fov_y) * aspect_ratio(view_)));
    float distance = std::max(reach / std::sin(half_fov), 8.0f);
    glm::vec2 middle = 0.5f * (box.min + box.max);
    // Farther than this, a character is under min_character_px tall: stay
    // there and aim at an agent near the middle (a ring's middle is empty).
    const float farthest = std::max(focal_length_pixels(view_) * kCharacterHeight / std::max(min_character_px_, 1e-3f), 8.0f);
    if (distance > farthest) {
      distance = farthest;
      middle = positions[static_cast<std::size_t>(focus_agent(positions, flags, middle))];
    }
    const glm::vec3 target = world_from_ground(middle, 0.9f);
    if (!started_) {
      target_ = target;
      distance_ = distance;
      started_ = true;
    } else {
      // Close in, a walker (at most ~2 m/s) must not outrun the easing: over
      // distance / 8 seconds it lags at most a quarter of the viewing
      // distance, well inside the frame (a time-lapse's half video second
      // may be many simulated seconds).
      const double ease = std::min(ease_seconds_, static_cast<double>(std::min(distance, distance_)) / 8.0);
      const float a = static_cast<float>(1.0 - std::exp(-std::max(0.0, t - last_t_) / ease));
      target_ += a * (target - target_);
      distance_ += a * (distance - distance_);
    }
  }
  last_t_ = t;
  Camera c = view_;
  c.target = target_;
  c.position = target_ + distance_ * direction_;
  c.near_plane = std::max(0.1f, 0.01f * distance_);
  c.far_plane = std::max(view_.far_plane, 4.0f * distance_);
  return c;
}

SimulationLocomotion::SimulationLocomotion(const sim::Simulation& sim, const LocomotionOptions& options)
    : space_(motion::make_default_blend_space()), thresholds_(options.lod_thresholds) {
  const Index n = sim.agent_count();
  anim::CrowdAnimatorConfig config;
  if (!thresholds_.empty()) config.lod_thresholds = thresholds_;
  thresholds_ = config.lod_thresholds;
  crowd_ = std::make_unique<anim::CrowdAnimator>(space_, n, config);
  // Gait phases drawn from the scenario's seed, so neighbours do not step in unison.
  std::mt19937 rng(static_cast<std::uint32_t>(sim.spec().seed));
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const std::vector<glm::vec2> at = sim.positions();
  const std::vector<float> headings = sim.headings();
  std::vector<glm::vec3> positions(static_cast<std::size_t>(n));
  std::vector<float> yaws(static_cast<std::size_t>(n)), phases(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < positions.size(); ++i) {
    positions[i] = world_from_ground(at[i]);
    yaws[i] = yaw_from_heading(headings[i]);
    phases[i] = unit(rng);
  }
  crowd_->place(positions, yaws, {}, phases);
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

void SimulationLocomotion::remember(const sim::Simulation& sim) {
  const auto n = static_cast<std::size_t>(sim.agent_count());
  copy_device(previous_positions_.data(), sim.crowd().position.data(), n * sizeof(glm::vec2));
  copy_device(previous_headings_.data(), sim.crowd().heading.data(), n * sizeof(float));
}

const anim::FrameStats& SimulationLocomotion::animate(const sim::Simulation& sim, float alpha, float dt, const Camera* camera, bool moving) {
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
  between.run();
  crowd_->drive_from_map(shown_positions_.span(), moving ? moved_.span() : still_.span(), shown_headings_.span());
  const anim::FrameStats& s = crowd_->animate({dt, camera, false});
  tally_.add(s, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  // Foot tracking starts with the first frame that moves time on, in windows.
  if (dt > 0.0f && tracked_ > 0 && (skating_frames_ == 0 || skating_frames_ >= kSkatingWindow)) {
    if (skating_frames_ > 0) {
      const motion::FootSkatingReport r = crowd_->foot_skating();
      for (const double slide : r.slides_cm) slides_cm_.push(slide);
    }
    crowd_->track(tracked_agents(crowd_->count(), tracked_));
    skating_frames_ = 0;
  }
  if (skating_frames_ > 0 || (dt > 0.0f && tracked_ > 0)) ++skating_frames_;
  return s;
}

nlohmann::json SimulationLocomotion::stats() const {
  nlohmann::json out;
  const anim::CrowdAnimator& crowd = *crowd_;
  const std::int64_t frames = tally_.frames;
  out["characters"] = crowd.count();
  out["joints"] = crowd.joint_count();
  out["frames"] = frames;
  out["frame_ms"] = tally_.frame_ms_json();
  // The stage's kernels (anim.*): milliseconds per frame.
  nlohmann::json kernels = nlohmann::json::object();
  for (const KernelStat& k : KernelTimings::global().stats())
    if (k.name.rfind("anim.", 0) == 0)
      kernels[k.name] = {{"count", k.count}, {"total_ms", k.total_ms}, {"median_ms", k.median_ms},
                         {"ms_per_frame", frames > 0 ? k.total_ms / static_cast<double>(frames) : 0.0}};
  out["kernels"] = kernels;
  out["joints_synthesised_per_character"] =
      tally_.character_frames() > 0.0 ? static_cast<double>(tally_.joints_synthesised) / tally_.character_frames() : 0.0;
  if (nlohmann::json lod = tally_.lod_json(crowd, thresholds_); !lod.is_null()) out["lod"] = lod;
  if (nlohmann::json cache = tally_.cache_json(crowd); !cache.is_null()) out["cache"] = cache;
  ThinnedSample slides = slides_cm_;
  if (skating_frames_ > 0)
    for (const double slide : crowd.foot_skating().slides_cm) slides.push(slide);
  // The p95 of the kept slides; mean, max and count over every contact.
  const motion::FootSkatingReport kept = motion::summarise_foot_skating(slides.values());
  const bool any = slides.count() > 0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out["foot_skating_cm"] = {{"mean", any ? slides.mean() : nan},
                            {"p95", kept.p95_cm},
                            {"max", any ? slides.max() : nan},
                            {"contacts", slides.count()},
                            {"agents", std::min(crowd.count(), tracked_)}};
  return out;
}

LocomotionStage::LocomotionStage(const sim::Simulation& sim, LocomotionStageOptions options)
    : options_(std::move(options)), locomotion_(sim, options_.locomotion) {
  if (!(options_.fps >= 0.0) || !std::isfinite(options_.fps)) throw Error("must be >= 0", at_field("locomotion.fps"));
}

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
