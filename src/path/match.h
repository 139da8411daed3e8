// Motion-path matching (the 2012 paper's path layer).
//
// A resampled path (points every s metres, path/spline.h) is cut into
// curves of k points, arc length d = k s. For every (curve c, motion m) pair
// the motion's root trajectory q_0..q_{k-1} (in its own frame: q_0 at the
// origin, leaving along +x) is turned onto the curve's start tangent t_c and
// moved to its start point p_0, and the Euclidean distances are summed:
//
//   E(c, m) = sum_i | p_i - (p_0 + R(t_c) q_i) |  +  w_v k |v_m - v_c|
//
// (the paper's Eq. 4.5 prints a square root of a difference; this is the
// Euclidean distance it means). The speed term, with w_v = speed_weight,
// lets a desired speed v_c choose between walking and running; v_c = 0
// leaves it out. A curve inside a marked stretch only accepts motions of the
// marked state. The grid of curves x motions is one parallel_for
// ("path.match_grid", match_kernels.cpp, also a CUDA kernel); the best motion
// per curve is a second one ("path.match_best").
//
// Greedy (the paper): each curve takes its best motion. Past the paper:
// dynamic programming over the state machine's transitions chooses the whole
// sequence minimising sum E + sum transition cost, so consecutive motions
// are always connectable (choose_sequences).
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/buffer.h"
#include "core/config.h"
#include "core/span.h"
#include "path/spline.h"
#include "path/state_machine.h"

namespace throng::path {

inline constexpr float kNoMatch = 3.0e38f;  // cost of a forbidden (curve, motion) pair

// E(c, m) for one pair: k points of the curve, its unit start tangent and
// the motion's k trajectory points.
THRONG_HOST_DEVICE inline float curve_motion_distance(const glm::vec2* curve, glm::vec2 tangent,
                                                      const glm::vec2* motion, std::int32_t k) {
  const glm::vec2 p0 = curve[0];
  float sum = 0.0f;
  for (std::int32_t i = 0; i < k; ++i) {
    const glm::vec2 q = motion[i];
    const glm::vec2 placed(p0.x + tangent.x * q.x - tangent.y * q.y, p0.y + tangent.y * q.x + tangent.x * q.y);
    const glm::vec2 d = curve[i] - placed;
    sum += sqrtf(d.x * d.x + d.y * d.y);
  }
  return sum;
}

// Curves of many paths, flattened for the grid.
struct CurveSet {
  std::int32_t k = 0;
  std::vector<glm::vec2> points;             // [curves * k]
  std::vector<glm::vec2> tangents;           // [curves]: unit tangent at each curve's first point
  std::vector<std::int32_t> required_state;  // [curves]: machine state index, or -1
  std::vector<float> speed;                  // [curves]: desired speed, m/s (0 = any)
  std::vector<std::int32_t> path_begin;      // [paths + 1]: curves of path p are [path_begin[p], path_begin[p+1])
  std::int32_t curve_count() const { return static_cast<std::int32_t>(tangents.size()); }
  std::int32_t path_count() const { return static_cast<std::int32_t>(path_begin.size()) - 1; }
};

// Cuts every path into whole curves of machine.k() points (the tail shorter
// than d is left out). Marks must name states of the machine (Error otherwise).
// desired_speed: one per path, or empty (0 = any).
CurveSet cut_paths(std::span<const ResampledPath> paths, const MotionGraph& machine,
                   std::span<const float> desired_speed = {});

// The grid job: cost[c * motions + m] = E(c, m) (+ speed term), or kNoMatch.
struct MatchGridJob {
  std::int32_t k = 0;
  std::int32_t motions = 0;
  float speed_weight = 0.0f;
  Span<const glm::vec2> motion_points;    // [motions * k]
  Span<const std::int32_t> motion_state;  // [motions]
  Span<const float> motion_speed;         // [motions]
  Span<const glm::vec2> curve_points;     // [curves * k]
  Span<const glm::vec2> curve_tangents;   // [curves]
  Span<const std::int32_t> curve_state;   // [curves]
  Span<const float> curve_speed;          // [curves]
  Span<float> cost;                       // [curves * motions]
  void validate() const;
  void run() const;
};

// best[c] = argmin_m cost[c * motions + m] (lowest index on ties).
struct BestMotionJob {
  std::int32_t motions = 0;
  Span<const float> cost;
  Span<std::int32_t> best;
  Span<float> best_cost;
  void validate() const;
  void run() const;
};

struct MatchOptions {
  float speed_weight = 0.2f;  // s: cost per point of 1 m/s speed mismatch, in metres
  void validate() const;
};

// The machine's locomotion segments and the curves, uploaded once to
// current_memory(); match() fills the grid and the greedy choice.
class MatchGrid {
 public:
  MatchGrid(const MotionGraph& machine, const CurveSet& curves, const MatchOptions& options = {});
  void match();
  std::int32_t motions() const { return motions_; }
  std::int32_t curves() const { return curves_; }
  // Host copies after match(): [curves * motions] (grid motion index m is
  // machine.locomotion_segments()[m]), best grid index per curve.
  std::vector<float> cost() const { return cost_.to_vector(); }
  std::vector<std::int32_t> best() const { return best_.to_vector(); }

 private:
  MatchGridJob job_;
  std::int32_t motions_ = 0, curves_ = 0;
  Buffer<glm::vec2> motion_points_, curve_points_, curve_tangents_;
  Buffer<std::int32_t> motion_state_, curve_state_;
  Buffer<float> motion_speed_, curve_speed_;
  Buffer<float> cost_, best_cost_;
  Buffer<std::int32_t> best_;
};

// A sequence of machine segments for one path: one per curve, plus the
// start and end segments (-1 when the machine names no start/end state).
struct Sequence {
  std::vector<std::int32_t> segments;  // machine segment ids, one per curve
  std::int32_t start_segment = -1;
  std::int32_t end_segment = -1;
  double match_cost = 0;       // sum of E over the curves (kNoMatch pairs count as such)
  double transition_cost = 0;  // sum over consecutive pairs (legal ones), start and end included
  std::int32_t illegal = 0;    // transitions the machine forbids
  double path_error = 0;       // mean distance per point (the geometric part of E), m
  double total() const { return illegal > 0 ? INFINITY : match_cost + transition_cost; }
};

// Scores a given sequence of grid motion indices for the curves of path p.
// start/end segments are chosen as the cheapest legal ones (or the cheapest
// at all, counted illegal, when none is legal).
Sequence score_sequence(const MotionGraph& machine, const CurveSet& curves, std::span<const float> cost,
                        std::int32_t path, std::span<const std::int32_t> grid_motions);

// Greedy: each curve's best motion (the grid's argmin).
std::vector<Sequence> greedy_sequences(const MotionGraph& machine, const CurveSet& curves, std::span<const float> cost,
                                       std::span<const std::int32_t> best);
// Greedy repaired to legality: each curve takes its best motion among those
// its predecessor may be followed by (the last also must reach the end
// state); illegal > 0 when even that fails.
std::vector<Sequence> repaired_greedy_sequences(const MotionGraph& machine, const CurveSet& curves,
                                                std::span<const float> cost);
// Dynamic programming over the machine's transitions, per path in parallel
// ("path.match_dp"): the legal sequence of least total cost (illegal > 0
// only when no legal sequence exists).
std::vector<Sequence> dp_sequences(const MotionGraph& machine, const CurveSet& curves, std::span<const float> cost);

}  // namespace throng::path
