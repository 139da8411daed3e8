// Locomotion synthesis by speed: the 2019 method (blend a slow and a fast
// cyclic clip joint by joint with SLERP at the same phase; root update
// p_{f+1} = T(d_{f,w}) R(r_f) S(s_f) p_f), and past it: any number of clips
// in a 1D blend space, foot-event synchronisation (per leg), exact arc
// integration, leg IK that plants blended feet, foot-skate cleanup of mocap.
//
// Two halves:
// * Host, once: prepare_locomotion_clip / prepare_locomotion_cycle turn a
//   clip into one clean cycle (loop found and closed, root split into a
//   path and an offset from it, contacts cleaned, foot events found, frame
//   0 at the left touchdown); BlendSpace1D sorts prepared clips by speed and
//   packs them into one motion texture plus small tables (BlendSpaceTables
//   puts them in device memory).
// * Per frame, host or device: blend_coordinate (speed -> x), blend_point
//   (x -> two clips and w), warp_phase (the canonical phase -> each clip's
//   phase, synchronised by foot events), blended_rotation (SLERP of the two
//   clips' samples), advance_locomotion (phase and Eq. 10), character_frame,
//   plant_legs, synthesise_pose (world joints). Per-frame work is sampling
//   only. The batch stage for N characters is anim/crowd_animator.h.
//
// Conventions: Y up, metres, seconds, characters face +Z at yaw 0 and turn
// left (towards +X) for positive yaw (core/ground.h). The path frame of a
// clip: origin on the ground at the path point, +Z along the path, +X left.
// Details and derivations: docs/locomotion.md.
//
// The parts, each usable alone:
//   motion/locomotion_clip.h      prepared clips (host)
//   motion/blend_space.h          the blend space and its device tables
//   motion/locomotion_sampling.h  per-frame sampling of the blend space
//   motion/locomotion_step.h      one character per frame: advance, frame
//   motion/leg_ik.h               two-bone IK and plant_legs
//   motion/locomotion_pose.h      synthesised poses, host drivers
// Angle helpers (wrap_angle, kPi): core/math.h.
#pragma once

#include "core/math.h"
#include "motion/blend_space.h"
#include "motion/leg_ik.h"
#include "motion/locomotion_clip.h"
#include "motion/locomotion_pose.h"
#include "motion/locomotion_sampling.h"
#include "motion/locomotion_step.h"
