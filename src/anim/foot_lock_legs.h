// One character's legs locked in its pose (host and device): what
// FootLockJob (anim/foot_lock.h, the rules) runs per character, and PoseJob
// right after each character's pose, while its joints are in cache.
#pragma once

#include <cstdint>
#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "anim/foot_lock.h"
#include "core/config.h"
#include "motion/leg_ik.h"

namespace throng::anim {

// One character's frame as foot locking reads it.
struct FootLockCharacter {
  motion::BlendPoint point;             // the blend its pose shows
  motion::ClipPhases legs[2];           // each leg's synchronised clip phases (left, right)
  float ground_y = 0.0f;                // its root's height on the ground (world, m)
  float scale = 1.0f;                   // positive
  const std::uint32_t* mask = nullptr;  // its joint mask; null = every joint
};

namespace foot_lock_detail {

THRONG_HOST_DEVICE inline bool in_subtree(const std::int32_t* parents, std::int32_t j, std::int32_t top) {
  for (std::int32_t p = j; p >= 0; p = parents[p])
    if (p == top) return true;
  return false;
}

THRONG_HOST_DEVICE inline glm::vec2 ground_xz(const glm::vec3& p) { return {p.x, p.z}; }

// Moves one leg's ankle by `shift` (world): two-bone IK turns thigh and
// knee (motion::two_bone_ik), the foot keeps its world rotation, and every
// joint of the leg's subtree follows the bone it hangs from.
THRONG_HOST_DEVICE inline void reach_with_leg(const motion::BlendSpaceView& v, int leg, float scale,
                                              const glm::vec3& shift, glm::vec3* p, glm::quat* r) {
  const motion::LegChain& chain = v.legs[leg];
  const std::int32_t n = chain.count;
  const std::int32_t thigh = chain.joints[n - 3], knee = chain.joints[n - 2], ankle = chain.joints[n - 1];
  const glm::vec3 hip = p[thigh], knee_was = p[knee], ankle_was = p[ankle];
  const glm::quat thigh_was = r[thigh], knee_rot_was = r[knee];
  glm::quat rt = thigh_was, rk = knee_rot_was;
  const glm::vec3 hinge(chain.hinge[0], chain.hinge[1], chain.hinge[2]);
  if (!motion::two_bone_ik(hip, scale * v.offsets[knee], scale * v.offsets[ankle], hinge, ankle_was + shift, rt, rk))
    return;
  const glm::vec3 knee_now = hip + rt * (scale * v.offsets[knee]);
  const glm::vec3 ankle_now = knee_now + rk * (scale * v.offsets[ankle]);
  const glm::quat turn_thigh = rt * glm::inverse(thigh_was), turn_knee = rk * glm::inverse(knee_rot_was);
  for (std::int32_t j = thigh + 1; j < v.joint_count; ++j) {
    if (v.joint_group[j] != 1 + leg) continue;
    if (in_subtree(v.parents, j, ankle)) {
      p[j] += ankle_now - ankle_was;
    } else if (in_subtree(v.parents, j, knee)) {
      p[j] = knee_now + turn_knee * (p[j] - knee_was);
      r[j] = turn_knee * r[j];
    } else {
      p[j] = hip + turn_thigh * (p[j] - hip);
      r[j] = turn_thigh * r[j];
    }
  }
  r[thigh] = rt;
}

// A step of the foot's own: in its first kStepShift the correction shrinks
// smoothly to none, the foot going over to where the pose puts it; then it
// comes down vertically, held there (the pose's foot turns on with the
// body while it descends).
inline constexpr float kStepShift = 0.5f;
THRONG_HOST_DEVICE inline float step_remaining(float progress) {
  const float u = glm::clamp(progress / kStepShift, 0.0f, 1.0f);
  return 1.0f - u * u * (3.0f - 2.0f * u);
}

// How high a stepping foot is (m, scale 1) at how far on its step is.
THRONG_HOST_DEVICE inline float step_lift(const FootLockConfig& config, const FootLock& lock) {
  return config.step_height_m * glm::sin(3.14159265f * (1.0f - lock.step_left / config.step_s));
}

// The length of a correction at most `most` (m).
THRONG_HOST_DEVICE inline glm::vec2 capped(const glm::vec2& correction, float most) {
  const float length = glm::length(correction);
  return length > most ? correction * (most / length) : correction;
}

// One frame (dt > 0) of such a step, given how far the pose's ankle moved
// since the last frame.
THRONG_HOST_DEVICE inline void take_step(const FootLockConfig& config, float dt, const glm::vec2& moved, FootLock& lock,
                                         glm::vec2& correction) {
  const float was = 1.0f - lock.step_left / config.step_s;
  lock.step_left = glm::max(lock.step_left - dt, 0.0f);
  const float progress = 1.0f - lock.step_left / config.step_s;
  if (was < kStepShift) {
    const float before = step_remaining(was);
    correction *= before > 0.0f ? step_remaining(progress) / before : 0.0f;
  } else {
    correction -= moved;
  }
}

// The correction carried on to this frame while the foot is not stepping;
// heel_down: the pinned point is the ankle, else the ball of the foot.
THRONG_HOST_DEVICE inline glm::vec2 carried_correction(const FootLockConfig& config, float dt, float scale, bool down,
                                                       bool heel_down, const glm::vec3& ankle, const glm::vec3& ball,
                                                       const FootLock& lock) {
  glm::vec2 correction = lock.correction;
  if (down && lock.down) {
    correction -= heel_down ? ground_xz(ankle) - lock.ankle : ground_xz(ball) - lock.ball;
  } else if (!down) {
    correction *= glm::exp(-dt / config.release_s);
  }
  return capped(correction, config.max_correction_m * scale);
}

inline constexpr float kTouchdownHeight = 0.005f;
// A foot low (within kHoldHeight of its ground, m at scale 1) whose posed
// ankle moves slower than kHoldSpeed is held too, though its clip has it in
// the air: creeping in a jam, the clips keep their cadence and shorten the
// stride, so a swing drags a few centimetres over the ground at a few
// centimetres a second, and held it lifts and sets down instead (a held
// foot left far behind takes a step of its own, as a planted one).
inline constexpr float kHoldHeight = 0.05f;
inline constexpr float kHoldSpeed = 1.0f;  // m/s
// A foot whose posed ankle moved farther in a frame than any walk takes it
// (kJumpM plus kJumpSpeed for each second of the frame) was moved with its
// character: across a periodic seam, or placed anew. Its leg starts again
// from no correction, as after CrowdAnimator::place().
inline constexpr float kJumpM = 1.0f;
inline constexpr float kJumpSpeed = 5.0f;  // m/s

// One leg: the correction carried on (FootLock), then the leg moved by it.
// locks: the character's two legs' state (the other leg's is read too).
THRONG_HOST_DEVICE inline void lock_leg(const motion::BlendSpaceView& v, const FootLockConfig& config, float dt,
                                        const FootLockCharacter& ch, int leg, FootLock* locks, glm::vec3* p,
                                        glm::quat* r) {
  FootLock& lock = locks[leg];
  if (!motion::plants_leg(v, leg, ch.mask)) {
    lock = FootLock{};
    return;
  }
  const float scale = ch.scale;
  const motion::BlendPoint& point = ch.point;
  const motion::LegChain& chain = v.legs[leg];
  const std::int32_t ankle = chain.joints[chain.count - 1];
  const glm::vec3 a = p[ankle];
  const glm::vec3 ball =
      chain.has_ball ? a + r[ankle] * (scale * glm::vec3(chain.ball[0], chain.ball[1], chain.ball[2])) : a;
  // The ankle's height over its lowest in the blend (m, scale 1): a heel on
  // the ground (within kTouchdownHeight) is down even where the clip's
  // touchdown is still to come, as frames a tenth of a second apart catch
  // the heel's last glide in.
  const float ground =
      motion::mix_weight(v.clips[point.a].ankle_ground[leg], v.clips[point.b].ankle_ground[leg], point.w);
  const float height = (a.y - ch.ground_y) / scale - ground;
  const bool low_and_slow = lock.seen && dt > 0.0f && height < kHoldHeight &&
                            glm::length(ground_xz(a) - lock.ankle) < kHoldSpeed * dt * scale;
  bool down = foot_down_in_blend(v, point, ch.legs[leg], leg) || height < kTouchdownHeight || low_and_slow;
  const bool jumped = glm::length(ground_xz(a) - lock.ankle) > (kJumpM + kJumpSpeed * dt) * scale;
  if (!lock.seen || jumped) lock = FootLock{};
  glm::vec2 correction = lock.correction;
  float lift = 0.0f;
  if (lock.step_left > 0.0f) {
    if (dt > 0.0f) {
      take_step(config, dt, ground_xz(a) - lock.ankle, lock, correction);
      correction = capped(correction, config.max_correction_m * scale);
    }
    lift = step_lift(config, lock);         // also while paused (dt = 0)
    down = down && lock.step_left <= 0.0f;  // planted from the frame the step lands
  } else if (dt > 0.0f) {
    // The pinned point: the ankle while the heel is down, then the ball.
    correction = carried_correction(config, dt, scale, down, height < motion::kHeelLift, a, ball, lock);
    const FootLock& other = locks[1 - leg];
    if (down && lock.down && other.step_left <= 0.0f && glm::length(correction) > config.step_threshold_m * scale)
      lock.step_left = config.step_s;
  }
  lock.correction = correction;
  lock.ankle = ground_xz(a);
  lock.ball = ground_xz(ball);
  lock.seen = 1;
  lock.down = down ? 1 : 0;
  if (glm::dot(correction, correction) > 1e-12f || lift > 0.0f)
    reach_with_leg(v, leg, scale, {correction.x, scale * lift, correction.y}, p, r);
}

}  // namespace foot_lock_detail

// Both legs of one character (locks: its two FootLock, left then right),
// in place in its world joints p and r.
THRONG_HOST_DEVICE inline void lock_feet(const motion::BlendSpaceView& v, const FootLockConfig& config, float dt,
                                         const FootLockCharacter& ch, FootLock* locks, glm::vec3* p, glm::quat* r) {
  for (int leg = 0; leg < 2; ++leg) foot_lock_detail::lock_leg(v, config, dt, ch, leg, locks, p, r);
}

}  // namespace throng::anim
