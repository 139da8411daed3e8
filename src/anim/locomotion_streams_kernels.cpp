// Kernels of locomotion through streams: compiled by nvcc in CUDA builds, by g++ otherwise.
#include <algorithm>
#include <cmath>
#include <string>

#include "anim/locomotion_streams.h"
#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"

namespace throng::anim {


// ---- world joints -> palettes ------------------------------------------------------------------

void JointPaletteJob::validate() const {
  if (joint_count <= 0) throw Error("must be positive", at_field("JointPaletteJob.joint_count"));
  const Index n = character_count();
  check_length("JointPaletteJob", "joint_positions", joint_positions.size(), n * joint_count);
  check_length("JointPaletteJob", "joint_rotations", joint_rotations.size(), n * joint_count);
  check_length("JointPaletteJob", "inverse_bind", inverse_bind.size(), joint_count);
  if (!scales.empty()) check_length("JointPaletteJob", "scales", scales.size(), n);
  if (!agents.empty()) check_length("JointPaletteJob", "agents", agents.size(), n);
}

void JointPaletteJob::run() const {
  validate();
  const std::int32_t J = joint_count;
  const auto P = joint_positions;
  const auto R = joint_rotations;
  const auto IB = inverse_bind;
  const auto S = scales;
  const auto who = agents;
  const auto offsets = palette_offsets;
  const auto out = palettes;
  const Index size = palettes.size();
  parallel_for(
      "anim.joint_palette", character_count(),
      THRONG_LAMBDA(Index c) {
        const Index a = who.empty() ? c : who[c];
        const Index base = offsets.empty() ? a * J : offsets[a];
        if (base < 0 || base + J > size) return;
        const float s = S.empty() ? 1.0f : S[c];
        for (std::int32_t j = 0; j < J; ++j) {
          Mat3x4 m = mat3x4_from(R[c * J + j], P[c * J + j]);
          if (s != 1.0f) {
            m.r0 = glm::vec4(s * glm::vec3(m.r0), m.r0.w);
            m.r1 = glm::vec4(s * glm::vec3(m.r1), m.r1.w);
            m.r2 = glm::vec4(s * glm::vec3(m.r2), m.r2.w);
          }
          out[base + j] = m * IB[j];
        }
      },
      64);
}

// ---- per frame -----------------------------------------------------------------------------------

void StreamBucketJob::validate() const {
  const Index n = agent_count();
  if (!levels.empty()) check_length("StreamBucketJob", "levels", levels.size(), n * kBodyPartCount);
  check_length("StreamBucketJob", "exact", exact.size(), n);
  check_length("StreamBucketJob", "exact_flags", exact_flags.size(), n);
  check_length("StreamBucketJob", "keys", keys.size(), n);
  if (bucket_count < 1) throw Error("must be positive", at_field("StreamBucketJob.bucket_count"));
}

void StreamBucketJob::run() const {
  validate();
  const motion::BlendSpaceView view = blend;
  const float width = bucket_width;
  const std::int32_t buckets = bucket_count;
  const auto speed = speeds;
  const auto level = levels;
  const auto out_exact = exact;
  const auto out_flags = exact_flags;
  const auto out_key = keys;
  parallel_for(
      "anim.loco_streams_keys", agent_count(),
      THRONG_LAMBDA(Index a) {
        bool near = false;
        if (!level.empty())
          for (int p = 0; p < kBodyPartCount; ++p) near = near || level[a * kBodyPartCount + p] == 0;
        out_exact[a] = near ? 1 : 0;
        out_flags[a] = near ? 1 : 0;
        out_key[a] = near ? -1 : cache_key(motion::blend_point(view, motion::blend_coordinate(view, speed[a])), width, buckets);
      },
      1024);
}

void StreamSelectJob::validate() const {
  const Index n = agent_count();
  check_length("StreamSelectJob", "exact", exact.size(), n);
  check_length("StreamSelectJob", "keys", keys.size(), n);
  check_length("StreamSelectJob", "key_frames", key_frames.size(), key_phases.size());
  check_length("StreamSelectJob", "streams", streams.size(), key_phases.size());
  check_length("StreamSelectJob", "clusters", clusters.size(), n * cluster_stride);
  check_length("StreamSelectJob", "phases", phases.size(), n);
  check_length("StreamSelectJob", "sources", sources.size(), n);
  check_length("StreamSelectJob", "offsets", offsets.size(), n);
  if (cluster < 0 || cluster >= cluster_stride) throw Error("must be below the cluster stride", at_field("StreamSelectJob.cluster"));
}

void StreamSelectJob::run() const {
  validate();
  const motion::BlendSpaceView view = blend;
  const motion::BlendSpaceView view_q = quantised;
  const float step = dt;
  const auto speed = speeds;
  const auto is_exact = exact;
  const auto key = keys;
  const auto head = key_phases;
  const auto frames = key_frames;
  const auto stream = streams;
  const auto refs = clusters;
  const std::int32_t stride = cluster_stride;
  const std::int32_t first = cluster;
  const auto phase = phases;
  const auto source = sources;
  const auto offset = offsets;
  const auto key_count = key_phases.size();
  parallel_for(
      "anim.loco_streams_select", agent_count(),
      THRONG_LAMBDA(Index a) {
        const float v = speed[a];
        float ph = phase[a];
        const std::int32_t k = key[a];
        if (is_exact[a] != 0 || k < 0 || k >= key_count) {  // synthesised: its own cadence at its own speed
          ph += motion::cycle_rate(view, motion::blend_point(view, motion::blend_coordinate(view, v)), v) * step;
          phase[a] = motion::wrap_phase(ph);
          source[a] = kNoSource;
          offset[a] = 0;
          return;
        }
        const float F = frames[k];
        std::int32_t o = 0;
        if (refs[a * stride + first].source == k) {
          o = refs[a * stride + first].offset;  // same bucket: keep the offset, play at the stream's cadence
        } else {
          // Joining a stream: advance at the bucket's cadence, then take the
          // slot that shows this phase (the nearest; the phase snaps to it).
          ph += motion::cycle_rate(view_q, motion::blend_point(view_q, motion::blend_coordinate(view_q, v)), v) * step;
          o = static_cast<std::int32_t>(glm::floor(motion::wrap_phase(head[k] - ph) * F + 0.5f));
          const std::int32_t top = stream[k].history - 1;
          o = o < 0 ? 0 : (o > top ? top : o);
        }
        phase[a] = motion::wrap_phase(head[k] - static_cast<float>(o) / F);
        source[a] = k;
        offset[a] = o;
      },
      1024);
}

void ExactGatherJob::run() const {
  const auto is_exact = exact;
  const auto rank = ranks;
  const auto pos = positions;
  const auto yaw = yaws;
  const auto phase = phases;
  const auto speed = speeds;
  const auto who = agents;
  const auto out_pos = out_positions;
  const auto out_yaw = out_yaws;
  const auto out_phase = out_phases;
  const auto out_speed = out_speeds;
  const Index room = agents.size();
  parallel_for(
      "anim.loco_streams_gather", exact.size(),
      THRONG_LAMBDA(Index a) {
        if (is_exact[a] == 0) return;
        const Index r = rank[a];
        if (r < 0 || r >= room) return;
        who[r] = a;
        out_pos[r] = pos[a];
        out_yaw[r] = yaw[a];
        out_phase[r] = phase[a];
        out_speed[r] = speed[a];
      },
      1024);
}

// ---- the error of sharing ----------------------------------------------------------------------

SharingError LocomotionStreams::sharing_error() const {
  SharingError e;
  if (count_ == 0) return e;
  const Memory m = current_memory();
  Buffer<glm::vec3> reference(count_ * joints_, m);
  Buffer<glm::quat> rotations(count_ * joints_, m);
  PoseJob pose;
  pose.blend = tables_.view();
  pose.positions = position_.span();
  pose.yaws = yaw_.span();
  pose.phases = phase_.span();
  pose.blend_speeds = speed_.span();
  pose.joint_positions = reference.span();
  pose.joint_rotations = rotations.span();
  pose.run();
  Buffer<float> errors(count_, m);
  const std::int32_t J = joints_;
  const auto exact = exact_.span();
  const auto pal = palettes_.span();
  const auto bind = bind_positions_.span();
  const auto ref = reference.span();
  const auto out = errors.span();
  parallel_for(
      "anim.loco_streams_error", count_,
      THRONG_LAMBDA(Index a) {
        if (exact[a] != 0) {
          out[a] = -1.0f;
          return;
        }
        float worst = 0.0f;
        for (std::int32_t j = 0; j < J; ++j) worst = glm::max(worst, glm::length(transform_point(pal[a * J + j], bind[j]) - ref[a * J + j]));
        out[a] = 100.0f * worst;
      },
      256);
  double sum = 0.0;
  for (const float x : errors.to_vector()) {
    if (x < 0.0f) continue;
    e.agent_max_cm.push_back(x);
    e.max_cm = std::max(e.max_cm, static_cast<double>(x));
    sum += x;
  }
  e.agents = static_cast<Index>(e.agent_max_cm.size());
  if (e.agents == 0) return e;
  e.mean_cm = sum / static_cast<double>(e.agents);
  std::vector<float> sorted = e.agent_max_cm;
  const auto k = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(sorted.size()))) - 1;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  e.p95_cm = sorted[k];
  return e;
}

}  // namespace throng::anim
