// What the renderer draws, as plain data: the renderer does not care who
// produced the pose (forward kinematics of a clip, locomotion synthesis,
// animation streams), only that it gets world-space joint frames.
//
//   JointRig rig = make_joint_rig(skeleton);     // once per skeleton
//   CharacterPoses poses;                        // every frame
//   poses.joint_count = rig.joint_count;
//   poses.joint_positions = ...;  poses.joint_rotations = ...;  poses.lod_levels = ...;
//   renderer.render(camera, poses, options);
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "anim/lod_spheres.h"
#include "core/span.h"
#include "motion/skeleton.h"

namespace throng::render {

enum class RenderMode : std::uint8_t {
  Joints,   // one squashed sphere per bone, as in the 2019 paper
  Skinned,  // the mannequin skinned in the vertex shader (not built yet)
};
const char* to_string(RenderMode m);
// "joints" | "skinned"; throws Error naming `field` otherwise.
RenderMode parse_render_mode(const std::string& text, const std::string& field);

// A point the joint mode draws between: a joint, or a leaf's end site
// (joint frame * offset, the head top, finger and toe tips).
struct RigPoint {
  std::int32_t joint = 0;
  glm::vec3 offset{0.0f};  // in the joint's frame; zero for the joint itself
  std::uint8_t part = 0;   // anim::BodyPart whose LOD level colours it
};

// One ellipsoid: centred between two points, its long axis along the bone,
// round in cross-section. from == to draws a sphere of `radius`.
struct RigBone {
  std::int32_t from = 0;  // into JointRig::points
  std::int32_t to = 0;
  float radius = 0.05f;   // semi-axis across the bone, metres
};

struct JointRig {
  std::int32_t joint_count = 0;
  std::vector<RigPoint> points;  // the first joint_count are the joints, in order
  std::vector<RigBone> bones;
  // Radius of a sphere about the root joint that holds the whole character
  // in any pose (the longest bone path from the root plus the thickest
  // bone): what culling tests.
  float bounding_radius = 1.0f;

  std::int32_t point_count() const { return static_cast<std::int32_t>(points.size()); }
  std::int32_t bone_count() const { return static_cast<std::int32_t>(bones.size()); }
  // Throws Error naming the field ("rig.bones[3].to") when out of range.
  void validate() const;
};

// The rig of any skeleton: a bone from every joint to its parent, one to
// every end site, a sphere at the root. Thickness follows bone length and
// the torso is stouter; body parts come from anim::make_body_parts when the
// skeleton's roles allow, else everything is torso.
JointRig make_joint_rig(const motion::Skeleton& skeleton);

// Per-frame pose of N characters, world space, in current_memory().
struct CharacterPoses {
  std::int32_t joint_count = 0;
  Span<const glm::vec3> joint_positions;  // characters * joint_count, character-major
  Span<const glm::quat> joint_rotations;  // characters * joint_count (end sites hang off them)
  // Joint-LOD levels, 0 = finest: empty (all 0), one per character, or one
  // per character and body part (characters * 5, as anim::LodJob writes).
  Span<const std::uint8_t> lod_levels;

  Index character_count() const { return joint_count > 0 ? joint_positions.size() / joint_count : 0; }
  // Throws Error naming the span whose size disagrees.
  void validate(const JointRig& rig) const;
};

// Obstacles of the simulation's map (x, y metres, z up), drawn extruded.
struct ObstacleStyle {
  float height = 1.2f;  // metres
  std::int32_t circle_segments = 40;
};

// A count per ground cell (e.g. agents per simulation bin) drawn as a heat
// map: cells along map x then y, origin at the map-space corner `min`.
struct BinsOverlay {
  glm::vec2 min{0.0f};
  float cell_size = 1.0f;
  std::int32_t columns = 0;
  std::int32_t rows = 0;
  Span<const std::int32_t> counts;  // columns * rows, row-major (y outer)
  std::int32_t saturate_at = 8;     // count drawn in the hottest colour
  void validate() const;
};

// A polyline on the map (a planned path), drawn just above the ground.
using MapPolyline = std::vector<glm::vec2>;

}  // namespace throng::render
