// The renderer's per-character work before drawing, as stages over spans in
// current_memory():
//   CullJob:        which characters the camera can see (bounding sphere
//                   against the view frustum) and in which draw group: the
//                   rig, and the tier by image size (fine mesh, coarse mesh,
//                   lines);
//   PackJob:        joint mode: the visible characters' rig points (joints
//                   and end sites) in world space, slot by slot, each with
//                   its LOD level and character id in w;
//   PalettePackJob: skinned mode: the visible characters' skinning palettes
//                   slot by slot (copied from given palettes, or made from
//                   world joint frames times inverse bind matrices), and a
//                   tag per slot (character id, LOD level of each part).
// Between them, one exclusive scan of the group flags gives every visible
// character its slot, group after group (core/reduce.h), so the packing is
// deterministic.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "anim/palette_ref.h"
#include "anim/pose.h"
#include "core/camera.h"
#include "core/span.h"
#include "render/scene.h"

namespace throng::render {

// How a visible character is drawn, by the image radius of its bounding
// sphere: near ones with the finest mesh, mid ones with the coarse mesh, the
// smallest (a few pixels tall) as one line per bone.
enum class DrawTier : std::uint8_t { Fine, Coarse, Lines };

// Rigs one frame may draw with (skinned mode: a crowd's rigs).
inline constexpr int kMaxRenderRigs = 8;
inline constexpr int kMaxDrawGroups = kMaxRenderRigs * kDrawTiers;

// What culling needs of a rig, passed by value to the kernel.
struct CullRig {
  float bounding_radius = 1.0f;  // about the root joint, scale 1
  glm::vec3 root_bind{0.0f};     // the root joint's bind position: palettes give the root as palette * root_bind
  std::int32_t joint_count = 0;  // palette matrices per character of this rig
};
struct CullRigs {
  CullRig rig[kMaxRenderRigs];
  std::int32_t count = 1;
};

struct CullJob {
  CameraView camera;
  CullRigs rigs;                  // joint frames: one
  float fine_min_pixels = 40.0f;  // image radius from which the fine mesh is used
  float lines_max_pixels = 4.0f;  // image radius below which bones are lines
  bool cull = true;               // false: every character is visible
  std::int32_t force_tier = -1;   // >= 0: every visible character in this tier (DrawTier)
  // Where the characters are: world joint frames (the root is joint 0;
  // scales per character, empty = 1) ...
  std::int32_t joint_count = 0;
  Span<const glm::vec3> joint_positions;  // characters * joint_count
  Span<const float> scales;
  // ... or palettes (joint_count 0): the root is palettes[palette_offsets[c]]
  // * root_bind of the character's rig (character_rigs[c], empty = 0), the
  // scale the length of that matrix's first column. A character whose rig
  // or palette is out of range is not drawn.
  Span<const anim::Mat3x4> palettes;
  Span<const Index> palette_offsets;
  Span<const std::int32_t> character_rigs;
  // ... or palette references (palette_refs not empty, rig 0): the root is
  // root_positions[c] + its yaw times root_bind, scale 1.
  Span<const anim::PaletteRef> palette_refs;
  Span<const glm::vec3> root_positions;
  Span<const float> root_yaws;
  // Characters whose flags lack a bit of visible_bits are not drawn; empty = all.
  Span<const std::uint8_t> flags;
  std::uint8_t visible_bits = 0;
  // out, rigs.count * kDrawTiers * characters, group-major: [g * characters
  // + c] is 1 when character c is visible and drawn in group g = rig *
  // kDrawTiers + tier. One exclusive scan over it gives every visible
  // character its slot, group after group.
  Span<std::uint32_t> group_flags;

  std::int32_t group_count() const { return rigs.count * kDrawTiers; }
  Index character_count() const {
    if (joint_count > 0) return joint_positions.size() / joint_count;
    return palette_refs.empty() ? palette_offsets.size() : palette_refs.size();
  }
  void validate() const;  // Error naming the span or parameter
  void run() const;       // parallel_for "render.cull"
};

// Where each draw group's slots and palette matrices start, after the scan
// (host values captured by the packing kernels).
struct DrawGroups {
  std::int32_t count = 0;
  Index first_slot[kMaxDrawGroups] = {};
  Index slots[kMaxDrawGroups] = {};
  Index first_matrix[kMaxDrawGroups] = {};   // PalettePackJob: slots of earlier groups times their joint counts
  std::int32_t joints[kMaxDrawGroups] = {};  // per slot of the group
  Index visible() const { return count > 0 ? first_slot[count - 1] + slots[count - 1] : 0; }
  Index matrices() const { return count > 0 ? first_matrix[count - 1] + slots[count - 1] * joints[count - 1] : 0; }
};

// slots[i] = group_flags[0] + ... + group_flags[i-1] (the "render.slots"
// scan, deterministic); returns the total, the visible characters. Lives in
// cull_kernels.cpp so that CUDA builds compile the scan for the device.
Index scan_draw_slots(Span<const std::uint32_t> group_flags, Span<std::uint32_t> slots);

// The groups of a CullJob that ran, from the exclusive scan of its flags
// (`visible`: the scan's total).
DrawGroups draw_groups(const CullJob& job, Span<const std::uint32_t> slots, Index visible);

// The slot of character c (or -1) and its group, from the flags and their scan.
THRONG_HOST_DEVICE inline Index slot_of(Span<const std::uint32_t> flags, Span<const std::uint32_t> slots, Index n,
                                        std::int32_t groups, Index c, std::int32_t& group) {
  for (std::int32_t g = 0; g < groups; ++g)
    if (flags[g * n + c] != 0u) {
      group = g;
      return slots[g * n + c];
    }
  group = -1;
  return -1;
}

// The w of a packed point: LOD level (0..15) + 16 * (character id mod 2^16),
// exact in a float.
THRONG_HOST_DEVICE inline float pack_point_tag(std::int32_t level, Index character) {
  return static_cast<float>((level & 15) + 16 * static_cast<std::int32_t>(character & 0xffff));
}

struct PackJob {
  std::int32_t joint_count = 0;
  Span<const RigPoint> points;            // JointRig::points
  Span<const glm::vec3> joint_positions;  // characters * joint_count, world
  Span<const glm::quat> joint_rotations;  // characters * joint_count, world
  Span<const std::uint8_t> lod_levels;    // empty, characters, or characters * 5
  Span<const std::uint32_t> group_flags;  // CullJob's, one rig: kDrawTiers groups
  Span<const std::uint32_t> slots;        // its exclusive scan
  Span<glm::vec4> out_points;             // (visible characters) * points.size()

  Index character_count() const { return group_flags.size() / kDrawTiers; }
  void validate() const;
  void run() const;  // parallel_for "render.pack"
};

// A slot's tag: x = character id, y = LOD level of each body part, 4 bits
// a part (part p at bits 4p..4p+3).
THRONG_HOST_DEVICE inline glm::uvec2 slot_tag(Index character, Span<const std::uint8_t> levels, Index n) {
  std::uint32_t packed = 0;
  if (!levels.empty()) {
    const Index stride = levels.size() / n;
    for (std::uint32_t p = 0; p < static_cast<std::uint32_t>(anim::kBodyPartCount); ++p) {
      const std::uint32_t level = stride == 1 ? levels[character] : levels[character * stride + p];
      packed |= (level & 15u) << (4u * p);
    }
  }
  return glm::uvec2(static_cast<std::uint32_t>(character), packed);
}

struct PalettePackJob {
  // World joint frames of one rig (joint_count > 0), its inverse bind
  // matrices and the characters' scales (empty = 1): palette_j = T(p_j)
  // R(q_j) S(s) * inverse_bind_j ...
  std::int32_t joint_count = 0;
  Span<const glm::vec3> joint_positions;
  Span<const glm::quat> joint_rotations;
  Span<const float> scales;
  Span<const anim::Mat3x4> inverse_bind;
  // ... or palettes to copy (joint_count 0) ...
  Span<const anim::Mat3x4> palettes;
  Span<const Index> palette_offsets;
  // ... or palette references to compose (anim::compose_palette).
  Span<const anim::PaletteRef> palette_refs;
  Span<const glm::vec3> root_positions;
  Span<const float> root_yaws;
  Span<const std::uint8_t> lod_levels;  // empty, characters, or characters * 5
  Span<const std::uint32_t> group_flags;
  Span<const std::uint32_t> slots;
  DrawGroups groups;
  Span<anim::Mat3x4> out_palettes;  // groups.matrices()
  Span<glm::uvec2> out_tags;        // groups.visible()

  Index character_count() const { return groups.count > 0 ? group_flags.size() / groups.count : 0; }
  void validate() const;
  void run() const;  // parallel_for "render.pack_palettes"
};

}  // namespace throng::render
