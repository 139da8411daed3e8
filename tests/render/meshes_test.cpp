#include "render/meshes.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/ground.h"

namespace throng::render {
namespace {

// Signed volume of a closed triangle mesh (divergence theorem).
double volume(const Mesh& m) {
  double v = 0.0;
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const glm::dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

TEST(UnitSphere, IsAClosedOutwardFacingUnitSphere) {
  for (auto [slices, stacks] : {std::pair{14, 9}, std::pair{6, 4}, std::pair{4, 2}}) {
    const Mesh m = unit_sphere(slices, stacks);
    for (const glm::vec3& p : m.positions) EXPECT_NEAR(glm::length(p), 1.0f, 1e-5f);
    // Closed and counter-clockwise from outside: positive volume a little
    // under the sphere's, approaching it with resolution.
    const double v = volume(m);
    EXPECT_GT(v, 0.0) << slices << "x" << stacks;
    EXPECT_LT(v, 4.18879);
    for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      const glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
                      c = m.positions[m.indices[t + 2]];
      EXPECT_GT(glm::dot(glm::cross(b - a, c - a), a + b + c), 0.0f);
    }
    EXPECT_EQ(m.triangle_count(), 2 * slices * (stacks - 1));
  }
  EXPECT_GT(volume(unit_sphere(14, 9)), 0.9 * 4.18879);
  EXPECT_THROW(unit_sphere(2, 4), Error);
}

TEST(ExtrudeObstacles, WallsFaceAwayFromTheSolidAndCapsCoverIt) {
  sim::Polygon square;
  square.outer = {{0.0f, 0.0f}, {4.0f, 0.0f}, {4.0f, 4.0f}, {0.0f, 4.0f}};    // counter-clockwise
  square.holes = {{{1.0f, 1.0f}, {1.0f, 3.0f}, {3.0f, 3.0f}, {3.0f, 1.0f}}};  // clockwise
  std::vector<sim::Polygon> polygons = {square};
  std::vector<sim::Circle> circles = {{{10.0f, 0.0f}, 1.0f}};
  ObstacleStyle style;
  style.height = 2.0f;
  style.circle_segments = 16;
  const ObstacleMesh m = extrude_obstacles(polygons, circles, style);
  EXPECT_EQ(m.walls.positions.size(), 4u * (4 + 4 + 16));
  EXPECT_EQ(m.walls.indices.size(), 6u * (4 + 4 + 16));
  // Each wall quad's normal points from the solid into free space: from
  // its midpoint, a step along the normal is free, a step against it solid.
  const auto solid = [&](glm::vec2 p) {
    const bool in_square = sim::point_in_polygon(p, square);
    return in_square || glm::length(p - glm::vec2(10.0f, 0.0f)) < 1.0f;
  };
  for (std::size_t q = 0; q < m.walls.positions.size(); q += 4) {
    const glm::vec2 mid =
        0.5f * (ground_from_world(m.walls.positions[q]) + ground_from_world(m.walls.positions[q + 1]));
    const glm::vec2 n = ground_from_world(m.walls.normals[q]);
    EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
    EXPECT_FALSE(solid(mid + 0.05f * n)) << "wall " << q / 4;
    EXPECT_TRUE(solid(mid - 0.05f * n)) << "wall " << q / 4;
    for (std::size_t k = 0; k < 4; ++k)
      EXPECT_TRUE(m.walls.positions[q + k].y == 0.0f || m.walls.positions[q + k].y == 2.0f);
  }
  // Caps: fans at the top; by the even-odd rule their coverage of a point
  // is odd exactly where the obstacle is solid.
  ASSERT_EQ(m.cap_triangles.size() % 3, 0u);
  for (const glm::vec3& v : m.cap_triangles) EXPECT_EQ(v.y, 2.0f);
  const auto covered_odd = [&](glm::vec2 p) {
    int count = 0;
    for (std::size_t t = 0; t < m.cap_triangles.size(); t += 3) {
      const glm::vec2 a = ground_from_world(m.cap_triangles[t]), b = ground_from_world(m.cap_triangles[t + 1]),
                      c = ground_from_world(m.cap_triangles[t + 2]);
      const float d1 = sim::cross2(b - a, p - a), d2 = sim::cross2(c - b, p - b), d3 = sim::cross2(a - c, p - c);
      const bool has_neg = d1 < 0 || d2 < 0 || d3<0, has_pos = d1> 0 || d2 > 0 || d3 > 0;
      if (!(has_neg && has_pos)) ++count;
    }
    return count % 2 == 1;
  };
  for (float x = -1.13f; x < 12.0f; x += 0.37f)
    for (float y = -1.21f; y < 5.0f; y += 0.41f) {
      const glm::vec2 p(x, y);
      // The circle is a 16-gon: skip points between it and its polygon.
      if (std::abs(glm::length(p - glm::vec2(10.0f, 0.0f)) - 1.0f) < 0.05f) continue;
      EXPECT_EQ(covered_odd(p), solid(p)) << x << "," << y;
    }
  style.height = -1.0f;
  EXPECT_THROW(extrude_obstacles(polygons, circles, style), Error);
}

}  // namespace
}  // namespace throng::render
