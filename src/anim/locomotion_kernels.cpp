// Locomotion and pose kernels: compiled by nvcc in CUDA builds, by g++ otherwise.
#include "anim/locomotion.h"
#include "core/error.h"
#include "core/ground.h"
#include "core/parallel.h"
#include "core/reduce.h"

namespace throng::anim {

namespace {

// masked_pose's evaluator when a character synthesises: the blend of its two
// clips (with the leg IK); the root's rotation goes into its world frame.
struct SynthesisedJoint {
  const motion::BlendSpaceView* view;
  const motion::CharacterFrame* frame;
  const motion::PlantedLegs* legs;
  THRONG_HOST_DEVICE glm::quat operator()(std::int32_t joint) const {
    const glm::quat q = motion::synthesised_rotation(*view, *frame, *legs, joint);
    return joint == 0 ? frame->frame * q : q;
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
  const motion::BlendSpaceView view = blend;
  const motion::LocomotionStep s = step;
  const auto speed = speeds;
  const auto turn = turn_rates;
  const auto curve = curvatures;
  const auto scale = scales;
  const auto pos = positions;
  const auto yaw = yaws;
  const auto phase = phases;
  const auto shown = blend_speeds;
  parallel_for(
      "anim.locomote", character_count(),
      THRONG_LAMBDA(Index c) {
        glm::vec3 p = pos[c];
        float y = yaw[c], ph = phase[c], b = shown[c];
        motion::advance_locomotion(view, s, speed[c], turn.empty() ? 0.0f : turn[c], curve.empty() ? 0.0f : curve[c],
                                   scale.empty() ? 1.0f : scale[c], p, y, ph, b);
        pos[c] = p;
        yaw[c] = y;
        phase[c] = ph;
        shown[c] = b;
      },
      256);
}

void MapInputJob::run() const {
  validate();
  const auto mp = map_positions;
  const auto mv = map_velocities;
  const auto mh = map_headings;
  const auto pos = positions;
  const auto yaw = yaws;
  const auto speed = speeds;
  parallel_for(
      "anim.from_map", character_count(),
      THRONG_LAMBDA(Index c) {
        pos[c] = world_from_ground(mp[c]);
        yaw[c] = motion::wrap_angle(yaw_from_heading(mh[c]));
        speed[c] = glm::length(mv[c]);
      },
      1024);
}

void PoseJob::run() const {
  validate();
  const motion::BlendSpaceView view = blend;
  const std::int32_t J = blend.joint_count;
  const std::int32_t W = mask_word_count(J);
  const std::int32_t frames = cache_frames;
  const float width = bucket_width;
  const std::int32_t buckets = bucket_count;
  const auto pos = positions;
  const auto yaw = yaws;
  const auto scale = scales;
  const auto phase = phases;
  const auto shown = blend_speeds;
  const auto masks = joint_masks;
  const auto slots = cache_slots;
  const auto cycles = cache_cycles;
  const auto drops = cache_drops;
  const auto shapes = joint_shapes;
  const auto out_p = joint_positions;
  const auto out_r = joint_rotations;
  const auto out_draw = draw_matrices;
  const auto out_count = evaluated;
  const auto out_cache = from_cache;
  parallel_for(
      "anim.pose", character_count(),
      THRONG_LAMBDA(Index c) {
        const motion::CharacterFrame f =
            motion::character_frame(view, shown[c], phase[c], pos[c], yaw[c], scale.empty() ? 1.0f : scale[c]);
        const std::uint32_t* mask = masks.empty() ? nullptr : masks.data() + c * W;
        const glm::quat* held = motion::held_rotations(view, f.point);
        glm::vec3* joints_p = out_p.data() + c * J;
        glm::quat* joints_r = out_r.data() + c * J;
        const std::int32_t slot = slots.empty() ? -1 : slots[cache_key(f.point, width, buckets)];
        std::int32_t n = 0;
        if (slot >= 0) {
          const motion::CyclePoint cp = motion::cycle_point(frames, f.phase);
          const glm::quat* cycle = cycles.data() + static_cast<Index>(slot) * frames * J;
          const CachedJoint e{cycle + static_cast<Index>(cp.f0) * J, cycle + static_cast<Index>(cp.f1) * J, cp.t, f.frame};
          const float* drop = drops.data() + static_cast<Index>(slot) * frames;
          const float lowered = f.scale * (drop[cp.f0] + cp.t * (drop[cp.f1] - drop[cp.f0]));
          n = masked_pose(J, view.parents, view.offsets, mask, e, held, f.root_position - glm::vec3(0.0f, lowered, 0.0f), joints_p,
                          joints_r, f.scale);
        } else {
          const motion::PlantedLegs legs = motion::plant_legs(view, f, mask);
          const SynthesisedJoint e{&view, &f, &legs};
          n = masked_pose(J, view.parents, view.offsets, mask, e, held, f.root_position - glm::vec3(0.0f, f.scale * legs.pelvis_drop, 0.0f),
                          joints_p, joints_r, f.scale);
        }
        if (!out_count.empty()) out_count[c] = n;
        if (!out_cache.empty()) out_cache[c] = slot >= 0 ? 1 : 0;
        if (!out_draw.empty())
          for (std::int32_t j = 0; j < J; ++j) out_draw[c * J + j] = draw_matrix(joints_p[j], joints_r[j], f.scale, shapes[j]);
      },
      32);
}

PoseTotals pose_totals(Span<const std::int32_t> evaluated, Span<const std::uint8_t> from_cache) {
  PoseTotals t;
  t.joints_synthesised = parallel_reduce(
      "anim.pose_totals", evaluated.size(), Index{0}, THRONG_LAMBDA(Index c) { return static_cast<Index>(evaluated[c]); },
      detail::Plus{});
  t.from_cache = parallel_reduce(
      "anim.pose_totals", from_cache.size(), Index{0}, THRONG_LAMBDA(Index c) { return static_cast<Index>(from_cache[c]); },
      detail::Plus{});
  return t;
}

std::vector<Index> cache_key_counts(const motion::BlendSpaceView& blend, Span<const float> blend_speeds, float bucket_width,
                                    std::int32_t bucket_count) {
  if (blend.clip_count < 1 || bucket_count < 1) throw Error("needs clips and buckets", at_field("cache_key_counts"));
  const Index keys = static_cast<Index>(blend.segment_count()) * bucket_count;
  const motion::BlendSpaceView view = blend;
  const auto shown = blend_speeds;
  return deterministic_histogram("anim.cache_keys", blend_speeds.size(), static_cast<std::int32_t>(keys), THRONG_LAMBDA(Index c) {
    return cache_key(motion::blend_point(view, motion::blend_coordinate(view, shown[c])), bucket_width, bucket_count);
  });
}

}  // namespace throng::anim
