// The glTF crowd export against the locomotion stage that produced it: a
// crowd animated for two seconds is written as .glb, parsed back with
// tinygltf (CrowdGlb) and evaluated by forward kinematics over its nodes;
// the joints must land where the animator put them, and the mesh skinned
// from the file's own skin where throng's skinning puts it.
#include "io/crowd_gltf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>
#include <vector>

#include "anim/crowd_animator.h"
#include "anim/rig.h"
#include "core/error.h"
#include "tests/anim/crowd_fixture.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

// Rotation q scaled by s, then translation t, as a palette row matrix.
anim::Mat3x4 frame_of(const glm::quat& q, const glm::vec3& t, float s) {
  anim::Mat3x4 m = anim::mat3x4_from(q, t);
  for (glm::vec4* r : {&m.r0, &m.r1, &m.r2}) *r = glm::vec4(s * r->x, s * r->y, s * r->z, r->w);
  return m;
}

fs::path temp_file(const char* name) { return fs::temp_directory_path() / (std::to_string(::getpid()) + "_" + name); }

// A random crowd of `n` walking characters (scales 0.85-1.15), animated at
// 24 fps; every frame goes into the take and into `world` (positions,
// rotations per frame).
struct Recorded {
  std::vector<std::vector<glm::vec3>> positions;
  std::vector<std::vector<glm::quat>> rotations;
  std::vector<float> scales;
};
CrowdTake record_crowd(Index n, int frames, Recorded& world) {
  const anim::testing::Crowd crowd = anim::testing::random_crowd(n, 5);
  anim::CrowdAnimatorConfig config;
  config.lod = false;
  anim::CrowdAnimator animator(anim::testing::default_space(), n, config);
  animator.place(crowd.positions, crowd.yaws, crowd.scales, crowd.phases);
  animator.set_speeds(crowd.speeds);
  const auto scales = animator.scales().std();
  world.scales.assign(scales.begin(), scales.end());
  CrowdTake take(anim::make_rig("mannequin", animator.blend_space().skeleton()), world.scales, 24.0);
  for (int f = 0; f < frames; ++f) {
    animator.animate({1.0f / 24.0f, nullptr, true});
    take.add_frame(animator.joint_positions(), animator.joint_rotations());
    const auto p = animator.joint_positions().std();
    const auto q = animator.joint_rotations().std();
    world.positions.emplace_back(p.begin(), p.end());
    world.rotations.emplace_back(q.begin(), q.end());
  }
  return take;
}

TEST(CrowdGltf, JointsReadBackWithinAMillimetreOfTheAnimator) {
  const Index n = 30;
  const int frames = 48;
  Recorded world;
  const CrowdTake take = record_crowd(n, frames, world);
  const fs::path path = temp_file("crowd.glb");
  write_crowd_glb(path.string(), take);
  ASSERT_TRUE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".partial"));
  const double size = static_cast<double>(fs::file_size(path));
  const double estimate = CrowdTake::estimate_bytes(take.rig(), n, frames);
  std::printf("  %lld agents x %d frames: %.0f bytes (estimate %.0f)\n", static_cast<long long>(n), frames, size,
              estimate);
  EXPECT_NEAR(estimate, size, 0.05 * size);

  const CrowdGlb glb(path.string());
  ASSERT_EQ(glb.agents(), n);
  ASSERT_EQ(glb.joints(), take.joints());
  ASSERT_EQ(glb.frames(), frames);
  EXPECT_DOUBLE_EQ(glb.fps(), 24.0);
  const std::int32_t J = glb.joints();
  std::vector<glm::vec3> p;
  std::vector<glm::quat> q;
  std::vector<float> s;
  double worst_mm = 0.0, worst_deg = 0.0;
  for (const int f : {0, 7, 19, 33, frames - 1})
    for (Index a = 0; a < n; ++a) {
      glb.joint_frames(a, f, p, q, s);
      for (std::int32_t j = 0; j < J; ++j) {
        const std::size_t k = static_cast<std::size_t>(a * J + j);
        worst_mm =
            std::max(worst_mm,
                     1000.0 * static_cast<double>(glm::length(p[static_cast<std::size_t>(j)] - world.positions[f][k])));
        worst_deg =
            std::max(worst_deg, anim::rotation_angle_deg(q[static_cast<std::size_t>(j)], world.rotations[f][k]));
        EXPECT_FLOAT_EQ(s[static_cast<std::size_t>(j)], world.scales[static_cast<std::size_t>(a)]);
      }
    }
  std::printf("  worst joint position %.4f mm, rotation %.4f deg\n", worst_mm, worst_deg);
  EXPECT_LT(worst_mm, 1.0);
  EXPECT_LT(worst_deg, 0.05);
  fs::remove(path);
}

// The file's mesh, skinned with the file's inverse bind matrices and joints
// (what a DCC tool draws), against throng's skinning of its own mannequin
// from the animator's joint frames (what the renderer draws): every vertex
// of every agent within a millimetre.
TEST(CrowdGltf, MeshSkinnedFromTheFileMatchesThrongsSkinning) {
  const Index n = 6;
  Recorded world;
  const CrowdTake take = record_crowd(n, 12, world);
  const fs::path path = temp_file("skin.glb");
  write_crowd_glb(path.string(), take);
  const CrowdGlb glb(path.string());
  const anim::SkinnedMesh& mesh = glb.mesh();
  const anim::Rig& rig = take.rig();
  ASSERT_EQ(mesh.vertex_count(), rig.mesh.vertex_count());
  ASSERT_EQ(mesh.indices, rig.mesh.indices);
  const std::int32_t J = glb.joints();
  std::vector<glm::vec3> p;
  std::vector<glm::quat> q;
  std::vector<float> s;
  auto skin = [&](const anim::SkinnedMesh& m, const std::vector<anim::Mat3x4>& palette, std::int32_t v) {
    glm::vec3 out(0.0f);
    for (int i = 0; i < 4; ++i)
      out += m.weights[static_cast<std::size_t>(v)][i] *
             anim::transform_point(palette[m.joints[static_cast<std::size_t>(v)][i]],
                                   m.positions[static_cast<std::size_t>(v)]);
    return out;
  };
  double worst_mm = 0.0;
  const int f = 11;
  for (Index a = 0; a < n; ++a) {
    glb.joint_frames(a, f, p, q, s);
    std::vector<anim::Mat3x4> from_file(static_cast<std::size_t>(J)), from_throng(static_cast<std::size_t>(J));
    for (std::int32_t j = 0; j < J; ++j) {
      const auto J_ = static_cast<std::size_t>(j), k = static_cast<std::size_t>(a * J + j);
      const float scale = world.scales[static_cast<std::size_t>(a)];
      from_file[J_] = frame_of(q[J_], p[J_], s[J_]) * glb.inverse_bind()[J_];
      from_throng[J_] = frame_of(world.rotations[f][k], world.positions[f][k], scale) * rig.inverse_bind[J_];
    }
    for (std::int32_t v = 0; v < mesh.vertex_count(); ++v)
      worst_mm = std::max(worst_mm, 1000.0 * static_cast<double>(glm::length(skin(mesh, from_file, v) -
                                                                             skin(rig.mesh, from_throng, v))));
  }
  std::printf("  worst skinned vertex %.4f mm over %lld agents x %d vertices\n", worst_mm, static_cast<long long>(n),
              mesh.vertex_count());
  EXPECT_LT(worst_mm, 1.0);
  fs::remove(path);
}

TEST(CrowdGltf, FilesThatAreNotACrowdGiveAnErrorNamingThem) {
  const fs::path text = temp_file("not.glb");
  std::ofstream(text) << "hello";
  try {
    CrowdGlb glb(text.string());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().file, text.string());
  }
  // Truncated: the first half of a real export.
  Recorded world;
  const fs::path whole = temp_file("whole.glb");
  write_crowd_glb(whole.string(), record_crowd(3, 4, world));
  std::string bytes;
  {
    std::ifstream in(whole, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(text, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  EXPECT_THROW(CrowdGlb{text.string()}, Error);
  EXPECT_THROW(CrowdGlb{(fs::temp_directory_path() / "no_such_crowd.glb").string()}, Error);
  // A BIN chunk that claims 8 bytes more than the file holds: its payload
  // would end exactly where the file ends if its header were not counted.
  std::vector<unsigned char> longer(bytes.begin(), bytes.end());
  std::uint32_t json_length = 0, bin_length = 0;
  std::memcpy(&json_length, &longer[12], 4);
  std::memcpy(&bin_length, &longer[20 + json_length], 4);
  ASSERT_EQ(20 + json_length + 8 + bin_length, longer.size());
  EXPECT_NO_THROW(CrowdGlb::parse(longer, "whole.glb"));
  bin_length += 8;
  std::memcpy(&longer[20 + json_length], &bin_length, 4);
  try {
    CrowdGlb::parse(longer, "long_bin.glb");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().file, "long_bin.glb");
    EXPECT_NE(std::string(e.what()).find("BIN chunk"), std::string::npos) << e.what();
  }
  fs::remove(text);
  fs::remove(whole);
}

}  // namespace
}  // namespace throng::io
