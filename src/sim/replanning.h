// Re-planning: an agent whose route was planned (path planning, no
// waypoints of its own) and that has been pushed where it can no longer see
// the waypoint it walks to, and has not come closer to it for a period,
// gets a new route from where it stands to its goal. Checked every
// kReplanPeriod seconds on the host; the new routes are appended to the
// crowd's flattened waypoints (the old ones are left unused). The same
// result for any thread count or backend.
#pragma once

#include <memory>
#include <vector>

#include "sim/crowd.h"
#include "sim/world.h"

namespace throng::sim {

// s: how often agents are checked, and how long one must have made no
// progress (come kReplanProgress closer to its waypoint) to be re-planned.
inline constexpr double kReplanPeriod = 2.0;
inline constexpr float kReplanProgress = 0.5f;  // m

class Replanner {
 public:
  Replanner() = default;
  // The agents of `host` (as spawned for `spec`) whose routes `planner`
  // planned: groups with a goal and no waypoints, not looping, not choosing
  // among exits. None without a planner.
  Replanner(const ScenarioSpec& spec, const CrowdHost& host, std::shared_ptr<const RoutePlanner> planner);
  bool empty() const { return agents_.empty(); }
  // At `time` (every kReplanPeriod): re-plans the agents that need it and
  // rewrites their routes in `crowd`. Returns how many were re-planned.
  Index update(double time, const World& world, CrowdState& crowd);
  Index replanned() const { return replanned_; }  // over the whole run

 private:
  std::shared_ptr<const RoutePlanner> planner_;
  std::vector<Index> agents_;
  std::vector<float> radius_;         // per entry of agents_
  std::vector<float> last_distance_;  // to the current waypoint at the last check (inf: none yet)
  std::vector<std::int32_t> last_cursor_;
  double next_ = kReplanPeriod;
  Index replanned_ = 0;
};

}  // namespace throng::sim
