// The lane twins of the scalar rotation kernels (motion/quat_lanes.h)
// against the scalar ones (motion/phase.h), lane by lane: the same bits,
// on random pairs in both hemispheres, with lanes at the first frame
// (t = 0), at the end points of the blend and at the exact same rotation.
#include "motion/quat_lanes.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

namespace throng::motion {
namespace {

bool same_bits(const glm::quat& a, const glm::quat& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

struct RandomLanes {
  std::mt19937 rng{17};
  std::normal_distribution<float> g{0.0f, 1.0f};
  std::uniform_real_distribution<float> u{0.0f, 1.0f};
  glm::quat unit() { return glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng))); }
  // Pairs a few degrees apart (a clip's neighbouring frames), far apart,
  // in the other hemisphere, or equal.
  void pairs(QuatLanes& a, QuatLanes& b) {
    for (int l = 0; l < kQuatLanes; ++l) {
      const glm::quat q = unit();
      glm::quat r = l % 4 == 0 ? unit() : glm::normalize(q * glm::angleAxis(0.3f * u(rng), glm::vec3(0, 1, 0)));
      if (l % 3 == 1) r = -r;
      if (l == 5) r = q;
      a.set(l, q);
      b.set(l, r);
    }
  }
};

TEST(QuatLanes, InterpolateFramesIsTheScalarOneLaneByLane) {
  RandomLanes random;
  for (int i = 0; i < 2000; ++i) {
    QuatLanes a, b, out;
    random.pairs(a, b);
    float t[kQuatLanes];
    for (int l = 0; l < kQuatLanes; ++l) t[l] = l == 2 ? 0.0f : l == 3 ? 1.0f : random.u(random.rng);
    interpolate_frames(kQuatLanes, a, b, t, out);
    for (int l = 0; l < kQuatLanes; ++l)
      ASSERT_TRUE(same_bits(out.get(l), interpolate_frames(a.get(l), b.get(l), t[l]))) << i << " lane " << l;
  }
}

TEST(QuatLanes, SlerpIsSlerpAtLaneByLane) {
  RandomLanes random;
  for (int i = 0; i < 2000; ++i) {
    QuatLanes a, b, out;
    random.pairs(a, b);
    const float t = i % 50 == 0 ? 0.0f : i % 50 == 1 ? 1.0f : random.u(random.rng);
    const SlerpAt s(t);
    slerp(kQuatLanes, s, a, b, out);
    for (int l = 0; l < kQuatLanes; ++l)
      ASSERT_TRUE(same_bits(out.get(l), s(a.get(l), b.get(l)))) << i << " lane " << l << " t " << t;
  }
}

}  // namespace
}  // namespace throng::motion
