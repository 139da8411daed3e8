#include <cstdio>
#include <fstream>

#include "app/commands.h"
#include "bench/registry.h"
#include "core/error.h"

namespace throng::app {

void add_bench_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("bench", "Run the benchmark suites; print a table and optionally write JSON");
  static bench::Options options;
  static std::string json_path;
  cmd->add_flag("--quick", options.quick, "Short runs on small sizes (a smoke test, not for quoting)");
  cmd->add_option("--json", json_path, "Write the results as JSON to this file");
  cmd->add_option("--filter", options.filter, "Regular expression on benchmark names, e.g. 'core/.*'");
  cmd->add_option("--thread-counts", options.threads, "CPU thread counts to run, e.g. 1,2 (default: 1 and all cores)")
      ->delimiter(',')
      ->check(at_least(1));
  cmd->callback([&g] {
    apply_global_options(g);
    std::ofstream out;
    if (!json_path.empty()) {
      out.open(json_path);
      if (!out) throw Error("cannot open for writing", at_field("--json", json_path));
    }
    std::fprintf(stderr, "running benchmarks%s...\n", options.quick ? " (quick)" : "");
    const auto rows = bench::run(options);
    if (rows.empty()) throw Error("no benchmark matches '" + options.filter + "'", at_field("--filter"));
    std::printf("%s", bench::table(rows).c_str());
    if (out.is_open()) {
      out << bench::json(rows);
      if (!out) throw Error("write failed", at_field("--json", json_path));
      std::printf("wrote %s\n", json_path.c_str());
    }
  });
}

}  // namespace throng::app
