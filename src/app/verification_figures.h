// What the verification tests share to judge and draw a run: arrival
// counts, the figures every run reports, and chart pieces (N-t curves,
// walls, tracks) for render::Chart.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/verification.h"

namespace throng::app {

// Series whose colours must match (a group's points and its range lines)
// take the chart palette's k-th colour (render::palette_colour); reference
// curves are grey and walls black.
inline constexpr render::Rgb kGrey{90, 90, 90}, kBlack{0, 0, 0};

// "12.3 s", or "never" for +inf.
std::string seconds_text(double t);
// "k of n" agents arrived; true when all of them did.
std::string arrived_text(const ScenarioObservation& obs);
bool everyone_arrived(const ScenarioObservation& obs);
// The figures every scenario run reports beside the test's own.
nlohmann::json run_figures(const ScenarioObservation& obs);

render::Chart make_chart(std::string title, std::string x_label, std::string y_label);
render::PlotSeries make_series(std::string label, std::vector<double> x, std::vector<double> y,
                               render::PlotSeries::Style style, std::optional<render::Rgb> colour = {});
// The N-t curve of sorted times: the k-th time reaches k.
render::PlotSeries n_t_curve(std::string label, const std::vector<double>& times,
                             std::optional<render::Rgb> colour = {});
// The walls: the walkable area's rings and the obstacle polygons, as one
// broken line.
render::PlotSeries walls_series(const sim::WorldSpec& w);
// Every agent's track (observed with tracks), styled by `style_of(agent)`:
// a label (each label shown once in the legend) and a colour.
void add_tracks(render::Chart& chart, const ScenarioObservation& obs,
                const std::function<std::pair<std::string, render::Rgb>(std::size_t)>& style_of);

// The exit of `exits` nearest to where an agent was last seen (the one it
// left by).
std::size_t exit_used(const std::vector<sim::ExitSpec>& exits, glm::vec2 last_seen);

}  // namespace throng::app
