// A sampled motion: per frame, per joint local rotations plus root translation.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <vector>

namespace throng::motion {

struct Clip {
  std::int32_t joint_count = 0;
  std::int32_t frame_count = 0;
  float frame_time = 1.0f / 30.0f;  // seconds per frame
  // Frame-major: rotations[frame * joint_count + joint], unit quaternions,
  // each the joint's rotation relative to its parent.
  std::vector<glm::quat> rotations;
  // Root position per frame in metres (the root's offset is not added again).
  std::vector<glm::vec3> root_positions;
  // Local translations of every joint per frame (frame-major) when a file
  // animates non-root joint positions; empty means "use the rest offsets".
  std::vector<glm::vec3> translations;

  float duration() const { return static_cast<float>(frame_count) * frame_time; }
  const glm::quat& rotation(std::int32_t frame, std::int32_t joint) const {
    return rotations[static_cast<std::size_t>(frame) * static_cast<std::size_t>(joint_count) +
                     static_cast<std::size_t>(joint)];
  }
  glm::quat& rotation(std::int32_t frame, std::int32_t joint) {
    return rotations[static_cast<std::size_t>(frame) * static_cast<std::size_t>(joint_count) +
                     static_cast<std::size_t>(joint)];
  }
  // Allocates every array for frames x joints (identity rotations, zero root).
  void resize(std::int32_t frames, std::int32_t joints);
};

}  // namespace throng::motion
