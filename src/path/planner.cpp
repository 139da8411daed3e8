#include "path/planner.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <tuple>

#include "core/error.h"
#include "path/host_parallel.h"

namespace throng::path {

const char* to_string(PlanStatus s) {
  switch (s) {
    case PlanStatus::Found: return "found";
    case PlanStatus::StartBlocked: return "start_blocked";
    case PlanStatus::GoalBlocked: return "goal_blocked";
    case PlanStatus::Unreachable: return "unreachable";
  }
  return "?";
}

RoadmapOptions PlanOptions::roadmap_options() const {
  RoadmapOptions r;
  r.radius = radius;
  return r;
}

void PlanOptions::validate() const {
  if (!(std::isfinite(radius) && radius >= 0)) throw Error("radius must be >= 0", at_field("plan.radius"));
  if (!(std::isfinite(clearance_weight) && clearance_weight >= 0))
    throw Error("clearance weight must be >= 0", at_field("plan.clearance_weight"));
  if (!std::isfinite(shortcut_clearance) || (shortcut_clearance >= 0 && shortcut_clearance < radius))
    throw Error("shortcut clearance must be >= radius (or negative for the default)",
                at_field("plan.shortcut_clearance"));
  if (!(std::isfinite(corner_radius) && corner_radius >= 0))
    throw Error("corner radius must be >= 0", at_field("plan.corner_radius"));
  if (attach_candidates < 1) throw Error("attach candidates must be >= 1", at_field("plan.attach_candidates"));
  free_space.validate();
}

float polyline_length(std::span<const glm::vec2> points) {
  float len = 0;
  for (std::size_t i = 1; i < points.size(); ++i) len += sim::length_of(points[i] - points[i - 1]);
  return len;
}

namespace {

// Cost of a whole roadmap edge (cumulative cost at its last point).
float edge_total(std::span<const float> cumulative_cost, const RoadmapEdge& edge) {
  return cumulative_cost[static_cast<std::size_t>(edge.point_begin + edge.point_count - 1)];
}

// Cheapest cost from `source` to every node (INFINITY where unreachable).
std::vector<float> node_costs_from(const Roadmap& m, std::span<const float> cumulative_cost, std::int32_t source) {
  std::vector<float> cost(static_cast<std::size_t>(m.node_count()), INFINITY);
  using Entry = std::pair<float, std::int32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  cost[static_cast<std::size_t>(source)] = 0;
  open.push({0.0f, source});
  while (!open.empty()) {
    const auto [c, v] = open.top();
    open.pop();
    if (c > cost[static_cast<std::size_t>(v)]) continue;
    for (std::int32_t k = m.adjacency_begin[static_cast<std::size_t>(v)];
         k < m.adjacency_begin[static_cast<std::size_t>(v) + 1]; ++k) {
      const RoadmapEdge& edge = m.edges[static_cast<std::size_t>(m.adjacency[static_cast<std::size_t>(k)])];
      const std::int32_t to = edge.a == v ? edge.b : edge.a;
      const float c2 = c + edge_total(cumulative_cost, edge);
      if (c2 < cost[static_cast<std::size_t>(to)]) {
        cost[static_cast<std::size_t>(to)] = c2;
        open.push({c2, to});
      }
    }
  }
  return cost;
}

}  // namespace

// Landmarks by farthest-point selection: the first is the node farthest
// from node 0 in cost, each next the node farthest from those chosen (over
// every component: a node another component's landmarks cannot reach is
// farthest of all). Farther landmarks bound more routes well.
RoadmapLandmarks choose_landmarks(const Roadmap& m, std::span<const float> cumulative_cost, std::int32_t count) {
  RoadmapLandmarks out;
  const auto n = static_cast<std::size_t>(m.node_count());
  if (n == 0) return out;
  std::vector<float> nearest(n, INFINITY);  // cost to the nearest landmark chosen so far
  std::int32_t next = 0;
  {
    const std::vector<float> from0 = node_costs_from(m, cumulative_cost, 0);
    for (std::size_t v = 0; v < n; ++v)
      if (from0[v] < INFINITY && from0[v] > from0[static_cast<std::size_t>(next)]) next = static_cast<std::int32_t>(v);
  }
  for (std::int32_t l = 0; l < count; ++l) {
    const std::vector<float> cost = node_costs_from(m, cumulative_cost, next);
    out.cost.insert(out.cost.end(), cost.begin(), cost.end());
    ++out.count;
    std::int32_t far = -1;
    for (std::size_t v = 0; v < n; ++v) {
      nearest[v] = std::min(nearest[v], cost[v]);
      if (far < 0 || nearest[v] > nearest[static_cast<std::size_t>(far)]) far = static_cast<std::int32_t>(v);
    }
    if (!(nearest[static_cast<std::size_t>(far)] > 0)) break;  // every node is a landmark
    next = far;
  }
  // Node-major: a node's costs to every landmark side by side.
  std::vector<float> by_node(out.cost.size());
  for (std::int32_t l = 0; l < out.count; ++l)
    for (std::size_t v = 0; v < n; ++v)
      by_node[v * static_cast<std::size_t>(out.count) + static_cast<std::size_t>(l)] =
          out.cost[static_cast<std::size_t>(l) * n + v];
  out.cost = std::move(by_node);
  return out;
}

float RoadmapLandmarks::lower_bound(std::int32_t v, std::span<const float> goal_cost) const {
  float best = 0;
  for (std::int32_t l = 0; l < count; ++l) {
    const float a = at(v, l), b = goal_cost[static_cast<std::size_t>(l)];
    if (a < INFINITY && b < INFINITY) best = std::max(best, std::fabs(a - b));
  }
  return best;
}

Planner Planner::build(const sim::World& world, const PlanOptions& options) {
  options.validate();
  return build(FreeSpace::build(world, options.free_space), options);
}

Planner Planner::build(FreeSpace space, const PlanOptions& options) {
  options.validate();
  Planner p;
  p.options_ = options;
  p.space_ = std::move(space);
  p.roadmap_ = build_roadmap(p.space_, options.roadmap_options());
  const Roadmap& m = p.roadmap_;
  p.cumulative_cost_.assign(m.points.size(), 0.0f);
  for (const RoadmapEdge& e : m.edges) {
    float acc = 0;
    for (std::int32_t i = 1; i < e.point_count; ++i) {
      const auto k = static_cast<std::size_t>(e.point_begin + i);
      const float len = sim::length_of(m.points[k] - m.points[k - 1]);
      const float c = std::max(0.5f * (m.point_clearance[k] + m.point_clearance[k - 1]), 1e-6f);
      acc += len * (1.0f + options.clearance_weight * options.radius / c);
      p.cumulative_cost_[k] = acc;
    }
  }
  // Eight landmarks: the bound tightens little with more, each costs a
  // search over the roadmap at build and a float per node.
  p.landmarks_ = choose_landmarks(m, p.cumulative_cost_, 8);
  return p;
}

EdgePoint Planner::attach(glm::vec2 p) const {
  const float r = options_.radius;
  // The nearest few usually answer; the lists are prefixes of each other,
  // so trying fewer first never changes the point chosen.
  for (std::int32_t limit :
       {std::min(4, options_.attach_candidates), options_.attach_candidates, roadmap_.edge_count()}) {
    for (const EdgePoint& e : roadmap_.nearest_points(p, limit))
      if (space_.segment_clear(p, e.point, r)) return e;
    if (limit >= roadmap_.edge_count()) break;
  }
  return {};
}

float Planner::cost_to_edge_start(const EdgePoint& e) const {
  const RoadmapEdge& edge = roadmap_.edges[static_cast<std::size_t>(e.edge)];
  const auto k = static_cast<std::size_t>(edge.point_begin + e.piece);
  return cumulative_cost_[k] + e.t * (cumulative_cost_[k + 1] - cumulative_cost_[k]);
}

namespace {

void push_point(std::vector<glm::vec2>& out, glm::vec2 p) {
  if (out.empty() || sim::length2(out.back() - p) > 1e-12f) out.push_back(p);
}

// Polyline points of `edge` strictly between the attach point and its end
// at node side `to_b` (true: towards b).
void append_partial(const Roadmap& m, const EdgePoint& at, bool to_b, std::vector<glm::vec2>& out) {
  const RoadmapEdge& e = m.edges[static_cast<std::size_t>(at.edge)];
  if (to_b)
    for (std::int32_t i = at.piece + 1; i < e.point_count; ++i) push_point(out, m.edge_point(at.edge, i));
  else
    for (std::int32_t i = at.piece; i >= 0; --i) push_point(out, m.edge_point(at.edge, i));
}

// Where a query's start and goal join the roadmap, with the costs the search
// needs: along the attach edges from their node a and in all (cost units),
// and the straight attach lengths (m).
struct Attachment {
  EdgePoint s, g;
  RoadmapEdge se, ge;  // the edges s and g lie on
  float s_from_a = 0, g_from_a = 0, s_total = 0, g_total = 0, s_attach = 0, g_attach = 0;
};

// The attachment of start s and goal g (both on an edge); s_from_a and
// g_from_a are their costs from their edges' node a.
Attachment attachment(const Roadmap& m, std::span<const float> cumulative_cost, const PathQuery& q, const EdgePoint& s,
                      const EdgePoint& g, float s_from_a, float g_from_a) {
  Attachment at;
  at.s = s;
  at.g = g;
  at.se = m.edges[static_cast<std::size_t>(s.edge)];
  at.ge = m.edges[static_cast<std::size_t>(g.edge)];
  at.s_from_a = s_from_a;
  at.g_from_a = g_from_a;
  at.s_total = edge_total(cumulative_cost, at.se);
  at.g_total = edge_total(cumulative_cost, at.ge);
  at.s_attach = sim::length_of(s.point - q.start);
  at.g_attach = sim::length_of(g.point - q.goal);
  return at;
}

// A* from S (node n, the start) to G (node n + 1, the goal) over the roadmap
// nodes. Returns the chain of nodes S..G, empty when G is not reached (or
// start and goal lie in different components).
std::vector<std::int32_t> search(const Roadmap& m, std::span<const float> cumulative_cost,
                                 const RoadmapLandmarks& landmarks, const PathQuery& q, const Attachment& at) {
  const std::int32_t n = m.node_count();
  const std::int32_t S = n, G = n + 1;
  const RoadmapEdge& se = at.se;
  const RoadmapEdge& ge = at.ge;
  if (m.node_component[static_cast<std::size_t>(se.a)] != m.node_component[static_cast<std::size_t>(ge.a)]) return {};
  std::vector<float> cost(static_cast<std::size_t>(n + 2), INFINITY);
  std::vector<std::int32_t> parent(static_cast<std::size_t>(n + 2), -1);
  // The goal's cost from each landmark: through either end of its edge.
  std::vector<float> goal_cost(static_cast<std::size_t>(landmarks.count));
  for (std::int32_t l = 0; l < landmarks.count; ++l) {
    goal_cost[static_cast<std::size_t>(l)] =
        std::min(landmarks.at(ge.a, l) + at.g_from_a, landmarks.at(ge.b, l) + at.g_total - at.g_from_a) + at.g_attach;
  }
  auto h = [&](std::int32_t v) {
    if (v == G) return 0.0f;
    if (v == S) return sim::length_of(q.start - q.goal);
    return std::max(sim::length_of(m.nodes[static_cast<std::size_t>(v)] - q.goal), landmarks.lower_bound(v, goal_cost));
  };
  // (f, node, cost when pushed): ties broken by node index; an entry whose
  // cost is above the node's current one is stale.
  using Entry = std::tuple<float, std::int32_t, float>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  auto relax = [&](std::int32_t from, std::int32_t to, float c) {
    const float g2 = cost[static_cast<std::size_t>(from)] + c;
    if (g2 < cost[static_cast<std::size_t>(to)]) {
      cost[static_cast<std::size_t>(to)] = g2;
      parent[static_cast<std::size_t>(to)] = from;
      open.push({g2 + h(to), to, g2});
    }
  };
  cost[static_cast<std::size_t>(S)] = 0;
  open.push({h(S), S, 0.0f});
  while (!open.empty()) {
    const auto [f, v, g] = open.top();
    open.pop();
    if (g > cost[static_cast<std::size_t>(v)]) continue;  // stale
    if (v == G) break;
    if (v == S) {
      relax(S, se.a, at.s_attach + at.s_from_a);
      relax(S, se.b, at.s_attach + at.s_total - at.s_from_a);
      if (at.s.edge == at.g.edge) relax(S, G, at.s_attach + std::fabs(at.g_from_a - at.s_from_a) + at.g_attach);
      continue;
    }
    if (v == ge.a) relax(v, G, at.g_from_a + at.g_attach);
    if (v == ge.b) relax(v, G, at.g_total - at.g_from_a + at.g_attach);
    for (std::int32_t k = m.adjacency_begin[static_cast<std::size_t>(v)];
         k < m.adjacency_begin[static_cast<std::size_t>(v) + 1]; ++k) {
      const std::int32_t e = m.adjacency[static_cast<std::size_t>(k)];
      const RoadmapEdge& edge = m.edges[static_cast<std::size_t>(e)];
      relax(v, edge.a == v ? edge.b : edge.a, edge_total(cumulative_cost, edge));
    }
  }
  std::vector<std::int32_t> chain;
  if (!(cost[static_cast<std::size_t>(G)] < INFINITY)) return chain;
  for (std::int32_t v = G; v >= 0; v = parent[static_cast<std::size_t>(v)]) chain.push_back(v);
  std::reverse(chain.begin(), chain.end());
  return chain;
}

// Appends the polyline of the cheapest edge joining nodes u and v, from u
// to v (what the search relaxed between them).
void append_cheapest_edge(const Roadmap& m, std::span<const float> cumulative_cost, std::int32_t u, std::int32_t v,
                          std::vector<glm::vec2>& raw) {
  std::int32_t best = -1;
  float best_cost = INFINITY;
  for (std::int32_t a = m.adjacency_begin[static_cast<std::size_t>(u)];
       a < m.adjacency_begin[static_cast<std::size_t>(u) + 1]; ++a) {
    const std::int32_t e = m.adjacency[static_cast<std::size_t>(a)];
    const RoadmapEdge& edge = m.edges[static_cast<std::size_t>(e)];
    if (!((edge.a == u && edge.b == v) || (edge.a == v && edge.b == u))) continue;
    const float c = edge_total(cumulative_cost, edge);
    if (c < best_cost) {
      best_cost = c;
      best = e;
    }
  }
  const RoadmapEdge& edge = m.edges[static_cast<std::size_t>(best)];
  if (edge.a == u)
    for (std::int32_t i = 0; i < edge.point_count; ++i) push_point(raw, m.edge_point(best, i));
  else
    for (std::int32_t i = edge.point_count - 1; i >= 0; --i) push_point(raw, m.edge_point(best, i));
}

// The roadmap polyline (m) of a found chain S..G: start, its attach point,
// the edges between the chain's nodes, the goal's attach point, goal.
std::vector<glm::vec2> chain_polyline(const Roadmap& m, std::span<const float> cumulative_cost, const PathQuery& q,
                                      const Attachment& at, const std::vector<std::int32_t>& chain) {
  const EdgePoint& s = at.s;
  const EdgePoint& g = at.g;
  const RoadmapEdge& se = at.se;
  const RoadmapEdge& ge = at.ge;
  std::vector<glm::vec2> raw;
  push_point(raw, q.start);
  push_point(raw, s.point);
  if (chain.size() == 2) {  // S -> G along the shared edge
    const bool forward = s.piece < g.piece || (s.piece == g.piece && s.t <= g.t);
    if (forward)
      for (std::int32_t i = s.piece + 1; i <= g.piece; ++i) push_point(raw, m.edge_point(s.edge, i));
    else
      for (std::int32_t i = s.piece; i > g.piece; --i) push_point(raw, m.edge_point(s.edge, i));
  } else {
    append_partial(m, s, chain[1] == se.b && !(chain[1] == se.a && at.s_from_a <= at.s_total - at.s_from_a), raw);
    for (std::size_t k = 1; k + 2 < chain.size(); ++k)
      append_cheapest_edge(m, cumulative_cost, chain[k], chain[k + 1], raw);
    // From the last node along the goal's edge to its attach point.
    const std::int32_t last = chain[chain.size() - 2];
    const bool from_a = last == ge.a && !(last == ge.b && at.g_total - at.g_from_a < at.g_from_a);
    if (from_a)
      for (std::int32_t i = 0; i <= g.piece; ++i) push_point(raw, m.edge_point(g.edge, i));
    else
      for (std::int32_t i = ge.point_count - 1; i > g.piece; --i) push_point(raw, m.edge_point(g.edge, i));
  }
  push_point(raw, g.point);
  push_point(raw, q.goal);
  return raw;
}

}  // namespace

// Stages: start and goal checks; the straight line, or attachment, search
// and chain polyline; then smoothing and the path's length.
PlannedPath Planner::plan(const PathQuery& q) const {
  PlannedPath out;
  const float r = options_.radius;
  if (!space_.contains(q.start) || space_.boundary_distance(q.start) < r) {
    out.status = PlanStatus::StartBlocked;
    return out;
  }
  if (!space_.contains(q.goal) || space_.boundary_distance(q.goal) < r) {
    out.status = PlanStatus::GoalBlocked;
    return out;
  }
  std::vector<glm::vec2> raw;
  if (!q.straight_blocked && space_.segment_clear(q.start, q.goal, r, true)) {
    raw = {q.start, q.goal};
  } else {
    const EdgePoint s = attach(q.start), g = attach(q.goal);
    if (s.edge < 0 || g.edge < 0) {
      out.status = PlanStatus::Unreachable;
      return out;
    }
    const Attachment at = attachment(roadmap_, cumulative_cost_, q, s, g, cost_to_edge_start(s), cost_to_edge_start(g));
    const std::vector<std::int32_t> chain = search(roadmap_, cumulative_cost_, landmarks_, q, at);
    if (chain.empty()) {
      out.status = PlanStatus::Unreachable;
      return out;
    }
    raw = chain_polyline(roadmap_, cumulative_cost_, q, at, chain);
  }
  out.status = PlanStatus::Found;
  out.points = options_.smooth ? shortcut(raw, options_.kept_clearance()) : raw;
  out.roadmap_points = std::move(raw);
  if (options_.smooth && options_.corner_radius > 0) out.points = round_corners(out.points, options_.corner_radius);

  out.length = polyline_length(out.points);
  return out;
}

std::vector<glm::vec2> Planner::shortcut(std::span<const glm::vec2> poly, float clearance) const {
  if (poly.size() <= 2) return {poly.begin(), poly.end()};
  // Every point of the polyline is in free space (the start, the goal and
  // the roadmap's points), so the line-of-sight tests skip containment.
  auto visible = [&](std::size_t a, std::size_t b) { return space_.segment_clear(poly[a], poly[b], clearance, true); };
  // Greedy sweep: from each kept point the farthest point found visible by
  // steps that double while the line of sight holds, then halve between the
  // last visible and the first hidden one (a route of a kilometre has
  // thousands of roadmap points: a point-by-point sweep tests them all).
  std::vector<std::size_t> pass = {0};
  std::size_t i = 0;
  while (i + 1 < poly.size()) {
    std::size_t seen = i + 1, step = 1;
    while (seen + step < poly.size() && visible(i, seen + step)) {
      seen += step;
      step *= 2;
    }
    std::size_t hidden = std::min(seen + step, poly.size());  // hidden, or past the end
    while (hidden - seen > 1) {
      const std::size_t mid = seen + (hidden - seen) / 2;
      (visible(i, mid) ? seen : hidden) = mid;
    }
    pass.push_back(seen);
    i = seen;
  }
  std::vector<glm::vec2> out;
  if (pass.size() > 256) {
    for (std::size_t k : pass) out.push_back(poly[k]);
    return out;
  }
  // Farthest visible point from each kept point.
  out.push_back(poly[0]);
  i = 0;
  while (i + 1 < pass.size()) {
    std::size_t j = pass.size() - 1;
    while (j > i + 1 && !visible(pass[i], pass[j])) --j;
    out.push_back(poly[pass[j]]);
    i = j;
  }
  return out;
}

std::vector<glm::vec2> Planner::round_corners(std::span<const glm::vec2> poly, float radius) const {
  if (poly.size() <= 2) return {poly.begin(), poly.end()};
  std::vector<glm::vec2> out = {poly[0]};
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
    const glm::vec2 p = poly[i];
    const float len_in = sim::length_of(p - poly[i - 1]), len_out = sim::length_of(poly[i + 1] - p);
    const glm::vec2 a = (p - poly[i - 1]) / len_in, b = (poly[i + 1] - p) / len_out;
    const float turn = std::acos(std::clamp(sim::dot2(a, b), -1.0f, 1.0f));
    std::vector<glm::vec2> arc;
    if (turn > 1e-3f && turn < 3.1f) {
      const float half = std::tan(0.5f * turn);
      // Tangent length L = rho tan(turn / 2), at most 45 % of either edge.
      float rho = std::min(radius, 0.45f * std::min(len_in, len_out) / half);
      const float side = sim::cross2(a, b) > 0 ? 1.0f : -1.0f;
      for (int attempt = 0; attempt < 5 && arc.empty(); ++attempt, rho *= 0.5f) {
        const float L = rho * half;
        const glm::vec2 t1 = p - a * L, centre = t1 + sim::perp_left(a) * (side * rho);
        const int steps = std::max(2, static_cast<int>(std::ceil(turn / 0.1f)));
        std::vector<glm::vec2> pts;
        for (int k = 0; k <= steps; ++k) {
          const float ang = side * turn * static_cast<float>(k) / static_cast<float>(steps);
          const glm::vec2 r0 = t1 - centre;
          pts.push_back(centre + glm::vec2(r0.x * std::cos(ang) - r0.y * std::sin(ang),
                                           r0.x * std::sin(ang) + r0.y * std::cos(ang)));
        }
        bool clear = true;
        for (std::size_t k = 1; k < pts.size() && clear; ++k)
          clear = space_.segment_clear(pts[k - 1], pts[k], options_.radius, true);  // from a free point
        if (clear) arc = std::move(pts);
      }
    }
    if (arc.empty()) {
      push_point(out, p);
    } else {
      for (glm::vec2 q : arc) push_point(out, q);
    }
  }
  push_point(out, poly.back());
  return out;
}

std::vector<PlannedPath> Planner::plan_all(std::span<const PathQuery> queries) const {
  std::vector<PlannedPath> out(queries.size());
  host_parallel_for("path.plan", static_cast<Index>(queries.size()),
                    [&](Index i) { out[static_cast<std::size_t>(i)] = plan(queries[static_cast<std::size_t>(i)]); });
  return out;
}

}  // namespace throng::path
