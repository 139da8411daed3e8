// One crowd simulation: world, crowd state, bins and the per-step stages of
// the perception layer, in the order of the frame (../shared/DESIGN.md):
//   1 bin    agents into uniform bins by a counting sort (grid.h)
//   2 sense  per agent, what the scenario's model (ModelParams::kind) makes
//            of its neighbours in the 3x3 bins and the walls nearby
//            (sense.h). Priority: the higher-priority force, obstacle
//            avoidance from the probe else agent avoidance. Collision-free
//            speed: the new velocity (collision_free_speed.h). Time to
//            collision: the total acceleration (ttc.h). Social force: the
//            step's mean velocity, integrated in substeps (social_force.h).
//   3 steer  priority: path following when nothing was sensed, then
//            integration; collision-free speed: the sensed velocity; time
//            to collision: integration; social force: the sensed velocity
//   4 move   contact passes and wall projection, accept or reject the move,
//            velocity, heading, arrivals and waypoints
// under one of two schedulers:
//   DoubleBuffer: every agent reads the previous step and writes the next;
//                 fully parallel, bitwise the same for any thread count.
//   FourColour:   the paper's batches: bins of one colour (cx & 1, cy & 1) in
//                 parallel, agents inside a bin in sequence, updated in place
//                 (sense and steer of one agent run back to back). Also the
//                 same for any thread count: no two cells of a batch touch.
//
// The move stage adds to the paper's forces a contact constraint: after
// integration, `model.contact_iterations` passes push overlapping pairs
// apart (each takes half the overlap) and project agents out of walls;
// while the last pass still found an overlap deeper than
// `model.contact_tolerance` (a jam pressing many agents together), up to
// `model.contact_extra_iterations` more passes run, so crowds pushed into
// a corner keep within the overlap bound and light crowds pay nothing; a
// position still closer than its radius to a wall is rejected (the agent
// stays put), so agents never penetrate obstacles. Velocity is the actual
// displacement / dt, so blocked agents slow down.
//
// Later stages of the frame (locomotion, LOD, pose, skin, emit) read the
// crowd's state after step(): see sim/frame_loop.h.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "sim/agent_grid.h"
#include "sim/collision_free_speed.h"
#include "sim/crowd.h"
#include "sim/exit_choice.h"
#include "sim/replanning.h"
#include "sim/grid.h"
#include "sim/navigation_field.h"
#include "sim/scenario.h"
#include "sim/world.h"

namespace throng::sim {

// Device-side views of the state the stages update (kernels in
// simulation_kernels.cpp).
struct AgentArrays {
  Span<glm::vec2> position;
  Span<glm::vec2> velocity;
  Span<float> heading;
  Span<const float> radius;
  Span<const float> pref_speed;
  Span<glm::vec2> path_start;
  Span<glm::vec2> goal;
  Span<const std::int32_t> waypoint_begin;
  Span<const std::int32_t> waypoint_count;
  Span<std::int32_t> waypoint_cursor;
  Span<const std::int32_t> waypoint_goal;
  Span<const std::int32_t> group;
  Span<std::uint8_t> flags;
  Span<float> arrival_time;
  Span<const glm::vec2> waypoints;
  Span<const std::int32_t> waypoint_stage;
  Span<const StageRuntime> stages;
  Span<const GroupRuntime> groups;
  Span<float> start_time;  // written when an agent stops to wait at a waypoint
};
AgentArrays arrays_of(CrowdState& c);

// What the move stage looks up once per agent per step (around its position
// at the start of the step) and reuses in every contact pass: the contact
// bins' 3x3 cells and the walls and circles nearby.
struct MoveCells {
  Cells3x3 agents;
  ObstacleCell obstacles;
};

// Where an agent heads this step under the models that sum over their
// neighbours (collision-free speed, time to collision, social force): the
// unit direction e0 its model aims it at (zero at its aim), how far its
// waypoint or goal is (m) and its preferred speed (m/s). Found from the
// agent's route (goal, waypoints, gates, navigation fields) by agent_aim.
struct AgentAim {
  glm::vec2 e0{0.0f};
  float distance = 0.0f;
  float pref_speed = 0.0f;
};

// The state of the steering bins' items gathered in item order (element k
// is agent bins.items[k]) while positions stay as binned: the double
// buffer's sense stage reads neighbours from it (NeighbourArrays), a few
// contiguous runs per agent instead of reads all over the crowd's arrays.
struct BinnedState {
  Span<glm::vec2> position;
  Span<glm::vec2> velocity;
  Span<float> radius;
  Span<std::uint8_t> flags;
  Span<AgentAim> aim;  // empty under the priority model (it does not use them)
};

struct StepContext {
  WorldView world;
  GridView bins;          // side query_radius: steering neighbours
  GridView contact_bins;  // side contact_cell: contact pairs
  ModelParams model;
  float dt = 0.1f;
  float time_after = 0.0f;  // simulated time at the end of this step
  // How far an agent may be from where it was binned when others read it:
  // 0 for the double buffer, one step's largest move for the four colours.
  float bin_slack = 0.0f;
  // Under the four colours, the state of the bins' items as binned (element
  // k: item k), which the collision-free speed model's far look reads
  // (add_far_anticipation): its cells, two away, move in the same launch.
  // Empty elsewhere: the far look reads the neighbours the model reads.
  BinnedState far_state;
  // The collision-free speed model's far look: element s, how the agents
  // of the steering bins' slot s walk (summarise_cell_headings), from the
  // state the far look reads; it passes over cells that add nothing
  // (cfs_cell_walks_along). Empty: every cell is looked at.
  Span<const CellHeadings> far_headings;
  FieldsView fields;   // navigation fields (none: every agent steers at its waypoint)
  Periodic periodic;   // the world's periodic boundaries (none: periods 0)
  BinnedState binned;  // the double buffer's sense stage: neighbours in item order; else empty
};

// Stages (each one or more parallel_for launches named "sim.<stage>...").
// Double buffer: what the model senses for every binned (active) agent (a
// force, or the collision-free velocity), then candidate positions.
void sense_double_buffer(const StepContext& ctx, const AgentArrays& a, Span<glm::vec2> sensed);
// The steering bins' items' state in item order: out.position[k] =
// a.position[ctx.bins.items[k]], and so on. out.aim, when not empty: each
// agent's aim (AgentAim), found first in agent order into `aims` (the reads
// of its route then run through the crowd's arrays in order), then copied.
void gather_binned_state(const StepContext& ctx, const AgentArrays& a, Span<AgentAim> aims, const BinnedState& out);
// out[s]: the walking directions and parked agents of the steering bins'
// slot s (CellHeadings), from `state`, the bins' items' state in item order.
void summarise_cell_headings(const GridView& bins, const BinnedState& state, Span<CellHeadings> out);
// The naive reference for the sense stage: every agent against every other,
// O(N^2); the same forces as sense_double_buffer (up to ties in urgency).
void sense_all_pairs(const StepContext& ctx, const AgentArrays& a, Span<glm::vec2> sensed);
void steer_double_buffer(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> sensed,
                         Span<glm::vec2> out_position);
// Both: the move cells around each binned agent's anchor (its position at
// the start of the step).
void move_cells(const StepContext& ctx, Span<const glm::vec2> anchor, Span<MoveCells> cells);
// Contact passes write, per agent, the deepest overlap the pass found
// before pushing (`depth`, m; the double buffer writes 0 for inactive
// agents, the four colours leave their entries as they were).
// Double buffer: one contact pass from `in` to `out`. `moved_before`, from
// mark_moved_items on the pass before (empty for the first pass): an agent
// none of whose move cells holds an agent that pass moved gets its input
// back, and keeps its depth, without looking at its neighbours: both are
// what the look would give, bit for bit, since everything it reads is what
// the pass before read.
void contacts_double_buffer(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> anchor,
                            Span<const MoveCells> cells, Span<const glm::vec2> in, Span<glm::vec2> out,
                            Span<float> depth, Span<const std::int32_t> moved_before = {});
// Four colour: sense + steer, then each contact pass, in place on a.position
// and a.velocity, colour by colour.
void sense_steer_four_colour(const StepContext& ctx, const AgentArrays& a);
void contacts_four_colour(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> anchor,
                          Span<const MoveCells> cells, Span<float> depth);
// The deepest of the per-agent overlaps a contact pass wrote, over the
// agents active now. The four-colour pass writes only the binned (active)
// agents' entries: an agent that left the crowd keeps its last depth, which
// must not count in later steps.
float deepest_contact(Span<const float> depth, Span<const std::uint8_t> flags);
// The agents a double-buffer pass from `in` to `out` moved (bit for bit:
// -0 differs from 0), counted along the contact bins' items:
// moved_before[k] = how many of items[0, k) moved, for k up to the item
// count (one entry more than items; further entries unused). Returns how
// many moved: a pass that moved none would give the same positions again,
// and so would every pass after it.
Index mark_moved_items(const GridView& contact_bins, Span<const glm::vec2> in, Span<const glm::vec2> out,
                       Span<std::int32_t> moved_before);
// What a contact pass did: its deepest overlap, and whether it moved anybody.
struct ContactPass {
  float deepest = 0.0f;  // m
  bool moved = false;
};
// Both: accepts or rejects each moved position, sets velocity, heading,
// arrivals and waypoints. `moved` may alias a.position.
void finalize_step(const StepContext& ctx, const AgentArrays& a, Span<const glm::vec2> anchor,
                   Span<const MoveCells> cells, Span<const glm::vec2> moved);
void copy_positions(Span<const glm::vec2> from, Span<glm::vec2> to);
// Agents whose flags have `bit` set (deterministic reduction).
Index count_flag(Span<const std::uint8_t> flags, std::uint8_t bit);
// Per spot k: the smallest gap (m) between a disc of spot_radius[k] there
// and any active agent binned in the 3x3 cells of `bins` around it (cells
// at least as wide as two radii); +inf when none is near.
void entry_clearance(const GridView& bins, const Periodic& periodic, Span<const glm::vec2> position,
                     Span<const float> radius, Span<const std::uint8_t> flags, Span<const glm::vec2> spots,
                     Span<const float> spot_radius, Span<float> clearance);

// An agent arriving over time (kAgentPending): when and where it enters.
struct PendingEntry {
  float time = 0.0f;  // s
  Index agent = 0;
  glm::vec2 spot{0.0f};
  float radius = 0.0f;
};

// How the sense stage finds neighbours: the paper's bins, or every agent
// (the O(N^2) reference of benchmarks and tests; double buffer only).
enum class NeighbourSearch : std::uint8_t { Bins, AllPairs };

struct SimulationOptions {
  ScenarioLimits limits;
  const RoutePlanner* planner = nullptr;  // path planning for groups with a goal and no waypoints
  // Re-plans, during the run, the planned routes of agents pushed off them
  // (sim/replanning.h); null: routes stay as spawned.
  std::shared_ptr<const RoutePlanner> replanner;
  // Navigation fields (sim/navigation_field.h) for the groups with a goal
  // and no waypoints whose goal is one point or a set of exits: one field
  // per target, for the largest radius heading there; with `planning:
  // quickest` built again every kQuickestRefreshS s at the crowd's density
  // (the simulation keeps the builder). Null: none.
  std::shared_ptr<const FieldBuilder> fields;
  NeighbourSearch neighbours = NeighbourSearch::Bins;
  // The reference forms of four shortcuts that change no result (tests
  // compare them bit for bit): bins hashed even where a dense box of cells
  // fits (AgentGrid), and counted with atomics then sorted (BinCounting),
  // every contact pass run even after one that moved nobody, every agent
  // looking at its neighbours in every pass (the double buffer's passes;
  // contacts_double_buffer), and the collision-free speed model's far look
  // through every cell in reach (StepContext::far_headings).
  bool dense_bins = true;
  BinCounting bin_counting = BinCounting::BySlotRange;
  bool skip_idle_contact_passes = true;
  bool skip_far_cells_walking_along = true;
};

class Simulation {
 public:
  // Builds the world and spawns the crowd in current_memory(). Errors name
  // the scenario field at fault (io/scenario_yaml maps them to file lines).
  explicit Simulation(const ScenarioSpec& spec, const SimulationOptions& options = {});

  // One step of dt: exits chosen again where due, bin (and admit the
  // arriving agents whose time has come and whose point is free), sense,
  // steer, move.
  void step();
  void run(std::int64_t steps);

  const ScenarioSpec& spec() const { return spec_; }
  const World& world() const { return world_; }
  CrowdState& crowd() { return crowd_; }
  const CrowdState& crowd() const { return crowd_; }
  const AgentGrid& bins() const { return bins_; }
  // Side of the contact bins: 4 * the largest radius covers every pair that
  // can touch during a step (each moves at most 0.9 radius).
  float contact_cell() const { return contact_bins_.cell_size(); }
  SchedulerKind scheduler() const { return scheduler_; }
  void set_scheduler(SchedulerKind s) { scheduler_ = s; }
  std::int64_t steps_done() const { return steps_done_; }
  // Contact passes the last step ran: contact_iterations, plus the extra
  // passes a jam needed; under the double buffer fewer when a pass moved
  // nobody (the passes left would have changed nothing).
  std::int32_t last_contact_passes() const { return contact_passes_; }
  // Steering bins' slots the far look's summary covered in the last step
  // that made one (StepContext::far_headings); 0 when none was made.
  Index far_cells_summarised() const { return far_cells_summarised_; }
  double time() const { return static_cast<double>(steps_done_) * spec_.dt; }
  Index agent_count() const { return crowd_.count; }

  // Host snapshots.
  std::vector<glm::vec2> positions() const { return crowd_.position.to_vector(); }
  std::vector<glm::vec2> velocities() const { return crowd_.velocity.to_vector(); }
  std::vector<float> headings() const { return crowd_.heading.to_vector(); }
  std::vector<std::uint8_t> flags() const { return crowd_.flags.to_vector(); }
  std::vector<float> arrival_times() const { return crowd_.arrival_time.to_vector(); }
  Index active_count() const;  // in the scene: entered and not despawned
  Index pending_count() const { return static_cast<Index>(pending_.size()); }  // yet to enter
  Index replanned_count() const { return replan_.replanned(); }                // routes planned anew so far
  const NavigationFields& fields() const { return fields_; }
  Index arrived_count() const;  // reached their goal at least once
  bool all_arrived() const { return arrived_count() == agent_count(); }

 private:
  void bin();
  bool admit_entries();
  void build_fields(const FieldBuilder& builder);
  // planning: quickest: every field built again at the crowd's density.
  void reweigh_fields();
  void sense_and_steer(const StepContext& ctx);
  Span<const CellHeadings> far_headings(const GridView& bins, const BinnedState& state);
  bool summarises_far_cells() const;
  void move(const StepContext& ctx);
  StepContext context() const;

  ScenarioSpec spec_;
  World world_;
  CrowdState crowd_;
  AgentGrid bins_;
  AgentGrid contact_bins_;
  SchedulerKind scheduler_ = SchedulerKind::DoubleBuffer;
  NeighbourSearch neighbours_ = NeighbourSearch::Bins;
  bool dense_bins_ = true, skip_idle_contact_passes_ = true, skip_far_cells_walking_along_ = true;
  float max_radius_ = 0.0f;
  std::int64_t steps_done_ = 0;
  std::int32_t contact_passes_ = 0;
  Index far_cells_summarised_ = 0;
  Buffer<glm::vec2> anchor_, candidate_, scratch_, sensed_;
  Buffer<float> contact_depth_;  // per agent: the deepest overlap the last contact pass found
  Buffer<MoveCells> move_cells_;
  Buffer<glm::vec2> binned_position_, binned_velocity_;  // the steering bins' items' state (gather_binned_state)
  Buffer<float> binned_radius_;
  Buffer<std::uint8_t> binned_flags_;
  Buffer<CellHeadings> cell_headings_;  // per slot of the steering bins (summarise_cell_headings)
  Buffer<AgentAim> aim_, binned_aim_;   // each agent's aim, in agent order and in the bins' item order
  Buffer<std::int32_t> moved_before_;   // contact items moved by the last pass, counted (mark_moved_items)
  std::vector<PendingEntry> pending_;   // by entry time, then agent
  ExitChooser exits_;                   // groups choosing the quickest exit
  Replanner replan_;                    // planned routes, planned again for agents pushed off them
  NavigationFields fields_;
  // planning: quickest: the builder and each field's target and radius.
  std::shared_ptr<const FieldBuilder> quickest_builder_;
  struct FieldTarget {
    glm::vec2 point{0.0f}, half{0.0f};  // a point, or a door line point +- half
    float radius = 0.0f;                // the largest agent heading there
  };
  std::vector<FieldTarget> field_targets_;
  std::int64_t fields_weighed_at_ = -1;   // the step they were last weighed at
  CrowdDensity density_cells_;            // the density map's cells (no densities)
  std::vector<float> density_free_area_;  // m^2 of each cell in free space
};

}  // namespace throng::sim
