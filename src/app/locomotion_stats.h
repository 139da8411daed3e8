// What `throng animate` and `throng run` report of the locomotion stage,
// summed over the frames: frame times, joints synthesised, the joint-LOD
// histogram and the motion cache's counters, as stats.json pieces.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "anim/crowd_animator.h"
#include "core/thinned_series.h"

namespace throng::app {

// Nearest-rank percentile (p in [0, 1]); 0 for no values.
double percentile(std::vector<double> values, double p);

// Frame times kept for the percentiles of a long run (ThinnedSample).
inline constexpr std::size_t kMaxFrameTimeSamples = 65536;

struct LocomotionTally {
  std::int64_t frames = 0;
  Index characters = 0;
  Index joints_synthesised = 0;  // over characters and frames
  Index from_cache = 0;          // character-frames that read a cached cycle
  ThinnedSample frame_ms{kMaxFrameTimeSamples};
  std::vector<Index> level_counts;      // [part * levels + level], character-frames
  std::vector<Index> joints_histogram;  // [k]: character-frames synthesising k joints

  void add(const anim::FrameStats& frame, double ms);
  double character_frames() const { return static_cast<double>(characters) * static_cast<double>(frames); }
  // {median, mean, p95, max} milliseconds (mean and max over every frame).
  nlohmann::json frame_ms_json() const;
  // thresholds, levels, body parts per level, the histogram; null without LOD.
  nlohmann::json lod_json(const anim::CrowdAnimator& crowd, const std::vector<float>& thresholds) const;
  // bucket width, capacity, hits, misses, insertions, evictions, bytes,
  // entries, hit rate, share read from the cache; null without a cache.
  nlohmann::json cache_json(const anim::CrowdAnimator& crowd) const;
};

}  // namespace throng::app
