// The walkable area of a world as analysis tools want it: the region agents
// may walk in, minus the union of every obstacle, written as WKT (OGC Simple
// Features text, what JuPedSim's SQLite files and PedPy's WalkableArea read)
// and as GeoJSON (RFC 7946).
//
// The shapes come from path::FreeSpace: vertices snapped to 1 mm, circles
// replaced by circumscribed polygons (vertices at most 1 cm outside the
// circle), overlapping obstacles merged, obstacles reaching past the
// boundary cut off by it. A world with no walkable boundary gets its
// bounding box (obstacles and `extent`) grown by 2 m as the outer ring.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/geometry.h"
#include "sim/simulation.h"
#include "sim/world.h"

namespace throng::io {

// Connected parts of free space, each an outer ring (counter-clockwise) with
// holes (clockwise), coordinates rounded to the millimetre. Each ring starts
// at its lowest-leftmost vertex and parts are in that vertex's order, so the
// same world always prints the same text.
std::vector<sim::Polygon> walkable_area(const sim::World& world, const sim::Aabb& extent = {});
// The same for a simulation: without a walkable boundary, the extent also
// holds every agent's current position, so a run's start lies inside it.
std::vector<sim::Polygon> walkable_area(const sim::Simulation& sim);

// "POLYGON ((x y, ...), (hole ...))" for one part, "MULTIPOLYGON (((...)), ...)"
// for several, "POLYGON EMPTY" for none. Rings are closed (last point = first).
std::string to_wkt(const std::vector<sim::Polygon>& area);
// A FeatureCollection with one Feature holding the Polygon or MultiPolygon.
nlohmann::json to_geojson(const std::vector<sim::Polygon>& area);

// DIR/geometry.wkt and DIR/geometry.geojson, each written whole (temporary
// file, then rename).
struct GeometryFiles {
  std::string wkt, geojson;
};
GeometryFiles write_geometry_files(const std::string& dir, const std::vector<sim::Polygon>& area);

}  // namespace throng::io
