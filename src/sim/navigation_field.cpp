#include "sim/navigation_field.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "sim/crowd.h"

namespace throng::sim {

std::int32_t NavigationFields::add(FieldData field) {
  const auto nodes = static_cast<std::size_t>(field.grid.nx) * static_cast<std::size_t>(field.grid.ny);
  if (field.grid.nx < 2 || field.grid.ny < 2 || field.distance.size() != nodes)
    throw Error(fmt::format("a navigation field of {} x {} nodes came with {} distances", field.grid.nx, field.grid.ny,
                            field.distance.size()));
  field.grid.offset = static_cast<std::int64_t>(host_distance_.size());
  host_grids_.push_back(field.grid);
  host_distance_.insert(host_distance_.end(), field.distance.begin(), field.distance.end());
  return static_cast<std::int32_t>(host_grids_.size() - 1);
}

void NavigationFields::upload() {
  grids_ = Buffer<FieldGrid>(std::span<const FieldGrid>(host_grids_), current_memory());
  distance_ = Buffer<float>(std::span<const float>(host_distance_), current_memory());
}

void NavigationFields::replace(std::int32_t k, const FieldData& field) {
  const FieldGrid& g = grid(k);
  const FieldGrid& f = field.grid;
  if (f.origin != g.origin || f.cell != g.cell || f.nx != g.nx || f.ny != g.ny ||
      field.distance.size() != static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny))
    throw Error(fmt::format("navigation field {} ({} x {} nodes of {} m) replaced by one of {} x {} nodes of {} m", k,
                            g.nx, g.ny, g.cell, f.nx, f.ny, f.cell));
  std::copy(field.distance.begin(), field.distance.end(),
            host_distance_.begin() + static_cast<std::ptrdiff_t>(g.offset));
}

float CrowdDensity::at(glm::vec2 p) const {
  const float gx = (p.x - origin.x) / cell, gy = (p.y - origin.y) / cell;
  if (!(gx >= 0.0f && gy >= 0.0f && gx < static_cast<float>(nx) && gy < static_cast<float>(ny))) return 0.0f;
  return density[static_cast<std::size_t>(static_cast<std::int32_t>(gy)) * static_cast<std::size_t>(nx) +
                 static_cast<std::size_t>(static_cast<std::int32_t>(gx))];
}

CrowdDensity density_cells(const Aabb& bounds, float cell) {
  CrowdDensity d;
  d.cell = cell;
  d.origin = bounds.min;
  d.nx = std::max(1, static_cast<std::int32_t>(std::ceil(bounds.size().x / cell)));
  d.ny = std::max(1, static_cast<std::int32_t>(std::ceil(bounds.size().y / cell)));
  d.density.assign(static_cast<std::size_t>(d.nx) * static_cast<std::size_t>(d.ny), 0.0f);
  return d;
}

void count_crowd(CrowdDensity& d, std::span<const glm::vec2> positions, std::span<const std::uint8_t> flags,
                 std::span<const float> free_area) {
  const auto nx = static_cast<std::size_t>(d.nx);
  std::vector<float> count(d.density.size(), 0.0f);
  if (!free_area.empty() && free_area.size() != count.size())
    throw Error(fmt::format("crowd density: {} free areas for {} cells", free_area.size(), count.size()));
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if ((flags[i] & kAgentActive) == 0) continue;
    const float gx = (positions[i].x - d.origin.x) / d.cell, gy = (positions[i].y - d.origin.y) / d.cell;
    if (gx >= 0.0f && gy >= 0.0f && gx < static_cast<float>(d.nx) && gy < static_cast<float>(d.ny))
      count[static_cast<std::size_t>(gy) * nx + static_cast<std::size_t>(gx)] += 1.0f;
  }
  const float cell_area = d.cell * d.cell;
  for (std::int32_t j = 0; j < d.ny; ++j)
    for (std::int32_t i = 0; i < d.nx; ++i) {
      float agents = 0.0f, area = 0.0f;
      for (std::int32_t y = std::max(0, j - 1); y <= std::min(d.ny - 1, j + 1); ++y)
        for (std::int32_t x = std::max(0, i - 1); x <= std::min(d.nx - 1, i + 1); ++x) {
          const std::size_t k = static_cast<std::size_t>(y) * nx + static_cast<std::size_t>(x);
          agents += count[k];
          area += free_area.empty() ? cell_area : free_area[k];
        }
      if (free_area.empty()) area = 9.0f * cell_area;  // as if the grid went on beyond its edges
      d.density[static_cast<std::size_t>(j) * nx + static_cast<std::size_t>(i)] =
          area >= 0.25f * cell_area ? agents / area : 0.0f;
    }
}

CrowdDensity crowd_density(std::span<const glm::vec2> positions, std::span<const std::uint8_t> flags,
                           const Aabb& bounds, float cell, std::span<const float> free_area) {
  CrowdDensity d = density_cells(bounds, cell);
  count_crowd(d, positions, flags, free_area);
  return d;
}

float weidmann_speed(float density) {
  if (!(density > 0.0f)) return 1.34f;
  return std::max(0.0f, 1.34f * (1.0f - std::exp(-1.913f * (1.0f / density - 1.0f / 5.4f))));
}

float congestion_slowness(float density) {
  if (!(density > 0.0f)) return 1.0f;
  return std::min(kMaxCongestion, 1.34f / std::max(weidmann_speed(density), 1.34f / kMaxCongestion));
}

std::span<const float> NavigationFields::distances(std::int32_t k) const {
  const FieldGrid& g = grid(k);
  return std::span<const float>(host_distance_)
      .subspan(static_cast<std::size_t>(g.offset), static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny));
}

FieldsView NavigationFields::host_view() const {
  return {{host_grids_.data(), static_cast<Index>(host_grids_.size())},
          {host_distance_.data(), static_cast<Index>(host_distance_.size())}};
}

namespace {

// Douglas-Peucker: the points of [a, b] farther than `tolerance` from the
// chord, recursively, appended to `out` (a excluded, b included).
void thin(const std::vector<glm::vec2>& p, std::size_t a, std::size_t b, float tolerance, std::vector<glm::vec2>& out) {
  float worst = -1.0f;
  std::size_t at = a;
  for (std::size_t k = a + 1; k < b; ++k) {
    const float d = distance_to_segment(p[k], p[a], p[b]);
    if (d > worst) {
      worst = d;
      at = k;
    }
  }
  if (worst > tolerance) {
    thin(p, a, at, tolerance, out);
    thin(p, at, b, tolerance, out);
  } else {
    out.push_back(p[b]);
  }
}

}  // namespace

std::vector<glm::vec2> trace_field(const FieldsView& f, std::int32_t k, glm::vec2 start, float step,
                                   std::int32_t max_points, float tolerance) {
  const glm::vec2 target = f.grids[k].target;
  std::vector<glm::vec2> walk = {start};
  glm::vec2 p = start;
  const float near = 2.0f * f.grids[k].cell + step;  // field_aim's own "at the target", and a step
  while (static_cast<std::int32_t>(walk.size()) < max_points) {
    const glm::vec2 aim = field_aim(f, k, p);
    if (aim == target) {
      if (length_of(target - p) <= near) walk.push_back(target);  // else the field ends here
      break;
    }
    p += normalize_or(aim - p, glm::vec2(0.0f)) * step;
    walk.push_back(p);
  }
  std::vector<glm::vec2> out = {start};
  if (walk.size() > 1) thin(walk, 0, walk.size() - 1, tolerance, out);
  return out;
}

}  // namespace throng::sim

namespace throng::sim {

namespace {
// Where the level `d` crosses the edge from node a (value va) to node b.
glm::vec2 level_point(glm::vec2 a, glm::vec2 b, float va, float vb, float d) {
  return a + (b - a) * ((d - va) / (vb - va));
}
}  // namespace

std::vector<std::vector<glm::vec2>> field_contours(const FieldsView& f, std::int32_t k, float spacing,
                                                   std::size_t max_segments) {
  const FieldGrid& g = f.grids[k];
  // (At least a hundredth of a cell: finer lines would be a smear, and the
  // levels of a cell stay few.)
  if (!(spacing >= 0.01f * g.cell) || !std::isfinite(spacing))
    throw Error(fmt::format("the spacing of a field's lines must be a number of metres of at least {:.3g} (got {})",
                            0.01f * g.cell, spacing));
  std::vector<std::vector<glm::vec2>> out;
  const float* d = f.distance.data() + g.offset;
  auto node = [&](std::int32_t i, std::int32_t j) {
    return g.origin + glm::vec2(static_cast<float>(i) * g.cell, static_cast<float>(j) * g.cell);
  };
  for (std::int32_t j = 0; j + 1 < g.ny; ++j)
    for (std::int32_t i = 0; i + 1 < g.nx; ++i) {
      // Corners counter-clockwise: (i, j), (i+1, j), (i+1, j+1), (i, j+1).
      const float v[4] = {d[static_cast<std::int64_t>(j) * g.nx + i], d[static_cast<std::int64_t>(j) * g.nx + i + 1],
                          d[static_cast<std::int64_t>(j + 1) * g.nx + i + 1],
                          d[static_cast<std::int64_t>(j + 1) * g.nx + i]};
      const glm::vec2 p[4] = {node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)};
      if (!(v[0] < INFINITY && v[1] < INFINITY && v[2] < INFINITY && v[3] < INFINITY)) continue;  // by a wall
      const float lo = std::min({v[0], v[1], v[2], v[3]}), hi = std::max({v[0], v[1], v[2], v[3]});
      for (auto m = static_cast<std::int64_t>(std::ceil(lo / spacing));; ++m) {
        const float level = static_cast<float>(m) * spacing;
        if (!(level < hi)) break;
        if (level <= lo) continue;  // a corner on the level: the neighbouring cell draws it
        glm::vec2 cross[4];
        int n = 0;
        for (int e = 0; e < 4; ++e) {
          const float va = v[e], vb = v[(e + 1) % 4];
          if ((va < level) != (vb < level)) cross[n++] = level_point(p[e], p[(e + 1) % 4], va, vb, level);
        }
        if (n == 2) out.push_back({cross[0], cross[1]});
        if (n == 4) {  // a saddle: pair the crossings by the level of the cell's middle
          const bool middle_below = 0.25f * (v[0] + v[1] + v[2] + v[3]) < level;
          const bool first_below = v[0] < level;
          if (middle_below == first_below) {
            out.push_back({cross[0], cross[1]});
            out.push_back({cross[2], cross[3]});
          } else {
            out.push_back({cross[3], cross[0]});
            out.push_back({cross[1], cross[2]});
          }
        }
        if (out.size() >= max_segments) return out;
      }
    }
  return out;
}

}  // namespace throng::sim
