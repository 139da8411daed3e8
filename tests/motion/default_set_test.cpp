// The project's own skeleton and procedural locomotion cycles, checked
// against the biomechanics targets by two methods (the cycle analysis and a
// count of the feet passing each other), for exact cyclicity, planted feet,
// constant bone lengths and the counter-rotation of arms and thorax.
#include "motion/default_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.h"
#include "motion/biomech.h"
#include "motion/cycle.h"
#include "motion/fk.h"
#include "motion/foot_skating.h"
#include "motion/roles.h"

namespace throng::motion {
namespace {

namespace dj = default_joint;
constexpr double kDeg = std::numbers::pi / 180.0;

glm::vec3 rest_position(const Skeleton& s, std::int32_t j) {
  glm::vec3 p(0.0f);
  for (; j >= 0; j = s.parents[static_cast<std::size_t>(j)]) p += s.offsets[static_cast<std::size_t>(j)];
  return p;
}

const LocomotionSpec& spec_named(const std::vector<LocomotionSpec>& specs, const std::string& name) {
  for (const auto& s : specs)
    if (s.name == name) return s;
  throw Error("no spec " + name);
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= static_cast<double>(a.size());
  mb /= static_cast<double>(b.size());
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

TEST(DefaultSkeleton, ProportionsOfA175mAdult) {
  const Skeleton s = default_skeleton();
  EXPECT_EQ(s.joint_count(), dj::Count);
  EXPECT_NO_THROW(s.validate());
  const glm::vec3 head_top = rest_position(s, dj::Head) + s.end_sites[dj::Head];
  EXPECT_NEAR(head_top.y, 1.75f, 0.01f);
  // Soles on the ground: toe tips 2 cm above it (their joint centre), ankle ~8 cm.
  EXPECT_NEAR(rest_position(s, dj::LeftFoot).y, 0.08f, 1e-5f);
  EXPECT_NEAR((rest_position(s, dj::LeftToeBase) + s.end_sites[dj::LeftToeBase]).y, 0.02f, 1e-5f);
  // Winter's segment fractions of height (thigh 0.245 H, shank 0.246 H,
  // upper arm 0.186 H, forearm 0.146 H) within 4 cm.
  EXPECT_NEAR(glm::length(s.offsets[dj::LeftLeg]), 0.245 * 1.75, 0.04);
  EXPECT_NEAR(glm::length(s.offsets[dj::LeftFoot]), 0.246 * 1.75, 0.04);
  EXPECT_NEAR(glm::length(s.offsets[dj::LeftForeArm]), 0.186 * 1.75, 0.04);
  EXPECT_NEAR(glm::length(s.offsets[dj::LeftHand]), 0.146 * 1.75, 0.04);
  // Left is +X (the character faces +Z).
  EXPECT_GT(rest_position(s, dj::LeftHand).x, 0.5f);
  EXPECT_LT(rest_position(s, dj::RightHand).x, -0.5f);
  for (std::size_t r = 0; r < kRoleCount; ++r) EXPECT_GE(s.roles[r], 0) << to_string(static_cast<Role>(r));
  EXPECT_EQ(s.spine_chain, (std::vector<std::int32_t>{dj::Spine, dj::Spine1, dj::Spine2}));
}

TEST(DefaultSkeleton, NameHeuristicsAgreeWithTheRolesWeSet) {
  const Skeleton ours = default_skeleton();
  Skeleton guessed = ours;
  guessed.roles.fill(-1);
  guessed.spine_chain.clear();
  assign_roles(guessed);
  for (std::size_t r = 0; r < kRoleCount; ++r)
    EXPECT_EQ(guessed.roles[r], ours.roles[r]) << to_string(static_cast<Role>(r));
  EXPECT_EQ(guessed.spine_chain, ours.spine_chain);
}

TEST(Biomech, RelationsMatchPublishedFigures) {
  using namespace biomech;
  // Normal walking: 100-120 steps/min around 1.2-1.4 m/s, step ~0.7 m.
  EXPECT_GT(walking_cadence(1.2), 100.0);
  EXPECT_LT(walking_cadence(1.4), 120.0);
  EXPECT_NEAR(step_length(1.35, walking_cadence(1.35)), 0.72, 0.04);
  // Step length grows with speed, and the walk ratio (step length over
  // cadence) stays inside the range measured in healthy adults walking at
  // free, slow and fast speeds: about 0.0060-0.0072 m per step/min (Sekiya
  // and Nagasaki 1998, Gait & Posture 7:225-227; Murakami and Otaka 2017).
  for (double v = 0.8; v < 2.0; v += 0.1) {
    EXPECT_GT(step_length(v + 0.1, walking_cadence(v + 0.1)), step_length(v, walking_cadence(v)));
    const double walk_ratio = step_length(v, walking_cadence(v)) / walking_cadence(v);
    EXPECT_GT(walk_ratio, 0.0060) << v;
    EXPECT_LT(walk_ratio, 0.0072) << v;
  }
  // Walk-run transition near 2 m/s, where adults step at about 140 steps/min.
  EXPECT_NEAR(walking_cadence(kWalkRunTransitionSpeed), 140.0, 6.0);
  EXPECT_EQ(gait_for_speed(0.0), Gait::Stand);
  EXPECT_EQ(gait_for_speed(1.9), Gait::Walk);
  EXPECT_EQ(gait_for_speed(2.1), Gait::Run);
  // Running: 165 +- 8 steps/min at 3.04 m/s; 154-160 at 2.4-2.9 m/s.
  EXPECT_NEAR(running_cadence(3.04), 165.0, 3.0);
  EXPECT_NEAR(running_cadence(2.4), 154.0, 8.0);
  EXPECT_NEAR(running_cadence(2.9), 160.0, 5.0);
  EXPECT_GT(running_cadence(5.0), running_cadence(3.0));
  // A flight phase: duty factor below one half when running.
  EXPECT_LT(duty_factor(Gait::Run, 2.7, 120.0 / running_cadence(2.7)), 0.5);
  EXPECT_GT(duty_factor(Gait::Walk, 1.35, 120.0 / walking_cadence(1.35)), 0.5);
}

TEST(DefaultMotions, SpecsValidateWithFieldNames) {
  LocomotionSpec s;
  s.name = "bad";
  s.speed = 3.5;  // too fast for a walk
  try {
    s.validate();
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "speed");
  }
  s.speed = 1.3;
  s.fps = 0;
  EXPECT_THROW(s.validate(), Error);
  s.fps = 60;
  s.gait = biomech::Gait::Stand;
  EXPECT_THROW(s.validate(), Error);  // a standing clip has speed 0
  Skeleton no_feet = default_skeleton();
  no_feet.roles[static_cast<std::size_t>(Role::LeftToe)] = -1;
  EXPECT_THROW(LocomotionGenerator(no_feet, LocomotionSpec{}), Error);
}

// The set is what the docs promise: names, 60 fps, whole strides.
TEST(DefaultMotions, SetHasTheDocumentedClips) {
  const Skeleton s = default_skeleton();
  const auto motions = make_default_motions(s);
  std::vector<std::string> names;
  for (const auto& m : motions) {
    names.push_back(m.spec.name);
    EXPECT_EQ(m.clip.joint_count, s.joint_count());
    EXPECT_EQ(m.clip.frame_count, m.targets.period_frames);
    EXPECT_FLOAT_EQ(m.clip.frame_time, 1.0f / 60.0f);
    EXPECT_FALSE(m.description.empty());
  }
  EXPECT_EQ(names, (std::vector<std::string>{"idle", "walk_slow", "walk", "walk_fast", "run_slow", "run_fast",
                                             "walk_turn_left", "walk_turn_right"}));
}

// Per locomotion clip: generator's targets vs biomechanics, then measured.
class LocomotionClip : public ::testing::TestWithParam<std::string> {};

TEST_P(LocomotionClip, MatchesBiomechanicsByTwoMethods) {
  const Skeleton sk = default_skeleton();
  const LocomotionSpec spec = spec_named(default_motion_specs(), GetParam());
  const LocomotionGenerator gen(sk, spec);
  const LocomotionTargets& t = gen.targets();
  const std::int32_t N = t.period_frames;
  // Rounding the stride to whole frames moves cadence by < 1 %.
  EXPECT_NEAR(t.cadence / biomech::cadence(spec.gait, spec.speed), 1.0, 0.01);
  EXPECT_NEAR(t.stride_length, spec.speed * N / spec.fps, 1e-9);

  const Clip clip = gen.sample(3 * N);
  const ModelSpaceClip m = forward_kinematics(sk, clip);

  // Method 1: the cycle analysis.
  CycleOptions o;
  o.loop = CycleOptions::Loop::Never;
  const CycleReport r = analyze_cycle(sk, clip, o);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.period_frames, N);
  EXPECT_LT(r.pose_rms_m, 1e-4);
  EXPECT_EQ(r.steps, 2);
  EXPECT_NEAR(r.cadence, t.cadence, 1e-6 * t.cadence);
  EXPECT_NEAR(r.mean_speed / spec.speed, 1.0, 0.01);
  EXPECT_NEAR(r.stride_length / t.stride_length, 1.0, 0.01);
  EXPECT_NEAR(r.turn_rate, spec.turn_rate, 0.01 * std::abs(spec.turn_rate) + 1e-6);

  // Method 2: the feet pass each other (forward separation changes sign)
  // twice per stride; root travel over two strides for the speed.
  std::vector<double> crossings;
  double prev = 0.0;
  for (std::int32_t f = 0; f < clip.frame_count; ++f) {
    const float psi = static_cast<float>(spec.turn_rate * f / spec.fps);
    const glm::vec3 forward(std::sin(psi), 0.0f, std::cos(psi));
    const double d = glm::dot(m.position(f, dj::LeftFoot) - m.position(f, dj::RightFoot), forward);
    if (f > 0 && (d > 0) != (prev > 0)) crossings.push_back(f - 1 + prev / (prev - d));  // linear zero crossing
    prev = d;
  }
  ASSERT_GE(crossings.size(), 5u);
  const double steps_per_s =
      (static_cast<double>(crossings.size()) - 1.0) / ((crossings.back() - crossings.front()) / spec.fps);
  EXPECT_NEAR(steps_per_s * 60.0 / t.cadence, 1.0, 0.01);
  const glm::vec3 a = clip.root_positions[0], b = clip.root_positions[static_cast<std::size_t>(2 * N)];
  const double chord = std::hypot(b.x - a.x, b.z - a.z);
  const double half = std::abs(spec.turn_rate) * 2 * N / spec.fps / 2;
  const double arc = half > 1e-9 ? chord * half / std::sin(half) : chord;
  EXPECT_NEAR(arc / (2 * N / spec.fps) / spec.speed, 1.0, 0.01);

  // Flight phase for runs, double support for walks.
  const ContactReport& c = r.contacts;
  std::int32_t none = 0, both = 0;
  for (std::int32_t f = 0; f < clip.frame_count; ++f) {
    const bool l = c.feet[0].in_contact[static_cast<std::size_t>(f)],
               rr = c.feet[1].in_contact[static_cast<std::size_t>(f)];
    none += !l && !rr;
    both += l && rr;
  }
  if (spec.gait == biomech::Gait::Run) {
    EXPECT_GT(none, 0);
    EXPECT_EQ(both, 0);
  } else {
    EXPECT_EQ(none, 0);
    EXPECT_GT(both, 0);
  }
}

TEST_P(LocomotionClip, ExactlyCyclicInTheHeadingFrame) {
  const Skeleton sk = default_skeleton();
  const LocomotionSpec spec = spec_named(default_motion_specs(), GetParam());
  const LocomotionGenerator gen(sk, spec);
  const double T = gen.targets().period_s, dt = 1.0 / spec.fps;
  const auto J = static_cast<std::size_t>(sk.joint_count());
  std::vector<glm::quat> q0(J), q1(J), qT(J), qT1(J);
  glm::vec3 r0, r1, rT, rT1;
  gen.pose_at(0.0, q0, r0);
  gen.pose_at(dt, q1, r1);
  gen.pose_at(T, qT, rT);
  gen.pose_at(T + dt, qT1, rT1);
  for (std::size_t j = 1; j < J; ++j) EXPECT_GT(std::abs(glm::dot(q0[j], qT[j])), 1.0f - 1e-6f) << sk.names[j];
  // Root: same height, same rotation and step once the heading is removed.
  const double h0 = heading_of(q0[0]), hT = heading_of(qT[0]);
  EXPECT_NEAR(std::remainder(hT - h0 - spec.turn_rate * T, 2 * std::numbers::pi), 0.0, 1e-5);
  EXPECT_NEAR(rT.y, r0.y, 1e-5);
  const glm::quat u0 = glm::angleAxis(static_cast<float>(-h0), glm::vec3(0, 1, 0));
  const glm::quat uT = glm::angleAxis(static_cast<float>(-hT), glm::vec3(0, 1, 0));
  EXPECT_GT(std::abs(glm::dot(u0 * q0[0], uT * qT[0])), 1.0f - 1e-6f);
  const glm::vec3 step0 = u0 * (r1 - r0), stepT = uT * (rT1 - rT);
  EXPECT_LT(glm::length(step0 - stepT), 1e-5f);
  // The clip's own loop: frame N would be the pose at T.
  const Clip clip = gen.make_clip();
  EXPECT_EQ(clip.frame_count, gen.targets().period_frames * spec.strides);
  for (std::size_t j = 1; j < J; ++j) EXPECT_GT(std::abs(glm::dot(clip.rotations[j], qT[j])), 1.0f - 1e-6f);
}

TEST_P(LocomotionClip, FeetStayPlantedAndBonesKeepTheirLength) {
  const Skeleton sk = default_skeleton();
  const LocomotionSpec spec = spec_named(default_motion_specs(), GetParam());
  const LocomotionGenerator gen(sk, spec);
  const std::int32_t N = gen.targets().period_frames;
  const Clip clip = gen.sample(3 * N);
  const ModelSpaceClip m = forward_kinematics(sk, clip);
  const FootSkatingReport skate = measure_foot_skating(sk, clip);
  EXPECT_GE(skate.contacts, 5);
  EXPECT_LT(skate.max_cm, 0.5);
  EXPECT_LT(skate.p95_cm, 0.5);
  for (std::int32_t f = 0; f < clip.frame_count; ++f)
    for (std::int32_t j = 1; j < sk.joint_count(); ++j) {
      const auto p = static_cast<std::size_t>(sk.parents[static_cast<std::size_t>(j)]);
      const float len = glm::length(m.position(f, j) - m.position(f, static_cast<std::int32_t>(p)));
      ASSERT_NEAR(len, glm::length(sk.offsets[static_cast<std::size_t>(j)]), 1e-4f)
          << sk.names[static_cast<std::size_t>(j)] << " frame " << f;
    }
  // Swing clearance: the toe tip clears the ground (its rest height is 2 cm)
  // in the middle of each swing, and never goes more than 1 mm below it.
  const double duty = gen.targets().duty_factor;
  for (std::int32_t f = 0; f < clip.frame_count; ++f) {
    for (int side = 0; side < 2; ++side) {
      const std::int32_t toe = side == 0 ? dj::LeftToeBase : dj::RightToeBase;
      const glm::vec3 tip = m.position(f, toe) + m.rotations[static_cast<std::size_t>(f) * sk.joint_count() + toe] *
                                                     sk.end_sites[static_cast<std::size_t>(toe)];
      EXPECT_GT(tip.y, 0.019f);
      double u = static_cast<double>(f) / N - (side == 0 ? 0.0 : 0.5);
      u -= std::floor(u);
      const double sw = (u - duty) / (1.0 - duty);
      if (sw > 0.2 && sw < 0.8) {
        EXPECT_GT(tip.y, 0.035f) << "frame " << f;
      }
    }
  }
}

TEST_P(LocomotionClip, ArmsAndThoraxCounterRotate) {
  const Skeleton sk = default_skeleton();
  const LocomotionSpec spec = spec_named(default_motion_specs(), GetParam());
  const LocomotionGenerator gen(sk, spec);
  const Clip clip = gen.sample(gen.targets().period_frames);
  const ModelSpaceClip m = forward_kinematics(sk, clip);
  // The thigh's swing (knee ahead of the pelvis) against the opposite arm's.
  std::vector<double> wrist_l, knee_l, knee_r, pelvis_yaw, thorax_yaw;
  for (std::int32_t f = 0; f < clip.frame_count; ++f) {
    const double psi = spec.turn_rate * f / spec.fps;
    const glm::quat unturn = glm::angleAxis(static_cast<float>(-psi), glm::vec3(0, 1, 0));
    const glm::vec3 root = m.position(f, dj::Hips);
    wrist_l.push_back((unturn * (m.position(f, dj::LeftHand) - root)).z);
    knee_l.push_back((unturn * (m.position(f, dj::LeftLeg) - root)).z);
    knee_r.push_back((unturn * (m.position(f, dj::RightLeg) - root)).z);
    pelvis_yaw.push_back(
        std::remainder(heading_of(m.rotations[static_cast<std::size_t>(f) * sk.joint_count() + dj::Hips]) - psi,
                       2 * std::numbers::pi));
    thorax_yaw.push_back(
        std::remainder(heading_of(m.rotations[static_cast<std::size_t>(f) * sk.joint_count() + dj::Spine2]) - psi,
                       2 * std::numbers::pi));
  }
  EXPECT_GT(correlation(wrist_l, knee_r), 0.7);   // the left arm swings with the right leg
  EXPECT_LT(correlation(wrist_l, knee_l), -0.7);  // and against the left leg
  EXPECT_LT(correlation(pelvis_yaw, thorax_yaw), -0.9);
  const auto [lo, hi] = std::minmax_element(pelvis_yaw.begin(), pelvis_yaw.end());
  EXPECT_GT(*hi - *lo, 2 * 3.0 * kDeg);  // pelvis rotation of a few degrees each way
  EXPECT_LT(*hi - *lo, 2 * 15.0 * kDeg);
}

INSTANTIATE_TEST_SUITE_P(Default, LocomotionClip,
                         ::testing::Values("walk_slow", "walk", "walk_fast", "run_slow", "run_fast", "walk_turn_left",
                                           "walk_turn_right"));

// Beyond the shipped set: speeds and turn rates across the ranges.
TEST(DefaultMotions, GeneratorHoldsAcrossSpeedsAndTurns) {
  const Skeleton sk = default_skeleton();
  struct Case {
    biomech::Gait gait;
    double speed;
  };
  for (const Case& c : {Case{biomech::Gait::Walk, 0.8}, Case{biomech::Gait::Walk, 1.6}, Case{biomech::Gait::Walk, 2.1},
                        Case{biomech::Gait::Run, 2.0}, Case{biomech::Gait::Run, 3.5}, Case{biomech::Gait::Run, 6.5}}) {
    for (double turn : {0.0, 0.6, -0.6}) {
      LocomotionSpec spec;
      spec.name = "sweep";
      spec.gait = c.gait;
      spec.speed = c.speed;
      spec.turn_rate = turn;
      const LocomotionGenerator gen(sk, spec);
      const std::int32_t N = gen.targets().period_frames;
      const Clip clip = gen.sample(3 * N);
      CycleOptions o;
      o.loop = CycleOptions::Loop::Never;
      const CycleReport r = analyze_cycle(sk, clip, o);
      ASSERT_TRUE(r.found) << c.speed << " " << turn;
      EXPECT_EQ(r.period_frames, N) << c.speed << " " << turn;
      EXPECT_EQ(r.steps, 2) << c.speed << " " << turn;
      EXPECT_NEAR(r.mean_speed / c.speed, 1.0, 0.02) << c.speed << " " << turn;
      EXPECT_NEAR(r.turn_rate, turn, 1e-3) << c.speed << " " << turn;
      EXPECT_LT(measure_foot_skating(sk, clip).max_cm, 0.5) << c.speed << " " << turn;
    }
  }
}

TEST(DefaultMotions, IdleStandsStillAndLoops) {
  const Skeleton sk = default_skeleton();
  const LocomotionSpec spec = spec_named(default_motion_specs(), "idle");
  const LocomotionGenerator gen(sk, spec);
  EXPECT_NEAR(gen.targets().period_s, 4.0, 1e-9);
  const Clip clip = gen.make_clip();
  const ModelSpaceClip m = forward_kinematics(sk, clip);
  double sway = 0;
  for (std::int32_t f = 0; f < clip.frame_count; ++f) {
    for (std::int32_t a : {dj::LeftFoot, dj::RightFoot, dj::LeftToeBase, dj::RightToeBase})
      ASSERT_LT(glm::length(m.position(f, a) - m.position(0, a)), 1e-4f) << "frame " << f;
    sway = std::max(sway, static_cast<double>(std::abs(m.position(f, dj::Hips).x - m.position(0, dj::Hips).x)));
  }
  EXPECT_GT(sway, 0.005);  // it breathes and shifts its weight
  const auto J = static_cast<std::size_t>(sk.joint_count());
  std::vector<glm::quat> q0(J), qT(J);
  glm::vec3 r0, rT;
  gen.pose_at(0.0, q0, r0);
  gen.pose_at(gen.targets().period_s, qT, rT);
  EXPECT_LT(glm::length(r0 - rT), 1e-6f);
  for (std::size_t j = 0; j < J; ++j) EXPECT_GT(std::abs(glm::dot(q0[j], qT[j])), 1.0f - 1e-6f);
  CycleOptions o;
  o.min_mean_speed = 0.0;
  o.max_period_s = 5.0;
  o.min_period_s = 3.0;
  const CycleReport r = analyze_cycle(sk, clip, o);
  ASSERT_TRUE(r.found);
  EXPECT_TRUE(r.input_is_loop);
  EXPECT_EQ(r.period_frames, clip.frame_count);
  EXPECT_EQ(r.steps, 0);
  EXPECT_LT(r.mean_speed, 1e-3);
}

}  // namespace
}  // namespace throng::motion
