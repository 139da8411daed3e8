// The sense stage for one agent: candidates from the 3x3 bins, reduced to
// what the steering forces need (the nearest obstacle hit, the most urgent
// neighbour threat), plus the projections of the move stage. Host+device.
#pragma once

#include "sim/collision_free_speed.h"
#include "sim/crowd.h"
#include "sim/grid.h"
#include "sim/neighbours.h"
#include "sim/social_force.h"
#include "sim/steering.h"
#include "sim/ttc.h"
#include "sim/world.h"

namespace throng::sim {

// Nearest probe hit whose force is non-zero, and that force.
struct ObstacleSense {
  ProbeHit hit;
  glm::vec2 force{0.0f};
};
THRONG_HOST_DEVICE inline ObstacleSense sense_obstacles(const WorldView& w, const Probe& pr, float max_force) {
  ObstacleSense best;
  auto consider = [&](const ProbeHit& h) {
    if (!h.hit || h.distance >= best.hit.distance) return;
    const glm::vec2 f = obstacle_force(pr, h, max_force);
    if (length2(f) <= 0.0f) return;
    best.hit = h;
    best.force = f;
  };
  for_each_wall_near(w, pr.origin, [&](const Segment& s) { consider(probe_segment(pr, s.a, s.b)); });
  for_each_in_cell(w.circle_grid, pr.origin,
                   [&](std::int32_t k) { consider(probe_circle(pr, w.circles[k].center, w.circles[k].radius)); });
  return best;
}

// Neighbour j at q (within the query radius, active) as a threat of the
// agent at p: kept in `best` when more urgent.
THRONG_HOST_DEVICE inline void consider_neighbour(Threat& best, Index j, glm::vec2 q, glm::vec2 p, glm::vec2 v,
                                                  glm::vec2 forward, float radius, const NeighbourArrays& n,
                                                  const ModelParams& m) {
  // An agent standing at its goal is passed like a post: no personal space,
  // so arriving agents can still reach goals next to those already there.
  const float space = (n.flags[j] & kAgentStopped) != 0 ? 0.0f : m.personal_space;
  const Threat t = predict_threat(p, v, forward, radius + space, q, n.velocity[j], n.radius[j] + space, m.pred_time);
  if (more_urgent(t, best)) best = t;
}

// Most urgent threat among active neighbours within the query radius,
// visited in bin order (deterministic). Of the 3x3 cells, those wholly
// beyond the query radius or wholly behind the agent are skipped (a threat
// must be ahead); `slack` widens both tests by how far neighbours may have
// moved since they were binned (0 when positions are those binned).
THRONG_HOST_DEVICE inline Threat sense_neighbours(const GridView& bins, std::int32_t cx, std::int32_t cy, Index self,
                                                  glm::vec2 p, glm::vec2 v, glm::vec2 forward, float radius,
                                                  const NeighbourArrays& n, const ModelParams& m, float slack) {
  Threat best;
  const float query = m.query_radius();
  const float query2 = query * query;
  auto candidates = [&](const auto& fn) {
    if (bins.wrap_x == 0 && bins.wrap_y == 0) {
      // The same cells picked without a branch per cell (kept_cells_within);
      // a dense grid's kept cells of a row make one run.
      auto keep = [&](const CellBounds& c) { return cell_ahead_within_reach(c, p, forward, query2); };
      for_each_binned_candidate(bins, kept_cells_within<1>(bins, cx, cy, slack, keep, [](Index) { return true; }), n,
                                fn);
      return;
    }
    // Where an axis wraps, cell by cell (kept_cells_within would keep one
    // cell less each way along an axis of fewer than 4).
    for (std::int32_t dy = -1; dy <= 1; ++dy)
      for (std::int32_t dx = -1; dx <= 1; ++dx) {
        const CellBounds cell = cell_bounds(bins, cx + dx, cy + dy, slack);
        if (!within_reach(cell, p, query2)) continue;
        // The corner of the cell furthest along `forward`.
        const glm::vec2 front(forward.x >= 0.0f ? cell.hi.x : cell.lo.x, forward.y >= 0.0f ? cell.hi.y : cell.lo.y);
        if (dot2(front - p, forward) <= 0.0f) continue;
        const Index s = bins.find(cx + dx, cy + dy);
        if (s < 0) continue;
        for_each_binned_candidate(bins, bins.start[s], bins.count[s], n, fn);
      }
  };
  for_each_neighbour(candidates, self, n, p, query2,
                     [&](Index j, glm::vec2 q) { consider_neighbour(best, j, q, p, v, forward, radius, n, m); });
  return best;
}

// The same over every agent: the O(N^2) reference.
THRONG_HOST_DEVICE inline Threat sense_neighbours_all_pairs(Index self, glm::vec2 p, glm::vec2 v, glm::vec2 forward,
                                                            float radius, const NeighbourArrays& n,
                                                            const ModelParams& m) {
  Threat best;
  const float query2 = m.query_radius() * m.query_radius();
  auto candidates = [&](const auto& fn) { for_each_active_candidate(n, fn); };
  for_each_neighbour(candidates, self, n, p, query2,
                     [&](Index j, glm::vec2 q) { consider_neighbour(best, j, q, p, v, forward, radius, n, m); });
  return best;
}

// Calls fn(q) with the nearest point q of each wall segment and circle of
// the obstacle cell of p (everything within one cell side); a circle whose
// centre is p has none.
template <class Fn>
THRONG_HOST_DEVICE inline void for_each_wall_point(const WorldView& w, glm::vec2 p, const Fn& fn) {
  for_each_obstacle(
      w, obstacle_cell(w, p), [&](const Segment& s) { fn(closest_point_on_segment(p, s.a, s.b)); },
      [&](const Circle& k) {
        const glm::vec2 d = p - k.center;
        const float dist = length_of(d);
        if (dist > 1e-6f) fn(k.center + d * (k.radius / dist));
      });
}

// ---- collision-free speed -------------------------------------------------------

// The far look of the collision-free speed model (cfs_looks_far): A_ij of
// every neighbour beyond the query radius and within cfs_far_reach added to
// `sum`. for_each_far_candidate(e0, reach2, fn) is given the agent's goal
// direction (me.e0, the one the push tests) and the reach squared (to
// leave out cells wholly behind or beyond, and those whose agents push
// nothing for that e0: cfs_cell_walks_along) and calls fn(from,
// candidates) with the neighbour arrays to read and the candidates in them
// (a for_each_candidate, neighbours.h), in the order their pushes are
// summed. The agent itself lies within the query
// radius. The candidates are sifted first (for_each_sifted) by the tests
// of the push that need only the position: within the band and
// cfs_ahead_of, which cfs_add_anticipation tests too, so the sift drops
// only candidates that push nothing.
template <class ForEachFarCandidate>
THRONG_HOST_DEVICE inline void add_far_anticipation(const CfsAgent& me, const ModelParams& m,
                                                    const ForEachFarCandidate& for_each_far_candidate, glm::vec2& sum) {
  const float query2 = m.query_radius() * m.query_radius(), reach = cfs_far_reach(m);
  for_each_far_candidate(me.e0, reach * reach, [&](const NeighbourArrays& from, const auto& candidates) {
    auto maybe_pushes = [&](Index, glm::vec2 q) {
      const glm::vec2 d = q - me.p;
      const float d2 = length2(d);
      const bool ahead = cfs_ahead_of(me, d);
      return (d2 >= query2) & (d2 < reach * reach) & ahead;
    };
    for_each_sifted(candidates, from, me.p, maybe_pushes, [&](Index j, glm::vec2 q) {
      glm::vec2 f;
      if (cfs_far_push(me, q, from.velocity[j], from.radius[j], (from.flags[j] & kAgentStopped) != 0, m.cfs, f))
        sum += f;
    });
  });
}

// The new velocity of the agent under the collision-free speed model
// (collision_free_speed.h); `self` is its element of the neighbour arrays.
// `for_each_candidate` visits every active agent that may be a neighbour
// (for_each_binned_candidate, or all agents for the reference); those
// beyond the query radius or `self` are skipped here; the far look's
// candidates come from `for_each_far_candidate` (add_far_anticipation).
// Walls and circles come from the agent's cell of the world's halo grids
// (everything within one cell side).
template <class ForEachCandidate, class ForEachFarCandidate>
THRONG_HOST_DEVICE inline glm::vec2 collision_free_velocity(const WorldView& w, Index self, const CfsAgent& me,
                                                            float v0, float dt, const NeighbourArrays& n,
                                                            const ModelParams& m,
                                                            const ForEachCandidate& for_each_candidate,
                                                            const ForEachFarCandidate& for_each_far_candidate) {
  const CollisionFreeSpeedParams& c = m.cfs;
  const float query2 = m.query_radius() * m.query_radius();
  // Walls first: they may slide e0 along them before the pushes are summed.
  const float reach = me.radius + cfs_wall_reach(c);
  glm::vec2 e0 = me.e0, walls(0.0f);
  bool near_wall = false;
  auto wall_point = [&](glm::vec2 q) {
    const glm::vec2 d = me.p - q;
    const float d2 = length2(d);
    near_wall = near_wall || d2 < (me.radius + kCfsNearWall) * (me.radius + kCfsNearWall);
    if (d2 >= reach * reach || d2 <= 1e-12f) return;
    e0 = cfs_slide_along_wall(e0, d * (1.0f / sqrtf(d2)));
    walls += cfs_wall_push(me, q, c);
  };
  for_each_wall_point(w, me.p, wall_point);
  glm::vec2 sum = e0 + walls;
  // Only neighbours within `hold` can keep the agent below v0 (a gap of
  // v0 max(T, dt) or more allows v0 under both caps; where a neighbour will
  // be moves by at most max_speed t_a; 1 mm for rounding): the pushes' pass
  // keeps them for the gap passes, which then need not walk the bins again
  // (the same speeds, far fewer neighbours). Past kCfsHolders of them (a
  // crush) the gap passes walk the bins.
  const float hold =
      me.radius + m.max_radius() + v0 * fmaxf(c.time_gap, dt) + m.max_speed * c.anticipation_time + 1e-3f;
  std::int32_t holders[kCfsHolders];
  int held = 0, nearby = 0;
  for_each_neighbour(for_each_candidate, self, n, me.p, query2, [&](Index j, glm::vec2 q) {
    sum += cfs_neighbour_push(me, q, n.velocity[j], n.radius[j], (n.flags[j] & kAgentStopped) != 0, c);
    ++nearby;
    // Kept without a branch on the distance: written in any case, counted
    // when within `hold` (the next neighbour overwrites one not counted).
    if (held < kCfsHolders) holders[held] = static_cast<std::int32_t>(j);
    held += length2(q - me.p) < hold * hold ? 1 : 0;
  });
  if (cfs_looks_far(me, v0, nearby, c)) add_far_anticipation(me, m, for_each_far_candidate, sum);
  auto for_each_holder = [&](const auto& fn) {
    if (held > kCfsHolders)
      return for_each_neighbour(for_each_candidate, self, n, me.p, query2, [&](Index j, glm::vec2) { fn(j); });
    for (int k = 0; k < held; ++k) fn(static_cast<Index>(holders[k]));
  };
  const glm::vec2 e =
      cfs_turn(normalize_or(me.v, glm::vec2(0.0f)), normalize_or(sum, glm::vec2(0.0f)), e0, dt, c.turn_time);
  if (length2(e) == 0.0f) return e;  // forces in balance: stand this step
  const bool slid = e0.x != me.e0.x || e0.y != me.e0.y;
  const float top =
      fminf(cfs_slide_speed(e0, me.e0, me.aim_distance, v0), cfs_turn_speed(e, me.e0, me.aim_distance, v0));
  // The time gap is kept to where neighbours will be in anticipation_time
  // (one crossing the agent's path will have left it), to those within the
  // lane; no step may end in a body where it is now.
  auto speed_past = [&](bool all) {
    float gap = INFINITY, gap_now = INFINITY;
    for_each_holder([&](Index j) {
      const glm::vec2 q = n.at(j, me.p);
      if (!all && cfs_waits_for(me, q, slid || (near_wall && n.id(j) > n.id(self)))) return;
      gap = fminf(
          gap, cfs_gap_ahead(me.p, me.radius, e, q + n.velocity[j] * c.anticipation_time, n.radius[j], c.lane_width));
      gap_now = fminf(gap_now, cfs_gap_ahead(me.p, me.radius, e, q, n.radius[j]));
    });
    return fminf(cfs_speed(gap, top, c.time_gap), fmaxf(gap_now, 0.0f) / dt);
  };
  float speed = speed_past(true);
  // Abreast of a neighbour with its goal across that neighbour's way: it
  // falls back and passes behind (cfs_yield_speed).
  if (const CfsYield yield = cfs_yield(me); yield.side != 0.0f)
    for_each_holder(
        [&](Index j) { speed = fminf(speed, cfs_yield_speed(me, yield, n.at(j, me.p), n.velocity[j], n.radius[j])); });
  // Held at rest while walking on would take it forward: the neighbours
  // that wait for it (cfs_waits_for) are left out of its gap and of the
  // no-step-into-a-body cap, so it may press into them, and the contact
  // passes part the pair.
  if (speed < kCfsBlockedSpeed && dot2(e, me.e0) > 0.0f) return e * speed_past(false);
  return e * speed;
}

// ---- time to collision -------------------------------------------------------

// The agent being steered under a force model (time to collision, social
// force): its state, where it heads and how fast it would like to walk.
struct ForceAgent {
  glm::vec2 p{0.0f};
  glm::vec2 v{0.0f};
  float radius = 0.2f;
  glm::vec2 e0{1.0f, 0.0f};  // unit direction to the goal
  float pref_speed = 1.3f;
};

// The total acceleration of the agent (`self`: its element of the
// neighbour arrays) under the time-to-collision model (ttc.h), clamped to
// max_acceleration: the goal term, then walls and circles of the agent's
// obstacle cell (nearest points within the sensing radius), then
// neighbours within the sensing radius in the order `for_each_candidate`
// visits them (the 3x3 bins, or all agents for the reference), so the sum
// is the same for any thread count.
template <class ForEachCandidate>
THRONG_HOST_DEVICE inline glm::vec2 ttc_force(const WorldView& w, Index self, const ForceAgent& me,
                                              const NeighbourArrays& n, const ModelParams& m,
                                              const ForEachCandidate& for_each_candidate) {
  const TtcParams& t = m.ttc;
  const float sense2 = t.sensing_radius * t.sensing_radius;
  glm::vec2 f = ttc_goal_force(me.v, me.pref_speed, me.e0, t);
  auto wall_point = [&](glm::vec2 q) {
    const glm::vec2 x = me.p - q;
    if (length2(x) < sense2) f += ttc_avoidance(x, me.v, me.radius, t);
  };
  for_each_wall_point(w, me.p, wall_point);
  for_each_neighbour(for_each_candidate, self, n, me.p, sense2, [&](Index j, glm::vec2 q) {
    f += ttc_avoidance(me.p - q, me.v - n.velocity[j], me.radius + n.radius[j], t);
  });
  return clamp_length(f, t.max_acceleration);
}

// ---- social force -----------------------------------------------------------------

// The total force (N) on `me` at time t into the step: the driving term,
// then walls and circles of its obstacle cell (nearest points within the
// sensing radius), then neighbours within the sensing radius, each where it
// was sensed at the start of the step moved on t at its velocity, in the
// order `for_each_candidate` visits them (the sum is the same for any
// thread count); h: the substep (sf_contact_force).
template <class ForEachCandidate>
THRONG_HOST_DEVICE inline glm::vec2 sf_total_force(const WorldView& w, Index self, const ForceAgent& me, float t,
                                                   float h, const NeighbourArrays& n, const SocialForceParams& s,
                                                   const ForEachCandidate& for_each_candidate) {
  const float sense2 = s.sensing_radius * s.sensing_radius;
  glm::vec2 f = sf_driving_force(me.v, me.pref_speed, me.e0, s);
  for_each_wall_point(w, me.p, [&](glm::vec2 q) {
    if (length2(me.p - q) < sense2) f += sf_wall_force(me.p, me.v, me.radius, q, s, h);
  });
  const glm::vec2 heading = normalize_or(me.v, me.e0);
  for_each_candidate([&](Index j, glm::vec2 at) {
    if (j == self) return;
    const glm::vec2 x = me.p - (n.periodic.near(at, me.p) + n.velocity[j] * t);
    if (length2(x) < sense2) f += sf_neighbour_force(x, me.v, n.velocity[j], me.radius + n.radius[j], heading, s, h);
  });
  return f;
}

// The step of `me` under the social force model (social_force.h): dt
// integrated in sf_substeps substeps, symplectic Euler (v first, at most
// max_speed, then p), against neighbours moving on at constant velocity.
// Returns the step's mean velocity, the displacement / dt.
template <class ForEachCandidate>
THRONG_HOST_DEVICE inline glm::vec2 social_force_velocity(const WorldView& w, Index self, ForceAgent me, float dt,
                                                          const NeighbourArrays& n, const ModelParams& m,
                                                          const ForEachCandidate& for_each_candidate) {
  const SocialForceParams& s = m.sf;
  const int substeps = sf_substeps(dt, s);
  const float h = dt / static_cast<float>(substeps);
  const glm::vec2 start = me.p;
  for (int k = 0; k < substeps; ++k) {
    const glm::vec2 f = sf_total_force(w, self, me, static_cast<float>(k) * h, h, n, s, for_each_candidate);
    me.v = clamp_length(me.v + f * (h / s.mass), m.max_speed);
    me.p += me.v * h;
  }
  return (me.p - start) * (1.0f / dt);
}

// Deterministic unit direction for two agents at exactly the same point.
THRONG_HOST_DEVICE inline glm::vec2 tie_direction(Index i, Index j) {
  const Index lo = i < j ? i : j, hi = i < j ? j : i;
  const std::uint64_t h =
      mix_key(static_cast<std::uint64_t>(lo) * 0x9e3779b97f4a7c15ull + static_cast<std::uint64_t>(hi));
  const float a = static_cast<float>(h >> 40) * (6.2831853f / 16777216.0f);
  const glm::vec2 u(cosf(a), sinf(a));
  return i < j ? u : -u;
}

// Contact constraint (the addition to the paper's model): each overlapping
// pair is pushed apart, this agent taking half of the overlap. `deepest`
// becomes the deepest of those overlaps (m; 0 when none).
// Candidates: the contact bins' cells `cells` (the 3x3 around the agent's);
// over a periodic area, each at its image nearest p.
THRONG_HOST_DEVICE inline glm::vec2 contact_push(const GridView& bins, const Cells3x3& cells, Index self, glm::vec2 p,
                                                 float radius, Span<const glm::vec2> positions, Span<const float> radii,
                                                 Span<const std::uint8_t> flags, const Periodic& periodic,
                                                 float& deepest) {
  glm::vec2 push(0.0f);
  deepest = 0.0f;
  for_each_in_cells(bins, cells, [&](std::int32_t j) {
    if (j == self || (flags[j] & kAgentActive) == 0) return;
    const glm::vec2 d = p - periodic.near(positions[j], p);
    const float reach = radius + radii[j];
    const float d2 = length2(d);
    if (d2 >= reach * reach) return;
    const float dist = sqrtf(d2);
    const glm::vec2 dir = dist > 1e-6f ? d * (1.0f / dist) : tie_direction(self, j);
    push += dir * (0.5f * (reach - dist));
    deepest = fmaxf(deepest, reach - dist);
  });
  return push;
}

// Moves a disc out of every wall and circle of `cell` it overlaps (two
// passes for corners). `anchor` (the last valid position) breaks ties when
// the centre lies on a wall. `clear` becomes true when a pass found nothing
// to move: the disc then keeps its radius from every wall and circle of
// the cell (what the move stage's acceptance asks), with no need to measure.
THRONG_HOST_DEVICE inline glm::vec2 project_out_of_obstacles(const WorldView& w, const ObstacleCell& cell, glm::vec2 p,
                                                             float r, glm::vec2 anchor, bool& clear) {
  clear = false;
  for (int pass = 0; pass < 2 && !clear; ++pass) {
    bool touched = false;
    for_each_obstacle(
        w, cell,
        [&](const Segment& s) {
          const glm::vec2 q = closest_point_on_segment(p, s.a, s.b);
          const float d = length_of(p - q);
          if (d >= r) return;
          touched = true;
          glm::vec2 n = normalize_or(perp_left(s.b - s.a), glm::vec2(1.0f, 0.0f));
          if (dot2(n, anchor - s.a) < 0.0f) n = -n;
          const glm::vec2 dir = d > 1e-6f ? (p - q) * (1.0f / d) : n;
          p = q + dir * r;
        },
        [&](const Circle& c) {
          const glm::vec2 d = p - c.center;
          if (length2(d) >= (c.radius + r) * (c.radius + r)) return;
          touched = true;
          p = c.center + normalize_or(d, normalize_or(anchor - c.center, glm::vec2(1.0f, 0.0f))) * (c.radius + r);
        });
    clear = !touched;
  }
  return p;
}

}  // namespace throng::sim
