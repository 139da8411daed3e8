// Locomotion synthesis against independent references: SLERP through the
// exponential map, the input clips' own frames and forward kinematics,
// closed-form lines and circles, and the foot-skating measure.
#include "motion/locomotion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "core/error.h"
#include "motion/default_set.h"
#include "tests/motion/reference_rotation.h"

namespace throng::motion {
namespace {

constexpr double kPi = 3.14159265358979323846;

const BlendSpace1D& default_space() {
  static const BlendSpace1D space = make_default_blend_space();
  return space;
}

using test::reference_slerp;
using test::rotation_between_deg;

// slerp_shortest's weights are a polynomial (no acos, no sine): against
// SLERP through the exponential map (double), on random pairs and on a
// sweep of half angles up to pi/2 (opposite rotations, where the series
// is worst), it turns within 1e-5 rad of the true rotation and stays unit.
TEST(LocomotionSlerp, SlerpShortestMatchesTheExponentialMapAndKeepsEndsExact) {
  constexpr double kDeg = kPi / 180.0;
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double worst = 0.0, worst_length = 0.0;
  const auto check = [&](const glm::quat& a, const glm::quat& b, float t) {
    const glm::quat q = slerp_shortest(a, b, t);
    ASSERT_TRUE(std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z)) << t;
    worst =
        std::max(worst, rotation_between_deg(glm::dquat(q), reference_slerp(glm::dquat(a), glm::dquat(b), t)) * kDeg);
    worst_length = std::max(worst_length, std::abs(glm::length(glm::dquat(q)) - 1.0));
  };
  for (int i = 0; i < 4000; ++i) {
    const glm::quat a = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
    glm::quat b = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
    if (i % 2 == 0) b = -b;  // the other hemisphere: must still take the short way
    check(a, b, u(rng));
  }
  for (int i = 0; i <= 400; ++i) {
    const float h = static_cast<float>(i) / 400.0f * static_cast<float>(kPi / 2.0);  // half angle
    const glm::quat a = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
    const glm::vec3 axis = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    const glm::quat b = a * glm::angleAxis(2.0f * h, axis);
    for (int k = 1; k < 40; ++k) check(a, b, static_cast<float>(k) / 40.0f);
  }
  std::printf("polynomial SLERP within %.2e rad of the exponential map, |q| within %.1e of 1\n", worst, worst_length);
  EXPECT_LT(worst, 1e-5);
  EXPECT_LT(worst_length, 1e-6);
  const glm::quat a(0.5f, 0.5f, 0.5f, 0.5f), b(0.0f, 1.0f, 0.0f, 0.0f);
  EXPECT_EQ(slerp_shortest(a, b, 0.0f), a);
  EXPECT_EQ(slerp_shortest(a, b, 1.0f), b);
}

// Within a clip, neighbouring frames are interpolated by normalised lerp:
// on every pair of neighbouring frames of every clip (up to ~18 degrees
// apart: a fast run's toes), at several fractions, it stays within 0.01
// degrees of SLERP (the error grows with the cube of the angle).
TEST(LocomotionSlerp, NeighbouringFramesInterpolateAsSlerpDoes) {
  const BlendSpace1D& space = default_space();
  double worst = 0.0, widest = 0.0;
  for (const LocomotionClip& c : space.clips()) {
    const std::int32_t F = c.frame_count();
    for (std::int32_t i = 0; i < F; ++i)
      for (std::int32_t j = 0; j < space.joint_count(); ++j) {
        const glm::quat a = c.cycle.rotation(i, j), b = c.cycle.rotation((i + 1) % F, j);
        widest = std::max(widest, rotation_between_deg(glm::dquat(a), glm::dquat(b)));
        for (float t : {0.1f, 0.25f, 0.5f, 0.8f})
          worst = std::max(worst, rotation_between_deg(glm::dquat(interpolate_frames(a, b, t)),
                                                       reference_slerp(glm::dquat(a), glm::dquat(b), t)));
      }
  }
  std::printf("neighbouring frames up to %.2f deg apart; normalised lerp within %.2e deg of SLERP\n", widest, worst);
  EXPECT_LT(worst, 1e-2);
}

TEST(LocomotionSlerp, BlendedRotationIsTheReferenceSlerpOfBothClipsSamples) {
  const BlendSpace1D& space = default_space();
  const BlendSpaceView v = space.view();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double worst = 0.0;
  for (int i = 0; i < 3000; ++i) {
    const float x = u(rng) * static_cast<float>(v.clip_count - 1);
    const BlendPoint p = blend_point(v, x);
    const ClipPhases ph = warp_phase(v.sync[p.segment].group[0], p.w, u(rng));
    const auto j = static_cast<std::int32_t>(u(rng) * static_cast<float>(v.joint_count - 1));
    const glm::dquat want =
        reference_slerp(glm::dquat(clip_rotation(v, p.a, ph.a, j)), glm::dquat(clip_rotation(v, p.b, ph.b, j)), p.w);
    worst = std::max(worst, rotation_between_deg(glm::dquat(blended_rotation(v, p, ph, j)), want));
  }
  EXPECT_LT(worst, 2e-3);
}

// The pose stage samples each joint once (synthesise_locals) and hands the
// samples to the leg IK; the reference samples on every call
// (plant_legs + synthesised_rotation). Same bits, with and without masks
// (one that turns a leg's knee off turns its IK off).
TEST(LocomotionPose, SamplingEachJointOnceChangesNoBit) {
  const BlendSpace1D& space = default_space();
  const BlendSpaceView v = space.view();
  const std::int32_t J = v.joint_count;
  ASSERT_LE(J, 32);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::quat> local(static_cast<std::size_t>(J));
  int planted = 0;
  for (int i = 0; i < 2000; ++i) {
    const float speed = u(rng) * 1.2f * space.max_speed();
    const CharacterFrame f = character_frame(v, speed, u(rng), glm::vec3(0.0f), 0.0f, 1.0f);
    std::uint32_t bits = i % 3 == 0 ? 0xffffffffu : static_cast<std::uint32_t>(rng());
    bits |= 1u;  // the root
    const std::uint32_t* mask = i % 3 == 1 ? nullptr : &bits;
    std::fill(local.begin(), local.end(), glm::quat(2.0f, 2.0f, 2.0f, 2.0f));
    const PlantedLegs got = synthesise_locals(v, f, mask, local.data());
    const PlantedLegs want = plant_legs(v, f, mask);
    ASSERT_EQ(got.active[0], want.active[0]) << i;
    ASSERT_EQ(got.active[1], want.active[1]) << i;
    ASSERT_EQ(got.pelvis_drop, want.pelvis_drop) << i;
    planted += got.active[0] ? 1 : 0;
    for (std::int32_t j = 0; j < J; ++j) {
      if (!mask_bit(mask, j)) {  // not written
        ASSERT_EQ(local[static_cast<std::size_t>(j)], glm::quat(2.0f, 2.0f, 2.0f, 2.0f)) << i << " joint " << j;
        continue;
      }
      const glm::quat r = synthesised_rotation(v, f, want, j);
      ASSERT_EQ(std::memcmp(&local[static_cast<std::size_t>(j)], &r, sizeof r), 0) << i << " joint " << j;
    }
  }
  EXPECT_GT(planted, 200);  // the IK ran, on its own samples
}

// The pose with polynomial SLERP against the same pose with exact SLERP
// (the exponential map in double) in the blend and in the IK's blended
// leg: every joint's local and world rotation within 0.001 degrees (the
// polynomial's own error, 3.5e-4 degrees, is all that may show).
struct ExactSlerpSampler {
  const BlendSpaceView* v;
  const CharacterFrame* f;
  glm::quat blended(std::int32_t joint) const {
    const std::uint8_t g = v->joint_group[joint];
    const glm::quat a = clip_rotation(*v, f->rows[g][0], joint), b = clip_rotation(*v, f->rows[g][1], joint);
    const float w = f->point.w;
    if (w <= 0.0f) return a;
    if (w >= 1.0f) return b;
    return glm::quat(reference_slerp(glm::dquat(a), glm::dquat(b), w));
  }
  glm::quat clip(int leg, int c, std::int32_t joint) const { return clip_rotation(*v, f->rows[1 + leg][c], joint); }
};
TEST(LocomotionPose, PolynomialSlerpPoseWithinAHundredthOfADegreeOfExactSlerp) {
  const BlendSpace1D& space = default_space();
  const BlendSpaceView v = space.view();
  const std::int32_t J = v.joint_count;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::quat> local(static_cast<std::size_t>(J)), exact(static_cast<std::size_t>(J));
  std::vector<glm::dquat> world(static_cast<std::size_t>(J)), world_exact(static_cast<std::size_t>(J));
  double worst_local = 0.0, worst_world = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const CharacterFrame f = character_frame(v, u(rng) * space.max_speed(), u(rng), glm::vec3(0.0f), 0.0f, 1.0f);
    synthesise_locals(v, f, nullptr, local.data());
    const ExactSlerpSampler sampler{&v, &f};
    const PlantedLegs legs = plant_legs(v, f, nullptr, sampler);
    for (std::int32_t j = 0; j < J; ++j) exact[static_cast<std::size_t>(j)] = sampler.blended(j);
    for (int leg = 0; leg < 2; ++leg)
      for (int k = 0; k < 3 && legs.active[leg]; ++k)
        exact[static_cast<std::size_t>(v.legs[leg].joints[v.legs[leg].count - 3 + k])] = legs.corrected[leg][k];
    for (std::int32_t j = 0; j < J; ++j) {
      const auto at = static_cast<std::size_t>(j);
      const std::int32_t p = v.parents[j];
      world[at] = (p < 0 ? glm::dquat(1, 0, 0, 0) : world[static_cast<std::size_t>(p)]) * glm::dquat(local[at]);
      world_exact[at] =
          (p < 0 ? glm::dquat(1, 0, 0, 0) : world_exact[static_cast<std::size_t>(p)]) * glm::dquat(exact[at]);
      const double d_local = rotation_between_deg(glm::dquat(local[at]), glm::dquat(exact[at]));
      const double d_world = rotation_between_deg(world[at], world_exact[at]);
      ASSERT_TRUE(std::isfinite(d_local) && std::isfinite(d_world)) << i << " joint " << j;
      worst_local = std::max(worst_local, d_local);
      worst_world = std::max(worst_world, d_world);
    }
  }
  std::printf("pose with polynomial SLERP: local within %.2e deg, world within %.2e deg of exact SLERP\n", worst_local,
              worst_world);
  EXPECT_LT(worst_local, 1e-3);  // the bound asked of it is 0.01
  EXPECT_LT(worst_world, 1e-3);
}

TEST(LocomotionPrepare, DefaultClipsBecomeCyclesWithTheirSpeedStrideAndEvents) {
  const BlendSpace1D& space = default_space();
  ASSERT_EQ(space.clip_count(), 6);
  const Skeleton skeleton = default_skeleton();
  for (const DefaultMotion& m : make_default_motions(skeleton)) {
    if (m.spec.turn_rate != 0.0) continue;
    const LocomotionClip* c = nullptr;
    for (const LocomotionClip& k : space.clips())
      if (k.name == m.spec.name) c = &k;
    ASSERT_NE(c, nullptr) << m.spec.name;
    EXPECT_NEAR(c->speed, m.spec.speed, 1e-4) << c->name;
    EXPECT_NEAR(c->period_s, m.targets.period_s, 1e-6) << c->name;
    EXPECT_NEAR(c->stride_m, m.spec.speed * m.targets.period_s, 1e-4) << c->name;
    EXPECT_NEAR(c->turn_removed_rad, 0.0, 1e-3) << c->name;
    if (m.spec.gait == biomech::Gait::Stand) {
      for (float e : c->events) EXPECT_LT(e, 0.0f) << c->name;  // no steps
      continue;
    }
    // Left touchdown at frame 0 (the generator starts there), right at half a cycle.
    EXPECT_EQ(c->event(FootEvent::LeftDown), 0.0f) << c->name;
    EXPECT_NEAR(c->event(FootEvent::RightDown), 0.5, 1.5 / c->frame_count()) << c->name;
    // Liftoff at the duty factor (within the contact detector's frame or two).
    EXPECT_NEAR(c->event(FootEvent::LeftUp), m.targets.duty_factor, 3.0 / c->frame_count() + 0.03) << c->name;
    // The root's offset from the path is centred.
    glm::dvec3 mean(0.0);
    for (const glm::vec3& o : c->cycle.root_positions) mean += glm::dvec3(o);
    mean /= static_cast<double>(c->frame_count());
    EXPECT_NEAR(mean.x, 0.0, 1e-5) << c->name;
    EXPECT_NEAR(mean.z, 0.0, 1e-5) << c->name;
  }
}

// w = 0 (and w = 1 at the fastest clip) plays the input clip: its local
// rotations at its frames, and its pose relative to the root in the root's
// heading frame, from an independent FK of the input clip.
TEST(LocomotionBlend, EndsOfTheBlendReproduceTheInputClips) {
  const BlendSpace1D& space = default_space();
  const BlendSpaceView v = space.view();
  const Skeleton skeleton = default_skeleton();
  const auto motions = make_default_motions(skeleton);
  for (std::int32_t k = 0; k < space.clip_count(); ++k) {
    const LocomotionClip& c = space.clips()[static_cast<std::size_t>(k)];
    const Clip* input = nullptr;
    for (const DefaultMotion& m : motions)
      if (m.spec.name == c.name) input = &m.clip;
    ASSERT_NE(input, nullptr);
    const ModelSpaceClip fk = forward_kinematics(skeleton, *input);
    const std::int32_t F = c.frame_count(), J = v.joint_count;
    const BlendPoint p = blend_point(v, static_cast<float>(k));
    ASSERT_TRUE((p.w == 0.0f && p.a == k) || (p.w == 1.0f && p.b == k)) << c.name;
    double worst_rotation = 0.0, worst_position = 0.0;
    std::vector<glm::vec3> pos(static_cast<std::size_t>(J));
    std::vector<glm::quat> rot(static_cast<std::size_t>(J));
    for (std::int32_t i = 0; i < F; ++i) {
      const float phase = (static_cast<float>(i) + 1e-4f) / static_cast<float>(F);  // on frame i
      const CharacterFrame f = character_frame_at(v, p, phase, glm::vec3(0.0f), 0.0f, 1.0f);
      const std::int32_t src = (i + c.source_start_frame) % F;
      for (std::int32_t j = 1; j < J; ++j)
        worst_rotation = std::max(worst_rotation, rotation_between_deg(glm::dquat(joint_rotation(v, f, j)),
                                                                       glm::dquat(input->rotation(src, j))));
      synthesise_pose(v, f, pos.data(), rot.data());
      // Joints relative to the root, in the root's heading frame.
      const double ours = heading_of(rot[0]), theirs = heading_of(fk.rotations[static_cast<std::size_t>(src * J)]);
      for (std::int32_t j = 0; j < J; ++j) {
        const glm::dvec3 a =
            glm::angleAxis(-ours, glm::dvec3(0, 1, 0)) * glm::dvec3(pos[static_cast<std::size_t>(j)] - pos[0]);
        const glm::dvec3 b =
            glm::angleAxis(-theirs, glm::dvec3(0, 1, 0)) * glm::dvec3(fk.position(src, j) - fk.position(src, 0));
        worst_position = std::max(worst_position, glm::length(a - b));
      }
      EXPECT_NEAR(pos[0].y, input->root_positions[static_cast<std::size_t>(src)].y, 1e-5) << c.name << " frame " << i;
    }
    EXPECT_LT(worst_rotation, 0.02) << c.name;  // degrees: 1e-4 of a frame's motion
    EXPECT_LT(worst_position, 2e-4) << c.name;  // metres
  }
}

// The blended root moves by w d^b + (1 - w) d^a per step (Eq. 10): over any
// stretch of phase, the root's displacement relative to the path point
// changes as the lerp of the clips' own root displacements over their
// (warped) phases.
TEST(LocomotionBlend, RootDisplacementIsTheLerpOfTheClipsDisplacements) {
  const BlendSpaceView v = default_space().view();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    const BlendPoint p = blend_point(v, u(rng) * static_cast<float>(v.clip_count - 1));
    const float phase0 = u(rng), phase1 = phase0 + 0.05f * u(rng);
    const auto root_travel =
        [&](float phase) {  // root in the world of a character whose path point advances L_w per cycle
          const ClipPhases ph = warp_phase(v.sync[p.segment].group[0], p.w, phase);
          return blended_root_offset(v, p, phase, ph).position + glm::vec3(0.0f, 0.0f, blended_stride(v, p) * phase);
        };
    const auto clip_travel = [&](std::int32_t clip, float phase) {  // a clip's root in its own world
      return clip_root_offset(v, clip, phase) + glm::vec3(0.0f, 0.0f, v.clips[clip].stride * phase);
    };
    const ClipPhases a = warp_phase(v.sync[p.segment].group[0], p.w, phase0);
    const ClipPhases b = warp_phase(v.sync[p.segment].group[0], p.w, phase1);
    if (b.a < a.a || b.b < a.b) continue;  // a clip's phase wrapped: its own world restarts
    const glm::vec3 d_blend = root_travel(phase1) - root_travel(phase0);
    const glm::vec3 d_a = clip_travel(p.a, b.a) - clip_travel(p.a, a.a);
    const glm::vec3 d_b = clip_travel(p.b, b.b) - clip_travel(p.b, a.b);
    worst = std::max(worst, static_cast<double>(glm::length(d_blend - ((1.0f - p.w) * d_a + p.w * d_b))));
  }
  EXPECT_LT(worst, 1e-5);
}

TEST(LocomotionBlend, SpeedIsTheLerpOfClipSpeedsAndCadenceFollows) {
  const BlendSpaceView v = default_space().view();
  for (std::int32_t k = 0; k + 1 < v.clip_count; ++k)
    for (float w : {0.0f, 0.25f, 0.5f, 0.9f}) {
      const float speed = mix_weight(v.clips[k].speed, v.clips[k + 1].speed, w);
      const BlendPoint p = blend_point(v, blend_coordinate(v, speed));
      EXPECT_EQ(p.segment, k);
      EXPECT_NEAR(p.w, w, 1e-5);
      // One cycle covers the blended stride at the cycle rate: speed = stride * rate.
      EXPECT_NEAR(blended_stride(v, p) * cycle_rate(v, p, speed), speed, 1e-5 * (1.0f + speed));
      // The blended cadence lies between the two clips' (idle: the walk's).
      const float rate = cycle_rate(v, p, speed);
      const float ra = 1.0f / v.clips[k].period, rb = 1.0f / v.clips[k + 1].period;
      if (v.clips[k].stride > kMinStride) {
        EXPECT_GE(rate, std::min(ra, rb) - 1e-5f);
        EXPECT_LE(rate, std::max(ra, rb) + 1e-5f);
      }
    }
  // Beyond the fastest clip it plays faster, with the same stride.
  const BlendPoint top = blend_point(v, blend_coordinate(v, 6.0f));
  EXPECT_EQ(top.w, 1.0f);
  EXPECT_NEAR(cycle_rate(v, top, 6.0f) * v.clips[v.clip_count - 1].stride, 6.0f, 1e-4);
}

TEST(LocomotionSync, EachClipIsAtItsEventWhenTheBlendIsAtItsMarker) {
  const BlendSpace1D& space = default_space();
  for (const SegmentSync& s : space.sync())
    for (const SyncMarkers& m : s.group)
      for (float w : {0.1f, 0.5f, 0.8f})
        for (std::int32_t k = 0; k < m.count; ++k) {
          const float canonical = mix_weight(m.a[k], m.b[k], w);
          const ClipPhases ph = warp_phase(m, w, canonical + 1e-6f);
          EXPECT_NEAR(ph.a, wrap_phase(m.a[k]), 2e-5);
          EXPECT_NEAR(ph.b, wrap_phase(m.b[k]), 2e-5);
        }
  // Walk with walk aligns all four events; walk with run the legs separately.
  const SegmentSync& walks = space.sync()[1];
  EXPECT_EQ(walks.group[0].count, 4);
  const SegmentSync& walk_run = space.sync()[3];
  EXPECT_EQ(walk_run.group[0].count, 2);  // touchdowns
  EXPECT_EQ(walk_run.group[1].count, 2);  // left down and up
  EXPECT_EQ(walk_run.group[2].count, 2);  // right down and up
}

TEST(LocomotionRootMotion, StraightLineMatchesTheClosedForm) {
  const BlendSpaceView v = default_space().view();
  for (float speed : {0.7f, 1.5f, 3.3f, 5.2f}) {
    LocomotionStep step;
    step.dt = 1.0f / 60.0f;
    glm::vec3 p(3.0f, 0.0f, -2.0f);
    float yaw = 0.6f, phase = 0.3f, shown = -1.0f;
    const int frames = 600;
    for (int i = 0; i < frames; ++i) advance_locomotion(v, step, speed, 0.0f, 0.0f, 1.0f, p, yaw, phase, shown);
    const double d = static_cast<double>(speed) * frames * step.dt;
    EXPECT_NEAR(p.x, 3.0 + d * std::sin(0.6), 2e-5 * d) << speed;
    EXPECT_NEAR(p.z, -2.0 + d * std::cos(0.6), 2e-5 * d) << speed;
    EXPECT_FLOAT_EQ(p.y, 0.0f);
    EXPECT_NEAR(yaw, 0.6f, 1e-6) << speed;
  }
}

TEST(LocomotionRootMotion, ConstantTurnStaysOnItsCircle) {
  const BlendSpaceView v = default_space().view();
  for (const auto& [speed, rate] : {std::pair{1.2f, 0.4f}, std::pair{2.5f, -0.9f}, std::pair{0.8f, 1.3f}}) {
    LocomotionStep step;
    step.dt = 1.0f / 30.0f;
    glm::vec3 p(1.0f, 0.0f, 2.0f);
    float yaw = -1.0f, phase = 0.0f, shown = -1.0f;
    const double r = speed / rate;  // signed: the centre is on the left (+X at yaw 0) for left turns
    const glm::dvec3 centre = glm::dvec3(p) + glm::dvec3(r * std::cos(-1.0), 0.0, -r * std::sin(-1.0));
    const int frames = 900;
    double worst = 0.0;
    for (int i = 0; i < frames; ++i) {
      advance_locomotion(v, step, speed, rate, 0.0f, 1.0f, p, yaw, phase, shown);
      worst = std::max(worst, std::abs(glm::length(glm::dvec3(p) - centre) - std::abs(r)));
    }
    EXPECT_LT(worst, 1e-4 * std::abs(r) + 1e-4) << speed << " " << rate;
    const double want_yaw = std::remainder(-1.0 + rate * frames * step.dt, 2.0 * kPi);
    EXPECT_NEAR(std::remainder(yaw - want_yaw, 2.0 * kPi), 0.0, 1e-3) << speed << " " << rate;
  }
}

TEST(LocomotionRootMotion, CurvatureKeepsTheCircleWhateverTheSpeed) {
  const BlendSpaceView v = default_space().view();
  LocomotionStep step;
  glm::vec3 p(10.0f, 0.0f, 0.0f);                // on a circle of radius 10 round the origin
  float yaw = kPi, phase = 0.0f, shown = -1.0f;  // facing -Z: left turns go round the origin
  double worst = 0.0;
  for (int i = 0; i < 1200; ++i) {
    const float speed = 0.5f + 3.5f * static_cast<float>((i / 150) % 4) / 3.0f;  // changes every 2.5 s
    advance_locomotion(v, step, speed, 0.0f, 0.1f, 1.0f, p, yaw, phase, shown);
    worst = std::max(worst, std::abs(glm::length(glm::dvec2(p.x, p.z)) - 10.0));
  }
  EXPECT_LT(worst, 2e-3);
}

TEST(LocomotionPaperMode, TheBlendChangesOnlyWhenACycleEnds) {
  const BlendSpaceView v = default_space().view();
  LocomotionStep step;
  step.hold_until_cycle_end = true;
  glm::vec3 p(0.0f);
  float yaw = 0.0f, phase = 0.0f, shown = -1.0f;
  advance_locomotion(v, step, 1.2f, 0.0f, 0.0f, 1.0f, p, yaw, phase, shown);
  EXPECT_EQ(shown, 1.2f);
  int changes = 0;
  for (int i = 0; i < 400; ++i) {
    const float before_phase = phase, before = shown;
    advance_locomotion(v, step, i < 50 ? 1.2f : 3.0f, 0.0f, 0.0f, 1.0f, p, yaw, phase, shown);
    if (shown != before) {
      ++changes;
      EXPECT_LT(phase, before_phase) << "changed without the phase wrapping";
    }
  }
  EXPECT_EQ(changes, 1);
  EXPECT_EQ(shown, 3.0f);
  // Continuous mode takes the new speed at once.
  step.hold_until_cycle_end = false;
  advance_locomotion(v, step, 2.0f, 0.0f, 0.0f, 1.0f, p, yaw, phase, shown);
  EXPECT_EQ(shown, 2.0f);
}

// The acceptance figure: straight constant-speed locomotion at ten speeds
// spread over (0, fastest clip], foot skating per contact below 2 cm.
TEST(LocomotionFootSkating, DefaultSetBelowTwoCentimetresAtTenSpeeds) {
  const BlendSpace1D& space = default_space();
  std::printf("%8s %9s %9s %9s %9s\n", "speed", "contacts", "mean_cm", "p95_cm", "max_cm");
  for (int i = 1; i <= 10; ++i) {
    const float speed = space.max_speed() * static_cast<float>(i) / 10.0f;
    const FootSkatingReport r = locomotion_foot_skating(space, speed, 8.0);
    std::printf("%8.2f %9d %9.3f %9.3f %9.3f\n", speed, r.contacts, r.mean_cm, r.p95_cm, r.max_cm);
    EXPECT_GE(r.contacts, 10) << speed;
    EXPECT_LT(r.mean_cm, 2.0) << speed;
  }
}

// Without the leg IK the same blends slide more: the measure sees it.
TEST(LocomotionFootSkating, PlantingTheFeetIsWhatKeepsBlendsFromSliding) {
  const BlendSpace1D& space = default_space();
  BlendSpaceOptions off;
  off.plant_feet = false;
  const BlendSpace1D loose(space.skeleton(), space.clips(), off);
  const float speed = 0.6f;  // idle <-> walk_slow, w = 0.6
  const FootSkatingReport with_ik = locomotion_foot_skating(space, speed, 8.0);
  const FootSkatingReport without = locomotion_foot_skating(loose, speed, 8.0);
  EXPECT_GE(with_ik.contacts, 10);
  EXPECT_GE(without.contacts, 10);
  EXPECT_LT(with_ik.mean_cm, 0.5 * without.mean_cm);
}

TEST(LocomotionErrors, BadSetsAndClipsAreNamed) {
  const BlendSpace1D& space = default_space();
  std::vector<LocomotionClip> twins{space.clips()[1], space.clips()[1]};
  twins[1].name = "walk_twin";
  try {
    BlendSpace1D bad(space.skeleton(), twins);
    FAIL() << "accepted two clips of the same speed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("walk_twin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(BlendSpace1D(space.skeleton(), {}), Error);
  Skeleton smaller = space.skeleton();
  smaller.add_joint("Extra", 0, glm::vec3(0.1f));
  EXPECT_THROW(BlendSpace1D(smaller, {space.clips()[0]}), Error);
  Clip short_clip;
  short_clip.resize(3, space.joint_count());
  EXPECT_THROW(prepare_locomotion_cycle(space.skeleton(), short_clip, "short"), Error);
  LocomotionOptions o;
  o.max_cleanup_m = -1.0;
  EXPECT_THROW(o.validate(), Error);
}

}  // namespace
}  // namespace throng::motion
