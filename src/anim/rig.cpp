#include "anim/rig.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "motion/fk.h"

namespace throng::anim {

std::int32_t ClusterLayout::find(const std::string& name) const {
  for (std::size_t c = 0; c < clusters.size(); ++c)
    if (clusters[c].name == name) return static_cast<std::int32_t>(c);
  return -1;
}

std::vector<std::int32_t> ClusterLayout::joints_of(std::int32_t cluster) const {
  std::vector<std::int32_t> out;
  for (std::size_t j = 0; j < cluster_of_joint.size(); ++j)
    if (cluster_of_joint[j] == cluster) out.push_back(static_cast<std::int32_t>(j));
  return out;
}

ClusterLayout make_cluster_layout(const motion::Skeleton& skeleton, std::vector<ClusterDef> clusters) {
  const std::int32_t J = skeleton.joint_count();
  if (clusters.empty()) throw Error("at least one cluster is needed", at_field("clusters"));
  if (static_cast<std::int32_t>(clusters.size()) > kMaxClusters)
    throw Error("at most " + std::to_string(kMaxClusters) + " clusters per rig, got " + std::to_string(clusters.size()),
                at_field("clusters"));
  constexpr std::int32_t kNone = -1;
  std::vector<std::int32_t> root_cluster(static_cast<std::size_t>(J), kNone);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const std::string field = "clusters[" + std::to_string(c) + "]";
    if (clusters[c].name.empty()) throw Error("a cluster needs a name", at_field(field + ".name"));
    for (std::size_t d = 0; d < c; ++d)
      if (clusters[d].name == clusters[c].name)
        throw Error("cluster name '" + clusters[c].name + "' used twice", at_field(field + ".name"));
    if (clusters[c].roots.empty()) throw Error("a cluster needs at least one root joint", at_field(field + ".roots"));
    const glm::quat& q = clusters[c].hook_rotation;
    const glm::vec3& t = clusters[c].hook_translation;
    if (!std::isfinite(q.w) || !std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) ||
        std::abs(glm::length(q) - 1.0f) > 1e-3f)
      throw Error("must be a finite unit quaternion", at_field(field + ".hook_rotation"));
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z))
      throw Error("must be finite", at_field(field + ".hook_translation"));
    for (std::size_t k = 0; k < clusters[c].roots.size(); ++k) {
      const std::string& name = clusters[c].roots[k];
      const std::int32_t j = skeleton.find(name);
      const std::string rf = field + ".roots[" + std::to_string(k) + "]";
      if (j < 0) throw Error("no joint named '" + name + "' in the skeleton", at_field(rf));
      if (root_cluster[static_cast<std::size_t>(j)] != kNone)
        throw Error("joint '" + name + "' is the root of two clusters", at_field(rf));
      root_cluster[static_cast<std::size_t>(j)] = static_cast<std::int32_t>(c);
    }
  }
  if (root_cluster[0] == kNone)
    throw Error("the skeleton's root joint '" + skeleton.names[0] + "' must be a root of some cluster",
                at_field("clusters"));
  ClusterLayout out;
  out.cluster_of_joint.resize(static_cast<std::size_t>(J));
  for (std::int32_t j = 0; j < J; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const std::int32_t c = root_cluster[ju] != kNone
                               ? root_cluster[ju]
                               : out.cluster_of_joint[static_cast<std::size_t>(skeleton.parents[ju])];
    out.cluster_of_joint[ju] = static_cast<std::uint8_t>(c);
  }
  out.hook_joint.assign(clusters.size(), -1);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const std::int32_t first = skeleton.find(clusters[c].roots[0]);
    out.hook_joint[c] = skeleton.parents[static_cast<std::size_t>(first)];
    if (std::none_of(out.cluster_of_joint.begin(), out.cluster_of_joint.end(), [&](std::uint8_t v) { return v == c; }))
      throw Error("cluster '" + clusters[c].name + "' owns no joint (its roots lie inside other clusters' roots only)",
                  at_field("clusters[" + std::to_string(c) + "]"));
  }
  for (std::int32_t j = 0; j < J; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const std::int32_t p = skeleton.parents[ju];
    if (p < 0 || out.cluster_of_joint[static_cast<std::size_t>(p)] != out.cluster_of_joint[ju]) {
      if (static_cast<std::int32_t>(out.segment_roots.size()) >= kMaxSegments)
        throw Error("at most " + std::to_string(kMaxSegments) + " cluster roots per rig", at_field("clusters"));
      out.segment_of_joint.push_back(static_cast<std::uint8_t>(out.segment_roots.size()));
      out.segment_roots.push_back(j);
    } else {
      out.segment_of_joint.push_back(out.segment_of_joint[static_cast<std::size_t>(p)]);
    }
  }
  out.clusters = std::move(clusters);
  return out;
}

std::vector<ClusterDef> default_cluster_defs(const motion::Skeleton& skeleton) {
  using motion::Role;
  const std::int32_t hips = skeleton.role(Role::Hips);
  const std::int32_t neck = skeleton.role(Role::Neck);
  const auto& names = skeleton.names;
  if (hips < 0 || neck < 0 || neck == hips) return {ClusterDef{"body", {names[0]}, {1, 0, 0, 0}, glm::vec3(0.0f)}};
  // The upper body starts at the child of the hips on the way to the neck.
  std::int32_t upper = neck;
  while (upper >= 0 && skeleton.parents[static_cast<std::size_t>(upper)] != hips)
    upper = skeleton.parents[static_cast<std::size_t>(upper)];
  std::vector<ClusterDef> out;
  out.push_back({"lower", {names[0]}, {1, 0, 0, 0}, glm::vec3(0.0f)});
  if (upper >= 0 && upper != neck)
    out.push_back({"upper", {names[static_cast<std::size_t>(upper)]}, {1, 0, 0, 0}, glm::vec3(0.0f)});
  out.push_back({"head", {names[static_cast<std::size_t>(neck)]}, {1, 0, 0, 0}, glm::vec3(0.0f)});
  return out;
}

Pose Rig::rest_pose() const {
  Pose p(joint_count());
  p.root = skeleton.offsets.empty() ? glm::vec3(0.0f) : skeleton.offsets[0];
  return p;
}

void PoseKinematics::palette(const Pose& pose, Mat3x4* out) const {
  const auto J = static_cast<std::int32_t>(parents.size());
  if (J > kMaxRigJoints || pose.joint_count() != J)
    throw Error("pose and skeleton differ in joint count", at_field("pose"));
  glm::vec3 positions[kMaxRigJoints];
  glm::quat rotations[kMaxRigJoints];
  motion::fk_pose(J, parents.data(), offsets.data(), pose.local.data(), nullptr, pose.root, positions, rotations);
  for (std::int32_t j = 0; j < J; ++j)
    out[j] = mat3x4_from(rotations[j], positions[j]) * inverse_bind[static_cast<std::size_t>(j)];
}

PoseKinematics Rig::kinematics() const { return {skeleton.parents, skeleton.offsets, inverse_bind}; }

Rig make_rig(std::string name, motion::Skeleton skeleton, std::vector<ClusterDef> clusters) {
  SkinnedMesh mesh = make_mannequin(skeleton);
  return make_rig(std::move(name), std::move(skeleton), std::move(clusters), std::move(mesh));
}

Rig make_rig(std::string name, motion::Skeleton skeleton, std::vector<ClusterDef> clusters, SkinnedMesh mesh) {
  skeleton.validate();
  const std::int32_t J = skeleton.joint_count();
  if (J > kMaxRigJoints)
    throw Error("rig '" + name + "': skeleton has " + std::to_string(J) + " joints, at most " +
                    std::to_string(kMaxRigJoints) + " are supported",
                at_field("skeleton"));
  mesh.validate();
  if (mesh.joint_count != J)
    throw Error("mesh is bound to " + std::to_string(mesh.joint_count) + " joints, skeleton has " + std::to_string(J),
                at_field("mesh"));
  Rig rig;
  rig.name = std::move(name);
  if (clusters.empty()) clusters = default_cluster_defs(skeleton);
  rig.clusters = make_cluster_layout(skeleton, std::move(clusters));
  rig.skeleton = std::move(skeleton);
  const Pose rest = rig.rest_pose();
  rig.bind_positions.resize(static_cast<std::size_t>(J));
  rig.bind_rotations.resize(static_cast<std::size_t>(J));
  motion::fk_pose(J, rig.skeleton.parents.data(), rig.skeleton.offsets.data(), rest.local.data(), nullptr, rest.root,
                  rig.bind_positions.data(), rig.bind_rotations.data());
  rig.inverse_bind.resize(static_cast<std::size_t>(J));
  for (std::size_t j = 0; j < static_cast<std::size_t>(J); ++j)
    rig.inverse_bind[j] = inverse_rigid(rig.bind_rotations[j], rig.bind_positions[j]);
  rig.mesh = std::move(mesh);
  return rig;
}

}  // namespace throng::anim
