// Motion analysis through BVH files. It lives with the io tests because it
// needs the BVH reader and writer (io depends on motion, not the reverse).
// - The default motion set (motion/default_set.h) exported as BVH reads
//   back with the same joint positions and the same measured cycle.
// - Cycle analysis (motion/cycle.h) on the real walks and the jog in
//   ../shared/data/bvh: plausible cadence, speed and stride, a loop that
//   closes, and the foot-skating figures printed. Skipped with a message
//   when the shared folder is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include "io/bvh_reader.h"
#include "io/bvh_writer.h"
#include "motion/cycle.h"
#include "motion/default_set.h"
#include "motion/fk.h"
#include "motion/foot_skating.h"
#include "tests/shared_data.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

TEST(DefaultMotionsBvh, ExportReadsBackWithTheSameMotionAndCycle) {
  const motion::Skeleton skeleton = motion::default_skeleton();
  for (const motion::DefaultMotion& m : motion::make_default_motions(skeleton)) {
    BvhWriteOptions w;  // ZXY, centimetres: what `throng export-default` writes
    w.frame_time = 1.0 / m.spec.fps;
    const std::string text = write_bvh_string(skeleton, m.clip, w);
    const BvhFile back = parse_bvh(text, m.spec.name + ".bvh");
    ASSERT_EQ(back.skeleton.names, skeleton.names) << m.spec.name;
    EXPECT_EQ(back.unit, motion::LengthUnit::Centimetre) << m.spec.name;  // detected from the leg length
    ASSERT_EQ(back.clip.frame_count, m.clip.frame_count);
    for (std::size_t r = 0; r < motion::kRoleCount; ++r)
      EXPECT_EQ(back.skeleton.roles[r], skeleton.roles[r])
          << m.spec.name << " " << motion::to_string(static_cast<motion::Role>(r));
    const motion::ModelSpaceClip a = motion::forward_kinematics(skeleton, m.clip);
    const motion::ModelSpaceClip b = motion::forward_kinematics(back.skeleton, back.clip);
    float worst = 0.0f;
    for (std::size_t i = 0; i < a.positions.size(); ++i)
      worst = std::max(worst, glm::length(a.positions[i] - b.positions[i]));
    EXPECT_LT(worst, 1e-4f) << m.spec.name;  // 0.1 mm
    if (m.spec.gait == motion::biomech::Gait::Stand) continue;
    const motion::CycleReport before = motion::analyze_cycle(skeleton, m.clip);
    const motion::CycleReport after = motion::analyze_cycle(back.skeleton, back.clip);
    ASSERT_TRUE(after.found) << m.spec.name;
    EXPECT_EQ(after.period_frames, before.period_frames) << m.spec.name;
    EXPECT_EQ(after.steps, 2) << m.spec.name;
    EXPECT_NEAR(after.cadence, m.targets.cadence, 1e-3 * m.targets.cadence) << m.spec.name;
    EXPECT_NEAR(after.mean_speed, m.spec.speed, 0.01 * m.spec.speed) << m.spec.name;
  }
}

struct Expect {
  const char* file;
  double cadence_lo, cadence_hi;  // steps/min
  double speed_lo, speed_hi;      // m/s
};

// Walks at 80-140 steps/min and 0.5-2 m/s; the jog at 140-190 and 2-3.5.
constexpr Expect kLocomotion[] = {
    {"cmu_02_01_walk_mb.bvh", 80, 140, 0.5, 2.0},  {"cmu_05_01_walk_daz.bvh", 80, 140, 0.5, 2.0},
    {"cmu_07_03_walk_daz.bvh", 80, 140, 0.5, 2.0}, {"cmu_08_08_walk_fast_daz.bvh", 80, 140, 0.5, 2.0},
    {"cmu_16_15_walk_daz.bvh", 80, 140, 0.5, 2.0}, {"cmu_16_36_run_jog_daz.bvh", 140, 190, 2.0, 3.5},
};

TEST(CycleOnSharedFiles, WalksAndJogHavePlausibleCycles) {
  THRONG_NEED_SHARED_BVH(dir);
  std::printf("%-30s %6s %7s %6s %9s %7s %7s %9s %9s %8s\n", "file", "frames", "period", "steps", "cadence", "stride",
              "speed", "skate_cm", "p95_cm", "contacts");
  for (const Expect& e : kLocomotion) {
    const fs::path path = *dir / e.file;
    if (!fs::exists(path)) {
      ADD_FAILURE() << "missing " << path;
      continue;
    }
    const BvhFile f = read_bvh(path.string());
    motion::CycleOptions o;
    o.skip_frames = 1;  // frame 0 is the converter's reference pose
    const motion::CycleReport r = motion::analyze_cycle(f.skeleton, f.clip, o);
    ASSERT_TRUE(r.found) << e.file;
    EXPECT_EQ(r.steps, 2) << e.file;  // one stride: one contact per foot
    EXPECT_GE(r.cadence, e.cadence_lo) << e.file;
    EXPECT_LE(r.cadence, e.cadence_hi) << e.file;
    EXPECT_GE(r.mean_speed, e.speed_lo) << e.file;
    EXPECT_LE(r.mean_speed, e.speed_hi) << e.file;
    // The stride against the root's own travel over the cycle, read from the
    // clip: the straight chord from frame a to frame b is never longer than
    // the path, and these takes walk nearly straight, so hardly shorter.
    ASSERT_LT(r.end_frame, f.clip.frame_count) << e.file;
    const glm::vec3 from = f.clip.root_positions[static_cast<std::size_t>(r.start_frame)];
    const glm::vec3 to = f.clip.root_positions[static_cast<std::size_t>(r.end_frame)];
    const double chord = std::hypot(to.x - from.x, to.z - from.z);
    EXPECT_GE(r.stride_length, 0.99 * chord) << e.file;
    EXPECT_LE(r.stride_length, 1.10 * chord) << e.file;
    EXPECT_LT(r.pose_rms_m, 0.05) << e.file;  // the best loop matches within a few cm

    // Closing the loop: repeated, the closed cycle is found again with the
    // same period and a seam no worse than the original match.
    const motion::Clip closed = motion::make_cyclic(f.clip, r);
    motion::CycleOptions again_options;
    again_options.loop = motion::CycleOptions::Loop::Never;
    const motion::CycleReport again = motion::analyze_cycle(f.skeleton, motion::repeat_cycle(closed, 3), again_options);
    ASSERT_TRUE(again.found) << e.file;
    EXPECT_NEAR(again.period_frames, r.period_frames, 1) << e.file;
    EXPECT_LE(again.pose_rms_m, r.pose_rms_m + 0.002) << e.file;

    const motion::FootSkatingReport skate = motion::measure_foot_skating(f.skeleton, f.clip, o.contacts);
    std::printf("%-30s %6d %6.3fs %6d %9.1f %6.2fm %5.2fm/s %9.2f %9.2f %8d\n", e.file, f.clip.frame_count, r.period_s,
                r.steps, r.cadence, r.stride_length, r.mean_speed, skate.mean_cm, skate.p95_cm, skate.contacts);
    EXPECT_GE(skate.contacts, 2) << e.file;  // at least the cycle's own steps
  }
}

}  // namespace
}  // namespace throng::io
