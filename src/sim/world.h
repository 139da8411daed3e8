// The geometric layer: walkable region and obstacles, indexed for queries
// near a point. Built once on the host from a WorldSpec; the flattened arrays
// and grids live in current_memory() so kernels read them through WorldView.
//
// Obstacles are polygons (with holes) and circles. Walls are the edges of
// every obstacle polygon and of the walkable boundary; holes of the walkable
// region become obstacle polygons. Three sparse grids of side cell_size:
//   segments: every cell an edge passes through, plus the ring of cells
//             around those (probe, projection, clearance);
//   circles:  every cell a disc overlaps, plus that ring;
//   polygons: every cell of a polygon's bounding box (point containment).
// Because of the ring ("halo"), the one cell containing a point lists every
// wall and circle within one cell side of it: one lookup instead of nine.
//
// A periodic world (WorldSpec::periodic_x, periodic_y) has a rectangular
// walkable area. What the kernels index is then its copies one period away
// on every wrapping side as well, inside a walkable rectangle three periods
// long: the sides at the seams are no walls, and an agent near a seam sees
// the walls and obstacles across it. The host's shapes (polygons(),
// circles(), walkable()) stay the scenario's own.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/buffer.h"
#include "sim/geometry.h"
#include "sim/grid.h"
#include "sim/scenario.h"

namespace throng::sim {

struct RingRef {
  std::int32_t begin = 0;  // into vertices
  std::int32_t count = 0;
};
struct PolygonRef {
  std::int32_t ring_begin = 0;  // into rings; the first is the outer ring
  std::int32_t ring_count = 0;
};

// Device-readable view of the world.
struct WorldView {
  float cell_size = 4.0f;
  bool has_walkable = false;
  RingRef walkable_outer;
  Span<const glm::vec2> vertices;
  Span<const RingRef> rings;
  Span<const PolygonRef> polygons;
  Span<const Segment> segments;
  Span<const Circle> circles;
  GridView segment_grid;
  // Walls too long for the grid (World::index): every query tests them.
  Span<const std::int32_t> long_walls;
  GridView circle_grid;
  GridView polygon_grid;
};

THRONG_HOST_DEVICE inline bool point_in_polygon_ref(const WorldView& w, glm::vec2 p, PolygonRef poly) {
  const RingRef outer = w.rings[poly.ring_begin];
  if (!point_in_ring(p, w.vertices.data() + outer.begin, outer.count)) return false;
  for (std::int32_t r = 1; r < poly.ring_count; ++r) {
    const RingRef hole = w.rings[poly.ring_begin + r];
    if (point_in_ring(p, w.vertices.data() + hole.begin, hole.count)) return false;
  }
  return true;
}

// Index of an obstacle polygon containing p, or -1 (own cell only).
THRONG_HOST_DEVICE inline std::int32_t polygon_containing(const WorldView& w, glm::vec2 p) {
  std::int32_t found = -1;
  for_each_in_cell(w.polygon_grid, p, [&](std::int32_t k) {
    if (found < 0 && point_in_polygon_ref(w, p, w.polygons[k])) found = k;
  });
  return found;
}
THRONG_HOST_DEVICE inline std::int32_t circle_containing(const WorldView& w, glm::vec2 p) {
  std::int32_t found = -1;
  for_each_in_cell(w.circle_grid, p, [&](std::int32_t k) {
    const Circle c = w.circles[k];
    if (found < 0 && length2(p - c.center) < c.radius * c.radius) found = k;
  });
  return found;
}

// p is in free space: inside the walkable region (when there is one) and in
// no obstacle.
THRONG_HOST_DEVICE inline bool in_free_space(const WorldView& w, glm::vec2 p) {
  if (w.has_walkable && !point_in_ring(p, w.vertices.data() + w.walkable_outer.begin, w.walkable_outer.count))
    return false;
  return polygon_containing(w, p) < 0 && circle_containing(w, p) < 0;
}

// The walls and circles listed in the halo cell of a point: every one within
// a cell side of it. The move stage keeps this per agent for a step (an
// agent moves less than its radius in a step, far less than a cell side).
struct ObstacleCell {
  std::int32_t cx = 0, cy = 0;  // the wall grid's cell of the point
  std::int32_t wall_start = 0, wall_count = 0;
  std::int32_t circle_start = 0, circle_count = 0;
};
THRONG_HOST_DEVICE inline ObstacleCell obstacle_cell(const WorldView& w, glm::vec2 p) {
  ObstacleCell c;
  c.cx = cell_coord(p.x, w.segment_grid.cell_size);
  c.cy = cell_coord(p.y, w.segment_grid.cell_size);
  const Index ws = w.segment_grid.find(c.cx, c.cy);
  if (ws >= 0) c.wall_start = w.segment_grid.start[ws], c.wall_count = w.segment_grid.count[ws];
  const Index cs =
      w.circle_grid.find(cell_coord(p.x, w.circle_grid.cell_size), cell_coord(p.y, w.circle_grid.cell_size));
  if (cs >= 0) c.circle_start = w.circle_grid.start[cs], c.circle_count = w.circle_grid.count[cs];
  return c;
}
// The long walls that the grid would have listed in cell (cx, cy): those
// meeting the cell and its ring of neighbours, in index order after the
// cell's own.
template <class WallFn>
THRONG_HOST_DEVICE inline void for_each_long_wall(const WorldView& w, std::int32_t cx, std::int32_t cy, WallFn&& wall) {
  const float side = w.segment_grid.cell_size, eps = side * 1e-4f;
  const glm::vec2 lo(static_cast<float>(cx - 1) * side - eps, static_cast<float>(cy - 1) * side - eps);
  const glm::vec2 hi(static_cast<float>(cx + 2) * side + eps, static_cast<float>(cy + 2) * side + eps);
  for (Index m = 0; m < w.long_walls.size(); ++m) {
    const Segment& s = w.segments[w.long_walls[m]];
    if (segment_meets_box(s.a, s.b, lo, hi)) wall(s);
  }
}
// Every wall within one cell side of p (and possibly some a little further).
template <class WallFn>
THRONG_HOST_DEVICE inline void for_each_wall_near(const WorldView& w, glm::vec2 p, WallFn&& wall) {
  for_each_in_cell(w.segment_grid, p, [&](std::int32_t k) { wall(w.segments[k]); });
  if (w.long_walls.size() > 0)
    for_each_long_wall(w, cell_coord(p.x, w.segment_grid.cell_size), cell_coord(p.y, w.segment_grid.cell_size), wall);
}

template <class WallFn, class CircleFn>
THRONG_HOST_DEVICE inline void for_each_obstacle(const WorldView& w, const ObstacleCell& c, WallFn&& wall,
                                                 CircleFn&& circle) {
  for (std::int32_t m = 0; m < c.wall_count; ++m) wall(w.segments[w.segment_grid.items[c.wall_start + m]]);
  if (w.long_walls.size() > 0) for_each_long_wall(w, c.cx, c.cy, wall);
  for (std::int32_t m = 0; m < c.circle_count; ++m) circle(w.circles[w.circle_grid.items[c.circle_start + m]]);
}

// Distance from p to the nearest wall or circle boundary of `cell` (beyond
// them: `far`).
THRONG_HOST_DEVICE inline float wall_clearance(const WorldView& w, const ObstacleCell& cell, glm::vec2 p, float far) {
  float best = far;
  for_each_obstacle(
      w, cell, [&](const Segment& s) { best = fminf(best, distance_to_segment(p, s.a, s.b)); },
      [&](const Circle& c) { best = fminf(best, fabsf(length_of(p - c.center) - c.radius)); });
  return best;
}
// The same for the walls within one cell side of p.
THRONG_HOST_DEVICE inline float wall_clearance(const WorldView& w, glm::vec2 p, float far) {
  return wall_clearance(w, obstacle_cell(w, p), p, far);
}

// A disc of radius r at p penetrates no obstacle by more than `tolerance`:
// walls and circle boundaries at least r - tolerance away, centre in free space.
THRONG_HOST_DEVICE inline bool disc_is_clear(const WorldView& w, glm::vec2 p, float r, float tolerance) {
  return wall_clearance(w, p, r) >= r - tolerance && in_free_space(w, p);
}

class World {
 public:
  World() = default;
  // Validates and indexes the geometry. Errors name the field path of the
  // offending shape ("world.obstacles[2]: polygon edges 3 and 7 cross").
  static World build(const WorldSpec& spec, float cell_size, const ScenarioLimits& limits = {},
                     Memory memory = current_memory());

  WorldView view() const;       // in the memory the world was built for
  WorldView host_view() const;  // host mirror, for spawning and validation

  float cell_size() const { return cell_size_; }
  bool has_walkable() const { return has_walkable_; }
  const Polygon& walkable() const { return walkable_; }
  // All obstacle polygons (spec polygons, walkable holes, scattered shapes).
  const std::vector<Polygon>& polygons() const { return polygons_; }
  const std::vector<Circle>& circles() const { return circles_; }
  // Every wall the kernels see (with a periodic world's copies).
  const std::vector<Segment>& segments() const { return segments_; }
  // Field path of obstacle polygon / circle k of the view (a copy across a
  // periodic seam is named as its original), for messages.
  const std::string& polygon_field(std::int32_t k) const {
    return polygon_fields_[static_cast<std::size_t>(k) % polygon_fields_.size()];
  }
  const std::string& circle_field(std::int32_t k) const {
    return circle_fields_[static_cast<std::size_t>(k) % circle_fields_.size()];
  }
  // Bounding box of the walkable region, or of all obstacles when unbounded.
  Aabb bounds() const { return bounds_; }
  // The periodic boundaries (periods 0 when there are none).
  const Periodic& periodic() const { return periodic_; }

  // Host queries.
  bool in_free_space(glm::vec2 p) const;
  // Field path of an obstacle containing p, or "" when none does; "outside
  // the walkable region" when p is outside it.
  std::string what_blocks(glm::vec2 p) const;
  // Disc of radius r at p fits without touching any wall (exact within one
  // cell side; r must be below cell_size).
  bool disc_fits(glm::vec2 p, float r) const;

 private:
  void index(const ScenarioLimits& limits, Memory memory);
  void make_periodic(const WorldSpec& spec);
  // The circles the kernels index.
  const std::vector<Circle>& indexed_circles() const { return periodic_.wraps() ? indexed_circles_ : circles_; }

  float cell_size_ = 4.0f;
  bool has_walkable_ = false;
  Polygon walkable_;
  std::vector<Polygon> polygons_;
  std::vector<std::string> polygon_fields_;
  std::vector<Circle> circles_;
  std::vector<std::string> circle_fields_;
  std::vector<Segment> segments_;
  Aabb bounds_;
  Periodic periodic_;

  // Flattened host arrays and their device copies.
  RingRef walkable_outer_;
  std::vector<glm::vec2> vertices_;
  std::vector<RingRef> rings_;
  std::vector<PolygonRef> polygon_refs_;
  Buffer<glm::vec2> d_vertices_;
  Buffer<RingRef> d_rings_;
  Buffer<PolygonRef> d_polygons_;
  Buffer<Segment> d_segments_;
  std::vector<std::int32_t> long_walls_;
  Buffer<std::int32_t> d_long_walls_;
  std::vector<Circle> indexed_circles_;  // a periodic world's circles_ and their copies (empty elsewhere)
  Buffer<Circle> d_circles_;
  StaticGrid segment_grid_, circle_grid_, polygon_grid_;
};

// Connected parts of free space on a raster (for "unreachable goal"): cell
// centres in free space are joined 4-way. Conservative: only reports two
// points apart when no path exists at raster resolution.
class Reachability {
 public:
  Reachability(const World& world, Aabb extent, std::int32_t resolution);
  // Component labels of p: its raster cell's, or when that cell's centre is
  // blocked (p close to an obstacle), those of the free cells around it.
  struct Labels {
    std::int32_t label[9];
    int count = 0;
  };
  Labels components(glm::vec2 p) const;
  // False only when both points have known labels and share none.
  bool connected(glm::vec2 a, glm::vec2 b) const;
  float cell_size() const { return h_; }

 private:
  std::int32_t label_at(std::int64_t x, std::int64_t y) const;
  Aabb extent_;
  float h_ = 1.0f;
  std::int64_t nx_ = 0, ny_ = 0;
  std::vector<std::int32_t> labels_;
};

}  // namespace throng::sim
