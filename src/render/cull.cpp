// Host-side checks of the render stages (kernels in cull_kernels.cpp).
#include <fmt/format.h>

#include "anim/lod_spheres.h"
#include "core/buffer.h"
#include "core/error.h"
#include "render/cull.h"

namespace throng::render {

namespace {

void check_levels(Span<const std::uint8_t> levels, Index n, const char* field) {
  if (!levels.empty() && levels.size() != n && levels.size() != n * anim::kBodyPartCount)
    throw Error(fmt::format("{} levels for {} characters", levels.size(), n), at_field(field));
}

void check_size(Index size, Index want, const char* field) {
  if (size != want) throw Error(fmt::format("size {} where {} is needed", size, want), at_field(field));
}

}  // namespace

void CullJob::validate() const {
  if (rigs.count < 1 || rigs.count > kMaxRenderRigs)
    throw Error(fmt::format("must be in 1..{}", kMaxRenderRigs), at_field("cull.rigs.count"));
  for (std::int32_t r = 0; r < rigs.count; ++r)
    if (!(rigs.rig[r].bounding_radius > 0.0f))
      throw Error("must be positive", at_field(fmt::format("cull.rigs[{}].bounding_radius", r)));
  if (joint_count < 0) throw Error("must be >= 0", at_field("cull.joint_count"));
  if (group_flags.size() % group_count() != 0)
    throw Error("not a whole number of characters", at_field("cull.group_flags"));
  const Index n = group_flags.size() / group_count();
  if (joint_count > 0) {
    if (rigs.count != 1) throw Error("joint frames are of one rig", at_field("cull.rigs.count"));
    check_size(joint_positions.size(), n * joint_count, "cull.joint_positions");
    if (!scales.empty()) check_size(scales.size(), n, "cull.scales");
  } else if (!palette_refs.empty()) {
    check_size(palette_refs.size(), n, "cull.palette_refs");
    check_size(root_positions.size(), n, "cull.root_positions");
    check_size(root_yaws.size(), n, "cull.root_yaws");
  } else {
    check_size(palette_offsets.size(), n, "cull.palette_offsets");
    if (!character_rigs.empty()) check_size(character_rigs.size(), n, "cull.character_rigs");
  }
  if (force_tier < -1 || force_tier >= kDrawTiers)
    throw Error(fmt::format("must be in -1..{}", kDrawTiers - 1), at_field("cull.force_tier"));
  if (!flags.empty()) check_size(flags.size(), n, "cull.flags");
  if (!(fine_min_pixels >= 0.0f)) throw Error("must be >= 0", at_field("cull.fine_min_pixels"));
  if (!(lines_max_pixels >= 0.0f)) throw Error("must be >= 0", at_field("cull.lines_max_pixels"));
}

DrawGroups draw_groups(const CullJob& job, Span<const std::uint32_t> slots, Index visible) {
  DrawGroups groups;
  groups.count = job.group_count();
  const Index n = job.character_count();
  if (slots.size() != groups.count * n)
    throw Error(fmt::format("size {} where {} is needed", slots.size(), groups.count * n), at_field("cull.slots"));
  // Where each group's slots begin: the scan at the group's first entry.
  Index starts[kMaxDrawGroups + 1] = {};
  for (std::int32_t g = 1; g < groups.count && n > 0; ++g) {
    std::uint32_t start = 0;
    copy_to_host(slots.subspan(g * n, 1), std::span<std::uint32_t>(&start, 1));
    starts[g] = start;
  }
  starts[groups.count] = visible;
  Index matrices = 0;
  for (std::int32_t g = 0; g < groups.count; ++g) {
    groups.joints[g] = job.rigs.rig[g / kDrawTiers].joint_count;
    groups.first_slot[g] = starts[g];
    groups.slots[g] = starts[g + 1] - starts[g];
    groups.first_matrix[g] = matrices;
    matrices += groups.slots[g] * groups.joints[g];
  }
  return groups;
}

void PackJob::validate() const {
  const Index n = character_count();
  if (joint_count <= 0) throw Error("must be positive", at_field("pack.joint_count"));
  if (points.size() < joint_count) throw Error("fewer points than joints", at_field("pack.points"));
  if (group_flags.size() % kDrawTiers != 0)
    throw Error("not a whole number of characters", at_field("pack.group_flags"));
  check_size(joint_positions.size(), n * joint_count, "pack.joint_positions");
  check_size(joint_rotations.size(), n * joint_count, "pack.joint_rotations");
  check_size(slots.size(), group_flags.size(), "pack.slots");
  check_levels(lod_levels, n, "pack.lod_levels");
  if (out_points.size() % points.size() != 0)
    throw Error(
        fmt::format("{} packed points is not a whole number of {}-point slots", out_points.size(), points.size()),
        at_field("pack.out_points"));
}

void PalettePackJob::validate() const {
  if (groups.count < 1 || groups.count > kMaxDrawGroups)
    throw Error(fmt::format("must be in 1..{}", kMaxDrawGroups), at_field("pack.groups.count"));
  if (group_flags.size() % groups.count != 0)
    throw Error("not a whole number of characters", at_field("pack.group_flags"));
  const Index n = character_count();
  check_size(slots.size(), group_flags.size(), "pack.slots");
  if (joint_count > 0) {
    check_size(joint_positions.size(), n * joint_count, "pack.joint_positions");
    check_size(joint_rotations.size(), n * joint_count, "pack.joint_rotations");
    check_size(inverse_bind.size(), joint_count, "pack.inverse_bind");
    if (!scales.empty()) check_size(scales.size(), n, "pack.scales");
    for (std::int32_t g = 0; g < groups.count; ++g)
      if (groups.joints[g] != joint_count)
        throw Error("joint frames are of one rig", at_field(fmt::format("pack.groups.joints[{}]", g)));
  } else if (!palette_refs.empty()) {
    check_size(palette_refs.size(), n, "pack.palette_refs");
    check_size(root_positions.size(), n, "pack.root_positions");
    check_size(root_yaws.size(), n, "pack.root_yaws");
  } else {
    check_size(palette_offsets.size(), n, "pack.palette_offsets");
  }
  check_levels(lod_levels, n, "pack.lod_levels");
  check_size(out_palettes.size(), groups.matrices(), "pack.out_palettes");
  check_size(out_tags.size(), groups.visible(), "pack.out_tags");
}

}  // namespace throng::render
