// Forward kinematics: local joint rotations -> model-space joint frames.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "core/config.h"
#include "motion/clip.h"
#include "motion/skeleton.h"

namespace throng::motion {

// One pose, host or device: parents before children, so one forward pass.
// local_translations may be null (rest offsets are used, the root placed at
// root_position). Writes model-space positions and rotations of every joint.
THRONG_HOST_DEVICE inline void fk_pose(std::int32_t joints, const std::int32_t* parents, const glm::vec3* offsets,
                                       const glm::quat* local_rotations, const glm::vec3* local_translations,
                                       glm::vec3 root_position, glm::vec3* out_positions, glm::quat* out_rotations) {
  for (std::int32_t j = 0; j < joints; ++j) {
    const glm::vec3 t = local_translations != nullptr ? local_translations[j] : offsets[j];
    const std::int32_t p = parents[j];
    if (p < 0) {
      out_positions[j] = root_position;
      out_rotations[j] = local_rotations[j];
    } else {
      out_positions[j] = out_positions[p] + out_rotations[p] * t;
      out_rotations[j] = out_rotations[p] * local_rotations[j];
    }
  }
}

// Model-space frames of every joint for every frame of a clip, computed in
// parallel over frames: element [frame * joints + joint].
struct ModelSpaceClip {
  std::int32_t joint_count = 0;
  std::int32_t frame_count = 0;
  std::vector<glm::vec3> positions;
  std::vector<glm::quat> rotations;
  const glm::vec3& position(std::int32_t frame, std::int32_t joint) const {
    return positions[static_cast<std::size_t>(frame) * static_cast<std::size_t>(joint_count) +
                     static_cast<std::size_t>(joint)];
  }
};
ModelSpaceClip forward_kinematics(const Skeleton& skeleton, const Clip& clip);

}  // namespace throng::motion
