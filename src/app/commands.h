// The `throng` subcommands. Each file cmd_<name>.cpp adds one to the CLI.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace throng::io {
struct BvhWriteOptions;
}

namespace throng::app {

// Options every subcommand shares (set on the top-level command).
struct GlobalOptions {
  std::string backend = "auto";  // auto | cpu | cuda
  int threads = 0;               // 0 = all cores
  std::string log_level = "info";
  std::string max_memory;  // "" = 80 % of physical memory (core/memory_budget.h)
};

// Applies --backend/--threads/--log-level/--max-memory; throws Error on bad values.
void apply_global_options(const GlobalOptions& g);

// Adds --backend/--threads/--log-level to `app`, bound to `g`. main() adds
// them to the top level and to every subcommand, so they may be given
// before or after the subcommand's name.
void add_global_options(CLI::App& app, GlobalOptions& g);

// Memory per agent for the budget check before set-up (core/memory_budget.h):
// growth of the resident set per agent measured with the built-in plaza
// between 10^4 and 10^5 agents (simulation 0.58 KB, plus up to 0.32 KB for a
// sparse crowd's dense contact bins, kDenseCellsPerItem: 0.76 KB measured
// on the plaza; locomotion with the 22-joint default character 0.68 KB, also
// per character of `throng animate`), rounded up.
constexpr double kSimBytesPerAgent = 960;
constexpr double kLocomotionBytesPerAgent = 768;

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

// --order and --units of the BVH-writing commands (convert, export-default):
// the write options with that rotation order and unit (frame time unset);
// throws Error naming the flag on an unknown name.
io::BvhWriteOptions bvh_write_options(const std::string& order, const std::string& units);

void add_run_command(CLI::App& app, const GlobalOptions& g);
void add_animate_command(CLI::App& app, const GlobalOptions& g);
void add_bench_command(CLI::App& app, const GlobalOptions& g);
void add_info_command(CLI::App& app, const GlobalOptions& g);
void add_convert_command(CLI::App& app, const GlobalOptions& g);
void add_export_command(CLI::App& app, const GlobalOptions& g);
void add_export_crowd_command(CLI::App& app, const GlobalOptions& g);
void add_match_command(CLI::App& app, const GlobalOptions& g);
void add_route_command(CLI::App& app, const GlobalOptions& g);
void add_verify_command(CLI::App& app, const GlobalOptions& g);
void add_view_command(CLI::App& app, const GlobalOptions& g);
void add_version_command(CLI::App& app);

}  // namespace throng::app
