// Batch FK over characters against FK of each character's frame alone.
#include "motion/fk_batch.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/exec.h"
#include "motion/fk.h"
#include "tests/motion/random_motion.h"

namespace throng::motion {
namespace {

struct Batch {
  Skeleton skeleton;
  Clip clip;
  std::vector<std::int32_t> frames;
  std::vector<glm::vec3> positions;
  std::vector<glm::quat> rotations;
  BatchFkJob job() {
    BatchFkJob j;
    j.joint_count = skeleton.joint_count();
    j.frame_count = clip.frame_count;
    j.parents = Span<const std::int32_t>(skeleton.parents.data(), skeleton.joint_count());
    j.offsets = Span<const glm::vec3>(skeleton.offsets.data(), skeleton.joint_count());
    j.clip_rotations = Span<const glm::quat>(clip.rotations.data(), static_cast<Index>(clip.rotations.size()));
    j.clip_roots = Span<const glm::vec3>(clip.root_positions.data(), clip.frame_count);
    j.frames = Span<const std::int32_t>(frames.data(), static_cast<Index>(frames.size()));
    j.out_positions = Span<glm::vec3>(positions.data(), static_cast<Index>(positions.size()));
    j.out_rotations = Span<glm::quat>(rotations.data(), static_cast<Index>(rotations.size()));
    return j;
  }
};

Batch make_batch(int characters) {
  std::mt19937 rng(11);
  Batch b;
  b.skeleton = testing::random_skeleton(rng, 20);
  b.clip = testing::random_clip(b.skeleton, 30, rng, false);
  for (int c = 0; c < characters; ++c)
    b.frames.push_back(static_cast<std::int32_t>(rng() % 34) - 2);  // some out of range
  b.positions.resize(static_cast<std::size_t>(characters * 20));
  b.rotations.resize(b.positions.size());
  return b;
}

TEST(BatchFk, EachCharacterMatchesClipFkOfItsFrame) {
  Batch b = make_batch(500);
  b.job().run();
  const ModelSpaceClip ref = forward_kinematics(b.skeleton, b.clip);
  for (std::size_t c = 0; c < b.frames.size(); ++c) {
    const std::int32_t f = std::clamp(b.frames[c], 0, b.clip.frame_count - 1);
    for (std::int32_t j = 0; j < 20; ++j) {
      ASSERT_EQ(b.positions[c * 20 + static_cast<std::size_t>(j)], ref.position(f, j)) << c << " " << j;
      ASSERT_EQ(b.rotations[c * 20 + static_cast<std::size_t>(j)], ref.rotations[static_cast<std::size_t>(f * 20 + j)]);
    }
  }
}

TEST(BatchFk, SameResultForAnyThreadCount) {
  Batch a = make_batch(3000), b = make_batch(3000);
  {
    ScopedExecution e(Backend::Cpu, 1);
    a.job().run();
  }
  {
    ScopedExecution e(Backend::Cpu, 0);
    b.job().run();
  }
  EXPECT_EQ(a.positions, b.positions);
}

TEST(BatchFk, ValidateNamesTheWrongField) {
  Batch b = make_batch(10);
  BatchFkJob j = b.job();
  j.out_rotations.count -= 1;
  try {
    j.run();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "BatchFkJob.out_rotations");
  }
  j = b.job();
  j.clip_roots.count = 0;
  EXPECT_THROW(j.validate(), Error);
  j = b.job();
  j.frame_count = 0;
  EXPECT_THROW(j.validate(), Error);
}

}  // namespace
}  // namespace throng::motion
