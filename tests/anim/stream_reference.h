// Independent references for the stream tests: forward kinematics with
// double-precision 4x4 matrices, SLERP by the sine formula in double, and
// comparisons of palettes against them.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <memory>
#include <string>
#include <vector>

#include "anim/controller.h"
#include "anim/pose.h"
#include "anim/rig.h"
#include "motion/default_set.h"

namespace throng::anim::testing {

// q0 -> q1 along the shorter arc: (sin((1-t)w) q0 + sin(t w) q1) / sin(w).
inline glm::dquat sine_slerp(glm::dquat q0, glm::dquat q1, double t) {
  double c = q0.w * q1.w + q0.x * q1.x + q0.y * q1.y + q0.z * q1.z;
  if (c < 0.0) {
    q1 = -q1;
    c = -c;
  }
  if (c > 1.0 - 1e-12) return glm::normalize(q0 * (1.0 - t) + q1 * t);
  const double w = std::acos(c);
  const double s = std::sin(w);
  return q0 * (std::sin((1.0 - t) * w) / s) + q1 * (std::sin(t * w) / s);
}

inline glm::dmat4 rigid(const glm::dquat& q, const glm::dvec3& t) {
  return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(q);
}

// Model matrices of every joint: M_j = M_parent * H * T(offset_j) * R(local_j),
// H the hook of j's cluster when j's parent is in another cluster; the root
// at T(world) R(yaw) T(root) R(local_0).
inline std::vector<glm::dmat4> reference_model(const Rig& rig, const std::vector<glm::dquat>& local, glm::dvec3 root,
                                               glm::dvec3 world_pos, double yaw) {
  const auto& s = rig.skeleton;
  const std::size_t J = s.parents.size();
  std::vector<glm::dmat4> M(J);
  const glm::dmat4 world = rigid(glm::angleAxis(yaw, glm::dvec3(0, 1, 0)), world_pos);
  for (std::size_t j = 0; j < J; ++j) {
    const int p = s.parents[j];
    if (p < 0) {
      M[j] = world * rigid(local[j], root);
      continue;
    }
    glm::dmat4 parent = M[static_cast<std::size_t>(p)];
    const auto c = rig.clusters.cluster_of_joint[j];
    if (rig.clusters.cluster_of_joint[static_cast<std::size_t>(p)] != c) {
      const ClusterDef& d = rig.clusters.clusters[c];
      parent = parent * rigid(glm::dquat(d.hook_rotation), glm::dvec3(d.hook_translation));
    }
    M[j] = parent * rigid(local[j], glm::dvec3(s.offsets[j]));
  }
  return M;
}

// Bind matrices by chaining rest offsets (no rotations) from the root offset.
inline std::vector<glm::dmat4> reference_bind(const Rig& rig) {
  const auto& s = rig.skeleton;
  std::vector<glm::dmat4> B(s.parents.size());
  for (std::size_t j = 0; j < B.size(); ++j) {
    const int p = s.parents[j];
    B[j] = p < 0 ? glm::translate(glm::dmat4(1.0), glm::dvec3(s.offsets[0]))
                 : glm::translate(B[static_cast<std::size_t>(p)], glm::dvec3(s.offsets[j]));
  }
  return B;
}

inline std::vector<glm::dmat4> reference_palette(const Rig& rig, const std::vector<glm::dquat>& local, glm::dvec3 root,
                                                 glm::dvec3 world_pos, double yaw) {
  std::vector<glm::dmat4> M = reference_model(rig, local, root, world_pos, yaw);
  const std::vector<glm::dmat4> B = reference_bind(rig);
  for (std::size_t j = 0; j < M.size(); ++j) M[j] = M[j] * glm::inverse(B[j]);
  return M;
}

// Largest absolute difference between a Mat3x4 and the top 3 rows of a 4x4 matrix.
inline double palette_error(const Mat3x4& m, const glm::dmat4& ref) {
  const glm::vec4 rows[3] = {m.r0, m.r1, m.r2};
  double e = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) e = std::max(e, std::abs(static_cast<double>(rows[r][c]) - ref[c][r]));
  return e;
}

inline std::vector<glm::dquat> to_double(const std::vector<glm::quat>& q) {
  return std::vector<glm::dquat>(q.begin(), q.end());
}

// The default humanoid rig and its "walk" clip (one stride at 60 fps).
inline const Rig& humanoid_rig() {
  static const Rig rig = make_rig("humanoid", motion::default_skeleton());
  return rig;
}

inline AnimClip default_clip(const std::string& name, bool loop = true) {
  for (const motion::LocomotionSpec& spec : motion::default_motion_specs())
    if (spec.name == name) {
      AnimClip c;
      c.name = name;
      c.clip =
          std::make_shared<motion::Clip>(motion::LocomotionGenerator(motion::default_skeleton(), spec).make_clip());
      c.loop = loop;
      return c;
    }
  throw std::runtime_error("no default motion " + name);
}

// A rig of another shape than the humanoid: the humanoid with three extra
// joints per hand (fingers), 28 joints, for mixed-skeleton crowds when the
// shared CMU data is absent.
inline motion::Skeleton fingered_skeleton() {
  motion::Skeleton s = motion::default_skeleton();
  for (const char* hand : {"LeftHand", "RightHand"}) {
    const float x = hand[0] == 'L' ? 1.0f : -1.0f;
    int parent = s.find(hand);
    for (int k = 0; k < 3; ++k)
      parent = s.add_joint(std::string(hand) + "Finger" + std::to_string(k), parent, glm::vec3(0.05f * x, 0.0f, 0.0f));
  }
  return s;
}

// A random-looking but deterministic rotation per (joint, frame).
inline glm::quat wiggle(int joint, int frame, float amount = 0.4f) {
  const float a = amount * std::sin(0.37f * static_cast<float>(frame) + 1.3f * static_cast<float>(joint));
  const glm::vec3 axis =
      glm::normalize(glm::vec3(std::sin(static_cast<float>(joint)), 1.0f, std::cos(2.0f * static_cast<float>(joint))));
  return glm::angleAxis(a, axis);
}

// A clip of `frames` frames of wiggles for any joint count.
inline AnimClip wiggle_clip(int joints, int frames, float frame_time, const std::string& name = "wiggle") {
  auto clip = std::make_shared<motion::Clip>();
  clip->resize(frames, joints);
  clip->frame_time = frame_time;
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < joints; ++j) clip->rotation(f, j) = wiggle(j, f);
    clip->root_positions[static_cast<std::size_t>(f)] = glm::vec3(0.01f * f, 0.9f + 0.02f * std::sin(0.5f * f), 0.0f);
  }
  AnimClip c;
  c.name = name;
  c.clip = clip;
  return c;
}

}  // namespace throng::anim::testing
