// Kernels of locomotion through streams: compiled by nvcc in CUDA builds, by g++ otherwise.
#include <algorithm>
#include <cmath>
#include <string>

#include "anim/locomotion_streams.h"
#include "anim/sphere_projection.h"
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
  parallel_for(
      "anim.joint_palette", character_count(),
      THRONG_JOB_LAMBDA(Index c) {
        const std::int32_t J = joint_count;
        const Index a = agents.empty() ? c : agents[c];
        const Index base = palette_offsets.empty() ? a * J : palette_offsets[a];
        if (base < 0 || base + J > palettes.size()) return;
        const float s = scales.empty() ? 1.0f : scales[c];
        for (std::int32_t j = 0; j < J; ++j) {
          Mat3x4 m = mat3x4_from(joint_rotations[c * J + j], joint_positions[c * J + j]);
          if (s != 1.0f) {
            m.r0 = glm::vec4(s * glm::vec3(m.r0), m.r0.w);
            m.r1 = glm::vec4(s * glm::vec3(m.r1), m.r1.w);
            m.r2 = glm::vec4(s * glm::vec3(m.r2), m.r2.w);
          }
          palettes[base + j] = m * inverse_bind[j];
        }
      },
      64);
}

// ---- per frame -----------------------------------------------------------------------------------

void StreamBucketJob::validate() const {
  const Index n = agent_count();
  if (near_camera) {
    check_length("StreamBucketJob", "positions", positions.size(), n);
    check_length("StreamBucketJob", "yaws", yaws.size(), n);
    if (!(camera.focal_px > 0.0f && camera.width >= 1.0f && camera.height >= 1.0f))
      throw Error("focal length and viewport must be positive", at_field("StreamBucketJob.camera"));
  }
  check_length("StreamBucketJob", "exact", exact.size(), n);
  check_length("StreamBucketJob", "exact_flags", exact_flags.size(), n);
  check_length("StreamBucketJob", "keys", keys.size(), n);
  if (bucket_count < 1) throw Error("must be positive", at_field("StreamBucketJob.bucket_count"));
}

namespace {

// Whether some part sphere of the agent (rest spheres turned by its yaw
// about +Y and moved to its ground point, as LodJob places them) covers
// at least `least` square pixels; the body sphere first.
THRONG_HOST_DEVICE inline bool near_camera_at(const StreamBucketJob& job, Index a) {
  const glm::vec3 p = job.positions[a];
  const glm::vec3 body = p + glm::vec3(job.body_sphere);
  if (sphere_pixel_coverage(to_camera_space(job.camera, body), job.body_sphere.w, job.camera, true) <
      job.exact_coverage)
    return false;
  const float c = glm::cos(job.yaws[a]), s = glm::sin(job.yaws[a]);
  for (int k = 0; k < kBodyPartCount; ++k) {
    const glm::vec4 t = job.part_spheres[k];
    const glm::vec3 centre = p + glm::vec3(c * t.x + s * t.z, t.y, -s * t.x + c * t.z);
    if (sphere_pixel_coverage(to_camera_space(job.camera, centre), t.w, job.camera, true) >= job.exact_coverage)
      return true;
  }
  return false;
}

}  // namespace

void StreamBucketJob::run() const {
  validate();
  parallel_for(
      "anim.loco_streams_keys", agent_count(),
      THRONG_JOB_LAMBDA(Index a) {
        const bool near = near_camera && near_camera_at(*this, a);
        exact[a] = near ? 1 : 0;
        exact_flags[a] = near ? 1 : 0;
        keys[a] = near ? -1
                       : cache_key(motion::blend_point(blend, motion::blend_coordinate(blend, speeds[a])), bucket_width,
                                   bucket_count);
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
}

void StreamSelectJob::run() const {
  validate();
  parallel_for(
      "anim.loco_streams_select", agent_count(),
      THRONG_JOB_LAMBDA(Index a) {
        const float v = speeds[a];
        float ph = phases[a];
        const std::int32_t k = keys[a];
        if (exact[a] != 0 || k < 0 || k >= key_phases.size()) {  // synthesised: its own cadence at its own speed
          ph += motion::cycle_rate(blend, motion::blend_point(blend, motion::blend_coordinate(blend, v)), v) * dt;
          phases[a] = motion::wrap_phase(ph);
          sources[a] = kNoSource;
          offsets[a] = 0;
          return;
        }
        const float F = key_frames[k];
        std::int32_t o = 0;
        const ClusterRef& ref = clusters[a * cluster_stride];
        if (ref.source == k) {
          o = ref.offset;  // same bucket: keep the offset, play at the stream's cadence
        } else {
          // Joining a stream: advance at the bucket's cadence, then take the
          // slot that shows this phase (the nearest; the phase snaps to it).
          ph +=
              motion::cycle_rate(quantised, motion::blend_point(quantised, motion::blend_coordinate(quantised, v)), v) *
              dt;
          o = static_cast<std::int32_t>(glm::floor(motion::wrap_phase(key_phases[k] - ph) * F + 0.5f));
          const std::int32_t top = streams[k].history - 1;
          o = o < 0 ? 0 : (o > top ? top : o);
        }
        phases[a] = motion::wrap_phase(key_phases[k] - static_cast<float>(o) / F);
        sources[a] = k;
        offsets[a] = o;
      },
      1024);
}

void ExactGatherJob::validate() const {
  const Index n = exact.size();
  check_length("ExactGatherJob", "ranks", ranks.size(), n);
  check_length("ExactGatherJob", "positions", positions.size(), n);
  check_length("ExactGatherJob", "yaws", yaws.size(), n);
  check_length("ExactGatherJob", "phases", phases.size(), n);
  check_length("ExactGatherJob", "speeds", speeds.size(), n);
  if (count < 0 || count > n)
    throw Error("must be in [0, " + std::to_string(n) + "]", at_field("ExactGatherJob.count"));
  // The outputs may be longer than count (buffers that keep their largest size).
  const auto at_least_room = [this](const char* field, Index got) {
    if (got < count)
      throw Error("has " + std::to_string(got) + " elements, fewer than count (" + std::to_string(count) + ")",
                  at_field(std::string("ExactGatherJob.") + field));
  };
  at_least_room("out_positions", out_positions.size());
  at_least_room("out_yaws", out_yaws.size());
  at_least_room("out_phases", out_phases.size());
  at_least_room("out_speeds", out_speeds.size());
}

void ExactGatherJob::run() const {
  validate();
  parallel_for(
      "anim.loco_streams_gather", exact.size(),
      THRONG_JOB_LAMBDA(Index a) {
        if (exact[a] == 0) return;
        const Index r = ranks[a];
        if (r < 0 || r >= count) return;
        out_positions[r] = positions[a];
        out_yaws[r] = yaws[a];
        out_phases[r] = phases[a];
        out_speeds[r] = speeds[a];
      },
      1024);
}

namespace {

// The model-space palette a stream's slot holds for an offset; null for the
// rest pose (kNoSource), a unique instance or a stream of another rig.
THRONG_HOST_DEVICE inline const Mat3x4* slot_palette(Span<const SourceView> streams, std::int32_t source,
                                                     std::int32_t offset, std::int32_t joints) {
  if (source < 0 || source >= streams.size()) return nullptr;
  const SourceView& s = streams[source];
  if (s.skinning == nullptr || s.joints != joints) return nullptr;
  return s.skinning + static_cast<Index>(history_slot(s, offset)) * joints;
}

}  // namespace

void StreamRefsJob::validate() const {
  const Index n = agent_count();
  if (joint_count <= 0) throw Error("must be positive", at_field("StreamRefsJob.joint_count"));
  check_length("StreamRefsJob", "clusters", clusters.size(), n * cluster_stride);
  check_length("StreamRefsJob", "exact", exact.size(), n);
  check_length("StreamRefsJob", "exact_ranks", exact_ranks.size(), n);
}

void StreamRefsJob::run() const {
  validate();
  const Index exact_count = exact_palettes.size() / joint_count;
  parallel_for(
      "anim.loco_streams_refs", agent_count(),
      THRONG_JOB_LAMBDA(Index a) {
        PaletteRef r;
        if (exact[a] != 0) {
          const Index rank = exact_ranks[a];
          if (rank >= 0 && rank < exact_count) {
            r.pose = exact_palettes.data() + rank * joint_count;
            r.world = 1u;
          }
          refs[a] = r;
          return;
        }
        const ClusterRef& c = clusters[a * cluster_stride];
        r.pose = slot_palette(streams, c.source, c.offset, joint_count);
        r.alpha = transition_alpha(c, frame);
        if (r.alpha < 1.0f) r.from = slot_palette(streams, c.from_source, c.from_offset, joint_count);
        refs[a] = r;
      },
      1024);
}

void PaletteComposeJob::validate() const {
  if (joint_count <= 0) throw Error("must be positive", at_field("PaletteComposeJob.joint_count"));
  const Index n = refs.size();
  check_length("PaletteComposeJob", "positions", positions.size(), n);
  check_length("PaletteComposeJob", "yaws", yaws.size(), n);
  check_length("PaletteComposeJob", "palettes", palettes.size(), count() * joint_count);
}

void PaletteComposeJob::run() const {
  validate();
  const Index n = refs.size();
  parallel_for(
      "anim.compose_palettes", count(),
      THRONG_JOB_LAMBDA(Index k) {
        const Index a = agents.empty() ? k : agents[k];
        if (a < 0 || a >= n) return;
        const PaletteRef r = refs[a];
        const Mat3x4 root = root_transform(positions[a], yaws[a]);
        for (std::int32_t j = 0; j < joint_count; ++j) palettes[k * joint_count + j] = compose_palette(r, root, j);
      },
      64);
}

// ---- the error of sharing ----------------------------------------------------------------------

namespace {

// Largest, mean and nearest-rank 95th percentile of per-agent errors (0 for none).
void summarise(std::vector<float> values, double& max, double& mean, double& p95) {
  max = mean = p95 = 0.0;
  if (values.empty()) return;
  double sum = 0.0;
  for (const float x : values) {
    max = std::max(max, static_cast<double>(x));
    sum += x;
  }
  mean = sum / static_cast<double>(values.size());
  const auto k = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  p95 = values[k];
}

}  // namespace

SharingError LocomotionStreams::sharing_error(Index at_most) const {
  SharingError e;
  if (count_ == 0) return e;
  // The agents compared, evenly spread over the crowd, and their inputs.
  const Index n = at_most > 0 ? std::min(at_most, count_) : count_;
  std::vector<Index> agents(static_cast<std::size_t>(n));
  for (Index k = 0; k < n; ++k) agents[static_cast<std::size_t>(k)] = k * count_ / n;
  const auto pick = [&](const auto& buffer) {
    const auto all = buffer.to_vector();
    std::vector<typename decltype(all)::value_type> some;
    for (const Index a : agents) some.push_back(all[static_cast<std::size_t>(a)]);
    return some;
  };
  const Memory m = current_memory();
  const Buffer<glm::vec3> positions(std::span<const glm::vec3>(pick(position_)), m);
  const Buffer<float> yaws(std::span<const float>(pick(yaw_)), m), phases(std::span<const float>(pick(phase_)), m),
      speeds(std::span<const float>(pick(speed_)), m);
  const Buffer<std::uint8_t> exact(std::span<const std::uint8_t>(pick(exact_)), m);
  const Buffer<Index> which(std::span<const Index>(agents), m);
  Buffer<glm::vec3> reference(n * joints_, m);
  Buffer<glm::quat> rotations(n * joints_, m);
  make_pose_job(tables_.view(), {positions.span(), yaws.span(), {}, phases.span(), speeds.span()}, reference.span(),
                rotations.span())
      .run();
  Buffer<Mat3x4> palettes(n * joints_, m);
  PaletteComposeJob{joints_, refs_.span(), position_.span(), yaw_.span(), which.span(), palettes.span()}.run();
  Buffer<float> errors(n, m);
  const std::int32_t J = joints_;
  const auto flags = exact.span();
  const auto pal = palettes.span();
  const auto bind = bind_positions_.span();
  const auto ref = reference.span();
  const auto out = errors.span();
  parallel_for(
      "anim.loco_streams_error", n,
      THRONG_LAMBDA(Index k) {
        if (flags[k] != 0) {
          out[k] = -1.0f;
          return;
        }
        float worst = 0.0f;
        for (std::int32_t j = 0; j < J; ++j)
          worst = glm::max(worst, glm::length(transform_point(pal[k * J + j], bind[j]) - ref[k * J + j]));
        out[k] = 100.0f * worst;
      },
      256);
  // Agents cross-fading between two streams apart from the others.
  const std::vector<PaletteRef> refs = pick(refs_);
  const std::vector<float> worst = errors.to_vector();
  std::vector<float> steady;
  for (std::size_t k = 0; k < worst.size(); ++k) {
    if (worst[k] < 0.0f) continue;
    e.agent_max_cm.push_back(worst[k]);
    const bool fading = refs[k].from != nullptr && refs[k].alpha < 1.0f;
    e.fading += fading ? 1 : 0;
    if (!fading) steady.push_back(worst[k]);
  }
  e.agents = static_cast<Index>(e.agent_max_cm.size());
  summarise(e.agent_max_cm, e.max_cm, e.mean_cm, e.p95_cm);
  double steady_mean = 0.0;
  summarise(steady, e.steady_max_cm, steady_mean, e.steady_p95_cm);
  return e;
}

}  // namespace throng::anim
