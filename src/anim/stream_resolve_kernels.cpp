#include <string>

#include "anim/stream_resolve.h"
#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"

namespace throng::anim {

namespace {

// Where one cluster's joints come from this frame.
struct SlotRead {
  const glm::quat* rotations = nullptr;  // null: the rest pose (identity rotations)
  const Mat3x4* skinning = nullptr;      // null: the rest pose (identity matrices)
  glm::vec3 root{0.0f};
  std::int32_t offset = -1;              // effective offset read, -1 for none
};

// The view of a source id, or null for none (or an id out of range).
// Spans by reference: copying a non-const Span lvalue would pick Span's
// host-only container constructor under nvcc.
THRONG_HOST_DEVICE inline const SourceView* find_source(const Span<const SourceView>& streams, const Span<const SourceView>& uniques,
                                                        std::int32_t source) {
  if (source >= 0 && source < streams.size()) return &streams[source];
  if (is_unique_source(source) && unique_instance(source) < uniques.size()) return &uniques[unique_instance(source)];
  return nullptr;
}

THRONG_HOST_DEVICE inline SlotRead read_source(const Span<const SourceView>& streams, const Span<const SourceView>& uniques, std::int32_t source,
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

void StreamCommandJob::run() const {
  const auto cmds = commands;
  const auto grp = groups;
  const auto refs = clusters;
  const std::int32_t stride = cluster_stride;
  const std::int32_t now = frame;
  const Index group_count = groups.size() - 1;
  parallel_for(
      "anim.stream_commands", group_count,
      THRONG_LAMBDA(Index g) {
        for (Index k = grp[g]; k < grp[g + 1]; ++k) {
          const ClusterCommand& c = cmds[k];
          ClusterRef* agent = refs.data() + c.agent * stride;
          ClusterRef& ref = agent[c.cluster];
          std::int32_t offset = c.offset;
          if (offset < 0) {
            offset = c.fallback_offset;
            for (std::int32_t o = 0; o < stride; ++o)
              if (o != c.cluster && agent[o].source == c.source) {
                offset = agent[o].offset;
                break;
              }
          }
          if (c.transition != 0 && c.blend_frames > 0.0f) {
            ref.from_source = ref.source;
            ref.from_offset = ref.offset;
            ref.t0 = now;
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

void StreamRetargetJob::validate() const {
  const Index n = agent_count();
  if (cluster_stride < 1 || cluster_stride > kMaxClusters) throw Error("must be in [1, 8]", at_field("StreamRetargetJob.cluster_stride"));
  if (!(blend_frames >= 0.0f && blend_frames < 1e7f)) throw Error("must be in [0, 1e7) frames", at_field("StreamRetargetJob.blend_frames"));
  check_length("StreamRetargetJob", "sources", sources.size(), n);
  check_length("StreamRetargetJob", "offsets", offsets.size(), n);
  check_length("StreamRetargetJob", "clusters", clusters.size(), n * cluster_stride);
  if (!changed.empty()) check_length("StreamRetargetJob", "changed", changed.size(), n);
}

void StreamRetargetJob::run() const {
  validate();
  const auto want = sources;
  const auto want_offset = offsets;
  const auto S = streams;
  const auto R = rigs;
  const auto AR = agent_rigs;
  const auto refs = clusters;
  const auto out_changed = changed;
  const std::int32_t stride = cluster_stride;
  const std::uint32_t mask = cluster_mask;
  const std::int32_t now = frame;
  const float blend = blend_frames;
  parallel_for(
      "anim.stream_retarget", agent_count(),
      THRONG_LAMBDA(Index a) {
        std::uint8_t changed_here = 0;
        const std::int32_t source = want[a];
        const std::int32_t rig = AR[a];
        bool valid = source >= kNoSource && rig >= 0 && rig < R.size();
        std::int32_t offset = 0;
        if (valid && source >= 0) {
          valid = source < S.size() && S[source].rig == rig;
          if (valid) {
            const std::int32_t top = S[source].history - 1;
            offset = want_offset[a];
            offset = offset < 0 ? 0 : (offset > top ? top : offset);
          }
        }
        if (valid) {
          const std::int32_t count = R[rig].cluster_count < stride ? R[rig].cluster_count : stride;
          for (std::int32_t c = 0; c < count; ++c) {
            if (((mask >> c) & 1u) == 0u) continue;
            ClusterRef& ref = refs[a * stride + c];
            if (is_unique_source(ref.source)) continue;
            if (ref.source == source) {
              ref.offset = offset;
              continue;
            }
            if (source >= 0 && ref.source >= 0 && blend > 0.0f) {
              ref.from_source = ref.source;
              ref.from_offset = ref.offset;
              ref.t0 = now;
              ref.blend_frames = blend;
            } else {
              ref.from_source = kNoSource;
              ref.from_offset = 0;
              ref.blend_frames = 0.0f;
            }
            ref.source = source;
            ref.offset = offset;
            ref.last_read = kNeverRead;
            changed_here = 1;
          }
        }
        if (!out_changed.empty()) out_changed[a] = changed_here;
      },
      1024);
}

// ---- events ---------------------------------------------------------------------

void StreamEventsJob::run() const {
  const auto S = streams;
  const auto U = uniques;
  const auto R = rigs;
  const auto AR = agent_rigs;
  const auto refs = clusters;
  const auto out = out_events;
  const std::int32_t stride = cluster_stride;
  EventFilter filter;
  for (std::int32_t c = 0; c < kMaxClusters; ++c) filter.allowed[c] = cluster_event_filter[static_cast<std::size_t>(c)];
  parallel_for(
      "anim.stream_events", agent_rigs.size(),
      THRONG_LAMBDA(Index a) {
        const std::int32_t rig = AR[a];
        const std::int32_t count = rig >= 0 && rig < R.size() ? R[rig].cluster_count : 0;
        EventMask mask = 0;
        for (std::int32_t c = 0; c < count && c < stride; ++c) {
          ClusterRef& ref = refs[a * stride + c];
          const SourceView* v = find_source(S, U, ref.source);
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
        out[a] = mask;
      },
      256);
}

// ---- resolve --------------------------------------------------------------------

void StreamResolveJob::validate() const {
  const Index n = agent_count();
  if (cluster_stride < 1 || cluster_stride > kMaxClusters) throw Error("must be in [1, 8]", at_field("StreamResolveJob.cluster_stride"));
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

void StreamResolveJob::run() const {
  validate();
  const RigTablesView T = tables;
  const auto S = streams;
  const auto U = uniques;
  const auto AR = agent_rigs;
  const auto PO = palette_offsets;
  const auto refs = clusters;
  const std::int32_t stride = cluster_stride;
  const auto OB = override_begin;
  const auto OV = overrides;
  const auto pos = positions;
  const auto yaw = yaws;
  const std::int32_t now = frame;
  const auto out = palettes;
  const auto read_out = read_offsets;
  const auto skipped = skip;
  const Index palette_size = palettes.size();
  parallel_for(
      "anim.stream_resolve", agent_count(),
      THRONG_LAMBDA(Index a) {
        if (!skipped.empty() && skipped[a] != 0) return;
        const std::int32_t r = AR[a];
        if (r < 0 || r >= T.rigs.size()) return;
        const RigView rig = T.rigs[r];
        const std::int32_t J = rig.joint_count;
        const Index base = PO[a];
        if (J > kMaxRigJoints || base < 0 || base + J > palette_size) return;

        // Each cluster's target and transition source slots.
        SlotRead to[kMaxClusters], from[kMaxClusters];
        float alpha[kMaxClusters];
        bool culled[kMaxClusters];
        const std::int32_t clusters_here = rig.cluster_count < stride ? rig.cluster_count : stride;
        for (std::int32_t c = 0; c < clusters_here; ++c) {
          const ClusterRef& ref = refs[a * stride + c];
          to[c] = read_source(S, U, ref.source, ref.offset, J, rig.rest_root);
          alpha[c] = transition_alpha(ref, now);
          if (alpha[c] < 1.0f) from[c] = read_source(S, U, ref.from_source, ref.from_offset, J, rig.rest_root);
          culled[c] = (ref.flags & kClusterCulled) != 0u;
          if (!read_out.empty()) read_out[a * stride + c] = to[c].offset;
        }

        // The agent's world transform (yaw about +Y, then translation).
        glm::quat world_q(1.0f, 0.0f, 0.0f, 0.0f);
        glm::vec3 world_t(0.0f);
        if (!yaw.empty()) world_q = glm::angleAxis(yaw[a], glm::vec3(0.0f, 1.0f, 0.0f));
        if (!pos.empty()) world_t = pos[a];

        Index ov = 0, ov_end = 0;
        if (!OB.empty()) {
          ov = OB[a];
          ov_end = OB[a + 1];
        }

        bool fast = ov == ov_end;
        for (std::int32_t c = 0; c < clusters_here; ++c) fast = fast && alpha[c] >= 1.0f;
        if (fast) {
          // Each joint: its segment's transform times the skinning matrix of its source slot.
          Mat3x4 W[kMaxSegments];
          for (std::int32_t j = 0; j < J; ++j) {
            const Index tj = rig.joint_base + j;
            std::int32_t c = T.joint_cluster[tj];
            c = c < clusters_here ? c : 0;
            const std::int32_t seg = T.joint_segment[tj];
            const Mat3x4* slot = to[c].skinning;
            const std::int32_t p = T.parents[tj];
            if (p < 0) {
              W[seg] = mat3x4_from(world_q, world_t);
            } else if (T.joint_cluster[rig.joint_base + p] != T.joint_cluster[tj]) {
              const Mat3x4 hooked = out[base + p] * T.segment_hooks[rig.segment_base + seg];
              W[seg] = slot != nullptr ? hooked * inverse_rigid(slot[p]) : hooked;
            }
            out[base + j] = slot != nullptr ? W[seg] * slot[j] : W[seg];
          }
        } else {
          glm::quat R[kMaxRigJoints];
          glm::vec3 P[kMaxRigJoints];
          for (std::int32_t j = 0; j < J; ++j) {
            const Index tj = rig.joint_base + j;
            std::int32_t c = T.joint_cluster[tj];
            c = c < clusters_here ? c : 0;
            glm::quat local = to[c].rotations != nullptr ? to[c].rotations[j] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
            if (alpha[c] < 1.0f) {
              const glm::quat src = from[c].rotations != nullptr ? from[c].rotations[j] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
              local = glm::slerp(src, local, alpha[c]);
            }
            while (ov < ov_end && OV[ov].joint < j) ++ov;
            const BoneOverride* o = ov < ov_end && OV[ov].joint == j ? &OV[ov] : nullptr;
            if (o != nullptr && o->kind == OverrideKind::Rotation) local = glm::slerp(local, o->rotation, o->weight);

            const std::int32_t p = T.parents[tj];
            if (p < 0) {
              glm::vec3 root = to[c].root;
              if (alpha[c] < 1.0f) root = glm::mix(from[c].root, root, alpha[c]);
              R[j] = world_q * local;
              P[j] = world_t + world_q * root;
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

            if (o != nullptr && o->kind == OverrideKind::LookAt) {
              const glm::vec3 f = glm::normalize(R[j] * o->aim_axis);
              glm::vec3 d = o->target - P[j];
              const float dl = glm::length(d);
              if (dl > 1e-6f) {
                d = d / dl;
                glm::vec3 axis = glm::cross(f, d);
                const float s = glm::length(axis);
                if (s > 1e-6f) {
                  float cosang = glm::dot(f, d);
                  cosang = cosang < -1.0f ? -1.0f : (cosang > 1.0f ? 1.0f : cosang);
                  float angle = glm::acos(cosang);
                  angle = (angle < o->max_angle ? angle : o->max_angle) * o->weight;
                  R[j] = glm::normalize(glm::angleAxis(angle, axis / s) * R[j]);
                }
              }
            }
            out[base + j] = mat3x4_from(R[j], P[j]) * T.inverse_bind[tj];
          }
        }

        // Culled clusters, children first so that every hook read is still posed.
        bool any_culled = false;
        for (std::int32_t c = 0; c < clusters_here; ++c) any_culled = any_culled || culled[c];
        if (any_culled) {
          for (std::int32_t j = J - 1; j >= 0; --j) {
            const Index tj = rig.joint_base + j;
            std::int32_t c = T.joint_cluster[tj];
            c = c < clusters_here ? c : 0;
            if (!culled[c]) continue;
            std::int32_t hook = T.hook_joints[rig.cluster_base + c];
            hook = hook >= 0 ? hook : 0;
            out[base + j] = collapse_to(transform_point(out[base + hook], T.bind_positions[rig.joint_base + hook]));
          }
        }
      },
      64);
}

}  // namespace throng::anim
