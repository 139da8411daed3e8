// motion/fk on CUDA against the CPU: forward_kinematics(skeleton, clip),
// over every frame of a clip with animated translations.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "motion/fk.h"
#include "tests/gpu/gpu_test.h"
#include "tests/motion/random_motion.h"

namespace throng::motion {
namespace {

TEST(CudaClipFk, MatchesCpu) {
  THRONG_REQUIRE_GPU();
  std::mt19937 rng(29);
  const Skeleton skeleton = testing::random_skeleton(rng, 31);
  const Clip clip = testing::random_clip(skeleton, 600, rng, true);
  // forward_kinematics uploads to current_memory() and returns host copies.
  const auto run = [&](Memory) { return forward_kinematics(skeleton, clip); };
  const ModelSpaceClip cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const ModelSpaceClip gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_EQ(gpu.joint_count, cpu.joint_count);
  ASSERT_EQ(gpu.frame_count, cpu.frame_count);
  // The FK chain of BatchFk (see motion_fk_batch_test.cpp) with animated
  // translations (offsets moved by ~10 cm): the same bounds.
  EXPECT_TRUE(gpu_test::near(gpu.rotations, cpu.rotations, {0.0, 5e-5})) << "rotations";
  EXPECT_TRUE(gpu_test::near(gpu.positions, cpu.positions, {1e-6, 2e-4})) << "positions";
}

}  // namespace
}  // namespace throng::motion
