#include "anim/motion_cache.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace throng::anim {

void CachedCycle::validate() const {
  if (frame_count <= 0) throw Error("must be positive", at_field("cycle.frame_count"));
  if (joint_count <= 0) throw Error("must be positive", at_field("cycle.joint_count"));
  const std::size_t want = static_cast<std::size_t>(frame_count) * static_cast<std::size_t>(joint_count);
  if (rotations.size() != want)
    throw Error("has " + std::to_string(rotations.size()) + " rotations, expected " + std::to_string(want),
                at_field("cycle.rotations"));
  if (!(std::isfinite(duration) && duration > 0.0f))
    throw Error("must be positive and finite", at_field("cycle.duration"));
}

double rotation_angle_deg(const glm::quat& a, const glm::quat& b) {
  // In double, from the relative rotation's vector and scalar parts: accurate
  // near 0 degrees, where acos of a dot product loses every digit.
  const glm::dquat r = glm::inverse(glm::dquat(a)) * glm::dquat(b);
  const double v = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
  return 2.0 * std::atan2(v, std::abs(r.w)) * (180.0 / 3.14159265358979323846);
}

void MotionCacheConfig::validate() const {
  if (!(std::isfinite(bucket_width) && bucket_width >= 1e-4f && bucket_width <= 1.0f))
    throw Error("must be in [0.0001, 1], got " + std::to_string(bucket_width), at_field("motion_cache.bucket_width"));
}

MotionCache::MotionCache(MotionCacheConfig config) : config_(config) {
  config_.validate();
  bucket_count_ = motion::weight_bucket_count(config_.bucket_width);
}

std::int32_t MotionCache::bucket_of(float w) const { return cache_bucket(w, config_.bucket_width, bucket_count_); }

float MotionCache::bucket_centre(std::int32_t bucket) const {
  return motion::weight_bucket_centre(bucket, config_.bucket_width);
}

const CachedCycle* MotionCache::find(float w, std::uint32_t state, std::int64_t lookups) {
  const auto it = entries_.find(key(state, bucket_of(w)));
  if (it == entries_.end()) {
    stats_.misses += lookups;
    return nullptr;
  }
  stats_.hits += lookups;
  return it->second.get();
}

bool MotionCache::contains(std::int32_t bucket, std::uint32_t state) const {
  return entries_.count(key(state, bucket)) != 0;
}

void MotionCache::erase(std::uint64_t k) {
  const auto it = entries_.find(k);
  if (it == entries_.end()) return;
  stats_.bytes -= it->second->bytes();
  entries_.erase(it);
  order_.erase(std::find(order_.begin(), order_.end(), k));
  stats_.entries = entries_.size();
}

const CachedCycle* MotionCache::insert(std::int32_t bucket, CachedCycle cycle, std::uint32_t state) {
  if (bucket < 0 || bucket >= bucket_count_)
    throw Error("bucket " + std::to_string(bucket) + " is not in [0, " + std::to_string(bucket_count_) + ")",
                at_field("motion_cache.bucket"));
  cycle.validate();
  const std::size_t size = cycle.bytes();
  const std::uint64_t k = key(state, bucket);
  erase(k);  // a replacement is a new entry, not an eviction
  if (size > config_.capacity_bytes) {
    ++stats_.rejected;
    return nullptr;
  }
  while (stats_.bytes + size > config_.capacity_bytes) {
    erase(order_.front());
    ++stats_.evictions;
  }
  auto stored = std::make_unique<CachedCycle>(std::move(cycle));
  const CachedCycle* out = stored.get();
  entries_.emplace(k, std::move(stored));
  order_.push_back(k);
  stats_.bytes += size;
  stats_.entries = entries_.size();
  ++stats_.insertions;
  return out;
}

const CachedCycle& MotionCache::get(float w, const Synthesise& synthesise, std::uint32_t state) {
  if (const CachedCycle* hit = find(w, state)) return *hit;
  const std::int32_t b = bucket_of(w);
  CachedCycle cycle = synthesise(bucket_centre(b));
  cycle.validate();
  if (cycle.bytes() > config_.capacity_bytes) {
    ++stats_.rejected;
    uncached_ = std::move(cycle);
    return uncached_;
  }
  return *insert(b, std::move(cycle), state);
}

void MotionCache::sample(float w, float phase, const Synthesise& synthesise, Span<glm::quat> out, std::uint32_t state) {
  const CachedCycle& cycle = get(w, synthesise, state);
  if (out.size() != cycle.joint_count)
    throw Error(
        "has " + std::to_string(out.size()) + " rotations, the cycle " + std::to_string(cycle.joint_count) + " joints",
        at_field("motion_cache.sample.out"));
  sample_cycle(cycle, phase, out.data());
}

void MotionCache::reset_counters() {
  stats_.hits = stats_.misses = stats_.insertions = stats_.evictions = stats_.rejected = 0;
}

void MotionCache::clear() {
  entries_.clear();
  order_.clear();
  stats_.bytes = 0;
  stats_.entries = 0;
}

std::vector<std::pair<std::uint32_t, std::int32_t>> MotionCache::fifo_order() const {
  std::vector<std::pair<std::uint32_t, std::int32_t>> out;
  for (std::uint64_t k : order_)
    out.emplace_back(static_cast<std::uint32_t>(k >> 32), static_cast<std::int32_t>(k & 0xffffffffu));
  return out;
}

QuantisationError measure_quantisation_error(const MotionCacheConfig& config, const MotionCache::Synthesise& synthesise,
                                             std::int32_t w_samples, std::int32_t phase_samples) {
  // The exact pose: a cycle synthesised at w itself, read at the phase.
  float cycle_w = NAN;
  CachedCycle at_w;
  const ExactPose exact = [&](float w, float phase, Span<glm::quat> out) {
    if (!(w == cycle_w)) {
      at_w = synthesise(w);
      at_w.validate();
      cycle_w = w;
    }
    if (out.size() != at_w.joint_count)
      throw Error("synthesis gave cycles with different joint counts", at_field("quantisation_error.synthesise"));
    sample_cycle(at_w, phase, out.data());
  };
  return measure_quantisation_error(config, synthesise, exact, w_samples, phase_samples);
}

QuantisationError measure_quantisation_error(const MotionCacheConfig& config, const MotionCache::Synthesise& synthesise,
                                             const ExactPose& exact, std::int32_t w_samples,
                                             std::int32_t phase_samples) {
  if (w_samples < 1 || w_samples > 100000)
    throw Error("must be in [1, 100000]", at_field("quantisation_error.w_samples"));
  if (phase_samples < 1 || phase_samples > 100000)
    throw Error("must be in [1, 100000]", at_field("quantisation_error.phase_samples"));
  const MotionCache buckets(config);  // for the bucket arithmetic only
  QuantisationError e;
  double sum = 0.0;
  Index terms = 0;
  std::unordered_map<std::int32_t, CachedCycle> bucket_cycles;
  std::vector<glm::quat> cached, exact_pose;
  for (std::int32_t i = 0; i < w_samples; ++i) {
    const float w = w_samples == 1 ? 0.5f : static_cast<float>(i) / static_cast<float>(w_samples - 1);
    const std::int32_t b = buckets.bucket_of(w);
    auto it = bucket_cycles.find(b);
    if (it == bucket_cycles.end()) {
      it = bucket_cycles.emplace(b, synthesise(buckets.bucket_centre(b))).first;
      it->second.validate();
    }
    const CachedCycle& from_bucket = it->second;
    const auto J = static_cast<std::size_t>(from_bucket.joint_count);
    cached.resize(J);
    exact_pose.resize(J);
    for (std::int32_t k = 0; k < phase_samples; ++k) {
      const float phase = static_cast<float>(k) / static_cast<float>(phase_samples);
      sample_cycle(from_bucket, phase, cached.data());
      exact(w, phase, Span<glm::quat>(exact_pose.data(), static_cast<Index>(J)));
      for (std::size_t j = 0; j < J; ++j) {
        const double a = rotation_angle_deg(cached[j], exact_pose[j]);
        sum += a;
        ++terms;
        if (a > e.max_deg) {
          e.max_deg = a;
          e.worst_w = w;
          e.worst_phase = phase;
          e.worst_joint = static_cast<std::int32_t>(j);
        }
      }
      ++e.samples;
    }
  }
  e.mean_deg = terms > 0 ? sum / static_cast<double>(terms) : 0.0;
  return e;
}

}  // namespace throng::anim
