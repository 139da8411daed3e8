#include "sim/geometry.h"

#include <algorithm>
#include <numeric>

namespace throng::sim {

namespace {
// Orientation of (a, b, c) in double: +1 left turn, -1 right turn, 0 collinear.
int orient(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  const double v = (static_cast<double>(b.x) - a.x) * (static_cast<double>(c.y) - a.y) -
                   (static_cast<double>(b.y) - a.y) * (static_cast<double>(c.x) - a.x);
  return v > 0 ? 1 : (v < 0 ? -1 : 0);
}
// c lies within the bounding box of [a, b] (used once collinear).
bool within_box(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  return std::min(a.x, b.x) <= c.x && c.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= c.y &&
         c.y <= std::max(a.y, b.y);
}
}  // namespace

bool point_in_ring(glm::vec2 p, const Ring& ring) {
  return point_in_ring(p, ring.data(), static_cast<Index>(ring.size()));
}

bool point_in_polygon(glm::vec2 p, const Polygon& poly) {
  if (!point_in_ring(p, poly.outer)) return false;
  for (const Ring& h : poly.holes)
    if (point_in_ring(p, h)) return false;
  return true;
}

bool point_in_circle(glm::vec2 p, const Circle& c) { return length2(p - c.center) < c.radius * c.radius; }

double signed_area2(const Ring& ring) {
  double s = 0;
  const std::size_t n = ring.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
    s += static_cast<double>(ring[j].x) * ring[i].y - static_cast<double>(ring[i].x) * ring[j].y;
  return n < 3 ? 0.0 : s;
}

double area(const Polygon& poly) {
  double a = std::abs(signed_area2(poly.outer));
  for (const Ring& h : poly.holes) a -= std::abs(signed_area2(h));
  return std::max(0.0, a * 0.5);
}

bool segments_intersect(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d, glm::vec2* point) {
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 != o2 && o3 != o4) {
    if (point != nullptr) {
      // Solve a + t (b - a) = c + u (d - c) in double.
      const double rx = static_cast<double>(b.x) - a.x, ry = static_cast<double>(b.y) - a.y;
      const double sx = static_cast<double>(d.x) - c.x, sy = static_cast<double>(d.y) - c.y;
      const double den = rx * sy - ry * sx;
      const double t =
          den != 0 ? ((static_cast<double>(c.x) - a.x) * sy - (static_cast<double>(c.y) - a.y) * sx) / den : 0.0;
      *point = glm::vec2(static_cast<float>(a.x + t * rx), static_cast<float>(a.y + t * ry));
    }
    return true;
  }
  // Collinear touching cases.
  if (o1 == 0 && within_box(a, b, c)) return true;
  if (o2 == 0 && within_box(a, b, d)) return true;
  if (o3 == 0 && within_box(c, d, a)) return true;
  if (o4 == 0 && within_box(c, d, b)) return true;
  return false;
}

std::optional<EdgePair> find_self_intersection(const Ring& ring) {
  const auto n = static_cast<std::int64_t>(ring.size());
  if (n < 3) return EdgePair{0, 0};
  auto vtx = [&](std::int64_t i) { return ring[static_cast<std::size_t>(i % n)]; };
  for (std::int64_t i = 0; i < n; ++i)
    if (vtx(i) == vtx(i + 1)) return EdgePair{i, i};
  // Adjacent edges meet at their shared vertex; they are bad only when the
  // second folds back along the first.
  for (std::int64_t i = 0; i < n; ++i) {
    const glm::vec2 a = vtx(i), b = vtx(i + 1), c = vtx(i + 2);
    if (orient(a, b, c) == 0 && dot2(b - a, c - b) < 0) return EdgePair{i, (i + 1) % n};
  }
  // Sweep: edges sorted by their smallest x; compare each with the following
  // edges until they start right of its largest x.
  std::vector<std::int64_t> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  auto min_x = [&](std::int64_t e) { return std::min(vtx(e).x, vtx(e + 1).x); };
  auto max_x = [&](std::int64_t e) { return std::max(vtx(e).x, vtx(e + 1).x); };
  std::sort(order.begin(), order.end(),
            [&](std::int64_t x, std::int64_t y) { return min_x(x) < min_x(y) || (min_x(x) == min_x(y) && x < y); });
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::int64_t e = order[k];
    const float right = max_x(e);
    for (std::size_t m = k + 1; m < order.size() && min_x(order[m]) <= right; ++m) {
      const std::int64_t f = order[m];
      const std::int64_t lo = std::min(e, f), hi = std::max(e, f);
      if (hi - lo == 1 || (lo == 0 && hi == n - 1)) continue;  // adjacent: handled above
      if (segments_intersect(vtx(e), vtx(e + 1), vtx(f), vtx(f + 1))) return EdgePair{lo, hi};
    }
  }
  return std::nullopt;
}

bool polygon_is_simple(const Polygon& poly) {
  if (find_self_intersection(poly.outer)) return false;
  std::vector<const Ring*> rings = {&poly.outer};
  for (const Ring& h : poly.holes) {
    if (find_self_intersection(h)) return false;
    rings.push_back(&h);
  }
  // Rings must not cross one another (bounding boxes first).
  for (std::size_t r = 0; r < rings.size(); ++r)
    for (std::size_t s = r + 1; s < rings.size(); ++s) {
      const Aabb A = bounds(*rings[r]), B = bounds(*rings[s]);
      if (A.max.x < B.min.x || B.max.x < A.min.x || A.max.y < B.min.y || B.max.y < A.min.y) continue;
      const Ring& R = *rings[r];
      const Ring& S = *rings[s];
      for (std::size_t i = 0; i < R.size(); ++i)
        for (std::size_t j = 0; j < S.size(); ++j)
          if (segments_intersect(R[i], R[(i + 1) % R.size()], S[j], S[(j + 1) % S.size()])) return false;
    }
  return true;
}

BoundaryPoint closest_boundary_point(glm::vec2 p, const Polygon& poly) {
  BoundaryPoint best;
  auto scan = [&](const Ring& r) {
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) {
      const glm::vec2 q = closest_point_on_segment(p, r[j], r[i]);
      const float d = length_of(p - q);
      if (d < best.distance) best = {q, d};
    }
  };
  if (!poly.outer.empty()) scan(poly.outer);
  for (const Ring& h : poly.holes)
    if (!h.empty()) scan(h);
  return best;
}

BoundaryPoint closest_boundary_point(glm::vec2 p, const Circle& c) {
  const glm::vec2 dir = normalize_or(p - c.center, glm::vec2(1.0f, 0.0f));
  const glm::vec2 q = c.center + dir * c.radius;
  return {q, length_of(p - q)};
}

float distance_to_polygon(glm::vec2 p, const Polygon& poly) {
  return point_in_polygon(p, poly) ? 0.0f : closest_boundary_point(p, poly).distance;
}

Aabb bounds(const Ring& ring) {
  Aabb b;
  for (glm::vec2 p : ring) b.add(p);
  return b;
}
Aabb bounds(const Polygon& poly) { return bounds(poly.outer); }
Aabb bounds(const Circle& c) {
  Aabb b;
  b.add(c.center - glm::vec2(c.radius));
  b.add(c.center + glm::vec2(c.radius));
  return b;
}

void append_edges(const Polygon& poly, std::vector<Segment>& out) {
  auto ring = [&](const Ring& r) {
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) out.push_back({r[j], r[i]});
  };
  if (!poly.outer.empty()) ring(poly.outer);
  for (const Ring& h : poly.holes)
    if (!h.empty()) ring(h);
}

Ring rect_ring(glm::vec2 min, glm::vec2 max) { return {min, {max.x, min.y}, max, {min.x, max.y}}; }

}  // namespace throng::sim
