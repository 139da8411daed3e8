// The path layer's curve: a C1 cubic spline through a polyline's points,
// resampled by arc length (T -> T1), with marked stretches that carry a
// fixed motion state (T2).
//
// Spline: cubic Hermite pieces on chord-length knots t_0 = 0,
// t_{i+1} = t_i + |p_{i+1} - p_i|, with Catmull-Rom tangents
//   m_i = (p_{i+1} - p_{i-1}) / (t_{i+1} - t_{i-1})   (interior knots),
//   m_0 = (p_1 - p_0) / (t_1 - t_0),  m_n = (p_n - p_{n-1}) / (t_n - t_{n-1}).
// Piece i, u in [0, 1], h = t_{i+1} - t_i:
//   P(u) = h00(u) p_i + h10(u) h m_i + h01(u) p_{i+1} + h11(u) h m_{i+1}
// with h00 = 2u^3 - 3u^2 + 1, h10 = u^3 - 2u^2 + u, h01 = -2u^3 + 3u^2,
// h11 = u^3 - u^2. dP/dt at t_i is m_i from both sides: C1 at every knot.
// Long polyline edges are first split so knots are at most `max_knot_spacing`
// apart: the curve then hugs the polyline and rounds its corners over about
// one knot spacing (its largest deviation is reported).
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <span>
#include <string>
#include <vector>

namespace throng::path {

class HermiteSpline {
 public:
  HermiteSpline() = default;
  // Through `points` (consecutive duplicates dropped; at least 2 distinct).
  explicit HermiteSpline(std::span<const glm::vec2> points);

  std::int32_t piece_count() const { return static_cast<std::int32_t>(knots_.size()) - 1; }
  const std::vector<glm::vec2>& knots() const { return knots_; }
  const std::vector<float>& knot_params() const { return t_; }
  // Position and derivative (d/dt) on piece i at u in [0, 1].
  glm::vec2 position(std::int32_t piece, float u) const;
  glm::vec2 derivative(std::int32_t piece, float u) const;

 private:
  std::vector<glm::vec2> knots_;
  std::vector<glm::vec2> tangents_;
  std::vector<float> t_;
};

// A stretch of the path [from, to] (arc length along the input polyline,
// metres) where the character must be in `state` (e.g. crawl under a bar).
struct PathMark {
  float from = 0.0f;
  float to = 0.0f;
  std::string state;
};

struct ResampleOptions {
  float spacing = 0.0225f;        // s, m: the clips' root step per frame
  float max_knot_spacing = 1.0f;  // m: polyline edges longer than this get extra knots
  void validate() const;          // throws Error naming the field
};

// T1 (and T2): points every `spacing` metres of arc length along the spline,
// with unit tangents; fixed_state[i] is the index into `mark_states` of the
// mark covering point i, or -1.
struct ResampledPath {
  float spacing = 0.0f;
  std::vector<glm::vec2> points;
  std::vector<glm::vec2> tangents;
  std::vector<float> arc;                 // arc length of each point along the spline
  std::vector<std::int32_t> fixed_state;  // -1 = free
  std::vector<std::string> mark_states;   // names, one per mark
  float spline_length = 0.0f;             // m
  float max_polyline_deviation = 0.0f;    // m: largest distance from a sample to the input polyline
};

// Fits the spline through `polyline` and resamples it. Marks are given in
// arc length along the polyline and mapped to the spline by proportion.
ResampledPath resample_path(std::span<const glm::vec2> polyline, const ResampleOptions& options,
                            std::span<const PathMark> marks = {});

}  // namespace throng::path
