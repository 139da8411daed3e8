#include "app/formation.h"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "core/math.h"
#include "io/motion_set.h"

namespace throng::app {

namespace fs = std::filesystem;

io::AnimateSpec load_animate_spec(const std::string& what, fs::path& folder) {
  std::error_code ec;
  if (fs::is_regular_file(what, ec)) {
    folder = fs::path(what).parent_path();
    return io::read_animate_spec(what);
  }
  const std::vector<std::string> names = io::builtin_animate_specs();
  if (std::find(names.begin(), names.end(), what) != names.end()) return io::builtin_animate_spec(what);
  throw Error(fmt::format("no such file or built-in scenario '{}' (built-in: {})", what, fmt::join(names, ", ")),
              at_field("scenario"));
}

Formation make_formation(const io::AnimateSpec& s) {
  Formation f;
  const auto n = static_cast<std::size_t>(s.characters);
  if (s.shape == io::AnimateSpec::Shape::Circle) {
    // Rings outward from `radius`, each as full as the spacing allows; the
    // last ring holds the rest, evenly spread.
    std::size_t placed = 0;
    for (int ring = 0; placed < n; ++ring) {
      const float r = s.radius + static_cast<float>(ring) * s.ring_spacing;
      const auto capacity = std::max<std::size_t>(1, static_cast<std::size_t>(2.0f * kPiF * r / s.spacing));
      const std::size_t here = std::min(capacity, n - placed);
      for (std::size_t k = 0; k < here; ++k) {
        const float a =
            2.0f * kPiF * (static_cast<float>(k) + 0.5f * static_cast<float>(ring % 2)) / static_cast<float>(here);
        // Counter-clockwise seen from above: angle a at (cos a, -sin a) in XZ,
        // walking along (-sin a, -cos a), a left turn of curvature 1 / r.
        f.positions.emplace_back(r * std::cos(a), 0.0f, -r * std::sin(a));
        f.yaws.push_back(s.clockwise ? a : a + kPiF);
        f.curvatures.push_back(s.clockwise ? -1.0f / r : 1.0f / r);
        f.rings.push_back(r);
      }
      placed += here;
      f.extent = r;
    }
  } else {
    const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
    const float half = 0.5f * s.spacing * static_cast<float>(side - 1);
    for (std::size_t i = 0; i < n; ++i) {
      f.positions.emplace_back(s.spacing * static_cast<float>(i % side) - half, 0.0f,
                               s.spacing * static_cast<float>(i / side) - half);
      f.yaws.push_back(0.0f);
      f.curvatures.push_back(0.0f);
      f.rings.push_back(0.0f);
    }
    f.extent = half * std::numbers::sqrt2_v<float>;
  }
  return f;
}

namespace {

anim::CrowdAnimatorConfig animator_config(const io::AnimateSpec& spec) {
  anim::CrowdAnimatorConfig config;
  config.hold_until_cycle_end = spec.paper_mode;
  config.lod = spec.lod;
  config.lod_thresholds = spec.lod_thresholds;
  config.cache = spec.cache;
  config.cache_config.bucket_width = spec.bucket_width;
  config.cache_config.capacity_bytes =
      static_cast<std::size_t>(static_cast<double>(spec.cache_capacity_mb) * 1024.0 * 1024.0);
  return config;
}

}  // namespace

FormationCrowd::FormationCrowd(io::AnimateSpec spec, const fs::path& folder)
    : spec_(std::move(spec)),
      space_(io::load_motion_set(spec_.motion, folder, "motion")),
      formation_(make_formation(spec_)),
      rng_(spec_.seed) {
  const Index n = spec_.characters;
  crowd_ = std::make_unique<anim::CrowdAnimator>(space_, n, animator_config(spec_));
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> scales(static_cast<std::size_t>(n)), phases(static_cast<std::size_t>(n));
  for (float& x : scales) x = spec_.scale_min + (spec_.scale_max - spec_.scale_min) * unit(rng_);
  for (float& x : phases) x = unit(rng_);
  speeds_.resize(static_cast<std::size_t>(n));
  crowd_->place(formation_.positions, formation_.yaws, scales, phases);
  crowd_->set_curvatures(formation_.curvatures);
  draw_speeds();
  next_draw_ = spec_.change_every_s;
}

void FormationCrowd::draw_speeds() {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (float& v : speeds_) v = spec_.speed_min + (spec_.speed_max - spec_.speed_min) * unit(rng_);
  crowd_->set_speeds(speeds_);
}

const anim::FrameStats& FormationCrowd::advance(float dt, const Camera* camera) {
  // Half a frame of slack: at a fixed rate the redraw falls on the frame
  // whose start time is a multiple of change_every_s.
  if (spec_.change_every_s > 0.0f && time_ >= next_draw_ - 0.5 * static_cast<double>(dt)) {
    draw_speeds();
    next_draw_ += spec_.change_every_s;
  }
  const anim::FrameStats& stats = crowd_->animate({dt, camera, true});
  time_ += static_cast<double>(dt);
  return stats;
}

}  // namespace throng::app
