#include "sim/replanning.h"

#include <cmath>

namespace throng::sim {

namespace {

// Whether the straight segment from a to b stays in free space (sampled
// every 10 cm): an agent that cannot see its waypoint is off its route.
bool in_view(const World& world, glm::vec2 a, glm::vec2 b) {
  const float d = length_of(b - a);
  const int n = static_cast<int>(std::ceil(d / 0.1f));
  for (int k = 1; k < n; ++k)
    if (!world.in_free_space(a + (b - a) * (static_cast<float>(k) / static_cast<float>(n)))) return false;
  return true;
}

}  // namespace

Replanner::Replanner(const ScenarioSpec& spec, const CrowdHost& host, std::shared_ptr<const RoutePlanner> planner)
    : planner_(std::move(planner)) {
  if (!planner_) return;
  for (std::size_t i = 0; i < host.group.size(); ++i) {
    const GroupSpec& G = spec.groups[static_cast<std::size_t>(host.group[i])];
    if (!G.waypoints.empty() || G.goal.kind == GoalSpec::Kind::Exits || G.goal.kind == GoalSpec::Kind::Direction ||
        G.arrival == ArrivalBehaviour::Loop)
      continue;
    agents_.push_back(static_cast<Index>(i));
    radius_.push_back(host.radius[i]);
  }
  last_distance_.assign(agents_.size(), INFINITY);
  last_cursor_.assign(agents_.size(), -1);
}

Index Replanner::update(double time, const World& world, CrowdState& crowd) {
  if (agents_.empty() || time + 1e-9 < next_) return 0;
  next_ = time + kReplanPeriod;
  const std::vector<glm::vec2> position = crowd.position.to_vector(), goal = crowd.goal.to_vector();
  const std::vector<std::uint8_t> flags = crowd.flags.to_vector();
  std::vector<std::int32_t> cursor = crowd.waypoint_cursor.to_vector(), begin = crowd.waypoint_begin.to_vector(),
                            count = crowd.waypoint_count.to_vector(), goal_index = crowd.waypoint_goal.to_vector();
  std::vector<glm::vec2> waypoints = crowd.waypoints.to_vector();
  // Who is off its route: can't see its waypoint, and came no closer to it.
  std::vector<std::size_t> lost;
  for (std::size_t k = 0; k < agents_.size(); ++k) {
    const auto i = static_cast<std::size_t>(agents_[k]);
    const bool walking = (flags[i] & kAgentActive) != 0 && (flags[i] & (kAgentStopped | kAgentWaiting)) == 0 &&
                         (flags[i] & kAgentArrived) == 0;
    const float d = length_of(goal[i] - position[i]);
    const bool stalled = cursor[i] == last_cursor_[k] && d > last_distance_[k] - kReplanProgress;
    last_distance_[k] = d;
    last_cursor_[k] = cursor[i];
    if (walking && stalled && !in_view(world, position[i], goal[i])) lost.push_back(k);
  }
  if (lost.empty()) return 0;
  // One query per agent: the planner reuses its roadmap for the radius.
  std::vector<glm::vec2> path_start = crowd.path_start.to_vector(), current = goal;
  for (std::size_t k : lost) {
    const auto i = static_cast<std::size_t>(agents_[k]);
    const glm::vec2 from = position[i], to = waypoints[static_cast<std::size_t>(begin[i] + goal_index[i])];
    const std::vector<std::vector<glm::vec2>> route =
        planner_->plan(world, std::span<const glm::vec2>(&from, 1), std::span<const glm::vec2>(&to, 1), radius_[k]);
    begin[i] = static_cast<std::int32_t>(waypoints.size());
    if (!route.empty()) waypoints.insert(waypoints.end(), route[0].begin(), route[0].end());
    waypoints.push_back(to);
    count[i] = static_cast<std::int32_t>(waypoints.size()) - begin[i];
    goal_index[i] = count[i] - 1;
    cursor[i] = 0;
    current[i] = waypoints[static_cast<std::size_t>(begin[i])];
    path_start[i] = position[i];
    last_distance_[k] = INFINITY;
    last_cursor_[k] = -1;
  }
  // (Re-planned routes are plain points: agents on journeys of stages are not re-planned.)
  std::vector<std::int32_t> stage = crowd.waypoint_stage.to_vector();
  stage.resize(waypoints.size(), -1);
  const Memory m = current_memory();
  crowd.waypoints = Buffer<glm::vec2>(std::span<const glm::vec2>(waypoints), m);
  crowd.waypoint_stage = Buffer<std::int32_t>(std::span<const std::int32_t>(stage), m);
  crowd.waypoint_begin.write(0, std::span<const std::int32_t>(begin));
  crowd.waypoint_count.write(0, std::span<const std::int32_t>(count));
  crowd.waypoint_goal.write(0, std::span<const std::int32_t>(goal_index));
  crowd.waypoint_cursor.write(0, std::span<const std::int32_t>(cursor));
  crowd.goal.write(0, std::span<const glm::vec2>(current));
  crowd.path_start.write(0, std::span<const glm::vec2>(path_start));
  replanned_ += static_cast<Index>(lost.size());
  return static_cast<Index>(lost.size());
}

}  // namespace throng::sim
