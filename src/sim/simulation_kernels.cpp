// The per-step stages of the crowd simulation. Compiled by nvcc in CUDA
// builds: bodies touch only spans and values.
#include <cstring>

#include "core/parallel.h"
#include "core/reduce.h"
#include "sim/sense.h"
#include "sim/simulation.h"

namespace throng::sim {

namespace {

constexpr float kWallTolerance = 1e-4f;   // m: accepted float error against walls
constexpr float kMaxStepFraction = 0.9f;  // of the radius: displacement cap in a contact pass
constexpr float kAcceptFraction = 0.95f;  // of the radius: largest accepted displacement per step

// Under the collision-free speed model an intermediate waypoint (a door, a
// corner of a route) also counts as reached once the agent has crossed the
// line through it square to its leg, within kWaypointHalfWidth of it: a
// crowd streams through a door side by side, and an agent the crowd pushed
// past the point must not turn back against the stream to touch it.
constexpr float kWaypointHalfWidth = 1.5f;  // m
THRONG_HOST_DEVICE inline bool passed_waypoint(glm::vec2 p, glm::vec2 leg_start, glm::vec2 waypoint,
                                               float arrival_radius) {
  const glm::vec2 along = normalize_or(waypoint - leg_start, glm::vec2(0.0f));
  if (length2(along) == 0.0f || dot2(p - waypoint, along) <= 0.0f) return false;
  const float half = arrival_radius > kWaypointHalfWidth ? arrival_radius : kWaypointHalfWidth;
  return fabsf(dot2(p - waypoint, perp_left(along))) <= half;
}

// Where the collision-free speed model heads for an intermediate waypoint:
// the nearest point of the same gate (the segment through the waypoint
// square to its leg, kWaypointHalfWidth each side), so agents stream
// through a door side by side in lanes instead of converging on one point
// in single file. A door narrower than the gate puts its ends behind the
// wall: an agent that sees a wall (within a cell side) between itself and
// the gate point heads for the waypoint instead; else it walks into the wall
// beside the door, and a straggler there can slide along it away from the
// door (seen in a 0.5 m door's room). So does a wall between the gate point
// and the waypoint: for a leg that comes in diagonally the gate's end lies
// in the room beside the door, and an agent pushed there circled it.
THRONG_HOST_DEVICE inline glm::vec2 waypoint_aim(const WorldView& w, glm::vec2 p, glm::vec2 leg_start,
                                                 glm::vec2 waypoint) {
  const glm::vec2 along = normalize_or(waypoint - leg_start, glm::vec2(0.0f));
  const glm::vec2 across = perp_left(along);
  const float offset = dot2(p - waypoint, across);
  const glm::vec2 gate = waypoint + across * fminf(fmaxf(offset, -kWaypointHalfWidth), kWaypointHalfWidth);
  bool blocked = false;
  for_each_wall_near(w, p, [&](const Segment& s) {
    blocked = blocked || segments_cross(p, gate, s.a, s.b) || segments_cross(gate, waypoint, s.a, s.b);
  });
  return blocked ? waypoint : gate;
}

// True when no wall within a cell side of p stands between p and the
// waypoint: a gate line crossed behind a wall (its end in the room beside a
// door, for a leg that came in diagonally) does not count as passed.
THRONG_HOST_DEVICE inline bool waypoint_in_view(const WorldView& w, glm::vec2 p, glm::vec2 waypoint) {
  bool blocked = false;
  for_each_wall_near(w, p, [&](const Segment& s) { blocked = blocked || segments_cross(p, waypoint, s.a, s.b); });
  return !blocked;
}

// A gate of the journey (a waypoint with an extent, sim/crowd.h): every
// model heads for the nearest point of it kept a body and kGateEndMargin
// from each end, led kGateLead past the line so that agents cross it
// rather than stop on it; it is passed by a step that crosses the line, in
// either direction, within a body of its ends.
constexpr float kGateEndMargin = 0.1f;  // m
constexpr float kGateLead = 1.0f;       // m
// Its middle; unit vectors along it and across it, away from the side the
// agent is on (from where its leg started while on the line); half its
// length (m).
struct Gate {
  glm::vec2 mid{0.0f}, along{0.0f}, ahead{0.0f};
  float half = 0.0f;
};
// The stage of agent i's current waypoint (into a.stages), -1 for a plain point.
THRONG_HOST_DEVICE inline std::int32_t current_stage(const AgentArrays& a, Index i) {
  return a.waypoint_stage[a.waypoint_begin[i] + a.waypoint_cursor[i]];
}
// Agent i's current waypoint as a gate; false for a point (with or without a wait).
THRONG_HOST_DEVICE inline bool current_gate(const AgentArrays& a, Index i, Gate& g) {
  const std::int32_t s = current_stage(a, i);
  if (s < 0 || length2(a.stages[s].gate_half) == 0.0f) return false;
  g.mid = a.goal[i];
  g.half = length_of(a.stages[s].gate_half);
  g.along = a.stages[s].gate_half * (1.0f / g.half);
  g.ahead = perp_left(g.along);
  const float side = dot2(a.position[i] - g.mid, g.ahead);
  if (side > 0.0f || (side == 0.0f && dot2(a.path_start[i] - g.mid, g.ahead) > 0.0f)) g.ahead = -g.ahead;
  return true;
}
// True when the step from `from` to `p` crosses the gate's line within a
// body (r) of its ends.
THRONG_HOST_DEVICE inline bool crossed_gate(const Gate& g, glm::vec2 from, glm::vec2 p, float r) {
  const float s0 = dot2(from - g.mid, g.ahead), s1 = dot2(p - g.mid, g.ahead);
  if ((s0 > 0.0f) == (s1 > 0.0f) || s0 == s1) return false;
  const glm::vec2 at = from + (p - from) * (s0 / (s0 - s1));
  return fabsf(dot2(at - g.mid, g.along)) <= g.half + r;
}
// True when agent i's current waypoint asks it to wait there: it walks to
// the point itself (not to a gate through it, as the collision-free speed
// model's other waypoints).
THRONG_HOST_DEVICE inline bool waits_at_waypoint(const AgentArrays& a, Index i) {
  const std::int32_t s = current_stage(a, i);
  return s >= 0 && a.stages[s].wait_s > 0.0f;
}
// (An agent beyond the aimed-at part heads for the line itself and takes
// the lead once in line with that part: led from beyond it, it would cut
// past the gate's end. A gate narrower than a body and its margins, a
// turnstile, leads those within half its half-length of its middle.)
THRONG_HOST_DEVICE inline glm::vec2 gate_aim(const Gate& g, glm::vec2 p, float r) {
  const float reach = fmaxf(g.half - r - kGateEndMargin, 0.0f);
  const float offset = dot2(p - g.mid, g.along);
  const float t = fminf(fmaxf(offset, -reach), reach);
  return g.mid + g.along * t + g.ahead * (fabsf(offset) <= fmaxf(reach, 0.5f * g.half) ? kGateLead : 0.0f);
}

// Where a navigation field leads agent i (its current waypoint is the
// field's target): the point the field aims at (sim/navigation_field.h).
// False when no field leads to its waypoint.
THRONG_HOST_DEVICE inline bool field_target(const StepContext& ctx, const AgentArrays& a, Index i, glm::vec2& out) {
  if (ctx.fields.grids.size() == 0) return false;
  const std::int32_t f = field_of(ctx.fields, a.goal[i]);
  if (f < 0) return false;
  out = field_aim(ctx.fields, f, a.position[i]);
  return true;
}

// Where a navigation field or a gate leads agent i: the field's aim (taken
// kGateLead past the line where it ends at the gate of an exit, so that the
// agent crosses it), else the gate's aim; false for neither.
THRONG_HOST_DEVICE inline bool led_target(const StepContext& ctx, const AgentArrays& a, Index i, glm::vec2& out) {
  Gate gate;
  const bool is_gate = current_gate(a, i, gate);
  if (field_target(ctx, a, i, out)) {
    if (!is_gate) return true;
    const float past = dot2(out - gate.mid, gate.ahead);
    if (fabsf(past) < kGateLead && fabsf(dot2(out - gate.mid, gate.along)) <= gate.half)
      out += gate.ahead * (kGateLead - past);
    return true;
  }
  if (is_gate) out = gate_aim(gate, a.position[i], a.radius[i]);
  return is_gate;
}

// The agents as the models read their neighbours: the steering bins'
// items' copy in item order where the step gathered one (element k is
// agent bins.items[k]), else the crowd's arrays (element i is agent i).
THRONG_HOST_DEVICE inline NeighbourArrays neighbours_of(const StepContext& ctx, const AgentArrays& a) {
  const BinnedState& b = ctx.binned;
  if (b.position.size() > 0) return {b.position, b.velocity, b.radius, b.flags, ctx.periodic, ctx.bins.items};
  return {a.position, a.velocity, a.radius, a.flags, ctx.periodic};
}
// Agent i's element of those arrays, k being its place in the bins' items.
THRONG_HOST_DEVICE inline Index element_of(const StepContext& ctx, Index k, Index i) {
  return ctx.binned.position.size() > 0 ? k : i;
}

THRONG_HOST_DEVICE inline bool is_steering(std::uint8_t flags) {
  return (flags & kAgentActive) != 0 && (flags & (kAgentStopped | kAgentWaiting)) == 0;
}

// Sense under the priority model: the higher-priority force of one agent,
// obstacle avoidance or else agent avoidance (zero when neither applies).
// `neighbours(p, v, forward, radius)` finds the most urgent threat: from the
// 3x3 bins, or all pairs.
template <class Neighbours>
THRONG_HOST_DEVICE inline glm::vec2 sense_priority(const StepContext& ctx, const AgentArrays& a, Index i,
                                                   const Neighbours& neighbours) {
  const ModelParams& m = ctx.model;
  const glm::vec2 p = a.position[i], v = a.velocity[i];
  const float r = a.radius[i];
  const Probe probe = make_probe(p, v, a.heading[i], r, m);
  // Priority: agent avoidance is only computed when no obstacle force applies.
  const glm::vec2 obstacle = sense_obstacles(ctx.world, probe, m.max_force).force;
  if (force_applies(obstacle)) return obstacle;
  return avoidance_force(probe.forward, neighbours(p, v, probe.forward, r), m.max_force);
}

// Where agent i heads (AgentAim). The collision-free speed model: its
// field's or gate's aim, else its goal, or a point of its leg past a plain
// waypoint (waypoint_aim); the force models: the field's or gate's aim, else
// the goal itself. The distance is to its waypoint or goal itself (a
// field's aim, a gate's point, lie a step ahead wherever the agent is).
THRONG_HOST_DEVICE inline AgentAim agent_aim(const StepContext& ctx, const AgentArrays& a, Index i) {
  const glm::vec2 p = a.position[i];
  glm::vec2 aim = a.goal[i];
  if (!led_target(ctx, a, i, aim) && ctx.model.kind == ModelKind::CollisionFreeSpeed) {
    const bool to_point = a.waypoint_cursor[i] == a.waypoint_goal[i] || waits_at_waypoint(a, i);
    if (!to_point) aim = waypoint_aim(ctx.world, p, a.path_start[i], a.goal[i]);
  }
  return {normalize_or(aim - p, glm::vec2(0.0f)), length_of(a.goal[i] - p), a.pref_speed[i]};
}
// Agent i's aim as sense reads it: from the copy in item order where the
// step gathered one (`self`: its element), else found here.
THRONG_HOST_DEVICE inline AgentAim aim_of(const StepContext& ctx, const AgentArrays& a, Index i, Index self) {
  return ctx.binned.aim.size() > 0 ? ctx.binned.aim[self] : agent_aim(ctx, a, i);
}

// Sense under the collision-free speed model: agent i's new velocity
// (`self`: its element of the neighbour arrays, neighbours_of).
// `for_each_candidate(fn)` visits the candidate neighbours,
// `for_each_far_candidate(e0, reach2, fn)` those of the far look.
template <class ForEachCandidate, class ForEachFarCandidate>
THRONG_HOST_DEVICE inline glm::vec2 sense_collision_free(const StepContext& ctx, const AgentArrays& a,
                                                         const NeighbourArrays& n, Index i, Index self,
                                                         const ForEachCandidate& for_each_candidate,
                                                         const ForEachFarCandidate& for_each_far_candidate) {
  const AgentAim aim = aim_of(ctx, a, i, self);
  const CfsAgent me{n.position[self], n.velocity[self], n.radius[self], aim.e0, aim.distance};
  return collision_free_velocity(ctx.world, self, me, aim.pref_speed, ctx.dt, n, ctx.model, for_each_candidate,
                                 for_each_far_candidate);
}

// Agent i as the force models see it: heading straight for its goal, or
// where its navigation field leads (`n`: neighbours_of).
THRONG_HOST_DEVICE inline ForceAgent force_agent(const StepContext& ctx, const AgentArrays& a, const NeighbourArrays& n,
                                                 Index i, Index self) {
  const AgentAim aim = aim_of(ctx, a, i, self);
  return {n.position[self], n.velocity[self], n.radius[self], aim.e0, aim.pref_speed};
}

// Sense under the time-to-collision model: the agent's total acceleration.
template <class ForEachCandidate>
THRONG_HOST_DEVICE inline glm::vec2 sense_ttc(const StepContext& ctx, const AgentArrays& a, const NeighbourArrays& n,
                                              Index i, Index self, const ForEachCandidate& for_each_candidate) {
  return ttc_force(ctx.world, self, force_agent(ctx, a, n, i, self), n, ctx.model, for_each_candidate);
}

// Sense under the social force model: the step's mean velocity.
template <class ForEachCandidate>
THRONG_HOST_DEVICE inline glm::vec2 sense_social_force(const StepContext& ctx, const AgentArrays& a,
                                                       const NeighbourArrays& n, Index i, Index self,
                                                       const ForEachCandidate& for_each_candidate) {
  return social_force_velocity(ctx.world, self, force_agent(ctx, a, n, i, self), ctx.dt, n, ctx.model,
                               for_each_candidate);
}

// The sense of the models that sum over every candidate neighbour
// (collision-free speed, time to collision, social force); `n`:
// neighbours_of, `self` agent i's element of it.
template <class ForEachCandidate, class ForEachFarCandidate>
THRONG_HOST_DEVICE inline glm::vec2 sense_candidates(const StepContext& ctx, const AgentArrays& a,
                                                     const NeighbourArrays& n, Index i, Index self,
                                                     const ForEachCandidate& for_each_candidate,
                                                     const ForEachFarCandidate& for_each_far_candidate) {
  if (ctx.model.kind == ModelKind::Ttc) return sense_ttc(ctx, a, n, i, self, for_each_candidate);
  if (ctx.model.kind == ModelKind::SocialForce) return sense_social_force(ctx, a, n, i, self, for_each_candidate);
  return sense_collision_free(ctx, a, n, i, self, for_each_candidate, for_each_far_candidate);
}

// Sense: what the model makes of the agent's surroundings, zero for agents
// that do not steer. Priority: the avoidance force (zero when nothing is
// sensed); collision-free speed: the new velocity; time to collision: the
// total acceleration; social force: the step's mean velocity. Neighbours
// come from the 3x3 bins around (cx, cy), the agent's cell; `self` is
// agent i's element of the neighbour arrays `n` (neighbours_of).
THRONG_HOST_DEVICE inline glm::vec2 sense_binned(const StepContext& ctx, const AgentArrays& a, const NeighbourArrays& n,
                                                 Index i, Index self, std::int32_t cx, std::int32_t cy) {
  if (!is_steering(n.flags[self])) return glm::vec2(0.0f);
  if (ctx.model.kind != ModelKind::Priority) {
    const Cells3x3 cells = cells_3x3(ctx.bins, cx, cy);
    auto candidates = [&](const auto& fn) { for_each_binned_candidate(ctx.bins, cells, n, fn); };
    // The far look's cells: the 5 x 5 round the agent's, those touching the
    // reach and the half-plane ahead of it (along e0); read as binned under
    // the four colours (StepContext::far_state).
    // Cells none of whose agents the far push could anticipate are passed
    // over (StepContext::far_headings).
    auto far = [&](glm::vec2 e0, float reach2, const auto& fn) {
      const glm::vec2 p = n.position[self];
      auto keep = [&](const CellBounds& c) { return cell_ahead_within_reach(c, p, e0, reach2); };
      const Span<const CellHeadings> headings = ctx.far_headings;
      auto keep_slot = [&](Index s) { return headings.size() == 0 || !cfs_cell_walks_along(headings[s], e0); };
      const BinnedState& b = ctx.far_state;
      const NeighbourArrays from =
          b.position.size() == 0 ? n : NeighbourArrays{b.position, b.velocity,   b.radius,
                                                       b.flags,    ctx.periodic, ctx.bins.items};
      const Cells5x5 far_cells = kept_cells(ctx.bins, cx, cy, ctx.bin_slack, keep, keep_slot);
      fn(from, [&](const auto& c) { for_each_binned_candidate(ctx.bins, far_cells, from, c); });
    };
    return sense_candidates(ctx, a, n, i, self, candidates, far);
  }
  return sense_priority(ctx, a, i, [&](glm::vec2 p, glm::vec2 v, glm::vec2 forward, float r) {
    return sense_neighbours(ctx.bins, cx, cy, self, p, v, forward, r, n, ctx.model, ctx.bin_slack);
  });
}

// Steer: integrates what was sensed. Priority: path following when the
// sensed force is zero, else that force; collision-free speed: the sensed
// velocity as it is (a first-order model); time to collision: the sensed
// acceleration, up to max_speed; social force: the sensed mean velocity
// (the model integrated its substeps in the sense stage).
THRONG_HOST_DEVICE inline void steer_agent(const StepContext& ctx, const AgentArrays& a, Index i, glm::vec2 sensed,
                                           glm::vec2& out_p, glm::vec2& out_v) {
  const glm::vec2 p = a.position[i], v = a.velocity[i];
  if (!is_steering(a.flags[i])) {
    out_p = p;
    out_v = glm::vec2(0.0f);
    return;
  }
  const ModelParams& m = ctx.model;
  if (m.kind == ModelKind::CollisionFreeSpeed || m.kind == ModelKind::SocialForce) {
    out_v = sensed;
  } else if (m.kind == ModelKind::Ttc) {
    out_v = clamp_length(v + sensed * ctx.dt, m.max_speed);
  } else {
    // Priority: path following only when no avoidance force was sensed; a
    // field's aim or a gate's is followed from where the agent stands (its
    // leg's lane may run through the walls the field leads round; it ends
    // at the gate's middle).
    glm::vec2 start = a.path_start[i], goal = a.goal[i];
    if (led_target(ctx, a, i, goal)) start = p;
    const glm::vec2 force =
        force_applies(sensed) ? sensed : path_following_force(p, v, a.pref_speed[i], start, goal, m);
    // Forces turn and brake; none makes an agent walk faster than it prefers.
    out_v = clamp_length(v + force * ctx.dt, a.pref_speed[i]);
  }
  out_p = p + out_v * ctx.dt;
}

// The move stage accepts a position only if it keeps the disc off every
// wall and is short enough that it cannot have crossed one (see the header).
// `known_clear`: the caller already knows the disc is off every wall.
THRONG_HOST_DEVICE inline bool acceptable_move(const StepContext& ctx, const MoveCells& cells, glm::vec2 from,
                                               glm::vec2 p, float r, bool known_clear = false) {
  const bool short_enough = length2(p - from) <= (kAcceptFraction * r) * (kAcceptFraction * r);
  return short_enough && (known_clear || wall_clearance(ctx.world, cells.obstacles, p, r) >= r - kWallTolerance);
}

// One contact pass for one agent reading positions P; `deepest` becomes the
// deepest overlap of the agent the pass found (before its push).
THRONG_HOST_DEVICE inline glm::vec2 contact_agent(const StepContext& ctx, const AgentArrays& a, Index i,
                                                  const MoveCells& cells, glm::vec2 anchor, Span<const glm::vec2> P,
                                                  float& deepest) {
  glm::vec2 p = P[i];
  deepest = 0.0f;
  if ((a.flags[i] & kAgentActive) == 0) return p;
  const float r = a.radius[i];
  p += clamp_length(contact_push(ctx.contact_bins, cells.agents, i, p, r, P, a.radius, a.flags, ctx.periodic, deepest),
                    0.5f * r);
  p = anchor + clamp_length(p - anchor, kMaxStepFraction * r);
  bool clear = false;
  p = project_out_of_obstacles(ctx.world, cells.obstacles, p, r, anchor, clear);
  // Where the move stage would reject the position (pressed into a sharp
  // corner), the agent stays at its anchor already now: later passes then
  // push its neighbours away from where it will be, not from where it
  // will not. (A position the projection left clear needs only the length test.)
  return acceptable_move(ctx, cells, anchor, p, r, clear) ? p : anchor;
}

// Agents are visited in bin order (the k-th binned agent), so agents whose
// 3x3 cells overlap are sensed one after another and find their candidates
// still in cache; each agent's result depends only on the state it reads,
// not on the order. Inactive agents are not binned: their sensed entry
// keeps whatever it held (zero, or its last value before it left), which
// steering ignores for an agent that does not steer.
struct Sense {
  StepContext ctx;
  AgentArrays a;
  Span<glm::vec2> sensed;
  THRONG_HOST_DEVICE void operator()(Index k) const {
    const Index i = ctx.bins.items[k], self = element_of(ctx, k, i);
    const NeighbourArrays n = neighbours_of(ctx, a);
    const glm::vec2 p = n.position[self];
    sensed[i] = sense_binned(ctx, a, n, i, self, ctx.bins.cell_x(p.x), ctx.bins.cell_y(p.y));
  }
};

// The naive reference: the same sense stage with every other agent as a
// candidate (O(N^2)), for benchmarks and for checking the bins.
struct SenseAllPairs {
  StepContext ctx;
  AgentArrays a;
  Span<glm::vec2> sensed;
  THRONG_HOST_DEVICE void operator()(Index i) const {
    if (!is_steering(a.flags[i])) {
      sensed[i] = glm::vec2(0.0f);
      return;
    }
    const NeighbourArrays n = neighbours_of(ctx, a);
    if (ctx.model.kind != ModelKind::Priority) {
      auto candidates = [&](const auto& fn) { for_each_active_candidate(n, fn); };
      auto far = [&](glm::vec2, float, const auto& fn) { fn(n, candidates); };
      sensed[i] = sense_candidates(ctx, a, n, i, i, candidates, far);
      return;
    }
    const ModelParams m = ctx.model;
    sensed[i] = sense_priority(ctx, a, i, [&](glm::vec2 p, glm::vec2 v, glm::vec2 forward, float r) {
      return sense_neighbours_all_pairs(i, p, v, forward, r, n, m);
    });
  }
};

struct Steer {
  StepContext ctx;
  AgentArrays a;
  Span<const glm::vec2> sensed;
  Span<glm::vec2> out_p;
  THRONG_HOST_DEVICE void operator()(Index i) const {
    glm::vec2 np, nv;
    steer_agent(ctx, a, i, sensed[i], np, nv);
    out_p[i] = np;
  }
};

// The move cells of every agent (around its position at the start of the
// step), found once and used by every contact pass and the final check.
struct FindMoveCells {
  StepContext ctx;
  Span<const glm::vec2> anchor;
  Span<MoveCells> cells;
  THRONG_HOST_DEVICE void operator()(Index i) const {
    const glm::vec2 b = anchor[i];
    const GridView& g = ctx.contact_bins;
    cells[i] = {cells_3x3(g, g.cell_x(b.x), g.cell_y(b.y)), obstacle_cell(ctx.world, b)};
  }
};

// True when no agent of the cells moved in the pass that counted
// moved_before (mark_moved_items).
THRONG_HOST_DEVICE inline bool quiet_cells(const Cells3x3& c, Span<const std::int32_t> moved_before) {
  for (int k = 0; k < c.runs; ++k)
    if (moved_before[c.start[k] + c.count[k]] != moved_before[c.start[k]]) return false;
  return true;
}

struct ContactsDoubleBuffer {
  StepContext ctx;
  AgentArrays a;
  Span<const glm::vec2> anchor, in;
  Span<const MoveCells> cells;
  Span<glm::vec2> out;
  Span<float> depth;
  Span<const std::int32_t> moved_before;  // empty: every agent looks at its neighbours
  THRONG_HOST_DEVICE void operator()(Index i) const {
    if (moved_before.size() > 0 && quiet_cells(cells[i].agents, moved_before)) {
      out[i] = in[i];
      return;
    }
    out[i] = contact_agent(ctx, a, i, cells[i], anchor[i], in, depth[i]);
  }
};

// Four colour: one launch per colour over the table slots; a slot of that
// colour updates its agents one after another, in place. Cells of one colour
// are two apart in x or y, so no cell of the launch reads another's agents.
struct SenseSteerColour {
  StepContext ctx;
  AgentArrays a;
  int colour;
  THRONG_HOST_DEVICE void operator()(Index s) const {
    const std::uint64_t key = ctx.bins.keys[s];
    if (key == kEmptyCell || cell_colour(key) != colour) return;
    const std::int32_t cx = key_cx(key), cy = key_cy(key);
    const std::int32_t b = ctx.bins.start[s], count = ctx.bins.count[s];
    const NeighbourArrays n = neighbours_of(ctx, a);
    for (std::int32_t k = 0; k < count; ++k) {
      const Index i = ctx.bins.items[b + k];
      glm::vec2 np, nv;
      steer_agent(ctx, a, i, sense_binned(ctx, a, n, i, i, cx, cy), np, nv);
      a.position[i] = np;
      a.velocity[i] = nv;
    }
  }
};

struct ContactsColour {
  StepContext ctx;
  AgentArrays a;
  Span<const glm::vec2> anchor;
  Span<const MoveCells> cells;
  Span<float> depth;
  int colour;
  THRONG_HOST_DEVICE void operator()(Index s) const {
    const std::uint64_t key = ctx.contact_bins.keys[s];
    if (key == kEmptyCell || cell_colour(key) != colour) return;
    const std::int32_t b = ctx.contact_bins.start[s], n = ctx.contact_bins.count[s];
    for (std::int32_t k = 0; k < n; ++k) {
      const Index i = ctx.contact_bins.items[b + k];
      a.position[i] = contact_agent(ctx, a, i, cells[i], anchor[i], a.position, depth[i]);
    }
  }
};

struct Finalize {
  StepContext ctx;
  AgentArrays a;
  Span<const glm::vec2> anchor;
  Span<const MoveCells> cells;
  Span<const glm::vec2> moved;
  THRONG_HOST_DEVICE void operator()(Index i) const {
    std::uint8_t flags = a.flags[i];
    if ((flags & kAgentActive) == 0) return;
    const glm::vec2 from = anchor[i];
    glm::vec2 p = moved[i];
    const float r = a.radius[i];
    if (!acceptable_move(ctx, cells[i], from, p, r)) p = from;
    glm::vec2 v = clamp_length((p - from) * (1.0f / ctx.dt), ctx.model.max_speed);
    if ((flags & kAgentStopped) != 0) v = glm::vec2(0.0f);
    if (ctx.periodic.wraps()) {
      // Back into the area across the seam. A periodic area's agents head
      // in a direction, a goal far ahead: it moves with them, step by step
      // and across the seam, so they never reach it and their way stays
      // parallel to the direction however they are pushed aside.
      p = ctx.periodic.wrap(p);
      a.path_start[i] = p + (a.path_start[i] - from);
      a.goal[i] = p + (a.goal[i] - from);
    }
    a.position[i] = p;
    if (length2(v) > 0.05f * 0.05f && (flags & kAgentWaiting) == 0) a.heading[i] = atan2f(v.y, v.x);
    // A waiting agent starts walking in the step that begins at its start time.
    // (1% of a step absorbs the float rounding of both times.)
    if ((flags & kAgentWaiting) != 0 && ctx.time_after + 0.01f * ctx.dt >= a.start_time[i])
      flags = static_cast<std::uint8_t>(flags & ~kAgentWaiting);
    else if ((flags & (kAgentStopped | kAgentWaiting)) == 0) {
      const GroupRuntime g = a.groups[a.group[i]];
      const glm::vec2 goal = a.goal[i];
      const std::int32_t cursor = a.waypoint_cursor[i];
      Gate gate;
      const bool is_gate = current_gate(a, i, gate);
      // (The priority model keeps the paper's point waypoints.)
      const bool through = is_gate ? crossed_gate(gate, from, p, r)
                                   : ctx.model.kind == ModelKind::CollisionFreeSpeed && cursor != a.waypoint_goal[i] &&
                                         !waits_at_waypoint(a, i) &&
                                         passed_waypoint(p, a.path_start[i], goal, g.arrival_radius) &&
                                         waypoint_in_view(ctx.world, p, goal);
      if (through || (!is_gate && length2(goal - p) <= g.arrival_radius * g.arrival_radius)) {
        const std::int32_t begin = a.waypoint_begin[i], count = a.waypoint_count[i];
        // A waiting area: the agent stands here (sensed) until then, as before its pre-movement ends.
        if (waits_at_waypoint(a, i)) {
          flags |= kAgentWaiting;
          a.start_time[i] = ctx.time_after + a.stages[current_stage(a, i)].wait_s;
          v = glm::vec2(0.0f);
        }
        if (cursor == a.waypoint_goal[i] && a.arrival_time[i] < 0.0f) {
          a.arrival_time[i] = ctx.time_after;
          flags |= kAgentArrived;
        }
        if (cursor + 1 < count) {
          a.path_start[i] = goal;
          a.waypoint_cursor[i] = cursor + 1;
          a.goal[i] = a.waypoints[begin + cursor + 1];
        } else if (g.arrival == ArrivalBehaviour::Stop) {
          flags |= kAgentStopped;
          v = glm::vec2(0.0f);
        } else if (g.arrival == ArrivalBehaviour::Despawn) {
          flags = static_cast<std::uint8_t>(flags & ~kAgentActive);
          v = glm::vec2(0.0f);
        } else {
          a.path_start[i] = goal;
          a.waypoint_cursor[i] = 0;
          a.goal[i] = a.waypoints[begin];
        }
      }
    }
    a.velocity[i] = v;
    a.flags[i] = flags;
  }
};

constexpr Index kAgentGrain = 256;
constexpr Index kSlotGrain = 256;

}  // namespace

void sense_double_buffer(const StepContext& ctx, const AgentArrays& a, Span<glm::vec2> sensed) {
  parallel_for("sim.sense", ctx.bins.items.size(), Sense{ctx, a, sensed}, kAgentGrain);
  count_traffic("sim.sense", ctx.bins.items, ctx.bins.start, ctx.bins.count, ctx.binned.position, ctx.binned.velocity,
                ctx.binned.radius, ctx.binned.flags, ctx.binned.aim, sensed);
  // The priority model reads the agent's own state from the crowd's arrays.
  if (ctx.model.kind == ModelKind::Priority) count_traffic("sim.sense", a.position, a.velocity, a.radius, a.heading);
}

void gather_binned_state(const StepContext& ctx, const AgentArrays& a, Span<AgentAim> aims, const BinnedState& out) {
  const Span<const std::int32_t> items = ctx.bins.items;
  const BinnedState b = out;
  const bool aimed = b.aim.size() > 0;
  if (aimed) {
    const StepContext c = ctx;
    parallel_for(
        "sim.sense.aims", a.position.size(),
        THRONG_LAMBDA(Index i) {
          if (is_steering(a.flags[i])) aims[i] = agent_aim(c, a, i);
        },
        kAgentGrain);
    count_traffic("sim.sense.aims", a.flags, a.position, a.goal, a.pref_speed, a.waypoint_cursor, aims);
  }
  parallel_for(
      "sim.sense.gather", items.size(),
      THRONG_LAMBDA(Index k) {
        const Index i = items[k];
        b.position[k] = a.position[i];
        b.velocity[k] = a.velocity[i];
        b.radius[k] = a.radius[i];
        b.flags[k] = a.flags[i];
        if (aimed) b.aim[k] = aims[i];
      },
      kAgentGrain);
  count_traffic("sim.sense.gather", items, a.position, a.velocity, a.radius, a.flags, b.position, b.velocity, b.radius,
                b.flags);
  if (aimed) count_traffic("sim.sense.gather", aims, b.aim);
}

void summarise_cell_headings(const GridView& bins, const BinnedState& state, Span<CellHeadings> out) {
  const Span<const glm::vec2> velocity = state.velocity;
  const Span<const std::uint8_t> flags = state.flags;
  parallel_for(
      "sim.sense.headings", bins.capacity(),
      THRONG_LAMBDA(Index s) {
        CellHeadings h;
        const std::int32_t b = bins.start[s], n = bins.count[s];
        for (std::int32_t k = b; k < b + n; ++k) add_heading(h, velocity[k], (flags[k] & kAgentStopped) != 0);
        out[s] = h;
      },
      kSlotGrain);
  count_traffic("sim.sense.headings", bins.start, bins.count, velocity, flags, out);
}

void sense_all_pairs(const StepContext& ctx, const AgentArrays& a, Span<glm::vec2> sensed) {
  parallel_for("sim.sense.all_pairs", a.position.size(), SenseAllPairs{ctx, a, sensed}, 16);
  count_traffic("sim.sense.all_pairs", a.position, a.velocity, a.radius, a.flags, a.goal, a.pref_speed,
                a.waypoint_cursor, sensed);
}

void steer_double_buffer(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> sensed,
                         Span<glm::vec2> out_position) {
  parallel_for("sim.steer", a.position.size(), Steer{ctx, a, sensed, out_position}, kAgentGrain);
  count_traffic("sim.steer", sensed, a.position, a.velocity, a.flags, a.pref_speed, out_position);
}

void move_cells(const StepContext& ctx, Span<const glm::vec2> anchor, Span<MoveCells> cells) {
  parallel_for("sim.move.cells", anchor.size(), FindMoveCells{ctx, anchor, cells}, kAgentGrain);
  count_traffic("sim.move.cells", anchor, cells);
}

void contacts_double_buffer(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> anchor,
                            Span<const MoveCells> cells, Span<const glm::vec2> in, Span<glm::vec2> out,
                            Span<float> depth, Span<const std::int32_t> moved_before) {
  parallel_for("sim.move.contacts", a.position.size(),
               ContactsDoubleBuffer{ctx, a, anchor, in, cells, out, depth, moved_before}, kAgentGrain);
  count_traffic("sim.move.contacts", ctx.contact_bins.items, anchor, cells, in, out, depth, a.radius, a.flags,
                moved_before);
}

void sense_steer_four_colour(const StepContext& ctx, const AgentArrays& a) {
  for (int c = 0; c < 4; ++c)
    parallel_for("sim.sense_steer.colour", ctx.bins.capacity(), SenseSteerColour{ctx, a, c}, kSlotGrain);
  // (the four launches together pass over every slot and agent once)
  count_traffic("sim.sense_steer.colour", ctx.bins.keys, ctx.bins.start, ctx.bins.count, ctx.bins.items, a.position,
                a.position, a.velocity, a.velocity, a.radius, a.flags, a.goal, a.pref_speed, a.waypoint_cursor);
}

void contacts_four_colour(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> anchor,
                          Span<const MoveCells> cells, Span<float> depth) {
  for (int c = 0; c < 4; ++c)
    parallel_for("sim.move.contacts.colour", ctx.contact_bins.capacity(),
                 ContactsColour{ctx, a, anchor, cells, depth, c}, kSlotGrain);
  count_traffic("sim.move.contacts.colour", ctx.contact_bins.keys, ctx.contact_bins.start, ctx.contact_bins.count,
                ctx.contact_bins.items, anchor, cells, depth, a.position, a.position, a.radius, a.flags);
}

float deepest_contact(Span<const float> depth, Span<const std::uint8_t> flags) {
  count_traffic("sim.move.contacts.deepest", depth, flags);
  return parallel_reduce(
      "sim.move.contacts.deepest", depth.size(), 0.0f,
      THRONG_LAMBDA(Index i)->float { return (flags[i] & kAgentActive) != 0 ? depth[i] : 0.0f; },
      THRONG_LAMBDA(float x, float y)->float { return x > y ? x : y; });
}

Index mark_moved_items(const GridView& contact_bins, Span<const glm::vec2> in, Span<const glm::vec2> out,
                       Span<std::int32_t> moved_before) {
  const Span<const std::int32_t> items = contact_bins.items;
  const Index n = items.size();
  const Span<std::int32_t> flags = moved_before.subspan(0, n + 1);
  parallel_for(
      "sim.move.contacts.moved", n + 1,
      THRONG_LAMBDA(Index k) {
        if (k == n) {
          flags[k] = 0;
          return;
        }
        const Index i = items[k];
        const glm::vec2 a = in[i], b = out[i];
        std::uint32_t bits_a[2], bits_b[2];
        memcpy(bits_a, &a, sizeof bits_a);
        memcpy(bits_b, &b, sizeof bits_b);
        flags[k] = bits_a[0] != bits_b[0] || bits_a[1] != bits_b[1] ? 1 : 0;
      },
      kAgentGrain);
  count_traffic("sim.move.contacts.moved", items, in, out, flags);
  count_traffic("sim.move.contacts.moved_scan", flags, flags);
  return exclusive_scan("sim.move.contacts.moved_scan", Span<const std::int32_t>(flags), flags);
}

void finalize_step(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> anchor,
                   Span<const MoveCells> cells, Span<const glm::vec2> moved) {
  parallel_for("sim.move.finalize", a.position.size(), Finalize{ctx, a, anchor, cells, moved});
  count_traffic("sim.move.finalize", anchor, cells, moved, a.position, a.velocity, a.heading, a.flags, a.flags,
                a.radius, a.goal, a.path_start, a.waypoint_cursor);
}

void copy_positions(Span<const glm::vec2> from, Span<glm::vec2> to) {
  parallel_for(
      "sim.move.copy", from.size(), THRONG_LAMBDA(Index i) { to[i] = from[i]; });
  count_traffic("sim.move.copy", from, to);
}

void entry_clearance(const GridView& bins, const Periodic& periodic, Span<const glm::vec2> position,
                     Span<const float> radius, Span<const std::uint8_t> flags, Span<const glm::vec2> spots,
                     Span<const float> spot_radius, Span<float> clearance) {
  parallel_for(
      "sim.inflow.clearance", spots.size(), THRONG_LAMBDA(Index k) {
        const glm::vec2 q = spots[k];
        float gap = INFINITY;
        for_each_in_3x3(bins, q, [&](Index j) {
          if ((flags[j] & kAgentActive) != 0)
            gap = fminf(gap, length_of(periodic.near(position[j], q) - q) - radius[j] - spot_radius[k]);
        });
        clearance[k] = gap;
      });
}

Index count_flag(Span<const std::uint8_t> flags, std::uint8_t bit) {
  count_traffic("sim.count", flags);
  return parallel_reduce(
      "sim.count", flags.size(), Index{0}, THRONG_LAMBDA(Index i)->Index { return (flags[i] & bit) != 0 ? 1 : 0; },
      THRONG_LAMBDA(Index x, Index y)->Index { return x + y; });
}

}  // namespace throng::sim
