// Angle constants and helpers shared by every family, host and device.
//
// Angles are in radians. The float helpers are THRONG_HOST_DEVICE (kernels
// use them); the double ones are host code (clip analysis and preparation).
#pragma once

#include <cmath>
#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/config.h"

namespace throng {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr float kPiF = 3.14159265358979323846f;
inline constexpr float kTwoPiF = 6.28318530717958647692f;
inline constexpr float kHalfPi = 1.57079632679489661923f;

// An angle into [-pi, pi): a - 2 pi floor((a + pi) / (2 pi)), in float.
THRONG_HOST_DEVICE inline float wrap_angle(float a) { return a - kTwoPiF * glm::floor((a + 0.5f * kTwoPiF) / kTwoPiF); }

// An angle into [-pi, pi) by fmod, in double (host): unwrapping headings
// frame by frame (h_i = h_{i-1} + wrap_angle(h - h_{i-1})).
inline double wrap_angle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a < 0) a += 2.0 * kPi;
  return a - kPi;
}

// The rotation by `yaw` radians about +Y (the world's up), in double (host).
inline glm::dquat yaw_rotation(double yaw) { return glm::angleAxis(yaw, glm::dvec3(0, 1, 0)); }

}  // namespace throng
