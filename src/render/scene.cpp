#include "render/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "anim/crowd_animator.h"
#include "anim/locomotion_streams.h"
#include "anim/lod.h"
#include "anim/rig.h"
#include "anim/stream_crowd.h"
#include "core/error.h"
#include "sim/crowd.h"

namespace throng::render {

const char* to_string(RenderMode m) { return m == RenderMode::Joints ? "joints" : "skinned"; }

RenderMode parse_render_mode(const std::string& text, const std::string& field) {
  if (text == "joints") return RenderMode::Joints;
  if (text == "skinned") return RenderMode::Skinned;
  throw Error(fmt::format("unknown render mode '{}' (joints or skinned)", text), at_field(field));
}

void JointRig::validate() const {
  if (joint_count <= 0 || joint_count > anim::kMaxLodJoints)
    throw Error(fmt::format("joint count {} is outside 1..{}", joint_count, anim::kMaxLodJoints),
                at_field("rig.joint_count"));
  if (point_count() < joint_count) throw Error("fewer points than joints", at_field("rig.points"));
  for (std::int32_t i = 0; i < point_count(); ++i) {
    const RigPoint& p = points[static_cast<std::size_t>(i)];
    if (p.joint < 0 || p.joint >= joint_count || (i < joint_count && p.joint != i))
      throw Error(fmt::format("joint {} out of range", p.joint), at_field(fmt::format("rig.points[{}].joint", i)));
    if (p.part >= anim::kBodyPartCount)
      throw Error("body part out of range", at_field(fmt::format("rig.points[{}].part", i)));
  }
  for (std::size_t b = 0; b < bones.size(); ++b) {
    const RigBone& bone = bones[b];
    if (bone.from < 0 || bone.from >= point_count())
      throw Error("point out of range", at_field(fmt::format("rig.bones[{}].from", b)));
    if (bone.to < 0 || bone.to >= point_count())
      throw Error("point out of range", at_field(fmt::format("rig.bones[{}].to", b)));
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

void SkinRig::validate() const {
  if (joint_count <= 0 || joint_count > anim::kMaxRigJoints)
    throw Error(fmt::format("joint count {} is outside 1..{}", joint_count, anim::kMaxRigJoints),
                at_field("skin.joint_count"));
  if (inverse_bind.size() != static_cast<std::size_t>(joint_count))
    throw Error("one matrix per joint", at_field("skin.inverse_bind"));
  if (bind_positions.size() != static_cast<std::size_t>(joint_count))
    throw Error("one position per joint", at_field("skin.bind_positions"));
  for (int t = 0; t < kDrawTiers; ++t) {
    const anim::SkinnedMesh& m = meshes[static_cast<std::size_t>(t)];
    const std::string field = fmt::format("skin.meshes[{}]", t);
    if (m.joint_count != joint_count)
      throw Error(fmt::format("bound to {} joints, the rig has {}", m.joint_count, joint_count), at_field(field));
    const bool lines = t + 1 == kDrawTiers;
    try {
      if (lines) {  // SkinnedMesh checks triangles: check the vertices, then the lines here
        anim::SkinnedMesh vertices = m;
        vertices.indices.clear();
        vertices.validate();
      } else {
        m.validate();
      }
    } catch (const Error& e) {
      throw Error(e.message(), at_field(field + "." + e.location().field));
    }
    if (lines && m.indices.size() % 2 != 0) throw Error("not whole lines", at_field(field + ".indices"));
    for (std::uint32_t i : m.indices)
      if (i >= static_cast<std::uint32_t>(m.vertex_count()))
        throw Error("vertex index out of range", at_field(field + ".indices"));
    const auto V = static_cast<std::size_t>(m.vertex_count());
    if (parts[static_cast<std::size_t>(t)].size() != V)
      throw Error("one part per vertex", at_field(fmt::format("skin.parts[{}]", t)));
    if (materials[static_cast<std::size_t>(t)].size() != V)
      throw Error("one material per vertex", at_field(fmt::format("skin.materials[{}]", t)));
    for (std::uint8_t p : parts[static_cast<std::size_t>(t)])
      if (p >= anim::kBodyPartCount) throw Error("body part out of range", at_field(fmt::format("skin.parts[{}]", t)));
  }
  if (!(bounding_radius > 0.0f) || !std::isfinite(bounding_radius))
    throw Error("must be positive and finite", at_field("skin.bounding_radius"));
}

namespace {

// A line per bone (parent to child joint, joint to end site), each end
// bound rigidly to the joint that carries the bone: the far tier.
anim::SkinnedMesh bone_lines(const anim::Rig& rig) {
  const motion::Skeleton& s = rig.skeleton;
  anim::SkinnedMesh m;
  m.joint_count = rig.joint_count();
  const auto add = [&](std::int32_t joint, glm::vec3 p) {
    m.positions.push_back(p);
    m.normals.emplace_back(0.0f, 1.0f, 0.0f);
    m.joints.emplace_back(static_cast<std::uint16_t>(joint), 0, 0, 0);
    m.weights.emplace_back(1.0f, 0.0f, 0.0f, 0.0f);
  };
  for (std::int32_t j = 0; j < rig.joint_count(); ++j) {
    const auto J = static_cast<std::size_t>(j);
    const std::int32_t p = s.parents[J];
    if (p >= 0) {
      m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
      add(p, rig.bind_positions[static_cast<std::size_t>(p)]);
      m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
      add(p, rig.bind_positions[J]);
    }
    if (s.has_end_site[J] && glm::length(s.end_sites[J]) > 0.0f) {
      m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
      add(j, rig.bind_positions[J]);
      m.indices.push_back(static_cast<std::uint32_t>(m.positions.size()));
      add(j, rig.bind_positions[J] + rig.bind_rotations[J] * s.end_sites[J]);
    }
  }
  return m;
}

// Is `joint` the joint of one of `roles`, or below one?
bool at_or_below(const motion::Skeleton& s, std::int32_t joint, std::initializer_list<motion::Role> roles) {
  for (std::int32_t j = joint; j >= 0; j = s.parents[static_cast<std::size_t>(j)])
    for (motion::Role r : roles)
      if (s.role(r) == j) return true;
  return false;
}

}  // namespace

SkinRig make_skin_rig(const anim::Rig& rig) {
  using motion::Role;
  const motion::Skeleton& s = rig.skeleton;
  const std::int32_t J = rig.joint_count();
  SkinRig out;
  out.name = rig.name;
  out.joint_count = J;
  out.inverse_bind = rig.inverse_bind;
  out.bind_positions = rig.bind_positions;
  anim::MannequinOptions coarse;
  coarse.sides = 6;
  coarse.body_rings = 2;
  coarse.cap_rings = 1;
  out.meshes = {rig.mesh, anim::make_mannequin(s, coarse), bone_lines(rig)};

  std::vector<std::uint8_t> part_of(static_cast<std::size_t>(J), static_cast<std::uint8_t>(anim::BodyPart::Torso));
  try {
    part_of = anim::make_body_parts(s).part_of;
  } catch (const Error&) {
    // No limb roles: one part.
  }
  std::vector<std::uint8_t> material(static_cast<std::size_t>(J), kShirt);
  for (std::int32_t j = 0; j < J; ++j) {
    const auto part = static_cast<anim::BodyPart>(part_of[static_cast<std::size_t>(j)]);
    if (part == anim::BodyPart::LeftLeg || part == anim::BodyPart::RightLeg)
      material[static_cast<std::size_t>(j)] = kTrousers;
    if (at_or_below(s, j, {Role::Neck, Role::Head, Role::LeftWrist, Role::RightWrist}))
      material[static_cast<std::size_t>(j)] = kSkin;
  }
  // Chain length from the root to every joint in the bind pose.
  std::vector<float> reach(static_cast<std::size_t>(J), 0.0f);
  for (std::int32_t j = 1; j < J; ++j) {
    const std::int32_t p = s.parents[static_cast<std::size_t>(j)];
    reach[static_cast<std::size_t>(j)] =
        reach[static_cast<std::size_t>(p)] +
        glm::distance(rig.bind_positions[static_cast<std::size_t>(p)], rig.bind_positions[static_cast<std::size_t>(j)]);
  }
  float radius = 0.0f;
  for (int t = 0; t < kDrawTiers; ++t) {
    const anim::SkinnedMesh& m = out.meshes[static_cast<std::size_t>(t)];
    for (std::int32_t v = 0; v < m.vertex_count(); ++v) {
      const auto V = static_cast<std::size_t>(v);
      int dominant = 0;
      for (int k = 0; k < 4; ++k) {
        if (m.weights[V][k] > m.weights[V][dominant]) dominant = k;
        if (m.weights[V][k] <= 0.0f) continue;
        const auto j = static_cast<std::size_t>(m.joints[V][k]);
        radius = std::max(radius, reach[j] + glm::distance(m.positions[V], rig.bind_positions[j]));
      }
      const auto j = static_cast<std::size_t>(m.joints[V][dominant]);
      out.parts[static_cast<std::size_t>(t)].push_back(part_of[j]);
      out.materials[static_cast<std::size_t>(t)].push_back(material[j]);
    }
  }
  out.bounding_radius = radius * 1.001f + 1e-3f;
  out.validate();
  return out;
}

CrowdRigs make_crowd_rigs(const motion::Skeleton& skeleton) {
  CrowdRigs rigs;
  rigs.joints = make_joint_rig(skeleton);
  rigs.skins.push_back(make_skin_rig(anim::make_rig("mannequin", skeleton)));
  return rigs;
}

CrowdRigs make_crowd_rigs(const anim::StreamCrowd& crowd) {
  CrowdRigs rigs;
  for (std::int32_t r = 0; r < crowd.rig_count(); ++r) rigs.skins.push_back(make_skin_rig(crowd.rig(r)));
  return rigs;
}

void CharacterPoses::validate(const CrowdRigs& crowd, RenderMode mode) const {
  Index n = 0;
  if (joint_count > 0) {
    if (!palettes.empty() || !palette_offsets.empty())
      throw Error("give joint frames or palettes, not both", at_field("poses.palettes"));
    if (!rigs.empty()) throw Error("joint frames are of one rig: leave rigs empty", at_field("poses.rigs"));
    if (joint_positions.size() % joint_count != 0)
      throw Error(
          fmt::format("{} positions is not a whole number of {}-joint characters", joint_positions.size(), joint_count),
          at_field("poses.joint_positions"));
    n = character_count();
    if (joint_rotations.size() != n * joint_count)
      throw Error(fmt::format("{} rotations for {} characters of {} joints", joint_rotations.size(), n, joint_count),
                  at_field("poses.joint_rotations"));
    if (!scales.empty() && scales.size() != n)
      throw Error(fmt::format("{} scales for {} characters", scales.size(), n), at_field("poses.scales"));
    const std::int32_t rig_joints = mode == RenderMode::Joints
                                        ? crowd.joints.joint_count
                                        : (crowd.skins.empty() ? 0 : crowd.skins.front().joint_count);
    if (mode == RenderMode::Joints && rig_joints == 0)
      throw Error("the renderer has no joint rig", at_field("render.mode"));
    if (mode == RenderMode::Skinned && crowd.skins.empty())
      throw Error("the renderer has no skinned mesh", at_field("render.mode"));
    if (rig_joints != joint_count)
      throw Error(fmt::format("{} joints, the rig has {}", joint_count, rig_joints), at_field("poses.joint_count"));
  } else if (from_refs()) {
    if (mode != RenderMode::Skinned)
      throw Error("palette references are drawn in skinned mode only", at_field("render.mode"));
    if (crowd.skins.empty()) throw Error("the renderer has no skinned mesh", at_field("render.mode"));
    if (!palettes.empty() || !palette_offsets.empty() || !rigs.empty() || !scales.empty())
      throw Error("give palette references or palettes, not both", at_field("poses.palette_refs"));
    n = character_count();
    if (root_positions.size() != n || root_yaws.size() != n)
      throw Error(
          fmt::format("{} root positions and {} yaws for {} characters", root_positions.size(), root_yaws.size(), n),
          at_field("poses.root_positions"));
  } else if (!palette_offsets.empty() || !palettes.empty()) {
    if (mode != RenderMode::Skinned) throw Error("palettes are drawn in skinned mode only", at_field("render.mode"));
    if (crowd.skins.empty()) throw Error("the renderer has no skinned mesh", at_field("render.mode"));
    if (!joint_positions.empty() || !joint_rotations.empty())
      throw Error("joint frames need joint_count > 0", at_field("poses.joint_count"));
    n = character_count();
    if (!rigs.empty() && rigs.size() != n)
      throw Error(fmt::format("{} rigs for {} characters (want 0 or {})", rigs.size(), n, n), at_field("poses.rigs"));
    if (!scales.empty()) throw Error("palettes hold their own scale: leave scales empty", at_field("poses.scales"));
  } else if (joint_count < 0 || !joint_positions.empty() || !joint_rotations.empty()) {
    throw Error("joint frames need joint_count > 0", at_field("poses.joint_count"));
  }
  if (!lod_levels.empty() && lod_levels.size() != n && lod_levels.size() != n * anim::kBodyPartCount)
    throw Error(fmt::format("{} levels for {} characters (want 0, {} or {})", lod_levels.size(), n, n,
                            n * anim::kBodyPartCount),
                at_field("poses.lod_levels"));
  if (!flags.empty() && flags.size() != n)
    throw Error(fmt::format("{} flags for {} characters", flags.size(), n), at_field("poses.flags"));
}

CharacterPoses poses_of(const anim::CrowdAnimator& crowd) {
  CharacterPoses p;
  p.joint_count = crowd.joint_count();
  p.joint_positions = crowd.joint_positions();
  p.joint_rotations = crowd.joint_rotations();
  p.scales = crowd.scales();
  if (crowd.last_frame().lod) p.lod_levels = crowd.lod_levels();  // levels of the last animate()
  return p;
}

CharacterPoses poses_of(const anim::CrowdAnimator& crowd, const sim::CrowdState& agents) {
  CharacterPoses p = poses_of(crowd);
  p.flags = agents.flags.span();
  p.visible_bits = sim::kAgentActive;
  return p;
}

CharacterPoses poses_of(const anim::StreamCrowd& crowd, Span<const anim::Mat3x4> palettes) {
  if (palettes.size() != crowd.palette_size())
    throw Error(fmt::format("{} matrices, the crowd needs {}", palettes.size(), crowd.palette_size()),
                at_field("poses.palettes"));
  CharacterPoses p;
  p.palettes = palettes;
  p.palette_offsets = crowd.palette_offsets();
  p.rigs = crowd.agent_rigs();
  return p;
}

CharacterPoses poses_of(const anim::LocomotionStreams& streams, const sim::CrowdState& agents) {
  CharacterPoses p;
  p.palette_refs = streams.palette_refs();
  p.root_positions = streams.positions();
  p.root_yaws = streams.yaws();
  p.flags = agents.flags.span();
  p.visible_bits = sim::kAgentActive;
  return p;
}

void BinsOverlay::validate() const {
  if (!(cell_size > 0.0f) || !std::isfinite(cell_size))
    throw Error("must be positive and finite", at_field("bins.cell_size"));
  if (columns < 0 || rows < 0 || static_cast<Index>(columns) * rows > (Index{1} << 26))
    throw Error(fmt::format("{} x {} cells is out of range", columns, rows), at_field("bins.columns"));
  if (counts.size() != static_cast<Index>(columns) * rows)
    throw Error(fmt::format("{} counts for {} x {} cells", counts.size(), columns, rows), at_field("bins.counts"));
  if (saturate_at < 1) throw Error("must be at least 1", at_field("bins.saturate_at"));
}

}  // namespace throng::render
