// Scenario files in YAML -> sim::ScenarioSpec (schema: docs/scenarios.md).
//
// Strict: an unknown key, a duplicate key, a value of the wrong type (a
// string where a number belongs, a map where a list belongs) or a missing
// required key is an Error naming file:line:column and the key path
// ("groups[0].speed.mean"). Geometry and model errors found later, when the
// world is built and the crowd spawned, name the same key path;
// ScenarioSource maps them back to the line of the file (build_simulation).
//
// The built-in scenarios are the files of examples/, embedded at build time
// (one source of truth): `throng run circle` reads the same text as
// `throng run examples/circle.yaml`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"
#include "io/motion_set.h"
#include "io/trajectory_format.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace throng::io {

// Hostile-input guards, checked while reading (before anything of that size
// is allocated).
struct ScenarioReadLimits {
  std::uint64_t max_file_bytes = 64ull << 20;
  std::int64_t max_nodes = 4'000'000;  // YAML nodes visited (aliases count each time they are used)
  std::int64_t max_groups = 10'000;
  sim::ScenarioLimits scenario;  // agents, vertices, obstacles, waypoints, extent
};

// Where every key of a scenario came from.
struct ScenarioSource {
  std::string file;                                               // the path, or "builtin:<name>"
  std::map<std::string, std::pair<int, int>, std::less<>> marks;  // key path -> 1-based (line, column)
  // Long lists kept compact: list path -> (line, column) of item i, for
  // "path[i]" (spawn points).
  std::map<std::string, std::vector<std::pair<int, int>>, std::less<>> item_marks;
  // The location of `field` or of its closest recorded parent
  // ("groups[0].goal.point[1]" -> "groups[0].goal" when only that is known).
  Location locate(const std::string& field) const;
  // The same error with this file's line and column for its field.
  Error located(const Error& e) const;
};

struct LoadedScenario {
  sim::ScenarioSpec spec;
  ScenarioSource source;
  // outputs.trajectories.format: kept here, beside the simulation's spec,
  // because only `throng run` reads it.
  TrajectoryFormat trajectory_format = TrajectoryFormat::Csv;
  // motion: the clips characters are animated from (`throng run`, `throng
  // view`, `throng export-crowd`); paths relative to the file's folder
  // (motion_folder(); a built-in's are relative to the working folder).
  MotionSetSpec motion;
  std::filesystem::path motion_folder() const;
};

// Parses YAML text; `name` is the file name used in errors.
LoadedScenario parse_scenario(std::string_view text, const std::string& name, const ScenarioReadLimits& limits = {});
LoadedScenario read_scenario_file(const std::string& path, const ScenarioReadLimits& limits = {});

// Built-in scenarios: the names of examples/*.yaml and their text.
std::vector<std::string> builtin_scenario_names();
std::optional<std::string_view> builtin_scenario_text(std::string_view name);
LoadedScenario load_builtin_scenario(std::string_view name, const ScenarioReadLimits& limits = {});
// A built-in name ("circle"), else a file path. A name that is neither is
// an Error listing the built-ins.
LoadedScenario load_scenario(const std::string& name_or_path, const ScenarioReadLimits& limits = {});

// Builds the world and spawns the crowd; errors carry the file position of
// the offending key.
std::unique_ptr<sim::Simulation> build_simulation(const LoadedScenario& scenario,
                                                  const sim::SimulationOptions& options = {});

}  // namespace throng::io
