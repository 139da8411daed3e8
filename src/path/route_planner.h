// Planned routes for the crowd simulation: the sim::RoutePlanner that
// `throng run` uses (through io::build_simulation) when a scenario's
// `planning` is `roadmap` and a group has a goal and no waypoints.
//
// For each agent radius it builds, once, the free space of the world
// (walkable region minus obstacles) and the Voronoi roadmap for that radius
// (path::Planner), then answers every agent's (start, goal) query in
// parallel. A start whose straight line to the goal keeps the radius gets no
// points (the straight walk is the shortest route); the others get the
// smoothed roadmap route without its two ends. Corners stay sharp: the path
// following of the simulation turns at each waypoint itself.
//
// Unreachable goals are the simulation's error (sim::Reachability, checked
// before planning); a query the roadmap cannot answer even so (a goal closer
// to a wall than the radius, a gap the raster sees open but narrower than
// the agent) falls back to the straight line and is counted.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "path/planner.h"
#include "sim/crowd.h"

namespace throng::path {

struct RoutePlannerOptions {
  // Shortcuts keep this much more than the radius from walls, m. More
  // makes fewer shortcuts where a start or goal is near a wall (longer
  // routes); the move stage keeps agents off walls anyway.
  float wall_margin = 0.1f;
  float clearance_weight = 1.0f;  // as PlanOptions::clearance_weight
  void validate() const;          // throws Error naming the field
  PlanOptions plan_options(float radius) const;
};

// What the planner did so far (all plan() calls together).
struct RoutePlannerStats {
  std::int64_t queries = 0;
  std::int64_t straight = 0;  // the straight line was clear
  std::int64_t planned = 0;   // routed over the roadmap
  std::int64_t fallback = 0;  // no roadmap route: straight line
  std::int32_t roadmaps = 0;  // roadmaps built (one per radius)
  double build_seconds = 0;   // free space and roadmaps
  double plan_seconds = 0;    // queries
};

class RoadmapRoutePlanner final : public sim::RoutePlanner {
 public:
  explicit RoadmapRoutePlanner(RoutePlannerOptions options = {});
  std::vector<std::vector<glm::vec2>> plan(const sim::World& world, std::span<const glm::vec2> starts,
                                           std::span<const glm::vec2> goals, float agent_radius) const override;
  RoutePlannerStats stats() const;

 private:
  // Callers hold mutex_.
  const FreeSpace& space_for(const sim::World& world, std::span<const glm::vec2> starts,
                             std::span<const glm::vec2> goals) const;
  const Planner& planner_for(float radius) const;
  FreeSpace build_space() const;  // of world_ with space_options_; errors name `planning`

  RoutePlannerOptions options_;
  mutable std::mutex mutex_;
  mutable const sim::World* world_ = nullptr;
  mutable FreeSpaceOptions space_options_;
  mutable std::unique_ptr<FreeSpace> space_;   // until the first roadmap takes it over
  mutable std::map<float, Planner> planners_;  // by radius
  mutable RoutePlannerStats stats_;
};

// The world has walls (a walkable region) or obstacles: planning can matter.
bool world_has_obstacles(const sim::World& world);

}  // namespace throng::path
