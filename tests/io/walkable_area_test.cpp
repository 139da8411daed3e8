// The walkable area as WKT and GeoJSON: hand-written expected text for small
// worlds (a room with a pillar, a room cut in two, an unbounded world).
#include "io/walkable_area.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/scenario_yaml.h"

namespace throng::io {
namespace {

// A scenario around `world` (one agent, so it builds).
sim::World world_of(const std::string& world) {
  const std::string text = "planning: none\nworld:\n" + world +
                           "groups:\n  - count: 1\n    spawn: {points: [[1, 1]]}\n    goal: {point: [2, 1]}\n";
  return sim::World::build(parse_scenario(text, "world.yaml").spec.world, 4.0f);
}

TEST(WalkableArea, SquareRoomWithOneRectangularObstacleIsAPolygonWithAHole) {
  const sim::World world = world_of(
      "  walkable: {polygon: [[0, 0], [10, 0], [10, 10], [0, 10]]}\n"
      "  obstacles:\n    - rect: {min: [4, 4], max: [6, 6.5]}\n");
  const std::vector<sim::Polygon> area = walkable_area(world);
  EXPECT_EQ(to_wkt(area), "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (4 4, 4 6.5, 6 6.5, 6 4, 4 4))");
  const nlohmann::json expected = nlohmann::json::parse(R"({
    "type": "FeatureCollection",
    "features": [{
      "type": "Feature",
      "properties": {"name": "walkable area"},
      "geometry": {"type": "Polygon", "coordinates": [
        [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]],
        [[4, 4], [4, 6.5], [6, 6.5], [6, 4], [4, 4]]]}
    }]})");
  EXPECT_EQ(to_geojson(area), expected) << to_geojson(area).dump();
}

TEST(WalkableArea, AWallAcrossTheRoomGivesAMultiPolygon) {
  // The wall reaches past the room: the boundary cuts it off.
  const sim::World world = world_of(
      "  walkable: {polygon: [[0, 0], [10, 0], [10, 10], [0, 10]]}\n"
      "  obstacles:\n    - rect: {min: [4, -1], max: [6, 11]}\n");
  const std::vector<sim::Polygon> area = walkable_area(world);
  EXPECT_EQ(to_wkt(area), "MULTIPOLYGON (((0 0, 4 0, 4 10, 0 10, 0 0)), ((6 0, 10 0, 10 10, 6 10, 6 0)))");
  const nlohmann::json g = to_geojson(area)["features"][0]["geometry"];
  EXPECT_EQ(g["type"], "MultiPolygon");
  EXPECT_EQ(g["coordinates"],
            nlohmann::json::parse("[[[[0,0],[4,0],[4,10],[0,10],[0,0]]], [[[6,0],[10,0],[10,10],[6,10],[6,0]]]]"));
}

TEST(WalkableArea, OverlappingObstaclesBecomeOneHole) {
  const sim::World world = world_of(
      "  walkable: {polygon: [[0, 0], [10, 0], [10, 10], [0, 10]]}\n"
      "  obstacles:\n    - rect: {min: [2, 2], max: [5, 4]}\n    - rect: {min: [4, 2], max: [6, 4]}\n");
  EXPECT_EQ(to_wkt(walkable_area(world)), "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 2 4, 6 4, 6 2, 2 2))");
}

TEST(WalkableArea, AWorldWithoutBoundaryUsesItsBoundingBoxGrownBy2m) {
  const sim::World world = world_of("  obstacles:\n    - rect: {min: [0, 0], max: [1, 1]}\n");
  EXPECT_EQ(to_wkt(walkable_area(world)), "POLYGON ((-2 -2, 3 -2, 3 3, -2 3, -2 -2), (0 0, 0 1, 1 1, 1 0, 0 0))");
  sim::Aabb extent;
  extent.add(glm::vec2(-5, 0.5f));
  EXPECT_EQ(to_wkt(walkable_area(world, extent)),
            "POLYGON ((-7 -2, 3 -2, 3 3, -7 3, -7 -2), (0 0, 0 1, 1 1, 1 0, 0 0))");
}

TEST(WalkableArea, GeometryFilesAreWrittenWhole) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "throng_walkable_area_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::vector<sim::Polygon> area = walkable_area(world_of("  walkable: {polygon: [[0, 0], [3, 0], [0, 4]]}\n"));
  const GeometryFiles files = write_geometry_files(dir.string(), area);
  std::ifstream wkt(files.wkt), geojson(files.geojson);
  std::stringstream a, b;
  a << wkt.rdbuf();
  b << geojson.rdbuf();
  EXPECT_EQ(a.str(), "POLYGON ((0 0, 3 0, 0 4, 0 0))\n");
  EXPECT_EQ(nlohmann::json::parse(b.str()), to_geojson(area));
  EXPECT_FALSE(std::filesystem::exists(files.wkt + ".tmp"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace throng::io
