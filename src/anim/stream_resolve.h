// The per-agent kernels of a stream crowd (anim/stream_crowd.h drives them):
// applying transition commands (one by one, or a desired stream per agent in
// a batch), delivering events, and resolving every agent's palette from
// (source, offset) pairs.
#pragma once

#include <array>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "anim/controller.h"
#include "anim/pose.h"
#include "anim/rig.h"
#include "anim/stream_pool.h"
#include "core/config.h"
#include "core/span.h"

namespace throng::anim {

// Source ids in a ClusterRef: a stream index (>= 0), a unique instance
// (-2 - instance), or none (-1: the rig's rest pose).
inline constexpr std::int32_t kNoSource = -1;
THRONG_HOST_DEVICE inline std::int32_t unique_source(std::int32_t instance) { return -2 - instance; }
THRONG_HOST_DEVICE inline bool is_unique_source(std::int32_t source) { return source <= -2; }
THRONG_HOST_DEVICE inline std::int32_t unique_instance(std::int32_t source) { return -2 - source; }

inline constexpr std::uint32_t kClusterCulled = 1u;  // the cluster is not drawn (palette collapsed to its hook)
inline constexpr std::int32_t kNeverRead = -2147483647 - 1;

// One agent's cluster (32 bytes): where its joints come from.
struct ClusterRef {
  std::int32_t source = kNoSource;       // target source
  std::int32_t offset = 0;               // frames behind the source's newest pose (before dilation)
  std::int32_t from_source = kNoSource;  // transition source, blended out
  std::int32_t from_offset = 0;
  std::int32_t t0 = 0;                  // frame the transition started
  float blend_frames = 0.0f;            // <= 0: no transition
  std::int32_t last_read = kNeverRead;  // frame number of the source last read (events)
  std::uint32_t flags = 0;              // kClusterCulled
};

// alpha = clamp((t - t0) / T, 0, 1), with times in animation frames.
THRONG_HOST_DEVICE inline float transition_alpha(const ClusterRef& c, std::int32_t frame) {
  if (c.blend_frames <= 0.0f) return 1.0f;
  const float a = static_cast<float>(frame - c.t0) / c.blend_frames;
  return a < 0.0f ? 0.0f : (a > 1.0f ? 1.0f : a);
}

enum class OverrideKind : std::uint8_t {
  Rotation,  // the joint's local rotation becomes slerp(history, rotation, weight)
  LookAt,    // the joint turns (at most max_angle, times weight) so aim_axis points at target
};

// A per-agent custom bone transform (48 bytes on the device).
struct BoneOverride {
  std::int32_t joint = -1;
  OverrideKind kind = OverrideKind::Rotation;
  float weight = 1.0f;
  float max_angle = 1.2f;                      // radians, LookAt
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // Rotation
  glm::vec3 target{0.0f};                // LookAt: world point (model space when resolve gets no agent transforms)
  glm::vec3 aim_axis{0.0f, 0.0f, 1.0f};  // LookAt: in the joint's bind frame (+Z: where the rig faces)
};

// Rigs concatenated without padding: rig r's joints are
// [joint_base, joint_base + joint_count) of the joint tables, its clusters
// [cluster_base, cluster_base + cluster_count) of the cluster tables.
struct RigView {
  Index joint_base = 0;
  std::int32_t joint_count = 0;
  std::int32_t cluster_base = 0;
  std::int32_t cluster_count = 0;
  std::int32_t segment_base = 0;
  std::int32_t segment_count = 0;
  glm::vec3 rest_root{0.0f};
};

struct RigTablesView {
  Span<const RigView> rigs;
  Span<const std::int32_t> parents;        // rig-local parent index per joint
  Span<const glm::vec3> offsets;           // rest offsets
  Span<const std::uint8_t> joint_cluster;  // cluster of each joint (rig-local)
  Span<const Mat3x4> inverse_bind;
  Span<const glm::quat> hook_rotations;  // per rig cluster
  Span<const glm::vec3> hook_translations;
  Span<const std::int32_t> hook_joints;    // per rig cluster, rig-local, -1 for the root's cluster
  Span<const std::uint8_t> joint_segment;  // segment of each joint (rig-local, ClusterLayout::segment_of_joint)
  Span<const Mat3x4> segment_hooks;        // per rig segment: B_p * hook * B_p^-1, p its root's parent, B = bind
  Span<const glm::vec3> bind_positions;    // per joint, model space
};

// One transition or assignment for one (agent, cluster).
struct ClusterCommand {
  Index agent = 0;
  std::int32_t cluster = 0;
  std::int32_t source = -1;
  std::int32_t offset = 0;  // < 0: match another cluster of the agent on the same source, else fallback_offset
  std::int32_t fallback_offset = 0;
  float blend_frames = 0.0f;    // <= 0: instant
  std::int32_t transition = 0;  // 0: assign (drops any transition), 1: transition from the current target
};

// Commands sorted by agent; groups[g] is the first command of the g-th
// agent that has any (groups has one more entry, the end). One thread per
// agent applies its commands in order ("anim.stream_commands").
struct StreamCommandJob {
  Span<const ClusterCommand> commands;
  Span<const Index> groups;
  Span<ClusterRef> clusters;
  std::int32_t cluster_stride = 1;
  std::int32_t frame = 0;
  void validate() const;  // Error naming the field
  void run() const;
};

// The batch form of transition_to_streamed, for a whole crowd at once
// ("anim.stream_retarget", one thread per agent): per agent a desired
// stream and offset for the clusters in cluster_mask (e.g. locomotion
// choosing every agent's stream by its speed each frame). Per cluster:
// * a cluster on a unique instance is left alone (host transitions own it);
// * the same stream at another offset takes the offset at once;
// * another stream is blended in over blend_frames (alpha as above, from
//   `frame`) when the cluster is on a stream now, else set at once;
// * a desired source of kNoSource sets the rest pose at once (an agent
//   posed elsewhere, e.g. by exact synthesis).
// sources[a] < kNoSource, a stream out of range or of another rig leave
// agent a alone; offsets are clamped to the stream's history. changed[a]
// (optional) is 1 when some cluster of agent a changed source.
struct StreamRetargetJob {
  Span<const std::int32_t> sources;  // per agent
  Span<const std::int32_t> offsets;  // per agent
  Span<const SourceView> streams;
  Span<const RigView> rigs;
  Span<const std::int32_t> agent_rigs;
  Span<ClusterRef> clusters;
  std::int32_t cluster_stride = 1;
  std::uint32_t cluster_mask = ~0u;  // bit c: cluster c follows
  std::int32_t frame = 0;
  float blend_frames = 0.0f;
  Span<std::uint8_t> changed;  // per agent, or empty

  Index agent_count() const { return agent_rigs.size(); }
  void validate() const;
  void run() const;
};

// Per agent, the OR over its clusters of the events its sources fired in
// the frames read since the last step (each cluster filtered by
// cluster_event_filter[cluster index]); updates ClusterRef::last_read
// ("anim.stream_events").
struct StreamEventsJob {
  Span<const SourceView> streams;
  Span<const SourceView> uniques;
  Span<const RigView> rigs;
  Span<const std::int32_t> agent_rigs;
  Span<ClusterRef> clusters;
  std::int32_t cluster_stride = 1;
  std::array<EventMask, kMaxClusters> cluster_event_filter{};
  Span<EventMask> out_events;  // per agent
  void validate() const;       // Error naming the field
  void run() const;
};

// Every agent's palette ("anim.stream_resolve"). An agent with no
// transition running and no override takes the fast path: per joint one
// 3x4 product of its segment's transform with the skinning matrix its
// source slot already holds (W_seg = world for the root's segment, and
// palette_p * B_p * hook * B_p^-1 * S_p^-1 where a cluster root hangs from
// joint p). Otherwise, per joint: the local rotation of its cluster's
// (source, offset) slot, SLERPed from the transition source by alpha,
// custom overrides applied; forward kinematics through the cluster hooks;
// times the agent's world transform and the inverse bind matrix. Both give
// world(a) * model_j * inverse_bind_j. Culled clusters' joints then collapse
// onto their hook.
struct StreamResolveJob {
  RigTablesView tables;
  Span<const SourceView> streams;
  Span<const SourceView> uniques;
  Span<const std::int32_t> agent_rigs;
  Span<const Index> palette_offsets;
  Span<const ClusterRef> clusters;
  std::int32_t cluster_stride = 1;
  Span<const std::int32_t> override_begin;  // agents + 1, or empty
  Span<const BoneOverride> overrides;
  Span<const glm::vec3> positions;  // agents, or empty (model space)
  Span<const float> yaws;           // agents, or empty
  std::int32_t frame = 0;
  Span<Mat3x4> palettes;
  Span<std::int32_t> read_offsets;  // agents * cluster_stride, or empty
  Span<const std::uint8_t> skip;    // per agent, or empty: agents != 0 are posed elsewhere and not written

  Index agent_count() const { return agent_rigs.size(); }
  void validate() const;  // Error naming the field
  void run() const;
};

}  // namespace throng::anim
