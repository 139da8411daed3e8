// The `throng` subcommands. Each file cmd_<name>.cpp adds one to the CLI.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace throng::app {

// Options every subcommand shares (set on the top-level command).
struct GlobalOptions {
  std::string backend = "auto";  // auto | cpu | cuda
  int threads = 0;               // 0 = all cores
  std::string log_level = "info";
};

// Applies --backend/--threads/--log-level; throws Error on bad values.
void apply_global_options(const GlobalOptions& g);

void add_run_command(CLI::App& app, const GlobalOptions& g);
void add_animate_command(CLI::App& app, const GlobalOptions& g);
void add_bench_command(CLI::App& app, const GlobalOptions& g);
void add_info_command(CLI::App& app, const GlobalOptions& g);
void add_convert_command(CLI::App& app, const GlobalOptions& g);
void add_export_command(CLI::App& app, const GlobalOptions& g);
void add_match_command(CLI::App& app, const GlobalOptions& g);
void add_view_command(CLI::App& app, const GlobalOptions& g);
void add_version_command(CLI::App& app);

}  // namespace throng::app
