#include "anim/lod.h"
#include "anim/sphere_projection.h"
#include "core/parallel.h"
#include "render/cull.h"

namespace throng::render {

void CullJob::run() const {
  validate();
  const CameraView cam = camera;
  const std::int32_t J = joint_count;
  const float radius = bounding_radius;
  const float fine_px = fine_min_pixels, lines_px = lines_max_pixels;
  const bool do_cull = cull;
  const Index n = character_count();
  const Span<const glm::vec3> pos = joint_positions;
  const Span<std::uint32_t> flags = tier_flags;
  parallel_for("render.cull", n, THRONG_LAMBDA(Index c) {
    const glm::vec3 centre = to_camera_space(cam, pos[c * J]);
    const bool visible = !do_cull || !anim::sphere_outside_view(centre, radius, cam);
    // Image radius of the bounding sphere against the tiers' limits (the
    // whole viewport when the camera is inside it or it straddles the
    // camera plane): focal * radius / depth >= limit, without dividing.
    const float depth = -centre.z;
    const float size = cam.focal_px * radius;
    const bool close = depth <= radius;
    const bool fine = close || size >= fine_px * depth;
    const bool lines = !close && size < lines_px * depth;
    flags[c] = visible && fine ? 1u : 0u;
    flags[n + c] = visible && !fine && !lines ? 1u : 0u;
    flags[2 * n + c] = visible && !fine && lines ? 1u : 0u;
  });
}

void PackJob::run() const {
  validate();
  const std::int32_t J = joint_count;
  const Index P = points.size();
  const Index n = character_count();
  const Index slot_count = out_points.size() / P;
  const Index level_stride = lod_levels.empty() || n == 0 ? 0 : lod_levels.size() / n;
  const Span<const RigPoint> rig = points;
  const Span<const glm::vec3> pos = joint_positions;
  const Span<const glm::quat> rot = joint_rotations;
  const Span<const std::uint8_t> levels = lod_levels;
  const Span<const std::uint32_t> flags = tier_flags, slot_of = slots;
  const Span<glm::vec4> out = out_points;
  parallel_for(
      "render.pack", n, THRONG_LAMBDA(Index c) {
        Index slot = -1;
        for (int t = 0; t < kDrawTiers; ++t)
          if (flags[t * n + c] != 0u) slot = slot_of[t * n + c];
        if (slot < 0 || slot >= slot_count) return;
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
