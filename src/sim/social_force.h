// The social force model (Helbing, Farkas, Vicsek 2000, "Simulating
// dynamical features of escape panic", Nature 407, 487-490), with the
// driving term of Helbing, Molnar 1995 (Phys. Rev. E 51, 4282). A
// second-order model: each agent of mass m feels
//
//   m dv_i/dt = m (v0 e0 - v_i) / tau
//             + sum_j [A w(phi_ij) exp((r_ij - d_ij) / B) + k g(r_ij - d_ij)] n_ij
//                     + kappa g(r_ij - d_ij) dv^t_ji t_ij
//             + sum_W [A exp((r_i - d_iW) / B) + k g(r_i - d_iW)] n_iW
//                     - kappa g(r_i - d_iW) (v_i . t_iW) t_iW
//
//   r_ij = r_i + r_j, d_ij = |x_i - x_j|, n_ij = (x_i - x_j) / d_ij (from j
//   to i), t_ij = (-n_ij.y, n_ij.x), dv^t_ji = (v_j - v_i) . t_ij, g(x) =
//   max(x, 0): the body force and sliding friction act only in contact.
//   Walls and circles: their nearest point q (d_iW = |x_i - q|), static.
//
// Anisotropy (Helbing, Johansson 2009): the social term of neighbour j is
// weighted by w(phi) = lambda + (1 - lambda) (1 + cos phi) / 2, phi the
// angle between the agent's walking direction and the direction to j: a
// walker shies from those ahead, hardly from those behind. lambda = 1 is
// the 2000 paper's isotropic force; walls are felt isotropically.
//
// Keep right (this engine's addition, as ttc.h): the forces are symmetric
// under mirroring, so two agents exactly head-on push each other straight
// back and stand nose to nose for ever (the papers add noise). While a pair
// approaches, the social term gets side_bias |f| (1 - m / r_ij) more to the
// right of the relative velocity v_i - v_j, m the distance the centres
// would pass at: largest dead centre, none at a graze. Each of the two
// agents keeps to its own right, and the same bits come out for any thread
// count (no random draw). side_bias = 0 is the paper's force.
//
// Integration: the body force is stiff (sqrt(k / m) = 39 /s with the
// published k and m, a period of 0.16 s) and the friction rate kappa g / m
// reaches hundreds per second in a crush, so explicit Euler at the
// simulation's dt = 0.1 s explodes. The sense stage therefore integrates
// the step itself in substeps of at most max_substep (symplectic Euler: v
// first, then p, stable for sqrt(k/m) h < 2), against the neighbours sensed
// once at the start of the step moving on at their velocities. Friction is
// backward Euler in the slip (sf_contact_force), stable at any overlap, and
// no substep leaves the agent faster than max_speed. The stage returns the step's mean velocity (displacement / dt):
// the move stage keeps velocity as displacement / dt anyway.
//
// Host+device; the kernels (simulation_kernels.cpp) feed neighbours from the
// 3x3 bins (sense.h, social_force_velocity), tests call these functions on
// hand-computed cases.
#pragma once

#include <cmath>

#include "sim/geometry.h"
#include "sim/scenario.h"

namespace throng::sim {

// The anisotropy weight w(phi) for walking direction `heading` (unit, or
// zero when standing: then isotropic) and n = the unit vector from j to i
// (so the direction to j is -n).
THRONG_HOST_DEVICE inline float sf_anisotropy_weight(glm::vec2 heading, glm::vec2 n, float lambda) {
  if (length2(heading) == 0.0f) return 1.0f;
  const float cos_phi = -dot2(heading, n);
  return lambda + (1.0f - lambda) * 0.5f * (1.0f + cos_phi);
}

// The contact force of a body of the other side: k g n + kappa' g dv^t t
// (N), for n the unit vector towards the agent, `overlap` = g(r - d) > 0
// and `slip` = dv^t = (v_other - v_agent) . t, t = perp_left(n). With a
// substep h > 0 the friction is backward Euler in the slip, kappa' = kappa
// / (1 + kappa g h / m): explicit friction at rate kappa g / m above 2 / h
// would reverse the slip and grow; this one only damps it (exact for one
// contact). h = 0: the paper's kappa.
THRONG_HOST_DEVICE inline glm::vec2 sf_contact_force(glm::vec2 n, float overlap, float slip, const SocialForceParams& p,
                                                     float h) {
  const float kappa = p.friction / (1.0f + p.friction * overlap * h / p.mass);
  return n * (p.body_stiffness * overlap) + perp_left(n) * (kappa * overlap * slip);
}

// The force (N) of neighbour j on agent i: x = x_i - x_j, v_i and v_j their
// velocities, R = r_i + r_j, `heading` the agent's unit walking direction
// (zero when standing), h the substep (sf_contact_force).
THRONG_HOST_DEVICE inline glm::vec2 sf_neighbour_force(glm::vec2 x, glm::vec2 vi, glm::vec2 vj, float R,
                                                       glm::vec2 heading, const SocialForceParams& p, float h) {
  const float d = length_of(x);
  if (d <= 1e-6f) return glm::vec2(0.0f);  // coincident: the contact passes separate them
  const glm::vec2 n = x * (1.0f / d);
  const float social = p.strength * sf_anisotropy_weight(heading, n, p.anisotropy) * expf((R - d) / p.range);
  glm::vec2 f = n * social;
  const glm::vec2 u = vi - vj;
  const float a = dot2(u, u), b = dot2(x, u);
  if (p.side_bias > 0.0f && b < 0.0f && a > 1e-12f) {
    // Keep right: the closer to dead centre (miss distance m of 0, of R),
    // the more of the social term also pushes right of the relative velocity.
    const float miss = sqrtf(fmaxf(d * d - b * b / a, 0.0f));
    const float centred = 1.0f - fminf(miss / R, 1.0f);
    f += glm::vec2(u.y, -u.x) * (p.side_bias * centred * social / sqrtf(a));
  }
  if (d < R) f += sf_contact_force(n, R - d, dot2(vj - vi, perp_left(n)), p, h);
  return f;
}

// The force (N) of the wall or circle point q on the agent at x_i with
// velocity v and radius r, h the substep (sf_contact_force).
THRONG_HOST_DEVICE inline glm::vec2 sf_wall_force(glm::vec2 xi, glm::vec2 v, float r, glm::vec2 q,
                                                  const SocialForceParams& p, float h) {
  const glm::vec2 x = xi - q;
  const float d = length_of(x);
  if (d <= 1e-6f) return glm::vec2(0.0f);  // centre on the wall: the move stage's projection decides the side
  const glm::vec2 n = x * (1.0f / d);
  glm::vec2 f = n * (p.strength * expf((r - d) / p.range));
  if (d < r) f += sf_contact_force(n, r - d, -dot2(v, perp_left(n)), p, h);
  return f;
}

// The driving force m (v0 e0 - v) / tau (N).
THRONG_HOST_DEVICE inline glm::vec2 sf_driving_force(glm::vec2 v, float pref_speed, glm::vec2 e0,
                                                     const SocialForceParams& p) {
  return (e0 * pref_speed - v) * (p.mass / p.relaxation_time);
}

// How many substeps of at most max_substep make up a step of dt.
THRONG_HOST_DEVICE inline int sf_substeps(float dt, const SocialForceParams& p) {
  const float n = ceilf(dt / p.max_substep - 1e-4f);
  return n < 1.0f ? 1 : static_cast<int>(n);
}

}  // namespace throng::sim
