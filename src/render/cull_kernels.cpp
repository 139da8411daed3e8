#include "anim/lod.h"
#include "anim/sphere_projection.h"
#include "core/parallel.h"
#include "core/reduce.h"
#include "render/cull.h"

namespace throng::render {

Index scan_draw_slots(Span<const std::uint32_t> group_flags, Span<std::uint32_t> slots) {
  return exclusive_scan<std::uint32_t>("render.slots", group_flags, slots);
}

void CullJob::run() const {
  validate();
  const CameraView cam = camera;
  const CullRigs table = rigs;
  const std::int32_t J = joint_count;
  const float fine_px = fine_min_pixels, lines_px = lines_max_pixels;
  const bool do_cull = cull;
  const std::int32_t forced = force_tier;
  const Index n = character_count();
  const std::int32_t groups = group_count();
  const Span<const glm::vec3> pos = joint_positions;
  const Span<const float> scale = scales;
  const Span<const anim::Mat3x4> pal = palettes;
  const Span<const Index> offsets = palette_offsets;
  const Span<const std::int32_t> rig_of = character_rigs;
  const Span<const std::uint8_t> shown = flags;
  const std::uint8_t bits = visible_bits;
  const Span<std::uint32_t> out = group_flags;
  parallel_for("render.cull", n, THRONG_LAMBDA(Index c) {
    for (std::int32_t g = 0; g < groups; ++g) out[g * n + c] = 0u;
    if (!shown.empty() && (shown[c] & bits) != bits) return;
    std::int32_t r = 0;
    glm::vec3 root(0.0f);
    float s = 1.0f;
    if (J > 0) {
      root = pos[c * J];
      if (!scale.empty()) s = scale[c];
    } else {
      r = rig_of.empty() ? 0 : rig_of[c];
      if (r < 0 || r >= table.count) return;
      const Index first = offsets[c];
      if (first < 0 || first + table.rig[r].joint_count > pal.size()) return;
      const anim::Mat3x4 m = pal[first];
      root = anim::transform_point(m, table.rig[r].root_bind);
      s = glm::length(glm::vec3(m.r0.x, m.r1.x, m.r2.x));
    }
    const float radius = table.rig[r].bounding_radius * s;
    const glm::vec3 centre = to_camera_space(cam, root);
    const bool visible = !do_cull || !anim::sphere_outside_view(centre, radius, cam);
    if (!visible) return;
    // Image radius of the bounding sphere against the tiers' limits (the
    // whole viewport when the camera is inside it or it straddles the
    // camera plane): focal * radius / depth >= limit, without dividing.
    const float depth = -centre.z;
    const float size = cam.focal_px * radius;
    const bool close = depth <= radius;
    const bool fine = close || size >= fine_px * depth;
    const bool lines = !close && size < lines_px * depth;
    const std::int32_t tier = forced >= 0 ? forced : (fine ? 0 : (lines ? 2 : 1));
    out[(r * kDrawTiers + tier) * n + c] = 1u;
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
  const Span<const std::uint32_t> flags = group_flags, slot_index = slots;
  const Span<glm::vec4> out = out_points;
  parallel_for(
      "render.pack", n, THRONG_LAMBDA(Index c) {
        std::int32_t group = 0;
        const Index slot = slot_of(flags, slot_index, n, kDrawTiers, c, group);
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

void PalettePackJob::run() const {
  validate();
  const std::int32_t J = joint_count;
  const Index n = character_count();
  const DrawGroups g = groups;
  const Span<const glm::vec3> pos = joint_positions;
  const Span<const glm::quat> rot = joint_rotations;
  const Span<const float> scale = scales;
  const Span<const anim::Mat3x4> inverse = inverse_bind, pal = palettes;
  const Span<const Index> offsets = palette_offsets;
  const Span<const std::uint8_t> levels = lod_levels;
  const Span<const std::uint32_t> flags = group_flags, slot_index = slots;
  const Span<anim::Mat3x4> out = out_palettes;
  const Span<glm::uvec2> tags = out_tags;
  parallel_for(
      "render.pack_palettes", n, THRONG_LAMBDA(Index c) {
        std::int32_t group = -1;
        const Index slot = slot_of(flags, slot_index, n, g.count, c, group);
        if (slot < 0) return;
        const std::int32_t joints = g.joints[group];
        const Index at = g.first_matrix[group] + (slot - g.first_slot[group]) * joints;
        tags[slot] = slot_tag(c, levels, n);
        if (J > 0) {
          const float s = scale.empty() ? 1.0f : scale[c];
          for (std::int32_t j = 0; j < J; ++j) {
            anim::Mat3x4 world = anim::mat3x4_from(rot[c * J + j], pos[c * J + j]);
            world.r0 = glm::vec4(glm::vec3(world.r0) * s, world.r0.w);
            world.r1 = glm::vec4(glm::vec3(world.r1) * s, world.r1.w);
            world.r2 = glm::vec4(glm::vec3(world.r2) * s, world.r2.w);
            out[at + j] = world * inverse[j];
          }
        } else {
          const Index first = offsets[c];
          const bool in_range = first >= 0 && first + joints <= pal.size();  // CullJob leaves others out
          for (std::int32_t j = 0; j < joints; ++j) out[at + j] = in_range ? pal[first + j] : anim::collapse_to(glm::vec3(0.0f));
        }
      },
      256);
}

}  // namespace throng::render
