// motion/fk_batch on CUDA against the CPU: BatchFkJob.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "motion/fk_batch.h"
#include "tests/gpu/gpu_test.h"
#include "tests/motion/random_motion.h"

namespace throng::motion {
namespace {

TEST(CudaBatchFk, MatchesCpu) {
  THRONG_REQUIRE_GPU();
  constexpr int kJoints = 30, kFrames = 40;
  constexpr Index kCharacters = 2500;
  std::mt19937 rng(23);
  const Skeleton skeleton = testing::random_skeleton(rng, kJoints);
  const Clip clip = testing::random_clip(skeleton, kFrames, rng, false);
  std::vector<std::int32_t> frames;
  for (Index c = 0; c < kCharacters; ++c)
    frames.push_back(static_cast<std::int32_t>(rng() % (kFrames + 6)) - 3);  // some out of range
  struct Out {
    std::vector<glm::vec3> p;
    std::vector<glm::quat> q;
  };
  const auto run = [&](Memory m) {
    Buffer<std::int32_t> parents = gpu_test::upload(skeleton.parents, m), bf = gpu_test::upload(frames, m);
    Buffer<glm::vec3> offsets = gpu_test::upload(skeleton.offsets, m), roots = gpu_test::upload(clip.root_positions, m);
    Buffer<glm::quat> rotations = gpu_test::upload(clip.rotations, m);
    Buffer<glm::vec3> out_p(kCharacters * kJoints, m);
    Buffer<glm::quat> out_q(kCharacters * kJoints, m);
    BatchFkJob job;
    job.joint_count = kJoints;
    job.frame_count = kFrames;
    job.parents = parents.span();
    job.offsets = offsets.span();
    job.clip_rotations = rotations.span();
    job.clip_roots = roots.span();
    job.frames = bf.span();
    job.out_positions = out_p.span();
    job.out_rotations = out_q.span();
    job.run();
    return Out{out_p.to_vector(), out_q.to_vector()};
  };
  const Out cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Out gpu = gpu_test::run_on(gpu_test::device_side(), run);
  // A chain of up to 30 quaternion products (each component a 4-term dot
  // product the GPU may contract into FMAs): ~2 roundings per level, so
  // ~60 * 6e-8 = 4e-6 on unit quaternions; 5e-5 leaves a margin of 10.
  EXPECT_TRUE(gpu_test::near(gpu.q, cpu.q, {0.0, 5e-5})) << "rotations";
  // Positions: up to 30 offsets of 5-40 cm rotated by those quaternions
  // plus a root within 5 m (|p| up to ~17 m): the rotation error times the
  // offsets plus a rounding per level, about 5e-5 m; allow 2e-4 m.
  EXPECT_TRUE(gpu_test::near(gpu.p, cpu.p, {1e-6, 2e-4})) << "positions";
}

}  // namespace
}  // namespace throng::motion
