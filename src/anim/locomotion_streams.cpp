#include "anim/locomotion_streams.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/array_kernels.h"
#include "core/check.h"
#include "core/error.h"
#include "core/random.h"
#include "core/timing.h"

namespace throng::anim {

namespace {

// The blend space as streamed agents show it: every blend at its bucket's centre.
motion::BlendSpaceView quantised_view(motion::BlendSpaceView v, float width, std::int32_t buckets) {
  v.quantum = width;
  v.quantum_buckets = buckets;
  return v;
}

}  // namespace

void LocomotionStreamsConfig::validate() const {
  auto field = [](const char* f) { return at_field(std::string("locomotion_streams.") + f); };
  if (!(frame_rate >= 1.0f && frame_rate <= 1000.0f))
    throw Error("must be in [1, 1000] frames per second", field("frame_rate"));
  MotionCacheConfig{bucket_width, 0}.validate();
  if (!(blend_seconds >= 0.0f && blend_seconds <= 60.0f)) throw Error("must be in [0, 60] s", field("blend_seconds"));
  if (!(exact_coverage > 0.0f && std::isfinite(exact_coverage)))
    throw Error("must be positive square pixels", field("exact_coverage"));
  if (!(stop_after_seconds >= 0.0f && stop_after_seconds <= 1e6f))
    throw Error("must be in [0, 1e6] s", field("stop_after_seconds"));
}

LocomotionStreams::LocomotionStreams(std::shared_ptr<const motion::BlendSpace1D> space, Index agents,
                                     LocomotionStreamsConfig config)
    : space_(std::move(space)),
      config_(config),
      count_(agents),
      crowd_(StreamCrowdConfig{config.frame_rate, config.seed, config.footstep_events}) {
  if (!space_) throw Error("needs a blend space", at_field("locomotion_streams.space"));
  config_.validate();
  if (agents < 0 || agents > (Index{1} << 31))
    throw Error("must be in [0, 2^31]", at_field("locomotion_streams.agents"));
  const Memory m = current_memory();
  joints_ = space_->joint_count();
  tables_ = motion::BlendSpaceTables(*space_, m);
  buckets_ = motion::weight_bucket_count(config_.bucket_width);
  keys_ = space_->segment_count() * buckets_;

  const std::int32_t rig = crowd_.add_rig(make_rig("locomotion", space_->skeleton()));
  const std::int32_t left = crowd_.event_names().intern("footstep_left");
  const std::int32_t right = crowd_.event_names().intern("footstep_right");
  const std::vector<motion::ClipInfo>& clips = space_->clip_infos();
  for (std::int32_t k = 0; k < keys_; ++k) {
    const std::int32_t segment = k / buckets_;
    const float w = motion::weight_bucket_centre(k % buckets_, config_.bucket_width);
    const auto s = static_cast<std::size_t>(segment);
    const float speed = clips.size() > 1 ? motion::mix_weight(clips[s].speed, clips[s + 1].speed, w) : clips[0].speed;
    Blend1DOptions options;
    options.speed = speed;
    options.footstep_left = left;
    options.footstep_right = right;
    auto controller = std::make_unique<Blend1DController>(space_, options);
    const float rate = controller->cycles_per_second();
    const float frames = rate > 0.0f ? config_.frame_rate / rate : 1.0f;
    if (!(frames <= 65000.0f))
      throw Error("a cycle of " + std::to_string(frames) + " frames is too long for a stream's history",
                  at_field("locomotion_streams.frame_rate"));
    StreamSpec spec;
    spec.name = "locomotion_" + std::to_string(segment) + "_" + std::to_string(k % buckets_);
    spec.history = static_cast<std::int32_t>(std::ceil(frames)) + 1;  // one whole cycle: every phase has a slot
    spec.root = RootMotion::Keep;  // the controller's root is already relative to the agent (the path point)
    spec.running = false;
    controllers_.push_back(controller.get());
    crowd_.streams().add(crowd_.rig(rig), rig, spec, std::move(controller));
    key_speed_.push_back(speed);
    key_frames_.push_back(frames);
  }
  last_used_.assign(static_cast<std::size_t>(keys_), -1);
  key_phase_ = Buffer<float>::zeros(keys_, m);
  key_frames_device_ = Buffer<float>(std::span<const float>(key_frames_), m);

  crowd_.add_agents(rig, count_);
  position_ = Buffer<glm::vec3>::zeros(count_, m);
  yaw_ = Buffer<float>::zeros(count_, m);
  speed_ = Buffer<float>::zeros(count_, m);
  std::vector<float> phases(static_cast<std::size_t>(count_));
  for (Index a = 0; a < count_; ++a)
    phases[static_cast<std::size_t>(a)] =
        static_cast<float>(Rng(config_.seed, static_cast<std::uint64_t>(a)).uniform());
  phase_ = Buffer<float>(std::span<const float>(phases), m);
  exact_ = Buffer<std::uint8_t>::zeros(count_, m);
  key_ = Buffer<std::int32_t>(count_, m);
  source_ = Buffer<std::int32_t>(count_, m);
  offset_ = Buffer<std::int32_t>(count_, m);
  exact_rank_ = Buffer<std::int32_t>(count_, m);
  refs_ = Buffer<PaletteRef>::zeros(count_, m);  // the rest pose until the first frame
  inverse_bind_ = Buffer<Mat3x4>(std::span<const Mat3x4>(crowd_.rig(rig).inverse_bind), m);
  bind_positions_ = Buffer<glm::vec3>(std::span<const glm::vec3>(crowd_.rig(rig).bind_positions), m);
  if (config_.exact_near_camera) {
    const BodyParts parts = make_body_parts(space_->skeleton());
    for (int p = 0; p < kBodyPartCount; ++p) part_spheres_[p] = parts.rest_spheres[static_cast<std::size_t>(p)];
  }
}

void LocomotionStreams::drive_from_map(Span<const glm::vec2> positions, Span<const glm::vec2> velocities,
                                       Span<const float> headings) {
  check_length("locomotion_streams", "drive_from_map.positions", positions.size(), count_);
  MapInputJob{positions, velocities, headings, position_.span(), yaw_.span(), speed_.span()}.run();
}

void LocomotionStreams::set_agents(std::span<const glm::vec3> positions, std::span<const float> yaws,
                                   std::span<const float> speeds) {
  check_length("locomotion_streams", "positions", static_cast<Index>(positions.size()), count_);
  check_length("locomotion_streams", "yaws", static_cast<Index>(yaws.size()), count_);
  check_length("locomotion_streams", "speeds", static_cast<Index>(speeds.size()), count_);
  position_.copy_from(positions);
  yaw_.copy_from(yaws);
  speed_.copy_from(speeds);
}

void LocomotionStreams::set_phases(std::span<const float> phases) {
  check_length("locomotion_streams", "phases", static_cast<Index>(phases.size()), count_);
  for (float p : phases)
    if (!(p >= 0.0f && p < 1.0f)) throw Error("must be in [0, 1)", at_field("locomotion_streams.phases"));
  phase_.copy_from(phases);
}

const LocomotionStreamsStats& LocomotionStreams::animate(const Camera* camera) {
  if (camera != nullptr) camera->validate();
  stats_ = LocomotionStreamsStats{};
  stats_.agents = count_;
  stats_.streams = keys_;
  const std::vector<Index> counts = classify(camera);  // exact flags, bucket keys, stats_.exact
  stats_.streamed = count_ - stats_.exact;
  {
    // Host: streams started or stopped by use, the running ones evaluated (their events reach agents in a kernel).
    ScopedTimer timer("anim.loco_streams_update");
    manage_streams(counts);
    crowd_.step();
    std::vector<float> phases(static_cast<std::size_t>(keys_), 0.0f);
    for (std::int32_t k = 0; k < keys_; ++k)
      phases[static_cast<std::size_t>(k)] = controllers_[static_cast<std::size_t>(k)]->phase();
    key_phase_.copy_from(std::span<const float>(phases));
  }
  select(1.0f / config_.frame_rate);
  stats_.retargeted = crowd_.retarget(source_.span(), offset_.span(), config_.blend_seconds);
  synthesise_exact();
  make_refs();
  record_tracks();

  const StreamMemory memory = crowd_.memory();
  stats_.pose_bytes = memory.stream_poses;
  stats_.palette_bytes = static_cast<std::size_t>(stats_.exact) * static_cast<std::size_t>(joints_) * sizeof(Mat3x4);
  stats_.ref_bytes = static_cast<std::size_t>(count_) * sizeof(PaletteRef);
  stats_.agent_state_bytes =
      memory.agent_state + static_cast<std::size_t>(count_) * (sizeof(glm::vec3) + 3 * sizeof(float) +
                                                               sizeof(std::uint8_t) + 4 * sizeof(std::int32_t));
  stats_.exact_bytes = static_cast<std::size_t>(stats_.exact) *
                       (sizeof(Index) + sizeof(glm::vec3) + 3 * sizeof(float) +
                        static_cast<std::size_t>(joints_) * (sizeof(glm::vec3) + sizeof(glm::quat)));
  for (std::int32_t k = 0; k < keys_; ++k) {
    if (crowd_.streams()[k].state() == StreamState::Running) ++stats_.streams_running;
    if (counts[static_cast<std::size_t>(k)] > 0) ++stats_.streams_in_use;
  }
  return stats_;
}

void LocomotionStreams::manage_streams(const std::vector<Index>& counts) {
  const std::int32_t next = crowd_.frame() + 1;  // the frame the coming step writes
  const auto idle_frames = static_cast<std::int32_t>(std::ceil(config_.stop_after_seconds * config_.frame_rate));
  for (std::int32_t k = 0; k < keys_; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    AnimStream& stream = crowd_.streams()[k];
    if (counts[ku] > 0) {
      last_used_[ku] = next;
      if (stream.state() != StreamState::Running) {
        // Filled at once: an agent joining reads its own phase's slot now.
        crowd_.streams().start_filled(k, crowd_.frame());
        ++stats_.streams_started;
      }
    } else if (stream.state() == StreamState::Running && next - last_used_[ku] > idle_frames) {
      crowd_.streams().stop(k);
    }
  }
}

std::vector<Index> LocomotionStreams::classify(const Camera* camera) {
  StreamBucketJob buckets;
  buckets.blend = quantised_view(tables_.view(), config_.bucket_width, buckets_);
  buckets.bucket_width = config_.bucket_width;
  buckets.bucket_count = buckets_;
  buckets.speeds = speed_.span();
  buckets.near_camera = config_.exact_near_camera && camera != nullptr;
  if (buckets.near_camera) {
    buckets.camera = make_camera_view(*camera);
    buckets.exact_coverage = config_.exact_coverage;
    for (int p = 0; p < kBodyPartCount; ++p) buckets.part_spheres[p] = part_spheres_[p];
    buckets.body_sphere = body_sphere(part_spheres_);
    buckets.positions = position_.span();
    buckets.yaws = yaw_.span();
  }
  buckets.exact = exact_.span();
  buckets.exact_flags = exact_rank_.span();
  buckets.keys = key_.span();
  buckets.run();
  stats_.exact = buckets.near_camera ? count_nonzero(exact_.span()) : 0;
  return histogram(key_.span(), keys_);
}

glm::vec4 body_sphere(const glm::vec4 (&parts)[kBodyPartCount]) {
  float low = parts[0].y - parts[0].w, high = parts[0].y + parts[0].w;
  for (const glm::vec4& p : parts) {
    low = std::min(low, p.y - p.w);
    high = std::max(high, p.y + p.w);
  }
  const float y = 0.5f * (low + high);
  float radius = 0.0f;
  for (const glm::vec4& p : parts)
    radius = std::max(radius, glm::length(glm::vec3(p) - glm::vec3(0.0f, y, 0.0f)) + p.w);
  return glm::vec4(0.0f, y, 0.0f, radius);
}

void LocomotionStreams::select(float dt) {
  StreamSelectJob job;
  job.blend = tables_.view();
  job.quantised = quantised_view(job.blend, config_.bucket_width, buckets_);
  job.dt = dt;
  job.speeds = speed_.span();
  job.exact = exact_.span();
  job.keys = key_.span();
  job.key_phases = key_phase_.span();
  job.key_frames = key_frames_device_.span();
  job.streams = crowd_.streams().views();
  job.clusters = crowd_.cluster_refs();
  job.cluster_stride = crowd_.cluster_stride();
  job.phases = phase_.span();
  job.sources = source_.span();
  job.offsets = offset_.span();
  job.run();
}

void LocomotionStreams::synthesise_exact() {
  if (stats_.exact == 0) return;
  const Memory m = current_memory();
  const Index n = stats_.exact;
  exclusive_scan(exact_rank_.span(), exact_rank_.span());
  if (exact_position_.size() < n) {  // grows to the largest exact count seen
    const Index cap = std::max(n, exact_position_.size() * 2);
    exact_position_ = Buffer<glm::vec3>(cap, m);
    exact_yaw_ = Buffer<float>(cap, m);
    exact_phase_ = Buffer<float>(cap, m);
    exact_speed_ = Buffer<float>(cap, m);
    joint_position_ = Buffer<glm::vec3>(cap * joints_, m);
    joint_rotation_ = Buffer<glm::quat>(cap * joints_, m);
    exact_palettes_ = Buffer<Mat3x4>(cap * joints_, m);
  }
  const ExactGatherJob gather{.exact = exact_.span(),
                              .ranks = exact_rank_.span(),
                              .positions = position_.span(),
                              .yaws = yaw_.span(),
                              .phases = phase_.span(),
                              .speeds = speed_.span(),
                              .count = n,
                              .out_positions = exact_position_.span(),
                              .out_yaws = exact_yaw_.span(),
                              .out_phases = exact_phase_.span(),
                              .out_speeds = exact_speed_.span()};
  gather.run();
  const PoseJob pose =
      make_pose_job(tables_.view(),
                    {exact_position_.span().subspan(0, n),
                     exact_yaw_.span().subspan(0, n),
                     {},
                     exact_phase_.span().subspan(0, n),
                     exact_speed_.span().subspan(0, n)},
                    joint_position_.span().subspan(0, n * joints_), joint_rotation_.span().subspan(0, n * joints_));
  pose.run();
  JointPaletteJob palettes;
  palettes.joint_count = joints_;
  palettes.joint_positions = pose.joint_positions;
  palettes.joint_rotations = pose.joint_rotations;
  palettes.inverse_bind = inverse_bind_.span();
  palettes.palettes = exact_palettes_.span();  // densely, in the order of the exact agents
  palettes.run();
}

void LocomotionStreams::make_refs() {
  const StreamRefsJob refs{.streams = crowd_.streams().views(),
                           .clusters = crowd_.cluster_refs(),
                           .cluster_stride = crowd_.cluster_stride(),
                           .frame = crowd_.frame(),
                           .joint_count = joints_,
                           .exact = exact_.span(),
                           .exact_ranks = exact_rank_.span(),
                           .exact_palettes = exact_palettes_.span(),
                           .refs = refs_.span()};
  refs.run();
}

Span<const Mat3x4> LocomotionStreams::palettes() const {
  if (palettes_.size() != count_ * joints_) palettes_ = Buffer<Mat3x4>(count_ * joints_, current_memory());
  PaletteComposeJob{joints_, refs_.span(), position_.span(), yaw_.span(), {}, palettes_.span()}.run();
  return palettes_.span();
}

void LocomotionStreams::track(std::vector<Index> agents) {
  skating_.track(std::move(agents), count_, joints_);
  tracked_palettes_ = Buffer<Mat3x4>();  // sized to the new agents at the next frame
}

void LocomotionStreams::record_tracks() {
  if (skating_.tracked().empty()) return;
  const auto J = static_cast<std::size_t>(joints_);
  const Rig& r = rig();
  const auto tracked = static_cast<Index>(skating_.tracked().size());
  if (tracked_palettes_.size() != tracked * joints_) {
    const Memory memory = current_memory();
    tracked_agents_ = Buffer<Index>(std::span<const Index>(skating_.tracked()), memory);
    tracked_palettes_ = Buffer<Mat3x4>(tracked * joints_, memory);
  }
  PaletteComposeJob{joints_,     refs_.span(),           position_.span(),
                    yaw_.span(), tracked_agents_.span(), tracked_palettes_.span()}
      .run();
  const std::vector<Mat3x4> palettes = tracked_palettes_.to_vector();
  for (std::size_t t = 0; t < skating_.tracked().size(); ++t) {
    const motion::FootSkatingRecorder::Frame f = skating_.append(t);
    for (std::size_t j = 0; j < J; ++j) {
      // The palette maps the bind pose to the world; the bind rotations are
      // identity, so its linear part is the joint's world rotation.
      const Mat3x4& m = palettes[t * J + j];
      f.positions[j] = transform_point(m, r.bind_positions[j]);
      const glm::mat3 rotation(glm::vec3(m.r0.x, m.r1.x, m.r2.x), glm::vec3(m.r0.y, m.r1.y, m.r2.y),
                               glm::vec3(m.r0.z, m.r1.z, m.r2.z));
      f.rotations[j] = glm::normalize(glm::quat_cast(rotation));
    }
  }
  skating_.end_frame();
}

motion::FootSkatingReport LocomotionStreams::foot_skating(const motion::ContactOptions& options) const {
  return skating_.measure(space_->skeleton(), 1.0 / config_.frame_rate, options);
}

}  // namespace throng::anim
