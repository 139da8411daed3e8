#include "core/camera.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <string>

#include "core/error.h"

namespace throng {

namespace {
bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void fail(const char* field, const std::string& message) {
  throw Error(message, at_field(std::string("camera.") + field));
}
}  // namespace

void Camera::validate() const {
  // A viewport beyond this is a typo, and pixel counts must fit a float exactly.
  constexpr std::int32_t kMaxViewport = 1 << 15;
  if (!finite(position)) fail("position", "must be finite");
  if (!finite(target)) fail("target", "must be finite");
  if (!finite(up)) fail("up", "must be finite");
  if (!(std::isfinite(fov_y) && fov_y > 0.0f && fov_y < 3.14159f))
    fail("fov_y", "must be in (0, pi) radians, got " + std::to_string(fov_y));
  if (width <= 0 || width > kMaxViewport) fail("width", "must be in [1, 32768] pixels, got " + std::to_string(width));
  if (height <= 0 || height > kMaxViewport)
    fail("height", "must be in [1, 32768] pixels, got " + std::to_string(height));
  if (!(std::isfinite(near_plane) && near_plane > 0.0f)) fail("near_plane", "must be positive");
  if (!(std::isfinite(far_plane) && far_plane > near_plane)) fail("far_plane", "must be greater than near_plane");
  const glm::vec3 forward = target - position;
  const float distance = glm::length(forward);
  if (!(distance > 1e-6f)) fail("target", "must differ from position");
  const float up_length = glm::length(up);
  if (!(up_length > 1e-6f)) fail("up", "must not be zero");
  // lookAt needs an up vector not parallel to the viewing direction.
  const float sine = glm::length(glm::cross(forward / distance, up / up_length));
  if (!(sine > 1e-4f)) fail("up", "must not be parallel to the viewing direction");
}

}  // namespace throng
