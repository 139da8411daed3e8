// A pinhole camera: one source of truth for the LOD stage and the renderer.
//
// Conventions (OpenGL, glm): world is Y-up; camera space has x right, y up
// and looks down -z. Pixels: u to the right, v downwards, pixel (i, j) covers
// [i, i+1) x [j, j+1) and its centre is (i + 0.5, j + 0.5); the principal
// point is the viewport centre and pixels are square. The focal length in
// pixels is f = (height / 2) / tan(fov_y / 2), so the projection matrix and
// the pixel mapping below agree exactly (tested).
#pragma once

#include <cstdint>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/config.h"

namespace throng {

struct Camera {
  glm::vec3 position{0.0f, 1.7f, 10.0f};
  glm::vec3 target{0.0f, 1.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float fov_y = 0.9272952f;   // vertical field of view, radians (2 atan(1/2), about 53 degrees)
  std::int32_t width = 1920;  // viewport, pixels
  std::int32_t height = 1080;
  float near_plane = 0.1f;  // metres
  float far_plane = 1000.0f;

  // Throws Error naming the bad field ("camera.fov_y", ...): fov outside
  // (0, pi), empty or huge viewport, near <= 0, far <= near, position ==
  // target, up parallel to the viewing direction, non-finite values.
  void validate() const;
};

THRONG_HOST_DEVICE inline float aspect_ratio(const Camera& c) {
  return static_cast<float>(c.width) / static_cast<float>(c.height);
}
THRONG_HOST_DEVICE inline float focal_length_pixels(const Camera& c) {
  return 0.5f * static_cast<float>(c.height) / glm::tan(0.5f * c.fov_y);
}
// World -> camera space.
THRONG_HOST_DEVICE inline glm::mat4 view_matrix(const Camera& c) { return glm::lookAtRH(c.position, c.target, c.up); }
// Camera space -> clip space, depth to [-1, 1] (OpenGL).
THRONG_HOST_DEVICE inline glm::mat4 projection_matrix(const Camera& c) {
  return glm::perspectiveRH_NO(c.fov_y, aspect_ratio(c), c.near_plane, c.far_plane);
}

// What per-agent kernels need, computed once per frame from a Camera.
struct CameraView {
  glm::mat4 view{1.0f};   // world -> camera space
  float focal_px = 1.0f;  // focal length, pixels
  float width = 1.0f;     // viewport, pixels
  float height = 1.0f;
  float near_plane = 0.1f;
  float far_plane = 1000.0f;
};

THRONG_HOST_DEVICE inline CameraView make_camera_view(const Camera& c) {
  CameraView v;
  v.view = view_matrix(c);
  v.focal_px = focal_length_pixels(c);
  v.width = static_cast<float>(c.width);
  v.height = static_cast<float>(c.height);
  v.near_plane = c.near_plane;
  v.far_plane = c.far_plane;
  return v;
}

THRONG_HOST_DEVICE inline glm::vec3 to_camera_space(const CameraView& v, glm::vec3 world) {
  return glm::vec3(v.view * glm::vec4(world, 1.0f));
}

// Camera-space point -> (u, v, depth): pixel coordinates and the distance in
// front of the camera along its axis. depth <= 0 means on or behind the
// camera plane, where (u, v) mean nothing.
THRONG_HOST_DEVICE inline glm::vec3 camera_to_pixel(const CameraView& v, glm::vec3 cam) {
  const float depth = -cam.z;
  if (depth <= 0.0f) return glm::vec3(0.0f, 0.0f, depth);
  const float s = v.focal_px / depth;
  return glm::vec3(0.5f * v.width + s * cam.x, 0.5f * v.height - s * cam.y, depth);
}

THRONG_HOST_DEVICE inline glm::vec3 world_to_pixel(const CameraView& v, glm::vec3 world) {
  return camera_to_pixel(v, to_camera_space(v, world));
}

// The camera-space direction (not normalised, z = -focal_px) of the ray
// through a point of the image, e.g. a pixel centre (i + 0.5, j + 0.5).
THRONG_HOST_DEVICE inline glm::vec3 pixel_ray(const CameraView& v, glm::vec2 pixel) {
  return glm::vec3(pixel.x - 0.5f * v.width, 0.5f * v.height - pixel.y, -v.focal_px);
}

// A camera circling a centre on the ground (XZ) plane at a constant radius,
// height and angular speed, looking at a point above the centre: benchmarks
// and the renderer's default camera.
struct CameraOrbit {
  glm::vec3 centre{0.0f};
  float radius = 30.0f;        // metres from the centre, in the ground plane
  float height = 8.0f;         // eye height above the centre
  float target_height = 1.0f;  // looks at centre + (0, target_height, 0)
  float angular_speed = 0.2f;  // radians per second, counter-clockwise seen from +Y
  float start_angle = 0.0f;    // radians; 0 puts the camera on +X of the centre
};

// The orbit's camera at `seconds`; fov, viewport and clip planes come from `lens`.
THRONG_HOST_DEVICE inline Camera orbit_camera(const CameraOrbit& o, const Camera& lens, float seconds) {
  const float a = o.start_angle + o.angular_speed * seconds;
  Camera c = lens;
  // Counter-clockwise seen from +Y (x toward -z): angle a at (cos a, -sin a) in XZ.
  c.position = o.centre + glm::vec3(o.radius * glm::cos(a), o.height, -o.radius * glm::sin(a));
  c.target = o.centre + glm::vec3(0.0f, o.target_height, 0.0f);
  c.up = glm::vec3(0.0f, 1.0f, 0.0f);
  return c;
}

}  // namespace throng
