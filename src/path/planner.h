// Path planning on the roadmap: many (start, goal) queries answered in
// parallel, each with A* over the medial-axis graph, then shortened by
// line-of-sight shortcuts that keep a clearance.
//
//   Planner planner = Planner::build(world, {.radius = 0.3f});
//   std::vector<PlannedPath> paths = planner.plan_all(queries);
//
// Costs: a roadmap piece of length L whose ends have clearances c0, c1 costs
// L * (1 + clearance_weight * radius / ((c0 + c1) / 2)): narrow passages cost
// more, never less than their length, so the straight-line distance is an
// admissible A* heuristic. Paths are polylines in map coordinates.
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <span>
#include <string>
#include <vector>

#include "path/free_space.h"
#include "path/roadmap.h"

namespace throng::path {

struct PlanOptions {
  float radius = 0.25f;           // m: the agent's radius
  float clearance_weight = 1.0f;  // >= 0: how much narrow passages cost
  // Clearance the shortcuts keep, m; below 0: radius + 0.05 m (room for the
  // spline's rounding of corners).
  float shortcut_clearance = -1.0f;
  bool smooth = true;
  // Corners of the smoothed path become circular arcs of this radius (less
  // where the neighbouring edges are short or the arc would leave the
  // clearance); 0 keeps sharp corners. Walking turns need about 1-2 m.
  float corner_radius = 1.0f;
  std::int32_t attach_candidates = 32;  // nearest roadmap edges tried first when attaching a point
  FreeSpaceOptions free_space;
  RoadmapOptions roadmap_options() const;  // the roadmap for `radius`
  float kept_clearance() const { return shortcut_clearance < 0 ? radius + 0.05f : shortcut_clearance; }
  void validate() const;  // throws Error naming the field
};

struct PathQuery {
  glm::vec2 start{0.0f};
  glm::vec2 goal{0.0f};
  // The caller already found the straight line from start to goal blocked
  // for this radius: plan() goes to the roadmap without testing it again
  // (a long line's test costs as much as the search).
  bool straight_blocked = false;
};

enum class PlanStatus : std::uint8_t { Found, StartBlocked, GoalBlocked, Unreachable };
const char* to_string(PlanStatus s);

struct PlannedPath {
  PlanStatus status = PlanStatus::Unreachable;
  std::vector<glm::vec2> points;          // smoothed polyline from start to goal (empty unless Found)
  std::vector<glm::vec2> roadmap_points;  // the same before smoothing
  float length = 0.0f;                    // m, of `points`
  bool found() const { return status == PlanStatus::Found; }
};

// Landmarks for the A* heuristic (ALT: A*, landmarks, triangle
// inequality): the cheapest cost from a few far-apart roadmap nodes to every
// node. For any node v and goal G, cost(v, G) >= |cost(L, G) - cost(L, v)|,
// a far tighter bound than the straight line where the roadmap's costs run
// above lengths (clearance weight, detours round obstacles).
struct RoadmapLandmarks {
  std::int32_t count = 0;
  std::vector<float> cost;  // node-major: cost[v * count + l]; INFINITY where l cannot reach v
  float at(std::int32_t v, std::int32_t l) const {
    return cost[static_cast<std::size_t>(v) * static_cast<std::size_t>(count) + static_cast<std::size_t>(l)];
  }
  // The bound for node v given the goal's costs from every landmark.
  float lower_bound(std::int32_t v, std::span<const float> goal_cost) const;
};

class Planner {
 public:
  Planner() = default;
  static Planner build(const sim::World& world, const PlanOptions& options);
  static Planner build(FreeSpace space, const PlanOptions& options);

  const PlanOptions& options() const { return options_; }
  const FreeSpace& space() const { return space_; }
  const Roadmap& roadmap() const { return roadmap_; }

  PlannedPath plan(const PathQuery& query) const;
  // Every query, in parallel over queries (host threads, "path.plan");
  // results are the same for any thread count.
  std::vector<PlannedPath> plan_all(std::span<const PathQuery> queries) const;

  // Shortcut pass on its own: drops points while the segment that replaces
  // them keeps `clearance` (first a greedy sweep, then farthest-visible).
  // Every point of the polyline must lie in free space.
  std::vector<glm::vec2> shortcut(std::span<const glm::vec2> polyline, float clearance) const;
  // Replaces each corner by a circular arc of at most `radius` whose chords
  // keep the planner's radius (halving the arc's radius up to 4 times, else
  // the corner stays).
  std::vector<glm::vec2> round_corners(std::span<const glm::vec2> polyline, float radius) const;

 private:
  // Where a point joins the roadmap; edge < 0 when it cannot.
  EdgePoint attach(glm::vec2 p) const;
  float cost_to_edge_start(const EdgePoint& e) const;

  PlanOptions options_;
  FreeSpace space_;
  Roadmap roadmap_;
  std::vector<float> cumulative_cost_;  // per roadmap point: cost from its edge's start
  RoadmapLandmarks landmarks_;
};

// `count` landmarks of the roadmap whose point costs are `cumulative_cost`
// (as the planner's), chosen far apart (farthest-point selection).
RoadmapLandmarks choose_landmarks(const Roadmap& m, std::span<const float> cumulative_cost, std::int32_t count);

// Length of a polyline.
float polyline_length(std::span<const glm::vec2> points);

}  // namespace throng::path
