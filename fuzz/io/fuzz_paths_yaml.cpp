// libFuzzer target for the paths reader of `throng match`: any bytes either
// read or throw throng::Error naming a file position; a file that reads has
// polylines of at least two finite points, and when it has a world, that
// world's free space builds and its planned queries are answered.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/error.h"
#include "io/paths_yaml.h"
#include "path/planner.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  io::PathsFile file;
  try {
    file = io::parse_paths(text, "fuzz.yaml");
  } catch (const Error& e) {
    if (e.location().line <= 0 && e.location().file.empty()) std::abort();  // every error says where
    return 0;
  }
  for (const io::PathEntry& p : file.paths) {
    if (!p.planned && p.points.size() < 2) std::abort();
    for (const glm::vec2 q : p.points)
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) std::abort();
  }
  if (!file.has_world) return 0;
  try {
    path::PlanOptions o;
    o.radius = file.radius;
    o.free_space.resolution = 0.01f;  // coarser snapping: large fuzzed worlds stay quick
    const path::Planner planner = path::Planner::build(
        path::FreeSpace::build(file.has_walkable ? &file.walkable : nullptr, file.polygons, file.circles, o.free_space),
        o);
    int queries = 0;
    for (const io::PathEntry& p : file.paths) {
      if (!p.planned || ++queries > 4) continue;
      const path::PlannedPath planned = planner.plan({p.from, p.to});
      for (const glm::vec2 q : planned.points)
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) std::abort();
    }
  } catch (const Error&) {
    // A world the planner rejects (coordinates beyond the snapped range, a bad radius): fine, it said so.
  }
  return 0;
}
