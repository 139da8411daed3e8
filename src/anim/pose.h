// Pose data shared by streams, controllers and skinning: a pose of local
// joint rotations plus a root position, and the 3x4 matrices of a skinning
// palette.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <vector>

#include "core/config.h"

namespace throng::anim {

// One pose of a skeleton: the rotation of every joint relative to its parent
// (motion::Clip's convention) and the root's position in model space.
struct Pose {
  std::vector<glm::quat> local;
  glm::vec3 root{0.0f};

  Pose() = default;
  explicit Pose(std::int32_t joints) : local(static_cast<std::size_t>(joints), glm::quat(1.0f, 0.0f, 0.0f, 0.0f)) {}
  std::int32_t joint_count() const { return static_cast<std::int32_t>(local.size()); }
};

// An affine transform as three rows [R | t] (48 bytes): what a skinning
// palette holds per joint, and what a vertex shader reads as three vec4.
// p' = (dot(r0, p1), dot(r1, p1), dot(r2, p1)) with p1 = (p, 1).
struct Mat3x4 {
  glm::vec4 r0{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec4 r1{0.0f, 1.0f, 0.0f, 0.0f};
  glm::vec4 r2{0.0f, 0.0f, 1.0f, 0.0f};
};

// Rotation q then translation t.
THRONG_HOST_DEVICE inline Mat3x4 mat3x4_from(const glm::quat& q, const glm::vec3& t) {
  const float xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const float xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const float wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  Mat3x4 m;
  m.r0 = glm::vec4(1.0f - 2.0f * (yy + zz), 2.0f * (xy - wz), 2.0f * (xz + wy), t.x);
  m.r1 = glm::vec4(2.0f * (xy + wz), 1.0f - 2.0f * (xx + zz), 2.0f * (yz - wx), t.y);
  m.r2 = glm::vec4(2.0f * (xz - wy), 2.0f * (yz + wx), 1.0f - 2.0f * (xx + yy), t.z);
  return m;
}

THRONG_HOST_DEVICE inline glm::vec3 transform_point(const Mat3x4& m, const glm::vec3& p) {
  const glm::vec4 p1(p, 1.0f);
  return glm::vec3(glm::dot(m.r0, p1), glm::dot(m.r1, p1), glm::dot(m.r2, p1));
}

THRONG_HOST_DEVICE inline glm::vec3 transform_vector(const Mat3x4& m, const glm::vec3& v) {
  const glm::vec4 v0(v, 0.0f);
  return glm::vec3(glm::dot(m.r0, v0), glm::dot(m.r1, v0), glm::dot(m.r2, v0));
}

// a * b as affine maps (b first).
THRONG_HOST_DEVICE inline glm::vec4 row_times(const glm::vec4& x, const Mat3x4& b) {
  return glm::vec4(x.x * b.r0.x + x.y * b.r1.x + x.z * b.r2.x, x.x * b.r0.y + x.y * b.r1.y + x.z * b.r2.y,
                   x.x * b.r0.z + x.y * b.r1.z + x.z * b.r2.z, x.x * b.r0.w + x.y * b.r1.w + x.z * b.r2.w + x.w);
}
THRONG_HOST_DEVICE inline Mat3x4 operator*(const Mat3x4& a, const Mat3x4& b) {
  Mat3x4 m;
  m.r0 = row_times(a.r0, b);
  m.r1 = row_times(a.r1, b);
  m.r2 = row_times(a.r2, b);
  return m;
}

// The inverse of a rigid transform (rotation q, translation t).
THRONG_HOST_DEVICE inline Mat3x4 inverse_rigid(const glm::quat& q, const glm::vec3& t) {
  const glm::quat qi = glm::conjugate(q);
  return mat3x4_from(qi, -(qi * t));
}

// The inverse of a rigid Mat3x4 (orthonormal rotation part): [R^T | -R^T t].
THRONG_HOST_DEVICE inline Mat3x4 inverse_rigid(const Mat3x4& m) {
  const glm::vec3 t(m.r0.w, m.r1.w, m.r2.w);
  Mat3x4 out;
  out.r0 = glm::vec4(m.r0.x, m.r1.x, m.r2.x, 0.0f);
  out.r1 = glm::vec4(m.r0.y, m.r1.y, m.r2.y, 0.0f);
  out.r2 = glm::vec4(m.r0.z, m.r1.z, m.r2.z, 0.0f);
  const glm::vec3 it = -transform_vector(out, t);
  out.r0.w = it.x;
  out.r1.w = it.y;
  out.r2.w = it.z;
  return out;
}

// Every vertex skinned by it collapses onto point p: how a culled cluster's
// joints are written, so its triangles vanish without a separate draw call.
THRONG_HOST_DEVICE inline Mat3x4 collapse_to(const glm::vec3& p) {
  Mat3x4 m;
  m.r0 = glm::vec4(0.0f, 0.0f, 0.0f, p.x);
  m.r1 = glm::vec4(0.0f, 0.0f, 0.0f, p.y);
  m.r2 = glm::vec4(0.0f, 0.0f, 0.0f, p.z);
  return m;
}

}  // namespace throng::anim
