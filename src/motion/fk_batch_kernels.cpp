#include <string>

#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"
#include "motion/fk.h"
#include "motion/fk_batch.h"

namespace throng::motion {

void BatchFkJob::validate() const {
  if (joint_count <= 0) throw Error("must be positive", at_field("BatchFkJob.joint_count"));
  if (frame_count <= 0) throw Error("must be positive", at_field("BatchFkJob.frame_count"));
  const Index J = joint_count;
  check_length("BatchFkJob", "parents", parents.size(), J);
  check_length("BatchFkJob", "offsets", offsets.size(), J);
  check_length("BatchFkJob", "clip_rotations", clip_rotations.size(), J * frame_count);
  check_length("BatchFkJob", "clip_roots", clip_roots.size(), frame_count);
  check_length("BatchFkJob", "out_positions", out_positions.size(), J * character_count());
  check_length("BatchFkJob", "out_rotations", out_rotations.size(), J * character_count());
}

void BatchFkJob::run() const {
  validate();
  const std::int32_t J = joint_count;
  const std::int32_t last = frame_count - 1;
  const auto P = parents;
  const auto O = offsets;
  const auto L = clip_rotations;
  const auto roots = clip_roots;
  const auto F = frames;
  const auto outP = out_positions;
  const auto outR = out_rotations;
  parallel_for(
      "motion.fk_batch", character_count(),
      THRONG_LAMBDA(Index c) {
        std::int32_t f = F[c];
        f = f < 0 ? 0 : (f > last ? last : f);
        fk_pose(J, P.data(), O.data(), L.data() + static_cast<Index>(f) * J, nullptr, roots[f], outP.data() + c * J,
                outR.data() + c * J);
      },
      64);
}

}  // namespace throng::motion
