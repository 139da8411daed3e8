#include "app/verification_figures.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace throng::app {

using render::PlotSeries;

std::string seconds_text(double t) { return std::isfinite(t) ? fmt::format("{:.1f} s", t) : std::string("never"); }

std::string arrived_text(const ScenarioObservation& obs) {
  return fmt::format("{} of {}", obs.arrivals().size(), obs.agents);
}

bool everyone_arrived(const ScenarioObservation& obs) {
  return obs.agents > 0 && static_cast<std::int64_t>(obs.arrivals().size()) == obs.agents;
}

nlohmann::json run_figures(const ScenarioObservation& obs) {
  const double t = obs.evacuation_time();
  return {{"agents", obs.agents},
          {"arrived", obs.arrivals().size()},
          {"simulated_s", obs.end_time},
          {"last_arrival_s", std::isfinite(t) ? nlohmann::json(t) : nlohmann::json(nullptr)},
          {"most_agents_in_walls", obs.most_in_walls},
          {"deepest_overlap_m", obs.deepest_overlap},
          {"model", sim::to_string(obs.spec.model.kind)}};
}

render::Chart make_chart(std::string title, std::string x_label, std::string y_label) {
  render::Chart c;
  c.title = std::move(title);
  c.x_label = std::move(x_label);
  c.y_label = std::move(y_label);
  return c;
}

PlotSeries make_series(std::string label, std::vector<double> x, std::vector<double> y, PlotSeries::Style style,
                       std::optional<render::Rgb> colour) {
  PlotSeries s;
  s.label = std::move(label);
  s.x = std::move(x);
  s.y = std::move(y);
  s.style = style;
  s.colour = colour;
  return s;
}

PlotSeries n_t_curve(std::string label, const std::vector<double>& times, std::optional<render::Rgb> colour) {
  std::vector<double> x{0.0}, y{0.0};
  for (std::size_t k = 0; k < times.size(); ++k) {
    x.push_back(times[k]);
    y.push_back(static_cast<double>(k + 1));
  }
  return make_series(std::move(label), std::move(x), std::move(y), PlotSeries::Style::Steps, colour);
}

PlotSeries walls_series(const sim::WorldSpec& w) {
  PlotSeries s = make_series("walls", {}, {}, PlotSeries::Style::Line, kBlack);
  s.width = 1.5f;
  auto ring = [&s](const sim::Ring& r) {
    for (std::size_t k = 0; k <= r.size(); ++k) {
      s.x.push_back(r[k % r.size()].x);
      s.y.push_back(r[k % r.size()].y);
    }
    s.x.push_back(NAN);  // a break before the next ring
    s.y.push_back(NAN);
  };
  auto polygon = [&ring](const sim::Polygon& p) {
    if (!p.outer.empty()) ring(p.outer);
    for (const sim::Ring& h : p.holes) ring(h);
  };
  if (w.has_walkable) polygon(w.walkable);
  for (const sim::Polygon& p : w.polygons) polygon(p);
  return s;
}

void add_tracks(render::Chart& chart, const ScenarioObservation& obs,
                const std::function<std::pair<std::string, render::Rgb>(std::size_t)>& style_of) {
  std::vector<std::string> labelled;
  for (std::size_t i = 0; i < obs.tracks.size(); ++i) {
    auto [label, colour] = style_of(i);
    PlotSeries s = make_series(label, {}, {}, PlotSeries::Style::Line, colour);
    if (std::find(labelled.begin(), labelled.end(), label) != labelled.end()) s.label.clear();
    labelled.push_back(label);
    s.width = 1.0f;
    for (glm::vec2 p : obs.tracks[i]) {
      s.x.push_back(p.x);
      s.y.push_back(p.y);
    }
    chart.series.push_back(std::move(s));
  }
}

std::size_t exit_used(const std::vector<sim::ExitSpec>& exits, glm::vec2 last_seen) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < exits.size(); ++k)
    if (glm::length(exits[k].point - last_seen) < glm::length(exits[best].point - last_seen)) best = k;
  return best;
}

}  // namespace throng::app
