#include "path/roadmap.h"

#include <algorithm>
#include <boost/polygon/segment_data.hpp>
#include <boost/polygon/voronoi.hpp>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "core/error.h"

namespace throng::path {

namespace bp = boost::polygon;
using VoronoiDiagram = bp::voronoi_diagram<double>;

namespace {

struct DVec {
  double x = 0, y = 0;
};
DVec operator-(DVec a, DVec b) { return {a.x - b.x, a.y - b.y}; }
DVec operator+(DVec a, DVec b) { return {a.x + b.x, a.y + b.y}; }
DVec operator*(DVec a, double s) { return {a.x * s, a.y * s}; }
double dot(DVec a, DVec b) { return a.x * b.x + a.y * b.y; }
double norm(DVec a) { return std::sqrt(dot(a, a)); }

// A Voronoi site in integer units: a segment's interior or one endpoint.
struct Site {
  bool point = false;
  DVec a, b;  // a only for a point
  double distance(DVec p) const {
    if (point) return norm(p - a);
    const DVec ab = b - a;
    const double l2 = dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return norm(p - (a + ab * t));
  }
};

Site site_of(const VoronoiDiagram::cell_type& cell, const std::vector<bp::segment_data<int>>& segments) {
  const auto& s = segments[cell.source_index()];
  const DVec lo{static_cast<double>(bp::low(s).x()), static_cast<double>(bp::low(s).y())};
  const DVec hi{static_cast<double>(bp::high(s).x()), static_cast<double>(bp::high(s).y())};
  switch (cell.source_category()) {
    case bp::SOURCE_CATEGORY_SEGMENT_START_POINT: return {true, lo, lo};
    case bp::SOURCE_CATEGORY_SEGMENT_END_POINT: return {true, hi, hi};
    default: return {false, lo, hi};
  }
}

// An edge is cut into at most this many pieces per stretch: beyond
// kMaxPieces * max_step (256 m at the defaults) the pieces grow, so a huge,
// nearly empty world costs what it contains, not what it measures. Straight
// edges lose nothing (their clearance is linear or has its minimum sampled);
// an arc that long lies far from every site, where the tolerance matters
// least.
constexpr int kMaxPieces = 512;

// Points of the edge from v0 to v1 (integer units), dense enough that the
// polyline stays within `tol` of a parabolic arc and no piece exceeds `step`
// (up to kMaxPieces per stretch).
std::vector<DVec> discretize(DVec v0, DVec v1, const Site& s0, const Site& s1, bool curved, double tol, double step) {
  std::vector<DVec> pts;
  if (!curved) {
    // Straight: a line bisector. Add where the clearance to a point site is
    // smallest (the foot of the point), so the minimum is sampled exactly.
    std::vector<double> ts = {0.0, 1.0};
    const DVec d = v1 - v0;
    const double l2 = dot(d, d);
    for (const Site* s : {&s0, &s1})
      if (s->point && l2 > 0) {
        const double t = dot(s->a - v0, d) / l2;
        if (t > 0 && t < 1) ts.push_back(t);
      }
    std::sort(ts.begin(), ts.end());
    for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
      const double len = (ts[i + 1] - ts[i]) * std::sqrt(l2);
      const int n = std::clamp(static_cast<int>(std::ceil(len / step)), 1, kMaxPieces);
      for (int k = 0; k < n; ++k) pts.push_back(v0 + d * (ts[i] + (ts[i + 1] - ts[i]) * k / n));
    }
    pts.push_back(v1);
    return pts;
  }
  // Parabola: the points equidistant from a point P and a segment's line.
  // Local frame: origin at the segment's start, x along it, y towards P;
  // a point (x, y) of the arc has y = ((x - px)^2 + py^2) / (2 py).
  const Site& P = s0.point ? s0 : s1;
  const Site& S = s0.point ? s1 : s0;
  const DVec u = (S.b - S.a) * (1.0 / norm(S.b - S.a));
  DVec n{-u.y, u.x};
  double py = dot(P.a - S.a, n);
  if (py < 0) {
    n = n * -1.0;
    py = -py;
  }
  if (py < 1e-9) return discretize(v0, v1, s0, s1, false, tol, step);  // degenerate: the point on the line
  const double px = dot(P.a - S.a, u);
  const double x0 = dot(v0 - S.a, u), x1 = dot(v1 - S.a, u);
  auto at = [&](double x) { return S.a + u * x + n * (((x - px) * (x - px) + py * py) / (2 * py)); };
  // The arc's curvature is at most 1 / py (at its apex); a chord of length L
  // strays about L^2 kappa / 8 from it.
  const double chord = std::min(step, std::sqrt(8.0 * tol * py));
  std::vector<double> xs = {x0, x1};
  if ((px - x0) * (px - x1) < 0) xs.push_back(px);  // the apex: smallest clearance
  std::sort(xs.begin(), xs.end());
  if (x0 > x1) std::reverse(xs.begin(), xs.end());
  for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
    // Arc length over [xs[i], xs[i+1]] is at least the x span; sample by it,
    // refined where the arc is steep.
    const double dx = xs[i + 1] - xs[i];
    const double slope = std::max(std::fabs(xs[i] - px), std::fabs(xs[i + 1] - px)) / py;
    const double len = std::fabs(dx) * std::sqrt(1 + slope * slope);
    const int k =
        static_cast<int>(std::clamp(std::ceil(len / std::max(chord, 1e-9)), 1.0, static_cast<double>(kMaxPieces)));
    for (int j = 0; j < k; ++j) pts.push_back(at(xs[i] + dx * j / k));
  }
  pts.front() = v0;
  pts.push_back(v1);
  return pts;
}

struct UnionFind {
  std::vector<std::int32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[static_cast<std::size_t>(x)] != x)
      x = parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    return x;
  }
  void join(std::int32_t a, std::int32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
};

// Map point (m) of a point in integer units of resolution `res` (m).
glm::vec2 to_map(DVec p, double res) { return glm::vec2(static_cast<float>(p.x * res), static_cast<float>(p.y * res)); }

// Clearance (units) at p of an edge between sites s0 and s1.
double clearance_at(const Site& s0, const Site& s1, DVec p) { return std::min(s0.distance(p), s1.distance(p)); }

// Where the clearance rises through `keep` between `bad` (below) and `good`
// (at or above): bisection, the good side kept (units).
DVec crossing(const Site& s0, const Site& s1, double keep, DVec bad, DVec good) {
  for (int it = 0; it < 40; ++it) {
    const DVec m = (bad + good) * 0.5;
    (clearance_at(s0, s1, m) >= keep ? good : bad) = m;
  }
  return good;
}

// A stretch of an edge's polyline with its clearances (units).
struct Run {
  std::vector<DVec> pts;
  std::vector<double> c;
};

// Points i..j of `pts` (clearances c, all >= keep), extended to where the
// clearance crosses `keep` on the pieces before and after, repeated points
// dropped (a cut at a sample point). Units.
Run kept_run(const std::vector<DVec>& pts, const std::vector<double>& c, std::size_t i, std::size_t j, const Site& s0,
             const Site& s1, double keep) {
  std::vector<DVec> run;
  std::vector<double> run_c;
  if (i > 0) {
    const DVec p = crossing(s0, s1, keep, pts[i - 1], pts[i]);
    run.push_back(p);
    run_c.push_back(clearance_at(s0, s1, p));
  }
  for (std::size_t k = i; k <= j; ++k) {
    run.push_back(pts[k]);
    run_c.push_back(c[k]);
  }
  if (j + 1 < pts.size()) {
    const DVec p = crossing(s0, s1, keep, pts[j + 1], pts[j]);
    run.push_back(p);
    run_c.push_back(clearance_at(s0, s1, p));
  }
  Run poly;
  for (std::size_t k = 0; k < run.size(); ++k)
    if (poly.pts.empty() || norm(run[k] - poly.pts.back()) > 1e-9) {
      poly.pts.push_back(run[k]);
      poly.c.push_back(run_c[k]);
    }
  return poly;
}

// Adds nodes and edges to a roadmap under construction; a Voronoi vertex
// becomes one node however many edges reach it.
class RoadmapBuilder {
 public:
  RoadmapBuilder(Roadmap& map, double res) : map_(map), res_(res) {}

  // A node at p (units) with its clearance (units); returns its index.
  std::int32_t add_node(DVec p, double clearance) {
    map_.nodes.push_back(to_map(p, res_));
    map_.node_clearance.push_back(static_cast<float>(clearance * res_));
    return static_cast<std::int32_t>(map_.nodes.size() - 1);
  }

  std::int32_t node_of_vertex(const VoronoiDiagram::vertex_type* v, double clearance) {
    auto it = vertex_node_.find(v);
    if (it != vertex_node_.end()) return it->second;
    const std::int32_t id = add_node({v->x(), v->y()}, clearance);
    vertex_node_.emplace(v, id);
    return id;
  }

  // The run `poly` of Voronoi edge `edge` (from v0 to v1, units) as a
  // roadmap edge; its ends are the edge's vertices where they coincide,
  // else new nodes. Skipped when it is a loop of zero length.
  void add_edge(const VoronoiDiagram::edge_type& edge, DVec v0, DVec v1, const Run& poly) {
    const bool starts_at_vertex = norm(poly.pts.front() - v0) <= 1e-9,
               ends_at_vertex = norm(poly.pts.back() - v1) <= 1e-9;
    RoadmapEdge e;
    e.a =
        starts_at_vertex ? node_of_vertex(edge.vertex0(), poly.c.front()) : add_node(poly.pts.front(), poly.c.front());
    e.b = ends_at_vertex ? node_of_vertex(edge.vertex1(), poly.c.back()) : add_node(poly.pts.back(), poly.c.back());
    e.point_begin = static_cast<std::int32_t>(map_.points.size());
    e.point_count = static_cast<std::int32_t>(poly.pts.size());
    e.min_clearance = INFINITY;
    for (std::size_t k = 0; k < poly.pts.size(); ++k) {
      map_.points.push_back(to_map(poly.pts[k], res_));
      map_.point_clearance.push_back(static_cast<float>(poly.c[k] * res_));
      e.min_clearance = std::min(e.min_clearance, static_cast<float>(poly.c[k] * res_));
      if (k > 0) e.length += static_cast<float>(norm(poly.pts[k] - poly.pts[k - 1]) * res_);
    }
    if (e.a == e.b && e.length <= 0) return;
    map_.edges.push_back(e);
  }

 private:
  Roadmap& map_;
  double res_;
  std::unordered_map<const VoronoiDiagram::vertex_type*, std::int32_t> vertex_node_;
};

// One finite primary Voronoi edge: discretized (tol, step in units), kept
// only inside free space, and cut into runs of clearance >= keep (units),
// each added as a roadmap edge. Counts map.inside_edges.
void add_voronoi_edge(const FreeSpace& space, const VoronoiDiagram::edge_type& edge,
                      const std::vector<bp::segment_data<int>>& segments, double tol, double step, double keep,
                      Roadmap& map, RoadmapBuilder& builder) {
  const double res = space.resolution();
  const Site s0 = site_of(*edge.cell(), segments), s1 = site_of(*edge.twin()->cell(), segments);
  const DVec v0{edge.vertex0()->x(), edge.vertex0()->y()}, v1{edge.vertex1()->x(), edge.vertex1()->y()};
  const std::vector<DVec> pts = discretize(v0, v1, s0, s1, edge.is_curved(), tol, step);
  // Wholly inside or outside free space (an edge never crosses a site):
  // test a point away from the ends.
  const DVec mid = pts.size() > 2 ? pts[pts.size() / 2] : (pts.front() + pts.back()) * 0.5;
  if (!space.contains(to_map(mid, res))) return;
  ++map.inside_edges;
  std::vector<double> c(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) c[i] = clearance_at(s0, s1, pts[i]);

  // Cut the polyline where the clearance crosses `keep`; keep the runs above.
  std::size_t i = 0;
  while (i < pts.size()) {
    if (c[i] < keep) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < pts.size() && c[j + 1] >= keep) ++j;
    const Run poly = kept_run(pts, c, i, j, s0, s1, keep);
    i = j + 1;
    if (poly.pts.size() < 2) continue;
    builder.add_edge(edge, v0, v1, poly);
  }
}

// The map's adjacency (CSR, edges in index order at each node) and each
// node's connected component (its smallest node index).
void link_nodes(Roadmap& map) {
  const std::size_t n = map.nodes.size();
  map.adjacency_begin.assign(n + 1, 0);
  for (const RoadmapEdge& e : map.edges) {
    ++map.adjacency_begin[static_cast<std::size_t>(e.a) + 1];
    if (e.b != e.a) ++map.adjacency_begin[static_cast<std::size_t>(e.b) + 1];
  }
  std::partial_sum(map.adjacency_begin.begin(), map.adjacency_begin.end(), map.adjacency_begin.begin());
  map.adjacency.assign(static_cast<std::size_t>(map.adjacency_begin.back()), 0);
  std::vector<std::int32_t> cursor(map.adjacency_begin.begin(), map.adjacency_begin.end() - 1);
  UnionFind uf(n);
  for (std::size_t k = 0; k < map.edges.size(); ++k) {
    const RoadmapEdge& e = map.edges[k];
    map.adjacency[static_cast<std::size_t>(cursor[static_cast<std::size_t>(e.a)]++)] = static_cast<std::int32_t>(k);
    if (e.b != e.a)
      map.adjacency[static_cast<std::size_t>(cursor[static_cast<std::size_t>(e.b)]++)] = static_cast<std::int32_t>(k);
    uf.join(e.a, e.b);
  }
  map.node_component.resize(n);
  for (std::size_t k = 0; k < n; ++k) map.node_component[k] = uf.find(static_cast<std::int32_t>(k));
}

// One chain of the contraction: from a kept node along edge `first`
// through nodes of degree two to the next kept node.
struct Chain {
  std::int32_t from = 0, to = 0;
  std::vector<std::int32_t> point_ids;  // old point indices in walking order, junctions once
};

Chain walk_chain(const Roadmap& map, const std::vector<char>& kept, std::int32_t from, std::int32_t first,
                 std::vector<char>& consumed) {
  Chain c;
  c.from = from;
  std::int32_t node = from, e = first;
  for (;;) {
    consumed[static_cast<std::size_t>(e)] = 1;
    const RoadmapEdge& edge = map.edges[static_cast<std::size_t>(e)];
    const bool forward = edge.a == node;
    for (std::int32_t i = c.point_ids.empty() ? 0 : 1; i < edge.point_count; ++i)
      c.point_ids.push_back(edge.point_begin + (forward ? i : edge.point_count - 1 - i));
    node = forward ? edge.b : edge.a;
    if (kept[static_cast<std::size_t>(node)]) break;
    // A node of degree two: leave by its other edge.
    const std::int32_t k = map.adjacency_begin[static_cast<std::size_t>(node)];
    e = map.adjacency[static_cast<std::size_t>(k)] == e ? map.adjacency[static_cast<std::size_t>(k) + 1]
                                                        : map.adjacency[static_cast<std::size_t>(k)];
  }
  c.to = node;
  return c;
}

// Joins the edges meeting at nodes of degree two into one edge each: the
// medial axis of polygonal obstacles has a node wherever the nearest sites
// change, most of them on the way between two junctions, and a search over
// the junctions alone visits several times fewer nodes. A loop without a
// junction (round an obstacle in a ring-shaped room) keeps one of its nodes.
void contract_chains(Roadmap& map) {
  const std::size_t n = map.nodes.size();
  std::vector<char> kept(n, 1), consumed(map.edges.size(), 0);
  for (std::size_t v = 0; v < n; ++v) {
    const std::int32_t b = map.adjacency_begin[v], count = map.adjacency_begin[v + 1] - b;
    if (count != 2) continue;
    const RoadmapEdge& e0 = map.edges[static_cast<std::size_t>(map.adjacency[static_cast<std::size_t>(b)])];
    const RoadmapEdge& e1 = map.edges[static_cast<std::size_t>(map.adjacency[static_cast<std::size_t>(b) + 1])];
    kept[v] = e0.a == e0.b || e1.a == e1.b ? 1 : 0;
  }
  std::vector<Chain> chains;
  auto walk_from = [&](std::size_t v) {
    for (std::int32_t k = map.adjacency_begin[v]; k < map.adjacency_begin[v + 1]; ++k) {
      const std::int32_t e = map.adjacency[static_cast<std::size_t>(k)];
      if (!consumed[static_cast<std::size_t>(e)])
        chains.push_back(walk_chain(map, kept, static_cast<std::int32_t>(v), e, consumed));
    }
  };
  for (std::size_t v = 0; v < n; ++v)
    if (kept[v]) walk_from(v);
  for (std::size_t e = 0; e < map.edges.size(); ++e)
    if (!consumed[e]) {  // a loop of degree-two nodes only
      const auto v = static_cast<std::size_t>(map.edges[e].a);
      kept[v] = 1;
      walk_from(v);
    }
  std::vector<std::int32_t> new_index(n, -1);
  Roadmap out;
  for (std::size_t v = 0; v < n; ++v)
    if (kept[v]) {
      new_index[v] = static_cast<std::int32_t>(out.nodes.size());
      out.nodes.push_back(map.nodes[v]);
      out.node_clearance.push_back(map.node_clearance[v]);
    }
  for (const Chain& c : chains) {
    RoadmapEdge e;
    e.a = new_index[static_cast<std::size_t>(c.from)];
    e.b = new_index[static_cast<std::size_t>(c.to)];
    e.point_begin = static_cast<std::int32_t>(out.points.size());
    e.point_count = static_cast<std::int32_t>(c.point_ids.size());
    e.min_clearance = INFINITY;
    for (std::size_t k = 0; k < c.point_ids.size(); ++k) {
      const auto id = static_cast<std::size_t>(c.point_ids[k]);
      out.points.push_back(map.points[id]);
      out.point_clearance.push_back(map.point_clearance[id]);
      e.min_clearance = std::min(e.min_clearance, map.point_clearance[id]);
      if (k > 0) e.length += sim::length_of(out.points.back() - out.points[out.points.size() - 2]);
    }
    out.edges.push_back(e);
  }
  map.nodes = std::move(out.nodes);
  map.node_clearance = std::move(out.node_clearance);
  map.edges = std::move(out.edges);
  map.points = std::move(out.points);
  map.point_clearance = std::move(out.point_clearance);
  link_nodes(map);
}

}  // namespace

void RoadmapOptions::validate() const {
  if (!(std::isfinite(radius) && radius >= 0)) throw Error("radius must be >= 0", at_field("roadmap.radius"));
  if (!(std::isfinite(arc_tolerance) && arc_tolerance > 0 && arc_tolerance <= 1))
    throw Error("arc tolerance must be in (0, 1] m", at_field("roadmap.arc_tolerance"));
  if (!(std::isfinite(max_step) && max_step > 0)) throw Error("max step must be > 0", at_field("roadmap.max_step"));
}

// Stages: the Voronoi diagram of the boundary segments (integer units), its
// edges inside free space cut to the kept clearance, then adjacency.
Roadmap build_roadmap(const FreeSpace& space, const RoadmapOptions& options) {
  options.validate();
  Roadmap map;
  map.options = options;
  const double res = space.resolution();
  const double keep = options.kept_clearance(space.resolution()) / res;  // in units
  const double tol = options.arc_tolerance / res, step = options.max_step / res;

  std::vector<bp::segment_data<int>> segments;
  segments.reserve(space.boundary_units().size());
  for (const auto& s : space.boundary_units())
    segments.emplace_back(bp::point_data<int>(s.x0, s.y0), bp::point_data<int>(s.x1, s.y1));
  VoronoiDiagram vd;
  bp::construct_voronoi(segments.begin(), segments.end(), &vd);

  RoadmapBuilder builder(map, res);
  for (const auto& edge : vd.edges()) {
    if (!edge.is_primary() || edge.is_infinite() || edge.twin() < &edge) continue;
    ++map.voronoi_edges;
    add_voronoi_edge(space, edge, segments, tol, step, keep, map, builder);
  }
  link_nodes(map);
  contract_chains(map);
  map.index_pieces();
  return map;
}

namespace {

// The nearest point of piece k (points k, k + 1) to p, kept in `best` when
// nearer than what it holds (the lower piece on a tie, as a scan in order).
void offer_piece(const Roadmap& m, glm::vec2 p, std::int32_t k, EdgePoint& best) {
  const RoadmapEdge& edge = m.edges[static_cast<std::size_t>(m.point_edge[static_cast<std::size_t>(k)])];
  float t = 0;
  const glm::vec2 q = sim::closest_point_on_segment(p, m.points[static_cast<std::size_t>(k)],
                                                    m.points[static_cast<std::size_t>(k) + 1], &t);
  const float d = sim::length_of(p - q);
  const std::int32_t piece = k - edge.point_begin;
  if (d < best.distance || (d == best.distance && piece < best.piece)) {
    best.piece = piece;
    best.t = t;
    best.point = q;
    best.distance = d;
  }
}

// The `limit` nearest of one point per edge, nearest first, ties by edge.
std::vector<EdgePoint> nearest_first(std::vector<EdgePoint> best, std::int32_t limit) {
  auto closer = [](const EdgePoint& x, const EdgePoint& y) {
    return x.distance < y.distance || (x.distance == y.distance && x.edge < y.edge);
  };
  const std::size_t k = std::min(best.size(), static_cast<std::size_t>(std::max(0, limit)));
  std::partial_sort(best.begin(), best.begin() + static_cast<std::ptrdiff_t>(k), best.end(), closer);
  best.resize(k);
  return best;
}

}  // namespace

std::vector<EdgePoint> Roadmap::nearest_points_brute_force(glm::vec2 p, std::int32_t limit) const {
  std::vector<EdgePoint> best;
  best.reserve(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    EdgePoint ep;
    ep.edge = static_cast<std::int32_t>(e);
    for (std::int32_t i = 0; i + 1 < edges[e].point_count; ++i) offer_piece(*this, p, edges[e].point_begin + i, ep);
    if (ep.distance < INFINITY) best.push_back(ep);
  }
  return nearest_first(std::move(best), limit);
}

void Roadmap::index_pieces() {
  point_edge.assign(points.size(), -1);
  index_bounds = sim::Aabb{};
  for (glm::vec2 q : points) index_bounds.add(q);
  // Cells of a few pieces each where the roadmap is dense, never smaller
  // than two of its longest regular pieces (a huge nearly empty world has
  // few pieces, kilometres long: its cells grow with them).
  const double area = std::max(1.0, static_cast<double>(index_bounds.size().x) * index_bounds.size().y);
  index_cell = static_cast<float>(std::max(
      2.0 * options.max_step, 2.0 * std::sqrt(area / static_cast<double>(std::max<std::size_t>(1, points.size())))));
  std::vector<std::pair<std::uint64_t, std::int32_t>> pairs;
  for (std::size_t e = 0; e < edges.size(); ++e)
    for (std::int32_t i = 0; i < edges[e].point_count; ++i) {
      const std::int32_t k = edges[e].point_begin + i;
      point_edge[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(e);
      if (i + 1 < edges[e].point_count)
        add_segment_cells(points[static_cast<std::size_t>(k)], points[static_cast<std::size_t>(k) + 1], index_cell, k,
                          pairs);
    }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  piece_index = sim::StaticGrid(index_cell, std::move(pairs), Memory::Host);
}

// Rings of cells around p's cell: after ring k every piece within k cells of
// p has been offered, so an edge whose best point lies nearer than k cell
// sides is final; the search stops once `limit` edges are final or the rings
// cover the whole roadmap.
std::vector<EdgePoint> Roadmap::nearest_points(glm::vec2 p, std::int32_t limit) const {
  if (limit <= 0 || edges.empty()) return {};
  if (point_edge.size() != points.size()) return nearest_points_brute_force(p, limit);
  const sim::GridView g = piece_index.host_view();
  const std::int32_t cx = sim::cell_coord(p.x, index_cell), cy = sim::cell_coord(p.y, index_cell);
  const std::int32_t far = std::max({std::abs(cx - sim::cell_coord(index_bounds.min.x, index_cell)),
                                     std::abs(cx - sim::cell_coord(index_bounds.max.x, index_cell)),
                                     std::abs(cy - sim::cell_coord(index_bounds.min.y, index_cell)),
                                     std::abs(cy - sim::cell_coord(index_bounds.max.y, index_cell))});
  std::vector<EdgePoint> best;  // one per edge met, in the order met (few: a linear search finds them)
  for (std::int32_t k = 0; k <= far; ++k) {
    // A ring wider than the roadmap has pieces: one scan is cheaper.
    if (static_cast<std::size_t>(8 * k) > points.size()) return nearest_points_brute_force(p, limit);
    for (std::int32_t dy = -k; dy <= k; ++dy)
      for (std::int32_t dx = -k; dx <= k; dx += (std::abs(dy) == k ? 1 : 2 * k)) {
        const Index s = g.find(cx + dx, cy + dy);
        if (s < 0) continue;
        for (std::int32_t i = 0; i < g.count[s]; ++i) {
          const std::int32_t piece = g.items[g.start[s] + i];
          const std::int32_t e = point_edge[static_cast<std::size_t>(piece)];
          auto it = std::find_if(best.begin(), best.end(), [e](const EdgePoint& ep) { return ep.edge == e; });
          if (it == best.end()) it = best.insert(best.end(), EdgePoint{e, 0, 0.0f, glm::vec2(0.0f), INFINITY});
          offer_piece(*this, p, piece, *it);
        }
      }
    if (best.size() > 256) return nearest_points_brute_force(p, limit);  // the linear search would dominate
    const float reach = static_cast<float>(k) * index_cell;
    std::int32_t final_count = 0;
    for (const EdgePoint& ep : best) final_count += ep.distance < reach ? 1 : 0;
    if (final_count >= limit) break;
  }
  return nearest_first(std::move(best), limit);
}

}  // namespace throng::path
