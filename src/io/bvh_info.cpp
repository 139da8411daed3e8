#include "io/bvh_info.h"

#include <algorithm>
#include <glm/common.hpp>
#include <map>

namespace throng::io {

namespace {
// Largest side of the rest pose's bounding box (joints and end sites).
double rest_extent(const motion::Skeleton& s) {
  const std::size_t J = s.offsets.size();
  std::vector<glm::dvec3> at(J);
  glm::dvec3 lo(0.0), hi(0.0);
  for (std::size_t j = 0; j < J; ++j) {
    const std::int32_t p = s.parents[j];
    at[j] = (p >= 0 ? at[static_cast<std::size_t>(p)] : glm::dvec3(0.0)) + glm::dvec3(s.offsets[j]);
    lo = glm::min(lo, at[j]);
    hi = glm::max(hi, at[j]);
    if (s.has_end_site[j]) {
      lo = glm::min(lo, at[j] + glm::dvec3(s.end_sites[j]));
      hi = glm::max(hi, at[j] + glm::dvec3(s.end_sites[j]));
    }
  }
  const glm::dvec3 d = hi - lo;
  return std::max(d.x, std::max(d.y, d.z));
}
}  // namespace

nlohmann::json bvh_info(const BvhFile& b) {
  using nlohmann::json;
  const motion::Skeleton& s = b.skeleton;
  std::map<std::string, int> orders;
  json skeleton = json::array();
  for (std::int32_t j = 0; j < s.joint_count(); ++j) {
    const std::string order = b.rotation_order(j);
    ++orders[order.empty() ? "none" : order];
    const std::int32_t p = s.parents[static_cast<std::size_t>(j)];
    skeleton.push_back({{"name", s.names[static_cast<std::size_t>(j)]},
                        {"parent", p >= 0 ? json(s.names[static_cast<std::size_t>(p)]) : json(nullptr)},
                        {"channels", b.channel_list(j)}});
  }
  json roles = json::object();
  for (std::size_t r = 0; r < motion::kRoleCount; ++r) {
    const std::int32_t j = s.roles[r];
    roles[motion::to_string(static_cast<motion::Role>(r))] =
        j >= 0 ? json(s.names[static_cast<std::size_t>(j)]) : json(nullptr);
  }
  json spine = json::array();
  for (std::int32_t j : s.spine_chain) spine.push_back(s.names[static_cast<std::size_t>(j)]);
  return {{"file", b.name},
          {"bytes", b.bytes},
          {"joints", s.joint_count()},
          {"end_sites", b.end_site_count},
          {"channels", b.channel_count()},
          {"frames", b.clip.frame_count},
          {"frame_time", b.frame_time},
          {"frame_rate", 1.0 / b.frame_time},
          {"duration", static_cast<double>(b.clip.frame_count) * b.frame_time},
          {"units",
           {{"unit", motion::to_string(b.unit)},
            {"detected", b.unit_detected},
            {"metres_per_unit", motion::metres_per_unit(b.unit)}}},
          {"rest_extent_m", rest_extent(s)},
          {"rotation_orders", orders},
          {"roles", roles},
          {"spine_chain", spine},
          {"skeleton", skeleton}};
}

}  // namespace throng::io
