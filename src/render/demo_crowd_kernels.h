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

// Model-space pose of each character of one clip at its phase, under its
// joint mask (anim::masked_pose; masked-out joints hold their parent's frame).
struct DemoPose {
  std::int32_t joint_count = 0;
  std::int32_t frame_count = 0;
  Span<const std::int32_t> parents;
  Span<const glm::vec3> offsets;
  Span<const glm::quat> clip_rotations;  // frame_count * joint_count, cyclic
  Span<const float> phases;
  Span<const glm::vec3> root_positions;
  Span<const std::uint32_t> joint_masks;  // characters * mask words
  Span<glm::vec3> out_positions;
  Span<glm::quat> out_rotations;
  Span<std::int32_t> evaluated;
};
void demo_pose(const DemoPose& p);  // parallel_for "render.demo_pose"

// Moves each character's model-space joints to the world: rotate by its
// yaw about +Y, translate to its ground position.
void demo_place(std::int32_t joint_count, Span<const glm::vec3> ground, Span<const float> yaws, Span<glm::vec3> positions,
                Span<glm::quat> rotations);  // parallel_for "render.demo_place"

}  // namespace throng::render
