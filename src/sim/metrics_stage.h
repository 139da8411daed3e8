// The metrics of a run as a frame stage: samples the crowd every few frames
// (and at the last frame) with the metric functions of metrics.h, records
// every crossing of the measurement lines and the stuck agents at every
// step, and writes the "crowd", "stuck_agents", "density_histogram",
// "fundamental_diagram" and "measurement" sections of stats.json.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/thinned_series.h"
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

// Samples kept for stats.json's series (ThinnedSeries: evenly spread over
// the run, the last always among them); the means, maxima and the
// fundamental diagram's bins are summed over every sample as it comes, so
// a run of any length keeps bounded memory.
inline constexpr std::size_t kMaxSeriesSamples = 4000;

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
  // The samples kept for the series (all of them up to kMaxSeriesSamples).
  std::vector<Sample> samples() const { return samples_.values(); }
  std::uint64_t samples_taken() const { return samples_.seen(); }
  const std::vector<MeasurementArea>& areas() const { return options_.measurement.areas; }
  const std::vector<LineTimes>& line_times() const { return line_times_; }
  const StuckStats& stuck() const { return stuck_.stats(); }

 private:
  void record_crossings(const Simulation& sim, const FrameInfo& frame);
  // `kept`: the samples kept for the series (samples_.values()).
  nlohmann::json measurement_section(const std::vector<Sample>& kept) const;
  nlohmann::json stuck_section() const;
  // One sample of an area: classic and Voronoi values side by side.
  static nlohmann::json area_sample_json(double time, const AreaMeasure& m);
  // Adds a sample to the running totals below.
  void accumulate(const Sample& s);

  // Sums over every sample taken, kept or not.
  struct Totals {
    Index max_pairs = 0, max_penetrations = 0;
    float max_depth = 0.0f, min_separation = INFINITY;
    double speed_sum = 0;
    std::vector<std::map<std::string, double>> area_sums;  // per area, per key of area_sample_json
  };
  // Fundamental-diagram sums of the first area's samples in one density bin.
  struct DensityBin {
    Index samples = 0;
    double speed = 0, speed_magnitude = 0, flow = 0, voronoi_density = 0, voronoi_speed = 0;
  };

  MetricsOptions options_;
  ThinnedSeries<Sample> samples_{kMaxSeriesSamples};
  Totals totals_;
  std::map<std::int64_t, DensityBin> fd_bins_;  // by floor(density / bin width)
  DensityHistogram density_;                    // summed over samples (agent-samples per bin)
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
