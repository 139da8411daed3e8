// One convention joins the simulation's ground plane and the 3D world.
//
// The world (motion, LOD, camera, renderer) is right-handed and Y-up
// (core/camera.h); characters stand on y = 0 and, at yaw 0, face +Z.
// The simulation and scenario files work on a map: ground coordinates
// (x, y) in metres with z up, headings in radians counter-clockwise from +x.
// A map point (x, y, z) is the world point (x, z, -y): a rotation of -90
// degrees about x, so handedness and turning sense are kept (a left turn on
// the map is a left turn seen from above in the world).
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/config.h"
#include "core/math.h"

namespace throng {

// Map (x, y, z-up) -> world (x, y-up, z).
THRONG_HOST_DEVICE inline glm::vec3 world_from_map(glm::vec3 m) { return glm::vec3(m.x, m.z, -m.y); }
THRONG_HOST_DEVICE inline glm::vec3 map_from_world(glm::vec3 w) { return glm::vec3(w.x, -w.z, w.y); }

// A ground point at a height above it.
THRONG_HOST_DEVICE inline glm::vec3 world_from_ground(glm::vec2 g, float height = 0.0f) {
  return glm::vec3(g.x, height, -g.y);
}
THRONG_HOST_DEVICE inline glm::vec2 ground_from_world(glm::vec3 w) { return glm::vec2(w.x, -w.z); }

// A map heading (direction (cos h, sin h)) and the character yaw about +Y
// that turns its +Z facing onto that direction: yaw = heading + pi/2.
THRONG_HOST_DEVICE inline float yaw_from_heading(float heading) { return heading + kHalfPi; }
THRONG_HOST_DEVICE inline float heading_from_yaw(float yaw) { return yaw - kHalfPi; }

}  // namespace throng
