// A small motion state machine for the path tests, built in code (the YAML
// reader and the default machine are tested in tests/io).
#pragma once

#include <cmath>
#include <numbers>

#include "motion/default_set.h"
#include "path/state_machine.h"

namespace throng::path::testing {

inline StateMachineSpec small_machine_spec(std::int32_t k = 32) {
  using motion::biomech::Gait;
  StateMachineSpec m;
  m.points_per_segment = k;
  m.start_state = "idle";
  m.end_state = "idle";
  auto clip = [&](const char* name, Gait gait, double speed, double turn_dps) {
    ClipSpec c;
    c.name = name;
    c.spec.name = name;
    c.spec.gait = gait;
    c.spec.speed = speed;
    c.spec.turn_rate = turn_dps * std::numbers::pi / 180.0;
    m.clips.push_back(c);
  };
  clip("idle", Gait::Stand, 0, 0);
  clip("walk", Gait::Walk, 1.35, 0);
  clip("run", Gait::Run, 2.7, 0);
  clip("left", Gait::Walk, 1.2, 30);
  clip("sharp_left", Gait::Walk, 1.0, 60);
  clip("right", Gait::Walk, 1.2, -30);
  m.groups = {{"locomotion", "", {}}, {"F", "locomotion", {}}, {"L", "locomotion", {}}, {"R", "locomotion", {}}};
  auto state = [&](const char* name, const char* group, bool loco, std::vector<std::pair<const char*, double>> segs) {
    StateSpec s;
    s.name = name;
    s.group = group;
    s.locomotion = loco;
    for (auto [clip_name, start] : segs) s.segments.push_back({clip_name, start, loco ? 0.0 : 60.0, {}});
    m.states.push_back(s);
  };
  state("idle", "", false, {{"idle", 0}});
  state("walk_forward", "F", true, {{"walk", 0}, {"walk", 32}});
  state("run_forward", "F", true, {{"run", 0}});
  state("walk_left", "L", true, {{"left", 0}, {"sharp_left", 0}});
  state("walk_right", "R", true, {{"right", 0}, {"right", 34}});
  auto edge = [&](const char* from, const char* to, float cost = 0) { m.edges.push_back({from, to, cost, {}}); };
  edge("F", "locomotion");
  edge("L", "F");
  edge("L", "L");
  edge("R", "F");
  edge("R", "R");
  edge("idle", "walk_forward");
  edge("walk_forward", "idle");
  return m;
}

inline const MotionGraph& small_machine() {
  static const MotionGraph m = MotionGraph::build(small_machine_spec(), motion::default_skeleton());
  return m;
}

}  // namespace throng::path::testing
