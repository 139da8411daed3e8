// throng match PATHS.yaml | --random N: the path layer end to end. Paths
// (given, or planned on the Voronoi roadmap of an obstacle world) become C1
// splines resampled at the state machine's spacing, cut into curves, matched
// against every motion segment in parallel, sequenced greedily (the paper)
// and by dynamic programming over the machine's transitions, and played back
// as one clip per character. Prints a summary and writes match.json.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.h"
#include "core/error.h"
#include "core/exec.h"
#include "core/random.h"
#include "io/bvh_writer.h"
#include "io/paths_yaml.h"
#include "io/run_outputs.h"
#include "io/state_machine_yaml.h"
#include "motion/default_set.h"
#include "path/pipeline.h"
#include "path/planner.h"

namespace throng::app {

namespace {

struct MatchArgs {
  std::string file;
  std::int64_t random = 0;
  std::uint64_t seed = 1;
  std::string machine;
  std::string out = "out/match";
  std::int32_t bvh = 0;
  float radius = 0.3f;
};

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json stats_json(const path::SequenceStats& s) {
  return {{"path_error_m", s.path_error},
          {"illegal_transitions", s.illegal},
          {"paths_with_illegal", s.paths_with_illegal},
          {"total_cost_of_legal", s.total_cost}};
}

// Refuses a paths file together with --random (or neither) and values out of range.
void check_match_args(const MatchArgs& a) {
  if (a.file.empty() == (a.random == 0)) throw Error("give a paths file or --random N (not both)", at_field("match"));
  if (a.random < 0 || a.random > 1'000'000) throw Error("must be in [1, 1000000]", at_field("--random"));
  if (!(a.radius > 0 && a.radius < 5)) throw Error("must be in (0, 5) m", at_field("--radius"));
  if (a.bvh < 0) throw Error("must be >= 0", at_field("--bvh"));
}

// Roadmap: the planner of --random's obstacle world (from --seed) or of the
// paths file's world, for agents of po.radius (m), its counts in
// report["roadmap"] and its build time (ms) in roadmap_ms; with neither, an empty planner.
path::Planner build_planner(const MatchArgs& a, const io::PathsFile& file, const path::PlanOptions& po,
                            nlohmann::json& report, double& roadmap_ms) {
  path::Planner planner;
  if (!(a.random > 0 || file.has_world)) return planner;
  const auto t0 = std::chrono::steady_clock::now();
  if (a.random > 0) {
    path::RandomWorldOptions wo;
    wo.seed = a.seed;
    planner = path::Planner::build(path::random_obstacle_world(wo), po);
  } else {
    planner = path::Planner::build(path::FreeSpace::build(file.has_walkable ? &file.walkable : nullptr, file.polygons,
                                                          file.circles, po.free_space),
                                   po);
  }
  roadmap_ms = ms_since(t0);
  spdlog::info("roadmap: {} nodes, {} edges (of {} Voronoi edges, {} inside free space) for radius {} m",
               planner.roadmap().node_count(), planner.roadmap().edge_count(), planner.roadmap().voronoi_edges,
               planner.roadmap().inside_edges, po.radius);
  report["roadmap"] = {{"nodes", planner.roadmap().node_count()},
                       {"edges", planner.roadmap().edge_count()},
                       {"voronoi_edges", planner.roadmap().voronoi_edges},
                       {"free_components", planner.space().components().size()},
                       {"radius_m", po.radius},
                       {"build_ms", roadmap_ms}};
  return planner;
}

// Queries to plan: --random's N random ones (from --seed), else the paths
// file's planned entries in file order.
std::vector<path::PathQuery> path_queries(const MatchArgs& a, const io::PathsFile& file, const path::Planner& planner) {
  if (a.random > 0) return path::random_queries(planner, a.random, a.seed);
  std::vector<path::PathQuery> queries;
  for (const io::PathEntry& e : file.paths)
    if (e.planned) queries.push_back({e.from, e.to});
  return queries;
}

// Paths to match: the file's given paths and its planned ones that were found
// (planned[q] for the q-th planned entry), or --random's found paths with
// speeds drawn in [1, 3) m/s from --seed; the paths not found counted in `unplanned`.
std::vector<path::PathInput> collect_inputs(const MatchArgs& a, const io::PathsFile& file,
                                            const std::vector<path::PlannedPath>& planned, std::int64_t& unplanned) {
  std::vector<path::PathInput> inputs;
  Rng speed_rng(a.seed, 0x5eed);
  if (a.random > 0) {
    for (std::size_t i = 0; i < planned.size(); ++i) {
      const float speed = static_cast<float>(speed_rng.uniform(1.0, 3.0));
      if (!planned[i].found()) {
        ++unplanned;
        continue;
      }
      inputs.push_back({"random" + std::to_string(i), planned[i].points, speed, {}});
    }
    return inputs;
  }
  std::size_t q = 0;
  for (std::size_t i = 0; i < file.paths.size(); ++i) {
    const io::PathEntry& e = file.paths[i];
    if (e.planned) {
      const path::PlannedPath& p = planned[q++];
      if (!p.found()) {
        spdlog::warn("{}: no path from ({}, {}) to ({}, {}): {}", e.name, e.from.x, e.from.y, e.to.x, e.to.y,
                     path::to_string(p.status));
        ++unplanned;
        continue;
      }
      inputs.push_back({e.name, p.points, e.speed, e.marks});
    } else {
      inputs.push_back({e.name, e.points, e.speed, e.marks});
    }
  }
  return inputs;
}

// The paths of a match run and what getting them cost.
struct MatchInputs {
  std::vector<path::PathInput> inputs;
  std::int64_t unplanned = 0;  // planned paths with no way found
  double roadmap_ms = 0, plan_ms = 0;
};

// Paths: given, or planned on the roadmap (report["roadmap"] when built);
// throws Error when none is left to match.
MatchInputs gather_paths(const MatchArgs& a, const io::PathsFile& file, nlohmann::json& report) {
  MatchInputs in;
  path::PlanOptions po;
  po.radius = a.random > 0 ? a.radius : file.radius;
  const path::Planner planner = build_planner(a, file, po, report, in.roadmap_ms);
  const std::vector<path::PathQuery> queries = path_queries(a, file, planner);
  std::vector<path::PlannedPath> planned;
  if (!queries.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    planned = planner.plan_all(queries);
    in.plan_ms = ms_since(t0);
  }
  in.inputs = collect_inputs(a, file, planned, in.unplanned);
  if (in.inputs.empty()) throw Error("no path to match (every planned path failed)", at_field("paths"));
  return in;
}

// The summary on stdout: paths, grid, the three sequencings' errors, the
// playback's deviation (m) and the stages' times (ms).
void print_match_summary(const path::MatchRun& run, const path::MotionGraph& machine, const MatchInputs& in,
                         double machine_ms) {
  double length = 0;
  for (const auto& p : run.paths) length += p.length;
  std::printf("paths            %zu (%lld not planned), %.1f m in all\n", run.paths.size(),
              static_cast<long long>(in.unplanned), length);
  std::printf("grid             %lld curves x %lld motions = %lld pairs, k = %d, d = %.2f m\n",
              static_cast<long long>(run.curves), static_cast<long long>(run.motions),
              static_cast<long long>(run.curves * run.motions), machine.k(), machine.segment_length());
  std::printf("greedy           path error %.4f m/point, %lld illegal transitions in %lld paths\n",
              run.greedy.path_error, static_cast<long long>(run.greedy.illegal),
              static_cast<long long>(run.greedy.paths_with_illegal));
  std::printf("greedy repaired  path error %.4f m/point, %lld illegal transitions\n", run.repaired.path_error,
              static_cast<long long>(run.repaired.illegal));
  std::printf("dynamic program  path error %.4f m/point, %lld illegal transitions\n", run.dp.path_error,
              static_cast<long long>(run.dp.illegal));
  std::printf("playback (DP)    deviation of the root from the path: mean %.3f m, max %.3f m\n", run.deviation_mean,
              run.deviation_max);
  std::printf(
      "time (ms)        machine %.1f, roadmap %.1f, plan %.1f, resample %.1f, grid %.1f, sequences %.1f, playback %.1f "
      "(%d threads, %s)\n",
      machine_ms, in.roadmap_ms, in.plan_ms, run.resample_ms, run.grid_ms, run.sequences_ms, run.playback_ms,
      current_threads(), to_string(current_backend()));
}

// match.json's "paths": per path its length (m), curves, errors (m/point),
// deviation (m), duration (s) and DP states.
nlohmann::json paths_json(const path::MatchRun& run) {
  nlohmann::json paths = nlohmann::json::array();
  for (const auto& p : run.paths)
    paths.push_back({{"name", p.name},
                     {"length_m", p.length},
                     {"curves", p.curves},
                     {"greedy_illegal", p.greedy_illegal},
                     {"greedy_error_m", p.greedy_error},
                     {"dp_error_m", p.dp_error},
                     {"deviation_mean_m", p.deviation_mean},
                     {"deviation_max_m", p.deviation_max},
                     {"duration_s", p.duration_s},
                     {"dp_states", p.dp_states}});
  return paths;
}

// match.json beside report["roadmap"]: the input, the machine, the grid, the
// sequencings, the playback, the timings (ms) and the paths.
void fill_match_report(nlohmann::json& report, const MatchArgs& a, const path::StateMachineSpec& spec,
                       const path::MotionGraph& machine, const path::MatchRun& run, const MatchInputs& in,
                       double machine_ms) {
  report["input"] =
      a.random > 0 ? nlohmann::json{{"random", a.random}, {"seed", a.seed}} : nlohmann::json{{"file", a.file}};
  report["machine"] = {{"name", spec.name},
                       {"states", machine.states().size()},
                       {"segments", machine.segment_count()},
                       {"locomotion_segments", machine.locomotion_segments().size()},
                       {"spacing_m", machine.spacing()},
                       {"k", machine.k()},
                       {"segment_length_m", machine.segment_length()},
                       {"build_ms", machine_ms}};
  report["grid"] = {{"curves", run.curves}, {"motions", run.motions}, {"ms", run.grid_ms}};
  report["greedy"] = stats_json(run.greedy);
  report["greedy_repaired"] = stats_json(run.repaired);
  report["dp"] = stats_json(run.dp);
  report["playback"] = {
      {"deviation_mean_m", run.deviation_mean}, {"deviation_max_m", run.deviation_max}, {"ms", run.playback_ms}};
  report["timings_ms"] = {{"machine", machine_ms},       {"roadmap", in.roadmap_ms}, {"plan", in.plan_ms},
                          {"resample", run.resample_ms}, {"grid", run.grid_ms},      {"sequences", run.sequences_ms},
                          {"playback", run.playback_ms}};
  report["threads"] = current_threads();
  report["backend"] = to_string(current_backend());
  report["unplanned"] = in.unplanned;
  report["paths"] = paths_json(run);
}

// Writes --out/match.json and a BVH clip per kept playback (path name.bvh).
void write_match_outputs(const MatchArgs& a, const nlohmann::json& report, const path::MatchRun& run,
                         const path::MotionGraph& machine) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec || !fs::is_directory(a.out))
    throw Error("cannot create folder: " + (ec ? ec.message() : std::string("not a folder")), at_line(a.out, 0));
  const fs::path json_path = fs::path(a.out) / "match.json";
  io::write_json_file(json_path.string(), report);
  for (std::size_t i = 0; i < run.clips.size(); ++i) {
    if (run.clips[i].frame_count == 0) continue;
    io::BvhWriteOptions w;
    w.frame_time = run.clips[i].frame_time;
    io::write_bvh((fs::path(a.out) / (run.paths[i].name + ".bvh")).string(), machine.skeleton(), run.clips[i], w);
  }
  std::printf("wrote            %s%s\n", json_path.string().c_str(), run.clips.empty() ? "" : " and BVH clips");
}

void run_match(const MatchArgs& a) {
  check_match_args(a);
  nlohmann::json report;
  const auto t0 = std::chrono::steady_clock::now();

  io::PathsFile file;
  if (!a.file.empty()) file = io::read_paths(a.file);
  const std::string machine_file = !a.machine.empty() ? a.machine : file.machine;
  const path::StateMachineSpec spec =
      machine_file.empty() ? io::default_state_machine_spec() : io::read_state_machine(machine_file);
  const path::MotionGraph machine = path::MotionGraph::build(spec, motion::default_skeleton());
  const double machine_ms = ms_since(t0);
  spdlog::info("state machine '{}': {} states, {} motion segments ({} locomotion), d = {} x {} m = {:.2f} m", spec.name,
               machine.states().size(), machine.segment_count(), machine.locomotion_segments().size(), machine.k(),
               machine.spacing(), machine.segment_length());

  const MatchInputs in = gather_paths(a, file, report);
  path::MatchRunOptions mo;
  mo.keep_clips = a.bvh;
  const path::MatchRun run = path::match_paths(machine, in.inputs, mo);

  print_match_summary(run, machine, in, machine_ms);
  fill_match_report(report, a, spec, machine, run, in, machine_ms);
  write_match_outputs(a, report, run, machine);
}

}  // namespace

void add_match_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("match", "Plan paths, match them against a motion state machine, play them back");
  static MatchArgs a;
  cmd->add_option("paths", a.file, "Paths file (YAML, see docs/path.md)");
  cmd->add_option("--random", a.random, "Instead: N random paths planned through a random obstacle field");
  cmd->add_option("--seed", a.seed, "Seed of the random field and paths (default 1)");
  cmd->add_option("--machine", a.machine,
                  "State machine file (default: the built-in data/motion/default_machine.yaml)");
  cmd->add_option("--radius", a.radius, "Agent radius for --random planning, m (default 0.3)");
  cmd->add_option("--out", a.out, "Output folder for match.json (default out/match)");
  cmd->add_option("--bvh", a.bvh, "Also write the playback clips of the first N paths as BVH");
  cmd->callback([&g] {
    apply_global_options(g);
    run_match(a);
  });
}

}  // namespace throng::app
