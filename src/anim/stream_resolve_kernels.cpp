#include <string>

#include "anim/stream_resolve.h"
#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"
#include "motion/phase.h"

namespace throng::anim {

namespace {

// Where one cluster's joints come from this frame.
struct SlotRead {
  const glm::quat* rotations;  // null: the rest pose (identity rotations)
  const Mat3x4* skinning;      // null: the rest pose (identity matrices)
  glm::vec3 root;
  std::int32_t offset;  // effective offset read, -1 for none
  // Spelled out: with default member initialisers, nvcc 13 stops with an
  // internal error ("Invalid bitcast") on the arrays of AgentPose below.
  THRONG_HOST_DEVICE SlotRead() : rotations(nullptr), skinning(nullptr), root(0.0f), offset(-1) {}
};

// The view of a source id, or null for none (or an id out of range).
// Spans by reference: copying a non-const Span lvalue would pick Span's
// host-only container constructor under nvcc.
THRONG_HOST_DEVICE inline const SourceView* find_source(const Span<const SourceView>& streams,
                                                        const Span<const SourceView>& uniques, std::int32_t source) {
  if (source >= 0 && source < streams.size()) return &streams[source];
  if (is_unique_source(source) && unique_instance(source) < uniques.size()) return &uniques[unique_instance(source)];
  return nullptr;
}

THRONG_HOST_DEVICE inline SlotRead read_source(const Span<const SourceView>& streams,
                                               const Span<const SourceView>& uniques, std::int32_t source,
                                               std::int32_t offset, std::int32_t joints, glm::vec3 rest_root) {
  SlotRead r;
  r.root = rest_root;
  const SourceView* v = find_source(streams, uniques, source);
  if (v == nullptr || v->joints != joints || v->rotations == nullptr) return r;
  const std::int32_t slot = history_slot(*v, offset);
  r.rotations = v->rotations + static_cast<Index>(slot) * joints;
  if (v->skinning != nullptr) r.skinning = v->skinning + static_cast<Index>(slot) * joints;
  r.root = v->roots[slot];
  r.offset = effective_offset(*v, offset);
  return r;
}

struct EventFilter {
  EventMask allowed[kMaxClusters];
};

}  // namespace

// ---- commands -----------------------------------------------------------------

void StreamCommandJob::validate() const {
  if (cluster_stride < 1 || cluster_stride > kMaxClusters)
    throw Error("must be in [1, 8]", at_field("StreamCommandJob.cluster_stride"));
  if (groups.empty())
    throw Error("needs at least one entry (the end of the last group)", at_field("StreamCommandJob.groups"));
}

void StreamCommandJob::run() const {
  validate();
  parallel_for(
      "anim.stream_commands", groups.size() - 1,
      THRONG_JOB_LAMBDA(Index g) {
        for (Index k = groups[g]; k < groups[g + 1]; ++k) {
          const ClusterCommand& c = commands[k];
          ClusterRef* agent = clusters.data() + c.agent * cluster_stride;
          ClusterRef& ref = agent[c.cluster];
          std::int32_t offset = c.offset;
          if (offset < 0) {
            offset = c.fallback_offset;
            for (std::int32_t o = 0; o < cluster_stride; ++o)
              if (o != c.cluster && agent[o].source == c.source) {
                offset = agent[o].offset;
                break;
              }
          }
          if (c.transition != 0 && c.blend_frames > 0.0f) {
            ref.from_source = ref.source;
            ref.from_offset = ref.offset;
            ref.t0 = frame;
            ref.blend_frames = c.blend_frames;
          } else {
            ref.from_source = kNoSource;
            ref.from_offset = 0;
            ref.blend_frames = 0.0f;
          }
          ref.source = c.source;
          ref.offset = offset;
          ref.last_read = kNeverRead;
        }
      },
      256);
}

// ---- batch retargeting ------------------------------------------------------------

namespace {

// Points agent a's clusters (those in the job's mask, of the first
// `count`, never a unique source's) at (source, offset), starting a
// transition where a cluster changes source; returns 1 if one changed.
THRONG_HOST_DEVICE inline std::uint8_t retarget_clusters(const StreamRetargetJob& job, Index a, std::int32_t source,
                                                         std::int32_t offset, std::int32_t count) {
  std::uint8_t changed = 0;
  const std::int32_t stride = job.cluster_stride;
  count = count < stride ? count : stride;
  for (std::int32_t c = 0; c < count; ++c) {
    if (((job.cluster_mask >> c) & 1u) == 0u) continue;
    ClusterRef& ref = job.clusters[a * stride + c];
    if (is_unique_source(ref.source)) continue;
    if (ref.source == source) {
      ref.offset = offset;
      continue;
    }
    if (source >= 0 && ref.source >= 0 && job.blend_frames > 0.0f) {
      ref.from_source = ref.source;
      ref.from_offset = ref.offset;
      ref.t0 = job.frame;
      ref.blend_frames = job.blend_frames;
    } else {
      ref.from_source = kNoSource;
      ref.from_offset = 0;
      ref.blend_frames = 0.0f;
    }
    ref.source = source;
    ref.offset = offset;
    ref.last_read = kNeverRead;
    changed = 1;
  }
  return changed;
}

}  // namespace

void StreamRetargetJob::validate() const {
  const Index n = agent_count();
  if (cluster_stride < 1 || cluster_stride > kMaxClusters)
    throw Error("must be in [1, 8]", at_field("StreamRetargetJob.cluster_stride"));
  if (!(blend_frames >= 0.0f && blend_frames < 1e7f))
    throw Error("must be in [0, 1e7) frames", at_field("StreamRetargetJob.blend_frames"));
  check_length("StreamRetargetJob", "sources", sources.size(), n);
  check_length("StreamRetargetJob", "offsets", offsets.size(), n);
  check_length("StreamRetargetJob", "clusters", clusters.size(), n * cluster_stride);
  if (!changed.empty()) check_length("StreamRetargetJob", "changed", changed.size(), n);
}

void StreamRetargetJob::run() const {
  validate();
  parallel_for(
      "anim.stream_retarget", agent_count(),
      THRONG_JOB_LAMBDA(Index a) {
        std::uint8_t changed_here = 0;
        const std::int32_t source = sources[a];
        const std::int32_t rig = agent_rigs[a];
        bool valid = source >= kNoSource && rig >= 0 && rig < rigs.size();
        std::int32_t offset = 0;
        if (valid && source >= 0) {
          valid = source < streams.size() && streams[source].rig == rig;
          if (valid) {
            const std::int32_t top = streams[source].history - 1;
            offset = offsets[a];
            offset = offset < 0 ? 0 : (offset > top ? top : offset);
          }
        }
        if (valid) changed_here = retarget_clusters(*this, a, source, offset, rigs[rig].cluster_count);
        if (!changed.empty()) changed[a] = changed_here;
      },
      1024);
}

// ---- events ---------------------------------------------------------------------

void StreamEventsJob::validate() const {
  const Index n = agent_rigs.size();
  if (cluster_stride < 1 || cluster_stride > kMaxClusters)
    throw Error("must be in [1, 8]", at_field("StreamEventsJob.cluster_stride"));
  check_length("StreamEventsJob", "clusters", clusters.size(), n * cluster_stride);
  check_length("StreamEventsJob", "out_events", out_events.size(), n);
}

void StreamEventsJob::run() const {
  validate();
  EventFilter filter;
  for (std::int32_t c = 0; c < kMaxClusters; ++c) filter.allowed[c] = cluster_event_filter[static_cast<std::size_t>(c)];
  parallel_for(
      "anim.stream_events", agent_rigs.size(),
      THRONG_JOB_LAMBDA(Index a) {
        const std::int32_t rig = agent_rigs[a];
        const std::int32_t count = rig >= 0 && rig < rigs.size() ? rigs[rig].cluster_count : 0;
        EventMask mask = 0;
        for (std::int32_t c = 0; c < count && c < cluster_stride; ++c) {
          ClusterRef& ref = clusters[a * cluster_stride + c];
          const SourceView* v = find_source(streams, uniques, ref.source);
          if (v == nullptr || v->newest < 0) continue;
          const std::int32_t read = v->newest - effective_offset(*v, ref.offset);
          if (ref.last_read != kNeverRead && read > ref.last_read) {
            // Frames (last_read, read], those still in the ring.
            std::int32_t first = ref.last_read + 1;
            const std::int32_t oldest = v->newest - v->history + 1;
            first = first > oldest ? first : oldest;
            EventMask m = 0;
            for (std::int32_t f = first; f <= read; ++f) {
              std::int32_t slot = (v->head - (v->newest - f)) % v->history;
              slot = slot < 0 ? slot + v->history : slot;
              m |= v->events[slot];
            }
            mask |= m & filter.allowed[c];
          }
          if (ref.last_read == kNeverRead || read > ref.last_read) ref.last_read = read;
        }
        out_events[a] = mask;
      },
      256);
}

// ---- resolve --------------------------------------------------------------------

void StreamResolveJob::validate() const {
  const Index n = agent_count();
  if (cluster_stride < 1 || cluster_stride > kMaxClusters)
    throw Error("must be in [1, 8]", at_field("StreamResolveJob.cluster_stride"));
  check_length("StreamResolveJob", "palette_offsets", palette_offsets.size(), n);
  check_length("StreamResolveJob", "clusters", clusters.size(), n * cluster_stride);
  if (!positions.empty()) check_length("StreamResolveJob", "positions", positions.size(), n);
  if (!yaws.empty()) check_length("StreamResolveJob", "yaws", yaws.size(), n);
  if (!override_begin.empty()) check_length("StreamResolveJob", "override_begin", override_begin.size(), n + 1);
  if (!read_offsets.empty()) check_length("StreamResolveJob", "read_offsets", read_offsets.size(), n * cluster_stride);
  if (!skip.empty()) check_length("StreamResolveJob", "skip", skip.size(), n);
  check_length("StreamResolveJob", "tables.offsets", tables.offsets.size(), tables.parents.size());
  check_length("StreamResolveJob", "tables.joint_cluster", tables.joint_cluster.size(), tables.parents.size());
  check_length("StreamResolveJob", "tables.inverse_bind", tables.inverse_bind.size(), tables.parents.size());
  check_length("StreamResolveJob", "tables.joint_segment", tables.joint_segment.size(), tables.parents.size());
  check_length("StreamResolveJob", "tables.bind_positions", tables.bind_positions.size(), tables.parents.size());
}

namespace {

// One agent as the resolve kernel poses it: its rig, where its palette
// starts, its world transform (yaw about +Y, then translation), and per
// cluster the target and transition source slots, the transition weight
// and whether the cluster is culled.
struct AgentPose {
  RigView rig;
  Index base = 0;
  std::int32_t clusters = 0;
  glm::quat world_q;
  glm::vec3 world_t;
  SlotRead to[kMaxClusters], from[kMaxClusters];
  float alpha[kMaxClusters];
  bool culled[kMaxClusters];

  // Cluster of rig-local joint j, the first one for a cluster beyond the stride.
  THRONG_HOST_DEVICE std::int32_t cluster_of(const RigTablesView& T, std::int32_t j) const {
    const std::int32_t c = T.joint_cluster[rig.joint_base + j];
    return c < clusters ? c : 0;
  }
};

// Reads agent a's cluster slots and world transform into `pose`; writes
// the offsets read when the job asks for them.
THRONG_HOST_DEVICE inline void read_agent(const StreamResolveJob& job, Index a, AgentPose& pose) {
  const RigView& rig = pose.rig;
  const std::int32_t stride = job.cluster_stride;
  pose.clusters = rig.cluster_count < stride ? rig.cluster_count : stride;
  for (std::int32_t c = 0; c < pose.clusters; ++c) {
    const ClusterRef& ref = job.clusters[a * stride + c];
    pose.to[c] = read_source(job.streams, job.uniques, ref.source, ref.offset, rig.joint_count, rig.rest_root);
    pose.alpha[c] = transition_alpha(ref, job.frame);
    if (pose.alpha[c] < 1.0f)
      pose.from[c] =
          read_source(job.streams, job.uniques, ref.from_source, ref.from_offset, rig.joint_count, rig.rest_root);
    pose.culled[c] = (ref.flags & kClusterCulled) != 0u;
    if (!job.read_offsets.empty()) job.read_offsets[a * stride + c] = pose.to[c].offset;
  }
  pose.world_q =
      job.yaws.empty() ? glm::quat(1.0f, 0.0f, 0.0f, 0.0f) : glm::angleAxis(job.yaws[a], glm::vec3(0.0f, 1.0f, 0.0f));
  pose.world_t = job.positions.empty() ? glm::vec3(0.0f) : job.positions[a];
}

// The fast path: each joint's palette entry is its segment's transform
// times the skinning matrix of its source slot.
THRONG_HOST_DEVICE inline void pose_from_skinning(const StreamResolveJob& job, const AgentPose& pose) {
  const RigTablesView& T = job.tables;
  const RigView& rig = pose.rig;
  Mat3x4 W[kMaxSegments];
  for (std::int32_t j = 0; j < rig.joint_count; ++j) {
    const Index tj = rig.joint_base + j;
    const std::int32_t c = pose.cluster_of(T, j);
    const std::int32_t seg = T.joint_segment[tj];
    const Mat3x4* slot = pose.to[c].skinning;
    const std::int32_t p = T.parents[tj];
    if (p < 0) {
      W[seg] = mat3x4_from(pose.world_q, pose.world_t);
    } else if (T.joint_cluster[rig.joint_base + p] != T.joint_cluster[tj]) {
      const Mat3x4 hooked = job.palettes[pose.base + p] * T.segment_hooks[rig.segment_base + seg];
      W[seg] = slot != nullptr ? hooked * inverse_rigid(slot[p]) : hooked;
    }
    job.palettes[pose.base + j] = slot != nullptr ? W[seg] * slot[j] : W[seg];
  }
}

// Turns world rotation R of a joint at P towards o's target about o's aim
// axis, by at most o.max_angle, weighted.
THRONG_HOST_DEVICE inline void look_at(const BoneOverride& o, glm::quat& R, glm::vec3 P) {
  const glm::vec3 f = glm::normalize(R * o.aim_axis);
  glm::vec3 d = o.target - P;
  const float dl = glm::length(d);
  if (!(dl > 1e-6f)) return;
  d = d / dl;
  glm::vec3 axis = glm::cross(f, d);
  const float s = glm::length(axis);
  if (!(s > 1e-6f)) return;
  float cosang = glm::dot(f, d);
  cosang = cosang < -1.0f ? -1.0f : (cosang > 1.0f ? 1.0f : cosang);
  float angle = glm::acos(cosang);
  angle = (angle < o.max_angle ? angle : o.max_angle) * o.weight;
  R = glm::normalize(glm::angleAxis(angle, axis / s) * R);
}

// Joint j's local rotation: its cluster's slot, SLERPed from the
// transition source by alpha, then a rotation override o (or null).
THRONG_HOST_DEVICE inline glm::quat local_rotation(const AgentPose& pose, std::int32_t c, std::int32_t j,
                                                   const BoneOverride* o) {
  glm::quat local = pose.to[c].rotations != nullptr ? pose.to[c].rotations[j] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  if (pose.alpha[c] < 1.0f) {
    const glm::quat src =
        pose.from[c].rotations != nullptr ? pose.from[c].rotations[j] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    local = motion::slerp_shortest(src, local, pose.alpha[c]);
  }
  if (o != nullptr && o->kind == OverrideKind::Rotation) local = motion::slerp_shortest(local, o->rotation, o->weight);
  return local;
}

// The blended path: per joint the local rotation (local_rotation), forward
// kinematics through the cluster hooks, look-at overrides, times the
// agent's world transform and the inverse bind matrix. Overrides
// [ov, ov_end) are sorted by joint.
THRONG_HOST_DEVICE inline void pose_blended(const StreamResolveJob& job, const AgentPose& pose, Index ov,
                                            Index ov_end) {
  const RigTablesView& T = job.tables;
  const RigView& rig = pose.rig;
  glm::quat R[kMaxRigJoints];
  glm::vec3 P[kMaxRigJoints];
  for (std::int32_t j = 0; j < rig.joint_count; ++j) {
    const Index tj = rig.joint_base + j;
    const std::int32_t c = pose.cluster_of(T, j);
    while (ov < ov_end && job.overrides[ov].joint < j) ++ov;
    const BoneOverride* o = ov < ov_end && job.overrides[ov].joint == j ? &job.overrides[ov] : nullptr;
    const glm::quat local = local_rotation(pose, c, j, o);
    const std::int32_t p = T.parents[tj];
    if (p < 0) {
      glm::vec3 root = pose.to[c].root;
      if (pose.alpha[c] < 1.0f) root = glm::mix(pose.from[c].root, root, pose.alpha[c]);
      R[j] = pose.world_q * local;
      P[j] = pose.world_t + pose.world_q * root;
    } else {
      glm::quat pq = R[p];
      glm::vec3 pt = P[p];
      if (T.joint_cluster[rig.joint_base + p] != T.joint_cluster[tj]) {
        // Entering another cluster: hang it from its hook.
        const Index h = rig.cluster_base + c;
        pt = pt + pq * T.hook_translations[h];
        pq = pq * T.hook_rotations[h];
      }
      R[j] = pq * local;
      P[j] = pt + pq * T.offsets[tj];
    }
    if (o != nullptr && o->kind == OverrideKind::LookAt) look_at(*o, R[j], P[j]);
    job.palettes[pose.base + j] = mat3x4_from(R[j], P[j]) * T.inverse_bind[tj];
  }
}

// Culled clusters' joints collapse onto their hook, children first so that
// every hook read is still posed.
THRONG_HOST_DEVICE inline void collapse_culled(const StreamResolveJob& job, const AgentPose& pose) {
  bool any_culled = false;
  for (std::int32_t c = 0; c < pose.clusters; ++c) any_culled = any_culled || pose.culled[c];
  if (!any_culled) return;
  const RigTablesView& T = job.tables;
  const RigView& rig = pose.rig;
  for (std::int32_t j = rig.joint_count - 1; j >= 0; --j) {
    const std::int32_t c = pose.cluster_of(T, j);
    if (!pose.culled[c]) continue;
    std::int32_t hook = T.hook_joints[rig.cluster_base + c];
    hook = hook >= 0 ? hook : 0;
    job.palettes[pose.base + j] =
        collapse_to(transform_point(job.palettes[pose.base + hook], T.bind_positions[rig.joint_base + hook]));
  }
}

// Agent a's palette, unless it is skipped or its rig or palette range is invalid.
THRONG_HOST_DEVICE inline void resolve_agent(const StreamResolveJob& job, Index a) {
  if (!job.skip.empty() && job.skip[a] != 0) return;
  const std::int32_t r = job.agent_rigs[a];
  if (r < 0 || r >= job.tables.rigs.size()) return;
  AgentPose pose;
  pose.rig = job.tables.rigs[r];
  pose.base = job.palette_offsets[a];
  if (pose.rig.joint_count > kMaxRigJoints || pose.base < 0 || pose.base + pose.rig.joint_count > job.palettes.size())
    return;
  read_agent(job, a, pose);
  Index ov = 0, ov_end = 0;
  if (!job.override_begin.empty()) {
    ov = job.override_begin[a];
    ov_end = job.override_begin[a + 1];
  }
  bool fast = ov == ov_end;
  for (std::int32_t c = 0; c < pose.clusters; ++c) fast = fast && pose.alpha[c] >= 1.0f;
  if (fast) {
    pose_from_skinning(job, pose);
  } else {
    pose_blended(job, pose, ov, ov_end);
  }
  collapse_culled(job, pose);
}

}  // namespace

void StreamResolveJob::run() const {
  validate();
  parallel_for(
      "anim.stream_resolve", agent_count(), THRONG_JOB_LAMBDA(Index a) { resolve_agent(*this, a); }, 64);
}

}  // namespace throng::anim
