#include "sim/metrics_stage.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.h"

namespace throng::sim {

Aabb default_measurement_area(const Simulation& sim) {
  Aabb scene = sim.world().has_walkable() ? sim.world().bounds() : Aabb{};
  if (scene.empty()) {
    scene = sim.world().bounds();
    for (const glm::vec2 p : sim.crowd().position.to_vector()) scene.add(p);
  }
  const glm::vec2 centre = scene.empty() ? glm::vec2(0.0f) : 0.5f * (scene.min + scene.max);
  Aabb a;
  a.add(centre - glm::vec2(5.0f));
  a.add(centre + glm::vec2(5.0f));
  return a;
}

CrowdMetricsStage::CrowdMetricsStage(const Simulation& sim, MetricsOptions options) : options_(options) {
  if (options_.sample_every < 1) throw Error("must be >= 1", at_field("metrics.sample_every"));
  if (!(options_.density_bin_width > 0)) throw Error("must be > 0", at_field("metrics.density_bin_width"));
  if (options_.measurement.empty()) options_.measurement = default_measurement_area(sim);
  if (!(options_.measurement.size().x > 0 && options_.measurement.size().y > 0))
    throw Error("the measurement area needs a positive width and height", at_field("measurement"));
}

void CrowdMetricsStage::after_step(const Simulation& sim, const FrameInfo& frame) {
  if (frame.frame % options_.sample_every != 0 && !frame.last) return;
  const CrowdState& c = sim.crowd();
  Sample s;
  s.time = frame.time;
  s.overlaps = measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), options_.overlap_tolerance, sim.contact_cell());
  s.penetrations = count_obstacle_penetrations(sim.world(), c.position.span(), c.radius.span(), c.flags.span(), options_.penetration_tolerance);
  s.mean_speed = mean_speed(c.velocity.span(), c.flags.span());
  s.area = measure_area(c.position.span(), c.velocity.span(), c.goal.span(), c.flags.span(), options_.measurement);
  const DensityHistogram h = density_histogram(c.position.span(), c.flags.span());
  density_.cell = h.cell;
  density_.bin_width = h.bin_width;
  for (int b = 0; b < kDensityBins; ++b) density_.agents[static_cast<std::size_t>(b)] += h.agents[static_cast<std::size_t>(b)];
  samples_.push_back(s);
}

void CrowdMetricsStage::finish(const Simulation& sim, nlohmann::json& stats) {
  const ArrivalStats arrivals = arrival_stats(sim.arrival_times());
  Index max_pairs = 0, max_penetrations = 0;
  float max_depth = 0.0f, min_separation = INFINITY;
  double speed_sum = 0;
  for (const Sample& s : samples_) {
    max_pairs = std::max(max_pairs, s.overlaps.pairs);
    max_penetrations = std::max(max_penetrations, s.penetrations);
    max_depth = std::max(max_depth, s.overlaps.max_depth);
    min_separation = std::min(min_separation, s.overlaps.min_separation);
    speed_sum += s.mean_speed;
  }
  const Sample last = samples_.empty() ? Sample{} : samples_.back();
  auto finite_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  stats["crowd"] = {
      {"agents", sim.agent_count()},
      {"active_at_end", sim.active_count()},
      {"arrived", arrivals.arrived},
      {"arrival_time_s", {{"mean", arrivals.mean_time}, {"min", arrivals.min_time}, {"max", arrivals.max_time}}},
      {"samples", samples_.size()},
      {"sample_every_frames", options_.sample_every},
      {"overlaps",
       {{"tolerance_m", options_.overlap_tolerance},
        {"pairs_at_end", last.overlaps.pairs},
        {"max_pairs", max_pairs},
        {"max_depth_m", max_depth}}},
      {"min_separation_m", finite_or_null(min_separation)},
      {"obstacle_penetrations", {{"tolerance_m", options_.penetration_tolerance}, {"at_end", last.penetrations}, {"max", max_penetrations}}},
      {"mean_speed_mps", {{"at_end", last.mean_speed}, {"over_samples", samples_.empty() ? 0.0 : speed_sum / static_cast<double>(samples_.size())}}},
  };
  nlohmann::json bins = nlohmann::json::array();
  for (int b = 0; b < kDensityBins; ++b)
    bins.push_back({{"min_density", static_cast<double>(b) * density_.bin_width},
                    {"max_density", b + 1 < kDensityBins ? nlohmann::json(static_cast<double>(b + 1) * density_.bin_width) : nlohmann::json(nullptr)},
                    {"agent_samples", density_.agents[static_cast<std::size_t>(b)]}});
  stats["density_histogram"] = {{"cell_m", density_.cell}, {"bin_width_per_m2", density_.bin_width}, {"bins", bins}};

  // Fundamental diagram: samples of the measurement area grouped by density.
  struct Bin {
    Index samples = 0;
    double speed = 0, speed_magnitude = 0, flow = 0;
  };
  std::map<std::int64_t, Bin> by_density;
  nlohmann::json series = nlohmann::json::array();
  for (const Sample& s : samples_) {
    series.push_back({{"time", s.time},
                      {"agents", s.area.agents},
                      {"density", s.area.density},
                      {"speed", s.area.mean_speed},
                      {"speed_magnitude", s.area.mean_speed_magnitude},
                      {"flow", s.area.flow}});
    if (s.area.agents == 0) continue;
    Bin& b = by_density[static_cast<std::int64_t>(std::floor(s.area.density / options_.density_bin_width))];
    ++b.samples;
    b.speed += s.area.mean_speed;
    b.speed_magnitude += s.area.mean_speed_magnitude;
    b.flow += s.area.flow;
  }
  nlohmann::json diagram = nlohmann::json::array();
  for (const auto& [k, b] : by_density)
    diagram.push_back({{"min_density", static_cast<double>(k) * options_.density_bin_width},
                       {"max_density", static_cast<double>(k + 1) * options_.density_bin_width},
                       {"samples", b.samples},
                       {"mean_speed", b.speed / static_cast<double>(b.samples)},
                       {"mean_speed_magnitude", b.speed_magnitude / static_cast<double>(b.samples)},
                       {"mean_flow", b.flow / static_cast<double>(b.samples)}});
  const Aabb& m = options_.measurement;
  stats["fundamental_diagram"] = {{"area", {{"min", {m.min.x, m.min.y}}, {"max", {m.max.x, m.max.y}}}},
                                  {"speed", "m/s along each agent's desired direction (towards its current goal); speed_magnitude: mean |v|"},
                                  {"flow", "specific flow, density x speed, 1/(m s)"},
                                  {"density_bin_width_per_m2", options_.density_bin_width},
                                  {"bins", diagram},
                                  {"samples", series}};
}

}  // namespace throng::sim
