// The scenario a command works on, as its command line names it: a file or
// a built-in name, resized by --agents and reseeded by --seed.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "core/config.h"
#include "io/scenario_yaml.h"

namespace throng::app {

struct ScenarioChoice {
  std::string scenario = "circle";
  Index agents = 0;  // 0 = as the scenario says
  std::optional<std::uint64_t> seed;

  // The positional scenario and --agents and --seed, on `cmd`.
  void add_options(CLI::App& cmd);
  // Loads it (errors name the file and line) and applies --agents and --seed.
  io::LoadedScenario load() const;
};

}  // namespace throng::app
