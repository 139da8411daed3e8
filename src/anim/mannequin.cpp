#include "anim/mannequin.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <fmt/format.h>

#include <string>

#include "core/error.h"
#include "core/math.h"
#include "motion/fk.h"

namespace throng::anim {

namespace {

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// One bone's capsule and the joints that weigh on it.
struct Bone {
  glm::vec3 a, b;
  float radius = 0.0f;
  std::int32_t driver = 0;  // rotates the bone
  std::int32_t at_a = -1;   // driver of the bone that ends at a (blended near a)
  std::int32_t at_b = -1;   // joint at b, whose rotation bends what follows (blended near b)
};

float smooth01(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x * x * (3.0f - 2.0f * x);
}

void add_capsule(SkinnedMesh& mesh, const Bone& bone, const MannequinOptions& o) {
  const glm::vec3 axis = bone.b - bone.a;
  const float len = glm::length(axis);
  const glm::vec3 u = axis / len;
  const glm::vec3 ref = std::abs(u.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  const glm::vec3 v = glm::normalize(glm::cross(u, ref));
  const glm::vec3 w = glm::cross(u, v);
  const float r = bone.radius;

  // Rings from the a pole to the b pole: (centre along u from a, ring radius, axial normal part).
  struct Ring {
    float h, rr, nu;
  };
  std::vector<Ring> rings;
  for (int i = 1; i <= o.cap_rings; ++i) {
    const float phi = -0.5f * kPiF + 0.5f * kPiF * static_cast<float>(i) / static_cast<float>(o.cap_rings);
    rings.push_back({r * std::sin(phi), r * std::cos(phi), std::sin(phi)});
  }
  for (int i = 1; i < o.body_rings - 1; ++i)
    rings.push_back({len * static_cast<float>(i) / static_cast<float>(o.body_rings - 1), r, 0.0f});
  for (int i = o.cap_rings; i >= 1; --i) {
    const float phi = 0.5f * kPiF - 0.5f * kPiF * static_cast<float>(i) / static_cast<float>(o.cap_rings);
    rings.push_back({len + r * std::sin(phi), r * std::cos(phi), std::sin(phi)});
  }

  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  auto add_vertex = [&](const glm::vec3& p, const glm::vec3& n) {
    mesh.positions.push_back(p);
    mesh.normals.push_back(glm::normalize(n));
    const float s = std::clamp(glm::dot(p - bone.a, u) / len, 0.0f, 1.0f);
    const float wb = bone.at_b >= 0 ? 0.5f * smooth01((s - (1.0f - o.blend)) / o.blend) : 0.0f;
    const float wa = bone.at_a >= 0 ? 0.5f * smooth01((o.blend - s) / o.blend) : 0.0f;
    mesh.joints.emplace_back(static_cast<std::uint16_t>(bone.driver),
                             static_cast<std::uint16_t>(bone.at_a >= 0 ? bone.at_a : 0),
                             static_cast<std::uint16_t>(bone.at_b >= 0 ? bone.at_b : 0), 0);
    mesh.weights.emplace_back(1.0f - wa - wb, wa, wb, 0.0f);
  };
  add_vertex(bone.a - r * u, -u);
  const int S = o.sides;
  for (const Ring& ring : rings)
    for (int k = 0; k < S; ++k) {
      const float alpha = 2.0f * kPiF * static_cast<float>(k) / static_cast<float>(S);
      const glm::vec3 radial = std::cos(alpha) * v + std::sin(alpha) * w;
      const float nr = std::sqrt(std::max(0.0f, 1.0f - ring.nu * ring.nu));
      add_vertex(bone.a + ring.h * u + ring.rr * radial, nr * radial + ring.nu * u);
    }
  add_vertex(bone.b + r * u, u);
  const auto top = static_cast<std::uint32_t>(mesh.positions.size() - 1);

  // Winds each triangle so its face normal points the way its vertex normals do.
  auto tri = [&](std::uint32_t i0, std::uint32_t i1, std::uint32_t i2) {
    const glm::vec3 n = glm::cross(mesh.positions[i1] - mesh.positions[i0], mesh.positions[i2] - mesh.positions[i0]);
    const glm::vec3 out = mesh.normals[i0] + mesh.normals[i1] + mesh.normals[i2];
    if (glm::dot(n, out) < 0.0f) std::swap(i1, i2);
    mesh.indices.insert(mesh.indices.end(), {i0, i1, i2});
  };
  auto ring_vertex = [&](std::size_t ring, int k) {
    return base + 1 + static_cast<std::uint32_t>(ring * S + static_cast<std::size_t>(k % S));
  };
  for (int k = 0; k < S; ++k) tri(base, ring_vertex(0, k), ring_vertex(0, k + 1));
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    for (int k = 0; k < S; ++k) {
      tri(ring_vertex(i, k), ring_vertex(i, k + 1), ring_vertex(i + 1, k + 1));
      tri(ring_vertex(i, k), ring_vertex(i + 1, k + 1), ring_vertex(i + 1, k));
    }
  for (int k = 0; k < S; ++k) tri(top, ring_vertex(rings.size() - 1, k), ring_vertex(rings.size() - 1, k + 1));
}

// Radius of the bone from joint p towards joint c (-1: p's end site).
float bone_radius(const motion::Skeleton& s, std::int32_t p, std::int32_t c, float len, float k) {
  using motion::Role;
  auto is = [&](std::int32_t j, std::initializer_list<Role> roles) {
    if (j < 0) return false;
    for (Role r : roles)
      if (s.role(r) == j) return true;
    return false;
  };
  auto in_spine = [&](std::int32_t j) {
    return std::find(s.spine_chain.begin(), s.spine_chain.end(), j) != s.spine_chain.end();
  };
  auto is_clavicle = [&](std::int32_t j) {
    for (Role r : {Role::LeftShoulder, Role::RightShoulder}) {
      const std::int32_t sh = s.role(r);
      if (sh > 0 && j >= 0 && s.parents[static_cast<std::size_t>(sh)] == j && !in_spine(j) && j != s.role(Role::Hips))
        return true;
    }
    return false;
  };
  if (is(p, {Role::Head})) return 0.1f * k;
  if (is(p, {Role::Neck})) return 0.05f * k;
  if (is(p, {Role::LeftThigh, Role::RightThigh})) return 0.07f * k;
  if (is(p, {Role::LeftKnee, Role::RightKnee})) return 0.05f * k;
  if (is(p, {Role::LeftAnkle, Role::RightAnkle})) return 0.04f * k;
  if (is(p, {Role::LeftToe, Role::RightToe})) return 0.03f * k;
  if (is(p, {Role::LeftShoulder, Role::RightShoulder})) return 0.045f * k;
  if (is(p, {Role::LeftElbow, Role::RightElbow})) return 0.038f * k;
  if (is(p, {Role::LeftWrist, Role::RightWrist}) && c < 0) return 0.03f * k;
  if (is(c, {Role::LeftThigh, Role::RightThigh})) return 0.08f * k;
  if (is(p, {Role::Hips}) || in_spine(p)) {
    if (is(c, {Role::Neck})) return 0.06f * k;
    if (in_spine(c)) return 0.11f * k;
    if (is_clavicle(c)) return 0.06f * k;
  }
  if (is_clavicle(p)) return 0.05f * k;
  return std::clamp(0.2f * len, 0.012f * k, 0.05f * k);
}

}  // namespace

void MannequinOptions::validate() const {
  auto bad = [](const char* field, const std::string& what) {
    throw Error(what, at_field(std::string("mannequin.") + field));
  };
  if (sides < 3 || sides > 64) bad("sides", "must be in [3, 64]");
  if (body_rings < 2 || body_rings > 64) bad("body_rings", "must be in [2, 64]");
  if (cap_rings < 1 || cap_rings > 32) bad("cap_rings", "must be in [1, 32]");
  if (!(blend > 0.0f && blend <= 0.5f)) bad("blend", "must be in (0, 0.5]");
  if (!(min_bone >= 0.0f && min_bone < 1.0f)) bad("min_bone", "must be in [0, 1)");
}

void SkinnedMesh::validate() const {
  const std::size_t n = positions.size();
  auto bad = [](const char* field, const std::string& what) {
    throw Error(what, at_field(std::string("mesh.") + field));
  };
  if (joint_count <= 0) bad("joint_count", "must be positive");
  if (normals.size() != n)
    bad("normals", "has " + std::to_string(normals.size()) + " entries, positions " + std::to_string(n));
  if (joints.size() != n)
    bad("joints", "has " + std::to_string(joints.size()) + " entries, positions " + std::to_string(n));
  if (weights.size() != n)
    bad("weights", "has " + std::to_string(weights.size()) + " entries, positions " + std::to_string(n));
  if (indices.size() % 3 != 0) bad("indices", "length is not a multiple of 3");
  for (std::size_t i = 0; i < n; ++i) {
    const std::string at = fmt::format("[{}]", i);
    if (!finite3(positions[i])) bad("positions", at + " is not finite");
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const float wk = weights[i][k];
      if (!(wk >= 0.0f && wk <= 1.0f)) bad("weights", at + " has a weight outside [0, 1]");
      if (wk > 0.0f && joints[i][k] >= joint_count)
        bad("joints", at + " names joint " + std::to_string(joints[i][k]) + " of " + std::to_string(joint_count));
      sum += wk;
    }
    if (std::abs(sum - 1.0f) > 1e-4f) bad("weights", at + " sums to " + std::to_string(sum) + ", not 1");
  }
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= n)
      bad("indices", "[" + std::to_string(i) + "] = " + std::to_string(indices[i]) + " is not a vertex");
}

SkinnedMesh make_mannequin(const motion::Skeleton& skeleton, const MannequinOptions& options) {
  options.validate();
  skeleton.validate();
  const std::int32_t J = skeleton.joint_count();
  std::vector<glm::quat> identity(static_cast<std::size_t>(J), glm::quat(1, 0, 0, 0));
  std::vector<glm::vec3> pos(static_cast<std::size_t>(J));
  std::vector<glm::quat> rot(static_cast<std::size_t>(J));
  motion::fk_pose(J, skeleton.parents.data(), skeleton.offsets.data(), identity.data(), nullptr, skeleton.offsets[0],
                  pos.data(), rot.data());

  float lo = pos[0].y, hi = pos[0].y;
  for (std::int32_t j = 0; j < J; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    lo = std::min(lo, pos[ju].y);
    hi = std::max(hi, pos[ju].y);
    if (skeleton.has_end_site[ju]) {
      const float y = (pos[ju] + skeleton.end_sites[ju]).y;
      lo = std::min(lo, y);
      hi = std::max(hi, y);
    }
  }
  const float height = hi - lo;
  const float k = height > 1e-3f ? height / 1.75f : 1.0f;

  SkinnedMesh mesh;
  mesh.joint_count = J;
  auto add_bone = [&](std::int32_t p, std::int32_t c, glm::vec3 b) {
    const glm::vec3 a = pos[static_cast<std::size_t>(p)];
    const float len = glm::length(b - a);
    if (!(len >= options.min_bone * k) || len <= 0.0f) return;
    Bone bone;
    bone.a = a;
    bone.b = b;
    bone.driver = p;
    bone.at_a = skeleton.parents[static_cast<std::size_t>(p)];
    bone.at_b = c;
    bone.radius = bone_radius(skeleton, p, c, len, k);
    add_capsule(mesh, bone, options);
  };
  for (std::int32_t j = 1; j < J; ++j)
    add_bone(skeleton.parents[static_cast<std::size_t>(j)], j, pos[static_cast<std::size_t>(j)]);
  for (std::int32_t j = 0; j < J; ++j)
    if (skeleton.has_end_site[static_cast<std::size_t>(j)])
      add_bone(j, -1, pos[static_cast<std::size_t>(j)] + skeleton.end_sites[static_cast<std::size_t>(j)]);
  if (mesh.positions.empty()) throw Error("skeleton has no bone long enough for a mannequin", at_field("mannequin"));
  return mesh;
}

}  // namespace throng::anim
