// Metrics over the crowd: deterministic parallel reductions.
#include <algorithm>
#include <cfloat>
#include <cmath>

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
  float tolerance;
  Periodic periodic;
  THRONG_HOST_DEVICE OverlapAcc operator()(Index k) const {
    OverlapAcc acc{0, 0, 0.0f, INFINITY};
    const Index i = bins.items[k];  // (the grid holds the active agents only)
    for_each_in_3x3(bins, p[i], [&](std::int32_t j) {
      if (j <= i) return;  // each pair once
      const float gap = length_of(p[i] - periodic.near(p[j], p[i])) - r[i] - r[j];
      acc.min_separation = gap < acc.min_separation ? gap : acc.min_separation;
      if (gap < 0.0f) ++acc.touching;
      if (-gap > tolerance) ++acc.pairs;
      if (-gap > acc.max_depth) acc.max_depth = -gap;
    });
    return acc;
  }
};

// NaN fails every comparison and infinity exceeds FLT_MAX: one test for
// both that compiles the same for the host and CUDA.
THRONG_HOST_DEVICE inline bool is_finite(glm::vec2 v) { return fabsf(v.x) <= FLT_MAX && fabsf(v.y) <= FLT_MAX; }

struct CountPair {
  Index count;
  double sum;
};
struct CombineCount {
  THRONG_HOST_DEVICE CountPair operator()(const CountPair& a, const CountPair& b) const {
    return {a.count + b.count, a.sum + b.sum};
  }
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

OverlapStats measure_overlaps(Span<const glm::vec2> positions, Span<const float> radii, Span<const std::uint8_t> flags,
                              float tolerance, float reach, const Periodic& periodic) {
  AgentGrid grid(reach, periodic);
  grid.rebuild(positions, flags);
  // Agents in cell order (the grid's items): one after another they read
  // the same cells, whatever order the crowd lists them in. Counts, the
  // largest and the smallest do not depend on the order.
  const GridView bins = grid.view();
  const OverlapAcc acc = parallel_reduce("sim.metrics.overlaps", bins.items.size(), OverlapAcc{0, 0, 0.0f, INFINITY},
                                         OverlapOf{bins, positions, radii, tolerance, periodic}, CombineOverlap{});
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

Index count_non_finite(Span<const glm::vec2> positions, Span<const glm::vec2> velocities) {
  return parallel_reduce(
      "sim.metrics.non_finite", positions.size(), Index{0},
      THRONG_LAMBDA(Index i)->Index { return is_finite(positions[i]) && is_finite(velocities[i]) ? 0 : 1; },
      THRONG_LAMBDA(Index a, Index b)->Index { return a + b; });
}

AreaSample measure_area(Span<const glm::vec2> positions, Span<const glm::vec2> velocities, Span<const glm::vec2> goals,
                        Span<const std::uint8_t> flags, const Aabb& area) {
  const glm::vec2 lo = area.min, hi = area.max;
  const AreaAcc c = parallel_reduce(
      "sim.metrics.area", positions.size(), AreaAcc{0, 0.0, 0.0},
      THRONG_LAMBDA(Index i)->AreaAcc {
        const glm::vec2 p = positions[i];
        if ((flags[i] & kAgentActive) == 0 || p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y)
          return {0, 0.0, 0.0};
        const glm::vec2 v = velocities[i];
        return {1, static_cast<double>(speed_towards(v, p, goals[i])), static_cast<double>(length_of(v))};
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

namespace {
// The crossing part of a step, as the kernels fill it in.
struct CrossingRecord {
  double fraction;
  Index agent;
  std::int32_t line;
  std::int32_t direction;
};

// Whether agent i's step may cross a line: active before and after, and
// the step's box meets the lines' box (most agents are far from every line).
THRONG_HOST_DEVICE inline bool may_cross(Index i, Span<const glm::vec2> before, Span<const std::uint8_t> flags_before,
                                         Span<const glm::vec2> after, Span<const std::uint8_t> flags_after,
                                         glm::vec2 lo, glm::vec2 hi, bool wraps) {
  if ((flags_before[i] & kAgentActive) == 0 || (flags_after[i] & kAgentActive) == 0) return false;
  if (wraps) return true;  // (a step across the seam spans the area)
  const glm::vec2 p0 = before[i], p1 = after[i];
  return !((p0.x < lo.x && p1.x < lo.x) || (p0.x > hi.x && p1.x > hi.x) || (p0.y < lo.y && p1.y < lo.y) ||
           (p0.y > hi.y && p1.y > hi.y));
}
// The crossing of line (a, b) by the step from p0 to p1 (step_crossing);
// over a periodic area the step is the shorter one across the seam, seen
// from either end (a line near one side of the seam is crossed by the copy
// of the step on that side).
THRONG_HOST_DEVICE inline int crossing_of(glm::vec2 p0, glm::vec2 p1, glm::vec2 a, glm::vec2 b,
                                          const Periodic& periodic, double* s) {
  if (!periodic.wraps()) return step_crossing(p0, p1, a, b, s);
  const int d = step_crossing(periodic.near(p0, p1), p1, a, b, s);
  return d != 0 ? d : step_crossing(p0, periodic.near(p1, p0), a, b, s);
}
}  // namespace

std::vector<LineCrossing> line_crossings(Span<const glm::vec2> before, Span<const std::uint8_t> flags_before,
                                         Span<const glm::vec2> after, Span<const std::uint8_t> flags_after,
                                         Span<const Segment> lines, const Aabb& bounds, double t0, double t1,
                                         const Periodic& periodic) {
  const Index n = after.size();
  const bool wraps = periodic.wraps();
  if (n == 0 || lines.size() == 0 || bounds.empty()) return {};
  const glm::vec2 lo = bounds.min, hi = bounds.max;
  const Index line_count = lines.size();
  // Two passes so the list comes out in agent order whatever the threads:
  // count each agent's crossings, place them by a prefix sum, then write.
  Buffer<Index> offsets(n, current_memory());
  const Span<Index> count = offsets.span();
  parallel_for(
      "sim.metrics.line_crossings", n, THRONG_LAMBDA(Index i) {
        Index c = 0;
        if (may_cross(i, before, flags_before, after, flags_after, lo, hi, wraps)) {
          double s = 0;
          for (Index k = 0; k < line_count; ++k)
            c += crossing_of(before[i], after[i], lines[k].a, lines[k].b, periodic, &s) != 0 ? 1 : 0;
        }
        count[i] = c;
      });
  const Index total = exclusive_scan("sim.metrics.line_crossings", Span<const Index>(count), count);
  if (total == 0) return {};
  Buffer<CrossingRecord> records(total, current_memory());
  const Span<CrossingRecord> out = records.span();
  const Span<const Index> first = offsets.span();
  parallel_for(
      "sim.metrics.line_crossings", n, THRONG_LAMBDA(Index i) {
        if (!may_cross(i, before, flags_before, after, flags_after, lo, hi, wraps)) return;
        Index at = first[i];
        for (Index k = 0; k < line_count; ++k) {
          double s = 0;
          const int d = crossing_of(before[i], after[i], lines[k].a, lines[k].b, periodic, &s);
          if (d != 0) out[at++] = CrossingRecord{s, i, static_cast<std::int32_t>(k), d};
        }
      });
  std::vector<LineCrossing> crossings;
  crossings.reserve(static_cast<std::size_t>(total));
  for (const CrossingRecord& r : records.to_vector())
    crossings.push_back({t0 + r.fraction * (t1 - t0), r.agent, r.line, r.direction});
  return crossings;
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

DensityHistogram density_histogram(Span<const glm::vec2> positions, Span<const std::uint8_t> flags, float cell,
                                   float bin_width, const Periodic& periodic) {
  const bool tiles = (periodic.period.x == 0.0f || periodic.period.x >= 4.0f * cell) &&
                     (periodic.period.y == 0.0f || periodic.period.y >= 4.0f * cell);
  AgentGrid grid(cell, tiles ? periodic : Periodic{});
  grid.rebuild(positions, flags);
  const GridView g = grid.view();
  const float inv_area = 1.0f / (g.cell_size * g.cell_size_y);
  // Every agent of a cell sees the cell's density: each slot adds its count
  // to its density's bin at once (empty slots count 0), with no lookup per
  // agent.
  const Histogram h = parallel_reduce(
      "sim.metrics.density", g.capacity(), Histogram{},
      THRONG_LAMBDA(Index s)->Histogram {
        Histogram one{};
        const std::int32_t agents = g.count[s];
        if (agents == 0) return one;
        const float density = static_cast<float>(agents) * inv_area;
        int b = static_cast<int>(density / bin_width);
        b = b < kDensityBins - 1 ? b : kDensityBins - 1;
        one.bins[b] = agents;
        return one;
      },
      CombineHistogram{});
  DensityHistogram out;
  out.cell = cell;
  out.bin_width = bin_width;
  std::copy(h.bins, h.bins + kDensityBins, out.agents.begin());
  return out;
}

LineFlow line_flow(std::span<const double> times, double width) {
  LineFlow f;
  f.crossings = static_cast<Index>(times.size());
  if (times.empty()) return f;
  f.first_time = times.front();
  f.last_time = times.back();
  f.timed = times.size() >= 2 && f.last_time > f.first_time;
  if (!f.timed) return f;
  f.flow = static_cast<double>(times.size() - 1) / (f.last_time - f.first_time);
  f.specific_flow = width > 0 ? f.flow / width : 0.0;
  const std::size_t n = times.size();
  const auto from = static_cast<std::size_t>(kSteadyFlowFrom * static_cast<double>(n)),
             to = static_cast<std::size_t>(kSteadyFlowTo * static_cast<double>(n));
  f.steady_flow =
      n >= 10 && times[to] > times[from] ? static_cast<double>(to - from) / (times[to] - times[from]) : f.flow;
  f.steady_specific_flow = width > 0 ? f.steady_flow / width : 0.0;
  return f;
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
