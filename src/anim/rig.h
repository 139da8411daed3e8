// A rig: what an animation stream is defined over. A skeleton, its part
// clusters (lower body, upper body, head...), its bind pose with inverse
// bind matrices, and the mesh bound to it (the mannequin by default).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "anim/mannequin.h"
#include "anim/pose.h"
#include "motion/skeleton.h"

namespace throng::anim {

// The resolve kernel keeps a skeleton's frames on the stack.
inline constexpr std::int32_t kMaxRigJoints = 128;
inline constexpr std::int32_t kMaxClusters = 8;
// Cluster root subtrees per rig (a cluster may have several roots).
inline constexpr std::int32_t kMaxSegments = 32;

// A part cluster: the subtrees of its root joints, minus the subtrees of
// other clusters' roots below them. Its joints are animated by whatever
// (stream, offset) the agent's cluster points at; the cluster hangs from its
// hook joint (the parent of its roots, in another cluster) through the hook
// transform, applied in the hook joint's frame.
struct ClusterDef {
  std::string name;
  std::vector<std::string> roots;  // joint names
  glm::quat hook_rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 hook_translation{0.0f};
};

struct ClusterLayout {
  std::vector<ClusterDef> clusters;
  std::vector<std::uint8_t> cluster_of_joint;  // per joint
  std::vector<std::int32_t> hook_joint;        // per cluster: parent of its first root, -1 for the root cluster
  // Segments: the subtree of each cluster root within its cluster. Segment
  // 0 starts at the skeleton's root; a joint is in its parent's segment
  // unless it is a cluster root.
  std::vector<std::uint8_t> segment_of_joint;  // per joint
  std::vector<std::int32_t> segment_roots;     // per segment: its root joint

  std::int32_t count() const { return static_cast<std::int32_t>(clusters.size()); }
  std::int32_t find(const std::string& name) const;  // -1 when absent
  std::vector<std::int32_t> joints_of(std::int32_t cluster) const;
};

// Assigns every joint to the cluster of its nearest ancestor (or itself)
// that is a cluster root. Throws Error naming "clusters[i].roots[k]" for an
// unknown joint or a root listed twice, "clusters" when the skeleton's root
// is in no cluster, when a cluster owns no joint, or when there are more than
// kMaxClusters clusters, kMaxSegments roots, or duplicate names.
ClusterLayout make_cluster_layout(const motion::Skeleton& skeleton, std::vector<ClusterDef> clusters);

// lower (the root, hips and legs), upper (spine, arms; from the first spine
// joint, or the neck's parent chain) and head (from the neck role). Without
// hips and neck roles: one cluster "body".
std::vector<ClusterDef> default_cluster_defs(const motion::Skeleton& skeleton);

// What turns a pose into a model-space skinning palette: forward
// kinematics, then each joint's inverse bind matrix.
struct PoseKinematics {
  std::vector<std::int32_t> parents;
  std::vector<glm::vec3> offsets;
  std::vector<Mat3x4> inverse_bind;
  // out[j] = model_j * inverse_bind_j, pose.joint_count() entries.
  void palette(const Pose& pose, Mat3x4* out) const;
};

struct Rig {
  std::string name;
  motion::Skeleton skeleton;
  ClusterLayout clusters;
  std::vector<glm::vec3> bind_positions;  // model space, rest pose
  std::vector<glm::quat> bind_rotations;  // model space (identity for a rest pose)
  std::vector<Mat3x4> inverse_bind;       // per joint: model space -> joint space at bind
  SkinnedMesh mesh;                       // the mesh binding

  std::int32_t joint_count() const { return skeleton.joint_count(); }
  Pose rest_pose() const;  // identity rotations, root at the skeleton's root offset
  PoseKinematics kinematics() const;
};

// Validates the skeleton (parents before children, at most kMaxRigJoints),
// lays out the clusters (default_cluster_defs when empty) and computes the
// bind pose; the mesh is make_mannequin(skeleton) unless given.
Rig make_rig(std::string name, motion::Skeleton skeleton, std::vector<ClusterDef> clusters = {});
Rig make_rig(std::string name, motion::Skeleton skeleton, std::vector<ClusterDef> clusters, SkinnedMesh mesh);

}  // namespace throng::anim
