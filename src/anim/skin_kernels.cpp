#include <string>

#include "anim/skin.h"
#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"

namespace throng::anim {

void skin_reference(const SkinnedMesh& mesh, std::span<const Mat3x4> palette, std::span<glm::vec3> out_positions,
                    std::span<glm::vec3> out_normals) {
  const auto V = static_cast<std::size_t>(mesh.vertex_count());
  if (palette.size() != static_cast<std::size_t>(mesh.joint_count))
    throw Error("has " + std::to_string(palette.size()) + " matrices, the mesh has " + std::to_string(mesh.joint_count) + " joints",
                at_field("skin.palette"));
  if (out_positions.size() != V) throw Error("must have one entry per vertex", at_field("skin.out_positions"));
  if (!out_normals.empty() && out_normals.size() != V) throw Error("must be empty or have one entry per vertex", at_field("skin.out_normals"));
  for (std::size_t v = 0; v < V; ++v) {
    glm::vec3 p, n;
    skin_vertex(palette.data(), mesh.positions[v], mesh.normals[v], mesh.joints[v], mesh.weights[v], p, n);
    out_positions[v] = p;
    if (!out_normals.empty()) out_normals[v] = n;
  }
}

void SkinJob::validate() const {
  const Index V = positions.size();
  if (joint_count <= 0) throw Error("must be positive", at_field("SkinJob.joint_count"));
  check_length("SkinJob", "normals", normals.size(), V);
  check_length("SkinJob", "joints", joints.size(), V);
  check_length("SkinJob", "weights", weights.size(), V);
  check_length("SkinJob", "out_positions", out_positions.size(), V * character_count());
  if (!out_normals.empty()) check_length("SkinJob", "out_normals", out_normals.size(), V * character_count());
}

void SkinJob::run() const {
  validate();
  const Index V = positions.size();
  const auto P = positions;
  const auto N = normals;
  const auto Jn = joints;
  const auto W = weights;
  const auto pal = palettes;
  const auto offsets = palette_offsets;
  const auto outP = out_positions;
  const auto outN = out_normals;
  const bool normals_out = !out_normals.empty();
  const std::int32_t J = joint_count;
  const Index palette_size = palettes.size();
  parallel_for(
      "anim.skin", character_count() * V,
      THRONG_LAMBDA(Index i) {
        const Index c = i / V;
        const Index v = i - c * V;
        const Index base = offsets[c];
        glm::vec3 p(0.0f), n(0.0f);
        // A palette that would run past the end leaves the vertex at the origin.
        if (base >= 0 && base + J <= palette_size) skin_vertex(pal.data() + base, P[v], N[v], Jn[v], W[v], p, n);
        outP[i] = p;
        if (normals_out) outN[i] = n;
      },
      256);
}

}  // namespace throng::anim
