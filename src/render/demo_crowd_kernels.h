// The demo crowd's per-character stages (kernels in demo_crowd_kernels.cpp).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/span.h"

namespace throng::render {

// Where each character of one clip is at `seconds`, and its clip phase.
struct DemoPlacement {
  double seconds = 0.0;
  float clip_duration = 1.0f;
  std::int32_t clip_frames = 1;
  Span<const glm::vec3> clip_roots;  // clip_frames: root without forward travel
  bool ring = false;                 // ring walkers circle the origin; else grid walkers
  float grid_side = 0.0f;            // grid walkers wrap round a square of this side
  Span<const float> phase_offset, speed, yaw0, radius, angle0;
  Span<const glm::vec3> base;
  Span<float> phases;          // out: normalised clip phase
  Span<glm::vec3> model_roots; // out: the root in the character's frame
  Span<glm::vec3> ground;      // out: world ground position
  Span<float> yaws;            // out: radians about +Y
};
void demo_roots(const DemoPlacement& p);  // parallel_for "render.demo_roots"

// Moves each character's model-space joints to the world: rotate by its
// yaw about +Y, translate to its ground position.
void demo_place(std::int32_t joint_count, Span<const glm::vec3> ground, Span<const float> yaws, Span<glm::vec3> positions,
                Span<glm::quat> rotations);  // parallel_for "render.demo_place"

}  // namespace throng::render
