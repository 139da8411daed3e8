// The collision-free speed model (Tordeux, Chraibi, Seyfried 2016,
// "Collision-free speed model for pedestrian dynamics", Traffic and
// Granular Flow '15, pp. 225-232; JuPedSim's default model), with an
// anticipation term for oncoming neighbours. A first-order model: each step
// an agent picks a direction, then the largest speed that keeps a time gap T
// to whoever stands ahead of it in that direction:
//
//   e_i = normalize(e0_i + sum_j R_ij + sum_w W_iw + sum_j A_ij)
//   v_i = e_i * clamp((s_i - 0) / T, 0, v0_i)
//
//   e0_i   unit direction towards the current goal;
//   R_ij = -a exp((l_ij - d_ij) / D) (x_j - x_i)/d_ij, l_ij = r_i + r_j: the
//          neighbour repulsion, felt only within a few D of contact;
//   W_iw = -b exp((r_i - d_iw) / Dw) (q_w - x_i)/d_iw, q_w the nearest point
//          of wall (or circle) w: the wall repulsion, by the agent's own
//          radius (no probe wider than the body);
//   s_i    the smallest gap d_ij - l_ij to a neighbour in front (e_i .
//          (x_j - x_i) >= 0) inside the corridor of the agent's body
//          (|e_i^perp . (x_j - x_i)| <= l_ij); +inf when there is none.
//
// Speed falls with the gap ahead, so the model brakes in a dense crowd and
// its flow follows the fundamental diagram instead of collapsing.
//
// The anticipation term A_ij (this engine's addition; the published model
// has no lateral avoidance, so two agents head-on on one line stop nose to
// nose for ever): a neighbour ahead that walks towards the agent, against or
// across its goal direction, and closes in at relative speed c > 0, is
// looked at where it will be at the time to contact tau = (d_ij - l_ij) / c:
// where it is for an oncoming walker, moved by its relative sideways speed
// times tau for one crossing the agent's way (walking 45-135 degrees off
// e0). If that lateral offset is within l_ij + side_margin of the agent's
// line and tau < avoid_time, it pushes the agent sideways, away from that
// side, with strength k (1 - tau / avoid_time) (1 - |offset| / band): beside
// an oncoming neighbour, behind a crossing one (heading for where a crosser
// is now leads in front of it, and both brake). A neighbour dead ahead is
// passed on the right: every agent keeps right, which breaks head-on and
// circle symmetries deterministically (the same bits for any thread count;
// no random draw) and lets counterflows sort into lanes. Only oncoming
// neighbours are extrapolated by their position, not their velocity: in a
// dense counterflow their sideways jostling would flip the side every step.
//
// Host+device; the kernels (simulation_kernels.cpp) feed neighbours from the
// 3x3 bins, tests call these functions on hand-computed cases.
#pragma once

#include <cmath>

#include "sim/geometry.h"
#include "sim/scenario.h"

namespace throng::sim {

// m/s: a neighbour walking towards the agent at least this fast is coming.
inline constexpr float kCfsOncoming = 0.05f;
// A coming neighbour is anticipated when its walking direction is at least
// 60 degrees off the agent's goal direction (cos 60 = 0.5): one in the same
// stream pushed back towards the agent (a jostling queue at a door) is not.
inline constexpr float kCfsAgainst = 0.5f;
// A neighbour walking at least this fast (m/s) with |cos| of its angle to
// the agent's goal direction below this crosses the agent's way (45-135
// degrees): its side is judged where it will be at contact.
inline constexpr float kCfsCrossingSpeed = 0.3f;
inline constexpr float kCfsCrossingCos = 0.7f;

// The agent being steered: position, velocity, radius, e0 and how far
// away its current waypoint or goal is (m).
struct CfsAgent {
  glm::vec2 p{0.0f};
  glm::vec2 v{0.0f};
  float radius = 0.2f;
  glm::vec2 e0{1.0f, 0.0f};
  float aim_distance = INFINITY;
};

// A_ij of neighbour j at offset d = q - p (dist = |d| > 0, u = d / dist,
// velocity w, l = r_i + r_j; `parked`: j stands at its goal for good),
// added to f when it applies. Only neighbours ahead along both the goal
// direction and the walked one (one the agent walks away from will not be
// met: anticipated, a walker beside it walking its way pushed it away from
// its goal for seconds), closing in, soon, near the agent's line, and
// walking towards it against or across its way (or parked for good). A
// slower walker ahead in the same direction is followed at the time gap,
// not dodged: dodging every slower neighbour spreads a queue sideways and
// chokes a door.
// The tests of A_ij that need only the offset d from the agent to the
// neighbour: ahead along e0 and not behind the walked direction (the far
// look sifts its candidates by them, add_far_anticipation in sense.h).
THRONG_HOST_DEVICE THRONG_INLINE bool cfs_ahead_of(const CfsAgent& i, glm::vec2 d) {
  const float ahead = dot2(d, i.e0), along_walk = dot2(d, i.v);
  return (ahead > 0.0f) & (along_walk >= 0.0f);
}
THRONG_HOST_DEVICE THRONG_INLINE void cfs_add_anticipation(const CfsAgent& i, glm::vec2 d, float dist, glm::vec2 u,
                                                           glm::vec2 w, float l, bool parked,
                                                           const CollisionFreeSpeedParams& m, glm::vec2& f) {
  const bool ahead = cfs_ahead_of(i, d);
  const float closing = -dot2(w - i.v, u);
  const bool towards = parked | (-dot2(w, u) > kCfsOncoming);
  // One branch on the five cheap tests (evaluated without short cuts).
  if ((m.avoid_strength > 0.0f) & towards & ahead & (closing > 1e-3f)) {
    // Past the cheap tests (most neighbours stop there): j's speed and heading.
    const float speed = length_of(w), along = dot2(w, i.e0);
    const bool against = parked || along < kCfsAgainst * speed;
    const float tau = fmaxf(dist - l, 0.0f) / closing;
    const glm::vec2 left = perp_left(i.e0);
    const bool crosser = speed > kCfsCrossingSpeed && fabsf(along) < kCfsCrossingCos * speed;
    const float lateral = dot2(d, left) + (crosser ? dot2(w - i.v, left) * tau : 0.0f);
    const float band = l + m.side_margin;
    if (against && tau < m.avoid_time && fabsf(lateral) < band) {
      const float strength = m.avoid_strength * (1.0f - tau / m.avoid_time) * (1.0f - fabsf(lateral) / band);
      // Away from the neighbour's side; dead ahead (within 1 cm), to the right.
      f += (lateral > 0.01f ? -left : (lateral < -0.01f ? left : -left)) * strength;
    }
  }
}

// R_ij + A_ij of neighbour j at q with velocity w and radius rj; `parked`:
// j stands at its goal for good.
THRONG_HOST_DEVICE THRONG_INLINE glm::vec2 cfs_neighbour_push(const CfsAgent& i, glm::vec2 q, glm::vec2 w, float rj,
                                                              bool parked, const CollisionFreeSpeedParams& m) {
  const glm::vec2 d = q - i.p;
  const float dist = length_of(d);
  if (dist <= 1e-6f) return glm::vec2(0.0f);  // coincident: the contact passes separate them
  const float l = i.radius + rj;
  const glm::vec2 u = d * (1.0f / dist);
  glm::vec2 f = u * (-m.neighbour_strength * expf((l - dist) / m.neighbour_range));
  cfs_add_anticipation(i, d, dist, u, w, l, parked, m, f);
  return f;
}

// The far look (this engine's addition). The bins' query radius reaches
// 0.5 avoid_time max_speed past contact, so two walkers closing at twice
// the walking speed first see each other about a second before avoid_time
// would have them dodge; in the circle of twenty the walkers from across
// the ring came into sight only 2 m from its middle, where ring neighbours
// already stood shoulder to shoulder, and the crowd jammed there. An agent
// walking at least kCfsFarSpeed of its preferred speed with at most
// kCfsFarCrowd neighbours within the query radius (people walking freely
// look further ahead; in a crowd those next to them fill their view) also
// anticipates neighbours out to cfs_far_reach: A_ij alone, from
// cfs_far_push. In crowds few agents qualify (the laboratory doors and the
// dense counterflow moved little); among free walkers it visits the
// candidates of up to 15 more cells, less those none of whose agents it
// could anticipate (cfs_cell_walks_along below; docs/simulation.md,
// Performance).
inline constexpr float kCfsFarSpeed = 0.5f;
inline constexpr int kCfsFarCrowd = 12;
// m: 2 max_radius + avoid_time max_speed, at most twice the query radius
// (so the 5 x 5 cells round an agent's hold it).
THRONG_HOST_DEVICE inline float cfs_far_reach(const ModelParams& m) {
  return 2.0f * m.max_radius() + m.cfs.avoid_time * m.max_speed;
}
THRONG_HOST_DEVICE inline bool cfs_looks_far(const CfsAgent& i, float v0, int nearby,
                                             const CollisionFreeSpeedParams& m) {
  return m.avoid_strength > 0.0f && nearby <= kCfsFarCrowd && length2(i.v) >= (kCfsFarSpeed * v0) * (kCfsFarSpeed * v0);
}
// A_ij of a neighbour beyond the query radius; true when it applies (f
// then holds it).
THRONG_HOST_DEVICE inline bool cfs_far_push(const CfsAgent& i, glm::vec2 q, glm::vec2 w, float rj, bool parked,
                                            const CollisionFreeSpeedParams& m, glm::vec2& f) {
  const glm::vec2 d = q - i.p;
  const float dist = length_of(d);
  f = glm::vec2(0.0f);
  cfs_add_anticipation(i, d, dist, d * (1.0f / dist), w, i.radius + rj, parked, m, f);
  return f.x != 0.0f || f.y != 0.0f;
}

// The far look passes over a whole cell none of whose agents it could
// anticipate (the same sums: such a cell adds nothing). The push needs a
// neighbour parked, or one closing in on the agent at more than
// kCfsOncoming (-w . u) and walking more than 60 degrees off the agent's e0
// (`against`). CellHeadings holds whether a cell must be looked at
// whatever e0 (somebody parked, or a velocity not finite) and the box of
// the unit walking directions of its agents faster than kCfsHeadingSpeed
// (slower ones cannot close in fast enough); any other cell whose box lies
// kCfsHeadingMargin inside cos 60 of e0 is passed over. In a stream, where
// everybody walks one way, that is nearly every cell; so is a cell where
// nobody walks faster than kCfsHeadingSpeed (and nobody is parked).
inline constexpr float kCfsHeadingSpeed = 0.8f * kCfsOncoming;  // m/s
inline constexpr float kCfsHeadingMargin = 0.01f;               // of the cosine: room for rounding
struct CellHeadings {
  glm::vec2 lo{INFINITY}, hi{-INFINITY};
  std::int32_t look = 0;  // 1: looked at for any e0
};
THRONG_HOST_DEVICE inline void add_heading(CellHeadings& h, glm::vec2 w, bool parked) {
  const float w2 = length2(w);
  // (An infinite component would leave a NaN direction out of the box.)
  h.look |= parked || !(w2 < INFINITY) ? 1 : 0;
  if (!(w2 >= kCfsHeadingSpeed * kCfsHeadingSpeed) || h.look != 0) return;
  const glm::vec2 u = w * (1.0f / sqrtf(w2));
  h.lo = {u.x < h.lo.x ? u.x : h.lo.x, u.y < h.lo.y ? u.y : h.lo.y};
  h.hi = {u.x > h.hi.x ? u.x : h.hi.x, u.y > h.hi.y ? u.y : h.hi.y};
}
// True when no agent of the cell can be anticipated by one with goal
// direction e0 (the least of e0 . u over the box is at one of its corners).
// Without a branch: the far look asks it of up to 16 cells per agent.
THRONG_HOST_DEVICE inline bool cfs_cell_walks_along(const CellHeadings& h, glm::vec2 e0) {
  const bool nobody_coming = h.lo.x > h.hi.x;  // nobody fast enough to be coming (the least is then NaN or inf)
  const float least = (e0.x >= 0.0f ? h.lo.x : h.hi.x) * e0.x + (e0.y >= 0.0f ? h.lo.y : h.hi.y) * e0.y;
  return (h.look == 0) & (nobody_coming | (least >= kCfsAgainst + kCfsHeadingMargin));
}

// W_iw of a wall point q (the nearest point of a segment or circle).
// A centre on the wall itself gets no push: the move stage's projection
// puts it back on its side.
THRONG_HOST_DEVICE inline glm::vec2 cfs_wall_push(const CfsAgent& i, glm::vec2 q, const CollisionFreeSpeedParams& m) {
  const glm::vec2 d = i.p - q;
  const float dist = length_of(d);
  if (dist <= 1e-6f) return glm::vec2(0.0f);
  return d * (m.wall_strength * expf((i.radius - dist) / m.wall_range) / dist);
}

// The gap to neighbour j if it is in front of the agent along e inside the
// agent's corridor, else +inf. The corridor is lane_width (r_i + r_j) to
// either side of the agent's line: 1 is the published model (whoever the
// body would touch), less lets staggered lanes interleave (a zipper).
THRONG_HOST_DEVICE inline float cfs_gap_ahead(glm::vec2 p, float ri, glm::vec2 e, glm::vec2 q, float rj,
                                              float lane_width = 1.0f) {
  const glm::vec2 d = q - p;
  if (dot2(d, e) < 0.0f) return INFINITY;
  const float l = ri + rj;
  if (fabsf(dot2(d, perp_left(e))) > l * lane_width) return INFINITY;
  return length_of(d) - l;
}

// Below this speed (m/s) an agent counts as held at rest by its neighbours
// (collision_free_velocity, sim/sense.h).
inline constexpr float kCfsBlockedSpeed = 0.05f;
// Of a neighbour at q that holds agent i at rest: true when it waits for i.
// One behind i on the way to i's goal ((q - p) . e0 < 0) waits: two agents
// pressed together at a door, one at the jamb and one beside it, each stand
// in the other's corridor and both stood still until the crowd shifted;
// the one further along goes first, as people do. One beside i (more than
// 60 degrees off e0: kCfsBesideCos) waits when `i_first`: three agents
// arched across a door's mouth, the two at the jambs slid along them into
// the middle one, each hold the next, and each has the next ahead of it
// (an arch, as in granular flow through a hopper). The caller
// (collision_free_velocity) lets an agent whose goal direction a wall slid
// go first, and, within kCfsNearWall of a wall, the lower index of two
// (the same for any thread count); away from walls (a jam in the open)
// nobody presses past a neighbour beside it, which kept bodies 3 cm deep
// in each other in the built-in circle's jam.
inline constexpr float kCfsBesideCos = 0.5f;
inline constexpr float kCfsNearWall = 1.0f;  // m from the agent's surface
THRONG_HOST_DEVICE inline bool cfs_waits_for(const CfsAgent& i, glm::vec2 q, bool i_first) {
  const float ahead = dot2(q - i.p, i.e0);
  return ahead < 0.0f || (i_first && ahead < kCfsBesideCos * length_of(q - i.p));
}

// Yielding to a walker abreast (this engine's addition). Two walkers side
// by side, each with its goal across the other's way (in the circle of 20,
// one bound south-east beside one bound west-north-west), walked on
// together for seconds, away from both goals: each is pushed off its goal
// direction by the other's repulsion as far as its goal pulls it across,
// and neither stands in the other's corridor, so neither brakes. People let
// the one a little ahead go first: an agent walking at least kCfsYieldSpeed
// with its goal more than 45 degrees off its heading (kCfsYieldGoalSide =
// sin 45) falls back to kCfsYieldShare of the speed of a neighbour beside
// it on that side (ahead of it by no more than it is beside it, within
// kCfsYieldGap, walking its way within 37 degrees, kCfsYieldAlong, at
// kCfsYieldSpeed or more along the agent's heading), and its goal leads it
// behind that neighbour. The speed floor keeps the rule out of jams: with
// a floor of 0.5 m/s, walkers shoved sideways in the dense counterflow
// yielded to each other and the streams locked in 2 of 16 draws, against
// none at 0.8 m/s.
inline constexpr float kCfsYieldSpeed = 0.8f;     // m/s
inline constexpr float kCfsYieldGoalSide = 0.7f;  // sin 45 degrees
inline constexpr float kCfsYieldAlong = 0.8f;     // cos 37 degrees
inline constexpr float kCfsYieldGap = 0.3f;       // m between the bodies
inline constexpr float kCfsYieldShare = 0.7f;

// When the agent may have to yield: the side of its heading its goal lies
// on (+1 left, -1 right; 0 when it walks slower than kCfsYieldSpeed or
// within 45 degrees of its goal: most agents, and no neighbour is looked
// at) and that heading (its unit velocity), found once for every neighbour.
struct CfsYield {
  float side = 0.0f;
  glm::vec2 heading{0.0f};
};
THRONG_HOST_DEVICE inline CfsYield cfs_yield(const CfsAgent& i) {
  const float speed2 = length2(i.v);
  if (speed2 < kCfsYieldSpeed * kCfsYieldSpeed) return {};
  const float across = dot2(i.e0, perp_left(i.v)) / sqrtf(speed2);
  const float side = across > kCfsYieldGoalSide ? 1.0f : (across < -kCfsYieldGoalSide ? -1.0f : 0.0f);
  return {side, i.v * (1.0f / sqrtf(speed2))};  // (normalize_or's bits)
}

// The most the agent walks beside neighbour j at q (velocity w, radius rj)
// when it may have to yield (cfs_yield, side not 0): +inf unless j walks
// abreast of it on its goal's side.
THRONG_HOST_DEVICE inline float cfs_yield_speed(const CfsAgent& i, const CfsYield& y, glm::vec2 q, glm::vec2 w,
                                                float rj) {
  const glm::vec2 h = y.heading, d = q - i.p;
  const float beside = dot2(d, perp_left(h)) * y.side, ahead = dot2(d, h), along = dot2(w, h);
  const bool abreast = beside > 0.0f && ahead > 0.0f && ahead <= beside && length_of(d) - i.radius - rj <= kCfsYieldGap;
  const bool our_way = along >= kCfsYieldSpeed && along >= kCfsYieldAlong * length_of(w);
  return abreast && our_way ? kCfsYieldShare * along : INFINITY;
}

// Neighbours close enough to hold an agent's speed that the pushes' pass
// keeps for the gap passes (collision_free_velocity): a disc of 1.7 m holds
// about 50 at 6 P/m^2.
inline constexpr int kCfsHolders = 64;

// The optimal-velocity function: the speed that keeps time gap T to the gap
// s ahead, within [0, v0].
THRONG_HOST_DEVICE inline float cfs_speed(float gap, float v0, float time_gap) {
  const float v = gap / time_gap;
  return v < 0.0f ? 0.0f : (v > v0 ? v0 : v);
}

// e0 slid along a wall the agent touches (nearest point q within the
// agent's radius + wall reach, outward normal n = (p - q)/|p - q|): the part
// of e0 into the wall is removed, so an agent pushed against a wall with its
// goal beyond the wall's end walks along it round the corner instead of
// standing still. Head-on into the wall (nothing left), it follows the wall
// to its right: a deterministic choice, like keeping right.
THRONG_HOST_DEVICE inline glm::vec2 cfs_slide_along_wall(glm::vec2 e0, glm::vec2 n) {
  const float into = dot2(e0, n);
  if (into >= 0.0f) return e0;
  const glm::vec2 along = e0 - n * into;
  if (length2(along) > 0.05f * 0.05f) return normalize_or(along, along);
  return glm::vec2(-n.y, n.x);  // the wall tangent to the right of walking into it (-n)
}

// Within kCfsSlideNear (m) of its waypoint or goal, an agent whose goal
// direction the walls turned (e0 slid along them to `slid`) walks no faster
// than v0 times the cosine of that turn, and at least kCfsSlideSlowest v0.
// It walks along the wall towards an opening near its goal (a door it was
// pushed beside): at full speed it cannot turn into an opening narrower
// than its turning circle (about v0 turn_time across), slides past it, and
// circles in front of the door for good (a 1.8 m/s walker at a 0.5 m door,
// docs/simulation.md). Further away it walks on at v0: an agent following
// a wall round a corner to a goal far beyond it does not slow.
inline constexpr float kCfsSlideNear = 2.0f;
inline constexpr float kCfsSlideSlowest = 0.3f;
// v0 times `factor` within kCfsSlideNear of the aim (between kCfsSlideSlowest
// and 1), v0 further away: the one rule of both slowdowns below.
THRONG_HOST_DEVICE inline float cfs_near_aim_speed(float factor, float aim_distance, float v0) {
  if (aim_distance >= kCfsSlideNear) return v0;
  return v0 * fminf(fmaxf(factor, kCfsSlideSlowest), 1.0f);
}
THRONG_HOST_DEVICE inline float cfs_slide_speed(glm::vec2 slid, glm::vec2 e0, float aim_distance, float v0) {
  if (slid.x == e0.x && slid.y == e0.y) return v0;
  return cfs_near_aim_speed(dot2(slid, e0), aim_distance, v0);
}

// Within kCfsSlideNear of its aim, an agent walking more than 60 degrees off
// its goal direction (e against e0; cos 60 = 0.5) slows with the turn, to
// kCfsSlideSlowest v0 at about 80 degrees: people slow to turn sharply. At
// full speed one that overshot a door narrower than its turning circle (a
// lone walker at a 0.5 m door led by the door line's gate) circled in front
// of it for good. Milder turns keep v0: jostled walkers near their goals
// do not brake.
THRONG_HOST_DEVICE inline float cfs_turn_speed(glm::vec2 e, glm::vec2 e0, float aim_distance, float v0) {
  return cfs_near_aim_speed(2.0f * dot2(e, e0), aim_distance, v0);
}

// The direction actually walked: the previous one turned towards the new one
// (at once when turn_time <= dt or the agent stood). A first-order model
// otherwise turns instantly, and agents pressed between neighbours flip
// direction every step; people and their animation cannot. The two are
// blended (previous (1 - a) + wanted a, a = dt / turn_time, normalised):
// about a of the angle between them when it is small, less and less as it
// nears 180 degrees, and nothing at 180. That keeps a walker pushed back in
// a jam facing its goal (its speed looks at the gap ahead of it; turning
// the angle itself made the built-in circle's jam clear 17% slower under
// the double buffer than under the four colours). But an agent walking
// away from its goal whose wanted direction points back to it (within 90
// degrees of e0, more than 150 degrees from the walk) was held there: a
// walker pushed back past the middle of the circle of twenty walked away
// from its goal at full speed for 4 s, its goal straight behind it every
// step. There it turns what the blend turns at 150 degrees (24 degrees a
// step at a = 1/3), towards the wanted side (straight back: to the right).
inline constexpr float kCfsTurnBackCos = 0.8660254f;  // cos 30 degrees
THRONG_HOST_DEVICE inline glm::vec2 cfs_turn(glm::vec2 previous, glm::vec2 wanted, glm::vec2 e0, float dt,
                                             float turn_time) {
  if (length2(previous) == 0.0f || turn_time <= dt) return wanted;
  const float a = dt / turn_time, along = dot2(previous, wanted);
  if (along >= -kCfsTurnBackCos || dot2(wanted, e0) <= 0.0f)
    return normalize_or(previous * (1.0f - a) + wanted * a, wanted);
  const float cross = previous.x * wanted.y - previous.y * wanted.x;
  const float turn = atan2f(a * 0.5f, 1.0f - a - a * kCfsTurnBackCos);  // the blend's turn at 150 degrees
  const float angle = cross > 0.0f ? turn : -turn;
  const float c = cosf(angle), s = sinf(angle);
  return {previous.x * c - previous.y * s, previous.x * s + previous.y * c};
}

// Walls (and circles) are sensed within this distance of the agent's
// surface: beyond it exp((r - d) / Dw) is below 1e-4 of the strength.
THRONG_HOST_DEVICE inline float cfs_wall_reach(const CollisionFreeSpeedParams& m) { return 9.2f * m.wall_range; }
// Neighbours repel within this gap (exp(-9.2) ~ 1e-4 of the strength).
THRONG_HOST_DEVICE inline float cfs_neighbour_reach(const CollisionFreeSpeedParams& m) {
  return 9.2f * m.neighbour_range;
}

}  // namespace throng::sim
