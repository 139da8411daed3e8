// sim/simulation on CUDA against the CPU: Simulation::step (bin, sense,
// steer, move: every kernel of simulation_kernels.cpp) on built-in
// scenarios under both schedulers and the all-pairs sense reference.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/simulation.h"
#include "tests/gpu/gpu_test.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

struct State {
  std::vector<glm::vec2> positions, velocities;
  std::vector<float> headings, arrival;
  std::vector<std::uint8_t> flags;
  Index active = 0, arrived = 0;
};

State run_steps(const ScenarioSpec& spec, SchedulerKind scheduler, NeighbourSearch neighbours, int steps) {
  SimulationOptions options;
  options.neighbours = neighbours;
  Simulation sim(spec, options);  // world, crowd and scratch in current_memory()
  sim.set_scheduler(scheduler);
  sim.run(steps);
  return {sim.positions(), sim.velocities(),   sim.headings(),     sim.arrival_times(),
          sim.flags(),     sim.active_count(), sim.arrived_count()};
}

struct Case {
  const char* scenario;
  Index agents;
  SchedulerKind scheduler;
  NeighbourSearch neighbours;
  ModelKind model = ModelKind::Priority;
};

void expect_one_step_matches(const Case& c) {
  SCOPED_TRACE(std::string(c.scenario) + ", " + to_string(c.scheduler) +
               (c.neighbours == NeighbourSearch::AllPairs ? ", all pairs" : "") + ", " + to_string(c.model));
  ScenarioSpec spec = test::builtin(c.scenario, c.agents);
  spec.model.kind = c.model;
  const auto run = [&](Memory) { return run_steps(spec, c.scheduler, c.neighbours, 1); };
  const State cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const State gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_EQ(gpu.positions.size(), static_cast<std::size_t>(c.agents));
  // One step from the same spawn: per agent a sense (distances, a
  // time-to-collision, a few divides), the steering force, an integration
  // and 4 contact passes, each tens of FMA-able operations on positions of
  // up to ~40 m. The step moves an agent by ~0.13 m, computed to ~1e-6
  // relative (a few dozen roundings), and adds it to a position whose ulp
  // is ~4e-6 m: 1e-4 m (~25 ulps at 40 m) bounds that with a margin.
  // A discrete decision (which force has priority, whether a contact pass
  // touches a pair, whether a move is accepted) flips only for an agent
  // within a rounding of its threshold: allow one such agent.
  EXPECT_TRUE(gpu_test::near(gpu.positions, cpu.positions, {1e-6, 1e-4, 2})) << "positions";
  // Velocity = displacement / dt (0.1 s): the position bound times 10.
  EXPECT_TRUE(gpu_test::near(gpu.velocities, cpu.velocities, {1e-5, 1e-3, 2})) << "velocities";
  // Headings follow the velocity (atan2), which is ill-conditioned for an
  // agent that barely moved: compared where the CPU speed exceeds 5 cm/s.
  std::vector<float> hg, hc;
  for (std::size_t i = 0; i < cpu.headings.size(); ++i)
    if (glm::length(cpu.velocities[i]) > 0.05f) {
      hg.push_back(gpu.headings[i]);
      hc.push_back(cpu.headings[i]);
    }
  EXPECT_TRUE(gpu_test::near_angle(hg, hc, 1e-3)) << "headings of moving agents";
  EXPECT_LE(gpu_test::differing(gpu.flags, cpu.flags).size(), 1u) << "flags";
  EXPECT_LE(gpu_test::differing(gpu.arrival, cpu.arrival).size(), 1u) << "arrival times";
  EXPECT_LE(std::abs(gpu.active - cpu.active), gpu_test::tolerant() ? 1 : 0);
  EXPECT_LE(std::abs(gpu.arrived - cpu.arrived), gpu_test::tolerant() ? 1 : 0);
}

TEST(CudaSimulation, OneStepMatchesCpu) {
  THRONG_REQUIRE_GPU();
  for (const Case& c :
       {Case{"crossing", 1000, SchedulerKind::DoubleBuffer, NeighbourSearch::Bins},
        Case{"crossing", 1000, SchedulerKind::FourColour, NeighbourSearch::Bins},
        Case{"bottleneck", 600, SchedulerKind::DoubleBuffer, NeighbourSearch::Bins},
        Case{"bottleneck", 600, SchedulerKind::FourColour, NeighbourSearch::Bins},
        Case{"bottleneck", 600, SchedulerKind::DoubleBuffer, NeighbourSearch::AllPairs},
        // The collision-free speed model: sums of exponentials over neighbours (expf
        // differs by an ulp or two between the backends), the same bounds.
        Case{"crossing", 1000, SchedulerKind::DoubleBuffer, NeighbourSearch::Bins, ModelKind::CollisionFreeSpeed},
        Case{"bottleneck", 600, SchedulerKind::FourColour, NeighbourSearch::Bins, ModelKind::CollisionFreeSpeed},
        Case{"bottleneck", 600, SchedulerKind::DoubleBuffer, NeighbourSearch::AllPairs, ModelKind::CollisionFreeSpeed},
        // The time-to-collision model: sums of exponentials and square roots, likewise.
        Case{"crossing", 1000, SchedulerKind::DoubleBuffer, NeighbourSearch::Bins, ModelKind::Ttc},
        // The social force model: the same sums, over ten substeps.
        Case{"crossing", 1000, SchedulerKind::DoubleBuffer, NeighbourSearch::Bins, ModelKind::SocialForce},
        Case{"bottleneck", 600, SchedulerKind::FourColour, NeighbourSearch::Bins, ModelKind::SocialForce}})
    expect_one_step_matches(c);
}

TEST(CudaSimulation, TwentyStepsStayCloseToCpu) {
  THRONG_REQUIRE_GPU();
  for (const SchedulerKind scheduler : {SchedulerKind::DoubleBuffer, SchedulerKind::FourColour}) {
    SCOPED_TRACE(to_string(scheduler));
    // The priority model, for which the bounds below were set (the
    // collision-free speed model's sums differ by an ulp or two between the
    // backends from the first step: OneStepMatchesCpu).
    ScenarioSpec spec = test::builtin("bottleneck", 600);
    spec.model.kind = ModelKind::Priority;
    const auto run = [&](Memory) { return run_steps(spec, scheduler, NeighbourSearch::Bins, 20); };
    const State cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
    const State gpu = gpu_test::run_on(gpu_test::device_side(), run);
    // Over many steps the dynamics amplify roundings (agents push each other
    // in a jam, and a flipped decision moves an agent by a whole contact
    // correction), so no ulp bound holds. The bound is meant to catch a
    // wrong kernel, whose errors are of the order of a step's displacement
    // (~0.13 m): 1 cm, and up to 2% of the agents (12) beyond it.
    EXPECT_TRUE(gpu_test::near(gpu.positions, cpu.positions, {0.0, 1e-2, 24})) << "positions after 20 steps";
    EXPECT_TRUE(gpu_test::near(gpu.velocities, cpu.velocities, {0.0, 1e-1, 24})) << "velocities after 20 steps";
    EXPECT_LE(std::abs(gpu.active - cpu.active), gpu_test::tolerant() ? 12 : 0);
    EXPECT_LE(std::abs(gpu.arrived - cpu.arrived), gpu_test::tolerant() ? 12 : 0);
  }
}

}  // namespace
}  // namespace throng::sim
