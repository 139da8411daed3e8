#include "sim/navigation_field.h"

#include <fmt/format.h>

#include <utility>

#include "core/error.h"

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
