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
//   only. The batch stage for N characters is anim/locomotion.h.
//
// Conventions: Y up, metres, seconds, characters face +Z at yaw 0 and turn
// left (towards +X) for positive yaw (core/ground.h). The path frame of a
// clip: origin on the ground at the path point, +Z along the path, +X left.
// Details and derivations: docs/locomotion.md.
#pragma once

#include <array>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "core/buffer.h"
#include "core/config.h"
#include "motion/clip.h"
#include "motion/cycle.h"
#include "motion/foot_skating.h"
#include "motion/motion_texture.h"
#include "motion/phase.h"
#include "motion/skeleton.h"

namespace throng::motion {

// ---------------------------------------------------------------------------
// Prepared clips

// Foot events of a cycle, as phases in [0, 1).
enum class FootEvent : std::uint8_t { LeftDown, LeftUp, RightDown, RightUp };
inline constexpr int kFootEvents = 4;
const char* to_string(FootEvent e);

struct LocomotionOptions {
  CycleOptions cycle;        // raw clips: how the loop is found (e.g. skip_frames)
  ContactOptions contacts;   // foot events of the cycle
  // Take a slight turn out of a clip meant to go straight (real mocap drifts
  // a few degrees per cycle): the path becomes a line, the root keeps its
  // motion relative to the turning path. A speed blend space wants this.
  bool straighten = true;
  // Clips whose root moves less than this per cycle (m) are stationary
  // (idle): no stride, the path point is the root's mean ground position.
  double stationary_below_m = 0.05;
  // Pin the feet during contacts in the cycle's own motion (clean_foot_contacts).
  bool clean_contacts = true;
  double contact_ramp_s = 0.1;  // corrections fade in and out over this before and after a contact
  // A contact goes on after the strict test while the ball stays low and
  // moves slower than contacts.speed_fraction times this (the push-off roll).
  double cleanup_speed_factor = 3.0;
  double max_cleanup_m = 0.04;  // frames that would need a larger correction are left free
  void validate() const;  // Error naming the field
};

// One locomotion cycle ready for synthesis.
struct LocomotionClip {
  std::string name;
  // One cycle: frame i at phase i / frame_count, frame 0 at the left foot's
  // touchdown (when the clip has one). Local joint rotations, except the
  // root's, which is relative to the path's heading at that phase;
  // root_positions hold the root's offset from the path point in the path
  // frame (x left, y up, z forward; its mean over the cycle is 0 in x, z).
  Clip cycle;
  double period_s = 0.0;   // seconds per cycle
  double stride_m = 0.0;   // path length per cycle (two steps)
  double turn_rad = 0.0;   // path heading change per cycle (0 when straightened)
  double speed = 0.0;      // stride / period, m/s
  double turn_removed_rad = 0.0;  // what straightening took out per cycle
  // Phases of the foot events, -1 where the cycle has none (idle) or the
  // contacts are not one per foot per cycle.
  std::array<float, kFootEvents> events{-1.0f, -1.0f, -1.0f, -1.0f};
  // Per joint: the cycle's mean local rotation, what joints that LOD turns
  // off hold instead of being synthesised.
  std::vector<glm::quat> mean_rotations;
  // Lowest height of each ankle joint over the cycle (m): [0] left, [1] right.
  std::array<float, 2> ankle_ground{0.0f, 0.0f};
  // Input frame that became frame 0 (within the input cycle).
  std::int32_t source_start_frame = 0;
  double contact_cleanup_m = 0.0;  // largest ankle correction of clean_foot_contacts

  std::int32_t frame_count() const { return cycle.frame_count; }
  float event(FootEvent e) const { return events[static_cast<std::size_t>(e)]; }
};

// A clip that is already exactly one cycle (frame F would be frame 0 moved
// by the cycle's rigid root motion), e.g. the default set's.
LocomotionClip prepare_locomotion_cycle(const Skeleton& skeleton, const Clip& cycle, std::string name,
                                        const LocomotionOptions& options = {});
// Foot-skate cleanup of a prepared cycle, as motion capture slides (heel
// rocker, marker drift, rescaled skeletons): in the cycle's own motion (its
// path at stride_m per cycle), each contact (motion/cycle.h) pins the ankle
// while the heel is down and the ball of the foot once it is up (the ball
// where it stands when the heel rises); two-bone IK moves thigh and knee to
// reach it and keeps the foot's world rotation. Corrections fade in and out
// over contact_ramp_s around each contact. Returns the largest correction (m).
double clean_foot_contacts(const Skeleton& skeleton, LocomotionClip& clip, const LocomotionOptions& options = {});

// Any locomotion clip: finds the best loop (analyze_cycle), closes it
// (make_cyclic), then prepare_locomotion_cycle. Error when no cycle is found.
LocomotionClip prepare_locomotion_clip(const Skeleton& skeleton, const Clip& clip, std::string name,
                                       const LocomotionOptions& options = {});

// ---------------------------------------------------------------------------
// Tables shared by host and device code

inline constexpr int kMaxSyncMarkers = 4;

// Phases in clip a and in clip b that a blend of the two aligns: foot
// events both clips have, in the same cyclic order. Stored unwrapped from
// the first: a[0] <= a[k] < a[0] + 1 increasing (b likewise). The canonical
// phase of marker k at weight w is a[k] + w (b[k] - a[k]); between markers
// each clip's phase follows linearly (circularly, marker count wraps to 0).
// count 1 with a[0] = b[0] = 0: no warp.
struct SyncMarkers {
  std::int32_t count = 1;
  float a[kMaxSyncMarkers] = {0.0f, 0.0f, 0.0f, 0.0f};
  float b[kMaxSyncMarkers] = {0.0f, 0.0f, 0.0f, 0.0f};
};

// Three warps per pair of clips. The body (root, spine, arms) aligns the
// touchdowns, so its phase stays the cycle's; each leg (the thigh's subtree)
// aligns its own touchdown and liftoff, so that a foot is down in the blend
// exactly when it is down in both clips. Walks blended with walks align all
// four events everywhere (the three warps agree); a walk blended with a run
// cannot align both feet's liftoffs with one warp (double support against
// flight puts them in a different order), hence one per leg.
inline constexpr int kSyncGroups = 3;  // body, left leg, right leg
struct SegmentSync {
  SyncMarkers group[kSyncGroups];
};
SegmentSync sync_markers(const LocomotionClip& a, const LocomotionClip& b);

// The joints from the skeleton root down to one ankle (thigh, knee, ankle
// last), for the leg IK that plants the feet of a blend; count 0 = none.
inline constexpr int kMaxLegChain = 8;
struct LegChain {
  std::int32_t count = 0;
  std::int32_t joints[kMaxLegChain] = {};
  float ball[3] = {0.0f, 0.0f, 0.0f};  // ball of the foot in the ankle's frame (toe joint or end site)
  bool has_ball = false;
  // The knee's hinge in the thigh's frame: the axis it bends about (the
  // IK bends the knee the same way as the clips do, even from straight).
  float hinge[3] = {1.0f, 0.0f, 0.0f};
};

// The knee's hinge in the thigh's frame from clips' knee rotations: the mean
// of thigh x shin over their frames, weighted by how much the knee bends.
glm::vec3 knee_hinge(const glm::vec3& knee_offset, const glm::vec3& ankle_offset, const std::vector<const Clip*>& clips,
                     std::int32_t knee);

struct ClipInfo {
  std::int32_t first_row = 0;  // of the clip's frames in the stacked texture
  std::int32_t rows = 0;       // frames per cycle
  float speed = 0.0f;          // m/s at scale 1
  float stride = 0.0f;         // m per cycle
  float turn = 0.0f;           // rad per cycle
  float period = 1.0f;         // s per cycle
  float ankle_ground[2] = {0.0f, 0.0f};  // lowest ankle heights (m)
};

// What per-character code reads, by pointer (host or device memory).
struct BlendSpaceView {
  std::int32_t joint_count = 0;
  std::int32_t clip_count = 0;
  MotionTextureView texture;                  // every clip's cycle, stacked by rows
  const ClipInfo* clips = nullptr;            // clip_count, by increasing speed
  const SegmentSync* sync = nullptr;          // per segment: max(clip_count - 1, 1)
  const std::uint8_t* joint_group = nullptr;  // joint_count: 0 body, 1 left leg, 2 right leg
  const glm::quat* mean_rotations = nullptr;  // clip_count * joint_count
  const std::int32_t* parents = nullptr;      // joint_count
  const glm::vec3* offsets = nullptr;         // joint_count, rest offsets (m)
  LegChain legs[2];                           // left, right: plant_legs
  bool plant_feet = true;
  // Blend weights snapped to the centres of buckets this wide (0 = exact):
  // with a motion cache every character shows its bucket's blend, so a
  // cached cycle is exactly what it would synthesise (speed stays exact,
  // the cadence follows the snapped stride).
  float quantum = 0.0f;
  std::int32_t quantum_buckets = 1;

  THRONG_HOST_DEVICE std::int32_t segment_count() const { return clip_count > 1 ? clip_count - 1 : 1; }
};

// ---------------------------------------------------------------------------
// The blend space

struct BlendSpaceOptions {
  TexelFormat format = TexelFormat::Float32;  // of the motion texture (fp16 halves it, w = 0/1 then not bit-exact)
  // Leg IK in blends: each ankle goes exactly where the two clips' ankles
  // lerp to (plant_legs). Needs thigh -> knee -> ankle parent chains.
  bool plant_feet = true;
};

// Clips of one skeleton sorted by speed (strictly increasing after sorting;
// Error otherwise, or when joint counts differ). Segment k blends clips k and
// k + 1. The speed coordinate x runs over [0, clip_count - 1].
class BlendSpace1D {
 public:
  BlendSpace1D(Skeleton skeleton, std::vector<LocomotionClip> clips, const BlendSpaceOptions& options = {});

  const Skeleton& skeleton() const { return skeleton_; }
  const std::vector<LocomotionClip>& clips() const { return clips_; }
  std::int32_t clip_count() const { return static_cast<std::int32_t>(clips_.size()); }
  std::int32_t segment_count() const { return clip_count() > 1 ? clip_count() - 1 : 1; }
  std::int32_t joint_count() const { return skeleton_.joint_count(); }
  std::int32_t max_frames() const;  // longest cycle, frames
  float min_speed() const { return clip_infos_.front().speed; }
  float max_speed() const { return clip_infos_.back().speed; }
  const std::vector<SegmentSync>& sync() const { return sync_; }
  const std::vector<std::uint8_t>& joint_groups() const { return joint_group_; }
  const MotionTexture& texture() const { return texture_; }
  const std::vector<ClipInfo>& clip_infos() const { return clip_infos_; }
  const std::vector<glm::quat>& mean_rotations() const { return mean_rotations_; }
  // The tables in host memory (valid while this object lives, unmoved).
  BlendSpaceView view() const;

 private:
  Skeleton skeleton_;
  std::vector<LocomotionClip> clips_;
  MotionTexture texture_;
  std::vector<ClipInfo> clip_infos_;
  std::vector<SegmentSync> sync_;
  std::vector<std::uint8_t> joint_group_;
  std::vector<glm::quat> mean_rotations_;
  std::array<LegChain, 2> legs_{};
  bool plant_feet_ = true;
};

// The blend space's tables in the memory that kernels read.
class BlendSpaceTables {
 public:
  BlendSpaceTables() = default;
  explicit BlendSpaceTables(const BlendSpace1D& space, Memory memory = current_memory());
  BlendSpaceView view() const { return view_; }

 private:
  Buffer<float> texels_f32_;
  Buffer<std::uint16_t> texels_f16_;
  Buffer<ClipInfo> clips_;
  Buffer<SegmentSync> sync_;
  Buffer<std::uint8_t> joint_group_;
  Buffer<glm::quat> mean_rotations_;
  Buffer<std::int32_t> parents_;
  Buffer<glm::vec3> offsets_;
  BlendSpaceView view_;
};

// The project's own set: idle, walk_slow, walk, walk_fast, run_slow and
// run_fast of the default skeleton (motion/default_set.h), 0 to 4.5 m/s.
BlendSpace1D make_default_blend_space();

// ---------------------------------------------------------------------------
// Per-frame sampling (host and device)

// Buckets of a weight w in [0, 1] of a given width (the last may be
// narrower): w -> bucket (clamped; NaN -> 0; w = 1 in the last), the bucket's
// centre, and how many buckets there are.
THRONG_HOST_DEVICE inline std::int32_t weight_bucket_count(float width) {
  const double n = glm::ceil(1.0 / static_cast<double>(width) - 1e-6);  // 1 / 0.05 = 20.000000000000004
  return n > 1.0 ? static_cast<std::int32_t>(n) : 1;
}
THRONG_HOST_DEVICE inline std::int32_t weight_bucket(float w, float width, std::int32_t bucket_count) {
  if (!(w > 0.0f)) return 0;
  const double b = glm::floor(static_cast<double>(w < 1.0f ? w : 1.0f) / static_cast<double>(width));
  const auto i = static_cast<std::int32_t>(b);
  return i < bucket_count - 1 ? i : bucket_count - 1;
}
THRONG_HOST_DEVICE inline float weight_bucket_centre(std::int32_t bucket, float width) {
  const double lo = static_cast<double>(bucket) * width;
  const double hi = glm::min(1.0, static_cast<double>(bucket + 1) * width);
  return static_cast<float>(0.5 * (lo + hi));
}

// Two neighbouring clips and the weight of the second.
struct BlendPoint {
  std::int32_t a = 0;
  std::int32_t b = 0;
  std::int32_t segment = 0;
  float w = 0.0f;
};

// Speed (m/s at scale 1) -> x in [0, clip_count - 1], piecewise linear
// through the clips' speeds; below the slowest clip 0, above the fastest
// clip_count - 1 (those speeds play the end clip faster or slower).
THRONG_HOST_DEVICE inline float blend_coordinate(const BlendSpaceView& v, float speed) {
  const std::int32_t n = v.clip_count;
  if (n <= 1 || !(speed > v.clips[0].speed)) return 0.0f;  // also NaN
  for (std::int32_t k = 0; k + 1 < n; ++k) {
    const float lo = v.clips[k].speed, hi = v.clips[k + 1].speed;
    if (speed < hi) return static_cast<float>(k) + (speed - lo) / (hi - lo);
  }
  return static_cast<float>(n - 1);
}

THRONG_HOST_DEVICE inline BlendPoint blend_point(const BlendSpaceView& v, float x) {
  BlendPoint p;
  const std::int32_t n = v.clip_count;
  if (n <= 1) return p;
  if (!(x > 0.0f)) x = 0.0f;  // also NaN
  if (x > static_cast<float>(n - 1)) x = static_cast<float>(n - 1);
  std::int32_t k = static_cast<std::int32_t>(x);
  if (k > n - 2) k = n - 2;
  p.a = k;
  p.b = k + 1;
  p.segment = k;
  p.w = x - static_cast<float>(k);
  if (v.quantum > 0.0f) p.w = weight_bucket_centre(weight_bucket(p.w, v.quantum, v.quantum_buckets), v.quantum);
  return p;
}

THRONG_HOST_DEVICE inline float mix_weight(float a, float b, float w) { return a + w * (b - a); }

// How far a clip's phase runs ahead of the canonical phase, in [-1/2, 1/2):
// a warp moves phases by far less than half a cycle, so this is the lead
// even when one of the two has just wrapped.
THRONG_HOST_DEVICE inline float phase_lead(float clip_phase, float phase) {
  const float d = clip_phase - phase;
  return d - glm::floor(d + 0.5f);
}

// Each clip's phase at the canonical (blended) phase under one warp:
// piecewise linear between the markers. w = 0 gives clip a the canonical
// phase itself, w = 1 clip b.
struct ClipPhases {
  float a = 0.0f;
  float b = 0.0f;
};
THRONG_HOST_DEVICE inline ClipPhases warp_phase(const SyncMarkers& s, float w, float phase) {
  phase = wrap_phase(phase);
  ClipPhases out;
  out.a = phase;
  out.b = phase;
  if (s.count <= 1 && s.a[0] == 0.0f && s.b[0] == 0.0f) return out;
  // Canonical positions relative to marker 0, on [0, 1).
  const float u = wrap_phase(phase - mix_weight(s.a[0], s.b[0], w));
  std::int32_t k = 0;
  while (k + 1 < s.count && mix_weight(s.a[k + 1] - s.a[0], s.b[k + 1] - s.b[0], w) <= u) ++k;
  const bool last = k + 1 >= s.count;
  const float da0 = s.a[k] - s.a[0], db0 = s.b[k] - s.b[0];
  const float da1 = last ? 1.0f : s.a[k + 1] - s.a[0], db1 = last ? 1.0f : s.b[k + 1] - s.b[0];
  const float m0 = mix_weight(da0, db0, w), m1 = mix_weight(da1, db1, w);
  const float t = m1 > m0 ? (u - m0) / (m1 - m0) : 0.0f;
  if (w > 0.0f) out.a = wrap_phase(s.a[0] + da0 + t * (da1 - da0));
  if (w < 1.0f) out.b = wrap_phase(s.b[0] + db0 + t * (db1 - db0));
  return out;
}

// Where a clip's phase falls in the stacked texture: two neighbouring rows
// and the fraction between them (computed once per clip and phase, used for
// every joint).
struct ClipRows {
  std::int32_t r0 = 0;
  std::int32_t r1 = 0;
  float t = 0.0f;
};
THRONG_HOST_DEVICE inline ClipRows clip_rows(const BlendSpaceView& v, std::int32_t clip, float clip_phase) {
  const ClipInfo& c = v.clips[clip];
  const CyclePoint cp = cycle_point(c.rows, clip_phase);
  ClipRows r;
  r.r0 = c.first_row + cp.f0;
  r.r1 = c.first_row + cp.f1;
  r.t = cp.t;
  return r;
}

// The orientation texel of a joint on a row (texelFetch semantics; rows
// from clip_rows are always inside the texture).
THRONG_HOST_DEVICE inline glm::quat texel_quat(const MotionTextureView& t, std::int32_t joint, std::int32_t row) {
  if (t.format == TexelFormat::Float32) {
    const float* q = t.texels_f32 + (static_cast<Index>(row) * t.width + 2 * joint) * 4;
    return glm::quat(q[3], q[0], q[1], q[2]);
  }
  const glm::vec4 r = t.texel_fetch(2 * joint, row);
  return glm::normalize(glm::quat(r.w, r.x, r.y, r.z));
}

// A joint's local rotation in one clip between its two rows (interpolate_frames).
THRONG_HOST_DEVICE inline glm::quat clip_rotation(const BlendSpaceView& v, const ClipRows& r, std::int32_t joint) {
  const glm::quat q0 = texel_quat(v.texture, joint, r.r0);
  if (r.t <= 0.0f) return q0;
  return interpolate_frames(q0, texel_quat(v.texture, joint, r.r1), r.t);
}
THRONG_HOST_DEVICE inline glm::quat clip_rotation(const BlendSpaceView& v, std::int32_t clip, float clip_phase, std::int32_t joint) {
  return clip_rotation(v, clip_rows(v, clip, clip_phase), joint);
}
// The root's offset from the path point (path frame, scale 1) in one clip.
THRONG_HOST_DEVICE inline glm::vec3 clip_root_offset(const BlendSpaceView& v, const ClipRows& r) {
  const glm::vec3 p0(v.texture.texel_fetch(1, r.r0));
  if (r.t <= 0.0f) return p0;
  const glm::vec3 p1(v.texture.texel_fetch(1, r.r1));
  return p0 + r.t * (p1 - p0);
}
THRONG_HOST_DEVICE inline glm::vec3 clip_root_offset(const BlendSpaceView& v, std::int32_t clip, float clip_phase) {
  return clip_root_offset(v, clip_rows(v, clip, clip_phase));
}

// The blended local rotation of a joint: SLERP (shortest arc) of the two
// clips' rotations by w; w = 0 and w = 1 return a clip's sample exactly.
THRONG_HOST_DEVICE inline glm::quat blended_rotation(const BlendSpaceView& v, float w, const ClipRows& a, const ClipRows& b,
                                                     std::int32_t joint) {
  if (w <= 0.0f) return clip_rotation(v, a, joint);
  if (w >= 1.0f) return clip_rotation(v, b, joint);
  return slerp_shortest(clip_rotation(v, a, joint), clip_rotation(v, b, joint), w);
}
THRONG_HOST_DEVICE inline glm::quat blended_rotation(const BlendSpaceView& v, const BlendPoint& p, const ClipPhases& ph,
                                                     std::int32_t joint) {
  return blended_rotation(v, p.w, clip_rows(v, p.a, ph.a), clip_rows(v, p.b, ph.b), joint);
}

// What a joint holds when LOD turns it off: the mean rotation of the clip
// with the larger weight (no sampling, no SLERP).
THRONG_HOST_DEVICE inline const glm::quat* held_rotations(const BlendSpaceView& v, const BlendPoint& p) {
  return v.mean_rotations + static_cast<Index>(p.w < 0.5f ? p.a : p.b) * v.joint_count;
}

THRONG_HOST_DEVICE inline float blended_stride(const BlendSpaceView& v, const BlendPoint& p) {
  return mix_weight(v.clips[p.a].stride, v.clips[p.b].stride, p.w);
}
THRONG_HOST_DEVICE inline float blended_turn(const BlendSpaceView& v, const BlendPoint& p) {
  return mix_weight(v.clips[p.a].turn, v.clips[p.b].turn, p.w);
}
THRONG_HOST_DEVICE inline float blended_period(const BlendSpaceView& v, const BlendPoint& p) {
  return mix_weight(v.clips[p.a].period, v.clips[p.b].period, p.w);
}

// Cycles per second at a speed (m/s at scale 1): the blended stride is
// covered at that speed, so speed = lerp(v_a, v_b, w) inside a segment
// (stride lerps with w, cadence follows) and outside the clips' range the
// end clip plays faster or slower with its feet still planted. A blend with
// no stride (idle alone) plays at its own period.
inline constexpr float kMinStride = 1e-4f;
THRONG_HOST_DEVICE inline float cycle_rate(const BlendSpaceView& v, const BlendPoint& p, float speed) {
  const float stride = blended_stride(v, p);
  if (stride > kMinStride) return (speed > 0.0f ? speed : 0.0f) / stride;
  const float period = blended_period(v, p);
  return period > 0.0f ? 1.0f / period : 0.0f;
}

// The root relative to the character's path frame at the canonical phase
// (scale 1): Eq. 10's blended displacement in closed form. The path point
// advances the blended stride per cycle; each clip's offset from its own
// path is blended, plus the distance its path runs ahead of the canonical
// phase (stride_c (phase_c - phase)), so the root moves exactly by
// w d^b + (1 - w) d^a per step.
struct RootOffset {
  glm::vec3 position{0.0f};
  float yaw = 0.0f;  // extra heading about +Y of the root frame (turning clips)
};
THRONG_HOST_DEVICE inline RootOffset blended_root_offset(const BlendSpaceView& v, const BlendPoint& p, float phase,
                                                         const ClipPhases& ph) {
  phase = wrap_phase(phase);
  const ClipInfo& a = v.clips[p.a];
  const ClipInfo& b = v.clips[p.b];
  RootOffset r;
  const glm::vec3 oa = clip_root_offset(v, p.a, ph.a);
  if (p.w <= 0.0f) {
    r.position = oa;
    return r;
  }
  const glm::vec3 ob = clip_root_offset(v, p.b, ph.b);
  if (p.w >= 1.0f) {
    r.position = ob;
    return r;
  }
  const float da = phase_lead(ph.a, phase), db = phase_lead(ph.b, phase);
  r.position = oa + p.w * (ob - oa);
  r.position.z += (1.0f - p.w) * a.stride * da + p.w * b.stride * db;
  r.yaw = (1.0f - p.w) * a.turn * da + p.w * b.turn * db;
  return r;
}

THRONG_HOST_DEVICE inline glm::quat yaw_quat(float yaw) {
  return glm::quat(glm::cos(0.5f * yaw), 0.0f, glm::sin(0.5f * yaw), 0.0f);
}
THRONG_HOST_DEVICE inline float wrap_angle(float a) {
  constexpr float kTwoPi = 6.28318530717958647692f;
  return a - kTwoPi * glm::floor((a + 0.5f * kTwoPi) / kTwoPi);
}

// ---------------------------------------------------------------------------
// One character per frame

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
  ClipRows rows[kSyncGroups][2];    // the same as texture rows, clip a and clip b
  float phase = 0.0f;  // canonical, [0, 1)
  RootOffset root;     // in the path frame, scale 1
  glm::vec3 root_position{0.0f};
  glm::quat frame{1.0f, 0.0f, 0.0f, 0.0f};
  float scale = 1.0f;
};
THRONG_HOST_DEVICE inline CharacterFrame character_frame_at(const BlendSpaceView& v, const BlendPoint& point, float phase,
                                                            glm::vec3 position, float yaw, float scale) {
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
THRONG_HOST_DEVICE inline glm::quat joint_rotation(const BlendSpaceView& v, const CharacterFrame& f, std::int32_t joint) {
  const std::uint8_t g = v.joint_group[joint];
  return blended_rotation(v, f.point.w, f.rows[g][0], f.rows[g][1], joint);
}

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

// Two-bone IK: turns the world rotations of a thigh and its knee so that the
// ankle (knee_offset, ankle_offset: rest offsets of knee and ankle) reaches
// `target` from the hip, or as near as the leg reaches. The knee bends about
// its hinge (`hinge`: the axis in the thigh's frame, see LegChain) to the
// angle the law of cosines gives, never backwards; then the leg swings about
// the hip by the shortest arc. False (nothing changed) for a degenerate leg.
THRONG_HOST_DEVICE inline bool two_bone_ik(const glm::vec3& hip, const glm::vec3& knee_offset, const glm::vec3& ankle_offset,
                                           const glm::vec3& hinge, const glm::vec3& target, glm::quat& r_thigh, glm::quat& r_knee) {
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
  glm::vec3 axis;
  float bend_now;
  if (area > 1e-3f * l1 * l2 && glm::dot(normal, hinge_world) >= 0.0f) {
    axis = normal / area;
    bend_now = glm::acos(glm::clamp(glm::dot(upper, lower) / (l1 * l2), -1.0f, 1.0f));
  } else {
    if (glm::dot(hinge_world, hinge_world) < 1e-10f) return false;
    axis = glm::normalize(hinge_world);
    bend_now = glm::atan(glm::dot(normal, axis), glm::dot(upper, lower));
  }
  const float cos_want = (d * d - l1 * l1 - l2 * l2) / (2.0f * l1 * l2);
  const float bend_want = glm::acos(glm::clamp(cos_want, -1.0f, 1.0f));
  r_knee = glm::angleAxis(bend_want - bend_now, axis) * r_knee;
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
THRONG_HOST_DEVICE inline PlantedLegs plant_legs(const BlendSpaceView& v, const CharacterFrame& f, const std::uint32_t* mask) {
  PlantedLegs out;
  if (!v.plant_feet || f.point.w <= 0.0f || f.point.w >= 1.0f) return out;
  const BlendPoint& p = f.point;
  // Per leg, before the IK: target, hip, and the blended world rotations.
  glm::vec3 target[2], hip[2];
  glm::quat hip_parent[2], r_thigh[2], r_knee[2], r_foot[2];
  bool use[2] = {false, false};
  float drop = 0.0f;
  for (int leg = 0; leg < 2; ++leg) {
    const LegChain& chain = v.legs[leg];
    const std::int32_t n = chain.count;
    if (n < 4) continue;
    const std::int32_t thigh = chain.joints[n - 3], knee = chain.joints[n - 2], ankle = chain.joints[n - 1];
    if (!mask_bit(mask, thigh) || !mask_bit(mask, knee) || !mask_bit(mask, ankle)) continue;
    // Ankle and ball in each clip, in the path frame at the canonical phase.
    const glm::vec3 ball_offset(chain.ball[0], chain.ball[1], chain.ball[2]);
    glm::vec3 ankle_target(0.0f), ball_target(0.0f);
    float lift[2] = {0.0f, 0.0f};
    float ground = 0.0f;
    for (int c = 0; c < 2; ++c) {
      const std::int32_t clip = c == 0 ? p.a : p.b;
      const float clip_phase = c == 0 ? f.phases[1 + leg].a : f.phases[1 + leg].b;
      const ClipRows& rows = f.rows[1 + leg][c];
      const ClipInfo& info = v.clips[clip];
      const float ahead = phase_lead(clip_phase, f.phase);
      glm::vec3 pos = clip_root_offset(v, rows);
      pos.z += info.stride * ahead;
      glm::quat rot = clip_rotation(v, rows, chain.joints[0]);
      if (info.turn != 0.0f) rot = yaw_quat(info.turn * ahead) * rot;
      for (std::int32_t i = 1; i < n; ++i) {
        pos += rot * v.offsets[chain.joints[i]];
        rot = rot * clip_rotation(v, rows, chain.joints[i]);
      }
      const float weight = c == 0 ? 1.0f - p.w : p.w;
      ankle_target += weight * pos;
      ball_target += weight * (pos + rot * ball_offset);
      ground += weight * info.ankle_ground[leg];
      lift[c] = pos.y - info.ankle_ground[leg];
    }
    // The blended chain down to the hip.
    glm::vec3 pos = f.root.position;
    glm::quat rot = yaw_quat(f.root.yaw) * joint_rotation(v, f, chain.joints[0]);
    for (std::int32_t i = 1; i + 3 < n; ++i) {
      pos += rot * v.offsets[chain.joints[i]];
      rot = rot * joint_rotation(v, f, chain.joints[i]);
    }
    hip_parent[leg] = rot;
    hip[leg] = pos + rot * v.offsets[thigh];
    r_thigh[leg] = rot * joint_rotation(v, f, thigh);
    r_knee[leg] = r_thigh[leg] * joint_rotation(v, f, knee);
    r_foot[leg] = r_knee[leg] * joint_rotation(v, f, ankle);
    // The pivot: the ankle while the blended heel is down, then the ball.
    glm::vec3 t = ankle_target;
    if (chain.has_ball) {
      const float heel = glm::clamp((ankle_target.y - ground) / kHeelLift, 0.0f, 1.0f);
      t += heel * (ball_target - r_foot[leg] * ball_offset - ankle_target);
    }
    if (v.clips[p.a].stride <= kMinStride && v.clips[p.b].stride > kMinStride) {
      const float ramp = p.w < kLiftRamp ? p.w / kLiftRamp : 1.0f;
      t.y += ramp * (1.0f - p.w) * (lift[1] - lift[0]);
    }
    target[leg] = t;
    use[leg] = true;
    // How far the pelvis must drop for this leg to reach.
    const float reach = kReach * (glm::length(v.offsets[knee]) + glm::length(v.offsets[ankle]));
    const glm::vec3 d = t - hip[leg];
    const float across = d.x * d.x + d.z * d.z;
    if (across < reach * reach) drop = glm::max(drop, -d.y - glm::sqrt(reach * reach - across));
  }
  out.pelvis_drop = glm::min(drop, kMaxPelvisDrop);
  for (int leg = 0; leg < 2; ++leg) {
    if (!use[leg]) continue;
    const LegChain& chain = v.legs[leg];
    const std::int32_t n = chain.count;
    const std::int32_t knee = chain.joints[n - 2], ankle = chain.joints[n - 1];
    const glm::vec3 lowered = hip[leg] - glm::vec3(0.0f, out.pelvis_drop, 0.0f);
    if (!two_bone_ik(lowered, v.offsets[knee], v.offsets[ankle], glm::vec3(chain.hinge[0], chain.hinge[1], chain.hinge[2]),
                     target[leg], r_thigh[leg], r_knee[leg]))
      continue;
    out.active[leg] = true;
    out.corrected[leg][0] = glm::inverse(hip_parent[leg]) * r_thigh[leg];
    out.corrected[leg][1] = glm::inverse(r_thigh[leg]) * r_knee[leg];
    out.corrected[leg][2] = glm::inverse(r_knee[leg]) * r_foot[leg];
  }
  return out;
}

// The synthesised local rotation of a joint: the blend, or the leg IK's.
THRONG_HOST_DEVICE inline glm::quat synthesised_rotation(const BlendSpaceView& v, const CharacterFrame& f, const PlantedLegs& legs,
                                                         std::int32_t joint) {
  for (int leg = 0; leg < 2; ++leg) {
    if (!legs.active[leg]) continue;
    const LegChain& chain = v.legs[leg];
    for (int k = 0; k < 3; ++k)
      if (chain.joints[chain.count - 3 + k] == joint) return legs.corrected[leg][k];
  }
  return joint_rotation(v, f, joint);
}

// World position and rotation of every joint (reference: every joint
// synthesised; the batch stage adds LOD masks and the cache).
THRONG_HOST_DEVICE inline void synthesise_pose(const BlendSpaceView& v, const CharacterFrame& f, glm::vec3* out_positions,
                                               glm::quat* out_rotations) {
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
