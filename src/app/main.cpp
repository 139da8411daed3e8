// throng: simulate and animate massive crowds.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/version.h"
#include "core/error.h"
#include "core/exec.h"
#include "core/memory_budget.h"
#include "core/spelling.h"

namespace throng::app {

void apply_global_options(const GlobalOptions& g) {
  const auto level = spdlog::level::from_str(g.log_level);
  if (level == spdlog::level::off && g.log_level != "off")
    throw Error("unknown log level '" + g.log_level + "' (trace, debug, info, warn, error, off)",
                at_field("--log-level"));
  spdlog::set_level(level);
  if (g.threads < 0) throw Error("thread count must be >= 0 (0 = all cores)", at_field("--threads"));
  configure_execution(resolve_backend(parse_backend_choice(g.backend)), g.threads);
  set_memory_budget(g.max_memory.empty() ? 0 : parse_memory_size(g.max_memory, "--max-memory"));
}

void add_global_options(CLI::App& app, GlobalOptions& g) {
  const char* group = "Global options (before or after the command)";
  app.add_option("--backend", g.backend, "Where kernels run: auto, cpu or cuda")
      ->check(CLI::IsMember({"auto", "cpu", "cuda"}))
      ->group(group);
  app.add_option("--threads", g.threads, "CPU threads (0 = all cores)")->check(at_least(0))->group(group);
  app.add_option("--log-level", g.log_level, "trace, debug, info, warn, error or off")->group(group);
  app.add_option("--max-memory", g.max_memory,
                 "Memory a command may plan to use, e.g. 8G (default: 80 % of physical memory)")
      ->group(group);
}

}  // namespace throng::app

namespace {

// `throng rnu`: CLI11 would say "A subcommand is required" (or that the
// word was not expected); say which word is not a command instead.
class UnknownCommand : public CLI::ParseError {
 public:
  explicit UnknownCommand(std::string message)
      : CLI::ParseError("UnknownCommand", std::move(message), CLI::ExitCodes::ExtrasError) {}
};

// The first word on the command line that is neither an option of the top
// level nor an option's value: the command's name, if one was given.
std::optional<std::string> command_word(const CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") return std::nullopt;
    if (arg.size() > 1 && arg[0] == '-') {
      if (arg.find('=') == std::string::npos) {
        const CLI::Option* option = app.get_option_no_throw(arg);
        if (option != nullptr && option->get_type_size() != 0) ++i;  // its value
      }
      continue;
    }
    return arg;
  }
  return std::nullopt;
}

void check_command_word(const CLI::App& app, int argc, char** argv) {
  const std::optional<std::string> word = command_word(app, argc, argv);
  if (!word) return;
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  for (const std::string& name : names)
    if (name == *word) return;
  std::string message = "unknown command '" + *word + "'";
  const std::string close = throng::closest_name(*word, names);
  if (!close.empty()) message += " (did you mean '" + close + "'?)";
  throw UnknownCommand(fmt::format("{}; the commands are {}", message, fmt::join(names, ", ")));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace throng::app;
  // Logs go to stderr, before anything logs: stdout carries only what a
  // command prints (`info --json` must stay parseable).
  spdlog::set_default_logger(spdlog::stderr_color_mt("throng"));
  spdlog::set_pattern("[%^%l%$] %v");
  CLI::App app{"throng: simulate and animate massive crowds"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("throng ") + throng::app::kVersion, "Print the version and exit");
  GlobalOptions g;
  add_global_options(app, g);
  add_run_command(app, g);
  add_animate_command(app, g);
  add_bench_command(app, g);
  add_info_command(app, g);
  add_convert_command(app, g);
  add_export_command(app, g);
  add_export_crowd_command(app, g);
  add_match_command(app, g);
  add_route_command(app, g);
  add_verify_command(app, g);
  add_view_command(app, g);
  add_version_command(app);
  // The same options after the command's name: `throng run circle --threads 1`.
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) add_global_options(*sub, g);
  try {
    check_command_word(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
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
