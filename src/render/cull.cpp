// Host-side checks of the render stages (kernels in cull_kernels.cpp).
#include <fmt/format.h>

#include "anim/lod_spheres.h"
#include "core/error.h"
#include "render/cull.h"

namespace throng::render {

void CullJob::validate() const {
  if (joint_count <= 0) throw Error("must be positive", at_field("cull.joint_count"));
  if (tier_flags.size() % kDrawTiers != 0) throw Error("not a whole number of characters", at_field("cull.tier_flags"));
  const Index n = character_count();
  if (joint_positions.size() != n * joint_count)
    throw Error(fmt::format("{} positions for {} characters of {} joints", joint_positions.size(), n, joint_count),
                at_field("cull.joint_positions"));
  if (!(bounding_radius > 0.0f)) throw Error("must be positive", at_field("cull.bounding_radius"));
  if (!(fine_min_pixels >= 0.0f)) throw Error("must be >= 0", at_field("cull.fine_min_pixels"));
  if (!(lines_max_pixels >= 0.0f)) throw Error("must be >= 0", at_field("cull.lines_max_pixels"));
}

void PackJob::validate() const {
  const Index n = character_count();
  const auto check = [&](Index size, Index want, const char* field) {
    if (size != want) throw Error(fmt::format("size {} where {} is needed", size, want), at_field(field));
  };
  if (joint_count <= 0) throw Error("must be positive", at_field("pack.joint_count"));
  if (points.size() < joint_count) throw Error("fewer points than joints", at_field("pack.points"));
  if (tier_flags.size() % kDrawTiers != 0) throw Error("not a whole number of characters", at_field("pack.tier_flags"));
  check(joint_positions.size(), n * joint_count, "pack.joint_positions");
  check(joint_rotations.size(), n * joint_count, "pack.joint_rotations");
  check(slots.size(), tier_flags.size(), "pack.slots");
  if (!lod_levels.empty() && lod_levels.size() != n && lod_levels.size() != n * anim::kBodyPartCount)
    throw Error(fmt::format("{} levels for {} characters", lod_levels.size(), n), at_field("pack.lod_levels"));
  if (out_points.size() % points.size() != 0)
    throw Error(fmt::format("{} packed points is not a whole number of {}-point slots", out_points.size(), points.size()),
                at_field("pack.out_points"));
}

}  // namespace throng::render
