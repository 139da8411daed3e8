// Free space for path planning: the walkable region minus the union of every
// obstacle, as polygons with holes, snapped to an integer grid.
//
// Boost.Polygon (boolean operations and Voronoi) works on integer
// coordinates: every vertex is multiplied by 1 / resolution and rounded, so a
// point moves by at most resolution * sqrt(2) / 2 (0.71 mm at the default 1 mm),
// and coordinates must stay within +-2^30 units (+-1074 km at 1 mm). Circles
// become circumscribed regular polygons whose vertices lie at most
// `circle_tolerance` outside the circle, so the polygon contains the circle:
// a distance to the free space's boundary is never larger than the distance
// to the true obstacle. The union makes overlapping obstacles one, so the
// boundary segments never cross (what the Voronoi builder requires).
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <utility>
#include <vector>

#include "sim/geometry.h"
#include "sim/grid.h"
#include "sim/world.h"

namespace throng::path {

struct FreeSpaceOptions {
  float resolution = 0.001f;       // m per integer unit of the snapped geometry
  float circle_tolerance = 0.01f;  // m: polygon vertices at most this far outside a circle
  // Without a walkable region: the free space is the bounding box of the
  // obstacles (and of `extent` when set) grown by this margin.
  float margin = 2.0f;
  sim::Aabb extent;        // optional area to include (e.g. start and goal points)
  float cell_size = 0.0f;  // index cell side; 0 = chosen from the geometry
  // Throws Error naming the field for NaN, non-positive or absurd values.
  void validate() const;
};

// Sides of the circumscribed regular polygon of a circle whose vertices lie
// within `tolerance` of it (at least 8, at most 1024).
std::int32_t circle_polygon_sides(float radius, float tolerance);
// That polygon, counter-clockwise.
sim::Ring circumscribed_polygon(const sim::Circle& c, float tolerance);

class FreeSpace {
 public:
  FreeSpace() = default;
  // From the world's walkable region, obstacle polygons and circles.
  static FreeSpace build(const sim::World& world, const FreeSpaceOptions& options = {});
  // From shapes directly (walkable may be null: unbounded).
  static FreeSpace build(const sim::Polygon* walkable, const std::vector<sim::Polygon>& obstacles,
                         const std::vector<sim::Circle>& circles, const FreeSpaceOptions& options = {});

  const FreeSpaceOptions& options() const { return options_; }
  float resolution() const { return options_.resolution; }
  // Connected parts of free space (for a point agent), each an outer ring with holes.
  const std::vector<sim::Polygon>& components() const { return components_; }
  // Every boundary edge of every component, in metres, and the same in integer units.
  const std::vector<sim::Segment>& boundary() const { return boundary_; }
  struct IntSegment {
    std::int32_t x0, y0, x1, y1;
  };
  const std::vector<IntSegment>& boundary_units() const { return boundary_units_; }
  sim::Aabb bounds() const { return bounds_; }

  // Index of the component containing p, or -1 (in an obstacle or outside).
  std::int32_t component_of(glm::vec2 p) const;
  // p lies in free space (some component): parity of the boundary edges a
  // ray from p to +x or -x crosses, walking only the index cells of p's row (the
  // components of a large world have thousands of holes: a plain
  // point-in-polygon test per query would visit every vertex).
  bool contains(glm::vec2 p) const;
  // Distance from p to the nearest boundary edge (inside or outside).
  float boundary_distance(glm::vec2 p) const;
  // Clearance of p: its distance to the boundary when p is in free space, else 0.
  float clearance(glm::vec2 p) const { return contains(p) ? boundary_distance(p) : 0.0f; }
  // A disc of radius r swept from a to b stays in free space: a is free and
  // every boundary edge is at least r from the segment [a, b].
  // `a_known_free`: the caller knows a lies in free space (a point of a
  // planned path), so its containment test is skipped.
  bool segment_clear(glm::vec2 a, glm::vec2 b, float r, bool a_known_free = false) const;
  // Smallest distance from the segment [a, b] to the boundary.
  float segment_clearance(glm::vec2 a, glm::vec2 b) const;

 private:
  void index();
  template <class Fn>
  void for_cells_near_segment(glm::vec2 a, glm::vec2 b, float reach, Fn&& fn) const;

  FreeSpaceOptions options_;
  std::vector<sim::Polygon> components_;
  std::vector<sim::Aabb> component_bounds_;
  std::vector<sim::Segment> boundary_;
  std::vector<IntSegment> boundary_units_;
  sim::Aabb bounds_;
  float cell_ = 1.0f;
  sim::StaticGrid grid_;  // boundary segments by cell (host memory)
};

// Registers segment [a, b] as `item` in the cells (side `cell`) of the
// bounding boxes of its parts no longer than a cell, so a long diagonal
// stays a thin band of cells: (cell key, item) pairs for a sim::StaticGrid.
void add_segment_cells(glm::vec2 a, glm::vec2 b, float cell, std::int32_t item,
                       std::vector<std::pair<std::uint64_t, std::int32_t>>& pairs);

// Smallest distance between segments [a, b] and [c, d] (0 when they cross).
float segment_segment_distance(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d);

}  // namespace throng::path
