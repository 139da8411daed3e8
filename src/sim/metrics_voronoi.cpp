// Voronoi density and speed (metrics.h): each cell is a disc polygon cut by
// the bisectors of the agent's neighbours, on the host. A neighbour farther
// than twice the cut-off cannot cut the disc, so the cells are exact cuts of
// the full Voronoi diagram by the discs.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "core/parallel.h"
#include "sim/crowd.h"
#include "sim/metrics.h"

namespace throng::sim {

namespace {

// The part of the convex polygon where n . x <= c (Sutherland-Hodgman for one edge).
ConvexPolygon clip(const ConvexPolygon& poly, glm::dvec2 n, double c) {
  ConvexPolygon out;
  const std::size_t k = poly.size();
  out.reserve(k + 1);
  for (std::size_t i = 0; i < k; ++i) {
    const glm::dvec2 p = poly[i], q = poly[(i + 1) % k];
    const double fp = n.x * p.x + n.y * p.y - c, fq = n.x * q.x + n.y * q.y - c;
    if (fp <= 0) out.push_back(p);
    if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0)) out.push_back(p + (fp / (fp - fq)) * (q - p));
  }
  return out;
}

// Agents near a box in a uniform grid of side >= 2 * cutoff: each agent's
// cut-off neighbours lie in its 3x3 cells. Cells list agents in index order.
class NearGrid {
 public:
  NearGrid(std::span<const glm::vec2> points, std::vector<Index> members, double cutoff)
      : points_(points), members_(std::move(members)) {
    Aabb box;
    for (Index i : members_) box.add(points_[static_cast<std::size_t>(i)]);
    if (box.empty()) box.add(glm::vec2(0.0f));
    lo_ = glm::dvec2(box.min);
    const glm::dvec2 extent = glm::dvec2(box.max) - lo_;
    // At least 2 * cutoff, and coarse enough that a sparse crowd in a large
    // box does not ask for more cells than agents.
    side_ = std::max(2.0 * cutoff, std::sqrt(extent.x * extent.y / static_cast<double>(members_.size() + 1)));
    nx_ = static_cast<Index>(extent.x / side_) + 1;
    ny_ = static_cast<Index>(extent.y / side_) + 1;
    start_.assign(static_cast<std::size_t>(nx_ * ny_ + 1), 0);
    for (Index i : members_) ++start_[static_cast<std::size_t>(cell_of(i) + 1)];
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    sorted_.resize(members_.size());
    std::vector<Index> fill(start_.begin(), start_.end() - 1);
    for (Index i : members_) sorted_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_of(i))]++)] = i;
  }

  // Agents within `radius` (<= 2 * cutoff) of agent i, i left out.
  void near(Index i, double radius, std::vector<Index>& out) const {
    out.clear();
    const glm::dvec2 p(points_[static_cast<std::size_t>(i)]);
    const Index cx = coord(p.x - lo_.x, nx_), cy = coord(p.y - lo_.y, ny_);
    for (Index y = std::max<Index>(cy - 1, 0); y <= std::min(cy + 1, ny_ - 1); ++y)
      for (Index x = std::max<Index>(cx - 1, 0); x <= std::min(cx + 1, nx_ - 1); ++x) {
        const std::size_t c = static_cast<std::size_t>(y * nx_ + x);
        for (Index k = start_[c]; k < start_[c + 1]; ++k) {
          const Index j = sorted_[static_cast<std::size_t>(k)];
          const glm::dvec2 d = glm::dvec2(points_[static_cast<std::size_t>(j)]) - p;
          if (j != i && d.x * d.x + d.y * d.y < radius * radius) out.push_back(j);
        }
      }
  }

 private:
  Index coord(double offset, Index cells) const {
    return std::clamp<Index>(static_cast<Index>(offset / side_), 0, cells - 1);
  }
  Index cell_of(Index i) const {
    const glm::dvec2 p(points_[static_cast<std::size_t>(i)]);
    return coord(p.y - lo_.y, ny_) * nx_ + coord(p.x - lo_.x, nx_);
  }
  std::span<const glm::vec2> points_;
  std::vector<Index> members_, sorted_;
  std::vector<Index> start_;
  glm::dvec2 lo_{0.0};
  double side_ = 1.0;
  Index nx_ = 1, ny_ = 1;
};

// The cell of point i: the disc polygon cut by the bisector with each
// neighbour, nearest first. Once a neighbour's bisector (at half its
// distance) lies beyond the cell's farthest corner, it and every farther one
// leave the cell unchanged.
ConvexPolygon cell_of(std::span<const glm::vec2> points, Index i, const std::vector<Index>& neighbours, double cutoff) {
  const glm::dvec2 p(points[static_cast<std::size_t>(i)]);
  ConvexPolygon cell;
  cell.reserve(kVoronoiDiscVertices);
  for (int k = 0; k < kVoronoiDiscVertices; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kVoronoiDiscVertices;
    cell.push_back(p + cutoff * glm::dvec2(std::cos(a), std::sin(a)));
  }
  std::vector<std::pair<double, Index>> by_distance;
  by_distance.reserve(neighbours.size());
  for (Index j : neighbours) {
    const glm::dvec2 d = glm::dvec2(points[static_cast<std::size_t>(j)]) - p;
    by_distance.emplace_back(d.x * d.x + d.y * d.y, j);
  }
  // Ties by index: the same order, so the same rounding, on every run.
  std::sort(by_distance.begin(), by_distance.end());
  double reach2 = cutoff * cutoff;  // squared distance of the cell's farthest corner from p
  for (const auto& [d2, j] : by_distance) {
    if (d2 <= 0.0) continue;  // two agents on one spot: no bisector; each keeps the other's region
    if (0.25 * d2 >= reach2) break;
    const glm::dvec2 q(points[static_cast<std::size_t>(j)]);
    const glm::dvec2 n = q - p;
    cell = clip(cell, n, 0.5 * (n.x * (p.x + q.x) + n.y * (p.y + q.y)));
    reach2 = 0.0;
    for (const glm::dvec2& v : cell) reach2 = std::max(reach2, (v.x - p.x) * (v.x - p.x) + (v.y - p.y) * (v.y - p.y));
  }
  return cell;
}

}  // namespace

double polygon_area(const ConvexPolygon& polygon) {
  double twice = 0;
  for (std::size_t i = 0, k = polygon.size(); i < k; ++i) {
    const glm::dvec2 a = polygon[i], b = polygon[(i + 1) % k];
    twice += a.x * b.y - a.y * b.x;
  }
  return 0.5 * std::fabs(twice);
}

ConvexPolygon clip_to_rect(const ConvexPolygon& polygon, const Aabb& rect) {
  ConvexPolygon out = clip(polygon, {1.0, 0.0}, rect.max.x);
  out = clip(out, {-1.0, 0.0}, -static_cast<double>(rect.min.x));
  out = clip(out, {0.0, 1.0}, rect.max.y);
  return clip(out, {0.0, -1.0}, -static_cast<double>(rect.min.y));
}

std::vector<ConvexPolygon> voronoi_cells(std::span<const glm::vec2> points, float cutoff) {
  const Index n = static_cast<Index>(points.size());
  std::vector<Index> all(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = i;
  const NearGrid grid(points, all, cutoff);
  std::vector<ConvexPolygon> cells(static_cast<std::size_t>(n));
  host_parallel_for(
      "sim.metrics.voronoi", n,
      [&](Index i) {
        std::vector<Index> neighbours;
        grid.near(i, 2.0 * cutoff, neighbours);
        cells[static_cast<std::size_t>(i)] = cell_of(points, i, neighbours, cutoff);
      },
      16);
  return cells;
}

VoronoiSample measure_area_voronoi(std::span<const glm::vec2> positions, std::span<const glm::vec2> velocities,
                                   std::span<const glm::vec2> goals, std::span<const std::uint8_t> flags,
                                   const Aabb& area, float cutoff, const Periodic& periodic) {
  if (periodic.wraps()) {
    // The agents and their copies one period away on every wrapping side:
    // a cell by the seam is cut by the neighbours across it.
    std::vector<glm::vec2> p, v, g;
    std::vector<std::uint8_t> f;
    periodic.for_each_shift([&](glm::vec2 shift) {
      for (std::size_t k = 0; k < positions.size(); ++k) {
        p.push_back(positions[k] + shift);
        v.push_back(velocities[k]);
        g.push_back(goals[k] + shift);
        f.push_back(flags[k]);
      }
    });
    return measure_area_voronoi(p, v, g, f, area, cutoff);
  }
  VoronoiSample s;
  // In double like the cells: float differences would put the area's size
  // off the sum of the cell parts by a float rounding.
  const double size = (static_cast<double>(area.max.x) - area.min.x) * (static_cast<double>(area.max.y) - area.min.y);
  if (area.empty() || !(size > 0) || !(cutoff > 0)) return s;
  // A cell stays within `cutoff` of its agent, and only agents within twice
  // that can cut it: agents farther than 3 cut-offs from the area play no part.
  auto near_area = [&](glm::vec2 p, float margin) {
    return p.x >= area.min.x - margin && p.x <= area.max.x + margin && p.y >= area.min.y - margin &&
           p.y <= area.max.y + margin;
  };
  std::vector<Index> members, inside;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if ((flags[i] & kAgentActive) == 0 || !near_area(positions[i], 3.0f * cutoff)) continue;
    members.push_back(static_cast<Index>(i));
    if (near_area(positions[i], cutoff)) inside.push_back(static_cast<Index>(i));
  }
  if (inside.empty()) return s;
  const NearGrid grid(positions, std::move(members), cutoff);
  std::vector<double> part(inside.size()), whole(inside.size());
  host_parallel_for(
      "sim.metrics.voronoi", static_cast<Index>(inside.size()),
      [&](Index k) {
        std::vector<Index> neighbours;
        const Index i = inside[static_cast<std::size_t>(k)];
        grid.near(i, 2.0 * cutoff, neighbours);
        const ConvexPolygon cell = cell_of(positions, i, neighbours, cutoff);
        whole[static_cast<std::size_t>(k)] = polygon_area(cell);
        part[static_cast<std::size_t>(k)] = polygon_area(clip_to_rect(cell, area));
      },
      16);
  // Summed in agent order: the same result for any thread count.
  double density = 0, speed = 0, magnitude = 0, covered = 0;
  for (std::size_t k = 0; k < inside.size(); ++k) {
    if (!(part[k] > 0) || !(whole[k] > 0)) continue;
    const std::size_t i = static_cast<std::size_t>(inside[k]);
    density += part[k] / whole[k];
    speed += static_cast<double>(speed_towards(velocities[i], positions[i], goals[i])) * part[k];
    magnitude += static_cast<double>(length_of(velocities[i])) * part[k];
    covered += part[k];
  }
  s.density = density / size;
  s.speed = speed / size;
  s.speed_magnitude = magnitude / size;
  s.covered = covered;
  return s;
}

}  // namespace throng::sim
