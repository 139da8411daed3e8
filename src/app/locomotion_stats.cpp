#include "app/locomotion_stats.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace throng::app {

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

void LocomotionTally::add(const anim::FrameStats& frame, double ms) {
  ++frames;
  characters = frame.characters;
  joints_synthesised += frame.joints_synthesised;
  from_cache += frame.from_cache;
  frame_ms.push(ms);
  if (frame.lod) {
    level_counts.resize(frame.lod->level_counts.size(), 0);
    joints_histogram.resize(frame.lod->joints_synthesised.size(), 0);
    for (std::size_t i = 0; i < level_counts.size(); ++i) level_counts[i] += frame.lod->level_counts[i];
    for (std::size_t i = 0; i < joints_histogram.size(); ++i) joints_histogram[i] += frame.lod->joints_synthesised[i];
  }
}

nlohmann::json LocomotionTally::frame_ms_json() const {
  const std::vector<double> kept = frame_ms.values();
  return {{"median", percentile(kept, 0.5)},
          {"mean", frame_ms.mean()},
          {"p95", percentile(kept, 0.95)},
          {"max", frame_ms.max()}};
}

nlohmann::json LocomotionTally::lod_json(const anim::CrowdAnimator& crowd, const std::vector<float>& thresholds) const {
  const anim::LodConfig* lod = crowd.lod_config();
  if (lod == nullptr || level_counts.empty()) return nullptr;
  nlohmann::json parts;
  for (anim::BodyPart p : anim::kAllBodyParts) {
    std::vector<Index> levels;
    for (int l = 0; l < lod->level_count; ++l)
      levels.push_back(level_counts[static_cast<std::size_t>(static_cast<int>(p) * lod->level_count + l)]);
    parts[anim::to_string(p)] = levels;
  }
  return {{"thresholds_px2", thresholds},
          {"levels", lod->level_count},
          {"character_frames_per_level", parts},
          {"joints_synthesised_histogram", joints_histogram}};
}

nlohmann::json LocomotionTally::cache_json(const anim::CrowdAnimator& crowd) const {
  const anim::CycleCacheTable* cache = crowd.cache();
  if (cache == nullptr) return nullptr;
  const anim::MotionCacheStats& c = cache->cache().stats();
  return {
      {"bucket_width", cache->bucket_width()},
      {"capacity_bytes", cache->cache().config().capacity_bytes},
      {"hits", c.hits},
      {"misses", c.misses},
      {"insertions", c.insertions},
      {"evictions", c.evictions},
      {"bytes", c.bytes},
      {"entries", c.entries},
      {"hit_rate", c.hit_rate()},
      {"from_cache_fraction", character_frames() > 0.0 ? static_cast<double>(from_cache) / character_frames() : 0.0}};
}

void SkatingTally::add(const motion::FootSkatingReport& r) {
  for (std::size_t i = 0; i < r.slides_cm.size(); ++i) {
    all.push(r.slides_cm[i]);
    if (i < r.regimes.size()) regimes[r.regimes[i] % motion::kGaitRegimes].push(r.slides_cm[i]);
  }
  std::vector<Index> both;
  std::set_union(agents.begin(), agents.end(), r.characters.begin(), r.characters.end(), std::back_inserter(both));
  agents = std::move(both);
}

namespace {

// mean, p95 (of the kept slides), max (cm; null for none) and contacts.
nlohmann::json slide_figures(const ThinnedSample& s) {
  const bool any = s.count() > 0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {{"mean", any ? s.mean() : nan},
          {"p95", motion::summarise_foot_skating(s.values()).p95_cm},
          {"max", any ? s.max() : nan},
          {"contacts", s.count()}};
}

}  // namespace

nlohmann::json SkatingTally::json(Index sampled) const {
  nlohmann::json out = slide_figures(all);
  out["agents"] = sampled;
  out["agents_measured"] = static_cast<Index>(agents.size());
  nlohmann::json by = nlohmann::json::object();
  for (int k = 0; k < motion::kGaitRegimes; ++k)
    by[motion::to_string(static_cast<motion::GaitRegime>(k))] = slide_figures(regimes[static_cast<std::size_t>(k)]);
  out["by_regime"] = by;
  return out;
}

}  // namespace throng::app
