// The metrics of a run as a frame stage: samples the crowd every few frames
// (and at the last frame) with the metric functions of metrics.h, records
// every crossing of the measurement lines and the stuck agents at every
// step, and writes the "crowd", "stuck_agents", "density_histogram",
// "fundamental_diagram" and "measurement" sections of stats.json.
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
  MeasurementSpec measurement;          // areas and lines (map); no areas = default_measurement_area
  StuckOptions stuck;                   // what counts as a stuck agent
  float density_bin_width = 0.25f;      // agents/m^2 per fundamental-diagram bin
};

// N-t points written per line and direction: every crossing up to this
// many, then every k-th (and the last) so that stats.json stays small.
inline constexpr std::size_t kMaxNtPoints = 2000;

// A 10 m square at the centre of the scene: the walkable region's bounds,
// else the obstacles' and agents' starting bounds.
Aabb default_measurement_area(const Simulation& sim);

class CrowdMetricsStage : public FrameStage {
 public:
  CrowdMetricsStage(const Simulation& sim, MetricsOptions options);
  std::string name() const override { return "sim.metrics"; }
  void after_step(const Simulation& sim, const FrameInfo& frame) override;
  void finish(const Simulation& sim, nlohmann::json& stats) override;

  struct AreaMeasure {
    AreaSample classic;
    VoronoiSample voronoi;
  };
  struct Sample {
    double time = 0;
    OverlapStats overlaps;
    Index penetrations = 0;
    double mean_speed = 0;
    std::vector<AreaMeasure> areas;  // one per measurement area, in order
  };
  // Crossing times of one line, s, in increasing order.
  struct LineTimes {
    std::vector<double> positive, negative;
  };
  const std::vector<Sample>& samples() const { return samples_; }
  const std::vector<MeasurementArea>& areas() const { return options_.measurement.areas; }
  const std::vector<LineTimes>& line_times() const { return line_times_; }
  const StuckStats& stuck() const { return stuck_.stats(); }

 private:
  void record_crossings(const Simulation& sim, const FrameInfo& frame);
  nlohmann::json measurement_section() const;
  nlohmann::json stuck_section() const;
  // One sample of an area: classic and Voronoi values side by side.
  static nlohmann::json area_sample_json(double time, const AreaMeasure& m);

  MetricsOptions options_;
  std::vector<Sample> samples_;
  DensityHistogram density_;  // summed over samples (agent-samples per bin)
  // Lines: crossings are seen between consecutive frames, so the stage keeps
  // the positions and flags of the frame before.
  Buffer<Segment> lines_;
  Aabb line_bounds_;
  Buffer<glm::vec2> previous_position_;
  Buffer<std::uint8_t> previous_flags_;
  double previous_time_ = 0;
  std::int64_t previous_frame_ = -1;
  std::vector<LineTimes> line_times_;
  // Stuck agents need every step too (time at rest is counted in steps).
  StuckTracker stuck_;
  std::int64_t stuck_frame_ = 0;
};

}  // namespace throng::sim
