// Loads a built-in scenario through the installed throng package, steps it
// 10 times and prints the agent count (checked by consumer_test.sh).
#include <cstdio>
#include <exception>

#include "io/scenario_yaml.h"  // include/throng is on the include path
#include "sim/simulation.h"

int main() {
  try {
    const auto scenario = throng::io::load_builtin_scenario("circle");
    auto sim = throng::io::build_simulation(scenario);
    for (int i = 0; i < 10; ++i) sim->step();
    std::printf("scenario=circle steps=10 agents=%lld spec_agents=%lld\n", static_cast<long long>(sim->agent_count()),
                static_cast<long long>(scenario.spec.total_agents()));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
