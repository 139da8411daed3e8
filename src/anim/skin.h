// Linear blend skinning: v' = sum_k w_k * palette[joint_k] * v. The CPU
// reference (one character, plain loops) and a batch job over many
// characters that runs as a kernel; the renderer does the same in its
// vertex shader from the palette layout documented in docs/streams.md.
#pragma once

#include <cstdint>
#include <glm/gtc/type_precision.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <span>

#include "anim/mannequin.h"
#include "anim/pose.h"
#include "core/config.h"
#include "core/span.h"

namespace throng::anim {

// One vertex, host or device. Normals take the blended linear part and are
// renormalised (exact for rigid palettes away from joints).
THRONG_HOST_DEVICE inline void skin_vertex(const Mat3x4* palette, const glm::vec3& p, const glm::vec3& n,
                                           const glm::u16vec4& joints, const glm::vec4& weights, glm::vec3& out_p,
                                           glm::vec3& out_n) {
  glm::vec3 sp(0.0f), sn(0.0f);
  for (int k = 0; k < 4; ++k) {
    const float w = weights[k];
    if (w == 0.0f) continue;
    const Mat3x4& m = palette[joints[k]];
    sp += w * transform_point(m, p);
    sn += w * transform_vector(m, n);
  }
  const float len = glm::length(sn);
  out_p = sp;
  out_n = len > 0.0f ? sn / len : sn;
}

// The CPU reference: one character's mesh with its palette (mesh.joint_count
// matrices). out_* have mesh.vertex_count() entries; out_normals may be empty.
void skin_reference(const SkinnedMesh& mesh, std::span<const Mat3x4> palette, std::span<glm::vec3> out_positions,
                    std::span<glm::vec3> out_normals);

// Many characters sharing one mesh, each with its palette at
// palettes[palette_offsets[c]]: out[c * V + v]. parallel_for "anim.skin"
// over characters x vertices.
struct SkinJob {
  Span<const glm::vec3> positions;    // V, bind pose
  Span<const glm::vec3> normals;      // V
  Span<const glm::u16vec4> joints;    // V
  Span<const glm::vec4> weights;      // V
  std::int32_t joint_count = 0;       // the mesh's skeleton
  Span<const Mat3x4> palettes;        // every character's palette
  Span<const Index> palette_offsets;  // per character: its first matrix
  Span<glm::vec3> out_positions;      // characters * V
  Span<glm::vec3> out_normals;        // characters * V, or empty

  Index character_count() const { return palette_offsets.size(); }
  void validate() const;  // Error naming the field
  void run() const;
};

}  // namespace throng::anim
