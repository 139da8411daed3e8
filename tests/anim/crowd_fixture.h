// Shared by the locomotion tests (tests/anim and the CUDA comparison in
// tests/gpu): the default blend space built once, a random crowd of
// characters (positions on the ground within +-extent m, yaws, scales
// 0.85-1.15, phases and speeds 0-5 m/s) and the camera they are seen from.
#pragma once

#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <glm/vec3.hpp>

#include "core/camera.h"
#include "core/config.h"
#include "motion/locomotion.h"

namespace throng::anim::testing {

inline constexpr float kPi = std::numbers::pi_v<float>;

// Built once per test program: the space's tables take a while.
inline const motion::BlendSpace1D& default_space() {
  static const motion::BlendSpace1D s = motion::make_default_blend_space();
  return s;
}

struct Crowd {
  std::vector<glm::vec3> positions;
  std::vector<float> yaws, scales, phases, speeds;
};

inline Crowd random_crowd(Index n, std::uint32_t seed, float extent = 40.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Crowd c;
  for (Index i = 0; i < n; ++i) {
    c.positions.emplace_back(extent * (2.0f * u(rng) - 1.0f), 0.0f, extent * (2.0f * u(rng) - 1.0f));
    c.yaws.push_back(2.0f * kPi * u(rng) - kPi);
    c.scales.push_back(0.85f + 0.3f * u(rng));
    c.phases.push_back(u(rng));
    c.speeds.push_back(5.0f * u(rng));
  }
  return c;
}

// 12 m up, 45 m back, looking at the crowd's centre, 1280x720.
inline Camera crowd_camera() {
  Camera cam;
  cam.position = glm::vec3(0.0f, 12.0f, 45.0f);
  cam.target = glm::vec3(0.0f, 0.0f, 0.0f);
  cam.width = 1280;
  cam.height = 720;
  return cam;
}

}  // namespace throng::anim::testing
