// Shared by the render tests: characters of the default skeleton in its
// rest pose (a T-pose facing +Z) placed on the ground, independent of the
// motion set, so pictures of them stay put while clips evolve.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "core/camera.h"
#include "core/ground.h"
#include "motion/default_set.h"
#include "motion/fk.h"
#include "render/scene.h"

namespace throng::render::testing {

struct TPoseCrowd {
  motion::Skeleton skeleton = motion::default_skeleton();
  std::vector<glm::vec3> positions;
  std::vector<glm::quat> rotations;
  std::vector<std::uint8_t> levels;  // one per character
  std::vector<float> scales;         // one per character
  std::vector<glm::vec3> places;     // `at` of each character
  std::vector<float> yaws;

  // A character standing at world ground point `at`, turned by `yaw` about
  // +Y, scaled by `scale` about `at`: its skinning palette is T(at) R(yaw) S(scale).
  void add(glm::vec3 at, float yaw = 0.0f, std::uint8_t level = 0, float scale = 1.0f) {
    const std::int32_t J = skeleton.joint_count();
    std::vector<glm::quat> local(static_cast<std::size_t>(J), glm::quat(1, 0, 0, 0));
    std::vector<glm::vec3> p(static_cast<std::size_t>(J));
    std::vector<glm::quat> q(static_cast<std::size_t>(J));
    motion::fk_pose(J, skeleton.parents.data(), skeleton.offsets.data(), local.data(), nullptr, skeleton.offsets[0],
                    p.data(), q.data());
    const glm::quat turn = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
    for (std::int32_t j = 0; j < J; ++j) {
      positions.push_back(at + turn * (scale * p[static_cast<std::size_t>(j)]));
      rotations.push_back(turn * q[static_cast<std::size_t>(j)]);
    }
    levels.push_back(level);
    scales.push_back(scale);
    places.push_back(at);
    yaws.push_back(yaw);
  }
  CharacterPoses poses() const {
    CharacterPoses out;
    out.joint_count = skeleton.joint_count();
    out.joint_positions = positions;
    out.joint_rotations = rotations;
    out.lod_levels = levels;
    return out;
  }
  std::int32_t count() const { return static_cast<std::int32_t>(levels.size()); }
};

// A pedestrian's eye (1.7 m) looking down a street into the crowd, 640x360,
// far plane at 60 m: the cull tests' camera, so frustum and distance both cut.
inline Camera street_camera() {
  Camera cam;
  cam.width = 640;
  cam.height = 360;
  cam.position = {0.0f, 1.7f, 0.0f};
  cam.target = {10.0f, 1.0f, -20.0f};
  cam.far_plane = 60.0f;
  return cam;
}

}  // namespace throng::render::testing
