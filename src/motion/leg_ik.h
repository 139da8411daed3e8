// Leg IK (host and device). two_bone_ik turns a thigh and its knee so that
// the ankle reaches a target; it cleans the foot contacts of prepared clips
// (clean_foot_contacts, motion/locomotion_clip.h) and, in plant_legs,
// plants the feet of a blend every frame.
#pragma once

#include <cstdint>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/config.h"
#include "motion/blend_space.h"
#include "motion/locomotion_sampling.h"
#include "motion/locomotion_step.h"

namespace throng::motion {

// Rotation taking unit vector a onto unit vector b along the shorter arc.
THRONG_HOST_DEVICE inline glm::quat rotation_between(const glm::vec3& a, const glm::vec3& b) {
  const float d = glm::dot(a, b);
  if (d < -0.999999f) {  // opposite: any perpendicular axis
    glm::vec3 axis = glm::cross(glm::vec3(1.0f, 0.0f, 0.0f), a);
    if (glm::dot(axis, axis) < 1e-8f) axis = glm::cross(glm::vec3(0.0f, 1.0f, 0.0f), a);
    return glm::angleAxis(3.14159265358979f, glm::normalize(axis));
  }
  const glm::vec3 c = glm::cross(a, b);
  return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));
}

// Rotation by the angle whose cosine and sine are c and s about a unit
// axis: (1 + c, s axis) normalised is (cos(a/2), sin(a/2) axis). Turns
// within 2.6 degrees of half a circle (1 + c below 1e-3, where that loses
// digits) take the angle itself.
THRONG_HOST_DEVICE inline glm::quat turn_about(const glm::vec3& axis, float c, float s) {
  if (1.0f + c < 1e-3f) return glm::angleAxis(glm::atan(s, c), axis);
  return glm::normalize(glm::quat(1.0f + c, s * axis.x, s * axis.y, s * axis.z));
}

// Two-bone IK of one leg. Positions and rotations are all in one frame (the
// world, or the path frame in plant_legs); lengths in metres.
// Inputs: hip, the thigh joint's position; knee_offset and ankle_offset,
// the rest offsets of knee (from the thigh) and ankle (from the knee);
// hinge, the knee's bending axis in the thigh's frame (LegChain::hinge);
// target, where the ankle should go.
// In and out: r_thigh and r_knee, the world rotations of thigh and knee.
// The knee bends about its hinge to the angle the law of cosines gives for
// the hip-to-target distance (clamped to what the leg reaches), never
// backwards; then the leg swings about the hip by the shortest arc onto the
// target. Returns false, changing nothing, for a degenerate leg: a bone
// shorter than 1e-6 m, or a straight (or backward-bent) leg whose hinge lies
// along the thigh.
THRONG_HOST_DEVICE inline bool two_bone_ik(const glm::vec3& hip, const glm::vec3& knee_offset,
                                           const glm::vec3& ankle_offset, const glm::vec3& hinge,
                                           const glm::vec3& target, glm::quat& r_thigh, glm::quat& r_knee) {
  const glm::vec3 upper = r_thigh * knee_offset;
  const glm::vec3 lower = r_knee * ankle_offset;
  const float l1 = glm::length(upper), l2 = glm::length(lower);
  if (!(l1 > 1e-6f && l2 > 1e-6f)) return false;
  const glm::vec3 to_target = target - hip;
  float d = glm::length(to_target);
  const float d_min = glm::abs(l1 - l2) + 1e-4f, d_max = 0.9999f * (l1 + l2);
  d = d < d_min ? d_min : (d > d_max ? d_max : d);
  // Bend about the plane of thigh and shin while the knee bends the way its
  // hinge says; when the leg is straight (no plane) or bent backwards,
  // about the hinge (perpendicular to the thigh) instead.
  const glm::vec3 u = upper / l1;
  glm::vec3 hinge_world = r_thigh * hinge;
  hinge_world -= glm::dot(hinge_world, u) * u;
  const glm::vec3 normal = glm::cross(upper, lower);
  const float area = glm::length(normal);
  // The bends as cosine and sine, never as angles: the turn from the bend
  // now to the one wanted follows from the difference formulas, and its
  // quaternion from the half-angle ones (no acos, atan or sine).
  glm::vec3 axis;
  float cos_now, sin_now;
  if (area > 1e-3f * l1 * l2 && glm::dot(normal, hinge_world) >= 0.0f) {
    axis = normal / area;
    cos_now = glm::dot(upper, lower) / (l1 * l2);
    sin_now = area / (l1 * l2);
  } else {
    if (glm::dot(hinge_world, hinge_world) < 1e-10f) return false;
    axis = glm::normalize(hinge_world);
    const float x = glm::dot(upper, lower), y = glm::dot(normal, axis), r = glm::sqrt(x * x + y * y);
    cos_now = r > 0.0f ? x / r : 1.0f;
    sin_now = r > 0.0f ? y / r : 0.0f;
  }
  const float cos_want = glm::clamp((d * d - l1 * l1 - l2 * l2) / (2.0f * l1 * l2), -1.0f, 1.0f);
  const float sin_want = glm::sqrt(1.0f - cos_want * cos_want);  // the knee bends 0 to 180 degrees
  r_knee = turn_about(axis, cos_want * cos_now + sin_want * sin_now, sin_want * cos_now - cos_want * sin_now) * r_knee;
  const glm::vec3 ankle_now = upper + r_knee * ankle_offset;
  if (glm::dot(ankle_now, ankle_now) > 1e-12f && glm::dot(to_target, to_target) > 1e-12f) {
    const glm::quat swing = rotation_between(glm::normalize(ankle_now), glm::normalize(to_target));
    r_thigh = swing * r_thigh;
    r_knee = swing * r_knee;
  }
  return true;
}

// Planted feet in a blend (past the paper). SLERP of joint rotations does
// not lerp joint positions, so a foot planted in both clips drifts a little
// in the blend. Eq. 10's root is exactly the lerp of the clips' roots, so a
// foot is exactly planted when its ankle, relative to the root, is the lerp
// of the clips' ankles. Per leg: forward kinematics of the root-to-ankle
// chain in each clip (at that leg's synchronised phase) gives that target;
// analytic two-bone IK (two_bone_ik) puts the blended ankle on it; the foot
// keeps its blended world rotation. Nothing changes at w = 0 or 1, nor for a
// leg whose thigh, knee or foot the mask turns off (planted feet are a detail
// of the finest level). corrected[leg][0..2]: local rotations of thigh,
// knee, ankle.
// * The point matched is the ankle while the heel is down and the ball of
//   the foot once the heel is up (kHeelLift above the ankle's lowest
//   height), as feet roll over the ball.
// * A leg synchronised apart from the body can find its target beyond reach
//   (the pelvis is at the body's phase): the pelvis drops just enough for
//   both targets to be within kReach of the legs' length (at most
//   kMaxPelvisDrop; pelvis_drop, metres at scale 1, lowers the root).
// * Blending a stationary clip (idle) with a walk would also scale the
//   step's foot lift down with w, so the foot drags: there the lift comes
//   from the walk (ramped in over w in [0, kLiftRamp]).
// Stages, per leg: clip_leg_targets, blended_leg, planted_leg_goal, then
// pelvis_drop_to_reach over both legs, then solve_planted_leg.
inline constexpr float kLiftRamp = 0.25f;
inline constexpr float kHeelLift = 0.03f;
inline constexpr float kReach = 0.998f;
inline constexpr float kMaxPelvisDrop = 0.15f;
struct PlantedLegs {
  bool active[2] = {false, false};
  glm::quat corrected[2][3];
  float pelvis_drop = 0.0f;
};
THRONG_HOST_DEVICE inline bool mask_bit(const std::uint32_t* mask, std::int32_t joint) {
  return mask == nullptr || ((mask[joint >> 5] >> (joint & 31)) & 1u) != 0u;
}

// Which of a leg's thigh, knee and ankle (0, 1, 2) a joint is; -1 for
// none, or when the chain is too short to plant.
THRONG_HOST_DEVICE inline int leg_slot(const LegChain& chain, std::int32_t joint) {
  if (chain.count < 4) return -1;
  for (int k = 0; k < 3; ++k)
    if (chain.joints[chain.count - 3 + k] == joint) return k;
  return -1;
}

// Whether plant_legs moves a leg (0 left, 1 right): its chain reaches the
// ankle through thigh and knee, and the mask keeps all three.
THRONG_HOST_DEVICE inline bool plants_leg(const BlendSpaceView& v, int leg, const std::uint32_t* mask) {
  const LegChain& chain = v.legs[leg];
  const std::int32_t n = chain.count;
  if (n < 4) return false;
  const std::int32_t thigh = chain.joints[n - 3], knee = chain.joints[n - 2], ankle = chain.joints[n - 1];
  return mask_bit(mask, thigh) && mask_bit(mask, knee) && mask_bit(mask, ankle);
}

// Where the stages read joint rotations: a sampler has blended(j), joint
// j's blended local rotation (joint_rotation), and clip(leg, c, j), joint
// j's local rotation in clip c (0 = a, 1 = b) at that leg's rows. This one
// samples the texture on every call (the reference); SampledJoints
// (motion/locomotion_pose.h) reads what one pass over the joints sampled.
struct SampleOnDemand {
  const BlendSpaceView* v;
  const CharacterFrame* f;
  THRONG_HOST_DEVICE glm::quat blended(std::int32_t joint) const { return joint_rotation(*v, *f, joint); }
  THRONG_HOST_DEVICE glm::quat clip(int leg, int c, std::int32_t joint) const {
    return clip_rotation(*v, f->rows[1 + leg][c], joint);
  }
};

// Stage 1. Where the two clips put one leg's foot. Input: the frame (blend
// point, the leg's synchronised phases and rows). Output: in the path frame
// at the canonical phase, scale 1, metres: the lerp by w of the clips'
// ankles and balls of the foot (forward kinematics of the root-to-ankle
// chain, each clip's path run ahead by its phase lead), the lerp of their
// lowest ankle heights, and each clip's ankle height above its lowest.
struct ClipLegTargets {
  glm::vec3 ankle{0.0f};
  glm::vec3 ball{0.0f};
  float ground = 0.0f;
  float lift[2] = {0.0f, 0.0f};  // clip a, clip b
};
template <class Sampler>
THRONG_HOST_DEVICE inline ClipLegTargets clip_leg_targets(const BlendSpaceView& v, const CharacterFrame& f, int leg,
                                                          const Sampler& sample) {
  const LegChain& chain = v.legs[leg];
  const std::int32_t n = chain.count;
  const BlendPoint& p = f.point;
  const glm::vec3 ball_offset(chain.ball[0], chain.ball[1], chain.ball[2]);
  ClipLegTargets out;
  for (int c = 0; c < 2; ++c) {
    const std::int32_t clip = c == 0 ? p.a : p.b;
    const float clip_phase = c == 0 ? f.phases[1 + leg].a : f.phases[1 + leg].b;
    const ClipRows& rows = f.rows[1 + leg][c];
    const ClipInfo& info = v.clips[clip];
    const float ahead = phase_lead(clip_phase, f.phase);
    glm::vec3 pos = clip_root_offset(v, rows);
    pos.z += info.stride * ahead;
    glm::quat rot = sample.clip(leg, c, chain.joints[0]);
    if (info.turn != 0.0f) rot = yaw_quat(info.turn * ahead) * rot;
    for (std::int32_t i = 1; i < n; ++i) {
      pos += rot * v.offsets[chain.joints[i]];
      rot = rot * sample.clip(leg, c, chain.joints[i]);
    }
    const float weight = c == 0 ? 1.0f - p.w : p.w;
    out.ankle += weight * pos;
    out.ball += weight * (pos + rot * ball_offset);
    out.ground += weight * info.ankle_ground[leg];
    out.lift[c] = pos.y - info.ankle_ground[leg];
  }
  return out;
}

// Stage 2. The blend's leg before the IK. Input: the frame. Output: in the
// path frame, scale 1: the thigh joint's position (m) and the world
// rotations of the thigh's parent, thigh, knee and ankle (the blended chain
// from the root, turned by the root's yaw offset).
struct BlendedLeg {
  glm::vec3 hip{0.0f};
  glm::quat hip_parent{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat thigh{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat knee{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat foot{1.0f, 0.0f, 0.0f, 0.0f};
};
template <class Sampler>
THRONG_HOST_DEVICE inline BlendedLeg blended_leg(const BlendSpaceView& v, const CharacterFrame& f, int leg,
                                                 const Sampler& sample) {
  const LegChain& chain = v.legs[leg];
  const std::int32_t n = chain.count;
  const std::int32_t thigh = chain.joints[n - 3], knee = chain.joints[n - 2], ankle = chain.joints[n - 1];
  glm::vec3 pos = f.root.position;
  glm::quat rot = yaw_quat(f.root.yaw) * sample.blended(chain.joints[0]);
  for (std::int32_t i = 1; i + 3 < n; ++i) {
    pos += rot * v.offsets[chain.joints[i]];
    rot = rot * sample.blended(chain.joints[i]);
  }
  BlendedLeg out;
  out.hip_parent = rot;
  out.hip = pos + rot * v.offsets[thigh];
  out.thigh = rot * sample.blended(thigh);
  out.knee = out.thigh * sample.blended(knee);
  out.foot = out.knee * sample.blended(ankle);
  return out;
}

// Stage 3. One leg's goal: the blended leg (stage 2) and where its ankle
// goes (path frame, scale 1, m). The pivot is the clips' ankle while the
// blended heel is down (within kHeelLift of the lerped ground), then their
// ball of the foot, less the blended foot's ankle-to-ball; between a
// stationary clip a and a striding clip b, the ankle also takes the
// striding clip's lift over its stationary one, ramped in over w.
struct PlantedLegGoal {
  glm::vec3 target{0.0f};
  BlendedLeg leg;
};
template <class Sampler>
THRONG_HOST_DEVICE inline PlantedLegGoal planted_leg_goal(const BlendSpaceView& v, const CharacterFrame& f, int leg,
                                                          const Sampler& sample) {
  const LegChain& chain = v.legs[leg];
  const BlendPoint& p = f.point;
  const ClipLegTargets clips = clip_leg_targets(v, f, leg, sample);
  PlantedLegGoal goal;
  goal.leg = blended_leg(v, f, leg, sample);
  glm::vec3 t = clips.ankle;
  if (chain.has_ball) {
    const glm::vec3 ball_offset(chain.ball[0], chain.ball[1], chain.ball[2]);
    const float heel = glm::clamp((clips.ankle.y - clips.ground) / kHeelLift, 0.0f, 1.0f);
    t += heel * (clips.ball - goal.leg.foot * ball_offset - clips.ankle);
  }
  if (v.clips[p.a].stride <= kMinStride && v.clips[p.b].stride > kMinStride) {
    const float ramp = p.w < kLiftRamp ? p.w / kLiftRamp : 1.0f;
    t.y += ramp * (1.0f - p.w) * (clips.lift[1] - clips.lift[0]);
  }
  goal.target = t;
  return goal;
}

// Stage 4. The pelvis drop (m, scale 1, >= 0) that brings a leg's target
// within kReach of its length (thigh plus shin rest offsets), given the
// drop the legs before it need: the larger of the two.
THRONG_HOST_DEVICE inline float pelvis_drop_to_reach(const BlendSpaceView& v, int leg, const PlantedLegGoal& goal,
                                                     float drop) {
  const LegChain& chain = v.legs[leg];
  const std::int32_t knee = chain.joints[chain.count - 2], ankle = chain.joints[chain.count - 1];
  const float reach = kReach * (glm::length(v.offsets[knee]) + glm::length(v.offsets[ankle]));
  const glm::vec3 d = goal.target - goal.leg.hip;
  const float across = d.x * d.x + d.z * d.z;
  if (across < reach * reach) drop = glm::max(drop, -d.y - glm::sqrt(reach * reach - across));
  return drop;
}

// Stage 5. Two-bone IK from the hip lowered by out.pelvis_drop (m) onto the
// goal's target; on success, out.active[leg] and the local rotations of
// thigh, knee and ankle (the foot keeps its blended world rotation).
THRONG_HOST_DEVICE inline void solve_planted_leg(const BlendSpaceView& v, int leg, PlantedLegGoal goal,
                                                 PlantedLegs& out) {
  const LegChain& chain = v.legs[leg];
  const std::int32_t n = chain.count;
  const std::int32_t knee = chain.joints[n - 2], ankle = chain.joints[n - 1];
  BlendedLeg& b = goal.leg;
  const glm::vec3 lowered = b.hip - glm::vec3(0.0f, out.pelvis_drop, 0.0f);
  if (!two_bone_ik(lowered, v.offsets[knee], v.offsets[ankle],
                   glm::vec3(chain.hinge[0], chain.hinge[1], chain.hinge[2]), goal.target, b.thigh, b.knee))
    return;
  out.active[leg] = true;
  out.corrected[leg][0] = glm::inverse(b.hip_parent) * b.thigh;
  out.corrected[leg][1] = glm::inverse(b.thigh) * b.knee;
  out.corrected[leg][2] = glm::inverse(b.knee) * b.foot;
}

template <class Sampler>
THRONG_HOST_DEVICE inline PlantedLegs plant_legs(const BlendSpaceView& v, const CharacterFrame& f,
                                                 const std::uint32_t* mask, const Sampler& sample) {
  PlantedLegs out;
  if (!v.plant_feet || f.point.w <= 0.0f || f.point.w >= 1.0f) return out;
  PlantedLegGoal goal[2];
  bool use[2] = {false, false};
  float drop = 0.0f;
  for (int leg = 0; leg < 2; ++leg) {
    if (!plants_leg(v, leg, mask)) continue;
    goal[leg] = planted_leg_goal(v, f, leg, sample);
    use[leg] = true;
    drop = pelvis_drop_to_reach(v, leg, goal[leg], drop);
  }
  out.pelvis_drop = glm::min(drop, kMaxPelvisDrop);
  for (int leg = 0; leg < 2; ++leg)
    if (use[leg]) solve_planted_leg(v, leg, goal[leg], out);
  return out;
}
THRONG_HOST_DEVICE inline PlantedLegs plant_legs(const BlendSpaceView& v, const CharacterFrame& f,
                                                 const std::uint32_t* mask) {
  return plant_legs(v, f, mask, SampleOnDemand{&v, &f});
}

}  // namespace throng::motion
