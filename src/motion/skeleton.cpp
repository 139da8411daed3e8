#include "motion/skeleton.h"

#include <string>

#include "core/error.h"
#include "motion/clip.h"

namespace throng::motion {

const char* to_string(Role r) {
  static constexpr const char* kNames[kRoleCount] = {
      "hips",        "neck",       "head",        "left_shoulder", "right_shoulder", "left_elbow",
      "right_elbow", "left_wrist", "right_wrist", "left_thigh",    "right_thigh",    "left_knee",
      "right_knee",  "left_ankle", "right_ankle", "left_toe",      "right_toe"};
  const auto i = static_cast<std::size_t>(r);
  return i < kRoleCount ? kNames[i] : "unknown";
}

std::int32_t Skeleton::find(std::string_view name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<std::int32_t>(i);
  return -1;
}

std::int32_t Skeleton::add_joint(std::string name, std::int32_t parent, glm::vec3 offset) {
  if (parent < -1 || parent >= joint_count()) throw Error("joint '" + name + "': parent index out of range");
  names.push_back(std::move(name));
  parents.push_back(parent);
  offsets.push_back(offset);
  end_sites.emplace_back(0.0f);
  has_end_site.push_back(0);
  return joint_count() - 1;
}

void Skeleton::validate() const {
  const std::size_t n = parents.size();
  if (names.size() != n || offsets.size() != n || end_sites.size() != n || has_end_site.size() != n)
    throw Error("skeleton arrays differ in length");
  if (n == 0) throw Error("skeleton has no joints");
  if (parents[0] != -1) throw Error("joint 0 must be the root (parent -1)");
  for (std::size_t i = 1; i < n; ++i)
    if (parents[i] < 0 || parents[i] >= static_cast<std::int32_t>(i))
      throw Error("joint '" + names[i] + "' (index " + std::to_string(i) + ") must come after its parent");
}

void Clip::resize(std::int32_t frames, std::int32_t joints) {
  frame_count = frames;
  joint_count = joints;
  rotations.assign(static_cast<std::size_t>(frames) * static_cast<std::size_t>(joints), glm::quat(1, 0, 0, 0));
  root_positions.assign(static_cast<std::size_t>(frames), glm::vec3(0.0f));
  translations.clear();
}

}  // namespace throng::motion
