// The fundamental diagram of the collision-free speed model against
// Weidmann's curve (Weidmann 1993, v0 1.34 m/s, gamma 1.913 /m^2, rho_max
// 5.4 /m^2), in the set-up of RiMEA 3.0 test 4: a 10 m wide corridor filled
// at a given density, everyone walking along it, speed along the corridor
// and density measured in a 10 m x 10 m area from 10 to 70 s.
//
// The corridor is long and open ahead, not periodic: the measurement area
// sits far enough behind the crowd's front (the rarefaction fan travels
// back into the crowd at Weidmann's characteristic speed q'(rho)) and ahead
// of its tail (which walks at v(rho)) that neither reaches it by 70 s.
//
// Single file: the same model in a 0.5 m wide corridor, against the linear
// relation between headway and speed that Seyfried, Steffen, Klingsch and
// Boltzmann (2005, "The fundamental diagram of pedestrian movement
// revisited", J. Stat. Mech. P10002) measured in single-file experiments:
// d = 0.36 m + 1.06 s * v, for headways d = 1/rho (rho per metre).
//
// THRONG_FD_CSV=path writes the table (density, speed, Weidmann) for
// scripts/plot_fundamental_diagram.py, which draws docs/fundamental_diagram.png.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "sim/metrics.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

double weidmann(double rho) { return 1.34 * (1.0 - std::exp(-1.913 * (1.0 / rho - 1.0 / 5.4))); }
double weidmann_slope(double rho) { return -1.34 * 1.913 / (rho * rho) * std::exp(-1.913 * (1.0 / rho - 1.0 / 5.4)); }

struct Point {
  double target = 0, density = 0, speed = 0;
};

// A corridor `width` wide, open far ahead of a crowd filling [0, length].
ScenarioSpec corridor(const char* name, double length, float width) {
  const float far = static_cast<float>(2.0 * length + 200.0);
  return test::collision_free_spec(name, 0.05f, 70.0f, {{-1.0f, 0.0f}, {far, 0.0f}, {far, width}, {-1.0f, width}});
}

// Runs 70 s and averages, once a simulated second from 10 s on, the density
// in `area` (per m^2, or per metre of its length when `per_metre`) and the
// speed along the desired direction.
Point sample_10_to_70_s(Simulation& sim, const Aabb& area, double target, bool per_metre) {
  Point p{target, 0, 0};
  int samples = 0;
  const std::int64_t per_second = static_cast<std::int64_t>(std::lround(1.0 / sim.spec().dt));
  for (std::int64_t k = 1; k <= 70 * per_second; ++k) {
    sim.step();
    if (k % per_second != 0 || k < 10 * per_second) continue;
    const CrowdState& c = sim.crowd();
    const AreaSample a = measure_area(c.position.span(), c.velocity.span(), c.goal.span(), c.flags.span(), area);
    p.density += per_metre ? static_cast<double>(a.agents) / static_cast<double>(area.size().x) : a.density;
    p.speed += a.mean_speed;
    ++samples;
  }
  p.density /= samples;
  p.speed /= samples;
  return p;
}

// One density: the crowd fills [0, length] x [0, 10]; the area is centred
// at x = X, X - 5 beyond where the tail walks by 70 s, and the fan from the
// front needs longer than 70 s to come back to X + 5.
Point measure(double rho) {
  const double v = weidmann(rho), fan = v + rho * weidmann_slope(rho);
  const double X = v * 70.0 + 10.0;
  const double length = X + 5.0 + std::max(0.0, -fan * 70.0) + 10.0;
  ScenarioSpec s = corridor("fundamental_diagram", length, 10.0f);
  GroupSpec g;
  g.count = static_cast<std::int64_t>(length * 10.0 * rho);
  g.radius = 0.2f;
  g.speed = {1.34f, 0.26f, 0.5f, 2.0f};  // Weidmann's free speed and its spread
  g.spawn.kind = Region::Kind::rect;
  g.spawn.min = {0.2f, 0.2f};
  g.spawn.max = {static_cast<float>(length), 9.8f};
  g.goal.kind = GoalSpec::Kind::Offset;
  g.goal.value = {static_cast<float>(length + 150.0), 0.0f};
  g.arrival = ArrivalBehaviour::Stop;
  s.groups = {g};
  Simulation sim(s);
  return sample_10_to_70_s(sim, {{static_cast<float>(X - 5.0), 0.0f}, {static_cast<float>(X + 5.0), 10.0f}}, rho,
                           false);
}

TEST(FundamentalDiagram, CollisionFreeSpeedFollowsWeidmann) {
  // Under the sanitizers (several times slower), two densities (the same
  // checks; 3 minutes with three).
  const std::vector<double> targets =
      test::sanitized() ? std::vector<double>{1.0, 3.0} : std::vector<double>{0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4, 4.5, 5};
  std::vector<Point> points;
  double squares = 0;
  for (double rho : targets) {
    const Point p = measure(rho);
    points.push_back(p);
    const double w = weidmann(p.density);
    squares += (p.speed - w) * (p.speed - w);
    std::printf("  target %.1f /m2: density %.2f /m2, speed %.3f m/s (Weidmann %.3f)\n", rho, p.density, p.speed, w);
    EXPECT_NEAR(p.density, rho, 0.15 * rho) << "the corridor was not filled as asked";
  }
  const double rms = std::sqrt(squares / static_cast<double>(points.size()));
  std::printf("  RMS deviation from Weidmann: %.3f m/s over %zu densities\n", rms, points.size());
  EXPECT_LE(rms, 0.15);
  for (std::size_t i = 1; i < points.size(); ++i)
    EXPECT_LT(points[i].speed, points[i - 1].speed) << "speed must fall with density";
  for (const Point& p : points) {
    if (p.density < 4.5) {
      EXPECT_GT(p.speed, 0.05) << "stopped at " << p.density << " /m2";
    }
  }
  if (const char* path = std::getenv("THRONG_FD_CSV")) {
    std::ofstream out(path);
    out << "target,density,speed,weidmann\n";
    for (const Point& p : points)
      out << p.target << ',' << p.density << ',' << p.speed << ',' << weidmann(p.density) << '\n';
  }
}

// Seyfried et al. 2005: the speed at headway d, within [0, v0].
double seyfried_single_file(double rho, double v0) { return std::clamp((1.0 / rho - 0.36) / 1.06, 0.0, v0); }

// One line density (per metre): agents exactly `1 / rho` apart along the
// middle of a 0.5 m corridor, all at 1.34 m/s (in single file the slowest
// would lead everyone), measured over 10 m from 10 to 70 s; the corridor is
// sized as above (the fan from the front travels back at most at half the
// free speed here).
Point measure_single_file(double rho) {
  // The tail may walk faster than the relation says: size for the free speed.
  const double d = 1.0 / rho;
  const double X = 1.34 * 70.0 + 10.0, length = X + 5.0 + 1.34 * 70.0 * 0.5 + 10.0;
  ScenarioSpec s = corridor("single_file", length, 0.5f);
  GroupSpec g;
  g.radius = 0.2f;
  g.speed = {1.34f, 0.0f, 1.34f, 1.34f};
  g.spawn.kind = Region::Kind::points;
  for (double x = 0.3; x < length; x += d) g.spawn.points.push_back({static_cast<float>(x), 0.25f});
  g.count = static_cast<std::int64_t>(g.spawn.points.size());
  g.goal.kind = GoalSpec::Kind::Offset;
  g.goal.value = {static_cast<float>(length + 150.0), 0.0f};
  s.groups = {g};
  Simulation sim(s);
  return sample_10_to_70_s(sim, {{static_cast<float>(X - 5.0), 0.0f}, {static_cast<float>(X + 5.0), 0.5f}}, rho, true);
}

TEST(FundamentalDiagram, CollisionFreeSpeedSingleFileFollowsSeyfried2005) {
  double squares = 0;
  int n = 0;
  double previous = INFINITY;
  for (double rho : {0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0}) {
    const Point p = measure_single_file(rho);
    const double want = seyfried_single_file(p.density, 1.34);
    squares += (p.speed - want) * (p.speed - want);
    ++n;
    std::printf("  %.1f /m: measured %.2f /m, speed %.3f m/s (Seyfried et al. %.3f)\n", rho, p.density, p.speed, want);
    EXPECT_NEAR(p.density, rho, 0.1 * rho);
    EXPECT_LT(p.speed, previous + 1e-3) << "speed must not rise with density";
    previous = p.speed;
  }
  const double rms = std::sqrt(squares / n);
  std::printf("  RMS deviation from the single-file relation: %.3f m/s\n", rms);
  EXPECT_LE(rms, 0.15);
}

}  // namespace
}  // namespace throng::sim
