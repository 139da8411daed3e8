#include "anim/crowd_animator.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/check.h"
#include "core/error.h"
#include "core/timing.h"
#include "motion/leg_ik.h"

namespace throng::anim {

namespace {

std::size_t at(Index i) { return static_cast<std::size_t>(i); }

void check_blend(const char* job, const motion::BlendSpaceView& v) {
  if (v.joint_count < 1 || v.joint_count > kMaxLodJoints || v.clip_count < 1 || v.clips == nullptr ||
      v.sync == nullptr || v.parents == nullptr || v.offsets == nullptr || v.joint_group == nullptr ||
      v.mean_rotations == nullptr)
    throw Error("is not set (BlendSpaceTables::view())", at_field(std::string(job) + ".blend"));
}

template <class T>
Buffer<T> filled(Index n, T value) {
  const std::vector<T> v(at(n), value);
  return Buffer<T>(std::span<const T>(v), current_memory());
}

}  // namespace

void LocomoteJob::validate() const {
  check_blend("LocomoteJob", blend);
  if (!(std::isfinite(step.dt) && step.dt >= 0.0f && step.dt <= 10.0f))
    throw Error("must be in [0, 10] s", at_field("LocomoteJob.step.dt"));
  const Index n = character_count();
  check_length("LocomoteJob", "speeds", speeds.size(), n);
  check_optional_length("LocomoteJob", "turn_rates", turn_rates.size(), n);
  check_optional_length("LocomoteJob", "curvatures", curvatures.size(), n);
  check_optional_length("LocomoteJob", "scales", scales.size(), n);
  check_length("LocomoteJob", "yaws", yaws.size(), n);
  check_length("LocomoteJob", "phases", phases.size(), n);
  check_length("LocomoteJob", "blend_speeds", blend_speeds.size(), n);
}

void MapInputJob::validate() const {
  const Index n = character_count();
  check_length("MapInputJob", "map_velocities", map_velocities.size(), n);
  check_length("MapInputJob", "map_headings", map_headings.size(), n);
  check_length("MapInputJob", "positions", positions.size(), n);
  check_length("MapInputJob", "yaws", yaws.size(), n);
  check_length("MapInputJob", "speeds", speeds.size(), n);
}

PoseJob make_pose_job(const motion::BlendSpaceView& blend, const CharacterGait& gait, Span<glm::vec3> joint_positions,
                      Span<glm::quat> joint_rotations) {
  PoseJob pose;
  static_cast<CharacterGait&>(pose) = gait;
  pose.blend = blend;
  pose.joint_positions = joint_positions;
  pose.joint_rotations = joint_rotations;
  return pose;
}

void PoseJob::validate() const {
  check_blend("PoseJob", blend);
  const Index n = character_count();
  const Index J = blend.joint_count;
  check_length("PoseJob", "yaws", yaws.size(), n);
  check_optional_length("PoseJob", "scales", scales.size(), n);
  check_length("PoseJob", "phases", phases.size(), n);
  check_length("PoseJob", "blend_speeds", blend_speeds.size(), n);
  check_optional_length("PoseJob", "joint_masks", joint_masks.size(), n * mask_word_count(blend.joint_count));
  if (!cache.slots.empty()) {
    if (cache.bucket_count < 1 || !(cache.bucket_width > 0.0f))
      throw Error("must be positive", at_field("PoseJob.cache.bucket_count"));
    check_length("PoseJob", "cache.slots", cache.slots.size(),
                 static_cast<Index>(blend.segment_count()) * cache.bucket_count);
    if (cache.frames < 1) throw Error("must be positive with a cache", at_field("PoseJob.cache.frames"));
    if (cache.cycles.size() % (static_cast<Index>(cache.frames) * J) != 0)
      throw Error("size must be a multiple of cache.frames * joints", at_field("PoseJob.cache.cycles"));
    const Index slots = cache.cycles.size() / (static_cast<Index>(cache.frames) * J);
    check_length("PoseJob", "cache.drops", cache.drops.size(), slots * cache.frames);
    // Every slot a key names must exist (a bad table must not read past the arena).
    if (current_memory() == Memory::Host)
      for (Index k = 0; k < cache.slots.size(); ++k)
        if (cache.slots[k] >= slots)
          throw Error("names slot " + std::to_string(cache.slots[k]) + " of " + std::to_string(slots),
                      at_field("PoseJob.cache.slots"));
  }
  check_length("PoseJob", "joint_positions", joint_positions.size(), n * J);
  check_length("PoseJob", "joint_rotations", joint_rotations.size(), n * J);
  if (!draw_matrices.empty()) {
    check_length("PoseJob", "draw_matrices", draw_matrices.size(), n * J);
    check_length("PoseJob", "joint_shapes", joint_shapes.size(), J);
  }
  check_optional_length("PoseJob", "evaluated", evaluated.size(), n);
  check_optional_length("PoseJob", "from_cache", from_cache.size(), n);
  if (!locks.empty()) {
    lock_config.validate();
    check_length("PoseJob", "locks", locks.size(), 2 * n);
    if (!(std::isfinite(lock_dt) && lock_dt >= 0.0f && lock_dt <= 10.0f))
      throw Error("must be in [0, 10] s", at_field("PoseJob.lock_dt"));
  }
}

std::vector<glm::mat4x3> joint_shapes(const motion::Skeleton& skeleton, float thickness, float min_radius) {
  skeleton.validate();
  if (!(thickness > 0.0f && thickness < 10.0f && min_radius > 0.0f && min_radius < 10.0f))
    throw Error("thickness and min_radius must be positive", at_field("joint_shapes"));
  const std::int32_t J = skeleton.joint_count();
  std::vector<glm::vec3> bone(at(J), glm::vec3(0.0f));
  std::vector<std::int32_t> children(at(J), 0);
  for (std::int32_t j = 1; j < J; ++j) {
    const auto p = at(skeleton.parents[at(j)]);
    bone[p] += skeleton.offsets[at(j)];
    ++children[p];
  }
  std::vector<glm::mat4x3> out(at(J));
  for (std::int32_t j = 0; j < J; ++j) {
    glm::vec3 b = children[at(j)] > 0 ? bone[at(j)] / static_cast<float>(children[at(j)])
                                      : (skeleton.has_end_site[at(j)] ? skeleton.end_sites[at(j)] : glm::vec3(0.0f));
    const float length = glm::length(b);
    glm::mat4x3 f(0.0f);
    if (length < 1e-5f) {
      f[0] = glm::vec3(min_radius, 0.0f, 0.0f);
      f[1] = glm::vec3(0.0f, min_radius, 0.0f);
      f[2] = glm::vec3(0.0f, 0.0f, min_radius);
    } else {
      const glm::mat3 r = glm::mat3_cast(motion::rotation_between(glm::vec3(0.0f, 1.0f, 0.0f), b / length));
      const float radius = std::max(thickness * length, min_radius);
      f[0] = r[0] * radius;
      f[1] = r[1] * (0.5f * length);
      f[2] = r[2] * radius;
      f[3] = 0.5f * b;
    }
    out[at(j)] = f;
  }
  return out;
}

// --- the cache table -----------------------------------------------------------

CycleCacheTable::CycleCacheTable(const motion::BlendSpace1D& space, MotionCacheConfig config, std::int32_t frames)
    : space_(&space), cache_(config) {
  if (frames < 0 || frames > 100000) throw Error("must be in [0, 100000]", at_field("motion_cache.frames"));
  frames_ = frames > 0 ? frames : default_cache_frames(space);
  const std::int32_t J = space.joint_count();
  key_count_ = space.segment_count() * cache_.bucket_count();
  const std::size_t cycle_bytes = static_cast<std::size_t>(frames_) * static_cast<std::size_t>(J) * sizeof(glm::quat);
  slot_count_ = static_cast<std::int32_t>(
      std::min<std::size_t>(static_cast<std::size_t>(key_count_), config.capacity_bytes / cycle_bytes));
  host_slots_.assign(at(key_count_), -1);
  for (std::int32_t s = slot_count_ - 1; s >= 0; --s) free_slots_.push_back(s);
  slots_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_slots_), current_memory());
  cycles_ = Buffer<glm::quat>(static_cast<Index>(slot_count_) * frames_ * J, current_memory());
  drops_ = Buffer<float>(static_cast<Index>(slot_count_) * frames_, current_memory());
}

std::int32_t default_cache_frames(const motion::BlendSpace1D& space) {
  // Every blend's cycle lasts at most the longest moving clip's period (a
  // blend with idle takes the walk's); idle alone its own.
  double period = 0.0;
  for (const motion::LocomotionClip& c : space.clips())
    if (c.stride_m > motion::kMinStride) period = std::max(period, c.period_s);
  if (period <= 0.0)
    for (const motion::LocomotionClip& c : space.clips()) period = std::max(period, c.period_s);
  return std::clamp(static_cast<std::int32_t>(std::ceil(kCacheSamplesPerSecond * period)), 16, 100000);
}

CachedCycle CycleCacheTable::synthesise(std::int32_t segment, float w, std::vector<float>* drops) const {
  if (segment < 0 || segment >= space_->segment_count())
    throw Error("no such segment", at_field("motion_cache.segment"));
  const motion::BlendSpaceView view = space_->view();
  const std::int32_t J = view.joint_count;
  motion::BlendPoint point;
  point.segment = segment;
  point.a = segment;
  point.b = view.clip_count > 1 ? segment + 1 : segment;
  point.w = view.clip_count > 1 ? std::clamp(w, 0.0f, 1.0f) : 0.0f;
  CachedCycle cycle;
  cycle.frame_count = frames_;
  cycle.joint_count = J;
  const float speed = motion::mix_weight(view.clips[point.a].speed, view.clips[point.b].speed, point.w);
  const float rate = motion::cycle_rate(view, point, speed);
  cycle.duration = rate > 0.0f ? 1.0f / rate : motion::blended_period(view, point);
  cycle.rotations.resize(static_cast<std::size_t>(frames_) * static_cast<std::size_t>(J));
  if (drops != nullptr) drops->assign(static_cast<std::size_t>(frames_), 0.0f);
  for (std::int32_t k = 0; k < frames_; ++k) {
    const float phase = static_cast<float>(k) / static_cast<float>(frames_);
    const motion::CharacterFrame f = motion::character_frame_at(view, point, phase, glm::vec3(0.0f), 0.0f, 1.0f);
    const motion::PlantedLegs legs =
        motion::synthesise_locals(view, f, nullptr, cycle.rotations.data() + static_cast<std::size_t>(k) * J);
    if (drops != nullptr) (*drops)[at(k)] = legs.pelvis_drop;
  }
  return cycle;
}

std::int32_t CycleCacheTable::update(const std::vector<Index>& counts, std::int32_t max_new) {
  if (static_cast<std::int32_t>(counts.size()) != key_count_)
    throw Error("has " + std::to_string(counts.size()) + " keys, expected " + std::to_string(key_count_),
                at_field("motion_cache.counts"));
  const std::int32_t B = cache_.bucket_count();
  const std::int32_t J = space_->joint_count();
  std::int32_t stored = 0;
  bool changed = false;
  for (std::int32_t key = 0; key < key_count_; ++key) {
    const Index n = counts[at(key)];
    if (n <= 0) continue;
    const std::int32_t segment = key / B, bucket = key % B;
    const float w = cache_.bucket_centre(bucket);
    if (cache_.find(w, static_cast<std::uint32_t>(segment), n) != nullptr) continue;
    if (stored >= max_new) continue;
    std::vector<float> drops;
    const CachedCycle* held =
        cache_.insert(bucket, synthesise(segment, w, &drops), static_cast<std::uint32_t>(segment));
    ++stored;
    // FIFO evictions free their slots.
    for (std::int32_t k = 0; k < key_count_; ++k) {
      const std::int32_t slot = host_slots_[at(k)];
      if (slot < 0 || cache_.contains(k % B, static_cast<std::uint32_t>(k / B))) continue;
      free_slots_.push_back(slot);
      host_slots_[at(k)] = -1;
      changed = true;
    }
    if (held == nullptr || free_slots_.empty()) continue;
    const std::int32_t slot = free_slots_.back();
    free_slots_.pop_back();
    cycles_.write(static_cast<Index>(slot) * frames_ * J, std::span<const glm::quat>(held->rotations));
    drops_.write(static_cast<Index>(slot) * frames_, std::span<const float>(drops));
    host_slots_[at(key)] = slot;
    changed = true;
  }
  if (changed) slots_.copy_from(host_slots_);
  return stored;
}

QuantisationError CycleCacheTable::quantisation_error(std::int32_t w_samples, std::int32_t phase_samples) const {
  const motion::BlendSpaceView view = space_->view();
  QuantisationError total;
  double weighted = 0.0;
  for (std::int32_t segment = 0; segment < space_->segment_count(); ++segment) {
    const auto synthesise_at = [&](float w) { return synthesise(segment, w); };
    const auto exact = [&](float w, float phase, Span<glm::quat> out) {
      motion::BlendPoint point;
      point.segment = segment;
      point.a = segment;
      point.b = view.clip_count > 1 ? segment + 1 : segment;
      point.w = view.clip_count > 1 ? w : 0.0f;
      const motion::CharacterFrame f = motion::character_frame_at(view, point, phase, glm::vec3(0.0f), 0.0f, 1.0f);
      check_length("CrowdAnimator quantisation", "out", out.size(), Index{view.joint_count});
      motion::synthesise_locals(view, f, nullptr, out.data());
    };
    const QuantisationError e =
        measure_quantisation_error(cache_.config(), synthesise_at, exact, w_samples, phase_samples);
    if (e.max_deg > total.max_deg) {
      total.max_deg = e.max_deg;
      total.worst_w = static_cast<float>(segment) + e.worst_w;  // as a blend coordinate x
      total.worst_phase = e.worst_phase;
      total.worst_joint = e.worst_joint;
    }
    weighted += e.mean_deg * static_cast<double>(e.samples);
    total.samples += e.samples;
  }
  total.mean_deg = total.samples > 0 ? weighted / static_cast<double>(total.samples) : 0.0;
  return total;
}

// --- the animator ----------------------------------------------------------------

void CrowdAnimatorConfig::validate() const {
  if (lod) {
    if (lod_thresholds.size() + 1 > static_cast<std::size_t>(kMaxLodLevels))
      throw Error("at most " + std::to_string(kMaxLodLevels - 1) + " thresholds", at_field("lod.thresholds"));
  }
  if (cache) cache_config.validate();
  if (cache_frames < 0 || cache_frames > 100000) throw Error("must be in [0, 100000]", at_field("motion_cache.frames"));
  if (max_new_cycles_per_frame < 0) throw Error("must be >= 0", at_field("motion_cache.max_new_cycles_per_frame"));
  if (foot_lock) foot_lock_config.validate();
}

CrowdAnimator::CrowdAnimator(const motion::BlendSpace1D& space, Index count, CrowdAnimatorConfig config)
    : space_(&space), config_(std::move(config)), count_(count), joints_(space.joint_count()) {
  config_.validate();
  if (count < 0 || count > (Index{1} << 31)) throw Error("must be in [0, 2^31]", at_field("characters"));
  const Memory m = current_memory();
  const Index n = count;
  const Index J = joints_;
  tables_ = motion::BlendSpaceTables(space, m);
  position_ = Buffer<glm::vec3>::zeros(n, m);
  yaw_ = Buffer<float>::zeros(n, m);
  scale_ = filled(n, 1.0f);
  phase_ = Buffer<float>::zeros(n, m);
  blend_speed_ = filled(n, -1.0f);
  speed_ = Buffer<float>::zeros(n, m);
  turn_rate_ = Buffer<float>::zeros(n, m);
  curvature_ = Buffer<float>::zeros(n, m);
  joint_position_ = Buffer<glm::vec3>(n * J, m);
  joint_rotation_ = Buffer<glm::quat>(n * J, m);
  evaluated_ = Buffer<std::int32_t>(n, m);
  from_cache_ = Buffer<std::uint8_t>(n, m);
  if (config_.draw_matrices) {
    const std::vector<glm::mat4x3> shapes = joint_shapes(space.skeleton());
    shapes_ = Buffer<glm::mat4x3>(std::span<const glm::mat4x3>(shapes), m);
    draw_ = Buffer<glm::mat4x3>(n * J, m);
  }
  if (config_.lod) {
    parts_ = make_body_parts(space.skeleton());
    lod_config_ = make_lod_config(*parts_, config_.lod_thresholds);
    lod_tables_.emplace(*lod_config_, m);
    levels_ = Buffer<std::uint8_t>(n * kBodyPartCount, m);
    masks_ = Buffer<std::uint32_t>(n * lod_config_->mask_words, m);
  }
  if (config_.cache) cache_.emplace(space, config_.cache_config, config_.cache_frames);
  if (config_.foot_lock) locks_ = Buffer<FootLock>::zeros(2 * n, m);
}

void CrowdAnimator::place(std::span<const glm::vec3> positions, std::span<const float> yaws,
                          std::span<const float> scales, std::span<const float> phases) {
  check_length("CrowdAnimator.place", "positions", static_cast<Index>(positions.size()), count_);
  check_length("CrowdAnimator.place", "yaws", static_cast<Index>(yaws.size()), count_);
  check_optional_length("CrowdAnimator.place", "scales", static_cast<Index>(scales.size()), count_);
  check_optional_length("CrowdAnimator.place", "phases", static_cast<Index>(phases.size()), count_);
  for (float s : scales)
    if (!(std::isfinite(s) && s > 0.0f))
      throw Error("scales must be positive and finite", at_field("CrowdAnimator.place.scales"));
  position_.copy_from(positions);
  yaw_.copy_from(yaws);
  if (!scales.empty()) scale_.copy_from(scales);
  if (!phases.empty()) phase_.copy_from(phases);
  blend_speed_ = filled(count_, -1.0f);
  if (config_.foot_lock) locks_ = Buffer<FootLock>::zeros(2 * count_, current_memory());
}

void CrowdAnimator::set_lod_thresholds(const std::vector<float>& thresholds) {
  if (!parts_) throw Error("joint LOD is off for this crowd", at_field("lod.thresholds"));
  LodConfig config = make_lod_config(*parts_, thresholds);  // validated
  lod_tables_.emplace(config, current_memory());
  lod_config_ = std::move(config);
  config_.lod_thresholds = thresholds;
}

void CrowdAnimator::set_speeds(std::span<const float> speeds) {
  check_length("CrowdAnimator", "speeds", static_cast<Index>(speeds.size()), count_);
  speed_.copy_from(speeds);
}
void CrowdAnimator::set_turn_rates(std::span<const float> turn_rates) {
  check_length("CrowdAnimator", "turn_rates", static_cast<Index>(turn_rates.size()), count_);
  turn_rate_.copy_from(turn_rates);
}
void CrowdAnimator::set_curvatures(std::span<const float> curvatures) {
  check_length("CrowdAnimator", "curvatures", static_cast<Index>(curvatures.size()), count_);
  curvature_.copy_from(curvatures);
}

void CrowdAnimator::drive_from_map(Span<const glm::vec2> positions, Span<const glm::vec2> velocities,
                                   Span<const float> headings) {
  check_length("CrowdAnimator.drive_from_map", "positions", positions.size(), count_);
  const MapInputJob job{positions, velocities, headings, position_.span(), yaw_.span(), speed_.span()};
  job.run();
}

const FrameStats& CrowdAnimator::animate(const FrameInput& input) {
  if (!(std::isfinite(input.dt) && input.dt >= 0.0f && input.dt <= 10.0f))
    throw Error("must be in [0, 10] s", at_field("frame.dt"));
  motion::BlendSpaceView view = tables_.view();
  if (cache_) {  // every character shows its bucket's blend: a cached cycle is exactly its pose
    view.quantum = cache_->bucket_width();
    view.quantum_buckets = cache_->bucket_count();
  }
  const LocomoteJob locomote{.blend = view,
                             .step = {input.dt, config_.hold_until_cycle_end, input.integrate_root},
                             .speeds = speed_.span(),
                             .turn_rates = turn_rate_.span(),
                             .curvatures = curvature_.span(),
                             .scales = scale_.span(),
                             .positions = position_.span(),
                             .yaws = yaw_.span(),
                             .phases = phase_.span(),
                             .blend_speeds = blend_speed_.span()};
  locomote.run();

  stats_ = FrameStats{};
  stats_.characters = count_;
  const bool lod = config_.lod && input.camera != nullptr;
  if (lod) {
    input.camera->validate();
    make_lod_job(*input.camera, *lod_tables_, *parts_, {position_.span(), yaw_.span(), scale_.span()}, levels_.span(),
                 masks_.span())
        .run();
    stats_.lod = lod_histogram(levels_.span(), masks_.span(), lod_config_->level_count, lod_config_->joint_count);
  }
  if (cache_) {
    ScopedTimer timer("anim.cache_update");
    const std::vector<Index> counts =
        cache_key_counts(view, blend_speed_.span(), cache_->bucket_width(), cache_->bucket_count());
    stats_.cycles_stored = cache_->update(counts, config_.max_new_cycles_per_frame);
  }

  PoseJob pose = make_pose_job(view, {position_.span(), yaw_.span(), scale_.span(), phase_.span(), blend_speed_.span()},
                               joint_position_.span(), joint_rotation_.span());
  if (lod) pose.joint_masks = masks_.span();
  if (cache_) pose.cache = cache_->view();
  if (config_.draw_matrices) {
    pose.joint_shapes = shapes_.span();
    pose.draw_matrices = draw_.span();
  }
  pose.evaluated = evaluated_.span();
  pose.from_cache = from_cache_.span();
  if (config_.foot_lock) {
    pose.locks = locks_.span();
    pose.lock_config = config_.foot_lock_config;
    pose.lock_dt = input.dt;
  }
  pose.run();

  const PoseTotals totals = pose_totals(evaluated_.span(), from_cache_.span());
  stats_.joints_synthesised = totals.joints_synthesised;
  stats_.from_cache = totals.from_cache;
  if (cache_) stats_.cache = cache_->cache().stats();

  if (!skating_.tracked().empty()) {
    if (skating_.frames() == 0) track_dt_ = input.dt;
    const std::size_t J = static_cast<std::size_t>(joints_);
    const Index words = mask_word_count(joints_);
    std::vector<std::uint32_t> mask(static_cast<std::size_t>(words));
    for (std::size_t t = 0; t < skating_.tracked().size(); ++t) {
      // Legs that joint LOD holds are not synthesised: not measured.
      bool feet = true;
      if (lod) {
        masks_.read(skating_.tracked()[t] * words, std::span<std::uint32_t>(mask));
        for (int leg = 0; leg < 2; ++leg)
          feet = feet && (view.legs[leg].count < 4 || motion::plants_leg(view, leg, mask.data()));
      }
      const motion::FootSkatingRecorder::Frame f = skating_.append(t, feet);
      const Index first = skating_.tracked()[t] * joints_;
      joint_position_.read(first, f.positions.first(J));
      joint_rotation_.read(first, f.rotations.first(J));
    }
    skating_.end_frame();
  }
  return stats_;
}

void CrowdAnimator::track(std::vector<Index> characters) { skating_.track(std::move(characters), count_, joints_); }

motion::FootSkatingReport CrowdAnimator::foot_skating(const motion::ContactOptions& options) const {
  return skating_.measure(space_->skeleton(), track_dt_, options);
}

}  // namespace throng::anim
