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
  const Index n = character_count();
  const std::int32_t groups = group_count();
  parallel_for(
      "render.cull", n, THRONG_JOB_LAMBDA(Index c) {
        for (std::int32_t g = 0; g < groups; ++g) group_flags[g * n + c] = 0u;
        if (!flags.empty() && (flags[c] & visible_bits) != visible_bits) return;
        std::int32_t r = 0;
        glm::vec3 root(0.0f);
        float s = 1.0f;
        if (joint_count > 0) {
          root = joint_positions[c * joint_count];
          if (!scales.empty()) s = scales[c];
        } else if (!palette_refs.empty()) {
          root = anim::transform_point(anim::root_transform(root_positions[c], root_yaws[c]), rigs.rig[0].root_bind);
        } else {
          r = character_rigs.empty() ? 0 : character_rigs[c];
          if (r < 0 || r >= rigs.count) return;
          const Index first = palette_offsets[c];
          if (first < 0 || first + rigs.rig[r].joint_count > palettes.size()) return;
          const anim::Mat3x4 m = palettes[first];
          root = anim::transform_point(m, rigs.rig[r].root_bind);
          s = glm::length(glm::vec3(m.r0.x, m.r1.x, m.r2.x));
        }
        const float radius = rigs.rig[r].bounding_radius * s;
        const glm::vec3 centre = to_camera_space(camera, root);
        const bool visible = !cull || !anim::sphere_outside_view(centre, radius, camera);
        if (!visible) return;
        // Image radius of the bounding sphere against the tiers' limits (the
        // whole viewport when the camera is inside it or it straddles the
        // camera plane): focal * radius / depth >= limit, without dividing.
        const float depth = -centre.z;
        const float size = camera.focal_px * radius;
        const bool close = depth <= radius;
        const bool fine = close || size >= fine_min_pixels * depth;
        const bool lines = !close && size < lines_max_pixels * depth;
        const std::int32_t tier = force_tier >= 0 ? force_tier : (fine ? 0 : (lines ? 2 : 1));
        group_flags[(r * kDrawTiers + tier) * n + c] = 1u;
      });
}

void PackJob::run() const {
  validate();
  const Index P = points.size();
  const Index n = character_count();
  const Index slot_count = out_points.size() / P;
  const Index level_stride = lod_levels.empty() || n == 0 ? 0 : lod_levels.size() / n;
  parallel_for(
      "render.pack", n,
      THRONG_JOB_LAMBDA(Index c) {
        std::int32_t group = 0;
        const Index slot = slot_of(group_flags, slots, n, kDrawTiers, c, group);
        if (slot < 0 || slot >= slot_count) return;
        for (Index k = 0; k < P; ++k) {
          const RigPoint p = points[k];
          const Index joint = c * joint_count + p.joint;
          const glm::vec3 world = joint_positions[joint] + joint_rotations[joint] * p.offset;
          std::int32_t level = 0;
          if (level_stride == 1) level = lod_levels[c];
          if (level_stride > 1) level = lod_levels[c * level_stride + p.part];
          out_points[slot * P + k] = glm::vec4(world, pack_point_tag(level, c));
        }
      },
      256);
}

void PalettePackJob::run() const {
  validate();
  const Index n = character_count();
  parallel_for(
      "render.pack_palettes", n,
      THRONG_JOB_LAMBDA(Index c) {
        std::int32_t group = -1;
        const Index slot = slot_of(group_flags, slots, n, groups.count, c, group);
        if (slot < 0) return;
        const std::int32_t joints = groups.joints[group];
        const Index at = groups.first_matrix[group] + (slot - groups.first_slot[group]) * joints;
        out_tags[slot] = slot_tag(c, lod_levels, n);
        if (joint_count > 0) {
          const float s = scales.empty() ? 1.0f : scales[c];
          for (std::int32_t j = 0; j < joint_count; ++j) {
            anim::Mat3x4 world =
                anim::mat3x4_from(joint_rotations[c * joint_count + j], joint_positions[c * joint_count + j]);
            world.r0 = glm::vec4(glm::vec3(world.r0) * s, world.r0.w);
            world.r1 = glm::vec4(glm::vec3(world.r1) * s, world.r1.w);
            world.r2 = glm::vec4(glm::vec3(world.r2) * s, world.r2.w);
            out_palettes[at + j] = world * inverse_bind[j];
          }
        } else if (!palette_refs.empty()) {
          const anim::PaletteRef ref = palette_refs[c];
          const anim::Mat3x4 root = anim::root_transform(root_positions[c], root_yaws[c]);
          for (std::int32_t j = 0; j < joints; ++j) out_palettes[at + j] = anim::compose_palette(ref, root, j);
        } else {
          const Index first = palette_offsets[c];
          const bool in_range = first >= 0 && first + joints <= palettes.size();  // CullJob leaves others out
          for (std::int32_t j = 0; j < joints; ++j)
            out_palettes[at + j] = in_range ? palettes[first + j] : anim::collapse_to(glm::vec3(0.0f));
        }
      },
      256);
}

}  // namespace throng::render
