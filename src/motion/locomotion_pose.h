// A character's synthesised pose (host and device): the blend's local
// rotations with the leg IK's in place (synthesised_rotation), world joints
// (synthesise_pose); and host drivers of one character for the reference
// and tests (animate_character, locomotion_foot_skating).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/config.h"
#include "motion/blend_space.h"
#include "motion/cycle.h"
#include "motion/fk.h"
#include "motion/foot_skating.h"
#include "motion/leg_ik.h"
#include "motion/locomotion_step.h"
#include "motion/quat_lanes.h"

namespace throng::motion {

// The synthesised local rotation of a joint: the blend, or the leg IK's.
THRONG_HOST_DEVICE inline glm::quat synthesised_rotation(const BlendSpaceView& v, const CharacterFrame& f,
                                                         const PlantedLegs& legs, std::int32_t joint) {
  for (int leg = 0; leg < 2; ++leg) {
    const int k = legs.active[leg] ? leg_slot(v.legs[leg], joint) : -1;
    if (k >= 0) return legs.corrected[leg][k];
  }
  return joint_rotation(v, f, joint);
}

// A character's joints sampled once (the sampler of plant_legs): blended
// local rotations where the mask keeps the joint, and each clip's rotation
// of every leg's thigh, knee and ankle in that leg's group; anything else
// is sampled on demand.
struct SampledJoints {
  const BlendSpaceView* v;
  const CharacterFrame* f;
  const std::uint32_t* mask;
  const glm::quat* local;
  glm::quat leg_clip[2][3][2];  // [leg][thigh, knee, ankle][clip a, b]
  THRONG_HOST_DEVICE glm::quat blended(std::int32_t joint) const {
    return mask_bit(mask, joint) ? local[joint] : joint_rotation(*v, *f, joint);
  }
  // Keeps joint's two clip samples when it is a thigh, knee or ankle in
  // its own leg's group (each thigh's subtree is; clip() samples anything
  // else anew).
  THRONG_HOST_DEVICE void keep_clip_samples(std::int32_t joint, const glm::quat& qa, const glm::quat& qb) {
    const std::uint8_t g = v->joint_group[joint];
    const int k = g > 0 ? leg_slot(v->legs[g - 1], joint) : -1;
    if (k >= 0) {
      leg_clip[g - 1][k][0] = qa;
      leg_clip[g - 1][k][1] = qb;
    }
  }
  THRONG_HOST_DEVICE glm::quat clip(int leg, int c, std::int32_t joint) const {
    const int k = v->joint_group[joint] == 1 + leg ? leg_slot(v->legs[leg], joint) : -1;
    return k >= 0 ? leg_clip[leg][k][c] : clip_rotation(*v, f->rows[1 + leg][c], joint);
  }
};

// The blend's local rotations of joints j0 .. j0 + kQuatLanes - 1 (those
// below joint_count) side by side: each clip sampled between its rows (the
// rows of the joint's group), then SLERP by w in (0, 1). Writes local[j]
// where the mask keeps j, and each clip's sample of the legs' thigh, knee
// and ankle into s.
THRONG_HOST_DEVICE inline void blend_joint_lanes(const BlendSpaceView& v, const CharacterFrame& f, const SlerpAt& blend,
                                                 std::int32_t j0, SampledJoints& s, glm::quat* local) {
  QuatLanes a0, a1, b0, b1, qa, qb, q;
  float ta[kQuatLanes], tb[kQuatLanes];
  const std::int32_t last = v.joint_count - 1;
  const int n = lanes_for(v.joint_count - j0);
  int l = 0;
  do {  // n >= 1 (the compiler sees every lane array written); lanes past the last joint repeat it
    const std::int32_t j = j0 + l < last ? j0 + l : last;
    const std::uint8_t g = v.joint_group[j];
    const ClipRows &ra = f.rows[g][0], &rb = f.rows[g][1];
    a0.set(l, texel_quat(v.texture, j, ra.r0));
    a1.set(l, texel_quat(v.texture, j, ra.r1));
    b0.set(l, texel_quat(v.texture, j, rb.r0));
    b1.set(l, texel_quat(v.texture, j, rb.r1));
    ta[l] = ra.t;
    tb[l] = rb.t;
  } while (++l < n);
  interpolate_frames(n, a0, a1, ta, qa);
  interpolate_frames(n, b0, b1, tb, qb);
  slerp(n, blend, qa, qb, q);
  for (l = 0; l < n && j0 + l <= last; ++l) {
    const std::int32_t j = j0 + l;
    if (mask_bit(s.mask, j)) local[j] = q.get(l);
    s.keep_clip_samples(j, qa.get(l), qb.get(l));
  }
}

// Every local rotation synthesised_rotation gives, bit for bit, each joint
// sampled once: writes local[j] for the joints the mask keeps (a null mask
// keeps all) and returns the leg IK's result (for its pelvis drop).
THRONG_HOST_DEVICE inline PlantedLegs synthesise_locals(const BlendSpaceView& v, const CharacterFrame& f,
                                                        const std::uint32_t* mask, glm::quat* local) {
  SampledJoints s{&v, &f, mask, local, {}};
  const float w = f.point.w;
  const SlerpAt blend(w);
  // Lanes sample every joint: worth it while the mask keeps most of them
  // (joint LOD keeps a few of a far character's).
  std::int32_t kept = mask == nullptr ? v.joint_count : 0;
  for (std::int32_t j = 0; mask != nullptr && j < v.joint_count; ++j) kept += mask_bit(mask, j) ? 1 : 0;
  if (w > 0.0f && w < 1.0f && 2 * kept >= v.joint_count) {
    for (std::int32_t j0 = 0; j0 < v.joint_count; j0 += kQuatLanes) blend_joint_lanes(v, f, blend, j0, s, local);
  } else {
    for (std::int32_t j = 0; j < v.joint_count; ++j) {
      if (!mask_bit(mask, j)) continue;
      const std::uint8_t g = v.joint_group[j];
      const ClipRows &ra = f.rows[g][0], &rb = f.rows[g][1];
      if (w <= 0.0f || w >= 1.0f) {  // one clip, no IK
        local[j] = blended_rotation(v, w, ra, rb, j);
        continue;
      }
      const glm::quat qa = clip_rotation(v, ra, j), qb = clip_rotation(v, rb, j);
      local[j] = blend(qa, qb);
      s.keep_clip_samples(j, qa, qb);
    }
  }
  const PlantedLegs legs = plant_legs(v, f, mask, s);
  for (int leg = 0; leg < 2; ++leg) {
    const LegChain& chain = v.legs[leg];
    for (int k = 0; k < 3 && legs.active[leg]; ++k) local[chain.joints[chain.count - 3 + k]] = legs.corrected[leg][k];
  }
  return legs;
}

// World position and rotation of every joint (reference: every joint
// synthesised; the batch stage adds LOD masks and the cache).
THRONG_HOST_DEVICE inline void synthesise_pose(const BlendSpaceView& v, const CharacterFrame& f,
                                               glm::vec3* out_positions, glm::quat* out_rotations) {
  const PlantedLegs legs = plant_legs(v, f, nullptr);
  for (std::int32_t j = 0; j < v.joint_count; ++j) {
    const glm::quat local = synthesised_rotation(v, f, legs, j);
    const std::int32_t p = v.parents[j];
    if (p < 0) {
      out_positions[j] = f.root_position - glm::vec3(0.0f, f.scale * legs.pelvis_drop, 0.0f);
      out_rotations[j] = f.frame * local;
    } else {
      out_positions[j] = out_positions[p] + out_rotations[p] * (f.scale * v.offsets[j]);
      out_rotations[j] = out_rotations[p] * local;
    }
  }
}

// ---------------------------------------------------------------------------
// Host helpers

// One character's state for the host reference and tests.
struct LocomotionCharacter {
  glm::vec3 position{0.0f};
  float yaw = 0.0f;
  float scale = 1.0f;
  float phase = 0.0f;
  float blend_speed = -1.0f;
};

// Drives one character at a constant speed (and turn rate) for `frames`
// frames, recording its world joints each frame after advancing:
// [frame * joints + joint] (a ModelSpaceClip in world space).
ModelSpaceClip animate_character(const BlendSpace1D& space, LocomotionCharacter character, float speed, float turn_rate,
                                 const LocomotionStep& step, std::int32_t frames);

// Foot skating of one character walking straight at a constant speed for
// `seconds` (sampled every step.dt): contacts found on the synthesised
// motion (low and slow feet), slide per contact (motion/foot_skating.h).
FootSkatingReport locomotion_foot_skating(const BlendSpace1D& space, float speed, double seconds,
                                          const LocomotionStep& step = {}, const ContactOptions& contacts = {});

}  // namespace throng::motion
