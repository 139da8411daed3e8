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
    throw Error("has " + std::to_string(palette.size()) + " matrices, the mesh has " +
                    std::to_string(mesh.joint_count) + " joints",
                at_field("skin.palette"));
  if (out_positions.size() != V) throw Error("must have one entry per vertex", at_field("skin.out_positions"));
  if (!out_normals.empty() && out_normals.size() != V)
    throw Error("must be empty or have one entry per vertex", at_field("skin.out_normals"));
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
  parallel_for(
      "anim.skin", character_count() * V,
      THRONG_JOB_LAMBDA(Index i) {
        const Index c = i / V;
        const Index v = i - c * V;
        const Index base = palette_offsets[c];
        glm::vec3 p(0.0f), n(0.0f);
        // A palette that would run past the end leaves the vertex at the origin.
        if (base >= 0 && base + joint_count <= palettes.size())
          skin_vertex(palettes.data() + base, positions[v], normals[v], joints[v], weights[v], p, n);
        out_positions[i] = p;
        if (!out_normals.empty()) out_normals[i] = n;
      },
      256);
}

}  // namespace throng::anim
