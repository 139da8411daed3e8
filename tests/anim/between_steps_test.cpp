// Agents between two simulation steps: positions on the segment, headings
// the shorter way round (across the -pi/pi seam), velocities as the
// displacement over the step, checked against a double-precision
// reference; identical on 1, 2 and 7 threads.
#include "anim/between_steps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include "core/buffer.h"
#include "core/error.h"
#include "core/exec.h"

namespace throng::anim {
namespace {

constexpr double kPi = std::numbers::pi;

struct Case {
  std::vector<glm::vec2> p0, p1;
  std::vector<float> h0, h1;
};

Case random_case(Index n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f), angle(-3.14159f, 3.14159f);
  Case c;
  for (Index i = 0; i < n; ++i) {
    c.p0.emplace_back(pos(rng), pos(rng));
    c.p1.push_back(c.p0.back() + glm::vec2(0.1f * pos(rng), 0.1f * pos(rng)));
    c.h0.push_back(angle(rng));
    c.h1.push_back(angle(rng));
  }
  return c;
}

template <class T>
Buffer<T> host(const std::vector<T>& v) {
  return Buffer<T>(std::span<const T>(v), Memory::Host);
}

struct Out {
  std::vector<glm::vec2> p;
  std::vector<float> h;
  std::vector<glm::vec2> v;
};

constexpr float kStep = 0.1f;

// A case's arrays in buffers, and the job over them.
struct Arrays {
  explicit Arrays(const Case& c)
      : p0(host(c.p0)),
        p1(host(c.p1)),
        out_p(static_cast<Index>(c.p0.size())),
        out_v(static_cast<Index>(c.p0.size())),
        h0(host(c.h0)),
        h1(host(c.h1)),
        out_h(static_cast<Index>(c.p0.size())) {}
  InterpolateAgentsJob job(float alpha) {
    InterpolateAgentsJob j;
    j.alpha = alpha;
    j.previous_positions = p0.span();
    j.positions = p1.span();
    j.previous_headings = h0.span();
    j.headings = h1.span();
    j.out_positions = out_p.span();
    j.out_headings = out_h.span();
    j.step_seconds = kStep;
    j.out_velocities = out_v.span();
    return j;
  }
  Buffer<glm::vec2> p0, p1, out_p, out_v;
  Buffer<float> h0, h1, out_h;
};

Out interpolate(const Case& c, float alpha) {
  Arrays a(c);
  a.job(alpha).run();
  return {a.out_p.to_vector(), a.out_h.to_vector(), a.out_v.to_vector()};
}

// The heading reached turning from a to b by the smaller angle, a fraction t of the way.
double reference_heading(double a, double b, double t) {
  double turn = std::remainder(b - a, 2.0 * kPi);  // in [-pi, pi]
  double h = std::remainder(a + t * turn, 2.0 * kPi);
  if (h >= kPi) h -= 2.0 * kPi;
  return h;
}

TEST(InterpolateAgents, MatchesTheReferenceAtEveryFraction) {
  const Case c = random_case(500, 3);
  for (float alpha : {0.0f, 0.25f, 0.5f, 0.9f, 1.0f}) {
    const Out o = interpolate(c, alpha);
    for (std::size_t i = 0; i < c.p0.size(); ++i) {
      const glm::dvec2 want =
          glm::dvec2(c.p0[i]) + static_cast<double>(alpha) * (glm::dvec2(c.p1[i]) - glm::dvec2(c.p0[i]));
      EXPECT_NEAR(o.p[i].x, want.x, 1e-4) << i;
      EXPECT_NEAR(o.p[i].y, want.y, 1e-4) << i;
      const glm::dvec2 velocity = (glm::dvec2(c.p1[i]) - glm::dvec2(c.p0[i])) / static_cast<double>(kStep);
      EXPECT_NEAR(o.v[i].x, velocity.x, 1e-3) << i;
      EXPECT_NEAR(o.v[i].y, velocity.y, 1e-3) << i;
      const double h = reference_heading(c.h0[i], c.h1[i], alpha);
      EXPECT_NEAR(std::remainder(static_cast<double>(o.h[i]) - h, 2.0 * kPi), 0.0, 1e-5) << i << " alpha " << alpha;
      EXPECT_GE(o.h[i], -static_cast<float>(kPi) - 1e-6f);
      EXPECT_LT(o.h[i], static_cast<float>(kPi) + 1e-6f);
    }
  }
}

TEST(InterpolateAgents, TurnsAcrossTheSeamTheShortWay) {
  Case c;
  c.p0 = {glm::vec2(0.0f)};
  c.p1 = {glm::vec2(1.0f, 0.0f)};
  c.h0 = {3.0f};   // just short of pi
  c.h1 = {-3.0f};  // just past it: 0.283 rad to the left, not 6 to the right
  const Out o = interpolate(c, 0.5f);
  EXPECT_NEAR(std::abs(o.h[0]), kPi, 1e-5);
  EXPECT_NEAR(o.p[0].x, 0.5f, 1e-6f);
}

// Over a periodic area an agent that stepped across the seam (from x =
// 19.9 to 0.1 of a 20 m period) walks on from 19.9 through 20 = 0: drawn
// at 19.95 a quarter of the way, at 0.05 three quarters, never in between.
TEST(InterpolateAgents, AStepAcrossAPeriodicSeamGoesTheShortWay) {
  Case c;
  c.p0 = {glm::vec2(19.9f, 1.0f)};
  c.p1 = {glm::vec2(0.1f, 1.0f)};
  c.h0 = {0.0f};
  c.h1 = {0.0f};
  Arrays a(c);
  InterpolateAgentsJob job = a.job(0.25f);
  job.periodic = Periodic{{0.0f, 0.0f}, {20.0f, 0.0f}};
  job.run();
  EXPECT_NEAR(a.out_p.to_vector()[0].x, 19.95f, 1e-4f);
  EXPECT_NEAR(a.out_v.to_vector()[0].x, 0.2f / kStep, 1e-3f);
  job.alpha = 0.75f;
  job.run();
  EXPECT_NEAR(a.out_p.to_vector()[0].x, 0.05f, 1e-4f);
  EXPECT_NEAR(a.out_p.to_vector()[0].y, 1.0f, 1e-6f);
}

TEST(InterpolateAgents, SameOnOneTwoAndSevenThreads) {
  const Case c = random_case(20000, 9);
  const auto run = [&](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    return interpolate(c, 0.37f);
  };
  const Out one = run(1);
  for (int threads : {2, 7}) {
    const Out other = run(threads);
    EXPECT_EQ(std::memcmp(one.p.data(), other.p.data(), one.p.size() * sizeof(glm::vec2)), 0) << threads;
    EXPECT_EQ(std::memcmp(one.h.data(), other.h.data(), one.h.size() * sizeof(float)), 0) << threads;
    EXPECT_EQ(std::memcmp(one.v.data(), other.v.data(), one.v.size() * sizeof(glm::vec2)), 0) << threads;
  }
}

TEST(InterpolateAgents, BadInputIsAnErrorNamingTheField) {
  Arrays a(random_case(4, 1));
  InterpolateAgentsJob job = a.job(0.5f);
  Buffer<glm::vec2> short_output(Index{3});
  job.out_positions = short_output.span();
  try {
    job.run();
    FAIL() << "a short output was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("interpolate.out_positions"), std::string::npos) << e.what();
  }
  job.out_positions = a.out_p.span();
  for (float bad : {-0.1f, 1.5f, std::nanf("")}) {
    job.alpha = bad;
    EXPECT_THROW(job.run(), Error) << bad;
  }
  job.alpha = 0.5f;
  job.run();
  job.step_seconds = 0.0f;  // velocities need the step's length
  EXPECT_THROW(job.run(), Error);
}

}  // namespace
}  // namespace throng::anim
