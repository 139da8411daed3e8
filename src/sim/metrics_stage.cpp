#include "sim/metrics_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

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

CrowdMetricsStage::CrowdMetricsStage(const Simulation& sim, MetricsOptions options)
    : options_(std::move(options)), stuck_(options_.stuck) {
  if (options_.sample_every < 1) throw Error("must be >= 1", at_field("metrics.sample_every"));
  if (!(options_.density_bin_width > 0)) throw Error("must be > 0", at_field("metrics.density_bin_width"));
  MeasurementSpec& m = options_.measurement;
  if (!(m.voronoi_cutoff > 0)) throw Error("must be > 0", at_field("measurement.voronoi_cutoff"));
  if (m.areas.empty()) m.areas.push_back({"default", default_measurement_area(sim)});
  for (std::size_t k = 0; k < m.areas.size(); ++k)
    if (!(m.areas[k].rect.size().x > 0 && m.areas[k].rect.size().y > 0))
      throw Error("the measurement area needs a positive width and height",
                  at_field(fmt::format("measurement.areas[{}].rect", k)));
  std::vector<Segment> lines;
  for (std::size_t k = 0; k < m.lines.size(); ++k) {
    const MeasurementLine& l = m.lines[k];
    if (!(length_of(l.to - l.from) > 0))
      throw Error("the line has no length: 'to' equals 'from'", at_field(fmt::format("measurement.lines[{}].to", k)));
    lines.push_back({l.from, l.to});
    line_bounds_.add(l.from);
    line_bounds_.add(l.to);
  }
  lines_ = Buffer<Segment>(std::span<const Segment>(lines), current_memory());
  line_times_.resize(lines.size());
}

void CrowdMetricsStage::record_crossings(const Simulation& sim, const FrameInfo& frame) {
  if (line_times_.empty() || frame.frame == previous_frame_) return;
  const CrowdState& c = sim.crowd();
  if (previous_frame_ >= 0) {
    // Agents added since the frame before have no step to cross with.
    const Index n = std::min(previous_position_.size(), c.position.size());
    const std::vector<LineCrossing> found = line_crossings(
        previous_position_.span().subspan(0, n), previous_flags_.span().subspan(0, n), c.position.span().subspan(0, n),
        c.flags.span().subspan(0, n), lines_.span(), line_bounds_, previous_time_, frame.time, sim.world().periodic());
    // The list is in agent order; sorted by time within the step, every
    // N-t curve only climbs.
    std::vector<LineTimes> step(line_times_.size());
    for (const LineCrossing& x : found) {
      LineTimes& t = step[static_cast<std::size_t>(x.line)];
      (x.direction > 0 ? t.positive : t.negative).push_back(x.time);
    }
    for (std::size_t k = 0; k < step.size(); ++k) {
      for (auto [from, to] : {std::pair{&step[k].positive, &line_times_[k].positive},
                              std::pair{&step[k].negative, &line_times_[k].negative}}) {
        std::stable_sort(from->begin(), from->end());
        to->insert(to->end(), from->begin(), from->end());
      }
    }
  }
  previous_position_ = c.position.to(c.position.memory());
  previous_flags_ = c.flags.to(c.flags.memory());
  previous_time_ = frame.time;
  previous_frame_ = frame.frame;
}

void CrowdMetricsStage::after_step(const Simulation& sim, const FrameInfo& frame) {
  // Crossings and stuck agents need every step; the rest is sampled.
  record_crossings(sim, frame);
  // Frame 0 is the initial state: no step, no velocity measured yet.
  if (frame.frame > stuck_frame_) {
    stuck_.update(sim);
    stuck_frame_ = frame.frame;
  }
  if (frame.frame % options_.sample_every != 0 && !frame.last) return;
  const CrowdState& c = sim.crowd();
  Sample s;
  s.time = frame.time;
  s.overlaps = measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), options_.overlap_tolerance,
                                sim.contact_cell(), sim.world().periodic());
  s.penetrations = count_obstacle_penetrations(sim.world(), c.position.span(), c.radius.span(), c.flags.span(),
                                               options_.penetration_tolerance);
  s.mean_speed = mean_speed(c.velocity.span(), c.flags.span());
  const std::vector<glm::vec2> position = c.position.to_vector(), velocity = c.velocity.to_vector(),
                               goal = c.goal.to_vector();
  const std::vector<std::uint8_t> flags = c.flags.to_vector();
  for (const MeasurementArea& a : options_.measurement.areas)
    s.areas.push_back({measure_area(c.position.span(), c.velocity.span(), c.goal.span(), c.flags.span(), a.rect),
                       measure_area_voronoi(position, velocity, goal, flags, a.rect,
                                            options_.measurement.voronoi_cutoff, sim.world().periodic())});
  const DensityHistogram defaults;
  const DensityHistogram h =
      density_histogram(c.position.span(), c.flags.span(), defaults.cell, defaults.bin_width, sim.world().periodic());
  density_.cell = h.cell;
  density_.bin_width = h.bin_width;
  for (int b = 0; b < kDensityBins; ++b)
    density_.agents[static_cast<std::size_t>(b)] += h.agents[static_cast<std::size_t>(b)];
  accumulate(s);
  samples_.push(std::move(s));
}

void CrowdMetricsStage::accumulate(const Sample& s) {
  Totals& t = totals_;
  t.max_pairs = std::max(t.max_pairs, s.overlaps.pairs);
  t.max_penetrations = std::max(t.max_penetrations, s.penetrations);
  t.max_depth = std::max(t.max_depth, s.overlaps.max_depth);
  t.min_separation = std::min(t.min_separation, s.overlaps.min_separation);
  t.speed_sum += s.mean_speed;
  t.area_sums.resize(s.areas.size());
  for (std::size_t k = 0; k < s.areas.size(); ++k) {
    const nlohmann::json values = area_sample_json(s.time, s.areas[k]);
    for (const auto& [key, value] : values.items())
      if (key != "time") t.area_sums[k][key] += value.get<double>();
  }
  const AreaSample& a = s.areas.front().classic;
  if (a.agents == 0) return;
  const VoronoiSample& v = s.areas.front().voronoi;
  DensityBin& b = fd_bins_[static_cast<std::int64_t>(std::floor(a.density / options_.density_bin_width))];
  ++b.samples;
  b.speed += a.mean_speed;
  b.speed_magnitude += a.mean_speed_magnitude;
  b.flow += a.flow;
  b.voronoi_density += v.density;
  b.voronoi_speed += v.speed;
}

void CrowdMetricsStage::finish(const Simulation& sim, nlohmann::json& stats) {
  const ArrivalStats arrivals = arrival_stats(sim.arrival_times());
  const Totals& t = totals_;
  const double taken = static_cast<double>(samples_.seen());
  const Sample last = samples_.empty() ? Sample{} : samples_.newest();
  auto finite_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  stats["crowd"] = {
      {"agents", sim.agent_count()},
      {"active_at_end", sim.active_count()},
      {"not_entered_at_end", sim.pending_count()},
      {"replanned", sim.replanned_count()},
      {"arrived", arrivals.arrived},
      {"arrival_time_s", {{"mean", arrivals.mean_time}, {"min", arrivals.min_time}, {"max", arrivals.max_time}}},
      {"samples", samples_.seen()},
      {"sample_every_frames", options_.sample_every},
      {"series_stride", samples_.stride()},
      {"overlaps",
       {{"tolerance_m", options_.overlap_tolerance},
        {"pairs_at_end", last.overlaps.pairs},
        {"max_pairs", t.max_pairs},
        {"max_depth_m", t.max_depth}}},
      {"min_separation_m", finite_or_null(t.min_separation)},
      {"obstacle_penetrations",
       {{"tolerance_m", options_.penetration_tolerance}, {"at_end", last.penetrations}, {"max", t.max_penetrations}}},
      {"mean_speed_mps", {{"at_end", last.mean_speed}, {"over_samples", taken > 0 ? t.speed_sum / taken : 0.0}}},
  };
  nlohmann::json bins = nlohmann::json::array();
  for (int b = 0; b < kDensityBins; ++b)
    bins.push_back(
        {{"min_density", static_cast<double>(b) * density_.bin_width},
         {"max_density", b + 1 < kDensityBins ? nlohmann::json(static_cast<double>(b + 1) * density_.bin_width)
                                              : nlohmann::json(nullptr)},
         {"agent_samples", density_.agents[static_cast<std::size_t>(b)]}});
  stats["density_histogram"] = {{"cell_m", density_.cell}, {"bin_width_per_m2", density_.bin_width}, {"bins", bins}};

  // Fundamental diagram: samples of the first measurement area grouped by density.
  const std::vector<Sample> kept = samples_.values();
  nlohmann::json series = nlohmann::json::array();
  for (const Sample& s : kept) series.push_back(area_sample_json(s.time, s.areas.front()));
  nlohmann::json diagram = nlohmann::json::array();
  for (const auto& [k, b] : fd_bins_) {
    const double n = static_cast<double>(b.samples);
    diagram.push_back({{"min_density", static_cast<double>(k) * options_.density_bin_width},
                       {"max_density", static_cast<double>(k + 1) * options_.density_bin_width},
                       {"samples", b.samples},
                       {"mean_speed", b.speed / n},
                       {"mean_speed_magnitude", b.speed_magnitude / n},
                       {"mean_flow", b.flow / n},
                       {"mean_voronoi_density", b.voronoi_density / n},
                       {"mean_voronoi_speed", b.voronoi_speed / n}});
  }
  const MeasurementSpec& spec = options_.measurement;
  const Aabb& m = spec.areas.front().rect;
  stats["fundamental_diagram"] = {
      {"area", {{"min", {m.min.x, m.min.y}}, {"max", {m.max.x, m.max.y}}}},
      {"speed", "m/s along each agent's desired direction (towards its current goal); speed_magnitude: mean |v|"},
      {"flow", "specific flow, density x speed, 1/(m s)"},
      {"voronoi_density",
       "Voronoi density (Steffen & Seyfried 2010), 1/m^2; voronoi_speed: Voronoi-weighted speed along the desired "
       "direction, m/s"},
      {"density_bin_width_per_m2", options_.density_bin_width},
      {"bins", diagram},
      {"samples", series}};
  stats["measurement"] = measurement_section(kept);
  stats["stuck_agents"] = stuck_section();
}

nlohmann::json CrowdMetricsStage::stuck_section() const {
  const StuckOptions& o = stuck_.options();
  const StuckStats& s = stuck_.stats();
  nlohmann::json examples = nlohmann::json::array();
  for (const StuckExample& e : s.examples)
    examples.push_back({{"agent", e.agent}, {"time_s", e.time}, {"position", {e.position.x, e.position.y}}});
  return {{"threshold_s", o.threshold_s},
          {"speed_below", o.speed_below},
          {"probe_gap_m", o.gap},
          {"agents", s.agents},
          {"at_end", s.now},
          {"max_at_once", s.max_at_once},
          {"first_time_s", s.agents > 0 ? nlohmann::json(s.first_time) : nlohmann::json(nullptr)},
          {"examples", examples}};
}

nlohmann::json CrowdMetricsStage::area_sample_json(double time, const AreaMeasure& m) {
  const AreaSample& a = m.classic;
  const VoronoiSample& v = m.voronoi;
  // Each classic value beside its Voronoi one; the flows are density x speed.
  return {{"time", time},
          {"agents", a.agents},
          {"density", a.density},
          {"voronoi_density", v.density},
          {"speed", a.mean_speed},
          {"voronoi_speed", v.speed},
          {"speed_magnitude", a.mean_speed_magnitude},
          {"voronoi_speed_magnitude", v.speed_magnitude},
          {"flow", a.flow},
          {"voronoi_flow", v.density * v.speed}};
}

nlohmann::json CrowdMetricsStage::measurement_section(const std::vector<Sample>& kept) const {
  const MeasurementSpec& spec = options_.measurement;
  nlohmann::json areas = nlohmann::json::array();
  for (std::size_t k = 0; k < spec.areas.size(); ++k) {
    nlohmann::json series = nlohmann::json::array();
    for (const Sample& s : kept) series.push_back(area_sample_json(s.time, s.areas[k]));
    // Means of every value but the time over every sample taken (kept in
    // the series or not), empty ones included.
    nlohmann::json mean = nlohmann::json::object();
    if (k < totals_.area_sums.size())
      for (const auto& [key, sum] : totals_.area_sums[k]) mean[key] = sum / static_cast<double>(samples_.seen());
    const Aabb& r = spec.areas[k].rect;
    areas.push_back({{"name", spec.areas[k].name},
                     {"min", {r.min.x, r.min.y}},
                     {"max", {r.max.x, r.max.y}},
                     {"area_m2", static_cast<double>(r.size().x) * r.size().y},
                     {"mean", mean},
                     {"samples", series}});
  }
  nlohmann::json lines = nlohmann::json::array();
  for (std::size_t k = 0; k < spec.lines.size(); ++k) {
    const MeasurementLine& l = spec.lines[k];
    const double width = static_cast<double>(length_of(l.to - l.from));
    auto direction = [width](const std::vector<double>& t) {
      const std::size_t n = t.size();
      const LineFlow f = line_flow(t, width);
      nlohmann::json nt = nlohmann::json::array();
      const std::size_t stride = (n + kMaxNtPoints - 1) / kMaxNtPoints;
      for (std::size_t i = 0; i < n; ++i)
        if (stride <= 1 || i == 0 || i + 1 == n || (i + 1) % stride == 0) nt.push_back({t[i], i + 1});
      auto or_null = [](bool known, double v) { return known ? nlohmann::json(v) : nlohmann::json(nullptr); };
      return nlohmann::json{{"crossings", n},
                            {"first_s", or_null(n > 0, f.first_time)},
                            {"last_s", or_null(n > 0, f.last_time)},
                            {"flow_per_s", or_null(f.timed, f.flow)},
                            {"specific_flow_per_m_s", or_null(f.timed, f.specific_flow)},
                            {"steady_flow_per_s", or_null(f.timed, f.steady_flow)},
                            {"steady_specific_flow_per_m_s", or_null(f.timed, f.steady_specific_flow)},
                            {"nt", nt}};
    };
    lines.push_back({{"name", l.name},
                     {"from", {l.from.x, l.from.y}},
                     {"to", {l.to.x, l.to.y}},
                     {"width_m", width},
                     {"positive", direction(line_times_[k].positive)},
                     {"negative", direction(line_times_[k].negative)}});
  }
  return {{"voronoi_cutoff_m", spec.voronoi_cutoff}, {"areas", areas}, {"lines", lines}};
}

}  // namespace throng::sim
