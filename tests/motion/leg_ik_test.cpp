// Two-bone leg IK (motion/leg_ik.h) against an independent reference in
// double: the same construction written with angles (acos of the law of
// cosines, atan2 of the bend now, the turn as an axis and angle), where the
// solver works with cosines and sines only. Also the properties the
// construction promises: the ankle on a reachable target, the bone lengths
// kept, a target out of reach met by the stretched leg.
#include "motion/leg_ik.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/motion/reference_rotation.h"

namespace throng::motion {
namespace {

struct Leg {
  glm::vec3 hip, knee_offset, ankle_offset, hinge, target;
  glm::quat thigh, knee;
};

glm::quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  return glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
}

// A leg in a random pose: thigh and shin of 0.3-0.5 m hanging from a hip,
// the knee bent 0-120 degrees about a hinge square to the thigh, and a
// target at `reach` (a fraction of the leg's length) in a random direction.
Leg random_leg(std::mt19937& rng, float reach) {
  std::uniform_real_distribution<float> len(0.3f, 0.5f), bend(0.0f, 2.1f), u(-1.0f, 1.0f);
  Leg l;
  l.hip = glm::vec3(u(rng), 0.9f + u(rng), u(rng));
  l.knee_offset = glm::vec3(0.0f, -len(rng), 0.0f);
  l.ankle_offset = glm::vec3(0.0f, -len(rng), 0.0f);
  l.hinge = glm::vec3(1.0f, 0.0f, 0.0f);
  l.thigh = random_rotation(rng);
  l.knee = l.thigh * glm::angleAxis(bend(rng), l.hinge);
  glm::vec3 dir(u(rng), u(rng), u(rng));
  dir = glm::length(dir) > 1e-3f ? glm::normalize(dir) : glm::vec3(0.0f, -1.0f, 0.0f);
  const float full = glm::length(l.knee_offset) + glm::length(l.ankle_offset);
  l.target = l.hip + dir * (reach * full);
  return l;
}

glm::dvec3 dv(glm::vec3 v) { return glm::dvec3(v); }

// The reference, in double, with angles.
void reference_ik(const Leg& l, glm::dquat& r_thigh, glm::dquat& r_knee) {
  r_thigh = glm::dquat(l.thigh);
  r_knee = glm::dquat(l.knee);
  const glm::dvec3 upper = r_thigh * dv(l.knee_offset), lower = r_knee * dv(l.ankle_offset);
  const double l1 = glm::length(upper), l2 = glm::length(lower);
  const glm::dvec3 to_target = dv(l.target) - dv(l.hip);
  const double d = std::clamp(glm::length(to_target), std::abs(l1 - l2) + 1e-4, 0.9999 * (l1 + l2));
  const glm::dvec3 u = upper / l1;
  glm::dvec3 hinge_world = r_thigh * dv(l.hinge);
  hinge_world -= glm::dot(hinge_world, u) * u;
  const glm::dvec3 normal = glm::cross(upper, lower);
  const double area = glm::length(normal);
  glm::dvec3 axis;
  double bend_now;
  if (area > 1e-3 * l1 * l2 && glm::dot(normal, hinge_world) >= 0.0) {
    axis = normal / area;
    bend_now = std::acos(std::clamp(glm::dot(upper, lower) / (l1 * l2), -1.0, 1.0));
  } else {
    axis = glm::normalize(hinge_world);
    bend_now = std::atan2(glm::dot(normal, axis), glm::dot(upper, lower));
  }
  const double bend_want = std::acos(std::clamp((d * d - l1 * l1 - l2 * l2) / (2.0 * l1 * l2), -1.0, 1.0));
  r_knee = glm::angleAxis(bend_want - bend_now, axis) * r_knee;
  const glm::dvec3 ankle_now = upper + r_knee * dv(l.ankle_offset);
  const glm::dvec3 a = glm::normalize(ankle_now), b = glm::normalize(to_target);
  const glm::dvec3 c = glm::cross(a, b);
  const glm::dquat swing = glm::normalize(glm::dquat(1.0 + glm::dot(a, b), c.x, c.y, c.z));
  r_thigh = swing * r_thigh;
  r_knee = swing * r_knee;
}

glm::vec3 ankle_of(const Leg& l, const glm::quat& thigh, const glm::quat& knee) {
  return l.hip + thigh * l.knee_offset + knee * l.ankle_offset;
}

TEST(LegIk, MatchesTheAngleFormWithinAHundredthOfADegree) {
  std::mt19937 rng(11);
  double worst = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const Leg l = random_leg(rng, 0.2f + 0.85f * static_cast<float>(k % 100) / 100.0f);
    glm::quat thigh = l.thigh, knee = l.knee;
    ASSERT_TRUE(two_bone_ik(l.hip, l.knee_offset, l.ankle_offset, l.hinge, l.target, thigh, knee));
    glm::dquat ref_thigh, ref_knee;
    reference_ik(l, ref_thigh, ref_knee);
    worst = std::max({worst, test::rotation_between_deg(glm::dquat(thigh), ref_thigh),
                      test::rotation_between_deg(glm::dquat(knee), ref_knee)});
  }
  std::printf("  worst rotation off the angle form: %.2e degrees\n", worst);
  EXPECT_LT(worst, 0.01);
}

TEST(LegIk, PutsTheAnkleOnAReachableTargetAndKeepsTheBones) {
  std::mt19937 rng(12);
  for (int k = 0; k < 2000; ++k) {
    const Leg l = random_leg(rng, 0.3f + 0.6f * static_cast<float>(k % 50) / 50.0f);
    glm::quat thigh = l.thigh, knee = l.knee;
    ASSERT_TRUE(two_bone_ik(l.hip, l.knee_offset, l.ankle_offset, l.hinge, l.target, thigh, knee));
    EXPECT_LT(glm::length(ankle_of(l, thigh, knee) - l.target), 1e-4f) << k;
    EXPECT_NEAR(glm::length(thigh * l.knee_offset), glm::length(l.knee_offset), 1e-5f);
    EXPECT_NEAR(glm::length(knee * l.ankle_offset), glm::length(l.ankle_offset), 1e-5f);
  }
}

TEST(LegIk, StretchesTowardsATargetOutOfReach) {
  std::mt19937 rng(13);
  for (int k = 0; k < 500; ++k) {
    const Leg l = random_leg(rng, 1.5f);
    glm::quat thigh = l.thigh, knee = l.knee;
    ASSERT_TRUE(two_bone_ik(l.hip, l.knee_offset, l.ankle_offset, l.hinge, l.target, thigh, knee));
    const glm::vec3 ankle = ankle_of(l, thigh, knee) - l.hip, want = l.target - l.hip;
    const float full = glm::length(l.knee_offset) + glm::length(l.ankle_offset);
    EXPECT_NEAR(glm::length(ankle), 0.9999f * full, 1e-4f);
    EXPECT_GT(glm::dot(glm::normalize(ankle), glm::normalize(want)), 0.99999f);
  }
}

TEST(LegIk, ADegenerateLegIsLeftAsItIs) {
  Leg l;
  l.hip = glm::vec3(0.0f, 1.0f, 0.0f);
  l.knee_offset = glm::vec3(0.0f);  // no thigh
  l.ankle_offset = glm::vec3(0.0f, -0.4f, 0.0f);
  l.hinge = glm::vec3(1.0f, 0.0f, 0.0f);
  l.target = glm::vec3(0.1f, 0.7f, 0.0f);
  glm::quat thigh(1.0f, 0.0f, 0.0f, 0.0f), knee = glm::angleAxis(0.3f, l.hinge);
  const glm::quat knee_before = knee;
  EXPECT_FALSE(two_bone_ik(l.hip, l.knee_offset, l.ankle_offset, l.hinge, l.target, thigh, knee));
  EXPECT_EQ(knee, knee_before);
}

// turn_about against the axis and angle it stands for, over the whole
// circle and up to its ends (where the half-angle form hands over).
TEST(LegIk, TurnAboutIsTheRotationOfItsCosineAndSine) {
  const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  double worst = 0.0;
  for (int k = -2000; k <= 2000; ++k) {
    const double a = 3.14159265358979 * static_cast<double>(k) / 2000.0;
    const glm::quat got = turn_about(axis, static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)));
    worst = std::max(worst, test::rotation_between_deg(glm::dquat(got), glm::angleAxis(a, glm::dvec3(axis))));
  }
  EXPECT_LT(worst, 1e-3);
}

}  // namespace
}  // namespace throng::motion
