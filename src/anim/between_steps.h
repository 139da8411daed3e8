// Agents between two simulation steps. The simulation moves in steps of dt
// (0.1 s in most scenarios) while video and the viewer show 30-60 frames a
// second: drawing every frame the last step's positions makes the crowd
// jerk along at 10 Hz. This stage gives the agents' map state at a fraction
// of the way from the previous step to the current one, for the locomotion
// stage (CrowdAnimator::drive_from_map) to animate and the renderer
// to draw.
#pragma once

#include <glm/vec2.hpp>

#include "core/periodic.h"
#include "core/span.h"

namespace throng::anim {

struct InterpolateAgentsJob {
  float alpha = 1.0f;                        // 0: the previous step, 1: the current one
  Span<const glm::vec2> previous_positions;  // map coordinates (core/ground.h)
  Span<const glm::vec2> positions;
  Span<const float> previous_headings;  // radians, CCW from +x
  Span<const float> headings;
  Span<glm::vec2> out_positions;  // lerp
  Span<float> out_headings;       // the shorter way round, in [-pi, pi)
  // Optional: the velocity that moves an agent along the segment, its
  // displacement over the step divided by step_seconds (> 0). Contacts and
  // wall projections move agents by more or less than their steering
  // velocity; animating this one keeps the stride matched to the motion.
  float step_seconds = 0.0f;
  Span<glm::vec2> out_velocities;
  // Over a periodic area: an agent that crossed the seam in the step walks
  // on from the previous position's copy nearest the current one, drawn
  // back in the area once past the seam.
  Periodic periodic;

  Index agent_count() const { return positions.size(); }
  void validate() const;  // Error naming the span or alpha
  void run() const;       // parallel_for "anim.interpolate_agents"
};

}  // namespace throng::anim
