// The motion cache against a brute-force FIFO model, and SLERP sampling
// against a reference SLERP built from the exponential map in double.
#include "anim/motion_cache.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "core/error.h"
#include "tests/motion/reference_rotation.h"

namespace throng::anim {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  return glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
}

using test::reference_slerp;

double angle_deg(glm::dquat a, glm::dquat b) { return rotation_angle_deg(glm::quat(a), glm::quat(b)); }

TEST(Slerp, GlmSlerpMatchesReferenceAndTakesTheShortArc) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> t01(0.0f, 1.0f);
  int negative_dots = 0;
  for (int i = 0; i < 5000; ++i) {
    const glm::quat a = random_rotation(rng);
    glm::quat b = random_rotation(rng);
    if (i % 7 == 0) b = glm::normalize(a * glm::quat(1.0f, 1e-3f, -2e-3f, 0.5e-3f));  // nearly equal
    if (i % 3 == 0) b = -b;  // the same rotation, the other hemisphere
    negative_dots += glm::dot(a, b) < 0.0f;
    const float t = t01(rng);
    const glm::quat got = glm::slerp(a, b, t);
    const glm::dquat want = reference_slerp(glm::dquat(a), glm::dquat(b), t);
    ASSERT_LT(angle_deg(glm::dquat(got), want), 2e-3) << i;
    // Shortest arc: the path from a covers t of the (<= 180 degree) angle to b.
    const double total = rotation_angle_deg(a, b);
    ASSERT_LE(total, 180.0);
    EXPECT_NEAR(rotation_angle_deg(a, got), t * total, 2e-3 + 1e-4 * total) << i;
  }
  EXPECT_GT(negative_dots, 1000);
}

TEST(Slerp, RotationAngleIsAccurateNearZeroAndSignBlind) {
  const glm::quat a = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 2, 3)));
  const glm::quat b = a * glm::angleAxis(static_cast<float>(1e-4 * kPi / 180.0), glm::vec3(0, 1, 0));
  EXPECT_NEAR(rotation_angle_deg(a, b), 1e-4, 2e-5);
  EXPECT_NEAR(rotation_angle_deg(a, -a), 0.0, 1e-6);
  EXPECT_NEAR(rotation_angle_deg(glm::quat(1, 0, 0, 0), glm::angleAxis(2.0f, glm::vec3(1, 0, 0))), 2.0 * 180.0 / kPi,
              1e-3);
}

CachedCycle random_cycle(std::mt19937& rng, std::int32_t frames, std::int32_t joints) {
  CachedCycle c;
  c.frame_count = frames;
  c.joint_count = joints;
  c.duration = 1.0f;
  for (std::int32_t i = 0; i < frames * joints; ++i) c.rotations.push_back(random_rotation(rng));
  return c;
}

TEST(SampleCycle, CyclePointWrapsAndSurvivesBadPhases) {
  const CyclePoint a = cycle_point(10, 0.25f);
  EXPECT_EQ(a.f0, 2);
  EXPECT_EQ(a.f1, 3);
  EXPECT_NEAR(a.t, 0.5f, 1e-5f);
  const CyclePoint b = cycle_point(10, -0.05f);  // = 0.95
  EXPECT_EQ(b.f0, 9);
  EXPECT_EQ(b.f1, 0);
  EXPECT_NEAR(b.t, 0.5f, 1e-4f);
  for (float bad : {std::nanf(""), INFINITY, -INFINITY, 1e30f, std::nextafter(1.0f, 0.0f)}) {
    const CyclePoint p = cycle_point(10, bad);
    EXPECT_GE(p.f0, 0);
    EXPECT_LT(p.f0, 10);
    EXPECT_GE(p.t, 0.0f);
    EXPECT_LE(p.t, 1.0f);
  }
  const CyclePoint one = cycle_point(1, 0.7f);
  EXPECT_EQ(one.f0, 0);
  EXPECT_EQ(one.f1, 0);
}

TEST(SampleCycle, FramesAtTheirPhasesSlerpBetweenAndWrapAround) {
  std::mt19937 rng(2);
  const CachedCycle c = random_cycle(rng, 10, 4);
  std::vector<glm::quat> out(4);
  for (int f = 0; f < 10; ++f) {
    sample_cycle(c, static_cast<float>(f) / 10.0f, out.data());
    for (int j = 0; j < 4; ++j)
      EXPECT_LT(rotation_angle_deg(out[static_cast<std::size_t>(j)], c.rotations[static_cast<std::size_t>(f * 4 + j)]),
                1e-3);
  }
  // Between frames 3 and 4, 30% of the way; between the last frame and frame 0.
  for (const auto& [phase, f0, f1, t] :
       {std::tuple{0.33f, 3, 4, 0.3}, std::tuple{0.95f, 9, 0, 0.5}, std::tuple{1.33f, 3, 4, 0.3},
        std::tuple{-0.67f, 3, 4, 0.3}, std::tuple{0.999999f, 9, 0, 0.99999}}) {
    sample_cycle(c, phase, out.data());
    for (int j = 0; j < 4; ++j) {
      const glm::dquat want = reference_slerp(glm::dquat(c.rotations[static_cast<std::size_t>(f0 * 4 + j)]),
                                              glm::dquat(c.rotations[static_cast<std::size_t>(f1 * 4 + j)]), t);
      EXPECT_LT(angle_deg(glm::dquat(out[static_cast<std::size_t>(j)]), want), 5e-3) << "phase " << phase;
    }
  }
}

// Content does not matter for the accounting: identity rotations are cheap.
CachedCycle plain_cycle(std::int32_t frames, std::int32_t joints) {
  CachedCycle c;
  c.frame_count = frames;
  c.joint_count = joints;
  c.duration = 1.0f;
  c.rotations.assign(static_cast<std::size_t>(frames * joints), glm::quat(1, 0, 0, 0));
  return c;
}

// The model: a list of (key, bytes), oldest first, and the same rules.
struct ModelCache {
  std::size_t capacity;
  std::vector<std::pair<std::pair<std::uint32_t, std::int32_t>, std::size_t>> entries;
  std::int64_t evictions = 0, insertions = 0, rejected = 0, hits = 0, misses = 0;

  std::size_t bytes() const {
    std::size_t b = 0;
    for (const auto& e : entries) b += e.second;
    return b;
  }
  bool find(std::pair<std::uint32_t, std::int32_t> k) {
    for (const auto& e : entries)
      if (e.first == k) {
        ++hits;
        return true;
      }
    ++misses;
    return false;
  }
  void insert(std::pair<std::uint32_t, std::int32_t> k, std::size_t size) {
    for (std::size_t i = 0; i < entries.size(); ++i)
      if (entries[i].first == k) {
        entries.erase(entries.begin() + static_cast<std::ptrdiff_t>(i));
        break;
      }
    if (size > capacity) {
      ++rejected;
      return;
    }
    while (bytes() + size > capacity) {
      entries.erase(entries.begin());
      ++evictions;
    }
    entries.push_back({k, size});
    ++insertions;
  }
};

TEST(MotionCache, FifoOrderAndByteAccountingMatchABruteForceModel) {
  for (std::size_t capacity : {std::size_t{0}, std::size_t{4000}, std::size_t{25000}, std::size_t{200000}}) {
    MotionCacheConfig config;
    config.bucket_width = 0.1f;
    config.capacity_bytes = capacity;
    MotionCache cache(config);
    ModelCache model{capacity, {}};
    std::mt19937 rng(static_cast<unsigned>(capacity) + 5);
    std::uniform_int_distribution<int> op(0, 2), bucket(0, 9), state(0, 2), frames(1, 60), joints(1, 40);
    std::uniform_real_distribution<float> w(-0.2f, 1.2f);
    for (int step = 0; step < 3000; ++step) {
      if (op(rng) == 0) {
        const float x = w(rng);
        const std::uint32_t s = static_cast<std::uint32_t>(state(rng));
        const int b = cache.bucket_of(x);
        EXPECT_EQ(cache.find(x, s) != nullptr, model.find({s, b}));
      } else {
        const int b = bucket(rng);
        const std::uint32_t s = static_cast<std::uint32_t>(state(rng));
        const CachedCycle c = plain_cycle(frames(rng), joints(rng));
        const std::size_t size = c.bytes();
        const CachedCycle* stored = cache.insert(b, c, s);
        model.insert({s, b}, size);
        EXPECT_EQ(stored == nullptr, size > capacity);
      }
      const MotionCacheStats& st = cache.stats();
      ASSERT_LE(st.bytes, capacity) << "step " << step;
      ASSERT_EQ(st.bytes, model.bytes()) << "step " << step;
      ASSERT_EQ(st.entries, model.entries.size());
      std::vector<std::pair<std::uint32_t, std::int32_t>> order;
      for (const auto& e : model.entries) order.push_back(e.first);
      ASSERT_EQ(cache.fifo_order(), order) << "step " << step;
      ASSERT_EQ(st.evictions, model.evictions);
      ASSERT_EQ(st.insertions, model.insertions);
      ASSERT_EQ(st.rejected, model.rejected);
      ASSERT_EQ(st.hits, model.hits);
      ASSERT_EQ(st.misses, model.misses);
    }
    if (capacity >= 25000) {
      EXPECT_GT(cache.stats().evictions, 100);
    }
    if (capacity == 0) {
      EXPECT_EQ(cache.stats().entries, 0u);
    }
  }
}

TEST(MotionCache, HitReturnsExactlyWhatWasInserted) {
  MotionCache cache;  // 20 MiB, width 0.05
  EXPECT_EQ(cache.config().capacity_bytes, 20u * 1024u * 1024u);
  EXPECT_EQ(cache.bucket_count(), 20);
  std::mt19937 rng(9);
  std::vector<CachedCycle> inserted;
  for (int b = 0; b < 20; ++b) {
    inserted.push_back(random_cycle(rng, 20 + b, 31));
    cache.insert(b, inserted.back());
  }
  for (int b = 0; b < 20; ++b) {
    const CachedCycle* hit = cache.find(cache.bucket_centre(b));
    ASSERT_NE(hit, nullptr);
    const CachedCycle& want = inserted[static_cast<std::size_t>(b)];
    EXPECT_EQ(hit->frame_count, want.frame_count);
    ASSERT_EQ(hit->rotations.size(), want.rotations.size());
    EXPECT_EQ(std::memcmp(hit->rotations.data(), want.rotations.data(), want.bytes()), 0);
  }
  EXPECT_EQ(cache.stats().hits, 20);
  EXPECT_EQ(cache.stats().misses, 0);
}

TEST(MotionCache, BucketsCoverTheUnitIntervalAndClamp) {
  for (float width : {0.05f, 0.1f, 0.3f, 1.0f, 0.0001f}) {
    MotionCacheConfig config;
    config.bucket_width = width;
    const MotionCache cache(config);
    EXPECT_EQ(cache.bucket_count(), static_cast<std::int32_t>(std::lround(std::ceil(1.0 / width - 1e-6))));
    EXPECT_EQ(cache.bucket_of(0.0f), 0);
    EXPECT_EQ(cache.bucket_of(-3.0f), 0);
    EXPECT_EQ(cache.bucket_of(std::nanf("")), 0);
    EXPECT_EQ(cache.bucket_of(1.0f), cache.bucket_count() - 1);
    EXPECT_EQ(cache.bucket_of(7.0f), cache.bucket_count() - 1);
    for (std::int32_t b = 0; b < cache.bucket_count(); b += std::max(1, cache.bucket_count() / 50)) {
      const float c = cache.bucket_centre(b);
      EXPECT_EQ(cache.bucket_of(c), b);
      EXPECT_GE(c, 0.0f);
      EXPECT_LE(c, 1.0f);
    }
  }
  // 0.3: buckets [0, .3) [.3, .6) [.6, .9) [.9, 1], the last one narrower.
  MotionCacheConfig config;
  config.bucket_width = 0.3f;
  const MotionCache cache(config);
  EXPECT_EQ(cache.bucket_count(), 4);
  EXPECT_NEAR(cache.bucket_centre(3), 0.95f, 1e-6f);
  for (float bad : {0.0f, -0.1f, 1.5f, std::nanf("")}) {
    config.bucket_width = bad;
    EXPECT_THROW(MotionCache{config}, Error);
  }
}

TEST(MotionCache, InvalidCyclesAndBucketsAreRejected) {
  MotionCache cache;
  std::mt19937 rng(3);
  CachedCycle c = random_cycle(rng, 4, 3);
  c.rotations.pop_back();
  EXPECT_THROW(cache.insert(0, c), Error);
  c = random_cycle(rng, 4, 3);
  c.duration = 0.0f;
  EXPECT_THROW(cache.insert(0, c), Error);
  EXPECT_THROW(cache.insert(20, random_cycle(rng, 4, 3)), Error);
  EXPECT_THROW(cache.insert(-1, random_cycle(rng, 4, 3)), Error);
  EXPECT_EQ(cache.stats().entries, 0u);
}

// A smooth family of cycles: cadence (frame count, duration) and amplitude
// change with w, as a blend of a slow and a fast clip would.
CachedCycle synthetic_cycle(float w) {
  CachedCycle c;
  c.joint_count = 6;
  c.frame_count = static_cast<std::int32_t>(std::lround(48.0 - 20.0 * w));
  c.duration = 1.2f - 0.5f * w;
  for (std::int32_t f = 0; f < c.frame_count; ++f)
    for (std::int32_t j = 0; j < c.joint_count; ++j) {
      const double phase = static_cast<double>(f) / c.frame_count;
      const double angle = (0.3 + 0.6 * w) * std::sin(2 * kPi * phase + j) + 0.2 * w * j;
      const glm::dvec3 axis = glm::normalize(glm::dvec3(1.0, 0.3 * j, 0.5 - 0.1 * j));
      c.rotations.push_back(glm::quat(glm::angleAxis(angle, axis)));
    }
  return c;
}

TEST(MotionCache, CachedPoseIsWithinTheQuantisationErrorItReports) {
  MotionCacheConfig config;
  config.bucket_width = 0.1f;
  const QuantisationError e = measure_quantisation_error(config, synthetic_cycle, 201, 64);
  EXPECT_EQ(e.samples, 201 * 64);
  EXPECT_GT(e.max_deg, 0.5);  // it is a real error ...
  EXPECT_LT(e.max_deg, 30.0);
  EXPECT_GT(e.mean_deg, 0.0);
  EXPECT_LT(e.mean_deg, e.max_deg);
  MotionCache cache(config);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::quat> cached(6), exact(6);
  double worst = 0;
  for (int i = 0; i < 3000; ++i) {
    const float w = u(rng), phase = u(rng);
    cache.sample(w, phase, synthetic_cycle, cached);
    sample_cycle(synthetic_cycle(w), phase, exact.data());
    for (int j = 0; j < 6; ++j)
      worst =
          std::max(worst, rotation_angle_deg(cached[static_cast<std::size_t>(j)], exact[static_cast<std::size_t>(j)]));
  }
  // ... and random (w, phase) stay within the grid's maximum (plus a margin for falling between grid points).
  EXPECT_LE(worst, 1.05 * e.max_deg);
  EXPECT_GT(worst, 0.5 * e.max_deg);
  EXPECT_EQ(cache.stats().misses, cache.bucket_count());  // each bucket synthesised once
  EXPECT_EQ(cache.stats().hits, 3000 - cache.bucket_count());
  // Halving the bucket width roughly halves the error.
  config.bucket_width = 0.05f;
  const QuantisationError finer = measure_quantisation_error(config, synthetic_cycle, 201, 64);
  EXPECT_LT(finer.max_deg, 0.7 * e.max_deg);
  EXPECT_GT(finer.max_deg, 0.3 * e.max_deg);
  std::printf("[ quantisation ] width 0.1: max %.3f deg, mean %.3f deg; width 0.05: max %.3f deg, mean %.3f deg\n",
              e.max_deg, e.mean_deg, finer.max_deg, finer.mean_deg);
}

TEST(MotionCache, OversizedCyclesAreServedButNotStored) {
  MotionCacheConfig config;
  config.capacity_bytes = 1000;  // smaller than one 6-joint, 28+-frame cycle
  MotionCache cache(config);
  const CachedCycle& c = cache.get(0.7f, synthetic_cycle);
  EXPECT_EQ(c.joint_count, 6);
  EXPECT_EQ(cache.stats().rejected, 1);
  EXPECT_EQ(cache.stats().entries, 0u);
  std::vector<glm::quat> out(5);
  EXPECT_THROW(cache.sample(0.7f, 0.0f, synthetic_cycle, out), Error);
}

}  // namespace
}  // namespace throng::anim
