// What `throng animate` and `throng run` report of the locomotion stage,
// summed over the frames: frame times, joints synthesised, the joint-LOD
// histogram and the motion cache's counters, as stats.json pieces.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "anim/crowd_animator.h"
#include "core/thinned_series.h"
#include "motion/foot_skating.h"

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

// Foot slides kept for the p95 of a long run (mean and max are exact).
inline constexpr std::size_t kMaxSkatingSlides = 65536;

// Foot skating pooled over the measuring windows of a run: every contact,
// and the contacts of each gait regime (motion::GaitRegime), with the agents
// that had a contact measured.
struct SkatingTally {
  ThinnedSample all{kMaxSkatingSlides};
  std::vector<ThinnedSample> regimes =
      std::vector<ThinnedSample>(motion::kGaitRegimes, ThinnedSample(kMaxSkatingSlides));
  std::vector<Index> agents;  // sorted

  void add(const motion::FootSkatingReport& r);
  // stats.json's foot_skating_cm: mean, p95, max (cm; null with no contact),
  // contacts, agents (sampled), agents_measured, by_regime.
  nlohmann::json json(Index sampled) const;
};

}  // namespace throng::app
