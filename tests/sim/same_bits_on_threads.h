// A scenario as `throng run` builds it (io::build_simulation), run `steps`
// steps on the CPU with 1 thread and with each of `others`: positions and
// velocities must hold the same bits (determinism across thread counts).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <utility>

#include "core/exec.h"
#include "io/scenario_yaml.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim::test {

inline void expect_same_bits_on_threads(const io::LoadedScenario& l, std::int64_t steps,
                                        std::initializer_list<int> others = {2, 4}) {
  auto snapshot = [&](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    const auto sim = io::build_simulation(l);
    sim->run(steps);
    return std::pair{sim->positions(), sim->velocities()};
  };
  const auto one = snapshot(1);
  for (int t : others) {
    const auto other = snapshot(t);
    EXPECT_TRUE(same_bits(one.first, other.first)) << t << " threads";
    EXPECT_TRUE(same_bits(one.second, other.second)) << t << " threads";
  }
}

}  // namespace throng::sim::test
