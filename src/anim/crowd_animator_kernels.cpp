// Locomotion and pose kernels: compiled by nvcc in CUDA builds, by g++ otherwise.
#include "anim/crowd_animator.h"
#include "anim/foot_lock_legs.h"
#include "core/check.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/parallel.h"
#include "core/reduce.h"

namespace throng::anim {

namespace {

// masked_pose's evaluator when a character synthesises: the local rotations
// synthesise_locals wrote into the output (masked_pose reads joint j before
// it writes j's world rotation there); the root's goes into its world frame.
struct SynthesisedJoint {
  const glm::quat* local;
  glm::quat frame;
  THRONG_HOST_DEVICE glm::quat operator()(std::int32_t joint) const {
    return joint == 0 ? frame * local[0] : local[joint];
  }
};

// ... and when it reads a cached cycle: between two neighbouring cycle frames.
struct CachedJoint {
  const glm::quat* a;
  const glm::quat* b;
  float t;
  glm::quat frame;
  THRONG_HOST_DEVICE glm::quat operator()(std::int32_t joint) const {
    const glm::quat q = motion::interpolate_frames(a[joint], b[joint], t);
    return joint == 0 ? frame * q : q;
  }
};

}  // namespace

void LocomoteJob::run() const {
  validate();
  parallel_for(
      "anim.locomote", character_count(),
      THRONG_JOB_LAMBDA(Index c) {
        glm::vec3 p = positions[c];
        float y = yaws[c], ph = phases[c], b = blend_speeds[c];
        motion::advance_locomotion(blend, step, speeds[c], turn_rates.empty() ? 0.0f : turn_rates[c],
                                   curvatures.empty() ? 0.0f : curvatures[c], scales.empty() ? 1.0f : scales[c], p, y,
                                   ph, b);
        positions[c] = p;
        yaws[c] = y;
        phases[c] = ph;
        blend_speeds[c] = b;
      },
      256);
}

void MapInputJob::run() const {
  validate();
  parallel_for(
      "anim.from_map", character_count(),
      THRONG_JOB_LAMBDA(Index c) {
        positions[c] = world_from_ground(map_positions[c]);
        yaws[c] = motion::wrap_angle(yaw_from_heading(map_headings[c]));
        speeds[c] = glm::length(map_velocities[c]);
      },
      1024);
}

namespace {

// Character c's joints, from its cached cycle slot when the cache holds its
// blend point, else synthesised; its counters and draw matrices.
THRONG_HOST_DEVICE inline void pose_character(const PoseJob& job, Index c) {
  const motion::BlendSpaceView& view = job.blend;
  const CycleCacheView& cache = job.cache;
  const std::int32_t J = view.joint_count;
  const motion::CharacterFrame f = motion::character_frame(view, job.blend_speeds[c], job.phases[c], job.positions[c],
                                                           job.yaws[c], job.scales.empty() ? 1.0f : job.scales[c]);
  const std::uint32_t* mask = job.joint_masks.empty() ? nullptr : job.joint_masks.data() + c * mask_word_count(J);
  const glm::quat* held = motion::held_rotations(view, f.point);
  glm::vec3* joints_p = job.joint_positions.data() + c * J;
  glm::quat* joints_r = job.joint_rotations.data() + c * J;
  const std::int32_t slot =
      cache.slots.empty() ? -1 : cache.slots[cache_key(f.point, cache.bucket_width, cache.bucket_count)];
  std::int32_t n = 0;
  if (slot >= 0) {
    const motion::CyclePoint cp = motion::cycle_point(cache.frames, f.phase);
    const glm::quat* cycle = cache.cycles.data() + static_cast<Index>(slot) * cache.frames * J;
    const CachedJoint e{cycle + static_cast<Index>(cp.f0) * J, cycle + static_cast<Index>(cp.f1) * J, cp.t, f.frame};
    const float* drop = cache.drops.data() + static_cast<Index>(slot) * cache.frames;
    const float lowered = f.scale * (drop[cp.f0] + cp.t * (drop[cp.f1] - drop[cp.f0]));
    n = masked_pose(J, view.parents, view.offsets, mask, e, held, f.root_position - glm::vec3(0.0f, lowered, 0.0f),
                    joints_p, joints_r, f.scale);
  } else {
    const motion::PlantedLegs legs = motion::synthesise_locals(view, f, mask, joints_r);
    const SynthesisedJoint e{joints_r, f.frame};
    n = masked_pose(J, view.parents, view.offsets, mask, e, held,
                    f.root_position - glm::vec3(0.0f, f.scale * legs.pelvis_drop, 0.0f), joints_p, joints_r, f.scale);
  }
  if (!job.locks.empty()) {
    FootLockCharacter ch;
    ch.point = f.point;
    ch.legs[0] = f.phases[1];
    ch.legs[1] = f.phases[2];
    ch.ground_y = job.positions[c].y;
    ch.scale = f.scale;
    ch.mask = mask;
    lock_feet(view, job.lock_config, job.lock_dt, ch, job.locks.data() + 2 * c, joints_p, joints_r);
  }
  if (!job.evaluated.empty()) job.evaluated[c] = n;
  if (!job.from_cache.empty()) job.from_cache[c] = slot >= 0 ? 1 : 0;
  if (!job.draw_matrices.empty())
    character_draw_matrices(J, joints_p, joints_r, f.scale, job.joint_shapes.data(), job.draw_matrices.data() + c * J);
}

}  // namespace

void PoseJob::run() const {
  validate();
  parallel_for(
      "anim.pose", character_count(), THRONG_JOB_LAMBDA(Index c) { pose_character(*this, c); }, 32);
}

PoseTotals pose_totals(Span<const std::int32_t> evaluated, Span<const std::uint8_t> from_cache) {
  PoseTotals t;
  t.joints_synthesised = parallel_reduce(
      "anim.pose_totals", evaluated.size(), Index{0},
      THRONG_LAMBDA(Index c) { return static_cast<Index>(evaluated[c]); }, Plus{});
  t.from_cache = parallel_reduce(
      "anim.pose_totals", from_cache.size(), Index{0},
      THRONG_LAMBDA(Index c) { return static_cast<Index>(from_cache[c]); }, Plus{});
  return t;
}

std::vector<Index> cache_key_counts(const motion::BlendSpaceView& blend, Span<const float> blend_speeds,
                                    float bucket_width, std::int32_t bucket_count) {
  if (blend.clip_count < 1 || bucket_count < 1) throw Error("needs clips and buckets", at_field("cache_key_counts"));
  const Index keys = static_cast<Index>(blend.segment_count()) * bucket_count;
  const motion::BlendSpaceView view = blend;
  const auto shown = blend_speeds;
  return deterministic_histogram(
      "anim.cache_keys", blend_speeds.size(), static_cast<std::int32_t>(keys), THRONG_LAMBDA(Index c) {
        return cache_key(motion::blend_point(view, motion::blend_coordinate(view, shown[c])), bucket_width,
                         bucket_count);
      });
}

}  // namespace throng::anim
