// throng: simulate and animate massive crowds.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>

#include "app/commands.h"
#include "core/error.h"
#include "core/exec.h"

namespace throng::app {

void apply_global_options(const GlobalOptions& g) {
  const auto level = spdlog::level::from_str(g.log_level);
  if (level == spdlog::level::off && g.log_level != "off")
    throw Error("unknown log level '" + g.log_level + "' (trace, debug, info, warn, error, off)", at_field("--log-level"));
  spdlog::set_level(level);
  if (g.threads < 0) throw Error("thread count must be >= 0 (0 = all cores)", at_field("--threads"));
  configure_execution(resolve_backend(parse_backend_choice(g.backend)), g.threads);
}

}  // namespace throng::app

int main(int argc, char** argv) {
  using namespace throng::app;
  spdlog::set_pattern("[%^%l%$] %v");
  CLI::App app{"throng: simulate and animate massive crowds"};
  app.require_subcommand(1);
  GlobalOptions g;
  app.add_option("--backend", g.backend, "Where kernels run: auto, cpu or cuda")->check(CLI::IsMember({"auto", "cpu", "cuda"}));
  app.add_option("--threads", g.threads, "CPU threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", g.log_level, "trace, debug, info, warn, error or off");
  add_run_command(app, g);
  add_animate_command(app, g);
  add_bench_command(app, g);
  add_info_command(app, g);
  add_convert_command(app, g);
  add_export_command(app, g);
  add_match_command(app, g);
  add_view_command(app, g);
  add_version_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "throng: error: %s (see --help)\n", e.what());
    return 2;
  } catch (const throng::Error& e) {
    std::fprintf(stderr, "throng: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "throng: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
