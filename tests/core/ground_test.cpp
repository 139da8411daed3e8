// The map <-> world convention against rotations built independently.
#include "core/ground.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

namespace throng {
namespace {

glm::vec3 rotate_y(float angle, glm::vec3 v) {
  return glm::vec3(glm::rotate(glm::mat4(1.0f), angle, glm::vec3(0, 1, 0)) * glm::vec4(v, 0.0f));
}

TEST(Ground, MapToWorldIsAProperRotation) {
  // The images of the map axes: x -> x, y (north) -> -z, z (up) -> +y.
  EXPECT_EQ(world_from_map({1, 0, 0}), glm::vec3(1, 0, 0));
  EXPECT_EQ(world_from_map({0, 1, 0}), glm::vec3(0, 0, -1));
  EXPECT_EQ(world_from_map({0, 0, 1}), glm::vec3(0, 1, 0));
  // Right-handed stays right-handed: x' cross y' = z'.
  const glm::vec3 c = glm::cross(world_from_map({1, 0, 0}), world_from_map({0, 1, 0}));
  EXPECT_EQ(c, world_from_map({0, 0, 1}));
  const glm::vec3 m(3.5f, -2.0f, 1.25f);
  EXPECT_EQ(map_from_world(world_from_map(m)), m);
  EXPECT_EQ(ground_from_world(world_from_ground({4.0f, -7.0f}, 2.0f)), glm::vec2(4.0f, -7.0f));
  EXPECT_EQ(world_from_ground({4.0f, -7.0f}, 2.0f), world_from_map({4.0f, -7.0f, 2.0f}));
}

TEST(Ground, HeadingAndYawFaceTheSameWay) {
  for (float h = -6.0f; h <= 6.0f; h += 0.37f) {
    const glm::vec3 map_dir = world_from_ground({std::cos(h), std::sin(h)});
    // A character at rest faces +Z; its yaw about +Y turns it onto the heading.
    const glm::vec3 facing = rotate_y(yaw_from_heading(h), glm::vec3(0, 0, 1));
    EXPECT_NEAR(glm::length(facing - map_dir), 0.0f, 1e-5f) << "heading " << h;
    EXPECT_NEAR(heading_from_yaw(yaw_from_heading(h)), h, 1e-6f);
  }
  // Turning left on the map (heading grows) turns left in the world:
  // counter-clockwise seen from +Y, i.e. a positive rotation about +Y.
  const glm::vec3 a = world_from_ground({1, 0}), b = world_from_ground({std::cos(0.1f), std::sin(0.1f)});
  EXPECT_GT(glm::cross(a, b).y, 0.0f);
}

}  // namespace
}  // namespace throng
