// anim/lod on CUDA against the CPU: LodSpheresJob, LodJob (world spheres
// and root transforms) and lod_histogram.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <tuple>
#include <vector>

#include "anim/lod.h"
#include "core/camera.h"
#include "motion/default_set.h"
#include "tests/gpu/gpu_test.h"

namespace throng::anim {
namespace {

Camera street_camera() {
  Camera cam;
  cam.position = glm::vec3(0.0f, 1.7f, 8.0f);
  cam.target = glm::vec3(0.0f, 1.0f, -30.0f);
  cam.width = 1280;
  cam.height = 720;
  return cam;
}

struct Result {
  std::vector<glm::vec4> spheres;
  std::vector<std::uint8_t> levels_world, levels_root;
  std::vector<std::uint32_t> masks_world, masks_root;
  std::vector<float> coverage_world, coverage_root;
  std::vector<Index> histogram;  // level counts, then joints synthesised
};

TEST(CudaLod, SpheresLevelsAndHistogramMatchCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kN = 4000;
  const motion::Skeleton skeleton = motion::default_skeleton();
  const BodyParts parts = make_body_parts(skeleton);
  const LodConfig config = make_lod_config(parts, {2500.0f, 600.0f, 100.0f});
  const std::int32_t J = skeleton.joint_count();
  // Characters scattered in front of and behind the camera; joints jittered
  // about a standing body so the spheres are not all alike.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> x(-40.0f, 40.0f), z(-80.0f, 10.0f), u(0.0f, 1.0f), jitter(-0.3f, 0.3f);
  std::vector<glm::vec3> roots, joints;
  std::vector<float> headings, scales;
  for (Index c = 0; c < kN; ++c) {
    roots.emplace_back(x(rng), 0.0f, z(rng));
    headings.push_back(6.2831853f * u(rng) - 3.1415927f);
    scales.push_back(0.85f + 0.3f * u(rng));
    for (std::int32_t j = 0; j < J; ++j)
      joints.push_back(roots.back() +
                       glm::vec3(jitter(rng), 1.8f * static_cast<float>(j) / static_cast<float>(J), jitter(rng)));
  }
  const CameraView view = make_camera_view(street_camera());
  const auto run = [&](Memory m) {
    Result r;
    const LodTables tables(config, m);
    Buffer<glm::vec3> b_joints = gpu_test::upload(joints, m), b_roots = gpu_test::upload(roots, m);
    Buffer<float> b_scales = gpu_test::upload(scales, m), b_headings = gpu_test::upload(headings, m);
    Buffer<glm::vec4> spheres(kN * kBodyPartCount, m);
    LodSpheresJob sj;
    sj.joint_count = J;
    sj.anchors = parts.anchors;
    sj.joint_positions = b_joints.span();
    sj.scales = b_scales.span();
    sj.spheres = spheres.span();
    sj.run();
    r.spheres = spheres.to_vector();
    for (const bool from_roots : {false, true}) {
      Buffer<std::uint8_t> levels(kN * kBodyPartCount, m);
      Buffer<std::uint32_t> masks(kN * config.mask_words, m);
      Buffer<float> coverage(kN * kBodyPartCount, m);
      LodJob job;
      job.camera = view;
      job.set_tables(tables);
      if (from_roots) {
        job.roots.positions = b_roots.span();
        job.roots.headings = b_headings.span();
        job.roots.scales = b_scales.span();
        job.template_spheres = parts.rest_spheres;
      } else {
        job.spheres = spheres.span();
      }
      job.levels = levels.span();
      job.joint_masks = masks.span();
      job.coverage = coverage.span();
      job.run();
      (from_roots ? r.levels_root : r.levels_world) = levels.to_vector();
      (from_roots ? r.masks_root : r.masks_world) = masks.to_vector();
      (from_roots ? r.coverage_root : r.coverage_world) = coverage.to_vector();
      if (from_roots) {
        const LodHistogram h = lod_histogram(levels.span(), masks.span(), config.level_count, config.joint_count);
        r.histogram = h.level_counts;
        r.histogram.insert(r.histogram.end(), h.joints_synthesised.begin(), h.joints_synthesised.end());
        r.histogram.push_back(h.total_joints_synthesised);
      }
    }
    return r;
  };
  const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);

  // Sphere centres: a lerp between two joints (FMA-able), scaled radii;
  // positions up to ~90 m: one or two roundings.
  EXPECT_TRUE(gpu_test::near(gpu.spheres, cpu.spheres, {1e-6, 1e-5})) << "spheres";
  // Coverage: view transform (a 4x4 product) and the ellipse area of the
  // projected sphere (~30 operations, a sqrt): 1e-4 relative, as the CPU
  // test allows against its double-precision reference, plus 1e-3 px^2.
  EXPECT_TRUE(gpu_test::near(gpu.coverage_world, cpu.coverage_world, {1e-4, 1e-3})) << "coverage from spheres";
  EXPECT_TRUE(gpu_test::near(gpu.coverage_root, cpu.coverage_root, {1e-4, 1e-3})) << "coverage from roots";
  // Levels: thresholds on that coverage; one within a few roundings of a
  // threshold may take the neighbouring level (at most 2 parts, the CPU
  // test's allowance against double precision). Masks follow the levels.
  for (const auto& [g, c, name] : {std::tuple{&gpu.levels_world, &cpu.levels_world, "from spheres"},
                                   std::tuple{&gpu.levels_root, &cpu.levels_root, "from roots"}}) {
    const std::vector<std::size_t> diff = gpu_test::differing(*g, *c);
    EXPECT_LE(diff.size(), 2u) << "levels " << name;
    for (std::size_t i : diff) {
      const int a = (*g)[i], b = (*c)[i];
      EXPECT_EQ(std::abs(a - b), 1) << "part " << i << " levels " << a << " vs " << b << " " << name;
    }
  }
  const std::vector<std::size_t> world_diff = gpu_test::differing(gpu.levels_world, cpu.levels_world);
  const std::vector<std::size_t> root_diff = gpu_test::differing(gpu.levels_root, cpu.levels_root);
  if (world_diff.empty()) {
    EXPECT_TRUE(gpu_test::bitwise_equal(gpu.masks_world, cpu.masks_world)) << "masks from spheres";
  }
  if (root_diff.empty()) {
    EXPECT_TRUE(gpu_test::bitwise_equal(gpu.masks_root, cpu.masks_root)) << "masks from roots";
    // Counting: integers, bitwise.
    EXPECT_TRUE(gpu_test::bitwise_equal(gpu.histogram, cpu.histogram)) << "histogram";
  }
}

}  // namespace
}  // namespace throng::anim
