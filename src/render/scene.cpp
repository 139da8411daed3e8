#include "render/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "anim/lod.h"
#include "core/error.h"

namespace throng::render {

const char* to_string(RenderMode m) { return m == RenderMode::Joints ? "joints" : "skinned"; }

RenderMode parse_render_mode(const std::string& text, const std::string& field) {
  if (text == "joints") return RenderMode::Joints;
  if (text == "skinned") return RenderMode::Skinned;
  throw Error(fmt::format("unknown render mode '{}' (joints or skinned)", text), at_field(field));
}

void JointRig::validate() const {
  if (joint_count <= 0 || joint_count > anim::kMaxLodJoints)
    throw Error(fmt::format("joint count {} is outside 1..{}", joint_count, anim::kMaxLodJoints), at_field("rig.joint_count"));
  if (point_count() < joint_count) throw Error("fewer points than joints", at_field("rig.points"));
  for (std::int32_t i = 0; i < point_count(); ++i) {
    const RigPoint& p = points[static_cast<std::size_t>(i)];
    if (p.joint < 0 || p.joint >= joint_count || (i < joint_count && p.joint != i))
      throw Error(fmt::format("joint {} out of range", p.joint), at_field(fmt::format("rig.points[{}].joint", i)));
    if (p.part >= anim::kBodyPartCount) throw Error("body part out of range", at_field(fmt::format("rig.points[{}].part", i)));
  }
  for (std::size_t b = 0; b < bones.size(); ++b) {
    const RigBone& bone = bones[b];
    if (bone.from < 0 || bone.from >= point_count()) throw Error("point out of range", at_field(fmt::format("rig.bones[{}].from", b)));
    if (bone.to < 0 || bone.to >= point_count()) throw Error("point out of range", at_field(fmt::format("rig.bones[{}].to", b)));
    if (!(bone.radius > 0.0f) || !std::isfinite(bone.radius))
      throw Error("radius must be positive and finite", at_field(fmt::format("rig.bones[{}].radius", b)));
  }
  if (!(bounding_radius > 0.0f) || !std::isfinite(bounding_radius))
    throw Error("must be positive and finite", at_field("rig.bounding_radius"));
}

JointRig make_joint_rig(const motion::Skeleton& s) {
  s.validate();
  const std::int32_t J = s.joint_count();
  JointRig rig;
  rig.joint_count = J;
  std::vector<std::uint8_t> part(static_cast<std::size_t>(J), static_cast<std::uint8_t>(anim::BodyPart::Torso));
  try {
    part = anim::make_body_parts(s).part_of;
  } catch (const Error&) {
    // No limb roles: colour the whole character as one part.
  }
  for (std::int32_t j = 0; j < J; ++j) rig.points.push_back({j, glm::vec3(0.0f), part[static_cast<std::size_t>(j)]});

  // Thickness: a fraction of the bone's length within limits; the torso's
  // trunk (bones between hips, spine and neck) stouter.
  const auto is_trunk = [&](std::int32_t j) {
    return s.parents[static_cast<std::size_t>(j)] < 0 ||
           std::find(s.spine_chain.begin(), s.spine_chain.end(), j) != s.spine_chain.end();
  };
  const auto thickness = [&](float length, bool trunk) {
    return trunk ? std::clamp(0.6f * length, 0.08f, 0.14f) : std::clamp(0.22f * length, 0.028f, 0.1f);
  };

  // Distance bound from the root to every point (sum of bone lengths).
  std::vector<float> reach(static_cast<std::size_t>(J), 0.0f);
  float max_reach = 0.0f, max_radius = 0.0f;
  for (std::int32_t j = 0; j < J; ++j) {
    const std::int32_t p = s.parents[static_cast<std::size_t>(j)];
    if (p < 0) {
      rig.bones.push_back({j, j, 0.1f});
      continue;
    }
    const float length = glm::length(s.offsets[static_cast<std::size_t>(j)]);
    reach[static_cast<std::size_t>(j)] = reach[static_cast<std::size_t>(p)] + length;
    const bool trunk = is_trunk(p) && (is_trunk(j) || j == s.role(motion::Role::Neck));
    rig.bones.push_back({p, j, thickness(length, trunk)});
  }
  for (std::int32_t j = 0; j < J; ++j) {
    if (!s.has_end_site[static_cast<std::size_t>(j)]) continue;
    const glm::vec3 offset = s.end_sites[static_cast<std::size_t>(j)];
    const float length = glm::length(offset);
    if (length <= 0.0f) continue;
    const std::int32_t point = rig.point_count();
    rig.points.push_back({j, offset, part[static_cast<std::size_t>(j)]});
    // The head is rounder than a limb segment.
    const bool head = j == s.role(motion::Role::Head);
    rig.bones.push_back({j, point, head ? std::clamp(0.5f * length, 0.07f, 0.12f) : thickness(length, false)});
    max_reach = std::max(max_reach, reach[static_cast<std::size_t>(j)] + length);
  }
  for (const RigBone& b : rig.bones) max_radius = std::max(max_radius, b.radius);
  for (float r : reach) max_reach = std::max(max_reach, r);
  rig.bounding_radius = max_reach + max_radius;
  rig.validate();
  return rig;
}

void CharacterPoses::validate(const JointRig& rig) const {
  if (joint_count != rig.joint_count)
    throw Error(fmt::format("{} joints, the rig has {}", joint_count, rig.joint_count), at_field("poses.joint_count"));
  if (joint_positions.size() % joint_count != 0)
    throw Error(fmt::format("{} positions is not a whole number of {}-joint characters", joint_positions.size(), joint_count),
                at_field("poses.joint_positions"));
  const Index n = character_count();
  if (joint_rotations.size() != n * joint_count)
    throw Error(fmt::format("{} rotations for {} characters of {} joints", joint_rotations.size(), n, joint_count),
                at_field("poses.joint_rotations"));
  if (!lod_levels.empty() && lod_levels.size() != n && lod_levels.size() != n * anim::kBodyPartCount)
    throw Error(fmt::format("{} levels for {} characters (want 0, {} or {})", lod_levels.size(), n, n, n * anim::kBodyPartCount),
                at_field("poses.lod_levels"));
}

void BinsOverlay::validate() const {
  if (!(cell_size > 0.0f) || !std::isfinite(cell_size)) throw Error("must be positive and finite", at_field("bins.cell_size"));
  if (columns < 0 || rows < 0 || static_cast<Index>(columns) * rows > (Index{1} << 26))
    throw Error(fmt::format("{} x {} cells is out of range", columns, rows), at_field("bins.columns"));
  if (counts.size() != static_cast<Index>(columns) * rows)
    throw Error(fmt::format("{} counts for {} x {} cells", counts.size(), columns, rows), at_field("bins.counts"));
  if (saturate_at < 1) throw Error("must be at least 1", at_field("bins.saturate_at"));
}

}  // namespace throng::render
