#include "io/routes_output.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "io/run_outputs.h"

namespace throng::io {

namespace {

double path_length(const std::vector<glm::vec2>& p) {
  double length = 0;
  for (std::size_t k = 1; k < p.size(); ++k) length += static_cast<double>(sim::length_of(p[k] - p[k - 1]));
  return length;
}

// A CSV field (RFC 4180): quoted, with its quotes doubled, when it holds a
// comma, a quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// Where the ray from p (inside `box`) in direction d leaves the box.
glm::vec2 edge_ahead(const sim::Aabb& box, glm::vec2 p, glm::vec2 d) {
  float t = INFINITY;
  if (d.x > 0.0f) t = std::min(t, (box.max.x - p.x) / d.x);
  if (d.x < 0.0f) t = std::min(t, (box.min.x - p.x) / d.x);
  if (d.y > 0.0f) t = std::min(t, (box.max.y - p.y) / d.y);
  if (d.y < 0.0f) t = std::min(t, (box.min.y - p.y) / d.y);
  return std::isfinite(t) ? p + d * std::max(t, 0.0f) : p;
}

}  // namespace

std::vector<AgentRoute> sample_routes(const sim::Simulation& sim, Index count) {
  const sim::CrowdState& c = sim.crowd();
  const Index n = sim.agent_count();
  const std::vector<glm::vec2> position = c.position.to_vector(), waypoints = c.waypoints.to_vector();
  const std::vector<std::int32_t> begin = c.waypoint_begin.to_vector(), goal = c.waypoint_goal.to_vector(),
                                  group = c.group.to_vector();
  const sim::FieldsView fields = sim.fields().host_view();
  std::vector<AgentRoute> out;
  const Index k_max = std::min(count, n);
  for (Index k = 0; k < k_max; ++k) {
    const auto i = static_cast<std::size_t>(k * n / k_max);
    AgentRoute r;
    r.agent = static_cast<Index>(i);
    const auto g = static_cast<std::size_t>(group[i]);
    const std::string& name = sim.spec().groups[g].name;
    r.group = name.empty() ? fmt::format("groups[{}]", g) : name;
    const auto first = waypoints.begin() + begin[i];
    // A goal reached over a navigation field: the way down the field.
    const std::int32_t field = goal[i] == 0 ? sim::field_of(fields, *first) : -1;
    const sim::GoalSpec& group_goal = sim.spec().groups[g].goal;
    if (group_goal.kind == sim::GoalSpec::Kind::Direction) {
      // Walking on for ever: the way across the area, to its edge.
      r.points = {position[i], edge_ahead(sim.world().bounds(), position[i], group_goal.value)};
    } else if (field >= 0) {
      r.points = sim::trace_field(fields, field, position[i]);
    } else {
      r.points.push_back(position[i]);
      r.points.insert(r.points.end(), first, first + goal[i] + 1);
    }
    r.length_m = path_length(r.points);
    r.straight_m = static_cast<double>(sim::length_of(r.points.back() - r.points.front()));
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<std::vector<glm::vec2>> field_lines(const sim::Simulation& sim, float spacing) {
  const sim::FieldsView fields = sim.fields().host_view();
  std::vector<std::vector<glm::vec2>> out;
  for (std::int32_t k = 0; k < sim.fields().count(); ++k) {
    std::vector<std::vector<glm::vec2>> lines = sim::field_contours(fields, k, spacing);
    out.insert(out.end(), std::make_move_iterator(lines.begin()), std::make_move_iterator(lines.end()));
  }
  return out;
}

nlohmann::json routes_geojson(const std::vector<AgentRoute>& routes) {
  nlohmann::json features = nlohmann::json::array();
  for (const AgentRoute& r : routes) {
    nlohmann::json line = nlohmann::json::array();
    for (glm::vec2 p : r.points) line.push_back({round_to_mm(p.x), round_to_mm(p.y)});
    features.push_back({{"type", "Feature"},
                        {"properties",
                         {{"agent", r.agent},
                          {"group", r.group},
                          {"length_m", std::round(r.length_m * 1000.0) / 1000.0},
                          {"straight_m", std::round(r.straight_m * 1000.0) / 1000.0},
                          {"waypoints", r.points.size() - 2}}},
                        {"geometry", {{"type", "LineString"}, {"coordinates", line}}}});
  }
  return {{"type", "FeatureCollection"}, {"features", features}};
}

std::string routes_csv(const std::vector<AgentRoute>& routes) {
  std::string out = "agent,group,point,x,y\n";
  for (const AgentRoute& r : routes) {
    const std::string group = csv_field(r.group);
    for (std::size_t k = 0; k < r.points.size(); ++k)
      out += fmt::format("{},{},{},{},{}\n", r.agent, group, k, round_to_mm(r.points[k].x), round_to_mm(r.points[k].y));
  }
  return out;
}

}  // namespace throng::io
