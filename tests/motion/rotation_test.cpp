// Euler <-> quaternion against rotation matrices built directly with glm::rotate.
#include "motion/rotation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <random>

namespace throng::motion {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dmat4 axis_matrix(char axis, double angle) {
  const glm::dvec3 v(axis == 'X', axis == 'Y', axis == 'Z');
  return glm::rotate(glm::dmat4(1.0), angle, v);
}

// The reference: the three matrices multiplied in listed order.
glm::dmat4 euler_matrix(EulerOrder order, glm::dvec3 angles) {
  const char* name = to_string(order);
  glm::dmat4 m(1.0);
  for (int n = 0; n < 3; ++n) m = m * axis_matrix(name[n], angles[name[n] - 'X']);
  return m;
}

double max_abs_diff(const glm::dmat4& a, const glm::dmat4& b) {
  double d = 0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) d = std::max(d, std::abs(a[c][r] - b[c][r]));
  return d;
}

TEST(Rotation, OrderNamesRoundTrip) {
  for (EulerOrder o : kAllEulerOrders) {
    EXPECT_EQ(parse_euler_order(to_string(o)), o);
    const auto axes = euler_axes(o);
    EXPECT_EQ(axes[0] + axes[1] + axes[2], 3);  // a permutation of 0, 1, 2
  }
  EXPECT_EQ(parse_euler_order("zxy"), EulerOrder::ZXY);
  EXPECT_FALSE(parse_euler_order("ZZY").has_value());
  EXPECT_FALSE(parse_euler_order("XY").has_value());
  EXPECT_FALSE(parse_euler_order("").has_value());
}

TEST(Rotation, SingleAxisMatchesGlmRotate) {
  for (int axis = 0; axis < 3; ++axis)
    for (double angle : {-2.5, -0.3, 0.0, 0.7, kPi / 2, 3.0}) {
      const glm::dmat4 m = glm::mat4_cast(axis_rotation(axis, angle));
      EXPECT_LT(max_abs_diff(m, axis_matrix(static_cast<char>('X' + axis), angle)), 1e-14) << axis << " " << angle;
    }
}

TEST(Rotation, EulerToQuatMatchesMatrixProductForAllOrders) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (EulerOrder o : kAllEulerOrders) {
    for (int trial = 0; trial < 2000; ++trial) {
      const glm::dvec3 a(angle(rng), angle(rng), angle(rng));
      const glm::dquat q = euler_to_quat(o, a);
      EXPECT_NEAR(glm::length(q), 1.0, 1e-14);
      const double d = max_abs_diff(glm::mat4_cast(q), euler_matrix(o, a));
      ASSERT_LT(d, 1e-13) << to_string(o) << " angles " << a.x << " " << a.y << " " << a.z;
    }
  }
}

TEST(Rotation, OrdersReallyDiffer) {
  // Guards against an implementation that ignores the order.
  const glm::dvec3 a(0.4, -0.9, 1.3);
  for (EulerOrder o1 : kAllEulerOrders)
    for (EulerOrder o2 : kAllEulerOrders)
      if (o1 != o2) {
        EXPECT_GT(max_abs_diff(glm::mat4_cast(euler_to_quat(o1, a)), glm::mat4_cast(euler_to_quat(o2, a))), 1e-3);
      }
}

// The rotation two quaternions represent, compared up to sign.
double rotation_distance(const glm::dquat& a, const glm::dquat& b) {
  return std::min(glm::length(a - b), glm::length(a + b));
}

TEST(Rotation, QuatToEulerRoundTripRandom) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (EulerOrder o : kAllEulerOrders) {
    for (int trial = 0; trial < 5000; ++trial) {
      const glm::dquat q = glm::normalize(glm::dquat(g(rng), g(rng), g(rng), g(rng)));
      const glm::dvec3 e = quat_to_euler(o, q);
      EXPECT_LE(std::abs(e[euler_axes(o)[1]]), kPi / 2 + 1e-12);
      for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(e[c]), kPi + 1e-12);
      ASSERT_LT(rotation_distance(euler_to_quat(o, e), q), 1e-12) << to_string(o);
      // Also against the independent matrix product.
      ASSERT_LT(max_abs_diff(euler_matrix(o, e), glm::mat4_cast(q)), 1e-12) << to_string(o);
    }
  }
}

TEST(Rotation, QuatToEulerNearAndAtGimbalLock) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  const double offsets[] = {0.0, 1e-12, 1e-9, 1e-8, 1e-7, 1e-5, 1e-3};
  for (EulerOrder o : kAllEulerOrders) {
    const int mid = euler_axes(o)[1];
    for (double sign : {-1.0, 1.0})
      for (double off : offsets)
        for (int trial = 0; trial < 50; ++trial) {
          glm::dvec3 a(angle(rng), angle(rng), angle(rng));
          a[mid] = sign * (kPi / 2 - off);
          const glm::dquat q = euler_to_quat(o, a);
          const glm::dvec3 e = quat_to_euler(o, q);
          ASSERT_LT(rotation_distance(euler_to_quat(o, e), q), 1e-7) << to_string(o) << " off " << off;
          // Through single precision, as the BVH writer sees clip quaternions.
          const glm::quat qf(q);
          const glm::dvec3 ef = quat_to_euler(o, glm::dquat(qf));
          ASSERT_LT(rotation_distance(euler_to_quat(o, ef), glm::normalize(glm::dquat(qf))), 1e-7) << to_string(o);
        }
  }
}

TEST(Rotation, QuatToEulerRecoversAnglesAwayFromLock) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  std::uniform_real_distribution<double> middle(-1.5, 1.5);
  for (EulerOrder o : kAllEulerOrders)
    for (int trial = 0; trial < 1000; ++trial) {
      glm::dvec3 a(angle(rng), angle(rng), angle(rng));
      a[euler_axes(o)[1]] = middle(rng);
      const glm::dvec3 e = quat_to_euler(o, euler_to_quat(o, a));
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(e[c], a[c], 1e-10) << to_string(o);
    }
}

}  // namespace
}  // namespace throng::motion
