// anim/skin on CUDA against the CPU: SkinJob (linear blend skinning of
// many characters from their palettes).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "anim/skin.h"
#include "tests/gpu/gpu_test.h"

namespace throng::anim {
namespace {

TEST(CudaSkin, PositionsAndNormalsMatchCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kCharacters = 300, kVertices = 700;
  constexpr std::int32_t kJoints = 22;
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w01(0.0f, 1.0f);
  std::uniform_int_distribution<int> joint(0, kJoints - 1);
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::u16vec4> joints;
  std::vector<glm::vec4> weights;
  for (Index v = 0; v < kVertices; ++v) {
    positions.emplace_back(0.4f * u(rng), 0.9f + 0.9f * u(rng), 0.3f * u(rng));
    normals.push_back(glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 0.01f)));
    joints.emplace_back(joint(rng), joint(rng), joint(rng), joint(rng));
    glm::vec4 w(w01(rng), w01(rng), v % 3 == 0 ? 0.0f : w01(rng),
                v % 2 == 0 ? 0.0f : w01(rng));  // some unused influences
    weights.push_back(w / (w.x + w.y + w.z + w.w));
  }
  // Palettes: rotations (unit quaternions) with translations of characters
  // spread over 100 m; offsets leave gaps, one is out of range (its
  // vertices stay at the origin).
  std::vector<Mat3x4> palettes;
  std::vector<Index> offsets;
  for (Index c = 0; c < kCharacters; ++c) {
    offsets.push_back(static_cast<Index>(palettes.size()) + (c % 5 == 0 ? 3 : 0));
    if (c % 5 == 0) palettes.resize(palettes.size() + 3);
    const glm::vec3 origin(50.0f * u(rng), 0.0f, 50.0f * u(rng));
    for (std::int32_t j = 0; j < kJoints; ++j) {
      const glm::quat q = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
      palettes.push_back(mat3x4_from(q, origin + glm::vec3(0.3f * u(rng), 1.0f + u(rng), 0.3f * u(rng))));
    }
  }
  offsets.back() = static_cast<Index>(palettes.size());  // past the end
  struct Out {
    std::vector<glm::vec3> p, n;
  };
  const auto run = [&](Memory m) {
    Buffer<glm::vec3> bp = gpu_test::upload(positions, m), bn = gpu_test::upload(normals, m);
    Buffer<glm::u16vec4> bj = gpu_test::upload(joints, m);
    Buffer<glm::vec4> bw = gpu_test::upload(weights, m);
    Buffer<Mat3x4> bpal = gpu_test::upload(palettes, m);
    Buffer<Index> boff = gpu_test::upload(offsets, m);
    Buffer<glm::vec3> out_p(kCharacters * kVertices, m), out_n(kCharacters * kVertices, m);
    SkinJob job;
    job.positions = bp.span();
    job.normals = bn.span();
    job.joints = bj.span();
    job.weights = bw.span();
    job.joint_count = kJoints;
    job.palettes = bpal.span();
    job.palette_offsets = boff.span();
    job.out_positions = out_p.span();
    job.out_normals = out_n.span();
    job.run();
    return Out{out_p.to_vector(), out_n.to_vector()};
  };
  const Out cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Out gpu = gpu_test::run_on(gpu_test::device_side(), run);
  // Per vertex: four 3x4 transforms (3 FMA-able dot products each) summed
  // with weights: ~40 operations on values up to ~55 m, each of which the
  // GPU may contract; 1e-5 relative plus 1e-5 m.
  EXPECT_TRUE(gpu_test::near(gpu.p, cpu.p, {1e-5, 1e-5})) << "positions";
  // Normals: the same on unit vectors, then a normalisation (sqrt, divide).
  EXPECT_TRUE(gpu_test::near(gpu.n, cpu.n, {1e-5, 1e-5})) << "normals";
}

}  // namespace
}  // namespace throng::anim
