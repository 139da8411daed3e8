// Sampling a cyclic sequence of poses at a normalised phase: the one rule
// that the locomotion synthesis (motion/locomotion.h) and the motion cache
// (anim/motion_cache.h) share. Frame k of a cycle of F frames sits at phase
// k / F; phase 1 wraps back to frame 0 (the last frame is not a copy of the
// first). Sampling by phase, not by frame index, is what keeps cycles of
// different lengths aligned.
#pragma once

#include <cstdint>
#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/config.h"

namespace throng::motion {

// Where a normalised phase (any real number; it wraps) falls in a cycle of
// `frames` frames: between frame f0 and f1 = f0 + 1 (or 0 after the last),
// a fraction t of the way.
struct CyclePoint {
  std::int32_t f0 = 0;
  std::int32_t f1 = 0;
  float t = 0.0f;
};
THRONG_HOST_DEVICE inline CyclePoint cycle_point(std::int32_t frames, float phase) {
  const float x = (phase - glm::floor(phase)) * static_cast<float>(frames);
  CyclePoint p;
  // A phase a hair below 1 can round up to `frames`; NaN and infinities
  // fail the test too. Both read frame 0 (and no float-to-int overflow).
  if (x >= 0.0f && x < static_cast<float>(frames)) {
    p.f0 = static_cast<std::int32_t>(x);
    p.t = x - static_cast<float>(p.f0);
  }
  p.f1 = p.f0 + 1 < frames ? p.f0 + 1 : 0;
  return p;
}

// Wraps a phase into [0, 1).
THRONG_HOST_DEVICE inline float wrap_phase(float phase) {
  const float p = phase - glm::floor(phase);
  return p < 1.0f ? p : 0.0f;  // -tiny - floor(-tiny) rounds to 1
}

// SLERP along the shorter arc at one fraction t, for many pairs (a
// character's joints share their blend weight). Its weights sin((1 - t) h)
// / sin(h) and sin(t h) / sin(h), h the half angle between the pair, are
// series in y = cos(h) - 1: sum_i b_i(t) y^i with b_0 = t and b_i = b_(i-1)
// (t^2 - i^2) / (i (2i + 1)) (D. Eberly, "A fast and accurate algorithm for
// computing SLERP", 2011), cut after y^9 with the last term raised by 1.875
// for the tail it drops. The coefficients depend on t alone, so they are
// computed once; a pair then costs a dot product and two polynomials of
// degree 9 (Estrin's scheme: short dependency chains), with no acos, sine
// or division and no branch on the angle. It turns within 6.2e-6 rad of the
// true SLERP, the worst at h = pi/2 (opposite rotations), far closer for
// the angles between clips (tested against the exponential map). The sum
// is off unit length by about as much, so one Newton step brings it back
// to float rounding. t <= 0 and t >= 1 return a and b exactly.
class SlerpAt {
 public:
  static constexpr int kTerms = 10;
  THRONG_HOST_DEVICE explicit SlerpAt(float t) : t_(t) {
    series(1.0f - t, ca_);
    series(t, cb_);
  }
  // The pair by value: taken by reference, GCC 12 (-O3 -march=native)
  // compiled a pose blended in place, x[j] = blend(x[j], y[j]), into wrong w
  // components (tests/anim/blend_controller_test.cpp, part turns).
  THRONG_HOST_DEVICE glm::quat operator()(const glm::quat a, const glm::quat b) const {
    if (t_ <= 0.0f) return a;
    if (t_ >= 1.0f) return b;
    float c = glm::dot(a, b);
    const float k = c < 0.0f ? -1.0f : 1.0f;
    c *= k;
    const float y = (c < 1.0f ? c : 1.0f) - 1.0f;
    const float wa = weight_a(y), wb = k * weight_b(y);
    const glm::quat q(wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z);
    const float s = 1.5f - 0.5f * glm::dot(q, q);
    return glm::quat(s * q.w, s * q.x, s * q.y, s * q.z);
  }
  THRONG_HOST_DEVICE float t() const { return t_; }
  // The weights of a and b (before the sign of the shorter arc) at y =
  // cos(h) - 1, h the half angle between the pair.
  THRONG_HOST_DEVICE float weight_a(float y) const { return estrin(ca_, y); }
  THRONG_HOST_DEVICE float weight_b(float y) const { return estrin(cb_, y); }

 private:
  // b_i = b_(i-1) (t^2 u_i - v_i) with u_i = 1 / (i (2i + 1)) and v_i = i /
  // (2i + 1): constants, so no division at run time.
  THRONG_HOST_DEVICE static void series(float t, float* out) {
    const float t2 = t * t;
    out[0] = t;
    out[1] = out[0] * (t2 * (1.0f / 3.0f) - 1.0f / 3.0f);
    out[2] = out[1] * (t2 * (1.0f / 10.0f) - 2.0f / 5.0f);
    out[3] = out[2] * (t2 * (1.0f / 21.0f) - 3.0f / 7.0f);
    out[4] = out[3] * (t2 * (1.0f / 36.0f) - 4.0f / 9.0f);
    out[5] = out[4] * (t2 * (1.0f / 55.0f) - 5.0f / 11.0f);
    out[6] = out[5] * (t2 * (1.0f / 78.0f) - 6.0f / 13.0f);
    out[7] = out[6] * (t2 * (1.0f / 105.0f) - 7.0f / 15.0f);
    out[8] = out[7] * (t2 * (1.0f / 136.0f) - 8.0f / 17.0f);
    out[9] = out[8] * (t2 * (1.0f / 171.0f) - 9.0f / 19.0f) * 1.875f;  // the tail
  }
  THRONG_HOST_DEVICE static float estrin(const float* c, float y) {
    const float y2 = y * y, y4 = y2 * y2;
    const float p01 = c[0] + c[1] * y, p23 = c[2] + c[3] * y, p45 = c[4] + c[5] * y, p67 = c[6] + c[7] * y;
    const float p89 = c[8] + c[9] * y;
    return (p01 + p23 * y2) + (p45 + p67 * y2) * y4 + p89 * (y4 * y4);
  }
  float t_;
  float ca_[kTerms], cb_[kTerms];
};
THRONG_HOST_DEVICE inline glm::quat slerp_shortest(const glm::quat& a, const glm::quat& b, float t) {
  return SlerpAt(t)(a, b);
}

// Between two neighbouring frames of a cycle (a few degrees apart)
// normalised lerp on the shorter arc is SLERP to within 0.01 degrees (the
// error grows with the cube of the angle; tested on every frame pair of the
// default clips, up to 18 degrees apart) at a fraction of its cost; the
// blend between clips, whose poses differ by far more, uses SlerpAt.
THRONG_HOST_DEVICE inline glm::quat interpolate_frames(const glm::quat& a, const glm::quat& b, float t) {
  if (t <= 0.0f) return a;
  const float k = glm::dot(a, b) < 0.0f ? -1.0f : 1.0f;
  return glm::normalize(glm::quat(a.w + t * (k * b.w - a.w), a.x + t * (k * b.x - a.x), a.y + t * (k * b.y - a.y),
                                  a.z + t * (k * b.z - a.z)));
}

// Local rotations at a normalised phase by SLERP between the two
// neighbouring frames of frame-major rotations[frame * joints + joint].
THRONG_HOST_DEVICE inline void sample_cycle(const glm::quat* rotations, std::int32_t frames, std::int32_t joints,
                                            float phase, glm::quat* out) {
  const CyclePoint p = cycle_point(frames, phase);
  const glm::quat* a = rotations + static_cast<Index>(p.f0) * joints;
  const glm::quat* b = rotations + static_cast<Index>(p.f1) * joints;
  const SlerpAt between(p.t);
  for (std::int32_t j = 0; j < joints; ++j) out[j] = between(a[j], b[j]);
}

}  // namespace throng::motion
