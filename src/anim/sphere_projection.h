// The image of a sphere under a pinhole camera, in closed form.
//
// A sphere of radius r whose centre is at depth d in front of the camera and
// at lateral offset (x, y) from its axis (camera space, GL conventions: the
// camera looks down -z, so d = -z) projects, when it lies wholly in front of
// the camera plane (d > r), to an ellipse of area
//
//     A = pi f^2 r^2 sqrt(k) / (d^2 - r^2)^(3/2),   k = x^2 + y^2 + d^2 - r^2
//
// pixels, with f the focal length in pixels. Its semi-axes are
// f r sqrt(k) / (d^2 - r^2) along the direction of (x, y) and f r / sqrt(d^2 - r^2)
// across it, and its centre is f d (x, y) / (d^2 - r^2) from the principal
// point. docs/lod.md derives this; tests/anim check it against rays cast
// through pixel centres.
#pragma once

#include <cstdint>
#include <glm/exponential.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/camera.h"
#include "core/config.h"
#include "core/math.h"

namespace throng::anim {

enum class SphereImage : std::uint8_t {
  Behind,     // wholly behind the camera plane: nothing is seen
  Ellipse,    // wholly in front of the camera plane: a bounded ellipse
  Unbounded,  // crosses the camera plane (camera outside): an unbounded conic region
  Inside,     // the camera is inside the sphere: it fills every pixel
};

const char* to_string(SphereImage kind);

template <class T>
struct ProjectedEllipse {
  SphereImage kind = SphereImage::Behind;
  glm::vec<2, T> centre{0};  // pixels (u right, v down); Ellipse only
  T major = 0;               // semi-axis along the direction away from the image centre, pixels
  T minor = 0;               // semi-axis across it, pixels
  T angle = 0;               // of the major axis, radians from +u toward +v
  T area = 0;                // pi * major * minor; 0 unless Ellipse
};

// Classifies the sphere and returns the exact unclipped area of its image
// in square pixels (0 when not an Ellipse; see sphere_pixel_coverage for a
// value usable as a screen-space measure in every case).
template <class T>
THRONG_HOST_DEVICE inline T sphere_ellipse_area(glm::vec<3, T> centre_cam, T radius, T focal_px,
                                                SphereImage* kind = nullptr) {
  const T d = -centre_cam.z;
  const T r2 = radius * radius;
  const T k = centre_cam.x * centre_cam.x + centre_cam.y * centre_cam.y + d * d - r2;
  SphereImage c = SphereImage::Ellipse;
  if (k <= T(0))
    c = SphereImage::Inside;
  else if (d <= -radius)
    c = SphereImage::Behind;
  else if (d <= radius)
    c = SphereImage::Unbounded;
  if (kind != nullptr) *kind = c;
  if (c != SphereImage::Ellipse) return T(0);
  const T e = d * d - r2;
  return T(kPi) * focal_px * focal_px * r2 * glm::sqrt(k / e) / e;  // = ... sqrt(k) / e^(3/2)
}

// The full ellipse (centre, axes, angle) in pixel coordinates of a viewport
// of width x height pixels whose principal point is its centre.
template <class T>
THRONG_HOST_DEVICE inline ProjectedEllipse<T> project_sphere(glm::vec<3, T> centre_cam, T radius, T focal_px, T width,
                                                             T height) {
  ProjectedEllipse<T> out;
  out.area = sphere_ellipse_area(centre_cam, radius, focal_px, &out.kind);
  if (out.kind != SphereImage::Ellipse) return out;
  const T d = -centre_cam.z;
  const T r2 = radius * radius;
  const T lateral2 = centre_cam.x * centre_cam.x + centre_cam.y * centre_cam.y;
  const T e = d * d - r2;
  const T k = lateral2 + e;
  const T s = focal_px * d / e;  // image centre offset per unit of lateral offset
  out.centre = glm::vec<2, T>(T(0.5) * width + s * centre_cam.x, T(0.5) * height - s * centre_cam.y);
  out.major = focal_px * radius * glm::sqrt(k) / e;
  out.minor = focal_px * radius / glm::sqrt(e);
  // Image v runs downwards, so the radial direction (x, y) becomes (x, -y).
  out.angle = lateral2 > T(0) ? glm::atan(-centre_cam.y, centre_cam.x) : T(0);
  return out;
}

// True when the sphere lies wholly outside the view frustum (beyond one of
// the four side planes, nearer than the near plane or beyond the far plane),
// so that no pixel of the viewport sees it. Conservative: a sphere near a
// frustum corner may be reported visible although it is not.
THRONG_HOST_DEVICE inline bool sphere_outside_view(glm::vec3 centre_cam, float radius, const CameraView& view) {
  const float d = -centre_cam.z;
  if (d + radius < view.near_plane || d - radius > view.far_plane) return true;
  // The right side plane (u = width, x = d w / (2 f)) has normal (f, 0, w/2)
  // up to length; the sphere is beyond it when the signed distance
  // s / |n| exceeds r, i.e. s > 0 and s^2 > r^2 |n|^2 (no square root).
  const float hx = 0.5f * view.width;
  const float hy = 0.5f * view.height;
  const float f = view.focal_px;
  const float r2 = radius * radius;
  const float limit_x = r2 * (f * f + hx * hx);
  const float limit_y = r2 * (f * f + hy * hy);
  const float right = f * centre_cam.x + hx * centre_cam.z;
  const float left = -f * centre_cam.x + hx * centre_cam.z;
  const float top = f * centre_cam.y + hy * centre_cam.z;
  const float bottom = -f * centre_cam.y + hy * centre_cam.z;
  return (right > 0.0f && right * right > limit_x) || (left > 0.0f && left * left > limit_x) ||
         (top > 0.0f && top * top > limit_y) || (bottom > 0.0f && bottom * bottom > limit_y);
}

// The screen-space measure that LOD thresholds compare against, in square
// pixels within [0, width * height]: the exact ellipse area, clamped to the
// viewport's area; the whole viewport when the camera is inside the sphere
// or the sphere crosses the camera plane (it is then at arm's length); 0
// when it is behind the camera or, with cull_outside, outside the frustum.
THRONG_HOST_DEVICE inline float sphere_pixel_coverage(glm::vec3 centre_cam, float radius, const CameraView& view,
                                                      bool cull_outside) {
  const float screen = view.width * view.height;
  SphereImage kind = SphereImage::Behind;
  const float area = sphere_ellipse_area(centre_cam, radius, view.focal_px, &kind);
  if (kind == SphereImage::Behind) return 0.0f;
  if (kind == SphereImage::Inside) return screen;
  if (cull_outside && sphere_outside_view(centre_cam, radius, view)) return 0.0f;
  if (kind != SphereImage::Ellipse) return screen;
  return area < screen ? area : screen;
}

}  // namespace throng::anim
