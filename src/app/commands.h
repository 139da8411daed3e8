// The `throng` subcommands. Each file cmd_<name>.cpp adds one to the CLI.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace throng::app {

// Options every subcommand shares (set on the top-level command).
struct GlobalOptions {
  std::string backend = "auto";  // auto | cpu | cuda
  int threads = 0;               // 0 = all cores
  std::string log_level = "info";
};

// Applies --backend/--threads/--log-level; throws Error on bad values.
void apply_global_options(const GlobalOptions& g);

// Adds --backend/--threads/--log-level to `app`, bound to `g`. main() adds
// them to the top level and to every subcommand, so they may be given
// before or after the subcommand's name.
void add_global_options(CLI::App& app, GlobalOptions& g);

// Range checks whose errors read "--agents: must be at least 1, got 0"
// (CLI11's own print the bounds of the type, a 309-digit number for double).
CLI::Validator at_least(double min);
CLI::Validator greater_than(double min);
CLI::Validator between(double lo, double hi);

// --lod-thresholds: positive, finite, decreasing, at most kMaxLodLevels - 1;
// errors name `flag`.
void check_lod_thresholds(const std::vector<float>& thresholds, const std::string& flag);

// Throws Error "OPTION: needs NEEDS" for the first of `options` given on
// `cmd` when `given` is false (options that only matter with another one).
void refuse_unless(const CLI::App& cmd, bool given, const std::vector<std::string>& options, const std::string& needs);


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
