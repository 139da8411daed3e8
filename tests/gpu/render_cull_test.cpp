// render/cull on CUDA against the CPU: CullJob (from joint frames and from
// palettes of two rigs), PackJob and PalettePackJob (from joint frames and
// by copying palettes).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "anim/rig.h"
#include "render/cull.h"
#include "render/scene.h"
#include "tests/gpu/gpu_test.h"
#include "tests/render/scene_fixture.h"

namespace throng::render {
namespace {

using testing::TPoseCrowd;

// The exclusive scan of the group flags on the host: the reference for
// scan_draw_slots on either backend.
Index host_slots(const std::vector<std::uint32_t>& flags, std::vector<std::uint32_t>& slots) {
  slots.resize(flags.size());
  std::uint32_t acc = 0;
  for (std::size_t i = 0; i < flags.size(); ++i) {
    slots[i] = acc;
    acc += flags[i];
  }
  return acc;
}

struct Result {
  std::vector<std::uint32_t> flags_joints, flags_palettes;
  std::vector<std::uint32_t> slots;  // scan_draw_slots of the CPU's flags
  Index visible = 0;
  std::vector<glm::vec4> points;
  std::vector<anim::Mat3x4> palettes_from_joints, palettes_copied;
  std::vector<glm::uvec2> tags_from_joints, tags_copied;
};

TEST(CudaCull, CullAndPackMatchCpu) {
  THRONG_REQUIRE_GPU();
  TPoseCrowd c;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> x(-70.0f, 70.0f), yaw(-3.14f, 3.14f), scale(0.8f, 1.25f);
  for (int i = 0; i < 1500; ++i)
    c.add({x(rng), 0.0f, x(rng) - 30.0f}, yaw(rng), static_cast<std::uint8_t>(i % 3), scale(rng));
  const Index n = c.count();
  const JointRig joint_rig = make_joint_rig(c.skeleton);
  const SkinRig skin = make_skin_rig(anim::make_rig("humanoid", c.skeleton));
  const std::int32_t J = skin.joint_count;
  const Index P = joint_rig.point_count();
  // Palettes of every character (its rigid T(at) R(yaw) S(scale)), and a
  // second "rig" for every third character so two rigs' groups are filled.
  std::vector<anim::Mat3x4> palettes;
  std::vector<Index> offsets;
  std::vector<std::int32_t> rigs;
  for (Index i = 0; i < n; ++i) {
    const auto I = static_cast<std::size_t>(i);
    anim::Mat3x4 m = anim::mat3x4_from(glm::angleAxis(c.yaws[I], glm::vec3(0, 1, 0)), c.places[I]);
    for (glm::vec4* r : {&m.r0, &m.r1, &m.r2}) *r = glm::vec4(glm::vec3(*r) * c.scales[I], r->w);
    offsets.push_back(static_cast<Index>(palettes.size()));
    palettes.insert(palettes.end(), static_cast<std::size_t>(J), m);
    rigs.push_back(i % 3 == 0 ? 1 : 0);
  }
  const CameraView view = make_camera_view(testing::street_camera());
  // Pack jobs read the CPU's flags and slots on both sides, so they are
  // compared on the same visible set whatever the cull decided.
  std::vector<std::uint32_t> cpu_flags, cpu_slots;
  Index cpu_visible = 0;
  const auto run = [&](Memory m) {
    Result r;
    Buffer<glm::vec3> positions = gpu_test::upload(c.positions, m);
    Buffer<glm::quat> rotations = gpu_test::upload(c.rotations, m);
    Buffer<float> scales = gpu_test::upload(c.scales, m);
    Buffer<std::uint8_t> levels = gpu_test::upload(c.levels, m);
    Buffer<anim::Mat3x4> b_palettes = gpu_test::upload(palettes, m),
                         inverse_bind = gpu_test::upload(skin.inverse_bind, m);
    Buffer<Index> b_offsets = gpu_test::upload(offsets, m);
    Buffer<std::int32_t> b_rigs = gpu_test::upload(rigs, m);
    Buffer<RigPoint> points = gpu_test::upload(joint_rig.points, m);

    CullJob cull;
    cull.camera = view;
    cull.rigs.rig[0] = {skin.bounding_radius, skin.bind_positions[0], J};
    cull.joint_count = J;
    cull.joint_positions = positions.span();
    cull.scales = scales.span();
    Buffer<std::uint32_t> flags(kDrawTiers * n, m);
    cull.group_flags = flags.span();
    cull.run();
    r.flags_joints = flags.to_vector();

    CullJob by_palettes;
    by_palettes.camera = view;
    by_palettes.rigs.count = 2;
    by_palettes.rigs.rig[0] = {skin.bounding_radius, skin.bind_positions[0], J};
    by_palettes.rigs.rig[1] = {0.5f * skin.bounding_radius, skin.bind_positions[0], J};
    by_palettes.palettes = b_palettes.span();
    by_palettes.palette_offsets = b_offsets.span();
    by_palettes.character_rigs = b_rigs.span();
    Buffer<std::uint32_t> flags2(2 * kDrawTiers * n, m);
    by_palettes.group_flags = flags2.span();
    by_palettes.run();
    r.flags_palettes = flags2.to_vector();

    if (cpu_flags.empty()) {
      cpu_flags = r.flags_joints;
      cpu_visible = host_slots(cpu_flags, cpu_slots);
    }
    Buffer<std::uint32_t> f = gpu_test::upload(cpu_flags, m), s(cpu_flags.size(), m);
    r.visible = scan_draw_slots(f.span(), s.span());
    r.slots = s.to_vector();
    PackJob pack;
    pack.joint_count = J;
    pack.points = points.span();
    pack.joint_positions = positions.span();
    pack.joint_rotations = rotations.span();
    pack.lod_levels = levels.span();
    pack.group_flags = f.span();
    pack.slots = s.span();
    Buffer<glm::vec4> out_points(cpu_visible * P, m);
    pack.out_points = out_points.span();
    pack.run();
    r.points = out_points.to_vector();

    for (const bool copy : {false, true}) {
      PalettePackJob pp;
      pp.groups = draw_groups(cull, s.span(), cpu_visible);  // reads the scan's group starts from memory m
      pp.lod_levels = levels.span();
      pp.group_flags = f.span();
      pp.slots = s.span();
      if (copy) {
        pp.palettes = b_palettes.span();
        pp.palette_offsets = b_offsets.span();
      } else {
        pp.joint_count = J;
        pp.joint_positions = positions.span();
        pp.joint_rotations = rotations.span();
        pp.scales = scales.span();
        pp.inverse_bind = inverse_bind.span();
      }
      Buffer<anim::Mat3x4> out(pp.groups.matrices(), m);
      Buffer<glm::uvec2> tags(pp.groups.visible(), m);
      pp.out_palettes = out.span();
      pp.out_tags = tags.span();
      pp.run();
      (copy ? r.palettes_copied : r.palettes_from_joints) = out.to_vector();
      (copy ? r.tags_copied : r.tags_from_joints) = tags.to_vector();
    }
    return r;
  };
  const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_GT(cpu_visible, 50);
  ASSERT_LT(cpu_visible, n);
  // The scan of one set of flags: integer sums, bitwise on both backends.
  EXPECT_EQ(cpu.visible, cpu_visible);
  EXPECT_EQ(gpu.visible, cpu_visible);
  EXPECT_EQ(cpu.slots, cpu_slots);
  EXPECT_EQ(gpu.slots, cpu_slots);

  // Visibility and tier are thresholds on a projected radius (a 4x4
  // transform, a divide): a character within a few roundings of a frustum
  // plane or tier boundary may go either way; at most 2 characters (each
  // moves one flag to another group: 2 entries).
  EXPECT_LE(gpu_test::differing(gpu.flags_joints, cpu.flags_joints).size(), 4u) << "cull flags from joint frames";
  EXPECT_LE(gpu_test::differing(gpu.flags_palettes, cpu.flags_palettes).size(), 4u) << "cull flags from palettes";
  // Points: a joint position plus its rotated offset (~15 FMA-able
  // operations, positions up to ~100 m); the tag in w is an integer-valued
  // float, exact.
  EXPECT_TRUE(gpu_test::near(gpu.points, cpu.points, {1e-6, 2e-5})) << "packed points";
  // Palettes from joint frames: T R S times the inverse bind (a 3x4
  // product, ~30 FMA-able operations); copies and tags: bitwise.
  EXPECT_TRUE(gpu_test::near(gpu.palettes_from_joints, cpu.palettes_from_joints, {1e-6, 2e-5}))
      << "palettes from joint frames";
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.palettes_copied, cpu.palettes_copied)) << "copied palettes";
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.tags_from_joints, cpu.tags_from_joints)) << "tags";
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.tags_copied, cpu.tags_copied)) << "tags of copied palettes";
}

}  // namespace
}  // namespace throng::render
