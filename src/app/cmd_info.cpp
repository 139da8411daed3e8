#include <fmt/format.h>
#include <oneapi/tbb/version.h>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/version.h"
#include "core/cuda_runtime.h"
#include "core/exec.h"

namespace throng::app {

void add_info_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("info", "Describe this build and machine");
  static bool as_json = false;
  cmd->add_flag("--json", as_json, "Print JSON instead of text");
  cmd->callback([&g] {
    apply_global_options(g);
    nlohmann::json j = {{"version", kVersion},
                        {"build_type", kBuildType},
                        {"compiler", kCompiler},
                        {"tbb", TBB_VERSION_STRING},
                        {"hardware_threads", hardware_threads()},
                        {"threads", current_threads()},
                        {"backend", to_string(current_backend())},
                        {"cuda", cuda_status()}};
    if (as_json) {
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    for (auto& [k, v] : j.items()) std::printf("%-17s %s\n", k.c_str(), v.is_string() ? v.get<std::string>().c_str() : v.dump().c_str());
  });
}

}  // namespace throng::app
