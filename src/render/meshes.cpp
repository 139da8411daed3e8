#include "render/meshes.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"
#include "core/ground.h"

namespace throng::render {

Mesh unit_sphere(std::int32_t slices, std::int32_t stacks) {
  if (slices < 3 || stacks < 2)
    throw Error(fmt::format("sphere needs slices >= 3 and stacks >= 2, not {} x {}", slices, stacks));
  Mesh m;
  const float pi = 3.14159265358979f;
  for (std::int32_t i = 0; i <= stacks; ++i) {
    const float polar = pi * static_cast<float>(i) / static_cast<float>(stacks);  // 0 at +Y
    for (std::int32_t j = 0; j <= slices; ++j) {
      const float azimuth = 2.0f * pi * static_cast<float>(j) / static_cast<float>(slices);
      const glm::vec3 p(std::sin(polar) * std::sin(azimuth), std::cos(polar), std::sin(polar) * std::cos(azimuth));
      m.positions.push_back(p);
      m.normals.push_back(p);
    }
  }
  const auto at = [&](std::int32_t i, std::int32_t j) { return static_cast<std::uint32_t>(i * (slices + 1) + j); };
  for (std::int32_t i = 0; i < stacks; ++i)
    for (std::int32_t j = 0; j < slices; ++j) {
      // Seen from outside, azimuth grows to the right and polar downwards.
      if (i > 0) m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i < stacks - 1) m.indices.insert(m.indices.end(), {at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  return m;
}

namespace {
void add_ring(ObstacleMesh& out, const std::vector<glm::vec2>& ring, bool solid_inside) {
  if (ring.size() < 3) return;
  const bool counter_clockwise = sim::signed_area2(ring) > 0.0;
  // Walls face away from the solid: right of each edge for a
  // counter-clockwise outer ring, the other way for holes.
  const float side = counter_clockwise == solid_inside ? 1.0f : -1.0f;
  const float h = out.height;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const glm::vec2 a = ring[i], b = ring[(i + 1) % ring.size()];
    const glm::vec2 d = b - a;
    const float len = std::sqrt(d.x * d.x + d.y * d.y);
    if (len <= 0.0f) continue;
    const glm::vec2 n_map = side * glm::vec2(d.y, -d.x) / len;
    const glm::vec3 n = world_from_ground(n_map);
    const auto base = static_cast<std::uint32_t>(out.walls.positions.size());
    for (const glm::vec3& p :
         {world_from_ground(a), world_from_ground(b), world_from_ground(b, h), world_from_ground(a, h)}) {
      out.walls.positions.push_back(p);
      out.walls.normals.push_back(n);
    }
    // Walls are drawn without face culling, so the winding does not matter.
    out.walls.indices.insert(out.walls.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  for (std::size_t i = 1; i + 1 < ring.size(); ++i) {
    out.cap_triangles.push_back(world_from_ground(ring[0], h));
    out.cap_triangles.push_back(world_from_ground(ring[i], h));
    out.cap_triangles.push_back(world_from_ground(ring[i + 1], h));
  }
}
}  // namespace

ObstacleMesh extrude_obstacles(Span<const sim::Polygon> polygons, Span<const sim::Circle> circles,
                               const ObstacleStyle& style) {
  if (!(style.height > 0.0f) || !std::isfinite(style.height))
    throw Error("must be positive and finite", at_field("obstacles.height"));
  if (style.circle_segments < 3 || style.circle_segments > 4096)
    throw Error("must be within 3..4096", at_field("obstacles.circle_segments"));
  ObstacleMesh out;
  out.height = style.height;
  for (const sim::Polygon& p : polygons) {
    add_ring(out, p.outer, true);
    for (const sim::Ring& hole : p.holes) add_ring(out, hole, false);
  }
  std::vector<glm::vec2> ring(static_cast<std::size_t>(style.circle_segments));
  for (const sim::Circle& c : circles) {
    for (std::int32_t k = 0; k < style.circle_segments; ++k) {
      const float a = 6.28318530718f * static_cast<float>(k) / static_cast<float>(style.circle_segments);
      ring[static_cast<std::size_t>(k)] = c.center + c.radius * glm::vec2(std::cos(a), std::sin(a));
    }
    add_ring(out, ring, true);
  }
  return out;
}

}  // namespace throng::render
