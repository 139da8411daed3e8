#include <cstdio>

#include "app/commands.h"
#include "app/version.h"

namespace throng::app {

void add_version_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("version", "Print the version");
  cmd->callback([] { std::printf("throng %s\n", kVersion); });
}

}  // namespace throng::app
