#include "render/camera_path.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace throng::render {

const char* to_string(CameraPath::Kind k) {
  switch (k) {
    case CameraPath::Kind::Fixed: return "fixed";
    case CameraPath::Kind::Orbit: return "orbit";
    case CameraPath::Kind::Flyover: return "flyover";
  }
  return "?";
}

CameraPath::Kind parse_camera_kind(const std::string& text, const std::string& field) {
  if (text == "fixed") return CameraPath::Kind::Fixed;
  if (text == "orbit") return CameraPath::Kind::Orbit;
  if (text == "flyover") return CameraPath::Kind::Flyover;
  throw Error(fmt::format("unknown camera path '{}' (fixed, orbit or flyover)", text), at_field(field));
}

namespace {
bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Uniform Catmull-Rom between b and c (a before, d after), u in [0, 1].
glm::vec3 catmull_rom(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, float u) {
  const float u2 = u * u, u3 = u2 * u;
  return 0.5f *
         ((2.0f * b) + (c - a) * u + (2.0f * a - 5.0f * b + 4.0f * c - d) * u2 + (3.0f * b - a - 3.0f * c + d) * u3);
}
}  // namespace

void CameraPath::validate() const {
  if (kind == Kind::Fixed) {
    lens.validate();
    return;
  }
  Camera probe = lens;
  // Away from the target across `up`, so that only the lens is checked.
  const glm::vec3 across =
      std::abs(glm::normalize(probe.up).z) < 0.9f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  probe.position = probe.target + across;
  probe.validate();  // everything but the placement
  if (kind == Kind::Orbit) {
    const CameraOrbit& o = orbit;
    if (!finite(o.centre)) throw Error("must be finite", at_field("camera.orbit.centre"));
    if (!(o.radius > 0.0f) || !std::isfinite(o.radius))
      throw Error("must be positive", at_field("camera.orbit.radius"));
    if (!std::isfinite(o.height) || !std::isfinite(o.target_height))
      throw Error("must be finite", at_field("camera.orbit.height"));
    if (!std::isfinite(o.angular_speed) || !std::isfinite(o.start_angle))
      throw Error("must be finite", at_field("camera.orbit.angular_speed"));
    return;
  }
  if (keys.size() < 2)
    throw Error(fmt::format("a fly-over needs at least 2 keys, not {}", keys.size()), at_field("camera.keys"));
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const CameraKey& k = keys[i];
    if (!std::isfinite(k.time) || (i > 0 && !(k.time > keys[i - 1].time)))
      throw Error("times must be finite and increasing", at_field(fmt::format("camera.keys[{}].time", i)));
    if (!finite(k.position) || !finite(k.target))
      throw Error("must be finite", at_field(fmt::format("camera.keys[{}]", i)));
    if (glm::length(k.position - k.target) <= 1e-4f)
      throw Error("position and target coincide", at_field(fmt::format("camera.keys[{}]", i)));
  }
}

Camera CameraPath::at(double seconds) const {
  if (kind == Kind::Fixed) return lens;
  if (kind == Kind::Orbit) return orbit_camera(orbit, lens, static_cast<float>(seconds));
  Camera c = lens;
  const float t = static_cast<float>(seconds);
  if (keys.empty()) return c;
  if (t <= keys.front().time || keys.size() == 1) {
    c.position = keys.front().position;
    c.target = keys.front().target;
    return c;
  }
  if (t >= keys.back().time) {
    c.position = keys.back().position;
    c.target = keys.back().target;
    return c;
  }
  std::size_t i = 0;
  while (i + 2 < keys.size() && t >= keys[i + 1].time) ++i;
  const std::size_t a = i > 0 ? i - 1 : i, b = i, cc = i + 1, d = std::min(i + 2, keys.size() - 1);
  const float u = (t - keys[b].time) / (keys[cc].time - keys[b].time);
  c.position = catmull_rom(keys[a].position, keys[b].position, keys[cc].position, keys[d].position, u);
  c.target = catmull_rom(keys[a].target, keys[b].target, keys[cc].target, keys[d].target, u);
  return c;
}

CameraPath framing_orbit(glm::vec3 centre, float extent, const Camera& lens, float period) {
  CameraPath p;
  p.kind = CameraPath::Kind::Orbit;
  p.lens = lens;
  const float r = std::max(extent, 2.0f);
  // Far enough that the disc fits the vertical field of view from 35 degrees up.
  const float distance = 1.15f * r / std::tan(0.5f * lens.fov_y) + r * 0.3f;
  p.orbit.centre = centre;
  p.orbit.radius = distance * std::cos(0.61f);
  p.orbit.height = distance * std::sin(0.61f);
  p.orbit.target_height = 0.5f;
  p.orbit.angular_speed = period > 0.0f ? 6.2831853f / period : 0.0f;
  p.orbit.start_angle = 0.6f;
  return p;
}

CameraPath animate_camera(const Camera& camera, CameraPath::Kind kind, float period) {
  camera.validate();
  if (kind != CameraPath::Kind::Fixed && !(period > 0.0f && std::isfinite(period)))
    throw Error("must be positive seconds", at_field("camera.period"));
  CameraPath p;
  p.kind = kind;
  p.lens = camera;
  if (kind == CameraPath::Kind::Fixed) return p;
  const glm::vec3 centre(camera.target.x, 0.0f, camera.target.z);
  glm::vec2 offset(camera.position.x - centre.x, camera.position.z - centre.z);
  const float drop = std::abs(camera.position.y - camera.target.y);
  if (glm::length(offset) < 0.02f * drop) {
    // Straight down: tilt towards the image's bottom edge (-up), 2% of the height.
    const glm::vec2 down(-camera.up.x, -camera.up.z);
    offset = 0.02f * drop * (glm::length(down) > 0.0f ? glm::normalize(down) : glm::vec2(0.0f, 1.0f));
  }
  if (kind == CameraPath::Kind::Orbit) {
    p.lens.up = glm::vec3(0.0f, 1.0f, 0.0f);  // what orbit_camera uses
    p.orbit.centre = centre;
    p.orbit.radius = glm::length(offset);
    p.orbit.height = camera.position.y;
    p.orbit.target_height = camera.target.y;
    p.orbit.angular_speed = 6.2831853f / period;
    p.orbit.start_angle = std::atan2(-offset.y, offset.x);  // core/camera.h: angle a at (cos a, -sin a)
    return p;
  }
  const glm::vec3 start = centre + glm::vec3(offset.x, camera.position.y, offset.y);
  const glm::vec3 across = centre + glm::vec3(-offset.x, camera.position.y, -offset.y);
  const glm::vec3 over = centre + glm::vec3(0.0f, camera.position.y * 1.2f + 2.0f, 0.0f);
  p.keys = {{0.0f, start, camera.target},
            {0.5f * period, over + 0.25f * (start - centre) * glm::vec3(1, 0, 1),
             camera.target - 0.5f * (start - centre) * glm::vec3(1, 0, 1)},
            {period, across, camera.target}};
  return p;
}

CameraPath framing_flyover(glm::vec3 centre, float extent, const Camera& lens, float duration) {
  CameraPath p;
  p.kind = CameraPath::Kind::Flyover;
  p.lens = lens;
  const float r = std::max(extent, 2.0f);
  const glm::vec3 x(1.0f, 0.0f, 0.0f), z(0.0f, 0.0f, 1.0f), y(0.0f, 1.0f, 0.0f);
  p.keys = {
      {0.0f, centre + z * (1.6f * r) + y * (0.25f * r + 2.0f), centre + y * 1.0f},
      {0.35f * duration, centre + z * (0.5f * r) + x * (0.3f * r) + y * (0.35f * r + 2.0f), centre - z * (0.3f * r)},
      {0.7f * duration, centre - z * (0.6f * r) + y * (0.7f * r + 3.0f), centre - z * (0.2f * r) + x * (0.2f * r)},
      {duration, centre - z * (1.5f * r) + x * (0.4f * r) + y * (1.1f * r + 4.0f), centre},
  };
  return p;
}

}  // namespace throng::render
