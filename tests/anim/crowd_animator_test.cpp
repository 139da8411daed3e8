// The batch locomotion and pose stages against the per-character reference
// (motion/locomotion.h), across thread counts, under LOD masks and with the
// motion cache.
#include "anim/crowd_animator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "core/error.h"
#include "core/exec.h"
#include "core/ground.h"
#include "tests/anim/crowd_fixture.h"

namespace throng::anim {
namespace {

using testing::Crowd;
using testing::kPi;
using testing::random_crowd;
const motion::BlendSpace1D& space() { return testing::default_space(); }

double angle_deg(const glm::quat& a, const glm::quat& b) { return rotation_angle_deg(a, b); }

// Local rotations from world rotations (root: relative to its yaw frame).
std::vector<glm::quat> locals_of(const std::vector<glm::quat>& world, std::int32_t J, Index c) {
  const motion::Skeleton& s = space().skeleton();
  std::vector<glm::quat> out(static_cast<std::size_t>(J));
  for (std::int32_t j = 0; j < J; ++j) {
    const glm::quat& w = world[static_cast<std::size_t>(c * J + j)];
    const std::int32_t p = s.parents[static_cast<std::size_t>(j)];
    out[static_cast<std::size_t>(j)] = p < 0 ? w : glm::inverse(world[static_cast<std::size_t>(c * J + p)]) * w;
  }
  return out;
}

TEST(CrowdAnimator, MatchesThePerCharacterReference) {
  const Index n = 400;
  const Crowd crowd = random_crowd(n, 11);
  CrowdAnimatorConfig config;
  config.lod = false;
  config.cache = false;
  config.foot_lock = false;  // the reference has none (tests/anim/foot_lock_test.cpp)
  CrowdAnimator animator(space(), n, config);
  animator.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
  animator.set_speeds(crowd.speeds);
  const motion::BlendSpaceView v = space().view();
  std::vector<motion::LocomotionCharacter> ref(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) {
    auto& r = ref[static_cast<std::size_t>(i)];
    r.position = crowd.positions[static_cast<std::size_t>(i)];
    r.yaw = crowd.yaws[static_cast<std::size_t>(i)];
    r.scale = crowd.scales[static_cast<std::size_t>(i)];
    r.phase = crowd.phases[static_cast<std::size_t>(i)];
  }
  motion::LocomotionStep step;
  const std::int32_t J = animator.joint_count();
  std::vector<glm::vec3> p(static_cast<std::size_t>(J));
  std::vector<glm::quat> q(static_cast<std::size_t>(J));
  for (int frame = 0; frame < 5; ++frame) {
    const FrameStats& stats = animator.animate({step.dt, nullptr, true});
    EXPECT_EQ(stats.joints_synthesised, n * J);
    const auto positions = animator.joint_positions().std();
    const auto rotations = animator.joint_rotations().std();
    double worst_p = 0.0, worst_q = 0.0;
    for (Index i = 0; i < n; ++i) {
      auto& r = ref[static_cast<std::size_t>(i)];
      motion::advance_locomotion(v, step, crowd.speeds[static_cast<std::size_t>(i)], 0.0f, 0.0f, r.scale, r.position,
                                 r.yaw, r.phase, r.blend_speed);
      motion::synthesise_pose(v, motion::character_frame(v, r.blend_speed, r.phase, r.position, r.yaw, r.scale),
                              p.data(), q.data());
      for (std::int32_t j = 0; j < J; ++j) {
        worst_p = std::max(worst_p, static_cast<double>(glm::length(positions[static_cast<std::size_t>(i * J + j)] -
                                                                    p[static_cast<std::size_t>(j)])));
        worst_q = std::max(worst_q,
                           angle_deg(rotations[static_cast<std::size_t>(i * J + j)], q[static_cast<std::size_t>(j)]));
      }
    }
    EXPECT_LT(worst_p, 1e-5) << frame;
    EXPECT_LT(worst_q, 1e-3) << frame;
  }
}

TEST(CrowdAnimator, IdenticalOutputForOneTwoAndManyThreads) {
  const Index n = 6000;
  const Crowd crowd = random_crowd(n, 12);
  const Camera cam = testing::crowd_camera();
  struct Result {
    std::vector<glm::vec3> p;
    std::vector<glm::quat> q;
    std::vector<std::uint32_t> masks;
    Index synthesised = 0, from_cache = 0;
    MotionCacheStats cache;
  };
  const auto run = [&](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    CrowdAnimatorConfig config;
    config.draw_matrices = true;
    CrowdAnimator animator(space(), n, config);
    animator.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
    animator.set_speeds(crowd.speeds);
    Result r;
    for (int frame = 0; frame < 4; ++frame) {
      const FrameStats& s = animator.animate({1.0f / 60.0f, &cam, true});
      r.synthesised += s.joints_synthesised;
      r.from_cache += s.from_cache;
      r.cache = s.cache;
    }
    r.p.assign(animator.joint_positions().begin(), animator.joint_positions().end());
    r.q.assign(animator.joint_rotations().begin(), animator.joint_rotations().end());
    r.masks.assign(animator.joint_masks().begin(), animator.joint_masks().end());
    return r;
  };
  const Result one = run(1);
  EXPECT_GT(one.from_cache, 0);
  EXPECT_LT(one.synthesised, 4 * n * space().joint_count());  // LOD turned joints off
  for (int threads : {2, 7}) {
    const Result other = run(threads);
    EXPECT_EQ(std::memcmp(one.p.data(), other.p.data(), one.p.size() * sizeof(glm::vec3)), 0) << threads;
    EXPECT_EQ(std::memcmp(one.q.data(), other.q.data(), one.q.size() * sizeof(glm::quat)), 0) << threads;
    EXPECT_EQ(one.masks, other.masks) << threads;
    EXPECT_EQ(one.synthesised, other.synthesised) << threads;
    EXPECT_EQ(one.from_cache, other.from_cache) << threads;
    EXPECT_EQ(one.cache.hits, other.cache.hits) << threads;
    EXPECT_EQ(one.cache.misses, other.cache.misses) << threads;
  }
}

// A joint whose LOD bit is off is not synthesised: the per-character count
// equals the mask's popcount (so its sum equals the histogram's total), the
// joint shows the held (mean) rotation of the dominant clip, and every
// synthesised joint equals full synthesis.
TEST(CrowdAnimator, MaskedJointsAreNotSynthesised) {
  const Index n = 3000;
  const Crowd crowd = random_crowd(n, 13, 60.0f);
  const Camera cam = testing::crowd_camera();
  CrowdAnimatorConfig config;
  config.cache = false;
  CrowdAnimator masked(space(), n, config);
  config.lod = false;
  CrowdAnimator full(space(), n, config);
  for (CrowdAnimator* a : {&masked, &full}) {
    a->place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
    a->set_speeds(crowd.speeds);
  }
  const FrameStats& s = masked.animate({1.0f / 60.0f, &cam, true});
  full.animate({1.0f / 60.0f, nullptr, true});
  ASSERT_TRUE(s.lod.has_value());
  EXPECT_EQ(s.joints_synthesised, s.lod->total_joints_synthesised);
  const std::int32_t J = masked.joint_count();
  const std::int32_t W = mask_word_count(J);
  const auto masks = masked.joint_masks().std();
  const auto counts = masked.evaluated().std();
  const std::vector<glm::quat> world_masked(masked.joint_rotations().begin(), masked.joint_rotations().end());
  const std::vector<glm::quat> world_full(full.joint_rotations().begin(), full.joint_rotations().end());
  const motion::BlendSpaceView v = space().view();
  const auto speeds = masked.blend_speeds().std();
  Index partly = 0;
  double worst_kept = 0.0, worst_held = 0.0;
  for (Index c = 0; c < n; ++c) {
    std::int32_t bits = 0;
    for (std::int32_t w = 0; w < W; ++w) bits += popcount32(masks[static_cast<std::size_t>(c * W + w)]);
    ASSERT_EQ(counts[static_cast<std::size_t>(c)], bits) << c;
    if (bits < J) ++partly;
    const auto lm = locals_of(world_masked, J, c);
    const auto lf = locals_of(world_full, J, c);
    const glm::quat* held = motion::held_rotations(
        v, motion::blend_point(v, motion::blend_coordinate(v, speeds[static_cast<std::size_t>(c)])));
    // A leg whose foot LOD dropped is not planted (planted feet are a
    // detail of the finest level): its thigh and knee are the plain blend,
    // not full synthesis's IK, and are left out here.
    std::vector<std::uint8_t> ik_without_foot(static_cast<std::size_t>(J), 0);
    for (const motion::LegChain& leg : v.legs) {
      const std::int32_t thigh = leg.joints[leg.count - 3], knee = leg.joints[leg.count - 2],
                         ankle = leg.joints[leg.count - 1];
      if (!joint_synthesised(masks.data() + c * W, ankle))
        ik_without_foot[static_cast<std::size_t>(thigh)] = ik_without_foot[static_cast<std::size_t>(knee)] = 1;
    }
    for (std::int32_t j = 1; j < J; ++j) {
      const bool kept = joint_synthesised(masks.data() + c * W, j);
      if (kept && ik_without_foot[static_cast<std::size_t>(j)]) continue;
      if (kept)
        worst_kept = std::max(worst_kept, angle_deg(lm[static_cast<std::size_t>(j)], lf[static_cast<std::size_t>(j)]));
      else
        worst_held = std::max(worst_held, angle_deg(lm[static_cast<std::size_t>(j)], held[j]));
    }
  }
  EXPECT_GT(partly, n / 4);  // the camera sees most of the crowd small
  EXPECT_LT(worst_held, 1e-3);
  EXPECT_LT(worst_kept, 1e-3);
}

// A hit reads the bucket's cycle at the character's phase; synthesis at the
// character's own w (no quantisation) at that phase differs by at most the
// error the table reports.
TEST(CycleCache, AHitReadsWhatSynthesisGivesWithinTheReportedError) {
  const Index n = 3000;
  const Crowd crowd = random_crowd(n, 14);
  CrowdAnimatorConfig config;
  config.lod = false;
  config.foot_lock = false;  // compared with synthesis alone
  config.max_new_cycles_per_frame = 1000;
  CrowdAnimator cached(space(), n, config);
  cached.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
  cached.set_speeds(crowd.speeds);
  const QuantisationError reported = cached.cache()->quantisation_error(101, 96);
  std::printf("cache error: max %.3f deg (x = %.3f, phase %.3f, joint %d), mean %.4f deg over %lld samples\n",
              reported.max_deg, reported.worst_w, reported.worst_phase, reported.worst_joint, reported.mean_deg,
              static_cast<long long>(reported.samples));
  EXPECT_GT(reported.max_deg, 0.0);
  // Absolute caps, so a growing error cannot hide behind a growing estimate:
  // buckets 0.05 wide (half a bucket, 0.025, from the exact blend point) at
  // most 11.4 deg on one joint when measured, 0.12 deg on average.
  EXPECT_LT(reported.max_deg, 13.0);
  EXPECT_LT(reported.mean_deg, 0.25);
  const std::int32_t J = cached.joint_count();
  const motion::BlendSpaceView v = space().view();  // exact: no buckets
  double worst = 0.0, sum = 0.0;
  Index terms = 0;
  for (int frame = 0; frame < 3; ++frame) {
    const FrameStats& s = cached.animate({1.0f / 60.0f, nullptr, true});
    if (frame == 0) continue;  // the first frame fills the cache
    EXPECT_EQ(s.from_cache, n);
    const std::vector<glm::quat> world(cached.joint_rotations().begin(), cached.joint_rotations().end());
    const auto shown = cached.blend_speeds().std();
    const auto phase = cached.phases().std();
    const auto yaw = cached.yaws().std();
    for (Index c = 0; c < n; ++c) {
      const auto k = static_cast<std::size_t>(c);
      auto local = locals_of(world, J, c);
      local[0] = glm::inverse(motion::yaw_quat(yaw[k])) * local[0];
      const motion::CharacterFrame f = motion::character_frame(v, shown[k], phase[k], glm::vec3(0.0f), 0.0f, 1.0f);
      const motion::PlantedLegs legs = motion::plant_legs(v, f, nullptr);
      for (std::int32_t j = 0; j < J; ++j) {
        const double a = angle_deg(local[static_cast<std::size_t>(j)], motion::synthesised_rotation(v, f, legs, j));
        worst = std::max(worst, a);
        sum += a;
        ++terms;
      }
    }
  }
  std::printf("measured on %lld characters: max %.3f deg, mean %.4f deg\n", static_cast<long long>(n), worst,
              sum / static_cast<double>(terms));
  EXPECT_LE(worst, 1.1 * reported.max_deg + 1e-3);
  EXPECT_GT(terms, 0);
  EXPECT_LT(worst, 10.0);  // 8.3 deg measured
  EXPECT_LT(sum / static_cast<double>(terms), 0.25);
}

TEST(CycleCache, CountsCharactersAndEvictsFirstInFirstOut) {
  const Index n = 2000;
  Crowd crowd = random_crowd(n, 15);
  CrowdAnimatorConfig config;
  config.lod = false;
  config.cache_config.capacity_bytes =
      3 * static_cast<std::size_t>(default_cache_frames(space())) * space().joint_count() * sizeof(glm::quat);
  CrowdAnimator animator(space(), n, config);
  animator.place(crowd.positions, crowd.yaws, {}, crowd.phases);  // scale 1: one blend speed, one key
  ASSERT_EQ(animator.cache()->slot_count(), 3);
  Index lookups = 0;
  for (int frame = 0; frame < 6; ++frame) {
    for (float& s : crowd.speeds)
      s = 0.5f + 0.7f * static_cast<float>(frame);  // one key per frame, a new one each time
    animator.set_speeds(crowd.speeds);
    const FrameStats& s = animator.animate({1.0f / 60.0f, nullptr, true});
    lookups += n;
    EXPECT_EQ(s.cache.hits + s.cache.misses, lookups);
    EXPECT_LE(s.cache.bytes, config.cache_config.capacity_bytes);
    EXPECT_EQ(s.cycles_stored, 1);
    EXPECT_EQ(s.from_cache, n);  // stored before the pose stage reads it
  }
  const MotionCacheStats& stats = animator.cache()->cache().stats();
  EXPECT_EQ(stats.misses, 6 * n);
  EXPECT_EQ(stats.evictions, 3);
  EXPECT_EQ(stats.entries, 3u);
  // Back to the previous frame's speed: a hit.
  animator.animate({1.0f / 60.0f, nullptr, true});
  EXPECT_EQ(animator.cache()->cache().stats().hits, n);
}

TEST(CrowdAnimator, DrivenByTheSimulationsMapArrays) {
  const Index n = 50;
  std::vector<glm::vec2> pos, vel;
  std::vector<float> heading;
  for (Index i = 0; i < n; ++i) {
    pos.emplace_back(0.5f * static_cast<float>(i), -2.0f + 0.1f * static_cast<float>(i));
    const float h = 0.13f * static_cast<float>(i) - 3.0f;
    heading.push_back(h);
    vel.emplace_back(0.05f * static_cast<float>(i) * std::cos(h), 0.05f * static_cast<float>(i) * std::sin(h));
  }
  CrowdAnimatorConfig config;
  config.lod = false;
  config.cache = false;
  CrowdAnimator animator(space(), n, config);
  const Buffer<glm::vec2> p(std::span<const glm::vec2>(pos), current_memory());
  const Buffer<glm::vec2> v(std::span<const glm::vec2>(vel), current_memory());
  const Buffer<float> h(std::span<const float>(heading), current_memory());
  for (int frame = 0; frame < 3; ++frame) {
    animator.drive_from_map(p.span(), v.span(), h.span());
    animator.animate({1.0f / 60.0f, nullptr, false});
  }
  const auto positions = animator.positions().std();
  const auto yaws = animator.yaws().std();
  const auto shown = animator.blend_speeds().std();
  const std::int32_t J = animator.joint_count();
  const auto joints = animator.joint_positions().std();
  for (Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_EQ(positions[k], world_from_ground(pos[k]));
    EXPECT_NEAR(std::remainder(yaws[k] - yaw_from_heading(heading[k]), 2.0f * kPi), 0.0f, 1e-5f);
    EXPECT_NEAR(shown[k], glm::length(vel[k]), 1e-6f);
    // The hips are over the agent (within the pelvis sway).
    const glm::vec3 hips = joints[static_cast<std::size_t>(i * J)];
    EXPECT_LT(glm::length(glm::vec2(hips.x, hips.z) - glm::vec2(positions[k].x, positions[k].z)), 0.1f) << i;
    // Facing: the character's +Z in world is the map heading.
    const glm::vec3 forward = glm::vec3(std::sin(yaws[k]), 0.0f, std::cos(yaws[k]));
    const glm::vec3 expected = world_from_ground(glm::vec2(std::cos(heading[k]), std::sin(heading[k])));
    EXPECT_LT(glm::length(forward - expected), 1e-5f);
  }
}

// The acceptance figure again, through the batch stage: ten characters,
// each at its own constant speed, tracked over 8 s.
TEST(CrowdAnimator, FootSkatingOfTheDefaultSetThroughTheBatch) {
  const std::int32_t speeds = 10;
  for (const bool cache : {false, true}) {
    CrowdAnimatorConfig config;
    config.lod = false;
    config.cache = cache;
    std::vector<glm::vec3> positions;
    std::vector<float> yaws(speeds, 0.0f), v;
    for (std::int32_t i = 0; i < speeds; ++i) {
      positions.emplace_back(3.0f * static_cast<float>(i), 0.0f, 0.0f);
      v.push_back(space().max_speed() * static_cast<float>(i + 1) / static_cast<float>(speeds));
    }
    std::printf("%s\n%8s %9s %9s %9s\n", cache ? "with the cache (bucket 0.05):" : "synthesised:", "speed", "contacts",
                "mean_cm", "p95_cm");
    for (std::int32_t i = 0; i < speeds; ++i) {
      CrowdAnimator one(space(), 1, config);
      one.place(std::span(positions).subspan(static_cast<std::size_t>(i), 1),
                std::span(yaws).subspan(static_cast<std::size_t>(i), 1));
      one.set_speeds(std::span(v).subspan(static_cast<std::size_t>(i), 1));
      one.track({0});
      for (int f = 0; f < 480; ++f) one.animate({1.0f / 60.0f, nullptr, true});
      const motion::FootSkatingReport r = one.foot_skating();
      std::printf("%8.2f %9d %9.3f %9.3f\n", v[static_cast<std::size_t>(i)], r.contacts, r.mean_cm, r.p95_cm);
      // 8 s of walking or running: several steps of each foot, every one measured.
      EXPECT_GE(r.contacts, 10) << v[static_cast<std::size_t>(i)] << (cache ? " cached" : "");
      EXPECT_LT(r.mean_cm, 2.0) << v[static_cast<std::size_t>(i)] << (cache ? " cached" : "");
    }
  }
}

TEST(JointShapes, SpheresSpanTheBoneToTheChild) {
  const motion::Skeleton& s = space().skeleton();
  const std::vector<glm::mat4x3> shapes = joint_shapes(s);
  ASSERT_EQ(shapes.size(), static_cast<std::size_t>(s.joint_count()));
  // LeftForeArm's only child is LeftHand at (0.25, 0, 0): poles at the joint and the hand.
  const std::int32_t fore = s.find("LeftForeArm"), hand = s.find("LeftHand");
  const glm::vec3 p(1.0f, 2.0f, 3.0f);
  const glm::quat q = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1.0f, 2.0f, -1.0f)));
  const glm::mat4x3 m = draw_matrix(p, q, 1.5f, shapes[static_cast<std::size_t>(fore)]);
  const glm::vec3 bottom = m * glm::vec4(0.0f, -1.0f, 0.0f, 1.0f), top = m * glm::vec4(0.0f, 1.0f, 0.0f, 1.0f);
  EXPECT_LT(glm::length(bottom - p), 1e-5f);
  EXPECT_LT(glm::length(top - (p + q * (1.5f * s.offsets[static_cast<std::size_t>(hand)]))), 1e-5f);
  // Across the bone: the radius is thickness x length.
  const glm::vec3 side = m * glm::vec4(1.0f, 0.0f, 0.0f, 1.0f);
  EXPECT_NEAR(glm::length(side - 0.5f * (top + bottom)), 1.5f * 0.18f * 0.25f, 1e-5f);
}

TEST(PoseJob, BadSpansAreNamed) {
  const motion::BlendSpaceTables tables(space());
  Buffer<glm::vec3> positions(3), joints(3 * space().joint_count());
  Buffer<float> yaws(3), phases(3), shown(2);
  Buffer<glm::quat> rotations(3 * space().joint_count());
  PoseJob job;
  job.blend = tables.view();
  job.positions = positions.span();
  job.yaws = yaws.span();
  job.phases = phases.span();
  job.blend_speeds = shown.span();
  job.joint_positions = joints.span();
  job.joint_rotations = rotations.span();
  try {
    job.run();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("PoseJob.blend_speeds"), std::string::npos) << e.what();
  }
  PoseJob empty;
  EXPECT_THROW(empty.validate(), Error);
}

}  // namespace
}  // namespace throng::anim
