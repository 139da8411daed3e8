// The path layer: the paper's Table 1 (matching N curves against every
// motion of the default state machine: 10 ... 1000 curves, 1 thread, all
// threads, and CUDA when usable), and the stages around it. A "curve" here
// is one character's planned path through a 60 x 40 m obstacle field (15 m
// or more between start and goal), resampled at the machine's spacing and
// cut into segments of k = 64 points; items/s counts (segment, motion) pairs.
#include <algorithm>
#include <vector>

#include "bench/registry.h"
#include "io/state_machine_yaml.h"
#include "motion/default_set.h"
#include "path/match.h"
#include "path/pipeline.h"
#include "path/planner.h"

namespace throng::bench {

namespace {

constexpr Index kMaxCurves = 1000;

struct Scene {
  path::StateMachine machine;
  path::Planner planner;
  std::vector<path::PathQuery> queries;
  std::vector<path::ResampledPath> paths;  // found paths, resampled
  std::vector<float> speeds;
};

// Built once, on first use, on the CPU.
const Scene& scene() {
  static const Scene s = [] {
    ScopedExecution cpu(Backend::Cpu, 0);
    Scene sc;
    sc.machine = path::StateMachine::build(io::default_state_machine_spec(), motion::default_skeleton());
    path::PlanOptions po;
    po.radius = 0.3f;
    sc.planner = path::Planner::build(path::random_obstacle_world({}), po);
    sc.queries = path::random_queries(sc.planner, 2 * kMaxCurves, 7);
    const std::vector<path::PlannedPath> planned = sc.planner.plan_all(sc.queries);
    path::ResampleOptions ro;
    ro.spacing = sc.machine.spacing();
    for (std::size_t i = 0; i < planned.size() && static_cast<Index>(sc.paths.size()) < kMaxCurves; ++i)
      if (planned[i].found()) {
        sc.paths.push_back(path::resample_path(planned[i].points, ro));
        sc.speeds.push_back(1.0f + 2.0f * static_cast<float>(i % 11) / 10.0f);
      }
    return sc;
  }();
  return s;
}

path::CurveSet curves_of(Index n) {
  const Scene& s = scene();
  const auto count = static_cast<std::size_t>(std::min<Index>(n, static_cast<Index>(s.paths.size())));
  return path::cut_paths(std::span<const path::ResampledPath>(s.paths.data(), count), s.machine,
                         std::span<const float>(s.speeds.data(), count));
}

void register_path(const Options& options) {
  const std::vector<Index> table1 = {10, 100, 200, 500, 1000};

  // Table 1: the grid of curves x motions and the best motion per segment.
  add(options, {"path/match_grid", table1,
                [](benchmark::State& state, Index n) {
                  const path::CurveSet cs = curves_of(n);
                  path::MatchGrid grid(scene().machine, cs);
                  for (auto _ : state) grid.match();
                  state.SetItemsProcessed(state.iterations() * static_cast<Index>(cs.curve_count()) * grid.motions());
                  state.counters["segments"] = cs.curve_count();
                  state.counters["motions"] = grid.motions();
                },
                true});

  // Past the paper: the dynamic program over the machine's transitions.
  add(options, {"path/match_dp", table1,
                [](benchmark::State& state, Index n) {
                  const path::CurveSet cs = curves_of(n);
                  path::MatchGrid grid(scene().machine, cs);
                  grid.match();
                  const std::vector<float> cost = grid.cost();
                  for (auto _ : state) benchmark::DoNotOptimize(path::dp_sequences(scene().machine, cs, cost));
                  state.SetItemsProcessed(state.iterations() * static_cast<Index>(cs.curve_count()) * grid.motions());
                }});

  // A* on the roadmap plus shortcuts and corner rounding, per query.
  add(options, {"path/plan", {100, 1000},
                [](benchmark::State& state, Index n) {
                  const Scene& s = scene();
                  const std::span<const path::PathQuery> q(s.queries.data(), static_cast<std::size_t>(n));
                  for (auto _ : state) benchmark::DoNotOptimize(s.planner.plan_all(q));
                  state.SetItemsProcessed(state.iterations() * n);
                }});

  // Voronoi roadmap of the 60 x 40 m field (N = obstacles).
  add(options, {"path/roadmap", {70},
                [](benchmark::State& state, Index n) {
                  path::RandomWorldOptions wo;
                  wo.obstacles = n;
                  const sim::World world = path::random_obstacle_world(wo);
                  path::PlanOptions po;
                  po.radius = 0.3f;
                  for (auto _ : state) benchmark::DoNotOptimize(path::Planner::build(world, po));
                  state.SetItemsProcessed(state.iterations() * n);
                },
                false, true});
}

}  // namespace

static const bool registered = register_suite("path", &register_path);

}  // namespace throng::bench
