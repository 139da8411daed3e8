// One character per frame (host and device): advance_locomotion moves a
// character's phase, blend and root by dt (Eq. 10); character_frame says
// where its skeleton goes this frame (blend point, each sync group's clip
// phases and rows, root position and frame); joint_rotation samples a
// joint's blended local rotation there.
#pragma once

#include <cstdint>
#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/config.h"
#include "core/math.h"
#include "motion/blend_space.h"
#include "motion/locomotion_sampling.h"
#include "motion/phase.h"

namespace throng::motion {

// wrap_angle (core/math.h, float and double), also named motion::wrap_angle.
using throng::wrap_angle;

// Per-frame settings of the locomotion stage.
struct LocomotionStep {
  float dt = 1.0f / 60.0f;  // s
  // The paper's mode: the blend weight (the speed the character shows)
  // changes only when a cycle ends. Default: continuous, any frame, phase kept.
  bool hold_until_cycle_end = false;
  // Move the character by its blended root motion (Eq. 10). Off when its
  // position and yaw come from elsewhere each frame (the crowd simulation).
  bool integrate_root = true;
};

// Advances one character by dt. Inputs: the speed to show (m/s, world), a
// turn rate (rad/s, + = left) and a curvature (rad per metre travelled: a
// character keeps to a circle of radius 1 / curvature whatever its speed),
// and its scale. State: position (world, on the ground), yaw, phase (of the
// blended cycle, [0, 1)) and blend_speed (the speed at scale 1 the blend
// shows; < 0 or NaN = not set yet, taken from the input).
// Root motion, Eq. 10 per frame: the path advances s * stride_w * dphase
// and turns turn_w * dphase + (turn_rate + curvature * distance); the step is
// the exact chord of that arc (constant turn over the frame), so circles
// close and lines stay lines.
THRONG_HOST_DEVICE inline void advance_locomotion(const BlendSpaceView& v, const LocomotionStep& step, float speed,
                                                  float turn_rate, float curvature, float scale, glm::vec3& position,
                                                  float& yaw, float& phase, float& blend_speed) {
  const float s = scale > 0.0f ? scale : 1.0f;
  const float target = speed > 0.0f ? speed / s : 0.0f;  // also NaN -> 0
  if (!step.hold_until_cycle_end || !(blend_speed >= 0.0f)) blend_speed = target;
  const BlendPoint p = blend_point(v, blend_coordinate(v, blend_speed));
  const float dphase = cycle_rate(v, p, blend_speed) * step.dt;
  float next = phase + dphase;
  if (next >= 1.0f) {
    next -= glm::floor(next);
    if (step.hold_until_cycle_end) blend_speed = target;  // the new weight from the next cycle on
  }
  phase = wrap_phase(next);
  if (!step.integrate_root) return;
  const float distance = s * blended_stride(v, p) * dphase;
  const float turn = blended_turn(v, p) * dphase + turn_rate * step.dt + curvature * distance;
  const float half = 0.5f * turn;
  const float chord = glm::abs(half) > 1e-6f ? distance * glm::sin(half) / half : distance;
  const float heading = yaw + half;
  position.x += chord * glm::sin(heading);
  position.z += chord * glm::cos(heading);
  yaw = wrap_angle(yaw + turn);
}

// Where a character's skeleton goes this frame: the blend, each clip's
// phase, the root's world position and the world rotation of its frame
// (root world rotation = frame * blended local root rotation).
struct CharacterFrame {
  BlendPoint point;
  ClipPhases phases[kSyncGroups];  // per sync group (SegmentSync)
  ClipRows rows[kSyncGroups][2];   // the same as texture rows, clip a and clip b
  float phase = 0.0f;              // canonical, [0, 1)
  RootOffset root;                 // in the path frame, scale 1
  glm::vec3 root_position{0.0f};
  glm::quat frame{1.0f, 0.0f, 0.0f, 0.0f};
  float scale = 1.0f;
};
THRONG_HOST_DEVICE inline CharacterFrame character_frame_at(const BlendSpaceView& v, const BlendPoint& point,
                                                            float phase, glm::vec3 position, float yaw, float scale) {
  CharacterFrame f;
  f.point = point;
  f.phase = wrap_phase(phase);
  const SegmentSync& sync = v.sync[f.point.segment];
  for (int g = 0; g < kSyncGroups; ++g) {
    f.phases[g] = warp_phase(sync.group[g], f.point.w, f.phase);
    f.rows[g][0] = clip_rows(v, f.point.a, f.phases[g].a);
    f.rows[g][1] = clip_rows(v, f.point.b, f.phases[g].b);
  }
  f.scale = scale > 0.0f ? scale : 1.0f;
  f.root = blended_root_offset(v, f.point, f.phase, f.phases[0]);
  const glm::quat heading = yaw_quat(yaw);
  f.root_position = position + heading * (f.scale * f.root.position);
  f.frame = f.root.yaw != 0.0f ? heading * yaw_quat(f.root.yaw) : heading;
  return f;
}
THRONG_HOST_DEVICE inline CharacterFrame character_frame(const BlendSpaceView& v, float blend_speed, float phase,
                                                         glm::vec3 position, float yaw, float scale) {
  return character_frame_at(v, blend_point(v, blend_coordinate(v, blend_speed)), phase, position, yaw, scale);
}

// A joint's blended local rotation at its sync group's phases.
THRONG_HOST_DEVICE inline glm::quat joint_rotation(const BlendSpaceView& v, const CharacterFrame& f,
                                                   std::int32_t joint) {
  const std::uint8_t g = v.joint_group[joint];
  return blended_rotation(v, f.point.w, f.rows[g][0], f.rows[g][1], joint);
}

}  // namespace throng::motion
