// The soak checks: a healthy run passes with a check every K frames and a
// report line per check; a non-finite agent, an agent outside the walkable
// area and an overlap beyond the bound each fail the check that sees them.
#include "sim/soak_stage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <unistd.h>

#include "core/error.h"
#include "sim/crowd.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

TEST(CountNonFinite, CountsAgentsWithANaNOrInfinitePositionOrVelocity) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<glm::vec2> p = {{0, 0}, {nan, 1}, {2, 2}, {3, 3}, {4, -inf}};
  const std::vector<glm::vec2> v = {{1, 0}, {0, 0}, {0, inf}, {0, 0}, {0, 0}};
  EXPECT_EQ(count_non_finite(Span<const glm::vec2>(p), Span<const glm::vec2>(v)), 3);
}

TEST(SoakCheckStage, AHealthyRunPassesWithALinePerCheck) {
  const std::string report =
      (std::filesystem::temp_directory_path() / ("throng_soak_" + std::to_string(getpid()) + ".jsonl")).string();
  Simulation sim(test::builtin("corridor", 40));
  FrameLoop loop(sim);
  SoakOptions o;
  o.every = 4;
  o.max_steps = 20;
  o.report = report;
  const SoakCheckStage& soak = loop.emplace<SoakCheckStage>(o);
  RunControl control;
  control.max_steps = 18;  // not a multiple of 4: the last frame is checked too
  loop.run(control);
  nlohmann::json stats;
  loop.finish(stats);
  ASSERT_EQ(soak.checks().size(), 6u);  // 0, 4, 8, 12, 16, 18
  EXPECT_EQ(soak.checks().back().step, 18);
  EXPECT_GT(soak.checks().back().rss_bytes, 0u);
  EXPECT_EQ(stats["soak"]["checks"], 6);
  EXPECT_EQ(stats["soak"]["rss_mib"]["warmup_step"], 4);  // the first check at or past a tenth of 20 steps
  EXPECT_TRUE(stats["soak"]["passed"]) << stats["soak"].dump();
  std::ifstream in(report);
  int lines = 0;
  for (std::string line; std::getline(in, line); ++lines) EXPECT_EQ(nlohmann::json::parse(line)["non_finite"], 0);
  EXPECT_EQ(lines, 6);
  std::filesystem::remove(report);
}

// Steps a corridor once, breaks it with `change` (after the step: the step
// itself would part overlapping agents) and expects the check to throw
// naming `what`.
void expect_check_fails(const std::function<void(CrowdState&)>& change, const std::string& what) {
  Simulation sim(test::builtin("corridor", 40));
  SoakOptions o;
  o.every = 1;
  SoakCheckStage soak(o);
  sim.step();
  change(sim.crowd());
  try {
    soak.after_step(sim, {sim.steps_done(), sim.time(), false});
    ADD_FAILURE() << "no failure for " << what;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at step 1 "), std::string::npos) << e.what();
  }
}

TEST(SoakCheckStage, ANonFiniteAgentFailsTheCheck) {
  expect_check_fails(
      [](CrowdState& c) {
        c.velocity[0] = {std::numeric_limits<float>::quiet_NaN(), 0.0f};
      },
      "non-finite");
}

TEST(SoakCheckStage, AnAgentOutsideTheWalkableAreaFailsTheCheck) {
  expect_check_fails(
      [](CrowdState& c) {
        c.position[0] = {0.0f, 40.0f};
      },
      "outside free space");  // the corridor is 6 m wide
}

TEST(SoakCheckStage, AnOverlapBeyondTheBoundFailsTheCheck) {
  // Radii 0.25 m and 20 cm apart: 30 cm deep.
  expect_check_fails([](CrowdState& c) { c.position[1] = c.position[0] + glm::vec2(0.2f, 0.0f); },
                     "overlap by more than the model's bound");
}

}  // namespace
}  // namespace throng::sim
