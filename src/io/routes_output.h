// The planned routes of a sample of agents, as `throng route` prints and
// writes them: each from where the agent starts through its waypoints (as
// given or as the route planner filled them in) to its goal.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "sim/simulation.h"

namespace throng::io {

struct AgentRoute {
  Index agent = 0;
  std::string group;              // the group's name, or "groups[g]"
  std::vector<glm::vec2> points;  // start, waypoints, goal (m, map coordinates)
  double length_m = 0;            // along the points
  double straight_m = 0;          // start to goal in a straight line
};

// The routes of up to `count` agents spread evenly over the crowd (agents
// k * N / count), read from the simulation as spawned (before any step).
// A loop's way back is left out; an agent yet to enter starts where it will.
// An agent whose goal has a navigation field (`planning: field`) gets the
// way down the field (sim::trace_field), its bends as waypoints.
// An agent walking in a direction (a periodic world) gets the way straight
// on to the edge of the area.
std::vector<AgentRoute> sample_routes(const sim::Simulation& sim, Index count);

// The lines of equal walking distance of every navigation field of the run
// (sim::field_contours), every `spacing` m; none without fields.
std::vector<std::vector<glm::vec2>> field_lines(const sim::Simulation& sim, float spacing);

// A GeoJSON FeatureCollection (RFC 7946) of LineStrings, one per route, with
// properties agent, group, length_m, straight_m and waypoints (points - 2).
nlohmann::json routes_geojson(const std::vector<AgentRoute>& routes);
// CSV "agent,group,point,x,y": one row per point of each route, in order.
std::string routes_csv(const std::vector<AgentRoute>& routes);

}  // namespace throng::io
