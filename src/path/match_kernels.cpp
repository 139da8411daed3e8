// The matching grid as kernels: one body for CPU threads and CUDA.
#include "core/error.h"
#include "core/parallel.h"
#include "path/match.h"

namespace throng::path {

void MatchGridJob::validate() const {
  if (k < 1) throw Error("k must be >= 1", at_field("match.k"));
  if (motions < 1) throw Error("the grid needs at least one motion", at_field("match.motions"));
  const Index curves = curve_tangents.size();
  if (motion_points.size() != Index{motions} * k || motion_state.size() != motions || motion_speed.size() != motions)
    throw Error("motion arrays disagree with motions * k", at_field("match.motion_points"));
  if (curve_points.size() != curves * k || curve_state.size() != curves || curve_speed.size() != curves)
    throw Error("curve arrays disagree with curves * k", at_field("match.curve_points"));
  if (cost.size() != curves * motions) throw Error("cost must hold curves * motions entries", at_field("match.cost"));
  if (!(speed_weight >= 0)) throw Error("speed weight must be >= 0", at_field("match.speed_weight"));
}

void MatchGridJob::run() const {
  validate();
  const MatchGridJob j = *this;
  const Index n = curve_tangents.size() * motions;
  parallel_for(
      "path.match_grid", n,
      THRONG_LAMBDA(Index i) {
        const Index c = i / j.motions;
        const Index m = i - c * j.motions;
        const std::int32_t required = j.curve_state[c];
        if (required >= 0 && j.motion_state[m] != required) {
          j.cost[i] = kNoMatch;
          return;
        }
        float e = curve_motion_distance(j.curve_points.data() + c * j.k, j.curve_tangents[c],
                                        j.motion_points.data() + m * j.k, j.k);
        const float v = j.curve_speed[c];
        if (v > 0.0f) e += j.speed_weight * static_cast<float>(j.k) * fabsf(j.motion_speed[m] - v);
        j.cost[i] = e;
      },
      64);
}

void BestMotionJob::validate() const {
  if (motions < 1) throw Error("the grid needs at least one motion", at_field("match.motions"));
  if (cost.size() != best.size() * motions || best_cost.size() != best.size())
    throw Error("cost must hold curves * motions entries", at_field("match.cost"));
}

void BestMotionJob::run() const {
  validate();
  const BestMotionJob j = *this;
  parallel_for(
      "path.match_best", best.size(),
      THRONG_LAMBDA(Index c) {
        const float* row = j.cost.data() + c * j.motions;
        std::int32_t arg = 0;
        float low = row[0];
        for (std::int32_t m = 1; m < j.motions; ++m)
          if (row[m] < low) {
            low = row[m];
            arg = m;
          }
        j.best[c] = arg;
        j.best_cost[c] = low;
      },
      256);
}

}  // namespace throng::path
