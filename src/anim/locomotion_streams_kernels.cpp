// Kernels of locomotion through streams: compiled by nvcc in CUDA builds, by g++ otherwise.
#include <algorithm>
#include <cmath>
#include <string>

#include "anim/locomotion_streams.h"
#include "core/array_kernels.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/reduce.h"

namespace throng::anim {

namespace {

struct BucketOf {
  Span<const std::int32_t> keys;
  THRONG_HOST_DEVICE std::int32_t operator()(Index a) const { return keys[a]; }
};

// The blend space as streamed agents show it: every blend at its bucket's centre.
motion::BlendSpaceView quantised(motion::BlendSpaceView v, float width, std::int32_t buckets) {
  v.quantum = width;
  v.quantum_buckets = buckets;
  return v;
}

std::int32_t first_cluster(std::uint32_t mask) {
  for (std::int32_t c = 0; c < kMaxClusters; ++c)
    if ((mask >> c) & 1u) return c;
  return 0;
}

}  // namespace

// ---- world joints -> palettes ------------------------------------------------------------------

void JointPaletteJob::validate() const {
  auto check = [](const char* field, Index got, Index want) {
    if (got != want)
      throw Error("has " + std::to_string(got) + " elements, expected " + std::to_string(want), at_field(std::string("JointPaletteJob.") + field));
  };
  if (joint_count <= 0) throw Error("must be positive", at_field("JointPaletteJob.joint_count"));
  const Index n = character_count();
  check("joint_positions", joint_positions.size(), n * joint_count);
  check("joint_rotations", joint_rotations.size(), n * joint_count);
  check("inverse_bind", inverse_bind.size(), joint_count);
  if (!scales.empty()) check("scales", scales.size(), n);
  if (!agents.empty()) check("agents", agents.size(), n);
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

// ---- per frame ---------------------------------------------------------------------------------

std::vector<Index> LocomotionStreams::classify(const Camera* camera) {
  const bool lod = config_.exact_near_camera && camera != nullptr && count_ > 0;
  if (lod) {
    LodJob job;
    job.camera = make_camera_view(*camera);
    job.set_tables(*lod_tables_);
    job.root_positions = position_.span();
    job.root_headings = yaw_.span();
    job.template_spheres = parts_->rest_spheres;
    job.levels = levels_.span();
    job.joint_masks = masks_.span();
    job.run();
  }
  const motion::BlendSpaceView view = quantised(tables_.view(), config_.bucket_width, buckets_);
  const float width = config_.bucket_width;
  const std::int32_t buckets = buckets_;
  const auto levels = levels_.span();
  const auto speed = speed_.span();
  const auto exact = exact_.span();
  const auto rank = exact_rank_.span();
  const auto key = key_.span();
  parallel_for(
      "anim.loco_streams_keys", count_,
      THRONG_LAMBDA(Index a) {
        bool near = false;
        if (lod)
          for (int p = 0; p < kBodyPartCount; ++p) near = near || levels[a * kBodyPartCount + p] == 0;
        exact[a] = near ? 1 : 0;
        rank[a] = near ? 1 : 0;
        key[a] = near ? -1 : cache_key(motion::blend_point(view, motion::blend_coordinate(view, speed[a])), width, buckets);
      },
      1024);
  stats_.exact = lod ? count_nonzero(exact_.span()) : 0;
  return deterministic_histogram("anim.loco_streams_buckets", count_, keys_, BucketOf{key_.span()});
}

void LocomotionStreams::select(float dt) {
  const motion::BlendSpaceView view = tables_.view();
  const motion::BlendSpaceView view_q = quantised(view, config_.bucket_width, buckets_);
  const auto speed = speed_.span();
  const auto exact = exact_.span();
  const auto key = key_.span();
  const auto phase = phase_.span();
  const auto source = source_.span();
  const auto offset = offset_.span();
  const auto head = key_phase_.span();
  const auto frames = key_frames_device_.span();
  const auto streams = crowd_.streams().views();
  const auto refs = crowd_.cluster_refs();
  const std::int32_t stride = crowd_.cluster_stride();
  const std::int32_t first = first_cluster(config_.cluster_mask);
  parallel_for(
      "anim.loco_streams_select", count_,
      THRONG_LAMBDA(Index a) {
        const float v = speed[a];
        float ph = phase[a];
        if (exact[a] != 0) {  // synthesised: its own cadence at its own speed
          ph += motion::cycle_rate(view, motion::blend_point(view, motion::blend_coordinate(view, v)), v) * dt;
          phase[a] = motion::wrap_phase(ph);
          source[a] = kNoSource;
          offset[a] = 0;
          return;
        }
        const std::int32_t k = key[a];
        const float F = frames[k];
        std::int32_t o = 0;
        const ClusterRef& ref = refs[a * stride + first];
        if (ref.source == k) {
          o = ref.offset;  // same bucket: keep the offset, play at the stream's cadence
        } else {
          // Joining a stream: advance at the bucket's cadence, then take the
          // slot that shows this phase (the nearest; the phase snaps to it).
          ph += motion::cycle_rate(view_q, motion::blend_point(view_q, motion::blend_coordinate(view_q, v)), v) * dt;
          o = static_cast<std::int32_t>(glm::floor(motion::wrap_phase(head[k] - ph) * F + 0.5f));
          const std::int32_t top = streams[k].history - 1;
          o = o < 0 ? 0 : (o > top ? top : o);
        }
        phase[a] = motion::wrap_phase(head[k] - static_cast<float>(o) / F);
        source[a] = k;
        offset[a] = o;
      },
      1024);
}

void LocomotionStreams::synthesise_exact() {
  if (stats_.exact == 0) return;
  const Memory m = current_memory();
  const Index n = stats_.exact;
  exclusive_scan(exact_rank_.span(), exact_rank_.span());
  if (exact_agents_.size() < n) {  // grows to the largest exact count seen
    const Index cap = std::max(n, exact_agents_.size() * 2);
    exact_agents_ = Buffer<Index>(cap, m);
    exact_position_ = Buffer<glm::vec3>(cap, m);
    exact_yaw_ = Buffer<float>(cap, m);
    exact_phase_ = Buffer<float>(cap, m);
    exact_speed_ = Buffer<float>(cap, m);
    joint_position_ = Buffer<glm::vec3>(cap * joints_, m);
    joint_rotation_ = Buffer<glm::quat>(cap * joints_, m);
  }
  const auto exact = exact_.span();
  const auto rank = exact_rank_.span();
  const auto agents = exact_agents_.span();
  const auto pos = position_.span();
  const auto yaw = yaw_.span();
  const auto phase = phase_.span();
  const auto speed = speed_.span();
  const auto out_pos = exact_position_.span();
  const auto out_yaw = exact_yaw_.span();
  const auto out_phase = exact_phase_.span();
  const auto out_speed = exact_speed_.span();
  parallel_for(
      "anim.loco_streams_gather", count_,
      THRONG_LAMBDA(Index a) {
        if (exact[a] == 0) return;
        const Index r = rank[a];
        agents[r] = a;
        out_pos[r] = pos[a];
        out_yaw[r] = yaw[a];
        out_phase[r] = phase[a];
        out_speed[r] = speed[a];
      },
      1024);
  PoseJob pose;
  pose.blend = tables_.view();
  pose.positions = exact_position_.span().subspan(0, n);
  pose.yaws = exact_yaw_.span().subspan(0, n);
  pose.phases = exact_phase_.span().subspan(0, n);
  pose.blend_speeds = exact_speed_.span().subspan(0, n);
  pose.joint_positions = joint_position_.span().subspan(0, n * joints_);
  pose.joint_rotations = joint_rotation_.span().subspan(0, n * joints_);
  pose.run();
  JointPaletteJob palettes;
  palettes.joint_count = joints_;
  palettes.joint_positions = pose.joint_positions;
  palettes.joint_rotations = pose.joint_rotations;
  palettes.inverse_bind = inverse_bind_.span();
  palettes.agents = exact_agents_.span().subspan(0, n);
  palettes.palette_offsets = crowd_.palette_offsets();
  palettes.palettes = palettes_.span();
  palettes.run();
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
