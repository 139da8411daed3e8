// A skinned triangle mesh, and the default one: a mannequin generated from
// any skeleton (a capsule per bone, smooth weights at the joints), so that
// crowds can be skinned and drawn without external assets.
#pragma once

#include <cstdint>
#include <glm/gtc/type_precision.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <vector>

#include "motion/skeleton.h"

namespace throng::anim {

// Vertices in the skeleton's bind pose (model space, metres), up to four
// joint influences each. Triangles wind counter-clockwise seen from outside.
struct SkinnedMesh {
  std::int32_t joint_count = 0;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;      // unit
  std::vector<glm::u16vec4> joints;    // influencing joints
  std::vector<glm::vec4> weights;      // matching weights, >= 0, summing to 1
  std::vector<std::uint32_t> indices;  // 3 per triangle

  std::int32_t vertex_count() const { return static_cast<std::int32_t>(positions.size()); }
  std::int32_t triangle_count() const { return static_cast<std::int32_t>(indices.size() / 3); }
  // Throws Error naming the field: array lengths, joint indices out of
  // range, weights negative, non-finite or not summing to 1 (1e-4), indices
  // out of range or not a multiple of 3.
  void validate() const;
};

struct MannequinOptions {
  std::int32_t sides = 12;      // vertices around each capsule
  std::int32_t body_rings = 5;  // rings along the straight part (>= 2)
  std::int32_t cap_rings = 3;   // rings per hemispherical cap (>= 1)
  float blend = 0.3f;           // fraction of a bone, at each end, blended with the neighbouring bone
  float min_bone = 0.02f;       // bones shorter than this (x height / 1.75 m) get no capsule
  void validate() const;        // Error naming "mannequin.<field>"
};

// One capsule per bone (parent joint to child joint, and joint to end site)
// in the rest pose of the skeleton (identity local rotations, root at its
// offset). Radii follow the joint roles (torso, thigh, shank, arm, head...)
// scaled by the skeleton's rest height / 1.75 m; bones of joints without a
// role get a radius from their length. A capsule follows the joint that
// rotates its bone; over `blend` of its length at each end its weight goes
// smoothly to 1/2 shared with the neighbouring bone's joint, so the joints
// bend without cracks. Works for any skeleton; roles only improve the shape.
SkinnedMesh make_mannequin(const motion::Skeleton& skeleton, const MannequinOptions& options = {});

}  // namespace throng::anim
