#include "path/free_space.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/polygon/polygon.hpp>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace throng::path {

namespace bp = boost::polygon;
using IPoint = bp::point_data<int>;
using IPolygon = bp::polygon_data<int>;
using IPolygonWithHoles = bp::polygon_with_holes_data<int>;
using IPolygonSet = bp::polygon_set_data<int>;

namespace {

// Largest |coordinate| in integer units; Boost's boolean operations and
// Voronoi predicates stay exact well inside 32 bits.
constexpr double kUnitLimit = 1073741824.0;  // 2^30

void require(bool ok, const std::string& field, const std::string& what) {
  if (!ok) throw Error(what, at_field(field));
}

struct Snapper {
  double scale;
  int unit(float v, const char* what) const {
    const double u = std::round(static_cast<double>(v) * scale);
    if (!std::isfinite(u) || std::fabs(u) > kUnitLimit)
      throw Error(fmt::format("{} coordinate {} m is beyond the snapped range of +-{:.0f} m at this resolution", what,
                              v, kUnitLimit / scale),
                  at_field("free_space.resolution"));
    return static_cast<int>(u);
  }
  IPoint point(glm::vec2 p, const char* what) const { return IPoint(unit(p.x, what), unit(p.y, what)); }
  IPolygon ring(const sim::Ring& r, const char* what) const {
    std::vector<IPoint> pts;
    pts.reserve(r.size());
    for (glm::vec2 p : r) {
      const IPoint q = point(p, what);
      if (pts.empty() || !(pts.back() == q)) pts.push_back(q);
    }
    IPolygon poly;
    poly.set(pts.begin(), pts.end());
    return poly;
  }
};

sim::Ring to_ring(const IPolygon& p, double inv_scale) {
  sim::Ring r;
  for (auto it = p.begin(); it != p.end(); ++it)
    r.emplace_back(static_cast<float>(it->x() * inv_scale), static_cast<float>(it->y() * inv_scale));
  return r;
}

}  // namespace

void FreeSpaceOptions::validate() const {
  require(std::isfinite(resolution) && resolution >= 1e-6f && resolution <= 1.0f, "free_space.resolution",
          "resolution must be in [1e-6, 1] m");
  require(std::isfinite(circle_tolerance) && circle_tolerance > 0 && circle_tolerance <= 1.0f,
          "free_space.circle_tolerance", "circle tolerance must be in (0, 1] m");
  require(std::isfinite(margin) && margin >= 0, "free_space.margin", "margin must be >= 0");
  require(std::isfinite(cell_size) && cell_size >= 0, "free_space.cell_size", "cell size must be >= 0 (0 = automatic)");
}

std::int32_t circle_polygon_sides(float radius, float tolerance) {
  if (!(radius > 0)) return 8;
  // Vertices of the circumscribed n-gon lie at r / cos(pi / n) <= r + tolerance.
  const double c = static_cast<double>(radius) / (static_cast<double>(radius) + tolerance);
  const double n = std::ceil(std::numbers::pi / std::acos(c));
  return static_cast<std::int32_t>(std::clamp(n, 8.0, 1024.0));
}

sim::Ring circumscribed_polygon(const sim::Circle& c, float tolerance) {
  const std::int32_t n = circle_polygon_sides(c.radius, tolerance);
  const double R = c.radius / std::cos(std::numbers::pi / n);
  sim::Ring ring;
  ring.reserve(static_cast<std::size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n;
    ring.emplace_back(static_cast<float>(c.center.x + R * std::cos(a)),
                      static_cast<float>(c.center.y + R * std::sin(a)));
  }
  return ring;
}

FreeSpace FreeSpace::build(const sim::World& world, const FreeSpaceOptions& options) {
  return build(world.has_walkable() ? &world.walkable() : nullptr, world.polygons(), world.circles(), options);
}

FreeSpace FreeSpace::build(const sim::Polygon* walkable, const std::vector<sim::Polygon>& obstacles,
                           const std::vector<sim::Circle>& circles, const FreeSpaceOptions& options) {
  using namespace bp::operators;
  options.validate();
  FreeSpace fs;
  fs.options_ = options;
  const Snapper snap{1.0 / options.resolution};

  IPolygonSet blocked;
  sim::Aabb all = options.extent;
  for (const sim::Polygon& p : obstacles) {
    if (p.outer.size() < 3) continue;
    IPolygonWithHoles pwh;
    const IPolygon outer = snap.ring(p.outer, "obstacle");
    std::vector<IPolygon> holes;
    for (const sim::Ring& h : p.holes)
      if (h.size() >= 3) holes.push_back(snap.ring(h, "obstacle"));
    pwh.set(outer.begin(), outer.end());
    pwh.set_holes(holes.begin(), holes.end());
    blocked.insert(pwh);
    all.add(sim::bounds(p));
  }
  for (const sim::Circle& c : circles) {
    if (!(c.radius > 0)) continue;
    blocked.insert(snap.ring(circumscribed_polygon(c, options.circle_tolerance), "circle"));
    all.add(sim::bounds(c));
  }

  IPolygonSet domain;
  if (walkable != nullptr) {
    IPolygonWithHoles pwh;
    const IPolygon outer = snap.ring(walkable->outer, "walkable");
    std::vector<IPolygon> holes;
    for (const sim::Ring& h : walkable->holes)
      if (h.size() >= 3) holes.push_back(snap.ring(h, "walkable"));
    pwh.set(outer.begin(), outer.end());
    pwh.set_holes(holes.begin(), holes.end());
    domain.insert(pwh);
  } else {
    if (all.empty()) all.add(glm::vec2(0.0f));
    const glm::vec2 lo = all.min - glm::vec2(options.margin), hi = all.max + glm::vec2(options.margin);
    domain.insert(bp::rectangle_data<int>(snap.unit(lo.x, "extent"), snap.unit(lo.y, "extent"),
                                          snap.unit(hi.x, "extent"), snap.unit(hi.y, "extent")));
  }

  const IPolygonSet free_set = domain - blocked;
  std::vector<IPolygonWithHoles> parts;
  free_set.get(parts);
  const double inv = options.resolution;
  for (const IPolygonWithHoles& part : parts) {
    sim::Polygon poly;
    IPolygon outer;
    outer.set(part.begin(), part.end());
    poly.outer = to_ring(outer, inv);
    for (auto h = part.begin_holes(); h != part.end_holes(); ++h) poly.holes.push_back(to_ring(*h, inv));
    fs.components_.push_back(std::move(poly));
    // Integer boundary segments, exactly as Boost produced them.
    auto add_ring = [&](auto begin, auto end) {
      std::vector<IPoint> pts(begin, end);
      const std::size_t n = pts.size();
      for (std::size_t i = 0; i < n; ++i) {
        const IPoint a = pts[i], b = pts[(i + 1) % n];
        if (a == b) continue;
        fs.boundary_units_.push_back({a.x(), a.y(), b.x(), b.y()});
        fs.boundary_.push_back({glm::vec2(static_cast<float>(a.x() * inv), static_cast<float>(a.y() * inv)),
                                glm::vec2(static_cast<float>(b.x() * inv), static_cast<float>(b.y() * inv))});
      }
    };
    add_ring(part.begin(), part.end());
    for (auto h = part.begin_holes(); h != part.end_holes(); ++h) add_ring(h->begin(), h->end());
  }
  fs.index();
  return fs;
}

void FreeSpace::index() {
  bounds_ = sim::Aabb{};
  component_bounds_.clear();
  for (const sim::Polygon& p : components_) {
    component_bounds_.push_back(sim::bounds(p));
    bounds_.add(component_bounds_.back());
  }
  cell_ = options_.cell_size;
  if (!(cell_ > 0)) {
    const glm::vec2 size = bounds_.size();
    const double area = std::max(1.0, static_cast<double>(size.x) * size.y);
    cell_ =
        static_cast<float>(std::clamp(2.0 * std::sqrt(area / std::max<std::size_t>(1, boundary_.size())), 0.25, 64.0));
  }
  // Each edge is registered in the cells of its pieces' bounding boxes
  // (pieces no longer than a cell side), so a long diagonal wall stays cheap.
  std::vector<std::pair<std::uint64_t, std::int32_t>> pairs;
  for (std::size_t k = 0; k < boundary_.size(); ++k)
    add_segment_cells(boundary_[k].a, boundary_[k].b, cell_, static_cast<std::int32_t>(k), pairs);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  grid_ = sim::StaticGrid(cell_, std::move(pairs), Memory::Host);
}

void add_segment_cells(glm::vec2 a, glm::vec2 b, float cell, std::int32_t item,
                       std::vector<std::pair<std::uint64_t, std::int32_t>>& pairs) {
  const int parts = std::max(1, static_cast<int>(std::ceil(sim::length_of(b - a) / cell)));
  for (int i = 0; i < parts; ++i) {
    const glm::vec2 p0 = a + (b - a) * (static_cast<float>(i) / static_cast<float>(parts));
    const glm::vec2 p1 = a + (b - a) * (static_cast<float>(i + 1) / static_cast<float>(parts));
    const std::int32_t x0 = sim::cell_coord(std::min(p0.x, p1.x), cell),
                       x1 = sim::cell_coord(std::max(p0.x, p1.x), cell);
    const std::int32_t y0 = sim::cell_coord(std::min(p0.y, p1.y), cell),
                       y1 = sim::cell_coord(std::max(p0.y, p1.y), cell);
    for (std::int32_t y = y0; y <= y1; ++y)
      for (std::int32_t x = x0; x <= x1; ++x) pairs.emplace_back(sim::cell_key(x, y), item);
  }
}

std::int32_t FreeSpace::component_of(glm::vec2 p) const {
  for (std::size_t i = 0; i < components_.size(); ++i)
    if (component_bounds_[i].contains(p) && sim::point_in_polygon(p, components_[i]))
      return static_cast<std::int32_t>(i);
  return -1;
}

bool FreeSpace::contains(glm::vec2 p) const {
  if (!bounds_.contains(p)) return false;
  const sim::GridView g = grid_.host_view();
  const std::int32_t cx = sim::cell_coord(p.x, cell_), cy = sim::cell_coord(p.y, cell_);
  // The ray runs to the nearer side of the bounds (+x or -x): half the row
  // on average.
  const bool right = bounds_.max.x - p.x <= p.x - bounds_.min.x;
  const std::int32_t x_first = right ? cx : sim::cell_coord(bounds_.min.x, cell_);
  const std::int32_t x_last = right ? sim::cell_coord(bounds_.max.x, cell_) : cx;
  bool inside = false;
  // A row longer than there are boundary edges (a huge, nearly empty world)
  // is cheaper to answer from every edge: the cost stays bounded by what the
  // world contains, not by its extent.
  if (static_cast<double>(x_last) - x_first + 1 > static_cast<double>(boundary_.size())) {
    for (const sim::Segment& e : boundary_)
      if (sim::edge_crosses_ray(p, e.a, e.b)) inside = !inside;
    return inside;
  }
  // Each crossing is counted in the one cell of the row that holds it (an
  // edge is registered in every cell its pieces' boxes touch).
  for (std::int32_t x = x_first; x <= x_last; ++x) {
    const Index slot = g.find(x, cy);
    if (slot < 0) continue;
    for (std::int32_t i = 0; i < g.count[slot]; ++i) {
      const sim::Segment& e = boundary_[static_cast<std::size_t>(g.items[g.start[slot] + i])];
      if ((e.a.y > p.y) == (e.b.y > p.y)) continue;
      const float cross_x = e.a.x + (p.y - e.a.y) * (e.b.x - e.a.x) / (e.b.y - e.a.y);
      if ((right ? cross_x > p.x : cross_x < p.x) && sim::cell_coord(cross_x, cell_) == x) inside = !inside;
    }
  }
  return inside;
}

float FreeSpace::boundary_distance(glm::vec2 p) const {
  if (boundary_.empty()) return INFINITY;
  const sim::GridView g = grid_.host_view();
  const std::int32_t cx = sim::cell_coord(p.x, cell_), cy = sim::cell_coord(p.y, cell_);
  // Rings of cells around p's cell; ring k covers every point within k cell
  // sides of p, so once the best distance is below that, it is final.
  // Up to 48 rings; a point that has no boundary that near (far outside,
  // or a sparse index) takes a plain scan.
  constexpr std::int32_t kMaxRing = 48;
  float best = INFINITY;
  for (std::int32_t k = 0; k <= kMaxRing; ++k) {
    for (std::int32_t dy = -k; dy <= k; ++dy)
      for (std::int32_t dx = -k; dx <= k; ++dx) {
        if (std::max(std::abs(dx), std::abs(dy)) != k) continue;
        const Index s = g.find(cx + dx, cy + dy);
        if (s < 0) continue;
        for (std::int32_t i = 0; i < g.count[s]; ++i) {
          const sim::Segment& seg = boundary_[static_cast<std::size_t>(g.items[g.start[s] + i])];
          best = std::min(best, sim::distance_to_segment(p, seg.a, seg.b));
        }
      }
    if (best <= static_cast<float>(k) * cell_) return best;
  }
  for (const sim::Segment& s : boundary_) best = std::min(best, sim::distance_to_segment(p, s.a, s.b));
  return best;
}

float segment_segment_distance(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d) {
  if (sim::segments_intersect(a, b, c, d)) return 0.0f;
  return std::min(std::min(sim::distance_to_segment(a, c, d), sim::distance_to_segment(b, c, d)),
                  std::min(sim::distance_to_segment(c, a, b), sim::distance_to_segment(d, a, b)));
}

template <class Fn>
void FreeSpace::for_cells_near_segment(glm::vec2 a, glm::vec2 b, float reach, Fn&& fn) const {
  const sim::GridView g = grid_.host_view();
  const float grow = reach + cell_;
  const std::int32_t x0 = sim::cell_coord(std::min(a.x, b.x) - grow, cell_),
                     x1 = sim::cell_coord(std::max(a.x, b.x) + grow, cell_);
  const std::int32_t y0 = sim::cell_coord(std::min(a.y, b.y) - grow, cell_),
                     y1 = sim::cell_coord(std::max(a.y, b.y) + grow, cell_);
  const float keep = reach + cell_ * 0.7072f;
  // The band of cells along a segment far longer than the geometry is dense
  // (kilometres of empty world) holds more cells than there are edges: then
  // every edge is offered instead, so a query costs at most one pass over
  // the boundary whatever the world's extent.
  const double band_cells =
      (static_cast<double>(sim::length_of(b - a)) / cell_ + 2.0 * (grow / cell_ + 1.0)) * (2.0 * (grow / cell_ + 1.0));
  if (band_cells > static_cast<double>(boundary_.size())) {
    for (const sim::Segment& s : boundary_)
      if (!fn(s)) return;
    return;
  }
  // Row by row, only the cells of the band around the part of [a, b] within
  // `grow` of the row (a long diagonal segment would otherwise visit its
  // whole bounding box). Rows and cells are visited from b's end: callers
  // that extend a line of sight from a point already seen clear (the
  // planner's shortcuts) find what blocks it near b, and stop there.
  const glm::vec2 d = b - a;
  const bool rows_down = b.y >= a.y, cells_left = b.x >= a.x;
  for (std::int32_t row = 0; row <= y1 - y0; ++row) {
    const std::int32_t y = rows_down ? y1 - row : y0 + row;
    const float y_lo = static_cast<float>(y) * cell_ - grow, y_hi = static_cast<float>(y + 1) * cell_ + grow;
    float t0 = 0.0f, t1 = 1.0f;
    if (std::fabs(d.y) > 1e-12f) {
      float ta = (y_lo - a.y) / d.y, tb = (y_hi - a.y) / d.y;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(0.0f, ta);
      t1 = std::min(1.0f, tb);
      if (t0 > t1) continue;
    } else if (a.y < y_lo || a.y > y_hi) {
      continue;
    }
    const float xa = a.x + t0 * d.x, xb = a.x + t1 * d.x;
    const std::int32_t row_x0 = std::max(x0, sim::cell_coord(std::min(xa, xb) - grow, cell_));
    const std::int32_t row_x1 = std::min(x1, sim::cell_coord(std::max(xa, xb) + grow, cell_));
    for (std::int32_t col = 0; col <= row_x1 - row_x0; ++col) {
      const std::int32_t x = cells_left ? row_x1 - col : row_x0 + col;
      const glm::vec2 centre((static_cast<float>(x) + 0.5f) * cell_, (static_cast<float>(y) + 0.5f) * cell_);
      if (sim::distance_to_segment(centre, a, b) > keep) continue;
      const Index s = g.find(x, y);
      if (s < 0) continue;
      for (std::int32_t i = 0; i < g.count[s]; ++i)
        if (!fn(boundary_[static_cast<std::size_t>(g.items[g.start[s] + i])])) return;
    }
  }
}

bool FreeSpace::segment_clear(glm::vec2 a, glm::vec2 b, float r, bool a_known_free) const {
  if (!a_known_free && !contains(a)) return false;
  bool clear = true;
  for_cells_near_segment(a, b, r, [&](const sim::Segment& s) {
    // Most edges offered lie well off the segment: the disc round the edge's
    // midpoint that holds it is a cheaper first test.
    const float half = 0.5f * sim::length_of(s.b - s.a);
    if (sim::distance_to_segment(0.5f * (s.a + s.b), a, b) - half >= r) return true;
    if (segment_segment_distance(a, b, s.a, s.b) < r || sim::segments_intersect(a, b, s.a, s.b)) clear = false;
    return clear;
  });
  return clear;
}

float FreeSpace::segment_clearance(glm::vec2 a, glm::vec2 b) const {
  // Any boundary edge nearer than the ends' own clearance is within that reach.
  const float reach = std::min(boundary_distance(a), boundary_distance(b));
  float best = reach;
  if (!(reach < INFINITY)) return reach;
  for_cells_near_segment(a, b, reach, [&](const sim::Segment& s) {
    best = std::min(best, segment_segment_distance(a, b, s.a, s.b));
    return true;
  });
  return best;
}

}  // namespace throng::path
