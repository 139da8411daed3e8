#include "app/scenario_choice.h"

#include "app/commands.h"

namespace throng::app {

void ScenarioChoice::add_options(CLI::App& cmd) {
  cmd.add_option("scenario", scenario, "Scenario file, or a built-in name")->capture_default_str();
  cmd.add_option("--agents", agents, "Total agents (groups keep their proportions)")->check(at_least(1));
  cmd.add_option("--seed", seed, "Random seed (spawn positions, speeds, random goals)");
}

io::LoadedScenario ScenarioChoice::load() const {
  io::LoadedScenario loaded = io::load_scenario(scenario);
  if (agents > 0) sim::scale_agent_counts(loaded.spec, agents);
  if (seed) loaded.spec.seed = *seed;
  return loaded;
}

}  // namespace throng::app
