// Per-frame sampling of a blend space (host and device), reading only a
// BlendSpaceView (motion/blend_space.h): speed -> blend point (two
// neighbouring clips and the weight of the second), each clip's phase under
// the foot-event warps, texture rows, the clips' joint rotations and root
// offsets, their blends, and the blended stride, turn and cycle rate.
#pragma once

#include <cstdint>
#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/config.h"
#include "motion/blend_space.h"
#include "motion/motion_texture.h"
#include "motion/phase.h"

namespace throng::motion {

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
THRONG_HOST_DEVICE inline glm::quat clip_rotation(const BlendSpaceView& v, std::int32_t clip, float clip_phase,
                                                  std::int32_t joint) {
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
THRONG_HOST_DEVICE inline glm::quat blended_rotation(const BlendSpaceView& v, float w, const ClipRows& a,
                                                     const ClipRows& b, std::int32_t joint) {
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

}  // namespace throng::motion
