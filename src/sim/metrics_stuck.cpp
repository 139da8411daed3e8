// Stuck agents (metrics.h): per-agent counters of steps at rest with the way
// ahead free, updated every step by parallel_for.
#include <cmath>

#include "core/reduce.h"
#include "sim/crowd.h"
#include "sim/metrics.h"
#include "sim/simulation.h"

namespace throng::sim {

namespace {
// Bits of StuckTracker::state_.
constexpr std::uint8_t kStuckNow = 1;    // stuck after this update
constexpr std::uint8_t kStuckEver = 2;   // stuck at some update so far
constexpr std::uint8_t kStuckFirst = 4;  // stuck for the first time at this update

// Agent i is at rest with nothing in its probe (see StuckOptions).
struct AtRestInFreeSpace {
  GridView bins;
  WorldView world;
  Span<const glm::vec2> p, v;
  Span<const float> r;
  Span<const glm::vec2> goal;
  Span<const std::uint8_t> flags;
  float speed_below, gap;
  Periodic periodic;
  THRONG_HOST_DEVICE bool operator()(Index i) const {
    const std::uint8_t f = flags[i];
    if ((f & kAgentActive) == 0 || (f & (kAgentStopped | kAgentWaiting)) != 0) return false;
    if (!(length2(v[i]) < speed_below * speed_below)) return false;
    const glm::vec2 to_goal = goal[i] - p[i];
    const float d = length_of(to_goal);
    if (!(d > 1e-6f)) return false;  // on its goal: no way ahead to be free
    const float ri = r[i];
    const glm::vec2 probe = p[i] + ((ri + gap) / d) * to_goal;
    if (!disc_is_clear(world, probe, ri, 0.0f)) return false;
    bool free = true;
    for_each_in_3x3(bins, probe, [&](std::int32_t j) {
      if (j == i || (flags[j] & kAgentActive) == 0) return;
      const float reach = ri + r[j];
      if (length2(periodic.near(p[j], probe) - probe) < reach * reach) free = false;
    });
    return free;
  }
};

struct StuckCounts {
  Index now, first;
};
struct CombineStuck {
  THRONG_HOST_DEVICE StuckCounts operator()(const StuckCounts& a, const StuckCounts& b) const {
    return {a.now + b.now, a.first + b.first};
  }
};

// Copies `old` into the front of a buffer of n elements, zeros after it.
template <class T>
Buffer<T> grown(const Buffer<T>& old, Index n) {
  std::vector<T> h = old.to_vector();
  h.resize(static_cast<std::size_t>(n), T{});
  return Buffer<T>(std::span<const T>(h), current_memory());
}
}  // namespace

std::int32_t StuckTracker::threshold_steps(double dt) const {
  // The fewest steps whose time exceeds the threshold; the small tolerance
  // keeps 5 s / 0.1 s at 50 steps (not 49.99...) so that 50 steps are not more.
  return static_cast<std::int32_t>(std::floor(options_.threshold_s / dt + 1e-6)) + 1;
}

void StuckTracker::update(const World& world, Span<const glm::vec2> positions, Span<const glm::vec2> velocities,
                          Span<const float> radii, Span<const glm::vec2> goals, Span<const std::uint8_t> flags,
                          float reach, double time, double dt) {
  const Index n = positions.size();
  if (rest_.size() != n) {
    rest_ = grown(rest_, n);
    state_ = grown(state_, n);
  }
  if (bins_.cell_size() != reach || bins_.periodic().period != world.periodic().period)
    bins_ = AgentGrid(reach, world.periodic());
  bins_.rebuild(positions, flags);
  const AtRestInFreeSpace at_rest{bins_.view(),
                                  world.view(),
                                  positions,
                                  velocities,
                                  radii,
                                  goals,
                                  flags,
                                  static_cast<float>(options_.speed_below),
                                  static_cast<float>(options_.gap),
                                  world.periodic()};
  const std::int32_t threshold = threshold_steps(dt);
  const Span<std::int32_t> rest = rest_.span();
  const Span<std::uint8_t> state = state_.span();
  parallel_for(
      "sim.metrics.stuck", n, THRONG_LAMBDA(Index i) {
        const std::int32_t steps = at_rest(i) ? rest[i] + 1 : 0;
        rest[i] = steps;
        const std::uint8_t was = state[i];
        const bool stuck = steps >= threshold;
        std::uint8_t s = was & kStuckEver;
        if (stuck) s |= kStuckNow | kStuckEver;
        if (stuck && (was & kStuckEver) == 0) s |= kStuckFirst;
        state[i] = s;
      });
  const Span<const std::uint8_t> done = state_.span();
  const StuckCounts c = parallel_reduce(
      "sim.metrics.stuck", n, StuckCounts{0, 0},
      THRONG_LAMBDA(Index i)->StuckCounts {
        return {(done[i] & kStuckNow) != 0 ? 1 : 0, (done[i] & kStuckFirst) != 0 ? 1 : 0};
      },
      CombineStuck{});
  stats_.now = c.now;
  stats_.max_at_once = c.now > stats_.max_at_once ? c.now : stats_.max_at_once;
  if (c.first == 0) return;
  if (stats_.agents == 0) stats_.first_time = time;
  stats_.agents += c.first;
  if (stats_.examples.size() >= kStuckExamples) return;
  // Rare (agents become stuck once): the host copy is paid only then.
  const std::vector<std::uint8_t> s = state_.to_vector();
  std::vector<glm::vec2> p(static_cast<std::size_t>(n));
  copy_to_host(positions, std::span<glm::vec2>(p));
  for (std::size_t i = 0; i < s.size() && stats_.examples.size() < kStuckExamples; ++i)
    if ((s[i] & kStuckFirst) != 0) stats_.examples.push_back({static_cast<Index>(i), time, p[i]});
}

void StuckTracker::update(const Simulation& sim) {
  const CrowdState& c = sim.crowd();
  update(sim.world(), c.position.span(), c.velocity.span(), c.radius.span(), c.goal.span(), c.flags.span(),
         sim.contact_cell(), sim.time(), static_cast<double>(sim.spec().dt));
}

}  // namespace throng::sim
