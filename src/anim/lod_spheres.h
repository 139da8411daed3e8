// The five body parts of the 2019 joint-LOD method and their bounding spheres.
//
// Every joint belongs to exactly one part: the subtree of each upper arm
// (left/right arm), of each thigh (left/right leg), and everything else
// (torso: hips, spine, clavicles, neck, head). Each part has one sphere,
// centred at the elbow, the knee, or mid-spine (halfway between hips and
// neck), whose radius bounds the part's joints and end sites in EVERY pose:
// the distance from a joint to another along rigid bones is at most the sum
// of the bone lengths on the tree path between them, whatever the rotations.
// So the sphere needs no per-frame refit; only its centre moves.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <vector>

#include "core/config.h"
#include "motion/skeleton.h"

namespace throng::anim {

enum class BodyPart : std::uint8_t { LeftArm, RightArm, Torso, LeftLeg, RightLeg };
inline constexpr int kBodyPartCount = 5;
inline constexpr std::array<BodyPart, kBodyPartCount> kAllBodyParts = {
    BodyPart::LeftArm, BodyPart::RightArm, BodyPart::Torso, BodyPart::LeftLeg, BodyPart::RightLeg};
const char* to_string(BodyPart p);  // "left_arm", "torso", ...

// A sphere centre in the current pose: mix(position[joint_a], position[joint_b], t).
struct SphereAnchor {
  std::int32_t joint_a = 0;
  std::int32_t joint_b = 0;
  float t = 0.0f;
  float radius = 0.0f;  // metres, for a character of scale 1
};

THRONG_HOST_DEVICE inline glm::vec3 anchor_centre(const SphereAnchor& a, const glm::vec3* joint_positions) {
  const glm::vec3 pa = joint_positions[a.joint_a];
  const glm::vec3 pb = joint_positions[a.joint_b];
  return pa + (pb - pa) * a.t;
}

struct BodyParts {
  std::int32_t joint_count = 0;
  std::array<SphereAnchor, kBodyPartCount> anchors{};
  std::array<std::int32_t, kBodyPartCount> part_root{};          // upper arm, skeleton root, thigh
  std::vector<std::uint8_t> part_of;                             // per joint: its BodyPart
  std::array<std::vector<std::int32_t>, kBodyPartCount> joints;  // per part, ascending
  std::vector<std::int32_t> depth;                               // per joint: bones between it and its part's root
  // Spheres in the rest pose in model space: origin on the ground under the
  // hips (the lowest rest joint or end site at y = 0), xyz centre, w radius.
  std::array<glm::vec4, kBodyPartCount> rest_spheres{};

  const std::vector<std::int32_t>& joints_of(BodyPart p) const { return joints[static_cast<std::size_t>(p)]; }
  const SphereAnchor& anchor(BodyPart p) const { return anchors[static_cast<std::size_t>(p)]; }
};

// Parts, anchors and radii from a skeleton whose roles are assigned
// (motion::assign_roles). Needs both elbows and knees and a neck or head;
// the upper arm and thigh default to the elbow's and knee's parents. Throws
// Error naming the missing role ("roles.left_elbow") or a bad hierarchy.
BodyParts make_body_parts(const motion::Skeleton& skeleton);

// Length of the tree path between two joints: the sum of the rest offsets
// (bone lengths) on the way, the root's own offset excluded.
float bone_path_length(const motion::Skeleton& skeleton, std::int32_t a, std::int32_t b);

}  // namespace throng::anim
