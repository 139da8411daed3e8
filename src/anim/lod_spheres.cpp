#include "anim/lod_spheres.h"

#include <algorithm>
#include <glm/geometric.hpp>
#include <string>

#include "core/error.h"

namespace throng::anim {

using motion::Role;
using motion::Skeleton;

const char* to_string(BodyPart p) {
  switch (p) {
    case BodyPart::LeftArm: return "left_arm";
    case BodyPart::RightArm: return "right_arm";
    case BodyPart::Torso: return "torso";
    case BodyPart::LeftLeg: return "left_leg";
    case BodyPart::RightLeg: return "right_leg";
  }
  return "unknown";
}

namespace {

std::size_t at(std::int32_t j) { return static_cast<std::size_t>(j); }

// Sum of bone lengths from the root down to each joint.
std::vector<float> root_distances(const Skeleton& s) {
  std::vector<float> d(at(s.joint_count()), 0.0f);
  for (std::int32_t j = 1; j < s.joint_count(); ++j) d[at(j)] = d[at(s.parents[at(j)])] + glm::length(s.offsets[at(j)]);
  return d;
}

std::int32_t common_ancestor(const Skeleton& s, std::int32_t a, std::int32_t b) {
  // Parents come before children, so the larger index is never the ancestor.
  while (a != b) {
    if (a > b)
      a = s.parents[at(a)];
    else
      b = s.parents[at(b)];
  }
  return a;
}

std::int32_t required_role(const Skeleton& s, Role r) {
  const std::int32_t j = s.role(r);
  if (j < 0 || j >= s.joint_count())
    throw Error(std::string("skeleton has no ") + motion::to_string(r) +
                    " joint, which LOD spheres need (name it as a role override)",
                at_field(std::string("roles.") + motion::to_string(r)));
  return j;
}

// The role's joint, else the parent of `child_role`'s joint.
std::int32_t role_or_parent(const Skeleton& s, Role r, Role child_role) {
  const std::int32_t j = s.role(r);
  if (j >= 0 && j < s.joint_count()) return j;
  return s.parents[at(required_role(s, child_role))];
}

bool is_descendant(const Skeleton& s, std::int32_t j, std::int32_t ancestor) {
  for (std::int32_t p = j; p >= 0; p = s.parents[at(p)])
    if (p == ancestor) return true;
  return false;
}

}  // namespace

float bone_path_length(const Skeleton& s, std::int32_t a, std::int32_t b) {
  const std::vector<float> d = root_distances(s);
  return d[at(a)] + d[at(b)] - 2.0f * d[at(common_ancestor(s, a, b))];
}

BodyParts make_body_parts(const Skeleton& s) {
  s.validate();
  const std::int32_t J = s.joint_count();
  BodyParts out;
  out.joint_count = J;
  const auto part_index = [](BodyPart p) { return static_cast<std::size_t>(p); };

  const std::int32_t hips = s.role(Role::Hips) >= 0 ? s.role(Role::Hips) : 0;
  const std::int32_t neck = s.role(Role::Neck) >= 0 ? s.role(Role::Neck) : required_role(s, Role::Head);
  const std::array<std::int32_t, kBodyPartCount> centre_joint = {
      required_role(s, Role::LeftElbow), required_role(s, Role::RightElbow), hips, required_role(s, Role::LeftKnee),
      required_role(s, Role::RightKnee)};
  out.part_root = {
      role_or_parent(s, Role::LeftShoulder, Role::LeftElbow), role_or_parent(s, Role::RightShoulder, Role::RightElbow),
      0, role_or_parent(s, Role::LeftThigh, Role::LeftKnee), role_or_parent(s, Role::RightThigh, Role::RightKnee)};

  // Limb subtrees must be disjoint and must not contain the skeleton root.
  out.part_of.assign(at(J), static_cast<std::uint8_t>(BodyPart::Torso));
  for (BodyPart p : kAllBodyParts) {
    if (p == BodyPart::Torso) continue;
    const std::int32_t root = out.part_root[part_index(p)];
    const std::string field = std::string("lod.parts.") + to_string(p);
    if (root <= 0) throw Error("a limb cannot start at the skeleton root", at_field(field));
    if (!is_descendant(s, centre_joint[part_index(p)], root))
      throw Error("its centre joint '" + s.names[at(centre_joint[part_index(p)])] + "' is not below its root joint '" +
                      s.names[at(root)] + "'",
                  at_field(field));
    for (std::int32_t j = root; j < J; ++j) {
      if (!is_descendant(s, j, root)) continue;
      if (out.part_of[at(j)] != static_cast<std::uint8_t>(BodyPart::Torso))
        throw Error("joint '" + s.names[at(j)] + "' is in two limbs (" +
                        to_string(static_cast<BodyPart>(out.part_of[at(j)])) + " and " + to_string(p) + ")",
                    at_field(field));
      out.part_of[at(j)] = static_cast<std::uint8_t>(p);
    }
  }
  if (out.part_of[at(hips)] != static_cast<std::uint8_t>(BodyPart::Torso) ||
      out.part_of[at(neck)] != static_cast<std::uint8_t>(BodyPart::Torso))
    throw Error("hips and neck must lie outside the arms and legs", at_field("lod.parts.torso"));

  out.depth.assign(at(J), 0);
  for (std::int32_t j = 0; j < J; ++j) {
    out.joints[out.part_of[at(j)]].push_back(j);
    const std::int32_t p = s.parents[at(j)];
    const bool part_root = p < 0 || out.part_of[at(p)] != out.part_of[at(j)];
    out.depth[at(j)] = part_root ? 0 : out.depth[at(p)] + 1;
  }

  // Radii: the worst tree-path bound over the part's joints and end sites.
  const std::vector<float> d = root_distances(s);
  const auto path = [&](std::int32_t a, std::int32_t b) {
    return d[at(a)] + d[at(b)] - 2.0f * d[at(common_ancestor(s, a, b))];
  };
  for (BodyPart p : kAllBodyParts) {
    SphereAnchor a;
    a.joint_a = centre_joint[part_index(p)];
    a.joint_b = p == BodyPart::Torso ? neck : a.joint_a;
    a.t = p == BodyPart::Torso ? 0.5f : 0.0f;
    float radius = 0.0f;
    for (std::int32_t j : out.joints[part_index(p)]) {
      // |mix(pa, pb, t) - x| <= (1 - t) |pa - x| + t |pb - x| (convexity of the norm).
      const float bound = (1.0f - a.t) * path(a.joint_a, j) + a.t * path(a.joint_b, j);
      const float tip = s.has_end_site[at(j)] ? glm::length(s.end_sites[at(j)]) : 0.0f;
      radius = std::max(radius, bound + tip);
    }
    a.radius = radius;
    out.anchors[part_index(p)] = a;
  }

  // Rest pose (all local rotations identity), root at the origin, then
  // shifted so the lowest joint or end site stands on y = 0.
  std::vector<glm::vec3> rest(at(J), glm::vec3(0.0f));
  float lowest = 0.0f;
  for (std::int32_t j = 0; j < J; ++j) {
    if (j > 0) rest[at(j)] = rest[at(s.parents[at(j)])] + s.offsets[at(j)];
    lowest = std::min(lowest, rest[at(j)].y);
    if (s.has_end_site[at(j)]) lowest = std::min(lowest, rest[at(j)].y + s.end_sites[at(j)].y);
  }
  for (BodyPart p : kAllBodyParts) {
    const SphereAnchor& a = out.anchors[part_index(p)];
    const glm::vec3 c = anchor_centre(a, rest.data()) - glm::vec3(0.0f, lowest, 0.0f);
    out.rest_spheres[part_index(p)] = glm::vec4(c, a.radius);
  }
  return out;
}

}  // namespace throng::anim
