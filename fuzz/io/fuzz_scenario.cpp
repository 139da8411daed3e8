// libFuzzer target for the scenario reader: any bytes either read or throw
// throng::Error naming a file position or a key path; whatever reads and is
// small enough is also built (world, spawn) and stepped, and every agent
// must then be at a finite position.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "io/scenario_yaml.h"

// The simulation logs its set-up (routes planned, agents without one) at
// info and warn; per input that would bury libFuzzer's own lines.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::err);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  // Small limits keep each run fast; the checks are the same code as in production.
  io::ScenarioReadLimits limits;
  limits.max_file_bytes = 1 << 20;
  limits.max_nodes = 200'000;
  limits.max_groups = 64;
  // Route planning on the roadmap grows with agents x obstacles (a 300-obstacle
  // plaza with 500 agents takes 40 s under the sanitizers), so both stay
  // small enough that every input runs well inside libFuzzer's timeout.
  limits.scenario.max_agents = 400;
  limits.scenario.max_vertices = 20'000;
  limits.scenario.max_obstacles = 40;
  limits.scenario.max_waypoints = 64;
  limits.scenario.max_grid_items = 1'000'000;
  limits.scenario.raster_resolution = 128;
  limits.scenario.max_extent = 1.0e5f;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const io::LoadedScenario s = io::parse_scenario(text, "fuzz.yaml", limits);
    sim::SimulationOptions options;
    options.limits = limits.scenario;
    const auto sim = io::build_simulation(s, options);
    sim->run(3);
    for (const glm::vec2 p : sim->positions())
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) std::abort();
  } catch (const Error& e) {
    if (e.location().line <= 0 && e.location().field.empty()) std::abort();  // every error says where
  }
  return 0;
}
