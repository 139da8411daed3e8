// The metrics of a run as a frame stage: samples the crowd every few frames
// (and at the last frame) with the metric functions of metrics.h and writes
// the "crowd", "density_histogram" and "fundamental_diagram" sections of
// stats.json.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/frame_loop.h"
#include "sim/metrics.h"

namespace throng::sim {

struct MetricsOptions {
  std::int64_t sample_every = 10;       // frames between samples (the last frame is always sampled)
  float overlap_tolerance = 0.05f;      // m: pair overlaps deeper than this count
  float penetration_tolerance = 1e-3f;  // m: obstacle penetrations deeper than this count
  Aabb measurement;                     // fundamental-diagram area (map); empty = default_measurement_area
  float density_bin_width = 0.25f;      // agents/m^2 per fundamental-diagram bin
};

// A 10 m square at the centre of the scene: the walkable region's bounds,
// else the obstacles' and agents' starting bounds.
Aabb default_measurement_area(const Simulation& sim);

class CrowdMetricsStage : public FrameStage {
 public:
  CrowdMetricsStage(const Simulation& sim, MetricsOptions options);
  std::string name() const override { return "sim.metrics"; }
  void after_step(const Simulation& sim, const FrameInfo& frame) override;
  void finish(const Simulation& sim, nlohmann::json& stats) override;

  struct Sample {
    double time = 0;
    OverlapStats overlaps;
    Index penetrations = 0;
    double mean_speed = 0;
    AreaSample area;
  };
  const std::vector<Sample>& samples() const { return samples_; }
  const Aabb& measurement() const { return options_.measurement; }

 private:
  MetricsOptions options_;
  std::vector<Sample> samples_;
  DensityHistogram density_;  // summed over samples (agent-samples per bin)
};

}  // namespace throng::sim
