#include <cstdio>

#include "app/commands.h"
#include "core/error.h"

namespace throng::app {

void add_run_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("run", "Run a scenario (a YAML file or a built-in name)");
  static std::string scenario = "circle";
  cmd->add_option("scenario", scenario, "Scenario file or built-in name");
  cmd->callback([&g] {
    apply_global_options(g);
    throw Error("the crowd simulation is not built yet", at_field("scenario"));
  });
}

}  // namespace throng::app
