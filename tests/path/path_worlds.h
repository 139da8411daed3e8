// Worlds for the path tests and a brute-force clearance to the true shapes.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/geometry.h"
#include "core/random.h"

namespace throng::path::testing {

struct Shapes {
  sim::Polygon walkable;
  std::vector<sim::Polygon> polygons;
  std::vector<sim::Circle> circles;
};

// Distance from p to the nearest obstacle or the walkable boundary; 0 when p
// is not in free space. Brute force over the original (unsnapped) shapes.
inline float true_clearance(glm::vec2 p, const Shapes& s) {
  if (!sim::point_in_polygon(p, s.walkable)) return 0.0f;
  float best = sim::closest_boundary_point(p, s.walkable).distance;
  for (const sim::Polygon& poly : s.polygons) {
    if (sim::point_in_polygon(p, poly)) return 0.0f;
    best = std::min(best, sim::closest_boundary_point(p, poly).distance);
  }
  for (const sim::Circle& c : s.circles) {
    const float d = sim::length_of(p - c.center) - c.radius;
    if (d <= 0) return 0.0f;
    best = std::min(best, d);
  }
  return best;
}

// Smallest true clearance along a segment, sampled every `step` metres.
inline float segment_true_clearance(glm::vec2 a, glm::vec2 b, const Shapes& s, float step = 0.01f) {
  const int n = std::max(1, static_cast<int>(std::ceil(sim::length_of(b - a) / step)));
  float best = INFINITY;
  for (int i = 0; i <= n; ++i) best = std::min(best, true_clearance(a + (b - a) * (static_cast<float>(i) / n), s));
  return best;
}

// A 40 x 30 m room with random circles and rotated boxes, some overlapping
// one another, plus an L-shaped wall with a hole-free notch.
inline Shapes obstacle_field(std::uint64_t seed, int count = 30) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {40, 30});
  Rng rng(seed);
  for (int i = 0; i < count; ++i) {
    const glm::vec2 c(static_cast<float>(rng.uniform(3, 37)), static_cast<float>(rng.uniform(3, 27)));
    const float size = static_cast<float>(rng.uniform(0.6, 3.0));
    if (i % 2 == 0) {
      s.circles.push_back({c, size * 0.5f});
    } else {
      const float a = static_cast<float>(rng.uniform(0, 3.14159));
      const glm::vec2 u(std::cos(a) * size * 0.5f, std::sin(a) * size * 0.5f), v = sim::perp_left(u) * 0.6f;
      s.polygons.push_back({{c - u - v, c + u - v, c + u + v, c - u + v}, {}});
    }
  }
  s.polygons.push_back({{{5, 5}, {12, 5}, {12, 6}, {6, 6}, {6, 10}, {5, 10}}, {}});
  return s;
}

}  // namespace throng::path::testing
