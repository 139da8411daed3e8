// Metrics over the crowd: deterministic parallel reductions.
#include <algorithm>

#include "core/reduce.h"
#include "sim/crowd.h"
#include "sim/metrics.h"

namespace throng::sim {

namespace {
struct OverlapAcc {
  Index touching;
  Index pairs;
  float max_depth;
  float min_separation;
};
struct CombineOverlap {
  THRONG_HOST_DEVICE OverlapAcc operator()(const OverlapAcc& a, const OverlapAcc& b) const {
    return {a.touching + b.touching, a.pairs + b.pairs, a.max_depth > b.max_depth ? a.max_depth : b.max_depth,
            a.min_separation < b.min_separation ? a.min_separation : b.min_separation};
  }
};
struct OverlapOf {
  GridView bins;
  Span<const glm::vec2> p;
  Span<const float> r;
  Span<const std::uint8_t> flags;
  float tolerance;
  THRONG_HOST_DEVICE OverlapAcc operator()(Index i) const {
    OverlapAcc acc{0, 0, 0.0f, INFINITY};
    if ((flags[i] & kAgentActive) == 0) return acc;
    for_each_in_3x3(bins, p[i], [&](std::int32_t j) {
      if (j <= i || (flags[j] & kAgentActive) == 0) return;  // each pair once
      const float gap = length_of(p[i] - p[j]) - r[i] - r[j];
      acc.min_separation = gap < acc.min_separation ? gap : acc.min_separation;
      if (gap < 0.0f) ++acc.touching;
      if (-gap > tolerance) ++acc.pairs;
      if (-gap > acc.max_depth) acc.max_depth = -gap;
    });
    return acc;
  }
};

struct CountPair {
  Index count;
  double sum;
};
struct CombineCount {
  THRONG_HOST_DEVICE CountPair operator()(const CountPair& a, const CountPair& b) const { return {a.count + b.count, a.sum + b.sum}; }
};

struct AreaAcc {
  Index count;
  double along, magnitude;
};
struct CombineArea {
  THRONG_HOST_DEVICE AreaAcc operator()(const AreaAcc& a, const AreaAcc& b) const {
    return {a.count + b.count, a.along + b.along, a.magnitude + b.magnitude};
  }
};

struct Histogram {
  std::int64_t bins[kDensityBins];
};
struct CombineHistogram {
  THRONG_HOST_DEVICE Histogram operator()(const Histogram& a, const Histogram& b) const {
    Histogram h;
    for (int k = 0; k < kDensityBins; ++k) h.bins[k] = a.bins[k] + b.bins[k];
    return h;
  }
};
}  // namespace

OverlapStats measure_overlaps(Span<const glm::vec2> positions, Span<const float> radii, Span<const std::uint8_t> flags, float tolerance,
                              float reach) {
  AgentGrid grid(reach);
  grid.rebuild(positions, flags);
  const OverlapAcc acc = parallel_reduce("sim.metrics.overlaps", positions.size(), OverlapAcc{0, 0, 0.0f, INFINITY},
                                         OverlapOf{grid.view(), positions, radii, flags, tolerance}, CombineOverlap{});
  return {acc.touching, acc.pairs, acc.max_depth, acc.min_separation};
}

Index count_obstacle_penetrations(const World& world, Span<const glm::vec2> positions, Span<const float> radii,
                                  Span<const std::uint8_t> flags, float tolerance) {
  const WorldView w = world.view();
  return parallel_reduce(
      "sim.metrics.penetrations", positions.size(), Index{0},
      THRONG_LAMBDA(Index i)->Index {
        if ((flags[i] & kAgentActive) == 0) return 0;
        return disc_is_clear(w, positions[i], radii[i], tolerance) ? 0 : 1;
      },
      THRONG_LAMBDA(Index a, Index b)->Index { return a + b; });
}

AreaSample measure_area(Span<const glm::vec2> positions, Span<const glm::vec2> velocities, Span<const glm::vec2> goals,
                        Span<const std::uint8_t> flags, const Aabb& area) {
  const glm::vec2 lo = area.min, hi = area.max;
  const AreaAcc c = parallel_reduce(
      "sim.metrics.area", positions.size(), AreaAcc{0, 0.0, 0.0},
      THRONG_LAMBDA(Index i)->AreaAcc {
        const glm::vec2 p = positions[i];
        if ((flags[i] & kAgentActive) == 0 || p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y) return {0, 0.0, 0.0};
        const glm::vec2 v = velocities[i], to_goal = goals[i] - p;
        const float d = length_of(to_goal);
        // An agent standing on its goal has no desired direction: no advance.
        const float along = d > 1e-6f ? dot2(v, to_goal) / d : 0.0f;
        return {1, static_cast<double>(along), static_cast<double>(length_of(v))};
      },
      CombineArea{});
  AreaSample s;
  s.area = static_cast<double>(area.size().x) * area.size().y;
  s.agents = c.count;
  s.density = s.area > 0 ? static_cast<double>(c.count) / s.area : 0.0;
  s.mean_speed = c.count > 0 ? c.along / static_cast<double>(c.count) : 0.0;
  s.mean_speed_magnitude = c.count > 0 ? c.magnitude / static_cast<double>(c.count) : 0.0;
  s.flow = s.density * s.mean_speed;
  return s;
}

double mean_speed(Span<const glm::vec2> velocities, Span<const std::uint8_t> flags) {
  const CountPair c = parallel_reduce(
      "sim.metrics.speed", velocities.size(), CountPair{0, 0.0},
      THRONG_LAMBDA(Index i)->CountPair {
        if ((flags[i] & kAgentActive) == 0) return {0, 0.0};
        return {1, static_cast<double>(length_of(velocities[i]))};
      },
      CombineCount{});
  return c.count > 0 ? c.sum / static_cast<double>(c.count) : 0.0;
}

DensityHistogram density_histogram(Span<const glm::vec2> positions, Span<const std::uint8_t> flags, float cell, float bin_width) {
  AgentGrid grid(cell);
  grid.rebuild(positions, flags);
  const GridView g = grid.view();
  const float inv_area = 1.0f / (cell * cell);
  const Histogram h = parallel_reduce(
      "sim.metrics.density", positions.size(), Histogram{},
      THRONG_LAMBDA(Index i)->Histogram {
        Histogram one{};
        if ((flags[i] & kAgentActive) == 0) return one;
        const Index s = g.find(cell_coord(positions[i].x, cell), cell_coord(positions[i].y, cell));
        const float density = static_cast<float>(g.count[s]) * inv_area;
        int b = static_cast<int>(density / bin_width);
        b = b < kDensityBins - 1 ? b : kDensityBins - 1;
        one.bins[b] = 1;
        return one;
      },
      CombineHistogram{});
  DensityHistogram out;
  out.cell = cell;
  out.bin_width = bin_width;
  std::copy(h.bins, h.bins + kDensityBins, out.agents.begin());
  return out;
}

ArrivalStats arrival_stats(const std::vector<float>& arrival_times) {
  ArrivalStats s;
  s.total = static_cast<Index>(arrival_times.size());
  double sum = 0;
  for (float t : arrival_times) {
    if (t < 0) continue;
    if (s.arrived == 0 || t < s.min_time) s.min_time = t;
    if (s.arrived == 0 || t > s.max_time) s.max_time = t;
    sum += t;
    ++s.arrived;
  }
  s.mean_time = s.arrived > 0 ? sum / static_cast<double>(s.arrived) : 0.0;
  return s;
}

}  // namespace throng::sim
