// 1D (speed) and 2D (speed x turn) blend controllers on the locomotion blend
// space: their poses against per-character synthesis (motion::synthesise_pose),
// their cadence against the closed form, footstep events, the 2D blend's
// limits, and both playing in streams.
#include "anim/blend_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "anim/stream_pool.h"
#include "core/error.h"
#include "stream_reference.h"
#include "tests/motion/reference_rotation.h"

namespace throng::anim {
namespace {

using namespace testing;

constexpr float kDt = 1.0f / 30.0f;

const DefaultBlendSpaces& spaces() { return default_blend_spaces(); }

// World joint positions of a pose (root at the origin, yaw 0) by the double
// reference's forward kinematics.
std::vector<glm::dvec3> joint_positions(const Rig& rig, const Pose& pose) {
  const auto M = reference_model(rig, to_double(pose.local), glm::dvec3(pose.root), glm::dvec3(0.0), 0.0);
  std::vector<glm::dvec3> out;
  for (const glm::dmat4& m : M) out.emplace_back(m[3]);
  return out;
}

// Per-character synthesis (locomotion's own reference) at a speed and phase.
std::vector<glm::dvec3> synthesised(const motion::BlendSpace1D& space, float speed, float phase) {
  const motion::BlendSpaceView v = space.view();
  const motion::CharacterFrame f = motion::character_frame(v, speed, phase, glm::vec3(0.0f), 0.0f, 1.0f);
  std::vector<glm::vec3> p(static_cast<std::size_t>(v.joint_count));
  std::vector<glm::quat> q(p.size());
  motion::synthesise_pose(v, f, p.data(), q.data());
  return std::vector<glm::dvec3>(p.begin(), p.end());
}

double largest_distance(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  double worst = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) worst = std::max(worst, glm::length(a[j] - b[j]));
  return worst;
}

const Rig& default_rig() {
  static const Rig rig = make_rig("humanoid", spaces().speeds->skeleton());
  return rig;
}

TEST(Blend1DController, PoseIsPerCharacterSynthesisAtItsSpeedAndPhase) {
  const Rig& rig = default_rig();
  for (const float speed : {0.0f, 0.3f, 1.1f, 1.5f, 2.2f, 3.9f, 5.0f}) {
    Blend1DOptions o;
    o.start_phase = 0.37f;
    Blend1DController c(spaces().speeds, o);
    ParameterSet params;
    params.set("speed", speed);
    EventMask events = 0;
    Pose pose;
    for (int f = 0; f < 40; ++f) {
      c.advance(kDt, params, events);
      c.evaluate(pose);
      ASSERT_EQ(pose.joint_count(), rig.joint_count());
      EXPECT_LT(largest_distance(joint_positions(rig, pose), synthesised(*spaces().speeds, speed, c.phase())), 1e-4)
          << speed << " " << f;
    }
  }
}

TEST(Blend1DController, PhaseAdvancesByDtOverTheBlendedPeriod) {
  // Inside the walk..walk_fast segment the stride lerps with w and the
  // cadence follows: the period is the blended stride over the speed.
  const auto& clips = spaces().speeds->clips();
  const motion::LocomotionClip* walk = nullptr;
  const motion::LocomotionClip* fast = nullptr;
  for (const auto& c : clips) {
    if (c.name == "walk") walk = &c;
    if (c.name == "walk_fast") fast = &c;
  }
  ASSERT_TRUE(walk && fast);
  const double speed = 0.5 * (walk->speed + fast->speed) + 0.07;
  const double w = (speed - walk->speed) / (fast->speed - walk->speed);
  const double period = (walk->stride_m + w * (fast->stride_m - walk->stride_m)) / speed;
  Blend1DOptions o;
  o.speed = static_cast<float>(speed);  // no parameter set: the option's speed
  Blend1DController c(spaces().speeds, o);
  EXPECT_NEAR(c.duration(), period, 1e-4 * period);
  ParameterSet none;
  EventMask events = 0;
  double unwrapped = 0.0;
  float last = c.phase();
  for (int f = 0; f < 300; ++f) {
    c.advance(kDt, none, events);
    unwrapped += motion::wrap_phase(c.phase() - last);
    last = c.phase();
  }
  EXPECT_NEAR(unwrapped, 300 * kDt / period, 1e-3);
  EXPECT_NEAR(c.time(), 300 * kDt, 1e-4);
  c.reset();
  EXPECT_EQ(c.phase(), 0.0f);
  EXPECT_EQ(c.time(), 0.0);
}

TEST(Blend1DController, FootstepsAlternateOncePerCycleEach) {
  Blend1DOptions o;
  o.speed = 1.35f;
  o.start_phase = 0.9f;
  o.footstep_left = 3;
  o.footstep_right = 5;
  Blend1DController c(spaces().speeds, o);
  ParameterSet none;
  int left = 0, right = 0, last = -1;
  double cycles = 0.0;
  for (int f = 0; f < 600; ++f) {
    EventMask events = 0;
    const float before = c.phase();
    c.advance(kDt, none, events);
    cycles += motion::wrap_phase(c.phase() - before);
    if (events & (1u << 3)) {
      ++left;
      EXPECT_NE(last, 3) << "two left steps in a row at frame " << f;
      last = 3;
      EXPECT_LT(c.phase(), 0.1f);  // the left touchdown is the cycle's phase 0
    }
    if (events & (1u << 5)) {
      ++right;
      EXPECT_NE(last, 5) << "two right steps in a row at frame " << f;
      last = 5;
    }
    EXPECT_EQ(events & ~((1u << 3) | (1u << 5)), 0u);
  }
  EXPECT_NEAR(left, cycles, 1.0);
  EXPECT_NEAR(right, cycles, 1.0);
}

TEST(Blend1DController, RejectsBadOptions) {
  Blend1DOptions o;
  o.speed = -1.0f;
  EXPECT_THROW(Blend1DController(spaces().speeds, o), Error);
  o.speed = 1.0f;
  o.start_phase = 1.0f;
  EXPECT_THROW(Blend1DController(spaces().speeds, o), Error);
  o.start_phase = 0.0f;
  o.footstep_left = 32;
  EXPECT_THROW(Blend1DController(spaces().speeds, o), Error);
  EXPECT_THROW(Blend1DController(nullptr, {}), Error);
}

TEST(Blend2DController, NoTurnIsTheSpeedBlendExactly) {
  for (const float speed : {0.0f, 0.8f, 1.25f, 2.6f}) {
    Blend1DController one(spaces().speeds);
    Blend2DController two(spaces().speeds, spaces().turn_left, spaces().turn_right);
    ParameterSet params;
    params.set("speed", speed);
    params.set("turn", 0.0f);
    EventMask e = 0;
    Pose a, b;
    for (int f = 0; f < 25; ++f) {
      one.advance(kDt, params, e);
      two.advance(kDt, params, e);
      one.evaluate(a);
      two.evaluate(b);
      ASSERT_EQ(one.phase(), two.phase());
      ASSERT_EQ(a.local, b.local) << speed << " " << f;
      ASSERT_EQ(a.root, b.root);
    }
    EXPECT_EQ(two.turn_weight(), 0.0f);
  }
}

TEST(Blend2DController, FullTurnAtTheTurningClipsSpeedIsThatClip) {
  const Rig& rig = default_rig();
  for (const bool left : {true, false}) {
    const auto& turn = left ? spaces().turn_left : spaces().turn_right;
    const motion::ClipInfo& info = turn->clip_infos()[0];
    const float rate = info.turn / info.period;
    Blend2DController c(spaces().speeds, spaces().turn_left, spaces().turn_right);
    ParameterSet params;
    params.set("speed", info.speed);
    params.set("turn", 1.5f * rate);  // beyond the clip's own rate: the clip itself
    EventMask e = 0;
    Pose pose;
    for (int f = 0; f < 30; ++f) {
      c.advance(kDt, params, e);
      EXPECT_NEAR(c.turn_weight(), 1.0f, 1e-5f);
      c.evaluate(pose);
      EXPECT_LT(largest_distance(joint_positions(rig, pose), synthesised(*turn, info.speed, c.phase())), 1e-4)
          << left << " " << f;
    }
    EXPECT_NEAR(c.duration(), info.period, 1e-3 * info.period);
  }
}

// Part way into a turn each joint is a unit rotation within 0.001 degrees
// of the SLERP (exponential map, double) of the straight pose and the
// turning clip's pose by the turn weight (at phase 0: advancing, each
// controller would keep its own cadence).
TEST(Blend2DController, PartTurnIsTheSlerpOfTheStraightAndTurningPoses) {
  const motion::ClipInfo& info = spaces().turn_left->clip_infos()[0];
  const float rate = info.turn / info.period;
  auto pose_at = [&](float turn, float* weight) {
    Blend2DOptions o;
    o.speed = info.speed;
    o.turn = turn;
    Blend2DController c(spaces().speeds, spaces().turn_left, spaces().turn_right, o);
    Pose p;
    c.evaluate(p);
    if (weight != nullptr) *weight = c.turn_weight();
    return p;
  };
  const Pose straight = pose_at(0.0f, nullptr), turning = pose_at(1.5f * rate, nullptr);
  double worst = 0.0;
  for (const float part : {0.3f, 0.6f}) {
    float u = 0.0f;
    const Pose p = pose_at(part * rate, &u);
    ASSERT_GT(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    for (std::size_t j = 0; j < p.local.size(); ++j) {
      const glm::dquat want = test::reference_slerp(glm::dquat(straight.local[j]), glm::dquat(turning.local[j]), u);
      EXPECT_NEAR(glm::length(glm::dquat(p.local[j])), 1.0, 1e-6) << part << " joint " << j;
      worst = std::max(worst, test::rotation_between_deg(glm::dquat(p.local[j]), want));
    }
  }
  std::printf("part turns within %.2e degrees of the reference SLERP\n", worst);
  EXPECT_LT(worst, 1e-3);
}

TEST(Blend2DController, TurnWeightGrowsWithTurnAndFadesAwayFromTheTurningSpeed) {
  const motion::ClipInfo& info = spaces().turn_left->clip_infos()[0];
  const float rate = info.turn / info.period;
  auto weight = [&](float speed, float turn) {
    Blend2DOptions o;
    o.speed = speed;
    o.turn = turn;
    return Blend2DController(spaces().speeds, spaces().turn_left, spaces().turn_right, o).turn_weight();
  };
  EXPECT_NEAR(weight(info.speed, 0.5f * rate), 0.5f, 1e-5f);
  EXPECT_NEAR(weight(info.speed,
                     -0.5f * spaces().turn_right->clip_infos()[0].turn / spaces().turn_right->clip_infos()[0].period),
              0.5f, 1e-5f);
  float previous = 1.0f;
  for (const float speed : {info.speed, info.speed + 0.1f, info.speed + 0.2f, info.speed + 0.4f}) {
    const float w = weight(speed, rate);
    EXPECT_LE(w, previous);
    previous = w;
  }
  EXPECT_LT(previous, 1.0f);
  EXPECT_EQ(weight(4.5f, rate), 0.0f);  // running: no walking turn
  EXPECT_EQ(weight(0.0f, rate), 0.0f);
  // A left turn leans the root the other way from a right turn.
  auto root_roll = [&](float turn) {
    Blend2DOptions o;
    o.speed = info.speed;
    o.turn = turn;
    Blend2DController c(spaces().speeds, spaces().turn_left, spaces().turn_right, o);
    Pose p;
    double mean_x = 0.0;
    ParameterSet none;
    EventMask e = 0;
    for (int f = 0; f < 60; ++f) {
      c.advance(kDt, none, e);
      c.evaluate(p);
      mean_x += (p.local[0] * glm::vec3(0.0f, 1.0f, 0.0f)).x / 60.0;
    }
    return mean_x;
  };
  EXPECT_LT(root_roll(rate) * root_roll(-rate), 0.0);
}

TEST(BlendControllers, PlayInStreamsUnchanged) {
  const Rig& rig = default_rig();
  StreamPool pool(30.0f);
  StreamSpec spec;
  spec.name = "walk";
  spec.history = 16;
  spec.root = RootMotion::Keep;
  const std::int32_t s = pool.add(rig, 0, spec, std::make_unique<Blend1DController>(spaces().speeds));
  pool[s].parameters().set("speed", 1.4f);
  spec.name = "turn";
  const std::int32_t t = pool.add(
      rig, 0, spec, std::make_unique<Blend2DController>(spaces().speeds, spaces().turn_left, spaces().turn_right));
  pool[t].parameters().set("speed", 1.2f);
  pool[t].parameters().set("turn", 0.4f);
  Blend1DController reference(spaces().speeds);
  ParameterSet params;
  params.set("speed", 1.4f);
  Pose want;
  for (int f = 0; f < 20; ++f) {
    pool.step(f);
    EventMask e = 0;
    if (f > 0) reference.advance(1.0f / 30.0f, params, e);
    reference.evaluate(want);
    EXPECT_EQ(pool[s].pose_at(0).local, want.local) << f;
  }
  EXPECT_GT(pool[t].controller().duration(), 0.0);
  // Clones play on independently.
  auto clone = pool[s].controller().clone();
  EXPECT_EQ(clone->time(), pool[s].controller().time());
}

}  // namespace
}  // namespace throng::anim
