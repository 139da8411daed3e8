#include "anim/foot_lock.h"

#include <cmath>

#include "core/check.h"
#include "core/error.h"

namespace throng::anim {

void FootLockConfig::validate() const {
  if (!(std::isfinite(max_correction_m) && max_correction_m >= 0.0f && max_correction_m <= 2.0f))
    throw Error("must be in [0, 2] m", at_field("foot_lock.max_correction_m"));
  if (!(std::isfinite(release_s) && release_s > 0.0f && release_s <= 10.0f))
    throw Error("must be in (0, 10] s", at_field("foot_lock.release_s"));
  if (!(std::isfinite(step_threshold_m) && step_threshold_m > 0.0f && step_threshold_m <= 2.0f))
    throw Error("must be in (0, 2] m", at_field("foot_lock.step_threshold_m"));
  if (!(std::isfinite(step_s) && step_s > 0.0f && step_s <= 10.0f))
    throw Error("must be in (0, 10] s", at_field("foot_lock.step_s"));
  if (!(std::isfinite(step_height_m) && step_height_m >= 0.0f && step_height_m <= 1.0f))
    throw Error("must be in [0, 1] m", at_field("foot_lock.step_height_m"));
  if (!(step_threshold_m < max_correction_m))
    throw Error("must be below max_correction_m (no step could start)", at_field("foot_lock.step_threshold_m"));
}

void FootLockJob::validate() const {
  config.validate();
  if (blend.joint_count < 1 || blend.clip_count < 1 || blend.clips == nullptr || blend.sync == nullptr ||
      blend.parents == nullptr || blend.offsets == nullptr || blend.joint_group == nullptr)
    throw Error("is not set (BlendSpaceTables::view())", at_field("FootLockJob.blend"));
  if (!(std::isfinite(dt) && dt >= 0.0f && dt <= 10.0f))
    throw Error("must be in [0, 10] s", at_field("FootLockJob.dt"));
  const Index n = character_count();
  const Index J = blend.joint_count;
  check_optional_length("FootLockJob", "scales", scales.size(), n);
  check_length("FootLockJob", "phases", phases.size(), n);
  check_length("FootLockJob", "blend_speeds", blend_speeds.size(), n);
  check_optional_length("FootLockJob", "joint_masks", joint_masks.size(), n * ((J + 31) / 32));
  check_length("FootLockJob", "locks", locks.size(), 2 * n);
  check_length("FootLockJob", "joint_positions", joint_positions.size(), n * J);
  check_length("FootLockJob", "joint_rotations", joint_rotations.size(), n * J);
}

}  // namespace throng::anim
