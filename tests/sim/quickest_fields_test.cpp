// Navigation fields weighed by the crowd's density (`planning: quickest`):
// - the slowness of congestion against Weidmann's relation, closed form;
// - the density map against counted agents;
// - a dense crowd ahead lengthens the way through it and turns the field's
//   direction aside, round it;
// - 500 people round the corner of RiMEA 3.0 test 15 (JuPedSim's corner,
//   examples/verification/rimea_15_corner.yaml) spread over the corridor's
//   width and are all out sooner than on the shortest-way field;
// - the same bits on 1, 2 and 4 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/exec.h"
#include "io/embedded.h"
#include "io/scenario_yaml.h"
#include "path/distance_field.h"
#include "sim/crowd.h"
#include "sim/navigation_field.h"
#include "sim/simulation.h"
#include "tests/sim/same_bits_on_threads.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

double weidmann(double rho) { return 1.34 * (1.0 - std::exp(-1.913 * (1.0 / rho - 1.0 / 5.4))); }

TEST(QuickestFields, CongestionSlownessIsTheFreeSpeedOverWeidmanns) {
  EXPECT_EQ(congestion_slowness(0.0f), 1.0f);
  EXPECT_EQ(congestion_slowness(-1.0f), 1.0f);
  EXPECT_EQ(congestion_slowness(NAN), 1.0f);
  for (double rho : {0.5, 1.0, 2.0, 3.0, 4.0})
    EXPECT_NEAR(congestion_slowness(static_cast<float>(rho)), 1.34 / weidmann(rho), 1e-3 * (1.34 / weidmann(rho)))
        << rho;
  float previous = 1.0f;
  for (float rho = 0.1f; rho < 8.0f; rho += 0.1f) {
    const float s = congestion_slowness(rho);
    EXPECT_GE(s, previous) << rho;
    EXPECT_LE(s, kMaxCongestion) << rho;
    previous = s;
  }
  EXPECT_EQ(congestion_slowness(5.4f), kMaxCongestion);  // Weidmann's speed is 0 there
  EXPECT_EQ(congestion_slowness(9.0f), kMaxCongestion);
}

// Nine agents in the cell (2, 2) of a 5 m x 5 m grid of 1 m cells: that
// cell and its eight neighbours read 9 / 9 m^2, the rest 0; inactive
// agents do not count.
TEST(QuickestFields, DensityMapCountsActiveAgentsOverThreeByThreeCells) {
  std::vector<glm::vec2> p;
  std::vector<std::uint8_t> flags;
  for (int k = 0; k < 9; ++k) {
    p.emplace_back(2.1f + 0.1f * static_cast<float>(k), 2.5f);
    flags.push_back(kAgentActive);
  }
  p.emplace_back(0.5f, 0.5f);
  flags.push_back(kAgentPending);
  Aabb bounds;
  bounds.add({0, 0});
  bounds.add({5, 5});
  const CrowdDensity d = crowd_density(p, flags, bounds);
  ASSERT_EQ(d.nx, 5);
  ASSERT_EQ(d.ny, 5);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      const bool near = std::abs(i - 2) <= 1 && std::abs(j - 2) <= 1;
      EXPECT_FLOAT_EQ(d.at({static_cast<float>(i) + 0.5f, static_cast<float>(j) + 0.5f}), near ? 1.0f : 0.0f)
          << i << ", " << j;
    }
  EXPECT_EQ(d.at({-1, 2}), 0.0f);
  EXPECT_EQ(d.at({2, 7}), 0.0f);
}

// A 30 m x 20 m room with its target at the east end and a crowd of
// 4 P/m^2 over 6 m x 6 m in the middle: the quickest way goes round the
// crowd, longer than the straight line and far shorter in time than
// through it (6 m at 6.2x the slowness), and just west of the crowd the
// field turns aside (on the shortest-way field it points straight at the
// target).
TEST(QuickestFields, ADenseCrowdAheadTurnsTheWayAside) {
  WorldSpec ws;
  ws.has_walkable = true;
  ws.walkable.outer = rect_ring({0, 0}, {30, 20});
  const World world = World::build(ws, 2.0f);
  Aabb bounds;
  bounds.add({0, 0});
  bounds.add({30, 20});
  CrowdDensity crowd;
  crowd.origin = {0, 0};
  crowd.nx = 30;
  crowd.ny = 20;
  crowd.density.assign(600, 0.0f);
  for (int j = 7; j < 13; ++j)
    for (int i = 12; i < 18; ++i) crowd.density[static_cast<std::size_t>(j * 30 + i)] = 4.0f;
  const path::FastMarchingFieldBuilder builder;
  NavigationFields fields;
  fields.add(builder.build(world, {28, 10}, 0.25f));
  fields.add(builder.build(world, {28, 10}, 0.25f, &crowd));
  const FieldsView v = fields.host_view();
  const glm::vec2 start(5.0f, 10.2f), before(10.5f, 10.2f);
  std::printf("  from (5, 10.2): %.2f m of walking, %.2f s at 1 m/s through the crowd's field\n",
              static_cast<double>(field_distance(v, 0, start)), static_cast<double>(field_distance(v, 1, start)));
  const float through = 6.0f * (congestion_slowness(4.0f) - 1.0f);
  EXPECT_GT(field_distance(v, 1, start), field_distance(v, 0, start) + 0.2f);
  EXPECT_LT(field_distance(v, 1, start), field_distance(v, 0, start) + 0.25f * through);
  const glm::vec2 plain = field_aim(v, 0, before) - before, weighed = field_aim(v, 1, before) - before;
  std::printf("  aim at (10.5, 10.2): (%.2f, %.2f) shortest, (%.2f, %.2f) quickest\n", static_cast<double>(plain.x),
              static_cast<double>(plain.y), static_cast<double>(weighed.x), static_cast<double>(weighed.y));
  EXPECT_LT(std::abs(plain.y), 0.1f);
  EXPECT_GT(std::abs(weighed.y), 0.3f);
}

// The corner of RiMEA 3.0 test 15 under the collision-free speed model,
// planning `field` or `quickest` (the file's own), with `agents` people.
double last_out_round_the_corner(const char* planning, std::int64_t agents) {
  std::string yaml(*io::kBuiltinVerification.find("rimea_15_corner"));
  const std::size_t at = yaml.find("planning: quickest");
  EXPECT_NE(at, std::string::npos);
  yaml.replace(at, 18, std::string("planning: ") + planning + "\nmodel: {type: collision_free_speed}");
  io::LoadedScenario l = io::parse_scenario(yaml, "rimea_15_corner.yaml");
  scale_agent_counts(l.spec, agents);
  const auto sim = io::build_simulation(l);
  const std::int64_t steps = l.spec.step_count();
  for (std::int64_t s = 0; s < steps && !sim->all_arrived(); ++s) sim->step();
  EXPECT_TRUE(sim->all_arrived()) << planning;
  return sim->time();
}

TEST(QuickestFields, ACrowdRoundACornerSpreadsAndIsOutSooner) {
  const std::int64_t n = test::sanitized() ? 200 : 500;
  const double shortest = last_out_round_the_corner("field", n);
  const double quickest = last_out_round_the_corner("quickest", n);
  std::printf("  %lld people round the corner: the last out after %.1f s on the shortest way, %.1f s on the quickest\n",
              static_cast<long long>(n), shortest, quickest);
  EXPECT_LT(quickest, 0.85 * shortest);
}

TEST(QuickestFields, SameBitsOnAnyThreadCount) {
  std::string yaml(*io::kBuiltinVerification.find("rimea_15_corner"));
  io::LoadedScenario l = io::parse_scenario(yaml, "rimea_15_corner.yaml");
  ASSERT_EQ(l.spec.planning, PlanningKind::Quickest);
  scale_agent_counts(l.spec, 150);
  test::expect_same_bits_on_threads(l, 600);  // 30 s: the fields are weighed again 15 times
}

}  // namespace
}  // namespace throng::sim
