// Locomotion synthesis on real motion capture: the walk (16_15) and the jog
// (16_36) of CMU subject 16 blended by speed. Reads ../shared/data/bvh
// (THRONG_SHARED_DIR, set by CTest); skips when it is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>

#include "io/bvh_reader.h"
#include "motion/locomotion.h"
#include "tests/shared_data.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

struct Subject16 {
  BvhFile walk, jog;
  std::optional<motion::BlendSpace1D> space;
};

const Subject16* subject16() {
  static const std::optional<Subject16> loaded = []() -> std::optional<Subject16> {
    const auto dir = ::throng::test::shared_bvh_dir();
    if (!dir) return std::nullopt;
    Subject16 s;
    s.walk = read_bvh((*dir / "cmu_16_15_walk_daz.bvh").string());
    s.jog = read_bvh((*dir / "cmu_16_36_run_jog_daz.bvh").string());
    motion::LocomotionOptions o;
    o.cycle.skip_frames = 1;  // frame 0 is the converter's reference pose
    std::vector<motion::LocomotionClip> clips;
    clips.push_back(motion::prepare_locomotion_clip(s.walk.skeleton, s.walk.clip, "walk_16_15", o));
    clips.push_back(motion::prepare_locomotion_clip(s.walk.skeleton, s.jog.clip, "jog_16_36", o));
    s.space.emplace(s.walk.skeleton, std::move(clips));
    return s;
  }();
  return loaded ? &*loaded : nullptr;
}

TEST(LocomotionOnSharedFiles, WalkAndJogOfOneSubjectFormABlendSpace) {
  const Subject16* s = subject16();
  THRONG_REQUIRE_SHARED_DATA(s != nullptr);
  // Same subject, same skeleton: the jog's clip plays on the walk's skeleton.
  ASSERT_EQ(s->walk.skeleton.joint_count(), s->jog.skeleton.joint_count());
  for (std::size_t j = 0; j < s->walk.skeleton.offsets.size(); ++j)
    EXPECT_LT(glm::length(s->walk.skeleton.offsets[j] - s->jog.skeleton.offsets[j]), 1e-4f)
        << s->walk.skeleton.names[j];
  const motion::BlendSpace1D& space = *s->space;
  ASSERT_EQ(space.clip_count(), 2);
  std::printf("%-12s %6s %8s %8s %8s %10s %8s %8s %8s %8s\n", "clip", "frames", "speed", "stride", "period", "straight",
              "L up", "R down", "R up", "cleanup");
  for (const motion::LocomotionClip& c : space.clips())
    std::printf("%-12s %6d %8.3f %8.3f %8.3f %9.2fd %8.3f %8.3f %8.3f %7.1fcm\n", c.name.c_str(), c.frame_count(),
                c.speed, c.stride_m, c.period_s, c.turn_removed_rad * 57.29578, c.event(motion::FootEvent::LeftUp),
                c.event(motion::FootEvent::RightDown), c.event(motion::FootEvent::RightUp),
                100.0 * c.contact_cleanup_m);
  const motion::LocomotionClip& walk = space.clips()[0];
  const motion::LocomotionClip& jog = space.clips()[1];
  EXPECT_EQ(walk.name, "walk_16_15");
  EXPECT_NEAR(walk.speed, 1.09, 0.1);  // as the cycle analysis measures (docs/default_motions.md)
  EXPECT_NEAR(jog.speed, 2.65, 0.1);
  // Walking keeps each foot down for more than half the cycle, jogging less.
  EXPECT_GT(walk.event(motion::FootEvent::LeftUp), 0.5f);
  EXPECT_LT(jog.event(motion::FootEvent::LeftUp), 0.45f);
  EXPECT_NEAR(walk.event(motion::FootEvent::RightDown), 0.5f, 0.06f);
  EXPECT_NEAR(jog.event(motion::FootEvent::RightDown), 0.5f, 0.06f);
  // Walk and jog: the legs are synchronised separately (touchdown + liftoff each).
  EXPECT_EQ(space.sync()[0].group[1].count, 2);
  EXPECT_EQ(space.sync()[0].group[2].count, 2);
}

// The acceptance figure on real mocap: straight constant-speed locomotion at
// ten speeds from the walk's to the jog's, foot skating below 2 cm per contact.
TEST(LocomotionOnSharedFiles, FootSkatingOfWalkJogBlendsBelowTwoCentimetres) {
  const Subject16* s = subject16();
  THRONG_REQUIRE_SHARED_DATA(s != nullptr);
  const motion::BlendSpace1D& space = *s->space;
  motion::LocomotionStep step;
  step.dt = 1.0f / 120.0f;  // the files' rate
  std::printf("%8s %9s %9s %9s %9s\n", "speed", "contacts", "mean_cm", "p95_cm", "max_cm");
  for (int i = 0; i < 10; ++i) {
    const float speed = space.min_speed() + (space.max_speed() - space.min_speed()) * static_cast<float>(i) / 9.0f;
    const motion::FootSkatingReport r = motion::locomotion_foot_skating(space, speed, 8.0, step);
    std::printf("%8.2f %9d %9.3f %9.3f %9.3f\n", speed, r.contacts, r.mean_cm, r.p95_cm, r.max_cm);
    EXPECT_GE(r.contacts, 12) << speed;
    EXPECT_LT(r.mean_cm, 2.0) << speed;
  }
  // For scale: the raw walk take slides several centimetres per contact.
  const motion::FootSkatingReport raw = motion::measure_foot_skating(s->walk.skeleton, s->walk.clip);
  std::printf("raw 16_15 take: mean %.2f cm, p95 %.2f cm over %d contacts\n", raw.mean_cm, raw.p95_cm, raw.contacts);
  EXPECT_GE(raw.contacts, 4);  // the take holds several steps of each foot
}

}  // namespace
}  // namespace throng::io
