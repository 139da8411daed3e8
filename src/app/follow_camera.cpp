#include "app/follow_camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/ground.h"

namespace throng::app {

FollowCamera::FollowCamera(const Camera& view, double ease_seconds, float min_character_px)
    : view_(view), ease_seconds_(ease_seconds), min_character_px_(min_character_px) {
  if (!(ease_seconds > 0.0) || !std::isfinite(ease_seconds))
    throw Error("must be positive seconds", at_field("camera.ease"));
  if (!(min_character_px >= 0.0f) || !std::isfinite(min_character_px))
    throw Error("must be a finite number of pixels >= 0", at_field("camera.min_character_px"));
  const glm::vec3 d = view.position - view.target;
  const float length = glm::length(d);
  if (!(length > 0.0f) || !std::isfinite(length))
    throw Error("the camera's position equals its target", at_field("camera"));
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
    if (foot.z <= 0.0f || head.z <= 0.0f || foot.x < 0.0f || foot.x >= v.width || foot.y < 0.0f || foot.y >= v.height)
      continue;
    heights.push_back(std::fabs(foot.y - head.y));
  }
  if (heights.empty()) return 0.0f;
  const auto mid = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2);
  std::nth_element(heights.begin(), mid, heights.end());
  return *mid;
}

Index FollowCamera::focus_agent(const std::vector<glm::vec2>& positions, const std::vector<std::uint8_t>& flags,
                                glm::vec2 middle) {
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
    const float half_fov =
        0.5f * std::min(view_.fov_y, 2.0f * std::atan(std::tan(0.5f * view_.fov_y) * aspect_ratio(view_)));
    float distance = std::max(reach / std::sin(half_fov), 8.0f);
    glm::vec2 middle = 0.5f * (box.min + box.max);
    // Farther than this, a character is under min_character_px tall: stay
    // there and aim at an agent near the middle (a ring's middle is empty).
    const float farthest =
        std::max(focal_length_pixels(view_) * kCharacterHeight / std::max(min_character_px_, 1e-3f), 8.0f);
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

}  // namespace throng::app
