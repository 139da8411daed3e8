// What the renderer draws, as plain data: the renderer does not care who
// produced the pose (forward kinematics of a clip, locomotion synthesis,
// animation streams), only that it gets world-space joint frames or
// skinning palettes.
//
//   CrowdRigs rigs = make_crowd_rigs(skeleton);  // once: joint rig + mannequin
//   CharacterPoses poses = poses_of(animator);   // every frame (or fill the spans)
//   renderer.render(camera, poses, options);
#pragma once

#include <array>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "anim/lod_spheres.h"
#include "anim/mannequin.h"
#include "anim/palette_ref.h"
#include "anim/pose.h"
#include "core/span.h"
#include "motion/skeleton.h"

namespace throng::anim {
class CrowdAnimator;
class LocomotionStreams;
class StreamCrowd;
struct Rig;
}  // namespace throng::anim
namespace throng::sim {
struct CrowdState;
}  // namespace throng::sim

namespace throng::render {

enum class RenderMode : std::uint8_t {
  Joints,   // one squashed sphere per bone, as in the 2019 paper
  Skinned,  // a mesh (the mannequin) skinned in the vertex shader
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
  float radius = 0.05f;  // semi-axis across the bone, metres
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

// Draw tiers by image size: near characters get the finest mesh, the
// smallest (a few pixels tall) are drawn as lines (render/cull.h).
inline constexpr int kDrawTiers = 3;

// What skinned mode draws for one rig (an anim::Rig: a skeleton and the mesh
// bound to it): a mesh per draw tier, all bound to the same joints.
struct SkinRig {
  std::string name;
  std::int32_t joint_count = 0;
  // Fine and coarse: triangle meshes; far: line segments (two indices a
  // line), drawn with GL_LINES through the same skinning.
  std::array<anim::SkinnedMesh, kDrawTiers> meshes;
  // What each vertex is coloured by, per mesh and vertex: its body part
  // (anim::BodyPart, for LOD colours) and its material (kSkin, kShirt, kTrousers).
  std::array<std::vector<std::uint8_t>, kDrawTiers> parts, materials;
  std::vector<anim::Mat3x4> inverse_bind;  // per joint: skinning from world joint frames
  std::vector<glm::vec3> bind_positions;   // per joint, model space
  // A sphere about the root joint that holds every vertex in any pose (the
  // longest bone chain to a vertex's joint plus the vertex's distance from
  // it, over all influences), for culling; times the character's scale.
  float bounding_radius = 1.0f;

  // Throws Error naming the field ("skin.meshes[2].joints").
  void validate() const;
};
inline constexpr std::uint8_t kShirt = 0, kTrousers = 1, kSkin = 2;

// The rig's own mesh (fine) and two generated mannequins of the skeleton,
// coarser (6 sides, 1-ring caps) and far (a line per bone).
SkinRig make_skin_rig(const anim::Rig& rig);

// Everything the renderer can draw a crowd with. Joint mode needs `joints`
// (a skeleton's rig); skinned mode one SkinRig per rig index of the poses.
struct CrowdRigs {
  JointRig joints;  // joint_count 0: joint mode unavailable
  std::vector<SkinRig> skins;
};
// The joint rig and the mannequin of one skeleton (anim::make_rig).
CrowdRigs make_crowd_rigs(const motion::Skeleton& skeleton);
// The skin rigs of every rig of a stream crowd, in its rig order.
CrowdRigs make_crowd_rigs(const anim::StreamCrowd& crowd);

// Per-frame pose of N characters, world space, in current_memory(). Either
// world joint frames (joint mode and skinned mode; the locomotion stage's
// output) or skinning palettes (skinned mode only; the animation streams'
// output).
struct CharacterPoses {
  std::int32_t joint_count = 0;
  // World joint frames, character-major [c * joint_count + j].
  Span<const glm::vec3> joint_positions;  // characters * joint_count
  Span<const glm::quat> joint_rotations;  // characters * joint_count (end sites hang off them)
  Span<const float> scales;               // per character (skinning from frames); empty = 1
  // Or palettes, as anim::StreamCrowd::resolve writes them: character c's
  // joint j is palettes[palette_offsets[c] + j] = world * model_j *
  // inverse_bind_j, its rig rigs[c] (empty = all rig 0), joint_count = 0.
  Span<const anim::Mat3x4> palettes;
  Span<const Index> palette_offsets;
  Span<const std::int32_t> rigs;
  // Or palette references (skinned mode only; locomotion through streams):
  // character c's joint j is anim::compose_palette(palette_refs[c],
  // root_transform(root_positions[c], root_yaws[c]), j), rig 0, joint_count 0.
  Span<const anim::PaletteRef> palette_refs;
  Span<const glm::vec3> root_positions;  // world, on the ground
  Span<const float> root_yaws;
  // Joint-LOD levels, 0 = finest: empty (all 0), one per character, or one
  // per character and body part (characters * 5, as anim::LodJob writes).
  Span<const std::uint8_t> lod_levels;
  // Which characters are drawn: those whose flags hold every bit of
  // visible_bits (the simulation's flags and kAgentActive: despawned agents
  // vanish); empty = all.
  Span<const std::uint8_t> flags;
  std::uint8_t visible_bits = 0;

  bool from_palettes() const { return joint_positions.empty() && (!palette_offsets.empty() || from_refs()); }
  bool from_refs() const { return !palette_refs.empty(); }
  Index character_count() const {
    if (joint_count > 0) return joint_positions.size() / joint_count;
    return from_refs() ? palette_refs.size() : palette_offsets.size();
  }
  // Throws Error naming the span whose size disagrees with the rigs.
  void validate(const CrowdRigs& rigs, RenderMode mode) const;
};

// The locomotion stage's output: world joint frames, scales, LOD levels.
CharacterPoses poses_of(const anim::CrowdAnimator& crowd);
// The same for the simulation's agents: despawned ones are not drawn.
CharacterPoses poses_of(const anim::CrowdAnimator& crowd, const sim::CrowdState& agents);
// A stream crowd's palettes (resolved with world positions and yaws).
CharacterPoses poses_of(const anim::StreamCrowd& crowd, Span<const anim::Mat3x4> palettes);
// Locomotion through streams: palette references and root transforms; for
// the simulation's agents, despawned ones are not drawn.
CharacterPoses poses_of(const anim::LocomotionStreams& streams, const sim::CrowdState& agents);

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
