#include "sim/world.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <unordered_map>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/random.h"

namespace throng::sim {

namespace {

void check_point(glm::vec2 p, float max_extent, const std::string& field) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw Error("coordinate is not a finite number", at_field(field));
  if (std::fabs(p.x) > max_extent || std::fabs(p.y) > max_extent)
    throw Error(fmt::format("coordinate ({}, {}) is beyond the limit of +-{} m", p.x, p.y, max_extent),
                at_field(field));
}

void check_ring(const Ring& r, float max_extent, const std::string& field) {
  if (r.size() < 3)
    throw Error(fmt::format("a polygon ring needs at least 3 vertices, got {}", r.size()), at_field(field));
  for (std::size_t i = 0; i < r.size(); ++i) check_point(r[i], max_extent, fmt::format("{}[{}]", field, i));
  if (const auto bad = find_self_intersection(r)) {
    if (bad->first == bad->second)
      throw Error(fmt::format("polygon has a zero-length edge at vertex {}", bad->first), at_field(field));
    throw Error(fmt::format("polygon is self-intersecting: edge {} (vertices {}-{}) crosses edge {} (vertices {}-{})",
                            bad->first, bad->first, (bad->first + 1) % static_cast<std::int64_t>(r.size()), bad->second,
                            bad->second, (bad->second + 1) % static_cast<std::int64_t>(r.size())),
                at_field(field));
  }
  if (std::fabs(signed_area2(r)) < 1e-8) throw Error("polygon has zero area", at_field(field));
}

void check_polygon(const Polygon& p, float max_extent, const std::string& field) {
  check_ring(p.outer, max_extent, field + ".polygon");
  for (std::size_t h = 0; h < p.holes.size(); ++h)
    check_ring(p.holes[h], max_extent, fmt::format("{}.holes[{}]", field, h));
  if (!polygon_is_simple(p)) throw Error("polygon rings cross one another", at_field(field));
  for (std::size_t h = 0; h < p.holes.size(); ++h)
    if (!point_in_ring(p.holes[h][0], p.outer))
      throw Error("hole lies outside the polygon's outer boundary", at_field(fmt::format("{}.holes[{}]", field, h)));
}

// Rows of cells a segment passes through, expanded by a hair so an edge
// running along a cell border is found from both sides.
template <class Fn>
void cells_of_segment(const Segment& s, float cell, Fn&& fn) {
  const float eps = cell * 1e-4f;
  const float ymin = std::min(s.a.y, s.b.y) - eps, ymax = std::max(s.a.y, s.b.y) + eps;
  const std::int32_t r0 = cell_coord(ymin, cell), r1 = cell_coord(ymax, cell);
  for (std::int32_t row = r0; row <= r1; ++row) {
    const float y0 = std::max(ymin, static_cast<float>(row) * cell),
                y1 = std::min(ymax, static_cast<float>(row + 1) * cell);
    float xa, xb;
    if (std::fabs(s.b.y - s.a.y) < 1e-12f) {
      xa = std::min(s.a.x, s.b.x);
      xb = std::max(s.a.x, s.b.x);
    } else {
      auto x_at = [&](float y) {
        const float t = std::clamp((y - s.a.y) / (s.b.y - s.a.y), 0.0f, 1.0f);
        return s.a.x + t * (s.b.x - s.a.x);
      };
      xa = std::min(x_at(y0), x_at(y1));
      xb = std::max(x_at(y0), x_at(y1));
    }
    const std::int32_t c0 = cell_coord(xa - eps, cell), c1 = cell_coord(xb + eps, cell);
    for (std::int32_t c = c0; c <= c1; ++c) fn(c, row);
  }
}

// Cells a disc overlaps, row by row.
template <class Fn>
void cells_of_circle(const Circle& c, float cell, Fn&& fn) {
  const std::int32_t r0 = cell_coord(c.center.y - c.radius, cell), r1 = cell_coord(c.center.y + c.radius, cell);
  for (std::int32_t row = r0; row <= r1; ++row) {
    const float y0 = static_cast<float>(row) * cell, y1 = static_cast<float>(row + 1) * cell;
    const float dy = c.center.y < y0 ? y0 - c.center.y : (c.center.y > y1 ? c.center.y - y1 : 0.0f);
    const float half = std::sqrt(std::max(0.0f, c.radius * c.radius - dy * dy));
    const std::int32_t c0 = cell_coord(c.center.x - half, cell), c1 = cell_coord(c.center.x + half, cell);
    for (std::int32_t k = c0; k <= c1; ++k) fn(k, row);
  }
}

double cells_in_box(const Aabb& b, float cell) {
  return (std::floor(b.max.x / cell) - std::floor(b.min.x / cell) + 1.0) *
         (std::floor(b.max.y / cell) - std::floor(b.min.y / cell) + 1.0);
}

// Obstacles scattered at random: circles and rotated rectangles whose
// bounding circles keep `clearance` between them.
void scatter(const ScatterSpec& s, const std::string& field, const ScenarioLimits& limits, std::vector<Polygon>& polys,
             std::vector<std::string>& poly_fields, std::vector<Circle>& circles,
             std::vector<std::string>& circle_fields) {
  if (s.count < 0 || s.count > limits.max_obstacles)
    throw Error(fmt::format("count must be in [0, {}]", limits.max_obstacles), at_field(field + ".count"));
  if (!(s.min_size > 0) || !(s.max_size >= s.min_size) || !std::isfinite(s.max_size))
    throw Error("sizes must satisfy 0 < min_size <= max_size", at_field(field + ".size"));
  if (!(s.clearance >= 0) || !std::isfinite(s.clearance))
    throw Error("clearance must be >= 0", at_field(field + ".clearance"));
  const glm::vec2 lo = s.region.min, hi = s.region.max;
  if (!(hi.x > lo.x && hi.y > lo.y)) throw Error("region must have max > min", at_field(field + ".region"));
  const float bound_r = s.max_size * 0.7072f;
  const float cell = 2.0f * bound_r + s.clearance;
  std::unordered_map<std::uint64_t, std::vector<std::pair<glm::vec2, float>>> placed;
  Rng rng(s.seed, 0x5ca77e7);
  std::int64_t made = 0;
  const std::int64_t attempts = 40 * s.count + 100;
  for (std::int64_t a = 0; a < attempts && made < s.count; ++a) {
    const float size = static_cast<float>(rng.uniform(s.min_size, s.max_size));
    const bool round = rng.uniform() < 0.5;
    const float angle = static_cast<float>(rng.uniform(0.0, 3.141592653589793));
    const float r = round ? size * 0.5f : size * 0.7072f;
    const glm::vec2 c(static_cast<float>(rng.uniform(lo.x + r, hi.x - r)),
                      static_cast<float>(rng.uniform(lo.y + r, hi.y - r)));
    if (!(c.x - r >= lo.x && c.x + r <= hi.x && c.y - r >= lo.y && c.y + r <= hi.y)) continue;
    const std::int32_t cx = cell_coord(c.x, cell), cy = cell_coord(c.y, cell);
    bool ok = true;
    for (std::int32_t dy = -1; dy <= 1 && ok; ++dy)
      for (std::int32_t dx = -1; dx <= 1 && ok; ++dx) {
        auto it = placed.find(cell_key(cx + dx, cy + dy));
        if (it == placed.end()) continue;
        for (const auto& [q, rq] : it->second)
          if (length_of(q - c) < r + rq + s.clearance) ok = false;
      }
    if (!ok) continue;
    placed[cell_key(cx, cy)].push_back({c, r});
    const std::string name = fmt::format("{} (shape {})", field, made);
    if (round) {
      circles.push_back({c, size * 0.5f});
      circle_fields.push_back(name);
    } else {
      const glm::vec2 u(std::cos(angle) * size * 0.5f, std::sin(angle) * size * 0.5f), v = perp_left(u);
      polys.push_back({{c - u - v, c + u - v, c + u + v, c - u + v}, {}});
      poly_fields.push_back(name);
    }
    ++made;
  }
  if (made < s.count)
    throw Error(
        fmt::format("placed only {} of {} shapes: enlarge the region or lower count, size or clearance", made, s.count),
        at_field(field));
}

}  // namespace

World World::build(const WorldSpec& spec, float cell_size, const ScenarioLimits& limits, Memory memory) {
  if (!(cell_size > 0) || !std::isfinite(cell_size))
    throw Error("cell size must be a positive number", at_field("model"));
  World w;
  w.cell_size_ = cell_size;
  std::int64_t vertices = 0;
  auto count_vertices = [&](const Polygon& p, const std::string& field) {
    vertices += static_cast<std::int64_t>(p.outer.size());
    for (const Ring& h : p.holes) vertices += static_cast<std::int64_t>(h.size());
    if (vertices > limits.max_vertices)
      throw Error(fmt::format("more than {} polygon vertices in the scenario", limits.max_vertices), at_field(field));
  };
  std::int64_t scattered = 0;
  for (const ScatterSpec& s : spec.scatters) scattered += std::max<std::int64_t>(0, s.count);
  if (static_cast<std::int64_t>(spec.polygons.size() + spec.circles.size()) + scattered > limits.max_obstacles)
    throw Error(fmt::format("more than {} obstacles", limits.max_obstacles), at_field("world.obstacles"));

  if (spec.has_walkable) {
    count_vertices(spec.walkable, "world.walkable");
    check_polygon(spec.walkable, limits.max_extent, "world.walkable");
    w.has_walkable_ = true;
    w.walkable_ = {spec.walkable.outer, {}};
    for (std::size_t h = 0; h < spec.walkable.holes.size(); ++h) {
      w.polygons_.push_back({spec.walkable.holes[h], {}});
      w.polygon_fields_.push_back(fmt::format("world.walkable.holes[{}]", h));
    }
  }
  for (std::size_t i = 0; i < spec.polygons.size(); ++i) {
    const std::string field =
        i < spec.polygon_fields.size() ? spec.polygon_fields[i] : fmt::format("world.obstacles[{}]", i);
    count_vertices(spec.polygons[i], field);
    check_polygon(spec.polygons[i], limits.max_extent, field);
    w.polygons_.push_back(spec.polygons[i]);
    w.polygon_fields_.push_back(field);
  }
  for (std::size_t i = 0; i < spec.circles.size(); ++i) {
    const std::string field =
        i < spec.circle_fields.size() ? spec.circle_fields[i] : fmt::format("world.circles[{}]", i);
    const Circle& c = spec.circles[i];
    check_point(c.center, limits.max_extent, field + ".center");
    if (!(c.radius > 0) || !(c.radius < limits.max_extent))
      throw Error("circle radius must be a positive number", at_field(field + ".radius"));
    w.circles_.push_back(c);
    w.circle_fields_.push_back(field);
  }
  for (std::size_t i = 0; i < spec.scatters.size(); ++i) {
    const std::string field =
        i < spec.scatter_fields.size() ? spec.scatter_fields[i] : fmt::format("world.scatter[{}]", i);
    check_point(spec.scatters[i].region.min, limits.max_extent, field + ".region");
    check_point(spec.scatters[i].region.max, limits.max_extent, field + ".region");
    scatter(spec.scatters[i], field, limits, w.polygons_, w.polygon_fields_, w.circles_, w.circle_fields_);
  }

  if (w.has_walkable_) {
    w.bounds_ = sim::bounds(w.walkable_);
  } else {
    for (const Polygon& p : w.polygons_) w.bounds_.add(sim::bounds(p));
    for (const Circle& c : w.circles_) w.bounds_.add(sim::bounds(c));
  }
  if (spec.periodic_x || spec.periodic_y) w.make_periodic(spec);
  w.index(limits, memory);
  return w;
}

void World::make_periodic(const WorldSpec& spec) {
  const Ring& r = walkable_.outer;
  bool rectangle = has_walkable_ && r.size() == 4;
  for (std::size_t k = 0; rectangle && k < 4; ++k) {
    const glm::vec2 a = r[k], b = r[(k + 1) % 4];
    rectangle = (a.x == b.x) != (a.y == b.y);  // every side along an axis
  }
  const glm::vec2 size = bounds_.size();
  if (!rectangle || !(size.x > 0.0f && size.y > 0.0f))
    throw Error("periodic boundaries need a rectangular walkable area: world.walkable: {rect: {min, max}}",
                at_field("world.periodic"));
  periodic_.origin = bounds_.min;
  periodic_.period = glm::vec2(spec.periodic_x ? size.x : 0.0f, spec.periodic_y ? size.y : 0.0f);
}

namespace {
// What the kernels of a periodic world index besides the scenario's
// shapes: their copies one period away (and the walkable rectangle grown by
// a period on each wrapping side), appended in order so that copy k of n
// shapes is shape k % n.
void add_periodic_copies(const Periodic& periodic, Polygon& walkable, std::vector<Polygon>& polygons,
                         std::vector<Circle>& circles) {
  const glm::vec2 L = periodic.period;
  Aabb grown = bounds(walkable);
  grown.min -= L;
  grown.max += L;
  walkable.outer = {grown.min, {grown.max.x, grown.min.y}, grown.max, {grown.min.x, grown.max.y}};
  const std::size_t np = polygons.size(), nc = circles.size();
  periodic.for_each_shift([&](glm::vec2 shift) {
    if (shift == glm::vec2(0.0f)) return;  // the shapes themselves
    for (std::size_t k = 0; k < np; ++k) {
      Polygon p = polygons[k];
      for (glm::vec2& v : p.outer) v += shift;
      for (Ring& h : p.holes)
        for (glm::vec2& v : h) v += shift;
      polygons.push_back(std::move(p));
    }
    for (std::size_t k = 0; k < nc; ++k) circles.push_back({circles[k].center + shift, circles[k].radius});
  });
}
}  // namespace

void World::index(const ScenarioLimits& limits, Memory memory) {
  check_interrupt("indexing the world");
  const float cell = cell_size_;
  auto add_ring = [&](const Ring& r) {
    rings_.push_back({static_cast<std::int32_t>(vertices_.size()), static_cast<std::int32_t>(r.size())});
    vertices_.insert(vertices_.end(), r.begin(), r.end());
  };
  // A periodic world indexes its shapes and their copies; any other its shapes.
  Polygon grown;
  std::vector<Polygon> copies;
  if (periodic_.wraps()) {
    grown = walkable_;
    copies = polygons_;
    indexed_circles_ = circles_;
    add_periodic_copies(periodic_, grown, copies, indexed_circles_);
  }
  const Polygon& walkable = periodic_.wraps() ? grown : walkable_;
  const std::vector<Polygon>& polygons = periodic_.wraps() ? copies : polygons_;
  const std::vector<Circle>& circles = indexed_circles();
  if (has_walkable_) {
    walkable_outer_ = {static_cast<std::int32_t>(vertices_.size()), static_cast<std::int32_t>(walkable.outer.size())};
    vertices_.insert(vertices_.end(), walkable.outer.begin(), walkable.outer.end());
    append_edges(walkable, segments_);
  }
  for (const Polygon& p : polygons) {
    polygon_refs_.push_back({static_cast<std::int32_t>(rings_.size()), static_cast<std::int32_t>(1 + p.holes.size())});
    add_ring(p.outer);
    for (const Ring& h : p.holes) add_ring(h);
    append_edges(p, segments_);
  }

  // A wall crossing more than kLongWallCells cells (the sides of a walkable
  // region kilometres across) stays out of the grid: the few longest are
  // tested by every query instead (for_each_long_wall), so indexing costs
  // what the world contains rather than what it measures.
  constexpr double kLongWallCells = 1024;
  constexpr std::size_t kMaxLongWalls = 64;
  auto cells_crossed = [cell](const Segment& s) {
    return (std::fabs(s.b.x - s.a.x) + std::fabs(s.b.y - s.a.y)) / cell + 1.0;
  };
  long_walls_.clear();
  for (std::size_t k = 0; k < segments_.size(); ++k)
    if (cells_crossed(segments_[k]) > kLongWallCells) long_walls_.push_back(static_cast<std::int32_t>(k));
  std::stable_sort(long_walls_.begin(), long_walls_.end(), [&](std::int32_t a, std::int32_t b) {
    return cells_crossed(segments_[static_cast<std::size_t>(a)]) >
           cells_crossed(segments_[static_cast<std::size_t>(b)]);
  });
  if (long_walls_.size() > kMaxLongWalls) long_walls_.resize(kMaxLongWalls);
  std::sort(long_walls_.begin(), long_walls_.end());
  std::vector<bool> in_grid(segments_.size(), true);
  for (const std::int32_t k : long_walls_) in_grid[static_cast<std::size_t>(k)] = false;

  // Count registrations before allocating them.
  double total = 0;
  // (Halo registrations: 9 per cell before duplicates are merged.)
  for (std::size_t k = 0; k < segments_.size(); ++k)
    if (in_grid[k]) total += 9.0 * (2.0 * cells_crossed(segments_[k]) + 2.0);
  for (const Circle& c : circles) total += 9.0 * cells_in_box(sim::bounds(c), cell);
  for (const Polygon& p : polygons) total += cells_in_box(sim::bounds(p), cell);
  if (total > static_cast<double>(limits.max_grid_items))
    throw Error(
        fmt::format(
            "obstacles would need about {:.0f} grid cells at cell size {} m (limit {}): use fewer or smaller obstacles "
            "or a larger model.max_speed (the cell is the model's query radius)",
            total, cell, limits.max_grid_items),
        at_field("world.obstacles"));

  std::vector<std::pair<std::uint64_t, std::int32_t>> pairs;
  // Walls and circles go into every cell they touch and the ring of cells
  // around those (the halo), so one lookup finds all within one cell side.
  auto with_halo = [&](std::int32_t k) {
    return [&pairs, k](std::int32_t x, std::int32_t y) {
      for (std::int32_t dy = -1; dy <= 1; ++dy)
        for (std::int32_t dx = -1; dx <= 1; ++dx) pairs.push_back({cell_key(x + dx, y + dy), k});
    };
  };
  for (std::size_t k = 0; k < segments_.size(); ++k)
    if (in_grid[k]) cells_of_segment(segments_[k], cell, with_halo(static_cast<std::int32_t>(k)));
  segment_grid_ = StaticGrid(cell, std::move(pairs), memory);
  pairs.clear();
  for (std::size_t k = 0; k < circles.size(); ++k)
    cells_of_circle(circles[k], cell, with_halo(static_cast<std::int32_t>(k)));
  circle_grid_ = StaticGrid(cell, std::move(pairs), memory);
  pairs.clear();
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    const Aabb b = sim::bounds(polygons[k]);
    for (std::int32_t y = cell_coord(b.min.y, cell); y <= cell_coord(b.max.y, cell); ++y)
      for (std::int32_t x = cell_coord(b.min.x, cell); x <= cell_coord(b.max.x, cell); ++x)
        pairs.push_back({cell_key(x, y), static_cast<std::int32_t>(k)});
  }
  polygon_grid_ = StaticGrid(cell, std::move(pairs), memory);

  d_vertices_ = Buffer<glm::vec2>(std::span<const glm::vec2>(vertices_), memory);
  d_rings_ = Buffer<RingRef>(std::span<const RingRef>(rings_), memory);
  d_polygons_ = Buffer<PolygonRef>(std::span<const PolygonRef>(polygon_refs_), memory);
  d_segments_ = Buffer<Segment>(std::span<const Segment>(segments_), memory);
  d_long_walls_ = Buffer<std::int32_t>(std::span<const std::int32_t>(long_walls_), memory);
  d_circles_ = Buffer<Circle>(std::span<const Circle>(circles), memory);
}

WorldView World::view() const {
  return {cell_size_,           has_walkable_,        walkable_outer_,     d_vertices_.span(),
          d_rings_.span(),      d_polygons_.span(),   d_segments_.span(),  d_circles_.span(),
          segment_grid_.view(), d_long_walls_.span(), circle_grid_.view(), polygon_grid_.view()};
}

WorldView World::host_view() const {
  return {cell_size_,
          has_walkable_,
          walkable_outer_,
          Span<const glm::vec2>(vertices_.data(), static_cast<Index>(vertices_.size())),
          Span<const RingRef>(rings_.data(), static_cast<Index>(rings_.size())),
          Span<const PolygonRef>(polygon_refs_.data(), static_cast<Index>(polygon_refs_.size())),
          Span<const Segment>(segments_.data(), static_cast<Index>(segments_.size())),
          Span<const Circle>(indexed_circles().data(), static_cast<Index>(indexed_circles().size())),
          segment_grid_.host_view(),
          Span<const std::int32_t>(long_walls_.data(), static_cast<Index>(long_walls_.size())),
          circle_grid_.host_view(),
          polygon_grid_.host_view()};
}

// (A periodic world's kernels see a walkable area three periods long; the
// host's queries, for spawning and validation, keep to the area itself.)
bool World::in_free_space(glm::vec2 p) const {
  return (!periodic_.wraps() || point_in_ring(p, walkable_.outer)) && sim::in_free_space(host_view(), p);
}

std::string World::what_blocks(glm::vec2 p) const {
  const WorldView v = host_view();
  if (v.has_walkable && !point_in_ring(p, walkable_.outer)) return "outside the walkable region world.walkable";
  if (const std::int32_t k = polygon_containing(v, p); k >= 0) return "inside obstacle " + polygon_field(k);
  if (const std::int32_t k = circle_containing(v, p); k >= 0) return "inside obstacle " + circle_field(k);
  return {};
}

bool World::disc_fits(glm::vec2 p, float r) const {
  return (!periodic_.wraps() || point_in_ring(p, walkable_.outer)) && disc_is_clear(host_view(), p, r, 0.0f);
}

// ---- Reachability -------------------------------------------------------------

Reachability::Reachability(const World& world, Aabb extent, std::int32_t resolution) : extent_(extent) {
  if (extent.empty()) return;
  const glm::vec2 size = extent.size();
  // Cells of at least 0.1 m: a gap an agent fits through (0.5 m for the
  // usual radius) still has several free cells across.
  h_ = std::max({size.x / static_cast<float>(resolution), size.y / static_cast<float>(resolution), 0.1f});
  nx_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(size.x / h_)));
  ny_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(size.y / h_)));
  labels_.assign(static_cast<std::size_t>(nx_ * ny_), -1);
  std::vector<std::uint8_t> free(labels_.size());
  const WorldView v = world.host_view();
  for (std::int64_t y = 0; y < ny_; ++y)
    for (std::int64_t x = 0; x < nx_; ++x) {
      const glm::vec2 c =
          extent_.min + glm::vec2((static_cast<float>(x) + 0.5f) * h_, (static_cast<float>(y) + 0.5f) * h_);
      free[static_cast<std::size_t>(y * nx_ + x)] = in_free_space(v, c) ? 1 : 0;
    }
  std::int32_t next = 0;
  std::deque<std::int64_t> queue;
  for (std::int64_t start = 0; start < nx_ * ny_; ++start) {
    if (!free[static_cast<std::size_t>(start)] || labels_[static_cast<std::size_t>(start)] >= 0) continue;
    labels_[static_cast<std::size_t>(start)] = next;
    queue.push_back(start);
    while (!queue.empty()) {
      const std::int64_t c = queue.front();
      queue.pop_front();
      const std::int64_t cx = c % nx_, cy = c / nx_;
      const std::int64_t nb[4][2] = {{cx - 1, cy}, {cx + 1, cy}, {cx, cy - 1}, {cx, cy + 1}};
      for (const auto& n : nb) {
        if (n[0] < 0 || n[1] < 0 || n[0] >= nx_ || n[1] >= ny_) continue;
        const auto k = static_cast<std::size_t>(n[1] * nx_ + n[0]);
        if (free[k] && labels_[k] < 0) {
          labels_[k] = next;
          queue.push_back(static_cast<std::int64_t>(k));
        }
      }
    }
    ++next;
  }
}

std::int32_t Reachability::label_at(std::int64_t x, std::int64_t y) const {
  if (x < 0 || y < 0 || x >= nx_ || y >= ny_) return -1;
  return labels_[static_cast<std::size_t>(y * nx_ + x)];
}

Reachability::Labels Reachability::components(glm::vec2 p) const {
  Labels out;
  if (labels_.empty() || !std::isfinite(p.x) || !std::isfinite(p.y)) return out;
  const double fx = std::floor((static_cast<double>(p.x) - extent_.min.x) / h_);
  const double fy = std::floor((static_cast<double>(p.y) - extent_.min.y) / h_);
  if (fx < -2 || fy < -2 || fx > static_cast<double>(nx_) + 2 || fy > static_cast<double>(ny_) + 2) return out;
  const auto x = static_cast<std::int64_t>(fx), y = static_cast<std::int64_t>(fy);
  if (const std::int32_t l = label_at(x, y); l >= 0) {
    out.label[out.count++] = l;
    return out;
  }
  // Own cell centre blocked (p near an obstacle): any free neighbour counts.
  for (std::int64_t dy = -1; dy <= 1; ++dy)
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      if (const std::int32_t l = label_at(x + dx, y + dy); l >= 0) out.label[out.count++] = l;
  return out;
}

bool Reachability::connected(glm::vec2 a, glm::vec2 b) const {
  const Labels la = components(a), lb = components(b);
  if (la.count == 0 || lb.count == 0) return true;  // unknown: do not claim unreachable
  for (int i = 0; i < la.count; ++i)
    for (int j = 0; j < lb.count; ++j)
      if (la.label[i] == lb.label[j]) return true;
  return false;
}

}  // namespace throng::sim
