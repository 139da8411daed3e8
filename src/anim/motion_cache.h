// The 2019 motion cache: synthesised locomotion cycles keyed by quantised speed.
//
// Synthesising a cycle for a speed parameter w in [0, 1] costs a SLERP per
// joint per frame; characters whose w falls in the same bucket (of width
// bucket_width) can share one cycle synthesised at the bucket's centre and
// read it at their own phase. Entries leave in FIFO order when the byte
// capacity (20 MiB by default, as in the paper) would be exceeded. The error
// this introduces is measured by measure_quantisation_error.
//
// A key may also carry a state (a locomotion set, a gait, a skeleton), so
// one cache can serve several clip sets; state 0 is the default.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <glm/common.hpp>
#include <glm/gtc/quaternion.hpp>
#include <memory>
#include <unordered_map>
#include <vector>

#include "core/config.h"
#include "core/span.h"
#include "motion/locomotion.h"
#include "motion/phase.h"

namespace throng::anim {

// One cycle: frame k is at normalised phase k / frame_count, and phase 1
// wraps back to frame 0 (the last frame is not a copy of the first).
struct CachedCycle {
  std::int32_t frame_count = 0;
  std::int32_t joint_count = 0;
  float duration = 0.0f;             // seconds per cycle
  std::vector<glm::quat> rotations;  // frame-major local rotations: [frame * joint_count + joint]

  std::size_t bytes() const { return rotations.size() * sizeof(glm::quat); }
  // Throws Error: non-positive counts, size mismatch, non-finite duration.
  void validate() const;
};

// Phase sampling is motion's (motion/phase.h); the cache reads cycles with it.
using motion::cycle_point;
using motion::CyclePoint;
using motion::sample_cycle;

inline void sample_cycle(const CachedCycle& cycle, float phase, glm::quat* out) {
  sample_cycle(cycle.rotations.data(), cycle.frame_count, cycle.joint_count, phase, out);
}

// The bucket of w for buckets of `width` (w clamped into [0, 1], NaN -> 0,
// w = 1 in the last bucket): host and kernels compute it the same way.
THRONG_HOST_DEVICE inline std::int32_t cache_bucket(float w, float width, std::int32_t bucket_count) {
  return motion::weight_bucket(w, width, bucket_count);
}

// Angle of the rotation taking a to b, degrees in [0, 180] (q and -q are the same rotation).
double rotation_angle_deg(const glm::quat& a, const glm::quat& b);

struct MotionCacheConfig {
  float bucket_width = 0.05f;                        // of w; 1 / bucket_width buckets (the last may be narrower)
  std::size_t capacity_bytes = 20u * 1024u * 1024u;  // rotations only; 0 disables storing
  // Throws Error naming "motion_cache.bucket_width" unless in [1e-4, 1].
  void validate() const;
};

struct MotionCacheStats {
  std::int64_t hits = 0;
  std::int64_t misses = 0;
  std::int64_t insertions = 0;
  std::int64_t evictions = 0;
  std::int64_t rejected = 0;  // cycles larger than the whole capacity, not stored
  std::size_t bytes = 0;      // held now
  std::size_t entries = 0;    // held now
  double hit_rate() const {
    return hits + misses > 0 ? static_cast<double>(hits) / static_cast<double>(hits + misses) : 0.0;
  }
};

class MotionCache {
 public:
  using Synthesise = std::function<CachedCycle(float w)>;

  explicit MotionCache(MotionCacheConfig config = {});

  const MotionCacheConfig& config() const { return config_; }
  std::int32_t bucket_count() const { return bucket_count_; }
  // w is clamped into [0, 1] (NaN counts as 0); w = 1 is in the last bucket.
  std::int32_t bucket_of(float w) const;
  // The w a bucket's cycle is synthesised at: the middle of its interval.
  float bucket_centre(std::int32_t bucket) const;

  // Counted lookup (a hit or a miss): the cached cycle or null. A batch
  // stage that looks a bucket up once for many characters passes their
  // number as `lookups`, so hits and misses count characters.
  const CachedCycle* find(float w, std::uint32_t state = 0, std::int64_t lookups = 1);
  // Uncounted.
  bool contains(std::int32_t bucket, std::uint32_t state = 0) const;

  // Stores a cycle for a bucket, first evicting the oldest entries until it
  // fits; a cycle for a bucket already held replaces it and becomes the
  // newest. A cycle larger than the capacity is not stored (null, counted
  // as rejected). Throws Error for an invalid cycle or bucket.
  const CachedCycle* insert(std::int32_t bucket, CachedCycle cycle, std::uint32_t state = 0);

  // find(w), else synthesise(bucket_centre(bucket_of(w))) and insert it.
  // The reference stays valid until the next insert or get.
  const CachedCycle& get(float w, const Synthesise& synthesise, std::uint32_t state = 0);
  // get(w) sampled at a normalised phase into out (joint_count rotations).
  void sample(float w, float phase, const Synthesise& synthesise, Span<glm::quat> out, std::uint32_t state = 0);

  const MotionCacheStats& stats() const { return stats_; }
  void reset_counters();  // hits, misses, insertions, evictions, rejected
  void clear();           // drops every entry (not counted as evictions)
  // (state, bucket) of every entry, oldest first.
  std::vector<std::pair<std::uint32_t, std::int32_t>> fifo_order() const;

 private:
  static std::uint64_t key(std::uint32_t state, std::int32_t bucket) {
    return (static_cast<std::uint64_t>(state) << 32) | static_cast<std::uint32_t>(bucket);
  }
  void erase(std::uint64_t k);

  MotionCacheConfig config_;
  std::int32_t bucket_count_ = 1;
  std::deque<std::uint64_t> order_;  // oldest first
  std::unordered_map<std::uint64_t, std::unique_ptr<CachedCycle>> entries_;
  CachedCycle uncached_;  // what get() returns when the cycle could not be stored
  MotionCacheStats stats_;
};

struct QuantisationError {
  double max_deg = 0.0;
  double mean_deg = 0.0;  // over all samples and joints
  float worst_w = 0.0f;
  float worst_phase = 0.0f;
  std::int32_t worst_joint = -1;
  Index samples = 0;  // (w, phase) pairs
};

// The error of reading a bucket's cycle instead of synthesising at w: over
// w_samples values of w spread evenly over [0, 1] and phase_samples phases,
// the angle between each joint's rotation in the bucket's cycle (synthesised
// at its centre) and in the exact cycle at w, both at the same phase.
QuantisationError measure_quantisation_error(const MotionCacheConfig& config, const MotionCache::Synthesise& synthesise,
                                             std::int32_t w_samples = 101, std::int32_t phase_samples = 64);

// The same, with the exact pose at (w, phase) given directly (out has the
// cycle's joint count) instead of read from a cycle synthesised at w: what a
// stage that synthesises per character compares a cache read with.
using ExactPose = std::function<void(float w, float phase, Span<glm::quat> out)>;
QuantisationError measure_quantisation_error(const MotionCacheConfig& config, const MotionCache::Synthesise& synthesise,
                                             const ExactPose& exact, std::int32_t w_samples = 101,
                                             std::int32_t phase_samples = 64);

}  // namespace throng::anim
