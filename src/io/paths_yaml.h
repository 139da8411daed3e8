// The input of `throng match`: paths given as polylines or as (from, to)
// queries planned on an optional obstacle world, each with a desired speed
// and marked stretches (format: docs/path.md). Errors carry file:line:column.
#pragma once

#include <glm/vec2.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "path/spline.h"
#include "sim/geometry.h"

namespace throng::io {

struct PathEntry {
  std::string name;
  std::vector<glm::vec2> points;  // explicit polyline; empty when planned
  bool planned = false;
  glm::vec2 from{0.0f}, to{0.0f};
  float speed = 0.0f;  // desired, m/s (0 = any)
  std::vector<path::PathMark> marks;
  Location where;
};

struct PathsFile {
  std::string machine;   // state machine file (resolved against the paths file's folder); empty = default
  float radius = 0.25f;  // agent radius for planning
  bool has_world = false;
  bool has_walkable = false;
  sim::Polygon walkable;
  std::vector<sim::Polygon> polygons;
  std::vector<sim::Circle> circles;
  std::vector<PathEntry> paths;
};

PathsFile parse_paths(std::string_view text, const std::string& name);
PathsFile read_paths(const std::string& file);

}  // namespace throng::io
