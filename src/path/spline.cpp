#include "path/spline.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "sim/geometry.h"

namespace throng::path {

HermiteSpline::HermiteSpline(std::span<const glm::vec2> points) {
  for (glm::vec2 p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw Error("spline point is not finite", at_field("path.points"));
    if (knots_.empty() || sim::length2(p - knots_.back()) > 1e-12f) knots_.push_back(p);
  }
  if (knots_.size() < 2) throw Error("a path needs at least two distinct points", at_field("path.points"));
  const std::size_t n = knots_.size();
  t_.assign(n, 0.0f);
  for (std::size_t i = 1; i < n; ++i) t_[i] = t_[i - 1] + sim::length_of(knots_[i] - knots_[i - 1]);
  tangents_.resize(n);
  tangents_[0] = (knots_[1] - knots_[0]) / (t_[1] - t_[0]);
  tangents_[n - 1] = (knots_[n - 1] - knots_[n - 2]) / (t_[n - 1] - t_[n - 2]);
  for (std::size_t i = 1; i + 1 < n; ++i) tangents_[i] = (knots_[i + 1] - knots_[i - 1]) / (t_[i + 1] - t_[i - 1]);
}

glm::vec2 HermiteSpline::position(std::int32_t piece, float u) const {
  const auto i = static_cast<std::size_t>(piece);
  const float h = t_[i + 1] - t_[i];
  const float u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * knots_[i] + (u3 - 2 * u2 + u) * h * tangents_[i] + (-2 * u3 + 3 * u2) * knots_[i + 1] +
         (u3 - u2) * h * tangents_[i + 1];
}

glm::vec2 HermiteSpline::derivative(std::int32_t piece, float u) const {
  const auto i = static_cast<std::size_t>(piece);
  const float h = t_[i + 1] - t_[i];
  const float u2 = u * u;
  // d/du of the basis, divided by h for d/dt.
  return ((6 * u2 - 6 * u) * knots_[i] + (3 * u2 - 4 * u + 1) * h * tangents_[i] + (-6 * u2 + 6 * u) * knots_[i + 1] +
          (3 * u2 - 2 * u) * h * tangents_[i + 1]) /
         h;
}

void ResampleOptions::validate() const {
  if (!(std::isfinite(spacing) && spacing >= 1e-4f && spacing <= 10.0f))
    throw Error("spacing must be in [1e-4, 10] m", at_field("resample.spacing"));
  if (!(std::isfinite(max_knot_spacing) && max_knot_spacing >= spacing))
    throw Error("max knot spacing must be >= spacing", at_field("resample.max_knot_spacing"));
}

namespace {

// The polyline's points with extra knots on edges longer than
// max_knot_spacing (m): n equal pieces each.
std::vector<glm::vec2> densify(std::span<const glm::vec2> polyline, float max_knot_spacing) {
  std::vector<glm::vec2> dense;
  for (std::size_t i = 0; i < polyline.size(); ++i) {
    if (i > 0) {
      const glm::vec2 a = polyline[i - 1], b = polyline[i];
      const int n = std::max(1, static_cast<int>(std::ceil(sim::length_of(b - a) / max_knot_spacing)));
      for (int k = 1; k < n; ++k) dense.push_back(a + (b - a) * (static_cast<float>(k) / n));
    }
    dense.push_back(polyline[i]);
  }
  return dense;
}

// Spline arc length (m, double) at sub-steps of at most half the spacing
// per piece (at least 8), and at each knot.
struct ArcTable {
  struct Sample {
    double arc;
    std::int32_t piece;
    float u;
  };
  std::vector<Sample> samples;
  std::vector<double> knot_arc;  // spline arc length at each knot
  double length = 0;             // of the whole spline
};

ArcTable arc_table(const HermiteSpline& spline, float spacing) {
  const auto& kt = spline.knot_params();
  ArcTable table;
  table.knot_arc = {0.0};
  double arc = 0;
  table.samples.push_back({0.0, 0, 0.0f});
  for (std::int32_t i = 0; i < spline.piece_count(); ++i) {
    const float h = kt[static_cast<std::size_t>(i) + 1] - kt[static_cast<std::size_t>(i)];
    const int m = std::max(8, static_cast<int>(std::ceil(2.0f * h / spacing)));
    glm::vec2 prev = spline.position(i, 0.0f);
    for (int k = 1; k <= m; ++k) {
      const float u = static_cast<float>(k) / static_cast<float>(m);
      const glm::vec2 p = spline.position(i, u);
      arc += static_cast<double>(sim::length_of(p - prev));
      prev = p;
      table.samples.push_back({arc, i, u});
    }
    table.knot_arc.push_back(arc);
  }
  table.length = arc;
  return table;
}

// Appends the spline's point at (piece, u) with its unit tangent and arc
// length (m), and raises out's deviation from the (densified) polyline near
// this piece.
void emit(ResampledPath& out, const HermiteSpline& spline, std::int32_t piece, float u, double at_arc) {
  const auto& knots = spline.knots();
  out.points.push_back(spline.position(piece, u));
  out.tangents.push_back(sim::normalize_or(spline.derivative(piece, u), glm::vec2(1.0f, 0.0f)));
  out.arc.push_back(static_cast<float>(at_arc));
  float dev = INFINITY;
  for (std::int32_t k = std::max(0, piece - 1); k <= std::min(spline.piece_count() - 1, piece + 1); ++k)
    dev = std::min(dev, sim::distance_to_segment(out.points.back(), knots[static_cast<std::size_t>(k)],
                                                 knots[static_cast<std::size_t>(k) + 1]));
  out.max_polyline_deviation = std::max(out.max_polyline_deviation, dev);
}

// Emits the points of `out`: each at distance `spacing` (m, Euclidean) from
// the previous one, the first such point along the curve: the table
// brackets it (its sub-steps are at most half the spacing), bisection
// places it. Where the curve bends, the arc between points is a little
// longer than the chord.
void place_points(const HermiteSpline& spline, const ArcTable& table, float spacing, ResampledPath& out) {
  const double s2 = static_cast<double>(spacing) * spacing;
  auto sample_pos = [&](const ArcTable::Sample& x) { return spline.position(x.piece, x.u); };
  auto far_enough = [&](glm::vec2 p) {
    const glm::dvec2 d = glm::dvec2(p) - glm::dvec2(out.points.back());
    return d.x * d.x + d.y * d.y >= s2;
  };
  emit(out, spline, 0, 0.0f, 0.0);
  std::size_t cursor = 0;
  for (;;) {
    while (cursor + 1 < table.samples.size() && !far_enough(sample_pos(table.samples[cursor + 1]))) ++cursor;
    if (cursor + 1 >= table.samples.size()) break;
    const ArcTable::Sample& a = table.samples[cursor];
    const ArcTable::Sample& b = table.samples[cursor + 1];
    const float ua = a.piece == b.piece ? a.u : 0.0f;  // a sample at the previous piece's end is u = 0 here
    float lo = 0.0f, hi = 1.0f;
    for (int it = 0; it < 40; ++it) {
      const float mid = 0.5f * (lo + hi);
      (far_enough(spline.position(b.piece, ua + mid * (b.u - ua))) ? hi : lo) = mid;
    }
    emit(out, spline, b.piece, ua + hi * (b.u - ua), a.arc + hi * (b.arc - a.arc));
    if (out.points.size() > 50'000'000)
      throw Error("path needs more than 50,000,000 points: raise the spacing", at_field("resample.spacing"));
  }
}

// Sets out.fixed_state (and out.mark_states) from the marks. Polyline arc
// length equals the chord-length knot parameter, so it maps to spline arc
// length (m) by interpolating between knots.
void apply_marks(std::span<const PathMark> marks, const HermiteSpline& spline, const ArcTable& table,
                 ResampledPath& out) {
  const auto& kt = spline.knot_params();
  out.fixed_state.assign(out.points.size(), -1);
  auto spline_arc = [&](float poly_arc) {
    const auto it = std::upper_bound(kt.begin(), kt.end(), poly_arc);
    if (it == kt.begin()) return 0.0;
    if (it == kt.end()) return table.length;
    const auto i = static_cast<std::size_t>(it - kt.begin()) - 1;
    const double f = (poly_arc - kt[i]) / (kt[i + 1] - kt[i]);
    return table.knot_arc[i] + f * (table.knot_arc[i + 1] - table.knot_arc[i]);
  };
  for (std::size_t k = 0; k < marks.size(); ++k) {
    const PathMark& m = marks[k];
    if (!(std::isfinite(m.from) && std::isfinite(m.to) && m.from >= 0 && m.to > m.from))
      throw Error(fmt::format("mark needs 0 <= from < to, got [{}, {}]", m.from, m.to),
                  at_field(fmt::format("marks[{}]", k)));
    if (m.state.empty()) throw Error("mark needs a state", at_field(fmt::format("marks[{}].state", k)));
    auto found = std::find(out.mark_states.begin(), out.mark_states.end(), m.state);
    const auto id = static_cast<std::int32_t>(found - out.mark_states.begin());
    if (found == out.mark_states.end()) out.mark_states.push_back(m.state);
    const double lo = spline_arc(m.from), hi = spline_arc(m.to);
    for (std::size_t j = 0; j < out.points.size(); ++j)
      if (out.arc[j] >= lo && out.arc[j] <= hi) out.fixed_state[j] = id;
  }
}

}  // namespace

// Stages: densified knots, the spline and its arc-length table, points at
// the spacing, marks.
ResampledPath resample_path(std::span<const glm::vec2> polyline, const ResampleOptions& options,
                            std::span<const PathMark> marks) {
  options.validate();
  const std::vector<glm::vec2> dense = densify(polyline, options.max_knot_spacing);
  const HermiteSpline spline(dense);
  const ArcTable table = arc_table(spline, options.spacing);
  ResampledPath out;
  out.spacing = options.spacing;
  out.spline_length = static_cast<float>(table.length);
  place_points(spline, table, options.spacing, out);
  apply_marks(marks, spline, table, out);
  return out;
}

}  // namespace throng::path
