#include "io/walkable_area.h"

#include <fmt/format.h>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "io/run_outputs.h"
#include "path/free_space.h"

namespace throng::io {

namespace {

// Boost's union leaves the vertices where merged obstacles met on a straight
// edge; a vertex whose neighbours continue straight through it says nothing.
void drop_straight_vertices(sim::Ring& ring) {
  for (std::size_t i = 0; ring.size() > 3 && i < ring.size();) {
    const glm::dvec2 a(ring[(i + ring.size() - 1) % ring.size()]), b(ring[i]), c(ring[(i + 1) % ring.size()]);
    const glm::dvec2 u = b - a, v = c - b;
    const bool straight =
        std::fabs(u.x * v.y - u.y * v.x) <= 1e-9 * glm::length(u) * glm::length(v) && glm::dot(u, v) > 0;
    if (straight)
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
    else
      ++i;
  }
}

// The ring in the requested winding (RFC 7946: exterior counter-clockwise,
// holes clockwise; FreeSpace's own winding is not specified), without
// repeated points: Boost returns rings closed (last point = first), and the
// writers below close them once.
sim::Ring oriented(const sim::Ring& r, bool counter_clockwise) {
  sim::Ring out;
  for (glm::vec2 p : r)
    if (out.empty() || p != out.back()) out.push_back(p);
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
  drop_straight_vertices(out);
  // Start at the lowest-leftmost vertex, so equal areas print equal.
  const auto first = std::min_element(out.begin(), out.end(),
                                      [](glm::vec2 a, glm::vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::rotate(out.begin(), first, out.end());
  if ((sim::signed_area2(out) > 0) != counter_clockwise) std::reverse(out.begin(), out.end());
  return out;
}

template <class Out>
void append_ring_wkt(Out out, const sim::Ring& r) {
  *out++ = '(';
  for (std::size_t i = 0; i <= r.size(); ++i) {
    const glm::vec2 p = r[i % r.size()];
    fmt::format_to(out, "{}{} {}", i == 0 ? "" : ", ", round_to_mm(p.x), round_to_mm(p.y));
  }
  *out++ = ')';
}

template <class Out>
void append_polygon_wkt(Out out, const sim::Polygon& p) {
  *out++ = '(';
  append_ring_wkt(out, p.outer);
  for (const sim::Ring& h : p.holes) {
    fmt::format_to(out, ", ");
    append_ring_wkt(out, h);
  }
  *out++ = ')';
}

nlohmann::json ring_json(const sim::Ring& r) {
  nlohmann::json ring = nlohmann::json::array();
  for (std::size_t i = 0; i <= r.size(); ++i)
    ring.push_back({round_to_mm(r[i % r.size()].x), round_to_mm(r[i % r.size()].y)});
  return ring;
}

nlohmann::json polygon_json(const sim::Polygon& p) {
  nlohmann::json rings = nlohmann::json::array({ring_json(p.outer)});
  for (const sim::Ring& h : p.holes) rings.push_back(ring_json(h));
  return rings;
}

}  // namespace

std::vector<sim::Polygon> walkable_area(const sim::World& world, const sim::Aabb& extent) {
  path::FreeSpaceOptions options;
  options.extent = extent;
  const path::FreeSpace space = path::FreeSpace::build(world, options);
  std::vector<sim::Polygon> parts;
  for (const sim::Polygon& c : space.components()) {
    sim::Polygon p{oriented(c.outer, true), {}};
    if (p.outer.size() < 3) continue;
    for (const sim::Ring& h : c.holes)
      if (sim::Ring hole = oriented(h, false); hole.size() >= 3) p.holes.push_back(std::move(hole));
    parts.push_back(std::move(p));
  }
  std::sort(parts.begin(), parts.end(), [](const sim::Polygon& a, const sim::Polygon& b) {
    return a.outer[0].x < b.outer[0].x || (a.outer[0].x == b.outer[0].x && a.outer[0].y < b.outer[0].y);
  });
  return parts;
}

std::vector<sim::Polygon> walkable_area(const sim::Simulation& sim) {
  sim::Aabb extent;
  if (!sim.world().has_walkable())
    for (glm::vec2 p : sim.positions()) extent.add(p);
  return walkable_area(sim.world(), extent);
}

std::string to_wkt(const std::vector<sim::Polygon>& area) {
  if (area.empty()) return "POLYGON EMPTY";
  std::string s;
  auto out = std::back_inserter(s);
  if (area.size() == 1) {
    s = "POLYGON ";
    append_polygon_wkt(out, area.front());
    return s;
  }
  s = "MULTIPOLYGON (";
  for (std::size_t i = 0; i < area.size(); ++i) {
    if (i > 0) s += ", ";
    append_polygon_wkt(out, area[i]);
  }
  s += ')';
  return s;
}

nlohmann::json to_geojson(const std::vector<sim::Polygon>& area) {
  nlohmann::json geometry;
  if (area.size() == 1) {
    geometry = {{"type", "Polygon"}, {"coordinates", polygon_json(area.front())}};
  } else {
    nlohmann::json polygons = nlohmann::json::array();
    for (const sim::Polygon& p : area) polygons.push_back(polygon_json(p));
    geometry = {{"type", "MultiPolygon"}, {"coordinates", polygons}};
  }
  nlohmann::json feature = {{"type", "Feature"}, {"properties", {{"name", "walkable area"}}}, {"geometry", geometry}};
  return {{"type", "FeatureCollection"}, {"features", nlohmann::json::array({feature})}};
}

GeometryFiles write_geometry_files(const std::string& dir, const std::vector<sim::Polygon>& area) {
  GeometryFiles files{dir + "/geometry.wkt", dir + "/geometry.geojson"};
  write_text_file(files.wkt, to_wkt(area) + "\n");
  write_json_file(files.geojson, to_geojson(area));
  return files;
}

}  // namespace throng::io
