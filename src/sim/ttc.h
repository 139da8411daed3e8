// The anticipatory time-to-collision power-law model (Karamouzas, Skinner,
// Guy 2014, "Universal power law governing pedestrian interactions", Phys.
// Rev. Lett. 113, 238701). A second-order model: each agent feels
//
//   F_i = (v_pref e0 - v_i) / xi + sum_j F_ij + sum_w F_iw,  |F_i| <= max_acceleration
//
// and integrates v += F dt, |v| <= max_speed, p += v dt (the steer stage).
// Two discs at x_i, x_j with velocities v_i, v_j and radius sum R collide,
// at constant velocities, after the smallest positive root tau of
// |x + v t| = R (x = x_i - x_j, v = v_i - v_j):
//
//   a = v.v, b = x.v, c = x.x - R^2, discr = b^2 - a c,
//   tau = (-b - sqrt(discr)) / a      (a collision needs discr > 0, tau > 0)
//
// The pair's interaction energy is E(tau) = k tau^-2 exp(-tau / tau0) and
// the force its gradient along the time to collision, F_ij = -(dE/dtau)
// grad_x tau, in closed form
//
//   F_ij = -k exp(-tau / tau0) (v - (a x - b v) / sqrt(discr)) / (a tau^2) (2 / tau + 1 / tau0).
//
// (The paper's code writes b = -x.v and tau = (b - sqrt(discr)) / a; the
// same root.) No force when the paths do not meet (discr <= 0) or the pair
// moves apart (tau <= 0). Already overlapping (c < 0) the energy is
// unbounded: this engine pushes the pair apart along x with the largest
// acceleration while they still approach (b < 0), none once they separate;
// the move stage's contact projection removes the overlap itself.
//
// Keep right (this engine's addition): the force is symmetric under
// mirroring, so two agents exactly head-on, or crossing at 90 degrees at
// the same speed, brake face to face for ever (the paper's simulations add
// noise). F_ij gets side_bias |F_ij| (1 - m / R) more to the right of the
// relative velocity v, m the distance the centres would pass at: largest
// dead centre, none at a graze. F_ji = -F_ij still holds, every agent keeps
// to its right, and the same bits come out for any thread count (no random
// draw). side_bias = 0 is the paper's force.
//
// Walls and circles: the nearest point q of each one near the agent is a
// static disc of radius 0 (x = x_i - q, v = v_i, R = r_i), a simplification
// of the paper's segment time to collision: a wall the agent walks along
// (b = 0) exerts nothing, one it walks into repels it like a standing
// neighbour.
//
// Host+device; the kernels (simulation_kernels.cpp) feed neighbours from the
// 3x3 bins (sense.h, ttc_force), tests call these functions on hand-computed
// cases.
#pragma once

#include <cmath>

#include "sim/geometry.h"
#include "sim/scenario.h"

namespace throng::sim {

// The time to collision of two discs with radius sum R, relative position
// x = x_i - x_j and relative velocity v = v_i - v_j at constant velocities:
// +inf when they never touch or move apart, 0 when they overlap now and
// approach.
THRONG_HOST_DEVICE inline float ttc_time_to_collision(glm::vec2 x, glm::vec2 v, float R) {
  const float a = dot2(v, v), b = dot2(x, v), c = dot2(x, x) - R * R;
  if (c < 0.0f) return b < 0.0f ? 0.0f : INFINITY;
  if (a <= 1e-12f || b >= 0.0f) return INFINITY;
  const float discr = b * b - a * c;
  if (discr <= 0.0f) return INFINITY;
  const float tau = (-b - sqrtf(discr)) / a;
  return tau > 0.0f ? tau : INFINITY;
}

// F_ij: the avoidance acceleration of disc i from disc j (same x, v, R as
// above), at most p.max_acceleration in length (overlapping and
// approaching: p.max_acceleration along x).
THRONG_HOST_DEVICE inline glm::vec2 ttc_avoidance(glm::vec2 x, glm::vec2 v, float R, const TtcParams& p) {
  const float a = dot2(v, v), b = dot2(x, v), c = dot2(x, x) - R * R;
  if (c < 0.0f) {
    const float d = length_of(x);
    return b < 0.0f && d > 1e-6f ? x * (p.max_acceleration / d) : glm::vec2(0.0f);
  }
  if (a <= 1e-12f || b >= 0.0f) return glm::vec2(0.0f);
  const float discr = b * b - a * c;
  if (discr <= 1e-12f) return glm::vec2(0.0f);
  const float s = sqrtf(discr);
  // tau below 1 ms counts as 1 ms: the force stays finite (and is clamped).
  const float tau = fmaxf((-b - s) / a, 1e-3f);
  const float scale =
      -p.strength * expf(-tau / p.time_horizon) * (2.0f / tau + 1.0f / p.time_horizon) / (a * tau * tau);
  glm::vec2 f = (v - (x * a - v * b) * (1.0f / s)) * scale;
  if (p.side_bias > 0.0f) {
    // Keep right: the closer to dead centre (miss distance m of 0, of R),
    // the more of |f| also pushes to the right of the relative velocity.
    const float miss = sqrtf(fmaxf(dot2(x, x) - b * b / a, 0.0f));
    const float centred = 1.0f - fminf(miss / R, 1.0f);
    const glm::vec2 right = glm::vec2(v.y, -v.x) * (1.0f / sqrtf(a));
    f += right * (p.side_bias * centred * length_of(f));
  }
  return clamp_length(f, p.max_acceleration);
}

// The goal term (v_pref e0 - v) / xi.
THRONG_HOST_DEVICE inline glm::vec2 ttc_goal_force(glm::vec2 v, float pref_speed, glm::vec2 e0, const TtcParams& p) {
  return (e0 * pref_speed - v) * (1.0f / p.relaxation_time);
}

}  // namespace throng::sim
