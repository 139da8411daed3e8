// A character's joint hierarchy: names, parents before children, rest offsets.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace throng::motion {

// Joints that LOD spheres, foot contacts and retargeting need, found by name
// (see find_roles) or set from an override table.
enum class Role : std::uint8_t {
  Hips,
  Neck,
  Head,
  LeftShoulder,  // upper arm joint (rotates the humerus)
  RightShoulder,
  LeftElbow,
  RightElbow,
  LeftWrist,
  RightWrist,
  LeftThigh,  // hip joint (rotates the femur)
  RightThigh,
  LeftKnee,
  RightKnee,
  LeftAnkle,
  RightAnkle,
  LeftToe,
  RightToe,
  Count
};
inline constexpr std::size_t kRoleCount = static_cast<std::size_t>(Role::Count);
const char* to_string(Role r);

struct Skeleton {
  std::vector<std::string> names;
  std::vector<std::int32_t> parents;  // parents[i] < i; the root's parent is -1
  std::vector<glm::vec3> offsets;     // rest offset from the parent, metres
  std::vector<glm::vec3> end_sites;   // end-site offset of a leaf, metres (zero if none)
  std::vector<std::uint8_t> has_end_site;
  std::array<std::int32_t, kRoleCount> roles;  // joint of each role, -1 when absent
  std::vector<std::int32_t> spine_chain;       // hips (excluded) up to neck (excluded)

  Skeleton() { roles.fill(-1); }
  std::int32_t joint_count() const { return static_cast<std::int32_t>(parents.size()); }
  std::int32_t find(std::string_view name) const;  // -1 when absent
  std::int32_t role(Role r) const { return roles[static_cast<std::size_t>(r)]; }
  // Appends a joint; parent must already exist (or be -1 for the root).
  std::int32_t add_joint(std::string name, std::int32_t parent, glm::vec3 offset);
  // Throws Error when parents are not ordered or arrays disagree in length.
  void validate() const;
};

}  // namespace throng::motion
