#include "sim/exit_choice.h"

#include <algorithm>
#include <cmath>

#include "core/random.h"

namespace throng::sim {

ExitChooser::ExitChooser(const ScenarioSpec& spec, const CrowdHost& host) {
  exits_.resize(spec.groups.size());
  exit_stage_ = host.exit_stages;
  exit_stage_.resize(spec.groups.size());
  std::vector<std::size_t> first_exit(spec.groups.size(), 0);
  bool any = false;
  for (std::size_t g = 0; g < spec.groups.size(); ++g) {
    const GoalSpec& goal = spec.groups[g].goal;
    first_exit[g] = exit_count_;
    if (goal.kind != GoalSpec::Kind::Exits || goal.choice != ExitChoice::Quickest) continue;
    exits_[g] = goal.exits;
    exit_count_ += goal.exits.size();
    period_ = any ? std::min(period_, static_cast<double>(goal.reconsider_s)) : goal.reconsider_s;
    any = true;
  }
  for (std::size_t i = 0; i < host.group.size(); ++i) {
    const auto g = static_cast<std::size_t>(host.group[i]);
    if (exits_[g].empty()) continue;
    Chooser c;
    c.agent = static_cast<Index>(i);
    c.group = host.group[i];
    c.goal_index = host.waypoint_goal[i];
    c.goal_slot = host.waypoint_begin[i] + c.goal_index;
    c.speed = std::max(host.pref_speed[i], 0.1f);
    c.queue_base = first_exit[g];
    // Spawning aimed the agent at its nearest exit: find which it is.
    const std::int32_t e = spec.groups[g].goal.exit_at(host.waypoints[static_cast<std::size_t>(c.goal_slot)]);
    if (e >= 0) c.exit = static_cast<std::uint32_t>(e);
    c.tie = Rng(spec.seed, (std::uint64_t{5} << 60) + static_cast<std::uint64_t>(i)).next();
    agents_.push_back(c);
  }
}

void ExitChooser::use_fields(FieldsView host_fields) {
  fields_ = host_fields;
  exit_field_.assign(exits_.size(), {});
  for (std::size_t g = 0; g < exits_.size(); ++g)
    for (const ExitSpec& x : exits_[g]) exit_field_[g].push_back(field_of(fields_, x.point));
}

float ExitChooser::exit_distance(std::int32_t group, std::uint32_t e, glm::vec2 p) const {
  const auto g = static_cast<std::size_t>(group);
  const glm::vec2 to = exits_[g][e].point;
  const std::int32_t f = exit_field_.empty() ? -1 : exit_field_[g][e];
  const float along = f < 0 ? INFINITY : field_distance(fields_, f, p);
  return along < INFINITY ? along : length_of(to - p);
}

float ExitChooser::exit_cost(const Chooser& c, glm::vec2 p, std::uint32_t e, float nearest,
                             const std::vector<Index>& queued) const {
  const ExitSpec& x = exits_[static_cast<std::size_t>(c.group)][e];
  const auto q = static_cast<float>(queued[c.queue_base + e]);
  const float walk = nearest + kExitDetourWeight * (exit_distance(c.group, e, p) - nearest);
  const float cost = walk / c.speed + q / (kExitSpecificFlow * x.width);
  return e == c.exit ? cost * (1.0f - kExitSwitchGain) : cost;
}

Index ExitChooser::update(double time, CrowdState& crowd) {
  if (agents_.empty() || time + 1e-9 < next_) return 0;
  next_ = time + period_;
  const std::vector<glm::vec2> position = crowd.position.to_vector();
  const std::vector<std::uint8_t> flags = crowd.flags.to_vector();
  const std::vector<std::int32_t> cursor = crowd.waypoint_cursor.to_vector();
  std::vector<glm::vec2> waypoints = crowd.waypoints.to_vector(), goal = crowd.goal.to_vector(),
                         path_start = crowd.path_start.to_vector();
  std::vector<std::int32_t> stage = crowd.waypoint_stage.to_vector();
  // Those in the scene still to leave, nearest an exit first (one yet to
  // enter chooses at the first round after it entered).
  std::vector<std::pair<float, std::size_t>> order;
  for (std::size_t k = 0; k < agents_.size(); ++k) {
    const Chooser& c = agents_[k];
    const auto i = static_cast<std::size_t>(c.agent);
    if ((flags[i] & kAgentArrived) != 0 || (flags[i] & kAgentActive) == 0) continue;
    float nearest = INFINITY;
    for (std::uint32_t e = 0; e < exits_[static_cast<std::size_t>(c.group)].size(); ++e)
      nearest = std::min(nearest, exit_distance(c.group, e, position[i]));
    order.push_back({nearest, k});
  }
  std::sort(order.begin(), order.end());
  std::vector<Index> queued(exit_count_, 0);
  Index switched = 0;
  for (const auto& [nearest, k] : order) {
    Chooser& c = agents_[k];
    const auto i = static_cast<std::size_t>(c.agent);
    const auto count = static_cast<std::uint32_t>(exits_[static_cast<std::size_t>(c.group)].size());
    std::uint32_t best = c.exit;
    float best_cost = exit_cost(c, position[i], best, nearest, queued);
    for (std::uint32_t r = 0; r < count; ++r) {
      const std::uint32_t e = static_cast<std::uint32_t>((c.tie + r) % count);  // the agent's own order on ties
      const float cost = exit_cost(c, position[i], e, nearest, queued);
      if (cost < best_cost) {
        best = e;
        best_cost = cost;
      }
    }
    ++queued[c.queue_base + best];
    if (best == c.exit) continue;
    c.exit = best;
    ++switched;
    const glm::vec2 to = exits_[static_cast<std::size_t>(c.group)][best].point;
    waypoints[static_cast<std::size_t>(c.goal_slot)] = to;
    const std::vector<std::int32_t>& stages = exit_stage_[static_cast<std::size_t>(c.group)];
    stage[static_cast<std::size_t>(c.goal_slot)] = best < stages.size() ? stages[best] : -1;
    if (cursor[i] == c.goal_index) {  // on its last leg: a new leg from where it stands
      goal[i] = to;
      path_start[i] = position[i];
    }
  }
  if (switched > 0) {
    crowd.waypoints.write(0, std::span<const glm::vec2>(waypoints));
    crowd.waypoint_stage.write(0, std::span<const std::int32_t>(stage));
    crowd.goal.write(0, std::span<const glm::vec2>(goal));
    crowd.path_start.write(0, std::span<const glm::vec2>(path_start));
  }
  return switched;
}

}  // namespace throng::sim
