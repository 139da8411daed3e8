// A scenario as plain host data: world geometry, agent groups, model
// parameters, time stepping, camera and outputs. io/scenario_yaml reads it
// from YAML (the schema is docs/scenarios.md); sim builds a World and a crowd
// from it. Field paths used in errors ("groups[1].spawn") follow the YAML keys.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/config.h"
#include "sim/geometry.h"

namespace throng::sim {

// Which steering model turns neighbours, walls and the goal into motion
// (docs/simulation.md has the equations and the source of every default).
enum class ModelKind : std::uint8_t {
  CollisionFreeSpeed,  // Tordeux, Chraibi, Seyfried 2016, with anticipation (collision_free_speed.h)
  Priority,            // the paper's three forces by priority (steering.h)
  Ttc,                 // Karamouzas, Skinner, Guy 2014: the time-to-collision power law (ttc.h)
  SocialForce,         // Helbing, Farkas, Vicsek 2000: the social force with body contact and friction (social_force.h)
};
const char* to_string(ModelKind k);
// "collision_free_speed" | "priority" | "ttc" | "social_force"; throws Error naming `field` otherwise.
ModelKind parse_model_kind(const std::string& text, const std::string& field);

// Parameters of the collision-free speed model (collision_free_speed.h).
// Defaults: a, D, b, Dw as JuPedSim's CollisionFreeSpeedModel (8, 0.1 m,
// 5, 0.02 m); T fitted to Weidmann's fundamental diagram (docs/simulation.md;
// the published calibration is about 1 s); the anticipation and turn terms
// are this engine's.
struct CollisionFreeSpeedParams {
  float time_gap = 0.75f;           // s: T, the time gap kept to the agent ahead
  float neighbour_strength = 8.0f;  // a: neighbour repulsion at contact, relative to the goal direction
  float neighbour_range = 0.1f;     // m: D, its decay length
  float wall_strength = 5.0f;       // b: wall repulsion at contact
  float wall_range = 0.02f;         // m: Dw
  float avoid_strength = 4.5f;      // k: sideways push from an oncoming neighbour about to meet us (0 = off)
  float avoid_time = 4.0f;          // s: how far ahead oncoming neighbours are anticipated
  float side_margin = 0.75f;        // m: an oncoming neighbour counts when its centre is within l + this of our line
  float turn_time = 0.3f;           // s: the walking direction turns towards the wanted one over about this
  float anticipation_time = 0.0f;   // s: the gap ahead is measured to where neighbours will be after this
  float lane_width = 1.0f;          // of r_i + r_j: the time gap is kept to neighbours ahead within this of our line
};

// Parameters of the time-to-collision power-law model (ttc.h). Defaults:
// k, tau0 and the goal relaxation time as Karamouzas, Skinner, Guy 2014
// (Phys. Rev. Lett. 113, 238701: k = 1.5, tau0 = 3 s, xi = 0.54 s rounded
// to 0.5 s); the paper senses 10 m, this engine 4 m (the bins' side); the
// largest acceleration 20 m/s^2 as the paper's reference code.
struct TtcParams {
  float strength =
      1.5f;  // m^2: k, scale of the interaction energy E = k tau^-2 exp(-tau/tau0) (m^2/s^2, per unit mass)
  float time_horizon = 3.0f;       // s: tau0, beyond which interactions fade exponentially
  float relaxation_time = 0.5f;    // s: xi, the goal term (v_pref e0 - v) / xi
  float sensing_radius = 4.0f;     // m: neighbours whose centre lies within this are considered
  float max_acceleration = 20.0f;  // m/s^2: the total force is clamped to this
  float side_bias =
      3.0f;  // keep right: multiple of |F_ij| also pushed right of the relative velocity (0 = the paper's)
};

// Parameters of the social force model (social_force.h). Defaults: m, tau,
// A, B, k and kappa as Helbing, Farkas, Vicsek 2000 ("Simulating dynamical
// features of escape panic", Nature 407, 487-490: 80 kg, 0.5 s, 2000 N,
// 0.08 m, 1.2e5 kg/s^2, 2.4e5 kg/(m s)), isotropic as that paper (lambda =
// 1; Helbing, Johansson 2009 use about 0.3 for walkers, which jams this
// engine's four-way and circle encounters, docs/simulation.md); the sensing
// radius, the substep and the keep-right bias are this engine's.
struct SocialForceParams {
  float mass = 80.0f;             // kg: m
  float relaxation_time = 0.5f;   // s: tau, the driving term m (v0 e0 - v) / tau
  float strength = 2000.0f;       // N: A, the social repulsion at contact
  float range = 0.08f;            // m: B, its decay length
  float body_stiffness = 1.2e5f;  // kg/s^2: k, the body force k g(r_ij - d_ij)
  float friction = 2.4e5f;        // kg/(m s): kappa, the sliding friction kappa g(r_ij - d_ij) dv^t
  float anisotropy = 1.0f;      // lambda: weight of the social repulsion from behind (1 = isotropic, the 2000 paper's)
  float sensing_radius = 2.0f;  // m: neighbours whose centre lies within this are felt
  float max_substep = 0.01f;    // s: the step is integrated in substeps of at most this (the body force's stiffness)
  float side_bias =
      6.0f;  // keep right: multiple of the social repulsion also pushed right of the relative velocity (0 = the paper's)
};

// The steering model and its parameters, and those of the move stage.
struct ModelParams {
  ModelKind kind = ModelKind::CollisionFreeSpeed;
  CollisionFreeSpeedParams cfs;
  TtcParams ttc;
  SocialForceParams sf;
  // The priority model (the paper's):
  float pred_time = 1.0f;        // s: prediction horizon (predTime)
  float max_force = 4.0f;        // m/s^2: largest steering acceleration
  float personal_space = 0.15f;  // m: observation radius = radius + personal_space
  float lane_half_width = 0.5f;  // m: path following steers back beyond this
  float relaxation_time = 0.5f;  // s: path following reaches the desired velocity in about this
  float probe_margin = 0.1f;     // m: probe half-width = radius + probe_margin
  // Every model:
  float max_speed = 2.0f;               // m/s: no agent is faster (maxVelocity)
  std::int32_t contact_iterations = 4;  // contact/obstacle projection passes per step (the added constraint)
  // More passes, at most this many, while the last found a pair overlapping
  // by more than contact_tolerance (a jam; see sim/simulation.h).
  std::int32_t contact_extra_iterations = 8;
  float contact_tolerance = 0.03f;  // m
  // m: the largest agent radius the scenario may use (0: the model's
  // default, max_radius() below); the collision-free speed model's bins
  // grow with it.
  float body_radius_limit = 0.0f;
  // Side of the steering bins: every neighbour the model looks at lies
  // within it. Priority: 2 * pred_time * max_speed (the paper's). Collision-
  // free speed: the gap that allows max_speed (T * max_speed) plus two of
  // the largest radius (max_radius()), at least the anticipation reach.
  // Time to collision and social force: their sensing radius.
  THRONG_HOST_DEVICE float query_radius() const {
    if (kind == ModelKind::Priority) return 2.0f * pred_time * max_speed;
    if (kind == ModelKind::Ttc) return ttc.sensing_radius;
    if (kind == ModelKind::SocialForce) return sf.sensing_radius;
    const float gap = cfs.time_gap * max_speed, anticipate = 0.5f * cfs.avoid_time * max_speed;
    return 2.0f * max_radius() + (gap > anticipate ? gap : anticipate);
  }
  // The largest agent radius the bins allow: body_radius_limit when given,
  // else pred_time * max_speed for the priority model and kDefaultMaxRadius
  // for the others.
  THRONG_HOST_DEVICE float max_radius() const {
    if (body_radius_limit > 0.0f) return body_radius_limit;
    return kind == ModelKind::Priority ? pred_time * max_speed : kDefaultMaxRadius;
  }
  static constexpr float kDefaultMaxRadius = 0.5f;  // m
  // Throws Error naming the field ("model.pred_time") for NaN, negative or
  // out-of-range values.
  void validate() const;
};

enum class ArrivalBehaviour : std::uint8_t { Stop, Despawn, Loop };
enum class SchedulerKind : std::uint8_t { DoubleBuffer, FourColour };
// How groups with a goal and no waypoints find their way: routes planned on
// the roadmap of free space (path/route_planner.h; io::build_simulation
// supplies the planner), navigation fields shared by every agent heading
// to the same target (sim/navigation_field.h, path/distance_field.h), the
// same fields weighed again every kQuickestRefreshS seconds by the crowd's
// density (the quickest way rather than the shortest), or straight to the
// goal.
enum class PlanningKind : std::uint8_t { Roadmap, None, Field, Quickest };
inline constexpr double kQuickestRefreshS = 2.0;
const char* to_string(ArrivalBehaviour a);
const char* to_string(SchedulerKind s);
const char* to_string(PlanningKind p);
// "double_buffer" | "four_colour"; throws Error on anything else.
SchedulerKind parse_scheduler(const std::string& text, const std::string& field);

// A region of the plane: rect, disc, ring (points on a circle), polygon, or
// points (exact spawn positions, one per agent; not an area).
struct Region {
  enum class Kind : std::uint8_t { rect, disc, ring, polygon, points };  // named as in YAML
  Kind kind = Kind::rect;
  glm::vec2 min{0.0f}, max{0.0f};  // Rect
  glm::vec2 center{0.0f};          // Disc, Ring
  float radius = 0.0f;             // Disc, Ring (Ring: 0 = from spacing)
  float spacing = 0.0f;            // Ring: arc length between agents when radius is 0
  Polygon polygon;                 // Polygon
  std::vector<glm::vec2> points;   // Points: agent k starts at points[k]
};

// A way out: agents heading for it aim at `point` (the middle of the door,
// say) and leave through `width` metres, which sizes its capacity.
// A scenario's `exits` list names exits that groups then refer to by name.
// An exit given as a door line is passed by crossing it anywhere along it
// (as a gate); one given as a point and width, within arrival_radius of
// the point.
struct ExitSpec {
  glm::vec2 point{0.0f};
  float width = 1.0f;    // m
  std::string name;      // empty when given inline in a group's goal
  glm::vec2 half{0.0f};  // m: from point to the line's `to` end; zero for a point and width
};
// How an agent picks among its group's exits: the nearest in a straight
// line (once, at the start), or the quickest (sim/exit_choice.h: walking
// time plus the wait behind those heading there, weighed again every
// reconsider_s seconds).
enum class ExitChoice : std::uint8_t { Nearest, Quickest };

// How far ahead of an agent a direction goal lies (m): the goal moves with
// the agent, so this only needs to be far beyond any arrival radius, and
// near enough that float rounding keeps it where it is (0.06 mm there).
inline constexpr float kDirectionReach = 1.0e3f;

// One waypoint of a group: the same for every agent, or per agent.
struct GoalSpec {
  enum class Kind : std::uint8_t {
    Point,   // value
    Offset,  // spawn position + value
    Mirror,  // 2 * value - spawn position (the antipode through value)
    Random,  // a random free point of `region` per agent
    Exits,   // one of `exits` per agent, chosen by `choice` (a group's goal only)
    Gate,    // the line from value to gate_to, passed when crossed anywhere along it (waypoints only)
    // Walk on in the unit direction `value`, never arriving (a group's goal
    // in a periodic world only): the goal lies kDirectionReach ahead of
    // the agent and moves with it, step by step and across the seam.
    Direction,
  };
  Kind kind = Kind::Point;
  glm::vec2 value{0.0f};
  glm::vec2 gate_to{0.0f};      // Gate
  Region region;                // Random
  std::vector<ExitSpec> exits;  // Exits
  ExitChoice choice = ExitChoice::Nearest;
  float reconsider_s = 2.0f;  // Exits, quickest: how often each agent weighs the exits again
  // s: a waypoint where the agent stands this long once it reaches it (a
  // waiting area: a `random` waypoint with a wait; not on the goal).
  float wait_s = 0.0f;
  // The first of `exits` whose point is `point`, or -1 (Exits: which exit
  // an agent aiming at `point` heads for).
  std::int32_t exit_at(glm::vec2 point) const {
    for (std::size_t e = 0; e < exits.size(); ++e)
      if (exits[e].point == point) return static_cast<std::int32_t>(e);
    return -1;
  }
  static GoalSpec at(glm::vec2 p) {
    GoalSpec g;
    g.value = p;
    return g;
  }
  // A gate waypoint: the line from `from` to `to`.
  static GoalSpec gate(glm::vec2 from, glm::vec2 to) {
    GoalSpec g;
    g.kind = Kind::Gate;
    g.value = from;
    g.gate_to = to;
    return g;
  }
};

struct SpeedSpec {
  float mean = 1.3f;    // m/s
  float stddev = 0.0f;  // normal distribution, clamped to [min, max]
  float min = 0.5f;
  float max = 2.0f;
};

// Pre-movement (reaction) time: how long each agent of a group stands where
// it spawned before it starts walking (RiMEA 3.0 test 5). Drawn per agent
// from the seed: uniform in [min, max]; normal or log-normal with the given
// mean and standard deviation of the times themselves, redrawn until inside
// [min, max] (then clamped after 64 draws). None: every agent walks at once.
struct PremovementSpec {
  enum class Kind : std::uint8_t { none, uniform, normal, lognormal };  // named as in YAML
  Kind kind = Kind::none;
  float mean = 0.0f;    // s (normal, lognormal)
  float stddev = 0.0f;  // s (normal, lognormal)
  float min = 0.0f;     // s
  float max = 0.0f;     // s
};

// People arriving over time (a source): agent k of the group enters at
// times[k], or else at from + k / rate, at a free point of the group's
// spawn area drawn from the seed; one whose point is taken by someone at its
// time waits there, unseen, until the point is free.
struct InflowSpec {
  bool enabled = false;
  float rate = 0.0f;         // P/s
  float from = 0.0f;         // s: the first entry
  float until = INFINITY;    // s: no entry is scheduled after this
  std::vector<float> times;  // s, ascending, one per agent; replaces rate and from
  // When agent k of the group is scheduled to enter (s).
  float entry_time(std::int64_t k) const {
    return times.empty() ? from + static_cast<float>(k) / rate : times[static_cast<std::size_t>(k)];
  }
};

struct GroupSpec {
  std::string name;
  std::int64_t count = 0;
  float radius = 0.25f;
  SpeedSpec speed;
  Region spawn;
  // The route: `waypoints` in order, then `goal`. Reaching the goal counts as
  // arriving. A group with a goal and no waypoints gets its waypoints from the
  // route planner when the simulation has one (path planning), else walks
  // straight to the goal.
  std::vector<GoalSpec> waypoints;
  GoalSpec goal;
  ArrivalBehaviour arrival = ArrivalBehaviour::Stop;  // loop: back along the route to the start, and again
  float arrival_radius = 0.5f;
  PremovementSpec premovement;
  InflowSpec inflow;
};

struct OutputSpec {
  std::string dir;         // empty = out/<name>
  std::int64_t every = 0;  // trajectory frame stride; 0 = about one frame per simulated second
  bool trajectories = true;
  bool stats = true;
};

// A generated obstacle field: `count` shapes placed at random in `region`.
struct ScatterSpec {
  std::int64_t count = 0;
  Region region;          // Rect
  float min_size = 1.0f;  // m: circle diameter or rectangle side
  float max_size = 4.0f;
  float clearance = 2.0f;  // m: free gap kept between scattered shapes
  std::uint64_t seed = 1;
};

struct WorldSpec {
  bool has_walkable = false;
  // Periodic boundaries (core/periodic.h): the rectangular walkable area's
  // opposite sides joined along x and/or y.
  bool periodic_x = false, periodic_y = false;
  Polygon walkable;                         // outer boundary and holes
  std::vector<Polygon> polygons;            // obstacle polygons
  std::vector<std::string> polygon_fields;  // "world.obstacles[3]" per polygon
  std::vector<Circle> circles;
  std::vector<std::string> circle_fields;
  std::vector<ScatterSpec> scatters;
  std::vector<std::string> scatter_fields;
};

// Where the crowd is measured (map coordinates): rectangles for density and
// speed (the fundamental diagram, classic and Voronoi), lines for flow by
// the N-t curve. Names label them in stats.json.
struct MeasurementArea {
  std::string name;
  Aabb rect;
};
// Walking from `from` to `to`, the positive crossing direction is to the left.
struct MeasurementLine {
  std::string name;
  glm::vec2 from{0.0f};
  glm::vec2 to{0.0f};
};
struct MeasurementSpec {
  std::vector<MeasurementArea> areas;  // empty = a 10 m square at the centre of the scene
  std::vector<MeasurementLine> lines;
  float voronoi_cutoff = 2.0f;  // m: Voronoi cells are clipped to a disc of this radius around their agent
};

struct ScenarioSpec {
  std::string name = "scenario";
  std::string description;
  float dt = 0.1f;                // s
  std::int64_t steps = 0;         // derived from duration when 0
  float duration = 60.0f;         // s
  bool stop_when_arrived = true;  // end the run early once every agent has arrived
  std::uint64_t seed = 1;
  SchedulerKind scheduler = SchedulerKind::DoubleBuffer;
  PlanningKind planning = PlanningKind::Roadmap;  // used where the world has obstacles or walls
  ModelParams model;
  WorldSpec world;
  std::vector<GroupSpec> groups;
  // The view for rendering and LOD, in the Y-up world (converted from the
  // map coordinates of the file with core/ground.h); nullopt = an overview
  // chosen from the scene's extent (overview_camera).
  std::optional<Camera> camera;
  // How videos move that camera (camera.motion, camera.period): "fixed",
  // "orbit" or "flyover" (render/camera_path.h), one turn or pass per
  // period seconds of video; empty / 0 = the command's defaults.
  std::string camera_motion;
  float camera_period_s = 0.0f;
  // Where density, speed and flow are measured (the fundamental diagram
  // is drawn for the first area).
  MeasurementSpec measurement;
  OutputSpec outputs;
  std::int64_t total_agents() const;
  std::int64_t step_count() const;  // steps, or ceil(duration / dt)
};

// Limits checked before anything is allocated (bad or hostile input).
struct ScenarioLimits {
  std::int64_t max_agents = 20'000'000;
  std::int64_t max_steps = 100'000'000;
  std::int64_t max_vertices = 1'000'000;     // all polygons together
  std::int64_t max_obstacles = 1'000'000;    // polygons + circles + scattered
  std::int64_t max_waypoints = 1'000;        // per group
  std::int64_t max_grid_items = 64'000'000;  // obstacle cell registrations
  std::int32_t raster_resolution = 1024;     // cells per side of the reachability raster
  float max_extent = 1.0e6f;                 // m: coordinates beyond +-this are rejected
};

// A camera looking down on the map rectangle `extent` from the south-west at
// about 40 degrees, far enough to see all of it (Y-up world, core/ground.h).
Camera overview_camera(const Aabb& extent);

// Resizes group counts so they add up to `total` (largest remainder), keeping
// their proportions; throws Error when total < number of groups or <= 0, or
// when a group spawns at fixed points or enters at listed times (its count is
// the number of points or times).
void scale_agent_counts(ScenarioSpec& spec, std::int64_t total);

}  // namespace throng::sim
