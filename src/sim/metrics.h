// Crowd metrics as library functions (tests and stats.json use them): pair
// overlaps, obstacle penetrations, arrivals, speed and density in a
// measurement area (the fundamental diagram, classic and Voronoi), crossings
// of measurement lines (flow by the N-t curve), a local density histogram,
// agents stuck at rest in free space.
// Spans in current_memory() unless said otherwise; every reduction is
// deterministic.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <glm/vec2.hpp>
#include <span>
#include <vector>

#include "core/span.h"
#include "sim/agent_grid.h"
#include "sim/geometry.h"
#include "sim/world.h"

namespace throng::sim {

class Simulation;

struct OverlapStats {
  Index touching = 0;      // pairs overlapping at all (discs closer than the sum of radii)
  Index pairs = 0;         // pairs overlapping by more than the tolerance
  float max_depth = 0.0f;  // deepest overlap, m (0 when none)
  float min_separation =
      INFINITY;  // smallest gap between discs, m (negative = overlap); inf when no two agents are within the bins' reach
};
// Active agents only; `reach` (>= twice the largest radius) sizes the bins.
// Over a periodic area, pairs across the seam count too.
OverlapStats measure_overlaps(Span<const glm::vec2> positions, Span<const float> radii, Span<const std::uint8_t> flags,
                              float tolerance, float reach, const Periodic& periodic = {});

// The deepest pair overlap the steering models keep to, m: a third of the
// 0.25 m radius (docs/simulation.md, "Acceptance", where the acceptance
// tests hold every step to the same 8 cm). The soak checks hold a long run to it.
inline constexpr float kOverlapBound = 0.08f;

// Agents (active or not) whose position or velocity is NaN or infinite.
Index count_non_finite(Span<const glm::vec2> positions, Span<const glm::vec2> velocities);

// Active agents whose disc enters an obstacle by more than `tolerance` (or
// whose centre is outside free space).
Index count_obstacle_penetrations(const World& world, Span<const glm::vec2> positions, Span<const float> radii,
                                  Span<const std::uint8_t> flags, float tolerance);

struct ArrivalStats {
  Index arrived = 0;
  Index total = 0;
  double mean_time = 0;  // s, over arrived agents
  double min_time = 0;
  double max_time = 0;
};
// Host values (arrival time < 0 = not arrived).
ArrivalStats arrival_stats(const std::vector<float>& arrival_times);

// Fundamental-diagram sample: agents inside a rectangle. Speed is measured
// along each agent's desired direction (towards the end of its current leg,
// `goals`): agents that swirl sideways in a jam move fast and advance slowly,
// and only the advance carries a flow. |v| is kept apart, labelled.
struct AreaSample {
  double area = 0;  // m^2
  Index agents = 0;
  double density = 0;               // agents / m^2
  double mean_speed = 0;            // m/s along the desired direction (0 when empty; negative = backwards)
  double mean_speed_magnitude = 0;  // m/s, mean |v| (0 when empty)
  double flow = 0;                  // specific flow: density * mean_speed, 1/(m s)
};
AreaSample measure_area(Span<const glm::vec2> positions, Span<const glm::vec2> velocities, Span<const glm::vec2> goals,
                        Span<const std::uint8_t> flags, const Aabb& area);

// Speed of an agent at p along the way to its goal (0 when it stands on it:
// no desired direction, no advance).
THRONG_HOST_DEVICE inline float speed_towards(glm::vec2 v, glm::vec2 p, glm::vec2 goal) {
  const glm::vec2 to_goal = goal - p;
  const float d = length_of(to_goal);
  return d > 1e-6f ? dot2(v, to_goal) / d : 0.0f;
}

// Voronoi density and speed in a rectangle (Steffen & Seyfried 2010; method
// D of Liao et al. 2014): every point of the area carries the density
// 1/|cell| and the speed of the agent whose Voronoi cell holds it, averaged
// over the area:
//   density = sum_i |cell_i n A| / |cell_i| / |A|,  speed = sum_i v_i |cell_i n A| / |A|.
// Cells are cut to a disc of radius `cutoff` around their agent (a regular
// polygon of kVoronoiDiscVertices corners inscribed in the circle), so a
// lone agent's cell stays finite; where the cells leave part of the area
// uncovered that part counts as empty (density and speed 0 there). Walls do
// not cut cells. Host spans; only active agents count.
inline constexpr int kVoronoiDiscVertices = 64;
struct VoronoiSample {
  double density = 0;          // agents / m^2
  double speed = 0;            // m/s along the desired direction
  double speed_magnitude = 0;  // m/s, |v|
  double covered = 0;          // m^2 of the area inside some agent's cell
};
VoronoiSample measure_area_voronoi(std::span<const glm::vec2> positions, std::span<const glm::vec2> velocities,
                                   std::span<const glm::vec2> goals, std::span<const std::uint8_t> flags,
                                   const Aabb& area, float cutoff, const Periodic& periodic = {});

// The Voronoi cell of every point among `points` (host), cut to the disc of
// radius `cutoff`, as a convex polygon counter-clockwise; the building block
// of measure_area_voronoi, for tests and plots.
using ConvexPolygon = std::vector<glm::dvec2>;
std::vector<ConvexPolygon> voronoi_cells(std::span<const glm::vec2> points, float cutoff);
double polygon_area(const ConvexPolygon& polygon);
// The part of a convex polygon inside the rectangle.
ConvexPolygon clip_to_rect(const ConvexPolygon& polygon, const Aabb& rect);

// Crossings of measurement lines by agents, for flow by the N-t curve
// (method A of Liao et al. 2014). An agent crosses line (a, b) during a step
// when its straight move from `before` to `after` changes side and passes
// between a and b. The side is the sign of cross(b - a, p - a): positive
// (left of a -> b) or not (right, or on the line), so an agent that stops on
// the line and walks on is counted once. direction +1: right to left (the
// positive direction), -1: left to right.
struct LineCrossing {
  double time = 0;  // s, interpolated along the step
  Index agent = 0;
  std::int32_t line = 0;
  std::int32_t direction = 0;
};
// Where the step p0 -> p1 crosses a -> b: the direction, and in *fraction
// the part of the step done at the crossing; 0 when it does not cross.
THRONG_HOST_DEVICE inline int step_crossing(glm::vec2 p0, glm::vec2 p1, glm::vec2 a, glm::vec2 b, double* fraction) {
  // In double: the sides of points close to the line keep their sign.
  const double ex = static_cast<double>(b.x) - a.x, ey = static_cast<double>(b.y) - a.y;
  const double d0 = ex * (static_cast<double>(p0.y) - a.y) - ey * (static_cast<double>(p0.x) - a.x);
  const double d1 = ex * (static_cast<double>(p1.y) - a.y) - ey * (static_cast<double>(p1.x) - a.x);
  const bool left0 = d0 > 0.0, left1 = d1 > 0.0;
  if (left0 == left1) return 0;
  const double s = d0 / (d0 - d1);  // d0 and d1 differ: one is > 0, the other <= 0
  const double qx = p0.x + s * (static_cast<double>(p1.x) - p0.x), qy = p0.y + s * (static_cast<double>(p1.y) - p0.y);
  const double u = ((qx - a.x) * ex + (qy - a.y) * ey) / (ex * ex + ey * ey);
  if (u < 0.0 || u > 1.0) return 0;
  *fraction = s;
  return left1 ? 1 : -1;
}
// Crossings by agents active both before and after a step from time t0 to
// t1, ordered by agent, then line: the same list for any thread count or
// backend. `lines` in current_memory(); `bounds` holds every line (agents
// whose step stays outside it are skipped).
std::vector<LineCrossing> line_crossings(Span<const glm::vec2> before, Span<const std::uint8_t> flags_before,
                                         Span<const glm::vec2> after, Span<const std::uint8_t> flags_after,
                                         Span<const Segment> lines, const Aabb& bounds, double t0, double t1,
                                         const Periodic& periodic = {});

// Flow through a line by the N-t curve (method A of Liao et al. 2014): of
// `times`, one direction's crossing times in increasing order, the mean flow
// between the first and the last crossing, (N - 1) / (t_N - t_1), and per
// metre of the line's `width`. Not timed (flows 0) with fewer than two
// crossings or all at one instant.
//
// The steady flow leaves out the build-up and the emptying: the slope of
// the N-t curve between the crossings at 10% and 90% of all of them (as
// JuPedSim's calibration to the wide-bottleneck experiments of Liao et al.
// 2014 measures it). A run of few agents per metre of door (below about
// 115 / m, Liao et al. 2016, Physica A 461) has no long steady phase, and
// its whole-run flow falls short of the laboratory's. Equal to the whole
// run's flow below 10 crossings.
inline constexpr double kSteadyFlowFrom = 0.1, kSteadyFlowTo = 0.9;
struct LineFlow {
  Index crossings = 0;
  double first_time = 0, last_time = 0;  // s (0 when none)
  bool timed = false;
  double flow = 0;           // persons / s
  double specific_flow = 0;  // persons / (m s)
  double steady_flow = 0;    // persons / s, 10-90% of the crossings
  double steady_specific_flow = 0;
};
LineFlow line_flow(std::span<const double> times, double width);

// Lane order of a counterflow along `axis` (unit vector), after Rex and
// Loewen (2007, Phys. Rev. E 75, 051402): for each active agent j, the
// active agents within `band` of its line along the axis (|lateral| < band)
// and within `reach` along it are counted as walking the same way (n_s) or
// the other way (n_o), by the sign of (goal - position) . axis;
// phi_j = ((n_s - n_o) / (n_s + n_o))^2, and the order is the mean of phi_j
// over agents with at least one such neighbour. 1: every agent sees only its
// own direction in its lane (lanes); a well-mixed crowd gives about
// 1 / (neighbours in the band). Host values; O(N^2), for measurement areas
// of a few thousand agents.
struct LaneOrder {
  double order = 0;   // mean phi_j (0 when no agent has neighbours in its band)
  Index counted = 0;  // agents with at least one neighbour in their band
};
// Over a periodic area, neighbours across the seam count at their nearest copy.
LaneOrder lane_order(const std::vector<glm::vec2>& positions, const std::vector<glm::vec2>& goals,
                     const std::vector<std::uint8_t>& flags, glm::vec2 axis, float band, float reach,
                     const Periodic& periodic = {});

// Mean speed of active agents.
double mean_speed(Span<const glm::vec2> velocities, Span<const std::uint8_t> flags);

// How many agents stand at each local density: density of an agent = agents
// in its square cell of side `cell` / cell^2; bins of `bin_width` agents/m^2,
// the last one open-ended. Over a periodic area (at least four cells along
// each wrapping axis) the cells tile the period, the one by the seam whole.
inline constexpr int kDensityBins = 16;
struct DensityHistogram {
  float cell = 2.0f;
  float bin_width = 0.5f;
  std::array<std::int64_t, kDensityBins> agents{};
};
DensityHistogram density_histogram(Span<const glm::vec2> positions, Span<const std::uint8_t> flags, float cell = 2.0f,
                                   float bin_width = 0.5f, const Periodic& periodic = {});

// Stuck agents. An agent is stuck when, for more than `threshold_s` of
// simulated time in a row, it is active, still steering (not kAgentStopped),
// at rest (|v| below `speed_below`) and the way ahead of it is free: the
// probe, a disc of the agent's radius r centred at p + (r + gap) * unit(goal
// - p) (goal: the end of its current leg), overlaps no other active agent's
// disc and enters no obstacle (disc_is_clear with no tolerance). An agent
// waiting in a queue has someone in its probe and is not stuck; one frozen
// in free space (forces that cancel, a wall corner beside a free way to its
// goal) is. An agent standing on its goal has no way ahead and is not
// counted. Time at rest is counted in whole steps: with dt 0.1 s an agent is
// stuck from its 51st step in a row (5.1 s > 5 s).
struct StuckOptions {
  double threshold_s = 5.0;
  double speed_below = 0.1;  // m/s
  double gap = 0.3;          // m from the agent's centre to the near edge of the probe
};
inline constexpr std::size_t kStuckExamples = 10;
struct StuckExample {
  Index agent = 0;
  double time = 0;       // s, when it became stuck the first time
  glm::vec2 position{};  // where
};
struct StuckStats {
  Index agents = 0;                    // distinct agents ever stuck
  Index now = 0;                       // stuck at the last update
  Index max_at_once = 0;               // most stuck at one update
  double first_time = -1;              // s, when the first became stuck; -1 while none has
  std::vector<StuckExample> examples;  // the first kStuckExamples to become stuck, by time, then agent
};
// Follows the crowd step by step: update() once after every step. Per-agent
// counters in current_memory(), updated by parallel_for: the same figures
// for any thread count or backend. Agents added between updates (a growing
// crowd) start with no time at rest.
class StuckTracker {
 public:
  explicit StuckTracker(StuckOptions options = {}) : options_(options) {}
  // The step of length dt that ended at `time`. Spans in current_memory();
  // `reach` (>= twice the largest radius) sizes the bins of the probe.
  void update(const World& world, Span<const glm::vec2> positions, Span<const glm::vec2> velocities,
              Span<const float> radii, Span<const glm::vec2> goals, Span<const std::uint8_t> flags, float reach,
              double time, double dt);
  // The simulation's last step.
  void update(const Simulation& sim);
  const StuckOptions& options() const { return options_; }
  const StuckStats& stats() const { return stats_; }
  // Steps in a row each agent has been at rest with its way free (host copy).
  std::vector<std::int32_t> rest_steps() const { return rest_.to_vector(); }
  // Steps in a row at rest that make an agent stuck: the fewest whose time
  // exceeds threshold_s.
  std::int32_t threshold_steps(double dt) const;

 private:
  StuckOptions options_;
  AgentGrid bins_;
  Buffer<std::int32_t> rest_;   // steps in a row at rest with the way free
  Buffer<std::uint8_t> state_;  // kStuck* bits (metrics_stuck.cpp)
  StuckStats stats_;
};

}  // namespace throng::sim
