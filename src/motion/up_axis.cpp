#include "motion/up_axis.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "motion/fk.h"

namespace throng::motion {

const char* to_string(UpAxis axis) { return axis == UpAxis::Z ? "z" : "y"; }

std::optional<UpAxis> parse_up_axis(std::string_view text) {
  if (text == "y" || text == "Y") return UpAxis::Y;
  if (text == "z" || text == "Z") return UpAxis::Z;
  return std::nullopt;
}

namespace {

// Feet to head (else hips) in frame 0 by roles; nullopt without them.
std::optional<glm::vec3> body_by_roles(const Skeleton& skeleton, const Clip& clip) {
  const std::int32_t left = skeleton.role(Role::LeftAnkle), right = skeleton.role(Role::RightAnkle);
  std::int32_t top = skeleton.role(Role::Head);
  if (top < 0) top = skeleton.role(Role::Neck);
  if (left < 0 || right < 0 || top < 0 || clip.frame_count < 1) return std::nullopt;
  // Frame 0 alone (not a copy of the whole clip).
  const auto J = static_cast<std::ptrdiff_t>(clip.joint_count);
  Clip first;
  first.joint_count = clip.joint_count;
  first.frame_count = 1;
  first.frame_time = clip.frame_time;
  first.rotations.assign(clip.rotations.begin(), clip.rotations.begin() + J);
  first.root_positions.assign(clip.root_positions.begin(), clip.root_positions.begin() + 1);
  if (!clip.translations.empty()) first.translations.assign(clip.translations.begin(), clip.translations.begin() + J);
  const ModelSpaceClip posed = forward_kinematics(skeleton, first);
  return posed.position(0, top) - 0.5f * (posed.position(0, left) + posed.position(0, right));
}

// The rest pose's extent along each axis (no sign: which end is the head
// is not known without roles).
glm::vec3 rest_extent(const Skeleton& skeleton) {
  const std::int32_t J = skeleton.joint_count();
  std::vector<glm::vec3> at(static_cast<std::size_t>(J), glm::vec3(0.0f));
  glm::vec3 lo(0.0f), hi(0.0f);
  for (std::int32_t j = 1; j < J; ++j) {
    const auto u = static_cast<std::size_t>(j);
    at[u] = at[static_cast<std::size_t>(skeleton.parents[u])] + skeleton.offsets[u];
    lo = glm::min(lo, at[u]);
    hi = glm::max(hi, at[u]);
  }
  return hi - lo;
}

}  // namespace

UpAxisGuess guess_up_axis(const Skeleton& skeleton, const Clip& clip) {
  UpAxisGuess g;
  const std::optional<glm::vec3> body = body_by_roles(skeleton, clip);
  if (!body) {
    g.body = rest_extent(skeleton);
    return g;
  }
  g.body = *body;
  g.from_roles = true;
  const glm::vec3 a = glm::abs(g.body);
  if (g.body.y > 0.0f && a.y >= 2.0f * a.x && a.y >= 2.0f * a.z) g.axis = UpAxis::Y;
  if (g.body.z > 0.0f && a.z >= 2.0f * a.x && a.z >= 2.0f * a.y) g.axis = UpAxis::Z;
  return g;
}

void z_up_to_y_up(Skeleton& skeleton, Clip& clip) {
  // -90 degrees about +X: (x, y, z) -> (x, z, -y).
  const glm::quat r = glm::angleAxis(-0.5f * 3.14159265358979f, glm::vec3(1.0f, 0.0f, 0.0f));
  const glm::quat r_inv = glm::conjugate(r);
  for (glm::vec3& o : skeleton.offsets) o = r * o;
  for (glm::vec3& e : skeleton.end_sites) e = r * e;
  for (glm::vec3& p : clip.root_positions) p = r * p;
  for (glm::vec3& t : clip.translations) t = r * t;
  for (glm::quat& q : clip.rotations) q = glm::normalize(r * q * r_inv);
}

}  // namespace throng::motion
