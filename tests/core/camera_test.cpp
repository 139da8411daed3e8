// The pinhole camera against the OpenGL pipeline (projection matrix, NDC,
// viewport transform) and against geometric facts it must satisfy.
#include "core/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>
#include <string>

#include "core/error.h"

namespace throng {
namespace {

Camera test_camera() {
  Camera c;
  c.position = {3.0f, 4.0f, 12.0f};
  c.target = {-1.0f, 0.5f, 0.0f};
  c.fov_y = 0.8f;
  c.width = 1280;
  c.height = 720;
  c.near_plane = 0.05f;
  c.far_plane = 500.0f;
  return c;
}

// The OpenGL route: clip = P V p, NDC = clip / w, viewport transform with v down.
glm::dvec2 pixel_via_matrices(const Camera& c, glm::vec3 p) {
  const glm::dvec4 clip =
      glm::dmat4(projection_matrix(c)) * glm::dmat4(view_matrix(c)) * glm::dvec4(glm::dvec3(p), 1.0);
  const glm::dvec3 ndc = glm::dvec3(clip) / clip.w;
  return {(ndc.x + 1.0) * 0.5 * c.width, (1.0 - ndc.y) * 0.5 * c.height};
}

TEST(Camera, FocalLengthFromFieldOfView) {
  Camera c = test_camera();
  c.fov_y = 2.0f * std::atan(0.5f);  // tan(fov/2) = 1/2 -> f = height
  EXPECT_NEAR(focal_length_pixels(c), 720.0f, 1e-3f);
  c.fov_y = 3.14159265f / 2.0f;  // 90 degrees -> f = height / 2
  EXPECT_NEAR(focal_length_pixels(c), 360.0f, 1e-3f);
}

TEST(Camera, ViewMatrixPutsCameraAtOriginLookingDownMinusZ) {
  const Camera c = test_camera();
  const CameraView v = make_camera_view(c);
  const glm::vec3 eye = to_camera_space(v, c.position);
  EXPECT_LT(glm::length(eye), 1e-5f);
  const glm::vec3 t = to_camera_space(v, c.target);
  const float distance = glm::length(c.target - c.position);
  EXPECT_NEAR(t.x, 0.0f, 1e-5f);
  EXPECT_NEAR(t.y, 0.0f, 1e-5f);
  EXPECT_NEAR(t.z, -distance, 1e-4f);
  // A point above the camera (world up) is above it in camera space too.
  EXPECT_GT(to_camera_space(v, c.position + glm::vec3(0, 1, 0)).y, 0.0f);
  // Rigid: distances are preserved.
  const glm::vec3 a(1, 2, 3), b(-4, 0.5f, 7);
  EXPECT_NEAR(glm::length(to_camera_space(v, a) - to_camera_space(v, b)), glm::length(a - b), 1e-4f);
}

TEST(Camera, PixelMappingAgreesWithProjectionMatrix) {
  const Camera c = test_camera();
  const CameraView v = make_camera_view(c);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-20.0f, 20.0f);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 p(coord(rng), coord(rng) * 0.3f, coord(rng));
    const glm::vec3 uvd = world_to_pixel(v, p);
    if (uvd.z < c.near_plane) continue;
    const glm::dvec2 ref = pixel_via_matrices(c, p);
    ASSERT_NEAR(uvd.x, ref.x, 1e-3 * (1.0 + std::abs(ref.x))) << i;
    ASSERT_NEAR(uvd.y, ref.y, 1e-3 * (1.0 + std::abs(ref.y))) << i;
    ++checked;
  }
  EXPECT_GT(checked, 500);
}

TEST(Camera, TargetAtImageCentreAndFieldOfViewEdgeAtTopRow) {
  const Camera c = test_camera();
  const CameraView v = make_camera_view(c);
  const glm::vec3 centre = world_to_pixel(v, c.target);
  EXPECT_NEAR(centre.x, 640.0f, 1e-3f);
  EXPECT_NEAR(centre.y, 360.0f, 1e-3f);
  // A ray tilted up by fov/2 from the axis meets the top edge (v = 0).
  const glm::mat4 world_from_cam = glm::inverse(v.view);
  const float depth = 10.0f;
  const glm::vec3 top_cam(0.0f, depth * std::tan(0.5f * c.fov_y), -depth);
  const glm::vec3 top = world_to_pixel(v, glm::vec3(world_from_cam * glm::vec4(top_cam, 1.0f)));
  EXPECT_NEAR(top.y, 0.0f, 2e-3f);
  EXPECT_NEAR(top.x, 640.0f, 2e-3f);
  EXPECT_NEAR(top.z, depth, 1e-4f);
}

TEST(Camera, PixelRayReprojectsToItsPixel) {
  const Camera c = test_camera();
  const CameraView v = make_camera_view(c);
  for (float u : {0.5f, 100.25f, 639.5f, 1279.5f})
    for (float w : {0.5f, 359.5f, 719.5f}) {
      const glm::vec3 dir = pixel_ray(v, {u, w});
      const glm::vec3 back = camera_to_pixel(v, dir * 3.7f);
      EXPECT_NEAR(back.x, u, 1e-3f);
      EXPECT_NEAR(back.y, w, 1e-3f);
    }
  EXPECT_LE(camera_to_pixel(v, {0.0f, 0.0f, 1.0f}).z, 0.0f);  // behind the camera
}

TEST(Camera, OrbitKeepsRadiusAndHeightAndTurnsCounterClockwise) {
  CameraOrbit o;
  o.centre = {5.0f, 0.0f, -3.0f};
  o.radius = 40.0f;
  o.height = 12.0f;
  o.angular_speed = 0.5f;
  const Camera lens = test_camera();
  float previous = 0.0f;
  for (int i = 0; i <= 20; ++i) {
    const float t = 0.25f * static_cast<float>(i);
    const Camera c = orbit_camera(o, lens, t);
    const glm::vec3 rel = c.position - o.centre;
    EXPECT_NEAR(std::hypot(rel.x, rel.z), 40.0f, 1e-3f);
    EXPECT_NEAR(rel.y, 12.0f, 1e-5f);
    EXPECT_EQ(c.width, lens.width);
    EXPECT_FLOAT_EQ(c.fov_y, lens.fov_y);
    // Angle measured counter-clockwise seen from +Y: atan2(-z, x).
    const float angle = std::atan2(-rel.z, rel.x);
    if (i > 0) {
      float step = angle - previous;
      if (step < -3.14159f) step += 6.2831853f;
      EXPECT_NEAR(step, 0.125f, 1e-4f);
    }
    previous = angle;
    // The centre stays on the image's vertical centre line.
    const glm::vec3 px = world_to_pixel(make_camera_view(c), o.centre + glm::vec3(0, o.target_height, 0));
    EXPECT_NEAR(px.x, 640.0f, 1e-2f);
    EXPECT_NO_THROW(c.validate());
  }
}

TEST(Camera, ValidateNamesTheBadField) {
  auto expect_field = [](Camera c, const char* field) {
    try {
      c.validate();
      ADD_FAILURE() << "no error for " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.location().field, std::string("camera.") + field) << e.what();
    }
  };
  EXPECT_NO_THROW(test_camera().validate());
  Camera c = test_camera();
  c.fov_y = 0.0f;
  expect_field(c, "fov_y");
  c.fov_y = 3.2f;
  expect_field(c, "fov_y");
  c = test_camera();
  c.width = 0;
  expect_field(c, "width");
  c = test_camera();
  c.height = -5;
  expect_field(c, "height");
  c = test_camera();
  c.near_plane = 0.0f;
  expect_field(c, "near_plane");
  c = test_camera();
  c.far_plane = c.near_plane;
  expect_field(c, "far_plane");
  c = test_camera();
  c.target = c.position;
  expect_field(c, "target");
  c = test_camera();
  c.up = glm::normalize(c.target - c.position);
  expect_field(c, "up");
  c = test_camera();
  c.position.x = std::nanf("");
  expect_field(c, "position");
}

}  // namespace
}  // namespace throng
