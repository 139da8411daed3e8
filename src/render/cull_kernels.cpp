#include <fmt/format.h>

#include "anim/lod.h"
#include "anim/sphere_projection.h"
#include "core/error.h"
#include "core/parallel.h"
#include "render/cull.h"

namespace throng::render {

void CullJob::validate() const {
  if (joint_count <= 0) throw Error("must be positive", at_field("cull.joint_count"));
  const Index n = character_count();
  if (coarse.size() != n) throw Error(fmt::format("{} flags for {} characters", coarse.size(), n), at_field("cull.coarse"));
  if (joint_positions.size() != n * joint_count)
    throw Error(fmt::format("{} positions for {} characters of {} joints", joint_positions.size(), n, joint_count),
                at_field("cull.joint_positions"));
  if (!(bounding_radius > 0.0f)) throw Error("must be positive", at_field("cull.bounding_radius"));
  if (!(fine_min_pixels >= 0.0f)) throw Error("must be >= 0", at_field("cull.fine_min_pixels"));
}

void CullJob::run() const {
  validate();
  const CameraView cam = camera;
  const std::int32_t J = joint_count;
  const float radius = bounding_radius;
  const float fine_px = fine_min_pixels;
  const bool do_cull = cull;
  const Span<const glm::vec3> pos = joint_positions;
  const Span<std::uint32_t> fine_out = fine, coarse_out = coarse;
  parallel_for("render.cull", character_count(), THRONG_LAMBDA(Index c) {
    const glm::vec3 centre = to_camera_space(cam, pos[c * J]);
    const bool visible = !do_cull || !anim::sphere_outside_view(centre, radius, cam);
    // Image radius of the bounding sphere, pixels (whole viewport when the
    // camera is inside it or it straddles the camera plane).
    const float depth = -centre.z;
    const bool near = depth <= radius || cam.focal_px * radius >= fine_px * depth;
    fine_out[c] = visible && near ? 1u : 0u;
    coarse_out[c] = visible && !near ? 1u : 0u;
  });
}

void PackJob::validate() const {
  const Index n = character_count();
  const auto check = [&](Index size, Index want, const char* field) {
    if (size != want) throw Error(fmt::format("size {} where {} is needed", size, want), at_field(field));
  };
  if (joint_count <= 0) throw Error("must be positive", at_field("pack.joint_count"));
  if (points.size() < joint_count) throw Error("fewer points than joints", at_field("pack.points"));
  check(joint_positions.size(), n * joint_count, "pack.joint_positions");
  check(joint_rotations.size(), n * joint_count, "pack.joint_rotations");
  check(coarse.size(), n, "pack.coarse");
  check(fine_slot.size(), n, "pack.fine_slot");
  check(coarse_slot.size(), n, "pack.coarse_slot");
  if (!lod_levels.empty() && lod_levels.size() != n && lod_levels.size() != n * anim::kBodyPartCount)
    throw Error(fmt::format("{} levels for {} characters", lod_levels.size(), n), at_field("pack.lod_levels"));
  if (out_points.size() % points.size() != 0 || out_points.size() / points.size() < fine_total)
    throw Error(fmt::format("{} packed points is not a whole number of {}-point slots", out_points.size(), points.size()),
                at_field("pack.out_points"));
}

void PackJob::run() const {
  validate();
  const std::int32_t J = joint_count;
  const Index P = points.size();
  const Index slots = out_points.size() / P;
  const Index level_stride = lod_levels.empty() ? 0 : lod_levels.size() / character_count();
  const Index fine_count = fine_total;
  const Span<const RigPoint> rig = points;
  const Span<const glm::vec3> pos = joint_positions;
  const Span<const glm::quat> rot = joint_rotations;
  const Span<const std::uint8_t> levels = lod_levels;
  const Span<const std::uint32_t> is_fine = fine, is_coarse = coarse, fine_at = fine_slot, coarse_at = coarse_slot;
  const Span<glm::vec4> out = out_points;
  parallel_for(
      "render.pack", character_count(), THRONG_LAMBDA(Index c) {
        Index slot = -1;
        if (is_fine[c] != 0u) slot = fine_at[c];
        if (is_coarse[c] != 0u) slot = fine_count + coarse_at[c];
        if (slot < 0 || slot >= slots) return;
        for (Index k = 0; k < P; ++k) {
          const RigPoint p = rig[k];
          const Index joint = c * J + p.joint;
          const glm::vec3 world = pos[joint] + rot[joint] * p.offset;
          std::int32_t level = 0;
          if (level_stride == 1) level = levels[c];
          if (level_stride > 1) level = levels[c * level_stride + p.part];
          out[slot * P + k] = glm::vec4(world, pack_point_tag(level, c));
        }
      },
      256);
}

}  // namespace throng::render
