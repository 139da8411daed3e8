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
  parallel_for(
      "motion.fk_batch", character_count(),
      THRONG_JOB_LAMBDA(Index c) {
        const std::int32_t J = joint_count;
        std::int32_t f = frames[c];
        f = f < 0 ? 0 : (f > frame_count - 1 ? frame_count - 1 : f);
        fk_pose(J, parents.data(), offsets.data(), clip_rotations.data() + static_cast<Index>(f) * J, nullptr,
                clip_roots[f], out_positions.data() + c * J, out_rotations.data() + c * J);
      },
      64);
}

}  // namespace throng::motion
