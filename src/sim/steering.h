// The paper's three steering forces, in priority order, as plain host+device
// functions of one agent and one candidate (an obstacle or a neighbour). The
// kernels (simulation_kernels.cpp) loop over the candidates found in the 3x3 bins;
// tests call these directly on hand-computed cases.
//
// Forces are accelerations (m/s^2). Priority: obstacle avoidance, when
// non-zero, suppresses the other two; agent avoidance, when non-zero,
// suppresses path following.
#pragma once

#include <cmath>

#include "sim/geometry.h"
#include "sim/scenario.h"

namespace throng::sim {

// Direction of travel: the velocity, or the heading when (nearly) at rest.
THRONG_HOST_DEVICE inline glm::vec2 forward_of(glm::vec2 velocity, float heading) {
  return normalize_or(velocity, glm::vec2(cosf(heading), sinf(heading)));
}

// ---- 1. obstacle avoidance -----------------------------------------------------

// The rectangle swept ahead of the agent: from its centre along `forward`,
// `length` = radius + pred_time * speed, half-width = radius + probe_margin.
struct Probe {
  glm::vec2 origin{0.0f};
  glm::vec2 forward{1.0f, 0.0f};
  float length = 0.0f;
  float half_width = 0.0f;
  float radius = 0.0f;  // the agent's; half_width - radius is the margin band on each side
};
THRONG_HOST_DEVICE inline Probe make_probe(glm::vec2 p, glm::vec2 v, float heading, float radius,
                                           const ModelParams& m) {
  return {p, forward_of(v, heading), radius + m.pred_time * length_of(v), radius + m.probe_margin, radius};
}

// The nearest point of an obstacle inside the probe: `distance` along the
// probe (0 when the obstacle reaches beside the agent), the point, and the
// obstacle's surface normal there (pointing to the agent's side).
struct ProbeHit {
  bool hit = false;
  float distance = INFINITY;
  glm::vec2 point{0.0f};
  glm::vec2 normal{0.0f};
};

THRONG_HOST_DEVICE inline ProbeHit probe_segment(const Probe& pr, glm::vec2 a, glm::vec2 b) {
  ProbeHit h;
  const glm::vec2 f = pr.forward, l = perp_left(pr.forward);
  const float ax = dot2(a - pr.origin, f), ay = dot2(a - pr.origin, l);
  const float bx = dot2(b - pr.origin, f), by = dot2(b - pr.origin, l);
  float lo = 0.0f, hi = 1.0f;
  // Clip the parameter range to |y| <= half_width, then to 0 <= x <= length.
  auto clip = [&](float s0, float s1, float min_v, float max_v) {
    const float ds = s1 - s0;
    if (fabsf(ds) < 1e-9f) {
      if (s0 < min_v || s0 > max_v) lo = 1.0f, hi = 0.0f;
      return;
    }
    float t1 = (min_v - s0) / ds, t2 = (max_v - s0) / ds;
    if (t1 > t2) {
      const float t = t1;
      t1 = t2;
      t2 = t;
    }
    lo = lo > t1 ? lo : t1;
    hi = hi < t2 ? hi : t2;
  };
  clip(ay, by, -pr.half_width, pr.half_width);
  if (lo > hi) return h;
  clip(ax, bx, 0.0f, pr.length);
  if (lo > hi) return h;
  const float x0 = ax + lo * (bx - ax), y0 = ay + lo * (by - ay);
  const float x1 = ax + hi * (bx - ax), y1 = ay + hi * (by - ay);
  float x, y;
  if (fabsf(x0 - x1) <= 1e-6f) {
    // Edge across the probe: take its point nearest the centre line.
    x = x0 < x1 ? x0 : x1;
    if ((y0 <= 0.0f && y1 >= 0.0f) || (y0 >= 0.0f && y1 <= 0.0f)) {
      const float t = fabsf(y1 - y0) > 1e-9f ? y0 / (y0 - y1) : 0.0f;
      x = x0 + t * (x1 - x0);
      y = 0.0f;
    } else {
      y = fabsf(y0) < fabsf(y1) ? y0 : y1;
    }
  } else if (x0 < x1) {
    x = x0, y = y0;
  } else {
    x = x1, y = y1;
  }
  h.hit = true;
  h.distance = x;
  h.point = pr.origin + f * x + l * y;
  glm::vec2 n = normalize_or(perp_left(b - a), glm::vec2(0.0f));
  if (dot2(n, pr.origin - a) < 0.0f) n = -n;
  h.normal = n;
  return h;
}

THRONG_HOST_DEVICE inline ProbeHit probe_circle(const Probe& pr, glm::vec2 c, float rho) {
  ProbeHit h;
  const glm::vec2 f = pr.forward, l = perp_left(pr.forward);
  const float cx = dot2(c - pr.origin, f), cy = dot2(c - pr.origin, l);
  float x, y, reach;  // nearest x inside the band at lateral y; reach = the far x
  if (fabsf(cy) <= pr.half_width) {
    x = cx - rho;
    y = cy;
    reach = cx + rho;
  } else {
    const float e = fabsf(cy) - pr.half_width;
    if (e >= rho) return h;
    const float half = sqrtf(rho * rho - e * e);
    x = cx - half;
    y = cy > 0.0f ? pr.half_width : -pr.half_width;
    reach = cx + half;
  }
  if (x > pr.length || reach < 0.0f) return h;
  h.hit = true;
  if (x < 0.0f) {
    // The disc reaches beside the agent: distance 0, nearest point of the circle.
    h.distance = 0.0f;
    h.normal = normalize_or(pr.origin - c, -f);
    h.point = c - h.normal * rho;
    return h;
  }
  h.distance = x;
  h.point = pr.origin + f * x + l * y;
  h.normal = normalize_or(h.point - c, -f);
  return h;
}

// Nearest hit gives the force: strength max_force * (1 - distance/length),
// weighted by how directly the agent approaches the surface (-normal .
// forward; surfaces it moves along or away from are no threat). Direction:
// repulsion (from the hit point to the agent) plus a lateral pull along the
// surface (towards the side the normal leans to; to the right when head-on).
// A hit only in the margin band (at least a radius to the side: the agent's
// disc would pass it) gives a sideways nudge away from it instead, so an
// agent sliding along a wall past a corner keeps going rather than turning
// back and forth at the corner.
THRONG_HOST_DEVICE inline glm::vec2 obstacle_force(const Probe& pr, const ProbeHit& h, float max_force) {
  if (!h.hit || pr.length <= 0.0f) return glm::vec2(0.0f);
  const float approach = -dot2(h.normal, pr.forward);
  if (approach <= 1e-4f) return glm::vec2(0.0f);
  const float d = h.distance < 0.0f ? 0.0f : h.distance;
  const float strength = max_force * (1.0f - d / pr.length) * approach;
  if (strength <= 0.0f) return glm::vec2(0.0f);
  const glm::vec2 l = perp_left(pr.forward);
  const float lateral = dot2(h.point - pr.origin, l);
  if (h.distance > 0.0f && fabsf(lateral) >= pr.radius - 1e-3f) return (lateral > 0.0f ? -l : l) * strength;
  const glm::vec2 repulsion = normalize_or(pr.origin - h.point, h.normal);
  const float lean = dot2(h.normal, l);
  const glm::vec2 pull = fabsf(lean) < 1e-3f ? -l : (lean > 0.0f ? l : -l);
  return normalize_or(repulsion + pull, pull) * strength;
}

// ---- 2. agent collision avoidance ---------------------------------------------

// Closest approach of a neighbour within pred_time, assuming both keep their
// velocities: time, predicted relative position (other - self) and the sum
// of observation radii. A threat when the neighbour is ahead (in the half
// plane of `forward`: one coming from behind is the overtaker's to avoid),
// approaching, and predicted closer than `reach`.
struct Threat {
  bool found = false;
  float time = INFINITY;
  glm::vec2 separation{0.0f};
  float reach = 0.0f;
};

THRONG_HOST_DEVICE inline Threat predict_threat(glm::vec2 p, glm::vec2 v, glm::vec2 forward, float observe_r,
                                                glm::vec2 q, glm::vec2 w, float other_observe_r, float pred_time) {
  Threat t;
  const glm::vec2 dp = q - p, dv = w - v;
  if (dot2(dp, forward) <= 0.0f) return t;
  const float closing = dot2(dp, dv);
  const float dv2 = dot2(dv, dv);
  if (!(closing < 0.0f) || dv2 <= 1e-12f) return t;
  float tc = -closing / dv2;
  tc = tc > pred_time ? pred_time : tc;
  t.separation = dp + dv * tc;
  t.reach = observe_r + other_observe_r;
  if (length2(t.separation) >= t.reach * t.reach) return t;
  t.found = true;
  t.time = tc;
  return t;
}

// The most urgent threat: earliest, then closest.
THRONG_HOST_DEVICE inline bool more_urgent(const Threat& a, const Threat& b) {
  if (!a.found) return false;
  if (!b.found) return true;
  if (a.time != b.time) return a.time < b.time;
  return length2(a.separation) < length2(b.separation);
}

// Lateral force away from where the neighbour will be: perpendicular to the
// agent's forward direction, strength max_force * (1 - |separation| / reach).
// Head-on (no lateral offset), agents keep right.
THRONG_HOST_DEVICE inline glm::vec2 avoidance_force(glm::vec2 forward, const Threat& t, float max_force) {
  if (!t.found || t.reach <= 0.0f) return glm::vec2(0.0f);
  const float strength = max_force * (1.0f - length_of(t.separation) / t.reach);
  if (strength <= 0.0f) return glm::vec2(0.0f);
  const glm::vec2 l = perp_left(forward);
  const float side = dot2(t.separation, l);
  const glm::vec2 away = side > 1e-3f ? -l : (side < -1e-3f ? l : -l);
  return away * strength;
}

// ---- 3. path following ------------------------------------------------------------

// Follows the leg from `start` to `goal` inside a lane: predicts the position
// pred_time ahead, projects it onto the leg and, when it lies outside the
// lane, seeks the projection moved one look-ahead further along the leg;
// inside the lane it walks along the leg. Within one look-ahead of the goal
// (or once past the end of the leg) it seeks the goal, slowing over the
// last pref_speed * relaxation_time metres.
// Force = (desired velocity - velocity) / relaxation_time, at most max_force.
THRONG_HOST_DEVICE inline glm::vec2 path_following_force(glm::vec2 p, glm::vec2 v, float pref_speed, glm::vec2 start,
                                                         glm::vec2 goal, const ModelParams& m) {
  const glm::vec2 to_goal = goal - p;
  const float dist = length_of(to_goal);
  const float lookahead = fmaxf(pref_speed * m.pred_time, m.lane_half_width);
  glm::vec2 desired;
  // Near the goal, or past the end of the leg (it missed the arrival disc
  // while avoiding someone): seek the goal itself.
  const bool past_end = dot2(p - goal, goal - start) > 0.0f;
  if (dist <= lookahead || past_end) {
    const float slow = pref_speed * m.relaxation_time;
    const float speed = slow > 0.0f && dist < slow ? pref_speed * dist / slow : pref_speed;
    desired = normalize_or(to_goal, glm::vec2(0.0f)) * speed;
  } else {
    const glm::vec2 dir = normalize_or(goal - start, to_goal * (1.0f / dist));
    const glm::vec2 predicted = p + v * m.pred_time;
    const glm::vec2 c = closest_point_on_segment(predicted, start, goal);
    if (length_of(predicted - c) > m.lane_half_width) {
      const float ahead = fminf(lookahead, length_of(goal - c));
      desired = normalize_or(c + dir * ahead - p, dir) * pref_speed;
    } else {
      desired = dir * pref_speed;
    }
  }
  return clamp_length((desired - v) * (1.0f / m.relaxation_time), m.max_force);
}

// ---- priority ----------------------------------------------------------------------

// Whether a force takes priority over the ones below it: it is not zero.
// The kernels apply the rule stage by stage (a lower force is computed only
// when no higher one applies); prioritized() is the whole rule at once.
THRONG_HOST_DEVICE inline bool force_applies(glm::vec2 force) { return length2(force) > 1e-12f; }

THRONG_HOST_DEVICE inline glm::vec2 prioritized(glm::vec2 obstacle, glm::vec2 agents, glm::vec2 path) {
  if (force_applies(obstacle)) return obstacle;
  if (force_applies(agents)) return agents;
  return path;
}

}  // namespace throng::sim
