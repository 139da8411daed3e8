// The path layer: the paper's Table 1 (matching N curves against every
// motion of the default state machine: 10 ... 1000 curves, 1 thread, all
// threads, and CUDA when usable), and the stages around it. A "curve" here
// is one character's planned path through a 60 x 40 m obstacle field (15 m
// or more between start and goal), resampled at the machine's spacing and
// cut into segments of k = 64 points; items/s counts (segment, motion) pairs.
#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench/registry.h"
#include "core/exec.h"
#include "io/scenario_yaml.h"
#include "io/state_machine_yaml.h"
#include "motion/default_set.h"
#include "path/match.h"
#include "path/pipeline.h"
#include "path/planner.h"
#include "path/route_planner.h"
#include "sim/crowd.h"

namespace throng::bench {

namespace {

constexpr Index kMaxCurves = 1000;

struct Scene {
  path::MotionGraph machine;
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
    sc.machine = path::MotionGraph::build(io::default_state_machine_spec(), motion::default_skeleton());
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

// The routes of `throng run` (path::RoadmapRoutePlanner): n agents' start
// and goal points in a world, with the planner's free space and roadmap
// already built (the "path/roadmap" row's cost), so the rows time the
// queries: a straight-line check per agent, then A* and shortcuts for the
// blocked ones. Worlds: the 60 x 40 m field of the rows above (random
// (start, goal) pairs 15 m or more apart: nearly all routed), the built-in
// maze (every agent routed through the walls) and the built-in crossing
// (every straight line clear: what planning adds where it is not needed).
struct RouteScene {
  sim::World world;
  std::vector<glm::vec2> starts, goals;
  float radius = 0.25f;
  path::RoadmapRoutePlanner planner;
};

std::unique_ptr<RouteScene> builtin_route_scene(const char* name, Index n) {
  auto scene = std::make_unique<RouteScene>();
  io::LoadedScenario l = io::load_builtin_scenario(name);
  sim::scale_agent_counts(l.spec, n);
  scene->world = sim::World::build(l.spec.world, l.spec.model.query_radius());
  const sim::CrowdHost crowd = sim::spawn_crowd(l.spec, scene->world);
  scene->starts = crowd.position;
  for (std::size_t i = 0; i < crowd.position.size(); ++i)
    scene->goals.push_back(crowd.waypoints[static_cast<std::size_t>(crowd.waypoint_begin[i] + crowd.waypoint_goal[i])]);
  scene->radius = l.spec.groups.front().radius;
  return scene;
}

std::unique_ptr<RouteScene> field_route_scene(Index n) {
  auto scene = std::make_unique<RouteScene>();
  scene->world = path::random_obstacle_world({});
  path::PlanOptions po;
  po.radius = scene->radius;
  const path::Planner planner = path::Planner::build(scene->world, po);
  for (const path::PathQuery& q : path::random_queries(planner, n, 11)) {
    scene->starts.push_back(q.start);
    scene->goals.push_back(q.goal);
  }
  return scene;
}

const RouteScene& route_scene(const std::string& name, Index n) {
  static std::map<std::pair<std::string, Index>, std::unique_ptr<RouteScene>> cache;
  auto& slot = cache[{name, n}];
  if (!slot) {
    ScopedExecution cpu(Backend::Cpu, 0);
    slot = name == "field" ? field_route_scene(n) : builtin_route_scene(name.c_str(), n);
    slot->planner.plan(slot->world, slot->starts, slot->goals, slot->radius);  // builds the free space and roadmap
  }
  return *slot;
}

Body route_plan(const char* scene_name) {
  return [scene_name](benchmark::State& state, Index n) {
    const RouteScene& s = route_scene(scene_name, n);
    for (auto _ : state) benchmark::DoNotOptimize(s.planner.plan(s.world, s.starts, s.goals, s.radius));
    state.SetItemsProcessed(state.iterations() * n);
    const path::RoutePlannerStats st = s.planner.stats();
    state.counters["routed_fraction"] =
        static_cast<double>(st.planned) / static_cast<double>(std::max<std::int64_t>(1, st.queries));
  };
}

void register_path(const Options& options) {
  const std::vector<Index> table1 = {10, 100, 200, 500, 1000};

  // Table 1: the grid of curves x motions and the best motion per segment.
  add(options, {"path/match_grid", table1,
                [](benchmark::State& state, Index n) {
                  const path::CurveSet cs = curves_of(n);
                  path::MatchGrid grid(scene().machine, cs);
                  for (auto _ : state) {
                    grid.match();
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * static_cast<Index>(cs.curve_count()) * grid.motions());
                  state.counters["segments"] = cs.curve_count();
                  state.counters["motions"] = grid.motions();
                },
                true});

  // Past the paper: the dynamic program over the machine's transitions.
  add(options, {"path/match_dp", table1, [](benchmark::State& state, Index n) {
                  const path::CurveSet cs = curves_of(n);
                  path::MatchGrid grid(scene().machine, cs);
                  grid.match();
                  const std::vector<float> cost = grid.cost();
                  for (auto _ : state) benchmark::DoNotOptimize(path::dp_sequences(scene().machine, cs, cost));
                  state.SetItemsProcessed(state.iterations() * static_cast<Index>(cs.curve_count()) * grid.motions());
                }});

  // A* on the roadmap plus shortcuts and corner rounding, per query.
  add(options, {"path/plan", {100, 1000}, [](benchmark::State& state, Index n) {
                  const Scene& s = scene();
                  const std::span<const path::PathQuery> q(s.queries.data(), static_cast<std::size_t>(n));
                  for (auto _ : state) benchmark::DoNotOptimize(s.planner.plan_all(q));
                  state.SetItemsProcessed(state.iterations() * n);
                }});

  // Voronoi roadmap of the 60 x 40 m field (N = obstacles).
  add(options, {"path/roadmap",
                {70},
                [](benchmark::State& state, Index n) {
                  path::RandomWorldOptions wo;
                  wo.obstacles = n;
                  const sim::World world = path::random_obstacle_world(wo);
                  path::PlanOptions po;
                  po.radius = 0.3f;
                  for (auto _ : state) benchmark::DoNotOptimize(path::Planner::build(world, po));
                  state.SetItemsProcessed(state.iterations() * n);
                },
                false,
                true});

  // Set-up of a walkable square 2n m across holding one 1 x 10 m wall: the
  // world index, the free space, its roadmap and routes round the wall for
  // ten agents. The cost must follow what the world holds, not n.
  add(options, {"path/huge_world_setup",
                {1000, 1000000},
                [](benchmark::State& state, Index n) {
                  const auto h = static_cast<float>(n);
                  sim::WorldSpec spec;
                  spec.has_walkable = true;
                  spec.walkable.outer = sim::rect_ring({-h, -h}, {h, h});
                  spec.polygons.push_back({sim::rect_ring({0, -5}, {1, 5}), {}});
                  std::vector<glm::vec2> starts, goals;
                  for (int k = 0; k < 10; ++k) {
                    starts.emplace_back(-8.0f, -2.0f + 0.4f * static_cast<float>(k));
                    goals.emplace_back(10.0f, -2.0f + 0.4f * static_cast<float>(k));
                  }
                  for (auto _ : state) {
                    const sim::World world = sim::World::build(spec, 4.0f);
                    const path::RoadmapRoutePlanner planner;
                    benchmark::DoNotOptimize(planner.plan(world, starts, goals, 0.25f));
                  }
                  state.SetItemsProcessed(state.iterations());
                },
                false,
                true});

  // Routes for n agents (see RouteScene).
  add(options, {"path/route_plan/field", {1000, 10000}, route_plan("field")});
  add(options, {"path/route_plan/maze", {100}, route_plan("maze")});
  add(options, {"path/route_plan/crossing", {10000}, route_plan("crossing")});
  add(options, {"path/route_plan/plaza", {1000, 10000}, route_plan("plaza")});
}

}  // namespace

static const bool registered = register_suite("path", &register_path);

}  // namespace throng::bench
