// Foot locking at run time (host and device), after the pose stage.
//
// A synthesised foot is planted only in the clip's own motion: its root
// walking straight at the clip's speed. A crowd agent turns, is pushed
// sideways, speeds up and brakes within a step, so the planted foot of the
// pose slides over the ground. Foot locking keeps it where it landed: per
// leg, a horizontal correction (world metres) is added to the synthesised
// ankle, and two-bone IK (motion/leg_ik.h) turns thigh and knee to reach it.
//
// While the clip says the foot is down (its touchdown and lift-off phases,
// motion::ClipInfo::contact), the correction takes back whatever the pinned
// point of the synthesised foot moved since the last frame: the ankle while
// the heel is down, the ball of the foot once it rises (feet roll over the
// ball). So the pinned point of the shown foot stays put. From lift-off the
// correction fades out (exponentially, over release_s), while the foot is
// in the air, and the foot lands about where the pose puts it. The correction is
// at most max_correction_m (times the character's scale): beyond it the leg
// could not reach, and the foot slides instead of the leg tearing.
//
// A planted foot whose correction grows past step_threshold_m (a character
// turning where it stands, or pushed sideways, has its clip's feet down
// throughout) takes a step of its own: over step_s it lifts by up to
// step_height_m, goes over to where the pose puts it in the first half and
// comes down vertically in the second; one foot at a time.
//
// Per-leg state lives in FootLock (two per character); a leg that LOD does
// not synthesise, every leg after CrowdAnimator::place(), and a leg whose
// character was moved farther in a frame than it can walk (across a
// periodic seam) starts again from no correction. A frame with dt = 0 (a paused viewer) moves nothing on.
#pragma once

#include <cstdint>
#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/config.h"
#include "core/span.h"
#include "motion/blend_space.h"
#include "motion/locomotion_sampling.h"

namespace throng::anim {

struct FootLockConfig {
  float max_correction_m = 0.3f;   // at scale 1
  float release_s = 0.08f;         // time constant of the fade after lift-off
  float step_threshold_m = 0.08f;  // a planted foot this far from its pose steps (scale 1)
  float step_s = 0.25f;            // how long such a step takes
  float step_height_m = 0.09f;     // how high its foot lifts (scale 1)
  void validate() const;           // Error naming the field
};

// One leg of one character.
struct FootLock {
  glm::vec2 correction{0.0f};  // world x, z (m) added to the synthesised ankle
  glm::vec2 ankle{0.0f};       // last frame's synthesised ankle, world x, z
  glm::vec2 ball{0.0f};        // ... and ball of the foot
  float step_left = 0.0f;      // s left of a step of the foot's own; 0 = none
  std::uint8_t seen = 0;       // 1: last frame synthesised this leg
  std::uint8_t down = 0;       // 1: the foot was down (and not stepping) last frame
};

// Whether a clip has leg's foot on the ground at the clip's phase: between
// its touchdown and lift-off. A clip with no foot events stands: feet down.
THRONG_HOST_DEVICE inline bool clip_foot_down(const motion::ClipInfo& clip, int leg, float phase) {
  const float down = clip.contact[leg][0], up = clip.contact[leg][1];
  if (down < 0.0f || up < 0.0f) return true;
  return down <= up ? (phase >= down && phase < up) : (phase >= down || phase < up);
}

// Whether the blend has leg's foot down, given each clip's synchronised leg
// phase: the clip with the larger weight decides, except that a blend of a
// standing clip with a striding one steps as the striding clip does (the
// blend lifts the feet as soon as it moves at all, motion/leg_ik.h) unless
// the striding clip weighs at most kStandingWeight or the blend's quantum:
// a character at rest shows the motion cache's first bucket (w half its
// width), not a step.
inline constexpr float kStandingWeight = 0.05f;
THRONG_HOST_DEVICE inline bool foot_down_in_blend(const motion::BlendSpaceView& v, const motion::BlendPoint& point,
                                                  const motion::ClipPhases& leg_phases, int leg) {
  const motion::ClipInfo& a = v.clips[point.a];
  const motion::ClipInfo& b = v.clips[point.b];
  const bool a_strides = a.stride > motion::kMinStride, b_strides = b.stride > motion::kMinStride;
  if (a_strides != b_strides) {
    const float striding_weight = a_strides ? 1.0f - point.w : point.w;
    if (striding_weight <= glm::max(kStandingWeight, v.quantum)) return true;
    return a_strides ? clip_foot_down(a, leg, leg_phases.a) : clip_foot_down(b, leg, leg_phases.b);
  }
  return point.w < 0.5f ? clip_foot_down(a, leg, leg_phases.a) : clip_foot_down(b, leg, leg_phases.b);
}

// After PoseJob: every character's legs locked, in place in the pose.
// Characters are the gait the pose was made from (the same blend view,
// quantum included).
struct FootLockJob {
  motion::BlendSpaceView blend;
  FootLockConfig config;
  float dt = 0.0f;                        // s since the last frame
  Span<const glm::vec3> positions;        // root on the ground, world
  Span<const float> scales;               // empty = 1
  Span<const float> phases;               // canonical gait phase
  Span<const float> blend_speeds;         // the speed the blend shows (scale 1)
  Span<const std::uint32_t> joint_masks;  // as PoseJob's; empty = every joint
  Span<FootLock> locks;                   // in/out: characters * 2 (left, right)
  Span<glm::vec3> joint_positions;        // in/out: [c * J + j], world
  Span<glm::quat> joint_rotations;        // in/out

  Index character_count() const { return positions.size(); }
  void validate() const;  // Error naming the span whose size is wrong
  void run() const;       // parallel_for "anim.foot_lock"
};

}  // namespace throng::anim
