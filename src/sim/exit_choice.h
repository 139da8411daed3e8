// Exit choice by the quickest way out: every reconsider_s seconds each agent
// whose group's goal is `exits` with choice quickest weighs each exit e by
//
//   cost_e = (d_min + kExitDetourWeight (d_e - d_min)) / v0
//            + q_e / (kExitSpecificFlow * width_e)
//
// d_e the distance to the exit (along its navigation field where the run
// has one, sim/navigation_field.h; else straight), d_min that to the
// nearest exit (the walk beyond it to a farther exit counts twice: people
// prefer the nearest exit, and with every metre weighed at its time the
// crowd split evenly between RiMEA 3.0 test 11's two doors, both emptying
// at the same moment, where most should take the nearer;
// docs/verification.md), v0 the agent's preferred speed and
// q_e the agents heading for e that are nearer the exits than it (each takes
// its turn at the door, which passes kExitSpecificFlow persons per metre of
// width and second), and heads for the cheapest. Agents decide in order of
// their distance to the nearest exit, so q_e counts those who decided before
// them in the same round; staying with the current exit is preferred unless
// another is cheaper by more than kExitSwitchGain, so nobody flips between
// two equal doors every round. Ties go to the exit that an agent's own
// seeded draw ranks first. A host stage (the choice reads every agent of
// the chosen groups), the same for any thread count or backend.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/crowd.h"
#include "sim/navigation_field.h"
#include "sim/scenario.h"

namespace throng::sim {

// P/(m s): what a door passes per metre of width in a queue (the SFPE
// handbook's design value for doors, 1.3 persons per metre and second).
inline constexpr float kExitSpecificFlow = 1.3f;
// An agent leaves its exit only for one at least this much cheaper.
inline constexpr float kExitSwitchGain = 0.1f;
// The weight of the walk beyond the nearest exit's distance (see above).
inline constexpr float kExitDetourWeight = 2.0f;

class ExitChooser {
 public:
  // The agents of `host` (as spawned for `spec`) whose group chooses the
  // quickest exit; none when no group does.
  ExitChooser() = default;
  ExitChooser(const ScenarioSpec& spec, const CrowdHost& host);
  bool empty() const { return agents_.empty(); }
  // Walking distances from the run's navigation fields (host copies, kept
  // by the caller for the chooser's life) for the exits that have one.
  void use_fields(FieldsView host_fields);
  // At the first call and then every reconsider_s seconds of `time`: the
  // exits weighed again and the goals of agents that switch rewritten in
  // `crowd` (the flattened waypoint and its stage and, on its last leg, the
  // current goal).
  // Returns the number of agents that switched.
  Index update(double time, CrowdState& crowd);

 private:
  struct Chooser {
    Index agent = 0;
    std::int32_t group = 0;
    std::int32_t goal_index = 0;  // of the goal in the agent's route (its waypoint_goal)
    std::int32_t goal_slot = 0;   // of the goal in the flattened waypoints
    float speed = 1.0f;           // preferred, m/s
    std::uint32_t exit = 0;       // current choice, into the group's exits
    std::size_t queue_base = 0;   // the group's first exit in the flat queue counts
    std::uint64_t tie = 0;        // seeded draw ranking the exits on a tie
  };
  float exit_cost(const Chooser& c, glm::vec2 p, std::uint32_t e, float nearest,
                  const std::vector<Index>& queued) const;
  float exit_distance(std::int32_t group, std::uint32_t e, glm::vec2 p) const;

  std::vector<std::vector<ExitSpec>> exits_;           // per group (empty where the group does not choose)
  std::vector<std::vector<std::int32_t>> exit_field_;  // per group and exit: its navigation field, or -1
  std::vector<std::vector<std::int32_t>> exit_stage_;  // per group and exit: its gate's stage, or -1 (CrowdHost)
  FieldsView fields_;
  std::size_t exit_count_ = 0;  // exits of all choosing groups (the flat queue counts)
  std::vector<Chooser> agents_;
  double period_ = 2.0;  // s: the shortest reconsider_s of the choosing groups
  double next_ = 0.0;    // s: when to choose next
};

}  // namespace throng::sim
