// Rotations of several joints side by side in lanes (a structure of
// arrays), for the pose's per-joint sampling: each operation is a plain
// loop over the lanes that the host compiler turns into SIMD instructions
// (AVX2: eight floats per instruction). The lane functions are the scalar
// ones (motion/phase.h) lane by lane: the same operations in the same
// order, so the same bits (tested).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>

#include "core/config.h"
#include "motion/phase.h"

namespace throng::motion {

// Up to kQuatLanes lanes, used in whole vectors of kLaneWidth: a pose of
// 22 joints fills three of eight floats. A stage runs over every lane
// before the next stage starts, so the vectors' dependency chains (square
// root, division, polynomial) overlap. A GPU thread keeps one lane (eight
// lanes of each operand would spill its registers to local memory).
#ifdef __CUDA_ARCH__
inline constexpr int kQuatLanes = 1;
inline constexpr int kLaneWidth = 1;
#else
inline constexpr int kQuatLanes = 32;
inline constexpr int kLaneWidth = 8;
#endif
// The lanes that n items take: n rounded up to whole vectors, at most kQuatLanes.
THRONG_HOST_DEVICE inline int lanes_for(int n) {
  const int rounded = (n + kLaneWidth - 1) / kLaneWidth * kLaneWidth;
  return rounded < kQuatLanes ? rounded : kQuatLanes;
}

struct QuatLanes {
  float w[kQuatLanes], x[kQuatLanes], y[kQuatLanes], z[kQuatLanes];
  THRONG_HOST_DEVICE void set(int l, const glm::quat& q) {
    w[l] = q.w;
    x[l] = q.x;
    y[l] = q.y;
    z[l] = q.z;
  }
  THRONG_HOST_DEVICE glm::quat get(int l) const { return glm::quat(w[l], x[l], y[l], z[l]); }
};

// glm::dot's order: (w w' + x x') + (y y' + z z').
THRONG_HOST_DEVICE inline float lane_dot(const QuatLanes& a, const QuatLanes& b, int l) {
  return (a.w[l] * b.w[l] + a.x[l] * b.x[l]) + (a.y[l] * b.y[l] + a.z[l] * b.z[l]);
}

// interpolate_frames in lanes 0 .. n - 1, each lane its own fraction t[l]
// (glm::normalize's division by the length included).
THRONG_HOST_DEVICE inline void interpolate_frames(int n, const QuatLanes& a, const QuatLanes& b, const float* t,
                                                  QuatLanes& out) {
  for (int l = 0; l < n; ++l) {
    const float k = lane_dot(a, b, l) < 0.0f ? -1.0f : 1.0f;
    const float u = t[l];
    const float w = a.w[l] + u * (k * b.w[l] - a.w[l]), x = a.x[l] + u * (k * b.x[l] - a.x[l]);
    const float y = a.y[l] + u * (k * b.y[l] - a.y[l]), z = a.z[l] + u * (k * b.z[l] - a.z[l]);
    const float len = glm::sqrt((w * w + x * x) + (y * y + z * z));
    const bool keep = u <= 0.0f;  // the first frame exactly
    const bool degenerate = len <= 0.0f;
    const float r = 1.0f / len;
    out.w[l] = keep ? a.w[l] : degenerate ? 1.0f : w * r;
    out.x[l] = keep ? a.x[l] : degenerate ? 0.0f : x * r;
    out.y[l] = keep ? a.y[l] : degenerate ? 0.0f : y * r;
    out.z[l] = keep ? a.z[l] : degenerate ? 0.0f : z * r;
  }
}

// SlerpAt's pair in lanes 0 .. n - 1: out = s(a, b), every lane at s's fraction.
THRONG_HOST_DEVICE inline void slerp(int n, const SlerpAt& s, const QuatLanes& a, const QuatLanes& b, QuatLanes& out) {
  if (s.t() <= 0.0f || s.t() >= 1.0f) {
    out = s.t() <= 0.0f ? a : b;
    return;
  }
  for (int l = 0; l < n; ++l) {
    float c = lane_dot(a, b, l);
    const float k = c < 0.0f ? -1.0f : 1.0f;
    c *= k;
    const float y = (c < 1.0f ? c : 1.0f) - 1.0f;
    const float wa = s.weight_a(y), wb = k * s.weight_b(y);
    const float w = wa * a.w[l] + wb * b.w[l], x = wa * a.x[l] + wb * b.x[l];
    const float yy = wa * a.y[l] + wb * b.y[l], z = wa * a.z[l] + wb * b.z[l];
    const float m = 1.5f - 0.5f * ((w * w + x * x) + (yy * yy + z * z));
    out.w[l] = m * w;
    out.x[l] = m * x;
    out.y[l] = m * yy;
    out.z[l] = m * z;
  }
}

}  // namespace throng::motion
