// The renderer's per-character work before drawing, as two stages over
// spans in current_memory():
//   CullJob: which characters the camera can see (bounding sphere against
//            the view frustum) and which of those are near enough, in
//            pixels, for the finer sphere mesh;
//   PackJob: the visible characters' rig points (joints and end sites) in
//            world space, packed slot by slot (fine ones first), each with
//            its LOD level and character id in w, ready for the GPU.
// Between them, exclusive scans of the two flag arrays give every visible
// character its slot (core/reduce.h), so the packing is deterministic.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/camera.h"
#include "core/span.h"
#include "render/scene.h"

namespace throng::render {

// How a visible character is drawn, by the image radius of its bounding
// sphere: near ones with the finer sphere mesh, mid ones with the coarse
// mesh, the smallest (a few pixels tall) as one line per bone.
enum class DrawTier : std::uint8_t { Fine, Coarse, Lines };
inline constexpr int kDrawTiers = 3;

struct CullJob {
  CameraView camera;
  std::int32_t joint_count = 0;
  float bounding_radius = 1.0f;  // about the root joint (JointRig::bounding_radius)
  float fine_min_pixels = 40.0f;  // image radius from which the fine mesh is used
  float lines_max_pixels = 4.0f;  // image radius below which bones are lines
  bool cull = true;  // false: every character is visible
  Span<const glm::vec3> joint_positions;  // characters * joint_count
  // out, kDrawTiers * characters, tier-major: [t * characters + c] is 1
  // when character c is visible and drawn in tier t. One exclusive scan
  // over it gives every visible character its slot, tier after tier.
  Span<std::uint32_t> tier_flags;

  Index character_count() const { return tier_flags.size() / kDrawTiers; }
  void validate() const;  // Error naming the span or parameter
  void run() const;       // parallel_for "render.cull"
};

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
  Span<const std::uint32_t> tier_flags;   // CullJob's
  Span<const std::uint32_t> slots;        // its exclusive scan
  Span<glm::vec4> out_points;             // (visible characters) * points.size()

  Index character_count() const { return tier_flags.size() / kDrawTiers; }
  void validate() const;
  void run() const;  // parallel_for "render.pack"
};

}  // namespace throng::render
