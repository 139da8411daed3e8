// Scripted cameras for videos: fixed, an orbit (core/camera.h's
// CameraOrbit) or a fly-over through keyframes. Every frame's Camera comes
// from here, and that Camera is the one the LOD stage is given as well.
#pragma once

#include <string>
#include <vector>

#include "core/camera.h"

namespace throng::render {

struct CameraKey {
  float time = 0.0f;  // seconds, increasing along the path
  glm::vec3 position{0.0f};
  glm::vec3 target{0.0f};
};

struct CameraPath {
  enum class Kind : std::uint8_t { Fixed, Orbit, Flyover };
  Kind kind = Kind::Orbit;
  Camera lens;                  // fov, viewport, clip planes; position/target for Fixed
  CameraOrbit orbit;            // Orbit
  std::vector<CameraKey> keys;  // Flyover: Catmull-Rom through positions and targets, held after the last
  // Throws Error naming the field ("camera.keys[2].time").
  void validate() const;
  Camera at(double seconds) const;
};
const char* to_string(CameraPath::Kind k);
CameraPath::Kind parse_camera_kind(const std::string& text, const std::string& field);  // fixed | orbit | flyover

// An orbit that frames a ground disc of radius `extent` about `centre`,
// from above at about 35 degrees, one turn every `period` seconds.
CameraPath framing_orbit(glm::vec3 centre, float extent, const Camera& lens, float period = 40.0f);

// A scenario's camera (core::Camera, e.g. converted from map coordinates
// with core/ground.h) set in motion: Fixed keeps it; Orbit circles the
// ground point under its target at its distance and height, starting where
// it stands, one turn per `period` seconds (a camera looking straight down
// is tilted a little, as an orbit needs a horizontal offset); Flyover goes
// from where it stands over its target to the mirrored point in `period`
// seconds. At time 0 every kind shows the scenario's camera.
CameraPath animate_camera(const Camera& camera, CameraPath::Kind kind, float period);

// A fly-over: from one side of the disc, low, over its middle and out high
// on the other side, in `duration` seconds.
CameraPath framing_flyover(glm::vec3 centre, float extent, const Camera& lens, float duration = 10.0f);

}  // namespace throng::render
