// Foot locking kernel: compiled by nvcc in CUDA builds, by g++ otherwise.
#include "anim/foot_lock_legs.h"
#include "anim/lod.h"
#include "core/parallel.h"

namespace throng::anim {

void FootLockJob::run() const {
  validate();
  parallel_for(
      "anim.foot_lock", character_count(),
      THRONG_JOB_LAMBDA(Index c) {
        const motion::BlendSpaceView& v = blend;
        FootLockCharacter ch;
        ch.point = motion::blend_point(v, motion::blend_coordinate(v, blend_speeds[c]));
        for (int leg = 0; leg < 2; ++leg)
          ch.legs[leg] = motion::warp_phase(v.sync[ch.point.segment].group[1 + leg], ch.point.w, phases[c]);
        ch.ground_y = positions[c].y;
        ch.scale = scales.empty() || !(scales[c] > 0.0f) ? 1.0f : scales[c];  // as PoseJob
        ch.mask = joint_masks.empty() ? nullptr : joint_masks.data() + c * mask_word_count(v.joint_count);
        lock_feet(v, config, dt, ch, locks.data() + 2 * c, joint_positions.data() + c * v.joint_count,
                  joint_rotations.data() + c * v.joint_count);
      },
      64);
}

}  // namespace throng::anim
