// Host-side geometry the renderer uploads once: the unit sphere that joint
// mode squashes along each bone, and the extruded obstacles.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "core/span.h"
#include "render/scene.h"
#include "sim/geometry.h"

namespace throng::render {

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
  std::int32_t triangle_count() const { return static_cast<std::int32_t>(indices.size() / 3); }
};

// A UV sphere of radius 1 (normals = positions); slices >= 3, stacks >= 2.
Mesh unit_sphere(std::int32_t slices, std::int32_t stacks);

// Obstacles of the map extruded to `style.height` in the Y-up world
// (core/ground.h). `walls`: two triangles per ring edge (any winding) with outward
// normals (into the holes for holes). `caps`: a triangle fan per ring at
// the top, to be filled by the even-odd rule (the renderer's stencil pass),
// which is the rule the simulation uses for polygons with holes.
struct ObstacleMesh {
  Mesh walls;
  std::vector<glm::vec3> cap_triangles;  // three vertices a triangle
  float height = 0.0f;
};
ObstacleMesh extrude_obstacles(Span<const sim::Polygon> polygons, Span<const sim::Circle> circles,
                               const ObstacleStyle& style);

}  // namespace throng::render
