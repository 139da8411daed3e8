// Cycle analysis against clips whose answers are known by construction:
// synthetic periodic motion (straight, rotated, turning), foot tracks with
// known contacts and slides, loop closing and cycle repetition.
#include "motion/cycle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.h"
#include "motion/default_set.h"
#include "motion/foot_skating.h"

namespace throng::motion {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Hips, two three-joint legs and a spine leaf (its rotation moves no joint).
Skeleton legs_skeleton() {
  Skeleton s;
  s.add_joint("Hips", -1, {0.0f, 0.95f, 0.0f});
  const std::int32_t spine = s.add_joint("Spine", 0, {0.0f, 0.2f, 0.0f});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 0.1f : -0.1f;
    const std::int32_t up = s.add_joint(side == 0 ? "LeftUpLeg" : "RightUpLeg", 0, {x, -0.05f, 0.0f});
    const std::int32_t knee = s.add_joint(side == 0 ? "LeftLeg" : "RightLeg", up, {0.0f, -0.42f, 0.0f});
    const std::int32_t ankle = s.add_joint(side == 0 ? "LeftFoot" : "RightFoot", knee, {0.0f, -0.42f, 0.0f});
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftThigh : Role::RightThigh)] = up;
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftKnee : Role::RightKnee)] = knee;
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftAnkle : Role::RightAnkle)] = ankle;
  }
  s.roles[static_cast<std::size_t>(Role::Hips)] = 0;
  s.spine_chain = {spine};
  return s;
}

struct Synthetic {
  std::int32_t period = 37;
  std::int32_t frames = 160;
  double fps = 30.0;
  double speed = 1.1;         // m/s
  double turn_rate = 0.0;     // rad/s
  double yaw0 = 0.0;          // constant heading of the whole clip
  double spine_drift = 0.0;   // rad per frame (not periodic)
  double height_drift = 0.0;  // m per frame
};

// Exactly periodic joint motion with period `period` frames; the root moves
// at `speed` along a line or circle.
Clip synthetic_clip(const Skeleton& s, const Synthetic& c) {
  Clip clip;
  clip.resize(c.frames, s.joint_count());
  clip.frame_time = static_cast<float>(1.0 / c.fps);
  for (std::int32_t f = 0; f < c.frames; ++f) {
    const double ph = kTwoPi * f / c.period, t = f / c.fps;
    const double psi = c.yaw0 + c.turn_rate * t;
    glm::dvec3 path = std::abs(c.turn_rate) < 1e-12
                          ? glm::dvec3(0.0, 0.0, c.speed * t)
                          : glm::dvec3(c.speed / c.turn_rate * (1 - std::cos(c.turn_rate * t)), 0.0,
                                       c.speed / c.turn_rate * std::sin(c.turn_rate * t));
    path = glm::angleAxis(c.yaw0, glm::dvec3(0, 1, 0)) * path;
    clip.root_positions[static_cast<std::size_t>(f)] =
        glm::vec3(path + glm::dvec3(0.0, 0.95 + 0.02 * std::sin(2 * ph) + c.height_drift * f, 0.0));
    clip.rotation(f, 0) = glm::quat(glm::angleAxis(psi + 0.06 * std::sin(ph), glm::dvec3(0, 1, 0)));
    clip.rotation(f, 1) = glm::quat(glm::angleAxis(0.1 * std::sin(ph + 2.0) + c.spine_drift * f, glm::dvec3(0, 1, 0)));
    for (int side = 0; side < 2; ++side) {
      const double p = ph + (side == 0 ? 0.0 : std::numbers::pi);
      const std::int32_t up = s.role(side == 0 ? Role::LeftThigh : Role::RightThigh);
      clip.rotation(f, up) = glm::quat(glm::angleAxis(-0.4 * std::sin(p), glm::dvec3(1, 0, 0)));
      clip.rotation(f, up + 1) = glm::quat(glm::angleAxis(0.5 + 0.45 * std::sin(p + 1.2), glm::dvec3(1, 0, 0)));
    }
  }
  return clip;
}

CycleOptions wide_options() {
  CycleOptions o;
  o.max_period_s = 3.0;  // twice the true period is inside the search range
  o.loop = CycleOptions::Loop::Never;
  return o;
}

TEST(CycleAnalysis, RecoversAKnownPeriodExactly) {
  const Skeleton s = legs_skeleton();
  const Synthetic c;
  const CycleReport r = analyze_cycle(s, synthetic_clip(s, c), wide_options());
  ASSERT_TRUE(r.found);
  EXPECT_FALSE(r.input_is_loop);
  EXPECT_EQ(r.period_frames, c.period);  // not 2 x 37, though that matches as well
  EXPECT_EQ(r.end_frame - r.start_frame, c.period);
  EXPECT_NEAR(r.period_s, c.period / c.fps, 1e-6);  // frame_time is a float
  EXPECT_LT(r.pose_rms_m, 1e-5);
  EXPECT_NEAR(r.mean_speed, c.speed, 1e-4);
  EXPECT_NEAR(r.turn_rate, 0.0, 1e-5);
  EXPECT_NEAR(r.displacement, c.speed * c.period / c.fps, 1e-4);
}

TEST(CycleAnalysis, IsHeadingInvariantAndFollowsTurns) {
  const Skeleton s = legs_skeleton();
  Synthetic rotated;
  rotated.yaw0 = 2.0;  // the whole clip faces another way
  const CycleReport a = analyze_cycle(s, synthetic_clip(s, rotated), wide_options());
  ASSERT_TRUE(a.found);
  EXPECT_EQ(a.period_frames, rotated.period);
  EXPECT_NEAR(a.mean_speed, rotated.speed, 1e-4);

  Synthetic turning;
  turning.turn_rate = -0.5;  // turning right along a circle
  turning.period = 41;
  const CycleReport b = analyze_cycle(s, synthetic_clip(s, turning), wide_options());
  ASSERT_TRUE(b.found);
  EXPECT_EQ(b.period_frames, turning.period);
  EXPECT_LT(b.pose_rms_m, 1e-5);
  EXPECT_NEAR(b.turn_rate, turning.turn_rate, 1e-4);
  EXPECT_NEAR(b.mean_speed, turning.speed, 2e-3);
}

TEST(CycleAnalysis, StandingStillIsNotALoopUnlessAllowed) {
  const Skeleton s = legs_skeleton();
  Synthetic still;
  still.speed = 0.0;
  const Clip clip = synthetic_clip(s, still);
  EXPECT_FALSE(analyze_cycle(s, clip, wide_options()).found);  // min_mean_speed 0.1 m/s
  CycleOptions o = wide_options();
  o.min_mean_speed = 0.0;
  const CycleReport r = analyze_cycle(s, clip, o);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.period_frames, still.period);
}

TEST(CycleAnalysis, OptionsAndInputsAreChecked) {
  const Skeleton s = legs_skeleton();
  const Clip clip = synthetic_clip(s, Synthetic{});
  CycleOptions o;
  o.min_period_s = 3.0;
  o.max_period_s = 1.0;
  try {
    analyze_cycle(s, clip, o);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "min_period_s");
  }
  o = CycleOptions{};
  o.contacts.height_fraction = -1;
  EXPECT_THROW(analyze_cycle(s, clip, o), Error);
  o = CycleOptions{};
  o.max_frame_joints = 100;  // refused before anything is allocated
  try {
    analyze_cycle(s, clip, o);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "max_frame_joints");
  }
  Clip bad_time = clip;
  bad_time.frame_time = 0.0f;
  EXPECT_THROW(analyze_cycle(s, bad_time, {}), Error);
  bad_time.frame_time = 1e-30f;  // would overflow frame counts
  EXPECT_THROW(analyze_cycle(s, bad_time, {}), Error);
  Clip wrong = clip;
  wrong.joint_count = 3;
  EXPECT_THROW(analyze_cycle(s, wrong, {}), Error);
  EXPECT_THROW(make_cyclic(clip, 10, 5), Error);
  EXPECT_THROW(make_cyclic(clip, 0, clip.frame_count), Error);
  EXPECT_THROW(repeat_cycle(clip, 0), Error);
  // Too short for any period: nothing found, no crash.
  Synthetic tiny;
  tiny.frames = 5;
  EXPECT_FALSE(analyze_cycle(s, synthetic_clip(s, tiny), wide_options()).found);
}

// Foot tracks written directly: contacts and slides are known exactly.
struct Tracks {
  Skeleton skeleton;
  ModelSpaceClip model;
  FeetJoints feet;
};

// Two feet (ankle + toe each); `place(frame, foot, point)` gives positions.
template <class Place>
Tracks make_tracks(std::int32_t frames, Place place) {
  Tracks t;
  Skeleton& s = t.skeleton;
  s.add_joint("Hips", -1, {0.0f, 0.9f, 0.0f});
  for (int side = 0; side < 2; ++side) {
    const std::int32_t up = s.add_joint("UpLeg", 0, {0.0f, -0.05f, 0.0f});
    const std::int32_t knee = s.add_joint("Leg", up, {0.0f, -0.4f, 0.0f});
    const std::int32_t ankle = s.add_joint("Foot", knee, {0.0f, -0.4f, 0.0f});
    const std::int32_t toe = s.add_joint("Toe", ankle, {0.0f, -0.05f, 0.15f});
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftThigh : Role::RightThigh)] = up;
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftKnee : Role::RightKnee)] = knee;
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftAnkle : Role::RightAnkle)] = ankle;
    s.roles[static_cast<std::size_t>(side == 0 ? Role::LeftToe : Role::RightToe)] = toe;
  }
  t.feet = FeetJoints::from_roles(s);
  ModelSpaceClip& m = t.model;
  m.joint_count = s.joint_count();
  m.frame_count = frames;
  m.positions.assign(static_cast<std::size_t>(frames * m.joint_count), glm::vec3(0.0f));
  m.rotations.assign(m.positions.size(), glm::quat(1, 0, 0, 0));
  for (std::int32_t f = 0; f < frames; ++f)
    for (int foot = 0; foot < 2; ++foot)
      for (int point = 0; point < 2; ++point) {
        const std::int32_t j =
            point == 0 ? t.feet.ankle[static_cast<std::size_t>(foot)] : t.feet.toe[static_cast<std::size_t>(foot)];
        m.positions[static_cast<std::size_t>(f * m.joint_count + j)] = place(f, foot, point);
      }
  return t;
}

// Horizontal position of a foot that rests at z0 until frame f0, moves to
// z1 by frame f1 (fast) and rests there: contacts start and end at rest.
float travel(std::int32_t f, std::int32_t f0, float z0, std::int32_t f1, float z1) {
  if (f <= f0) return z0;
  if (f >= f1) return z1;
  return z0 + (z1 - z0) * static_cast<float>(f - f0) / static_cast<float>(f1 - f0);
}

TEST(FootContacts, LowAndSlowFramesWithGapsFilled) {
  // Left foot down on [10, 30) and [50, 70) except a 2-frame lift at 60
  // (straight up); right foot always in the air and moving.
  const Tracks t = make_tracks(90, [](std::int32_t f, int foot, int point) {
    const float base = point == 0 ? 0.08f : 0.03f;
    if (foot == 1) return glm::vec3(0.0f, base + 0.2f, 0.1f * static_cast<float>(f));
    const bool down = (f >= 10 && f < 30) || (f >= 50 && f < 70 && f != 60 && f != 61);
    const float z = f < 40 ? travel(f, -10, -2.0f, 8, 1.0f) : travel(f, 31, 1.0f, 48, 3.0f);
    return glm::vec3(0.0f, down ? base : base + 0.3f, f > 71 ? 3.0f + 0.2f * static_cast<float>(f - 71) : z);
  });
  ContactOptions o;
  o.smoothing_s = 0.0;
  const ContactReport r = detect_foot_contacts(t.skeleton, t.model, 1.0 / 30.0, t.feet, o);
  ASSERT_EQ(r.feet[0].intervals.size(), 2u);
  EXPECT_EQ(r.feet[0].intervals[0].begin, 10);
  EXPECT_EQ(r.feet[0].intervals[0].end, 30);
  EXPECT_EQ(r.feet[0].intervals[1].begin, 50);  // the blip is filled (gap 2 frames < 0.1 s)
  EXPECT_EQ(r.feet[0].intervals[1].end, 70);
  EXPECT_TRUE(r.feet[1].intervals.empty());
  EXPECT_NEAR(r.feet[0].ground[0], 0.08, 1e-6);
  EXPECT_NEAR(r.feet[0].ground[1], 0.03, 1e-6);
}

TEST(FootSkating, MeasuresTheSlideOfThePinnedPoint) {
  // Left foot on the ground for [10, 40): in the first contact both points
  // slide 1 mm per frame; the right foot rolls (ankle moves, toe pinned).
  const Tracks t = make_tracks(60, [](std::int32_t f, int foot, int point) {
    const float base = point == 0 ? 0.08f : 0.03f;
    const bool down = f >= 10 && f < 40;
    if (foot == 0 && !down)
      return glm::vec3(0.0f, base + 0.3f, f < 10 ? travel(f, -5, -2.0f, 8, 0.0f) : travel(f, 41, 0.029f, 55, 2.0f));
    if (!down) return glm::vec3(1.0f, base + 0.3f, point == 0 ? 0.35f : 0.5f);  // lifted straight up
    if (foot == 0) return glm::vec3(0.0f, base, 0.001f * static_cast<float>(f - 10));
    return point == 1 ? glm::vec3(1.0f, base, 0.5f)
                      : glm::vec3(1.0f, base + 0.001f * static_cast<float>(f - 10),
                                  0.35f + 0.0005f * static_cast<float>(f - 10));
  });
  ContactOptions o;
  o.smoothing_s = 0.0;
  const ContactReport c = detect_foot_contacts(t.skeleton, t.model, 1.0 / 30.0, t.feet, o);
  const FootSkatingReport r = measure_foot_skating(t.model, c, t.feet);
  ASSERT_EQ(r.contacts, 2);
  EXPECT_NEAR(r.slides_cm[0], 2.9, 1e-3);  // 29 steps of 1 mm
  EXPECT_NEAR(r.slides_cm[1], 0.0, 1e-6);  // rolling over the pinned toe is no slide
  EXPECT_NEAR(r.mean_cm, 1.45, 1e-3);
  EXPECT_NEAR(r.max_cm, 2.9, 1e-3);
  EXPECT_NEAR(r.p95_cm, 2.9, 1e-3);
}

// Nothing measured is not zero skating: with no contact every figure is NaN
// (so any bound on it fails) and the report says so in words.
TEST(FootSkating, NoContactsMeansNoFigures) {
  const FootSkatingReport none = summarise_foot_skating({});
  EXPECT_FALSE(none.measured());
  EXPECT_EQ(none.contacts, 0);
  EXPECT_TRUE(std::isnan(none.mean_cm));
  EXPECT_TRUE(std::isnan(none.p95_cm));
  EXPECT_TRUE(std::isnan(none.max_cm));
  EXPECT_FALSE(none.mean_cm < 2.0);
  EXPECT_EQ(describe(none), "no contacts measured");
  const FootSkatingReport some = summarise_foot_skating({1.0, 3.0});
  EXPECT_TRUE(some.measured());
  EXPECT_EQ(describe(some), "mean 2.00 cm, p95 3.00 cm over 2 contacts");
}

TEST(MakeCyclic, LeavesAnExactLoopAloneAndClosesADriftingOne) {
  const Skeleton s = legs_skeleton();
  Synthetic c;
  const Clip exact = synthetic_clip(s, c);
  const Clip loop = make_cyclic(exact, 20, 20 + c.period);
  ASSERT_EQ(loop.frame_count, c.period);
  for (std::int32_t f = 0; f < loop.frame_count; ++f) {
    EXPECT_LT(glm::length(loop.root_positions[static_cast<std::size_t>(f)] -
                          exact.root_positions[static_cast<std::size_t>(20 + f)]),
              1e-6f);
    for (std::int32_t j = 0; j < s.joint_count(); ++j)
      EXPECT_GT(std::abs(glm::dot(loop.rotation(f, j), exact.rotation(20 + f, j))), 1.0f - 1e-6f);
  }

  // Spine rotation and root height drift: the period is still found (the
  // spine is a leaf, so no position moves) but frame b differs from frame a.
  c.spine_drift = 0.01;
  c.height_drift = 0.001;
  const Clip drifting = synthetic_clip(s, c);
  const CycleReport r = analyze_cycle(s, drifting, wide_options());
  ASSERT_TRUE(r.found);
  ASSERT_EQ(r.period_frames, c.period);
  const Clip closed = make_cyclic(drifting, r);
  const std::int32_t n = closed.frame_count;
  auto spine_step = [&](const Clip& clip, std::int32_t from, std::int32_t to) {
    return std::abs(2.0 * std::acos(std::min(1.0f, std::abs(glm::dot(clip.rotation(from, 1), clip.rotation(to, 1))))));
  };
  // Before: the wrap (b-1 -> a) jumps back by the drift of a whole period.
  const double raw_wrap = spine_step(drifting, r.end_frame - 1, r.start_frame);
  const double typical = spine_step(drifting, r.start_frame, r.start_frame + 1);
  EXPECT_GT(raw_wrap, 3.0 * typical);
  // After: the wrap is an ordinary step, and so is the height change.
  EXPECT_LT(spine_step(closed, n - 1, 0), 2.0 * spine_step(closed, 0, 1));
  const float dy_wrap = std::abs(closed.root_positions[0].y - closed.root_positions[static_cast<std::size_t>(n - 1)].y);
  float dy_max = 0.0f;
  for (std::int32_t f = 0; f + 1 < n; ++f)
    dy_max = std::max(dy_max, std::abs(closed.root_positions[static_cast<std::size_t>(f + 1)].y -
                                       closed.root_positions[static_cast<std::size_t>(f)].y));
  EXPECT_LE(dy_wrap, dy_max * 1.01f);
  // Repeating the closed loop gives a clip whose period is the loop.
  const CycleReport again = analyze_cycle(s, repeat_cycle(closed, 4), wide_options());
  ASSERT_TRUE(again.found);
  EXPECT_EQ(again.period_frames, n);
}

TEST(RepeatCycle, ContinuesTheRootInTheHeadingFrame) {
  const Skeleton sk = default_skeleton();
  for (const char* name : {"walk", "walk_turn_left"}) {
    LocomotionSpec spec;
    for (const auto& sp : default_motion_specs())
      if (sp.name == name) spec = sp;
    const LocomotionGenerator gen(sk, spec);
    const std::int32_t N = gen.targets().period_frames;
    const Clip repeated = repeat_cycle(gen.make_clip(), 3);
    const Clip direct = gen.sample(3 * N);
    ASSERT_EQ(repeated.frame_count, direct.frame_count);
    for (std::int32_t f = 0; f < direct.frame_count; ++f) {
      // The loop step is estimated from its neighbours: ~mm after 3 strides.
      EXPECT_LT(glm::length(repeated.root_positions[static_cast<std::size_t>(f)] -
                            direct.root_positions[static_cast<std::size_t>(f)]),
                0.005f)
          << name << " frame " << f;
      for (std::int32_t j = 0; j < sk.joint_count(); ++j)
        ASSERT_GT(std::abs(glm::dot(repeated.rotation(f, j), direct.rotation(f, j))), 1.0f - 2e-4f)
            << name << " frame " << f;
    }
    // A single stride is recognised as a loop and analysed as one.
    const CycleReport r = analyze_cycle(sk, gen.make_clip());
    ASSERT_TRUE(r.found);
    EXPECT_TRUE(r.input_is_loop);
    EXPECT_EQ(r.period_frames, N);
    EXPECT_EQ(r.steps, 2);
  }
}

}  // namespace
}  // namespace throng::motion
