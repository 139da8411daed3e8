// Stream pools: the history ring, time dilation, stopping and restarting,
// growing the history at run time, pose memory, and the unique pool.
#include "anim/stream_pool.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "stream_reference.h"

namespace throng::anim {
namespace {

using namespace testing;
constexpr float kFps = 30.0f;
constexpr float kDt = 1.0f / kFps;

// A clip whose frame k has root x = k: the history's contents identify the frame.
AnimClip counting_clip(int joints, int frames) {
  AnimClip c = wiggle_clip(joints, frames, kDt, "count");
  auto clip = std::make_shared<motion::Clip>(*c.clip);
  for (int f = 0; f < frames; ++f) clip->root_positions[static_cast<std::size_t>(f)] = glm::vec3(f, 1.0f, 0.0f);
  c.clip = clip;
  c.loop = false;
  return c;
}

// A stream started filled holds M poses at once, frames newest - M + 1 ..
// newest, and agents may read every offset without dilating.
TEST(StreamHistory, StartFilledWritesTheWholeHistoryAtOnce) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "count";
  spec.history = 12;
  spec.root = RootMotion::Keep;
  spec.running = false;
  const AnimClip clip = counting_clip(rig.joint_count(), 100);
  pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(clip));
  const AnimStream& s = pool[0];
  pool.start_filled(0, 40);
  EXPECT_EQ(s.state(), StreamState::Running);
  EXPECT_EQ(s.written(), 12);
  EXPECT_EQ(s.newest_frame(), 40);
  EXPECT_EQ(s.max_offset(), 11);
  EXPECT_EQ(s.view().max_offset, 11);
  // Offset o: the controller o frames before its newest, i.e. clip frame 11 - o.
  for (int o = 0; o < 12; ++o) EXPECT_FLOAT_EQ(s.pose_at(o).root.x, static_cast<float>(11 - o)) << o;
  pool.step(41);
  EXPECT_FLOAT_EQ(s.pose_at(0).root.x, 12.0f);
  EXPECT_FLOAT_EQ(s.pose_at(11).root.x, 1.0f);
  EXPECT_EQ(s.max_offset(), 11);
  // A running stream restarts filled from time 0.
  pool.start_filled(0, 41);
  EXPECT_FLOAT_EQ(s.pose_at(0).root.x, 11.0f);
  EXPECT_THROW(pool.start_filled(3, 0), Error);
}

TEST(StreamHistory, RingHoldsTheLastMPosesNewestFirst) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "count";
  spec.history = 8;
  spec.root = RootMotion::Keep;
  const AnimClip clip = counting_clip(rig.joint_count(), 100);
  pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(clip));
  const AnimStream& s = pool[0];
  EXPECT_EQ(s.written(), 0);
  EXPECT_EQ(s.newest_frame(), -1);
  Pose want;
  for (int frame = 0; frame < 20; ++frame) {
    pool.step(frame);
    EXPECT_EQ(s.newest_frame(), frame);
    EXPECT_EQ(s.written(), std::min(frame + 1, 8));
    // Offset o holds the pose written o frames ago: clip frame (frame - o).
    for (int o = 0; o < s.written(); ++o) {
      const Pose p = s.pose_at(o);
      EXPECT_FLOAT_EQ(p.root.x, static_cast<float>(frame - o)) << frame << " " << o;
      sample_clip(clip, (frame - o) * static_cast<double>(kDt), want);
      EXPECT_EQ(p.local, want.local);
    }
    // P is the head slot: the controller's current pose.
    Pose now;
    s.controller().evaluate(now);
    EXPECT_EQ(s.pose_at(0).local, now.local);
    // Its skinning palette is the pose's forward kinematics times the inverse binds.
    const SourceView v = s.view();
    const Pose head = s.pose_at(0);
    const auto ref = reference_palette(rig, to_double(head.local), glm::dvec3(head.root), glm::dvec3(0.0), 0.0);
    for (int j = 0; j < rig.joint_count(); ++j)
      ASSERT_LT(palette_error(v.skinning[v.head * rig.joint_count() + j], ref[static_cast<std::size_t>(j)]), 1e-5);
  }
  EXPECT_EQ(s.head(), 19 % 8);
}

// A slot holds J local rotations (16 bytes each), J skinning matrices (48)
// and the root (12).
TEST(StreamHistory, PoseMemoryIsTheSumOfStreamSizesWithoutPadding) {
  const Rig& human = humanoid_rig();
  const Rig fingered = make_rig("fingered", fingered_skeleton());
  StreamPool pool(kFps);
  const std::vector<std::pair<const Rig*, int>> streams = {{&human, 64}, {&fingered, 64}, {&human, 16}, {&fingered, 5}};
  std::size_t want = 0, padded = 0;
  for (std::size_t i = 0; i < streams.size(); ++i) {
    StreamSpec spec;
    spec.name = std::string(1, 's').append(std::to_string(i));
    spec.history = streams[i].second;
    const int J = streams[i].first->joint_count();
    pool.add(*streams[i].first, streams[i].first == &human ? 0 : 1, spec,
             std::make_unique<ClipPlayer>(wiggle_clip(J, 10, kDt)));
    want += static_cast<std::size_t>(streams[i].second) *
            (static_cast<std::size_t>(J) * (sizeof(glm::quat) + sizeof(Mat3x4)) + sizeof(glm::vec3));
    padded +=
        static_cast<std::size_t>(streams[i].second) * (28u * (sizeof(glm::quat) + sizeof(Mat3x4)) + sizeof(glm::vec3));
    EXPECT_EQ(pool[static_cast<std::int32_t>(i)].pose_bytes(),
              static_cast<std::size_t>(streams[i].second) * (J * 64u + 12u));
  }
  EXPECT_EQ(pool.pose_bytes(), want);
  EXPECT_LT(pool.pose_bytes(), padded);
}

TEST(TimeDilation, OffsetsGrowAtTheChangeRateAndNeverPassWhatWasWritten) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "walk";
  spec.history = 64;
  spec.time_to_dilate = 4.0f;  // 120 frames for 64 slots
  pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(wiggle_clip(rig.joint_count(), 10, kDt)));
  const AnimStream& s = pool[0];
  const double rate = 64.0 / (4.0 * kFps);  // (M_new - M) / (timeToDilate * animFrameRate), M = 0 at start
  EXPECT_NEAR(s.change_rate(), rate, 1e-12);
  for (int frame = 0; frame < 200; ++frame) {
    pool.step(frame);
    const int expected_max = std::min(63, static_cast<int>(std::floor(std::max(0, frame) * rate + 1e-9)));
    EXPECT_EQ(s.max_offset(), expected_max) << frame;
    EXPECT_LT(s.max_offset(), s.written()) << frame;
    const SourceView v = s.view();
    for (int target : {0, 7, 31, 63}) {
      const int read = effective_offset(v, target);
      EXPECT_EQ(read, std::min(target, expected_max));
      EXPECT_LT(read, s.written());
    }
  }
  EXPECT_EQ(s.max_offset(), 63);
}

TEST(TimeDilation, TooShortADilationTimeIsRefused) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "fast";
  spec.history = 64;
  spec.time_to_dilate = 1.0f;  // 30 frames for 64 slots: offsets would outrun the history
  try {
    pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(wiggle_clip(rig.joint_count(), 10, kDt)));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "streams.fast.time_to_dilate");
  }
}

TEST(StreamState, StoppedStreamsHoldTheirHistoryAndRestartDilated) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "count";
  spec.history = 16;
  spec.time_to_dilate = 16.0f / kFps;  // the fastest: one slot per frame
  spec.root = RootMotion::Keep;
  pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(counting_clip(rig.joint_count(), 200)));
  for (int f = 0; f < 40; ++f) pool.step(f);
  EXPECT_EQ(pool[0].max_offset(), 15);
  pool.stop(0);
  EXPECT_EQ(pool[0].state(), StreamState::Stopped);
  const Pose held = pool[0].pose_at(3);
  for (int f = 40; f < 50; ++f) pool.step(f);
  EXPECT_EQ(pool[0].newest_frame(), 39);
  EXPECT_EQ(pool[0].pose_at(3).local, held.local);
  pool.start(0);
  EXPECT_EQ(pool[0].max_offset(), 0);
  EXPECT_EQ(pool[0].written(), 0);
  pool.step(50);
  EXPECT_FLOAT_EQ(pool[0].pose_at(0).root.x, 0.0f);  // restarted from time 0
  EXPECT_EQ(pool[0].written(), 1);
}

TEST(StreamState, InPlaceRootKeepsOnlyTheHeight) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "count";
  pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(counting_clip(rig.joint_count(), 200)));
  for (int f = 0; f < 5; ++f) pool.step(f);
  EXPECT_EQ(pool[0].pose_at(0).root, glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST(StreamHistory, GrowingAtRunTimeKeepsOffsetsAndDilates) {
  const Rig& rig = humanoid_rig();
  StreamPool pool(kFps);
  StreamSpec spec;
  spec.name = "count";
  spec.history = 16;
  spec.time_to_dilate = 16.0f / kFps;
  spec.root = RootMotion::Keep;
  pool.add(rig, 0, spec, std::make_unique<ClipPlayer>(counting_clip(rig.joint_count(), 400)));
  for (int f = 0; f < 30; ++f) pool.step(f);
  EXPECT_THROW(pool.set_history(0, 64, 0.5f), Error);  // 48 more slots need 1.6 s
  pool.set_history(0, 64, 3.2f);
  const AnimStream& s = pool[0];
  EXPECT_NEAR(s.change_rate(), 48.0 / (3.2 * kFps), 1e-6);
  for (int o = 0; o < 16; ++o) EXPECT_FLOAT_EQ(s.pose_at(o).root.x, static_cast<float>(29 - o));
  for (int f = 30; f < 200; ++f) {
    pool.step(f);
    EXPECT_LT(s.max_offset(), s.written());
    for (int o = 0; o < s.written(); ++o) ASSERT_FLOAT_EQ(s.pose_at(o).root.x, static_cast<float>(f - o));
  }
  EXPECT_EQ(s.max_offset(), 63);
  pool.set_history(0, 8, 0.0f);  // shrinking is immediate
  EXPECT_EQ(s.max_offset(), 7);
  EXPECT_FLOAT_EQ(s.pose_at(7).root.x, 192.0f);
}

TEST(UniquePool, InstancesAreAllocatedPerRigUpToCapacity) {
  const Rig& human = humanoid_rig();
  const Rig fingered = make_rig("fingered", fingered_skeleton());
  UniquePool pool(kFps);
  pool.set_capacity(human, 0, 2);
  pool.set_capacity(fingered, 1, 1);
  EXPECT_EQ(pool.pose_bytes(), 2u * (22u * 64u + 12u) + 1u * (28u * 64u + 12u));
  const std::int32_t wave =
      pool.add_animation({"wave", 0, std::make_unique<ClipPlayer>(counting_clip(22, 50)), RootMotion::Keep});
  const std::int32_t bow =
      pool.add_animation({"bow", 1, std::make_unique<ClipPlayer>(wiggle_clip(28, 50, kDt)), RootMotion::Keep});
  EXPECT_THROW(pool.add_animation({"bad", 1, std::make_unique<ClipPlayer>(wiggle_clip(22, 5, kDt)), RootMotion::Keep}),
               Error);
  const std::int32_t a = pool.acquire(wave);
  pool.step(0);
  pool.step(1);
  const std::int32_t b = pool.acquire(wave);
  EXPECT_NE(a, b);
  EXPECT_THROW(pool.acquire(wave), Error);  // two humanoid slots
  const std::int32_t c = pool.acquire(bow);
  EXPECT_EQ(pool.active_count(), 3);
  pool.step(2);
  // Each instance plays from its own start: a is two frames ahead of b.
  EXPECT_NEAR(pool.controller(a)->time() - pool.controller(b)->time(), 2.0 * kDt, 1e-6);
  const auto views = pool.views();
  EXPECT_EQ(views[a].newest, 2);
  EXPECT_EQ(views[c].joints, 28);
  EXPECT_FLOAT_EQ(views[b].roots[0].x, 0.0f);
  EXPECT_FLOAT_EQ(views[a].roots[0].x, 2.0f);
  pool.release(a);
  EXPECT_FALSE(pool.active(a));
  EXPECT_EQ(pool.acquire(wave), a);  // the slot is reused
}

}  // namespace
}  // namespace throng::anim
