#include "app/locomotion_stats.h"

#include <algorithm>
#include <cmath>

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

}  // namespace throng::app
