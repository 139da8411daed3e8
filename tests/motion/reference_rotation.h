// Independent references for rotation code under test, in double.
#pragma once

#include <cmath>
#include <glm/gtc/quaternion.hpp>

namespace throng::test {

// SLERP through the exponential map: q0 (q0^-1 q1)^t, choosing the sign of
// q1 that makes the relative rotation the shorter one.
inline glm::dquat reference_slerp(glm::dquat q0, glm::dquat q1, double t) {
  if (glm::dot(q0, q1) < 0.0) q1 = -q1;
  const glm::dquat r = glm::inverse(q0) * q1;
  const glm::dvec3 v(r.x, r.y, r.z);
  const double s = glm::length(v);
  if (s < 1e-15) return q0;
  const double half = std::atan2(s, r.w) * t;  // r.w >= 0: the half angle is in [0, pi/2]
  const glm::dvec3 axis = v / s;
  return q0 * glm::dquat(std::cos(half), axis.x * std::sin(half), axis.y * std::sin(half), axis.z * std::sin(half));
}

// The angle in degrees of the rotation from a to b (unit or not), by atan2:
// steady near zero, where acos of their dot product is not. The tests' own
// twin of anim::rotation_angle_deg, for double inputs (a reference slerp's)
// and for the motion tests, which do not link anim.
inline double rotation_between_deg(const glm::dquat& a, const glm::dquat& b) {
  const glm::dquat r = glm::inverse(a) * b;
  return 2.0 * std::atan2(std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z), std::abs(r.w)) *
         (180.0 / 3.14159265358979323846);
}

}  // namespace throng::test
