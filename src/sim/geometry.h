// Planar geometry in metres: rings, polygons with holes, circles, segments.
//
// Host-side shapes (std::vector) describe the world; the small inline
// functions marked THRONG_HOST_DEVICE work on plain points and are what the
// steering kernels call. A later roadmap (Voronoi of free space) builds on the
// same types, so nothing here is specific to agents.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/vec2.hpp>
#include <optional>
#include <vector>

#include "core/config.h"

namespace throng::sim {

using Ring = std::vector<glm::vec2>;  // closed implicitly: last vertex joins the first

// Outer boundary plus holes. Orientation is free (tests use the even-odd rule).
struct Polygon {
  Ring outer;
  std::vector<Ring> holes;
};

struct Circle {
  glm::vec2 center{0.0f};
  float radius = 0.0f;
};

struct Segment {
  glm::vec2 a{0.0f};
  glm::vec2 b{0.0f};
};

struct Aabb {
  glm::vec2 min{INFINITY};
  glm::vec2 max{-INFINITY};
  void add(glm::vec2 p) {
    min = glm::vec2(std::fmin(min.x, p.x), std::fmin(min.y, p.y));
    max = glm::vec2(std::fmax(max.x, p.x), std::fmax(max.y, p.y));
  }
  void add(const Aabb& b) {
    if (!b.empty()) {
      add(b.min);
      add(b.max);
    }
  }
  bool empty() const { return !(min.x <= max.x && min.y <= max.y); }
  bool contains(glm::vec2 p) const { return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y; }
  glm::vec2 size() const { return empty() ? glm::vec2(0.0f) : max - min; }
};

// ---- inline kernels-friendly primitives -------------------------------------

THRONG_HOST_DEVICE THRONG_INLINE float cross2(glm::vec2 a, glm::vec2 b) { return a.x * b.y - a.y * b.x; }
THRONG_HOST_DEVICE THRONG_INLINE float dot2(glm::vec2 a, glm::vec2 b) { return a.x * b.x + a.y * b.y; }
THRONG_HOST_DEVICE THRONG_INLINE float length2(glm::vec2 a) { return dot2(a, a); }
THRONG_HOST_DEVICE THRONG_INLINE float length_of(glm::vec2 a) { return sqrtf(dot2(a, a)); }
// Left-hand perpendicular (rotated +90 degrees).
THRONG_HOST_DEVICE THRONG_INLINE glm::vec2 perp_left(glm::vec2 a) { return glm::vec2(-a.y, a.x); }
// a / |a|, or `fallback` when a is (nearly) zero.
THRONG_HOST_DEVICE THRONG_INLINE glm::vec2 normalize_or(glm::vec2 a, glm::vec2 fallback) {
  const float l2 = dot2(a, a);
  return l2 > 1e-12f ? a * (1.0f / sqrtf(l2)) : fallback;
}
// a scaled down to length at most `max_length`.
THRONG_HOST_DEVICE THRONG_INLINE glm::vec2 clamp_length(glm::vec2 a, float max_length) {
  const float l2 = dot2(a, a);
  if (l2 <= max_length * max_length || l2 <= 0.0f) return a;
  return a * (max_length / sqrtf(l2));
}

// Closest point to p on segment [a, b]; t in [0, 1] is its parameter.
THRONG_HOST_DEVICE inline glm::vec2 closest_point_on_segment(glm::vec2 p, glm::vec2 a, glm::vec2 b,
                                                             float* t_out = nullptr) {
  const glm::vec2 ab = b - a;
  const float l2 = dot2(ab, ab);
  float t = l2 > 0.0f ? dot2(p - a, ab) / l2 : 0.0f;
  t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
  if (t_out != nullptr) *t_out = t;
  return a + ab * t;
}

THRONG_HOST_DEVICE inline float distance_to_segment(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
  return length_of(p - closest_point_on_segment(p, a, b));
}

// The segment [a, b] meets the box [lo, hi] (Liang-Barsky clipping; a
// touch counts).
THRONG_HOST_DEVICE inline bool segment_meets_box(glm::vec2 a, glm::vec2 b, glm::vec2 lo, glm::vec2 hi) {
  float t0 = 0.0f, t1 = 1.0f;
  const glm::vec2 d = b - a;
  auto clip = [&](float p, float q) {  // the part with p t <= q
    if (p == 0.0f) return q >= 0.0f;
    const float t = q / p;
    if (p < 0.0f)
      t0 = fmaxf(t0, t);
    else
      t1 = fminf(t1, t);
    return t0 <= t1;
  };
  return clip(-d.x, a.x - lo.x) && clip(d.x, hi.x - a.x) && clip(-d.y, a.y - lo.y) && clip(d.y, hi.y - a.y);
}

// [a, b] and [c, d] cross at a point inside both (touching does not count;
// float, for kernels: geometry validation uses segments_intersect).
THRONG_HOST_DEVICE inline bool segments_cross(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d) {
  const glm::vec2 ab = b - a, cd = d - c;
  return cross2(ab, c - a) * cross2(ab, d - a) < 0.0f && cross2(cd, a - c) * cross2(cd, b - c) < 0.0f;
}

// Crossing-number step of the even-odd rule for edge (a, b) and a ray from p
// towards +x: true when the edge toggles "inside".
THRONG_HOST_DEVICE inline bool edge_crosses_ray(glm::vec2 p, glm::vec2 a, glm::vec2 b) {
  if ((a.y > p.y) == (b.y > p.y)) return false;
  const float x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
  return p.x < x;
}

// Even-odd point-in-ring over a vertex array.
THRONG_HOST_DEVICE inline bool point_in_ring(glm::vec2 p, const glm::vec2* v, Index n) {
  bool inside = false;
  for (Index i = 0, j = n - 1; i < n; j = i++)
    if (edge_crosses_ray(p, v[j], v[i])) inside = !inside;
  return inside;
}

// ---- host functions -----------------------------------------------------------

bool point_in_ring(glm::vec2 p, const Ring& ring);
// Inside the outer ring and outside every hole.
bool point_in_polygon(glm::vec2 p, const Polygon& poly);
bool point_in_circle(glm::vec2 p, const Circle& c);

// Twice the signed area (positive = counter-clockwise).
double signed_area2(const Ring& ring);
double area(const Polygon& poly);  // outer minus holes, >= 0

// Segment intersection. Returns true when the closed segments share a point;
// when they cross at a single point, *point is set to it.
bool segments_intersect(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d, glm::vec2* point = nullptr);

// Two edges of the ring that intersect other than at their shared vertex, or
// nullopt for a simple ring. Also reports zero-length edges and rings with
// fewer than three vertices as (i, i). O(n log n) average via a sweep over x.
struct EdgePair {
  std::int64_t first;
  std::int64_t second;
};
std::optional<EdgePair> find_self_intersection(const Ring& ring);
// Any two rings of the polygon crossing, or a ring crossing itself.
bool polygon_is_simple(const Polygon& poly);

struct BoundaryPoint {
  glm::vec2 point{0.0f};
  float distance = INFINITY;
};
// Closest point on the boundary (outer ring and holes).
BoundaryPoint closest_boundary_point(glm::vec2 p, const Polygon& poly);
BoundaryPoint closest_boundary_point(glm::vec2 p, const Circle& c);
// Distance from p to the polygon region: 0 inside, else distance to boundary.
float distance_to_polygon(glm::vec2 p, const Polygon& poly);

Aabb bounds(const Ring& ring);
Aabb bounds(const Polygon& poly);
Aabb bounds(const Circle& c);

// Every edge of the polygon (outer and holes) as a segment.
void append_edges(const Polygon& poly, std::vector<Segment>& out);

// Axis-aligned rectangle as a counter-clockwise ring.
Ring rect_ring(glm::vec2 min, glm::vec2 max);

}  // namespace throng::sim
