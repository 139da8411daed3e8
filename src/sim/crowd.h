// The crowd as structure-of-arrays buffers in current_memory(), and spawning
// it from a scenario's groups (on the host, then uploaded).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/buffer.h"
#include "sim/scenario.h"
#include "sim/world.h"

namespace throng::sim {

// Agent flags (bits of CrowdState::flags).
inline constexpr std::uint8_t kAgentActive = 1;    // simulated and binned
inline constexpr std::uint8_t kAgentArrived = 2;   // reached its final waypoint at least once
inline constexpr std::uint8_t kAgentStopped = 4;   // arrived with behaviour `stop`: no more steering
inline constexpr std::uint8_t kAgentWaiting = 8;   // before its start time (pre-movement): stands, is sensed
inline constexpr std::uint8_t kAgentPending = 16;  // not yet entered (inflow): inactive until Simulation admits it

// Per-group constants the kernels need.
struct GroupRuntime {
  ArrivalBehaviour arrival = ArrivalBehaviour::Stop;
  float arrival_radius = 0.5f;
};

// What a waypoint asks beyond being reached (a stage of the journey): a
// gate's half extent (from its middle, the waypoint, to one end; zero for a
// point) and how long the agent stands once there.
struct StageRuntime {
  glm::vec2 gate_half{0.0f};  // m
  float wait_s = 0.0f;        // s
};
inline constexpr float kMinGateLength = 0.1f;  // m: a gate's two ends lie at least this far apart

struct CrowdState {
  Index count = 0;
  Buffer<glm::vec2> position;
  Buffer<glm::vec2> velocity;
  Buffer<float> heading;                // radians, from +x
  Buffer<float> radius;                 // m
  Buffer<float> pref_speed;             // m/s
  Buffer<glm::vec2> path_start;         // start of the current leg
  Buffer<glm::vec2> goal;               // end of the current leg (current waypoint)
  Buffer<std::int32_t> waypoint_begin;  // into waypoints
  Buffer<std::int32_t> waypoint_count;
  Buffer<std::int32_t> waypoint_cursor;  // current waypoint, 0-based
  Buffer<std::int32_t> waypoint_goal;    // the waypoint whose arrival counts as arriving
  Buffer<std::int32_t> group;
  Buffer<std::uint8_t> flags;
  Buffer<float> arrival_time;           // s, -1 until arrived
  Buffer<float> start_time;             // s: stands (kAgentWaiting) or stays out (kAgentPending) until then
  Buffer<glm::vec2> waypoints;          // every agent's waypoint list, flattened
  Buffer<std::int32_t> waypoint_stage;  // per entry of waypoints: into stages, -1 = a plain point
  Buffer<StageRuntime> stages;
  Buffer<GroupRuntime> groups;
};

// Host copy of the per-agent spawn data (what spawn_crowd computed).
struct CrowdHost {
  std::vector<glm::vec2> position;
  std::vector<float> heading, radius, pref_speed;
  std::vector<float> start_time;    // s (pre-movement or entry); empty = every agent walks at once
  std::vector<std::uint8_t> flags;  // initial flags; empty = every agent active
  std::vector<std::int32_t> group, waypoint_begin, waypoint_count, waypoint_goal;
  std::vector<glm::vec2> waypoints;
  std::vector<std::int32_t> waypoint_stage;  // per entry of waypoints; empty = every one a plain point
  std::vector<StageRuntime> stages;
  // Per group, per exit of its goal: into stages (a door line), -1 for an
  // exit given as a point; empty for a group without exits.
  std::vector<std::vector<std::int32_t>> exit_stages;
  std::vector<GroupRuntime> groups;
};

// Path planning plugs in here: for every group with a goal and no waypoints,
// plan() gets the world, the agents' start and goal points and returns, per
// agent, the points to walk through in between (empty = straight to the
// goal). path/route_planner.h is the roadmap planner `throng run` uses.
class RoutePlanner {
 public:
  virtual ~RoutePlanner() = default;
  virtual std::vector<std::vector<glm::vec2>> plan(const World& world, std::span<const glm::vec2> starts,
                                                   std::span<const glm::vec2> goals, float agent_radius) const = 0;
};

// Places every group's agents without overlaps in free space, draws their
// speeds and goals from the seed, and checks each goal lies in free space and
// is reachable from where the agent starts. Each agent's route is its
// waypoints (or the planner's points), then its goal; a loop adds the way
// back. Areas are filled from a hexagonal lattice (up to about 6.5 agents
// per m^2 at radius 0.2 m); a points spawn puts agent k at point k. Errors
// name the group field ("groups[1].spawn", "groups[0].spawn.points[3]",
// "groups[0].goal").
CrowdHost spawn_crowd(const ScenarioSpec& spec, const World& world, const ScenarioLimits& limits = {},
                      const RoutePlanner* planner = nullptr);
CrowdState upload_crowd(const CrowdHost& host, Memory memory = current_memory());

}  // namespace throng::sim
