// Navigation fields: for a target (a goal or an exit), the walking distance
// to it from every node of a regular grid over the walkable area, computed
// once and shared by every agent heading there. An agent whose current
// waypoint is a field's target steers down the field's gradient instead of
// at the point: round corners and through openings along the shortest way,
// across the whole width of a passage, with no waypoints at inner corners
// and no per-agent search. path/distance_field.h builds them (fast
// marching); the kernels here only sample them, on the CPU or the GPU.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/vec2.hpp>
#include <span>
#include <vector>

#include "core/buffer.h"
#include "core/config.h"
#include "core/span.h"
#include "sim/geometry.h"

namespace throng::sim {

// One field's grid: node (i, j) lies at origin + (i, j) * cell; its
// distance is distance[offset + j * nx + i] (m of walking, weighted near
// walls; INFINITY where the agent's disc does not fit).
struct FieldGrid {
  glm::vec2 origin{0.0f};
  float cell = 0.2f;  // m
  std::int32_t nx = 0, ny = 0;
  std::int64_t offset = 0;
  glm::vec2 target{0.0f};
  glm::vec2 target_half{0.0f};  // m: a door line's target, target +- this (seeded along it); zero for a point
};

// The point of the field's target (a point, or a door line) nearest p.
THRONG_HOST_DEVICE inline glm::vec2 field_target_near(const FieldGrid& g, glm::vec2 p) {
  const float h2 = dot2(g.target_half, g.target_half);
  if (h2 == 0.0f) return g.target;
  const float t = fminf(fmaxf(dot2(p - g.target, g.target_half) / h2, -1.0f), 1.0f);
  return g.target + g.target_half * t;
}

// A field as the builder returns it, before it joins the run's fields.
struct FieldData {
  FieldGrid grid;  // offset ignored
  std::vector<float> distance;
};

// Every field of a run, as the kernels read them.
struct FieldsView {
  Span<const FieldGrid> grids;
  Span<const float> distance;
};

// The field whose target is `target` (exactly: targets are copied, not
// computed), or -1.
THRONG_HOST_DEVICE inline std::int32_t field_of(const FieldsView& f, glm::vec2 target) {
  for (Index k = 0; k < f.grids.size(); ++k)
    if (f.grids[k].target.x == target.x && f.grids[k].target.y == target.y) return static_cast<std::int32_t>(k);
  return -1;
}

// The four nodes of field `field` round p: their distances (i, j), (i+1,
// j), (i, j+1), (i+1, j+1) and p's place in the cell (tx, ty in [0, 1)).
// False outside the grid (checked as floats first: NaN or a huge position
// has no integer cell).
struct FieldCell {
  float v[4];
  float tx, ty;
};
THRONG_HOST_DEVICE inline bool field_cell(const FieldsView& f, std::int32_t field, glm::vec2 p, FieldCell& out) {
  const FieldGrid& g = f.grids[field];
  const float gx = (p.x - g.origin.x) / g.cell, gy = (p.y - g.origin.y) / g.cell;
  if (!(gx >= 0.0f && gy >= 0.0f && gx < static_cast<float>(g.nx - 1) && gy < static_cast<float>(g.ny - 1)))
    return false;
  const float fx = floorf(gx), fy = floorf(gy);
  const auto i = static_cast<std::int32_t>(fx), j = static_cast<std::int32_t>(fy);
  if (!(i + 1 < g.nx && j + 1 < g.ny)) return false;
  const float* d = f.distance.data() + g.offset + static_cast<std::int64_t>(j) * g.nx + i;
  out = {{d[0], d[1], d[g.nx], d[g.nx + 1]}, gx - fx, gy - fy};
  return true;
}

// Where an agent at p heading for the field's target steers: the target
// itself within two cells of it (of a door line: its nearest point), else
// a point a metre down the field's gradient (bilinear over the four nodes
// round p; a node where the disc
// does not fit counts as a cell farther than the farthest of the others, so
// the gradient also leads away from walls). Outside the grid, or with every
// node blocked: the target. (Comparing the field's distance with the
// straight one cannot tell "in plain view": a wall corner the way grazes
// lengthens it by centimetres, the grid's own error by per cent.)
THRONG_HOST_DEVICE inline glm::vec2 field_aim(const FieldsView& f, std::int32_t field, glm::vec2 p) {
  const FieldGrid& g = f.grids[field];
  const glm::vec2 near = field_target_near(g, p);
  FieldCell c;
  if (length_of(near - p) <= 2.0f * g.cell || !field_cell(f, field, p, c)) return near;
  float worst = -1.0f;
  for (float x : c.v)
    if (x < INFINITY) worst = fmaxf(worst, x);
  if (worst < 0.0f) return near;
  for (float& x : c.v)
    if (!(x < INFINITY)) x = worst + g.cell;
  const float* v = c.v;
  const float tx = c.tx, ty = c.ty;
  const glm::vec2 grad((v[1] - v[0]) * (1 - ty) + (v[3] - v[2]) * ty, (v[2] - v[0]) * (1 - tx) + (v[3] - v[1]) * tx);
  const float len = length_of(grad);
  if (!(len > 0.0f)) return near;
  return p - grad * (1.0f / len);
}

// The field's distance at p (bilinear over the four nodes round it; blocked
// nodes left out, weights renormalised), or INFINITY outside the grid or
// where all four are blocked.
THRONG_HOST_DEVICE inline float field_distance(const FieldsView& f, std::int32_t field, glm::vec2 p) {
  FieldCell c;
  if (!field_cell(f, field, p, c)) return INFINITY;
  const float w[4] = {(1 - c.tx) * (1 - c.ty), c.tx * (1 - c.ty), (1 - c.tx) * c.ty, c.tx * c.ty};
  float sum = 0.0f, weight = 0.0f;
  for (int k = 0; k < 4; ++k)
    if (c.v[k] < INFINITY) {
      sum += w[k] * c.v[k];
      weight += w[k];
    }
  return weight > 0.0f ? sum / weight : INFINITY;
}

// A run's fields in current_memory(): added on the host, then uploaded.
class NavigationFields {
 public:
  // Adds a field; returns its index.
  std::int32_t add(FieldData field);
  // Copies every field added to current_memory() (once, after the last add).
  void upload();
  FieldsView view() const { return {grids_.span(), distance_.span()}; }
  FieldsView host_view() const;  // the host copies (outputs and tests)
  std::int32_t count() const { return static_cast<std::int32_t>(host_grids_.size()); }
  const FieldGrid& grid(std::int32_t k) const { return host_grids_[static_cast<std::size_t>(k)]; }
  // Replaces the distances of field k with those of `field`, which must lie
  // on the same grid (origin, cell and size; else an Error), on the host;
  // upload() copies them on.
  void replace(std::int32_t k, const FieldData& field);
  // The distances of field k, host copy (outputs and tests).
  std::span<const float> distances(std::int32_t k) const;
  std::size_t bytes() const { return host_distance_.size() * sizeof(float); }

 private:
  std::vector<FieldGrid> host_grids_;
  std::vector<float> host_distance_;
  Buffer<FieldGrid> grids_;
  Buffer<float> distance_;
};

// The way an agent starting at `start` walks down field k, as the kernels
// steer it (field_aim), with no one in the way: points `step` m apart until
// the target (at most `max_points`), then thinned to where the way bends by
// more than `tolerance` m. Starts with `start`; ends with the target when
// the walk reached it, else where the field ends (outside its grid, or
// every node round the point blocked) or the points ran out. For route
// outputs.
std::vector<glm::vec2> trace_field(const FieldsView& f, std::int32_t k, glm::vec2 start, float step = 0.1f,
                                   std::int32_t max_points = 200000, float tolerance = 0.1f);

// The lines of equal walking distance of field k, every `spacing` m (or s
// for a weighed field), as segments across the grid's cells (marching
// squares, the distance linear along each cell edge; cells with a blocked
// node are left out), at most max_segments of them; spacing at least a
// hundredth of the grid's cell (else an Error). For drawing the field.
std::vector<std::vector<glm::vec2>> field_contours(const FieldsView& f, std::int32_t k, float spacing,
                                                   std::size_t max_segments = 1'000'000);

// The crowd's density over a grid of square cells (host), for fields that
// weigh congestion (`planning: quickest`): agents per m^2 of each cell,
// averaged over the cell and its eight neighbours, so that an agent's own
// presence weighs a ninth of a lone cell's and the map changes smoothly.
struct CrowdDensity {
  glm::vec2 origin{0.0f};
  float cell = 1.0f;  // m
  std::int32_t nx = 0, ny = 0;
  std::vector<float> density;  // agents / m^2, row by row
  // The density of the cell holding p; 0 outside the grid.
  float at(glm::vec2 p) const;
};
// The density of the active agents over `bounds` in cells of side `cell`.
// `free_area` (m^2 per cell, row by row; empty: every cell wholly free)
// is the walkable part of each cell: the agents of a 3x3 window are divided
// by the window's free area (0 where it has less than a quarter of a cell),
// so a crowd along a wall or in a narrow corridor reads its true density.
CrowdDensity crowd_density(std::span<const glm::vec2> positions, std::span<const std::uint8_t> flags,
                           const Aabb& bounds, float cell = 1.0f, std::span<const float> free_area = {});
// Its two halves: the cells over `bounds` (densities 0), and the densities
// of the active agents in them.
CrowdDensity density_cells(const Aabb& bounds, float cell);
void count_crowd(CrowdDensity& d, std::span<const glm::vec2> positions, std::span<const std::uint8_t> flags,
                 std::span<const float> free_area = {});

// Weidmann's speed at `density` (agents / m^2): v0 (1 - exp(-gamma (1/rho
// - 1/rho_max))) with v0 1.34 m/s, gamma 1.913 /m^2, rho_max 5.4 /m^2
// (Weidmann 1993); v0 at 0 and below, 0 from rho_max on.
float weidmann_speed(float density);
// How much slower walking is at `density` than in the open: the free speed
// over Weidmann's speed there, at most kMaxCongestion; 1 in the open.
inline constexpr float kMaxCongestion = 10.0f;
float congestion_slowness(float density);

class World;

// The hook a run's navigation plugs into (path/distance_field.h has the
// fast-marching builder `throng run` uses for `planning: field` and
// `planning: quickest`): the field of walking distances to `target` (to
// the door line target +- target_half, where that is not zero) for discs
// of `radius`; with `crowd`, of walking times at its density
// (congestion_slowness), in seconds at the free speed of 1 m/s. build()
// may be called from several threads at once (planning: quickest weighs a
// run's fields in parallel).
class FieldBuilder {
 public:
  virtual ~FieldBuilder() = default;
  virtual FieldData build(const World& world, glm::vec2 target, float radius, const CrowdDensity* crowd = nullptr,
                          glm::vec2 target_half = glm::vec2(0.0f)) const = 0;
};

}  // namespace throng::sim
