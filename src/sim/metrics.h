// Crowd metrics as library functions (tests and stats.json use them): pair
// overlaps, obstacle penetrations, arrivals, speed and density in a
// measurement area (the fundamental diagram), a local density histogram.
// Spans in current_memory(); every reduction is deterministic.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/span.h"
#include "sim/geometry.h"
#include "sim/world.h"

namespace throng::sim {

struct OverlapStats {
  Index touching = 0;         // pairs overlapping at all (discs closer than the sum of radii)
  Index pairs = 0;            // pairs overlapping by more than the tolerance
  float max_depth = 0.0f;     // deepest overlap, m (0 when none)
  float min_separation = INFINITY;  // smallest gap between discs, m (negative = overlap); inf when no two agents are within the bins' reach
};
// Active agents only; `reach` (>= twice the largest radius) sizes the bins.
OverlapStats measure_overlaps(Span<const glm::vec2> positions, Span<const float> radii, Span<const std::uint8_t> flags, float tolerance,
                              float reach);

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
  double area = 0;                  // m^2
  Index agents = 0;
  double density = 0;               // agents / m^2
  double mean_speed = 0;            // m/s along the desired direction (0 when empty; negative = backwards)
  double mean_speed_magnitude = 0;  // m/s, mean |v| (0 when empty)
  double flow = 0;                  // specific flow: density * mean_speed, 1/(m s)
};
AreaSample measure_area(Span<const glm::vec2> positions, Span<const glm::vec2> velocities, Span<const glm::vec2> goals,
                        Span<const std::uint8_t> flags, const Aabb& area);

// Mean speed of active agents.
double mean_speed(Span<const glm::vec2> velocities, Span<const std::uint8_t> flags);

// How many agents stand at each local density: density of an agent = agents
// in its square cell of side `cell` / cell^2; bins of `bin_width` agents/m^2,
// the last one open-ended.
inline constexpr int kDensityBins = 16;
struct DensityHistogram {
  float cell = 2.0f;
  float bin_width = 0.5f;
  std::array<std::int64_t, kDensityBins> agents{};
};
DensityHistogram density_histogram(Span<const glm::vec2> positions, Span<const std::uint8_t> flags, float cell = 2.0f, float bin_width = 0.5f);

}  // namespace throng::sim
