// Forward kinematics for many characters at once, each showing its own frame
// of one clip: the per-agent pose stage in its simplest form.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/span.h"

namespace throng::motion {

struct BatchFkJob {
  std::int32_t joint_count = 0;
  std::int32_t frame_count = 0;
  Span<const std::int32_t> parents;      // joint_count, parents before children
  Span<const glm::vec3> offsets;         // joint_count, rest offsets
  Span<const glm::quat> clip_rotations;  // frame_count * joint_count, frame-major
  Span<const glm::vec3> clip_roots;      // frame_count root positions
  Span<const std::int32_t> frames;       // per character: its frame (clamped into the clip)
  Span<glm::vec3> out_positions;         // characters * joint_count, character-major
  Span<glm::quat> out_rotations;         // characters * joint_count

  Index character_count() const { return frames.size(); }
  // Throws Error naming the first span whose size is wrong.
  void validate() const;
  // validate(), then one parallel_for over characters ("motion.fk_batch").
  void run() const;
};

}  // namespace throng::motion
