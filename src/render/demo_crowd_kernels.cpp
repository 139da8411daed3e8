#include "render/demo_crowd_kernels.h"

#include <glm/gtc/quaternion.hpp>

#include "anim/lod.h"
#include "anim/motion_cache.h"
#include "core/ground.h"
#include "core/parallel.h"

namespace throng::render {

namespace {
// One clip's local rotation of joint j, between two neighbouring frames.
struct ClipBetweenFrames {
  const glm::quat* a;
  const glm::quat* b;
  float t;
  THRONG_HOST_DEVICE glm::quat operator()(std::int32_t j) const { return glm::slerp(a[j], b[j], t); }
};
}  // namespace

void demo_pose(const DemoPose& p) {
  const DemoPose q = p;
  const std::int32_t J = p.joint_count, W = anim::mask_word_count(p.joint_count);
  parallel_for("render.demo_pose", p.phases.size(), THRONG_LAMBDA(Index c) {
    const motion::CyclePoint at = motion::cycle_point(q.frame_count, q.phases[c]);
    const ClipBetweenFrames evaluate{q.clip_rotations.data() + static_cast<Index>(at.f0) * J,
                                     q.clip_rotations.data() + static_cast<Index>(at.f1) * J, at.t};
    q.evaluated[c] = anim::masked_pose(J, q.parents.data(), q.offsets.data(), q.joint_masks.data() + c * W, evaluate, nullptr,
                                       q.root_positions[c], q.out_positions.data() + c * J, q.out_rotations.data() + c * J);
  }, 64);
}

void demo_roots(const DemoPlacement& p) {
  const DemoPlacement q = p;
  parallel_for("render.demo_roots", p.phases.size(), THRONG_LAMBDA(Index c) {
    const double t = q.seconds + static_cast<double>(q.phase_offset[c]);
    const double cycles = t / static_cast<double>(q.clip_duration);
    const float phase = static_cast<float>(cycles - floor(cycles));
    q.phases[c] = phase;
    const anim::CyclePoint at = anim::cycle_point(q.clip_frames, phase);
    q.model_roots[c] = q.clip_roots[at.f0] + (q.clip_roots[at.f1] - q.clip_roots[at.f0]) * at.t;
    const float travelled = static_cast<float>(t) * q.speed[c];
    if (q.ring) {
      // Counter-clockwise seen from above: map heading = angle + pi/2.
      const float r = q.radius[c];
      const float angle = q.angle0[c] + (r > 0.0f ? travelled / r : 0.0f);
      q.ground[c] = world_from_ground(glm::vec2(r * cosf(angle), r * sinf(angle)));
      q.yaws[c] = yaw_from_heading(angle + kHalfPi);
    } else {
      const float yaw = q.yaw0[c];
      // Facing +Z at yaw 0; yaw turns towards +X.
      glm::vec3 w = q.base[c] + travelled * glm::vec3(sinf(yaw), 0.0f, cosf(yaw));
      if (q.grid_side > 0.0f) {
        const float half = 0.5f * q.grid_side;
        w.x = w.x + half - q.grid_side * floorf((w.x + half) / q.grid_side) - half;
        w.z = w.z + half - q.grid_side * floorf((w.z + half) / q.grid_side) - half;
      }
      q.ground[c] = w;
      q.yaws[c] = yaw;
    }
  });
}

void demo_place(std::int32_t joint_count, Span<const glm::vec3> ground, Span<const float> yaws, Span<glm::vec3> positions,
                Span<glm::quat> rotations) {
  const std::int32_t J = joint_count;
  parallel_for(
      "render.demo_place", ground.size(), THRONG_LAMBDA(Index c) {
        const float half = 0.5f * yaws[c];
        const glm::quat turn(cosf(half), 0.0f, sinf(half), 0.0f);  // about +Y
        const glm::vec3 at = ground[c];
        for (std::int32_t j = 0; j < J; ++j) {
          const Index k = c * J + j;
          positions[k] = at + turn * positions[k];
          rotations[k] = turn * rotations[k];
        }
      },
      256);
}

}  // namespace throng::render
