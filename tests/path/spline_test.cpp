// The C1 spline and arc-length resampling (T -> T1, T2 marks).
#include "path/spline.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "sim/geometry.h"
#include "core/random.h"

namespace throng::path {
namespace {

std::vector<glm::vec2> random_polyline(std::uint64_t seed, int n) {
  Rng rng(seed);
  std::vector<glm::vec2> p = {{0, 0}};
  float heading = 0;
  for (int i = 1; i < n; ++i) {
    heading += static_cast<float>(rng.uniform(-1.4, 1.4));
    const float len = static_cast<float>(rng.uniform(0.3, 6.0));
    p.push_back(p.back() + len * glm::vec2(std::cos(heading), std::sin(heading)));
  }
  return p;
}

TEST(Spline, InterpolatesKnotsAndIsC1) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const std::vector<glm::vec2> pts = random_polyline(seed, 12);
    const HermiteSpline s(pts);
    ASSERT_EQ(s.piece_count(), 11);
    for (std::int32_t i = 0; i < s.piece_count(); ++i) {
      EXPECT_LT(sim::length_of(s.position(i, 0) - pts[static_cast<std::size_t>(i)]), 1e-4f);
      EXPECT_LT(sim::length_of(s.position(i, 1) - pts[static_cast<std::size_t>(i) + 1]), 1e-4f);
    }
    for (std::int32_t i = 0; i + 1 < s.piece_count(); ++i) {
      // Position and first derivative agree from both sides of knot i + 1.
      const glm::vec2 left = s.derivative(i, 1.0f), right = s.derivative(i + 1, 0.0f);
      EXPECT_LT(sim::length_of(left - right), 1e-4f * std::max(1.0f, sim::length_of(left)));
      // And numerically, from finite differences in the knot parameter.
      const float hl = s.knot_params()[static_cast<std::size_t>(i) + 1] - s.knot_params()[static_cast<std::size_t>(i)];
      const float hr =
          s.knot_params()[static_cast<std::size_t>(i) + 2] - s.knot_params()[static_cast<std::size_t>(i) + 1];
      const float e = 1e-3f;
      const glm::vec2 dl = (s.position(i, 1.0f) - s.position(i, 1.0f - e)) / (e * hl);
      const glm::vec2 dr = (s.position(i + 1, e) - s.position(i + 1, 0.0f)) / (e * hr);
      EXPECT_LT(sim::length_of(dl - dr), 0.02f * std::max(1.0f, sim::length_of(dl)));
    }
  }
}

TEST(Spline, StraightLineStaysStraight) {
  const std::vector<glm::vec2> pts = {{0, 0}, {1, 1}, {5, 5}, {5.5f, 5.5f}};
  ResampleOptions o;
  o.spacing = 0.05f;
  const ResampledPath r = resample_path(pts, o);
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    EXPECT_NEAR(r.points[i].x, r.points[i].y, 1e-4f);
    EXPECT_NEAR(r.tangents[i].x, std::sqrt(0.5f), 1e-4f);
  }
  EXPECT_NEAR(r.spline_length, 5.5f * std::sqrt(2.0f), 1e-3f);
  EXPECT_LT(r.max_polyline_deviation, 1e-4f);
}

TEST(Resample, SpacingWithinOnePercent) {
  // The clips' root steps per frame: walk (1.35 m/s) to fast run (4.5 m/s) at 60 fps.
  for (float spacing : {0.0225f, 0.05f, 0.075f}) {
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      ResampleOptions o;
      o.spacing = spacing;
      const std::vector<glm::vec2> pts = random_polyline(seed, 15);
      const ResampledPath r = resample_path(pts, o);
      ASSERT_GT(r.points.size(), 10u);
      // The last point is within one spacing of the end of the curve.
      EXPECT_LE(sim::length_of(r.points.back() - pts.back()), spacing * 1.001f);
      double worst = 0;
      for (std::size_t i = 1; i < r.points.size(); ++i) {
        const double d = sim::length_of(r.points[i] - r.points[i - 1]);
        worst = std::max(worst, std::fabs(d - spacing) / spacing);
        EXPECT_GE(r.arc[i] - r.arc[i - 1],
                  spacing * 0.99f);  // an arc is never shorter than its chord (the table's arc is approximate)
      }
      EXPECT_LT(worst, 0.01) << "spacing " << spacing << " seed " << seed;
      for (glm::vec2 t : r.tangents) EXPECT_NEAR(sim::length_of(t), 1.0f, 1e-4f);
      // Corners are rounded within about a knot spacing of the polyline.
      EXPECT_LT(r.max_polyline_deviation, 0.5f);
    }
  }
}

TEST(Resample, TangentsFollowTheCurve) {
  // A circle of radius 3 as a fine polyline: tangents are perpendicular to the radius.
  std::vector<glm::vec2> pts;
  for (int i = 0; i <= 64; ++i) {
    const float a = 3.14159265f * i / 64;
    pts.emplace_back(3 * std::cos(a), 3 * std::sin(a));
  }
  ResampleOptions o;
  o.spacing = 0.03f;
  const ResampledPath r = resample_path(pts, o);
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    EXPECT_NEAR(sim::length_of(r.points[i]), 3.0f, 2e-3f);
    // One-sided end tangents are the end chords' directions: skip the end pieces.
    if (r.arc[i] > 0.2f && r.arc[i] < r.spline_length - 0.2f) {
      EXPECT_NEAR(sim::dot2(r.tangents[i], r.points[i] / 3.0f), 0.0f, 0.005f);
    }
  }
  EXPECT_NEAR(r.spline_length, 3.14159f * 3, 0.01f);
}

TEST(Resample, MarksCarryAFixedState) {
  const std::vector<glm::vec2> pts = {{0, 0}, {10, 0}, {10, 10}};
  ResampleOptions o;
  o.spacing = 0.1f;
  const std::vector<PathMark> marks = {
      {2.0f, 4.0f, "run_forward"}, {15.0f, 16.0f, "walk_left"}, {17.0f, 18.0f, "run_forward"}};
  const ResampledPath r = resample_path(pts, o, marks);
  ASSERT_EQ(r.mark_states.size(), 2u);
  EXPECT_EQ(r.mark_states[0], "run_forward");
  int marked = 0;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const float x = r.points[i].x, y = r.points[i].y;
    if (y < 1e-3f && x > 2.05f && x < 3.95f) {
      EXPECT_EQ(r.fixed_state[i], 0);
    }
    if (y < 1e-3f && (x < 1.95f || (x > 4.05f && x < 9))) {
      EXPECT_EQ(r.fixed_state[i], -1);
    }
    if (std::fabs(x - 10) < 1e-3f && y > 5.05f && y < 5.95f) {
      EXPECT_EQ(r.fixed_state[i], 1);
    }
    marked += r.fixed_state[i] >= 0;
  }
  EXPECT_NEAR(marked * 0.1f, 4.0f, 0.35f);
  const std::vector<PathMark> bad = {{3.0f, 2.0f, "x"}};
  EXPECT_THROW(resample_path(pts, o, bad), Error);
}

TEST(Resample, RejectsBadInput) {
  const std::vector<glm::vec2> one = {{1, 1}, {1, 1}};
  EXPECT_THROW(resample_path(one, {}), Error);
  const std::vector<glm::vec2> nan = {{0, 0}, {NAN, 1}};
  EXPECT_THROW(resample_path(nan, {}), Error);
  ResampleOptions o;
  o.spacing = 0;
  const std::vector<glm::vec2> ok = {{0, 0}, {1, 0}};
  EXPECT_THROW(resample_path(ok, o), Error);
}

}  // namespace
}  // namespace throng::path
