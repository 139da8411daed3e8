// motion/motion_texture on CUDA against the CPU: forward_kinematics over
// every row of a motion texture, float and half texels.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "motion/motion_texture.h"
#include "tests/gpu/gpu_test.h"
#include "tests/motion/random_motion.h"

namespace throng::motion {
namespace {

TEST(CudaMotionTextureFk, MatchesCpuForFloatAndHalfTexels) {
  THRONG_REQUIRE_GPU();
  std::mt19937 rng(31);
  const Skeleton skeleton = testing::random_skeleton(rng, 27);
  const Clip clip = testing::random_clip(skeleton, 500, rng, true);
  for (const TexelFormat format : {TexelFormat::Float32, TexelFormat::Float16}) {
    SCOPED_TRACE(format == TexelFormat::Float32 ? "float32" : "float16");
    const MotionTexture texture = make_motion_texture(skeleton, clip, format);
    // The texture is built on the host; forward_kinematics uploads it to
    // current_memory() and returns host copies.
    const auto run = [&](Memory) { return forward_kinematics(texture); };
    const ModelSpaceClip cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
    const ModelSpaceClip gpu = gpu_test::run_on(gpu_test::device_side(), run);
    // Decoding half texels is exact on both; then the FK chain of
    // motion_fk_batch_test.cpp: the same bounds.
    EXPECT_TRUE(gpu_test::near(gpu.rotations, cpu.rotations, {0.0, 5e-5})) << "rotations";
    EXPECT_TRUE(gpu_test::near(gpu.positions, cpu.positions, {1e-6, 2e-4})) << "positions";
  }
}

}  // namespace
}  // namespace throng::motion
