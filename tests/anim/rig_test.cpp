// Rigs: part clusters, bind pose, the mannequin and linear blend skinning
// (CPU reference against a batch kernel and against the bind pose).
#include "anim/rig.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "anim/skin.h"
#include "core/buffer.h"
#include "core/error.h"
#include "core/exec.h"
#include "motion/default_set.h"
#include "stream_reference.h"

namespace throng::anim {
namespace {

using namespace testing;
namespace dj = motion::default_joint;

std::set<std::string> names_of(const Rig& rig, const std::string& cluster) {
  std::set<std::string> out;
  for (std::int32_t j : rig.clusters.joints_of(rig.clusters.find(cluster)))
    out.insert(rig.skeleton.names[static_cast<std::size_t>(j)]);
  return out;
}

TEST(Clusters, DefaultHumanoidSplitsIntoLowerUpperAndHead) {
  const Rig& rig = humanoid_rig();
  ASSERT_EQ(rig.clusters.count(), 3);
  EXPECT_EQ(rig.clusters.clusters[0].name, "lower");
  EXPECT_EQ(names_of(rig, "lower"), (std::set<std::string>{"Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
                                                           "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}));
  EXPECT_EQ(names_of(rig, "head"), (std::set<std::string>{"Neck", "Head"}));
  EXPECT_EQ(names_of(rig, "upper").size(), 11u);  // spine x3, two clavicles, arms, forearms, hands
  EXPECT_EQ(rig.clusters.hook_joint[0], -1);
  EXPECT_EQ(rig.clusters.hook_joint[1], dj::Hips);
  EXPECT_EQ(rig.clusters.hook_joint[2], dj::Spine2);
}

TEST(Clusters, ExplicitRootsAndErrors) {
  const motion::Skeleton s = motion::default_skeleton();
  const ClusterLayout l =
      make_cluster_layout(s, {{"body", {"Hips"}}, {"left_arm", {"LeftArm"}}, {"right_arm", {"RightArm"}}});
  EXPECT_EQ(l.joints_of(1), (std::vector<std::int32_t>{dj::LeftArm, dj::LeftForeArm, dj::LeftHand}));
  EXPECT_EQ(l.hook_joint[1], dj::LeftShoulder);
  auto field_of = [&](std::vector<ClusterDef> defs) {
    try {
      make_cluster_layout(s, std::move(defs));
    } catch (const Error& e) {
      return e.location().field;
    }
    return std::string("no error");
  };
  EXPECT_EQ(field_of({{"lower", {"Hips"}}, {"x", {"Nope"}}}), "clusters[1].roots[0]");
  EXPECT_EQ(field_of({{"upper", {"Spine"}}}), "clusters");                       // root joint in no cluster
  EXPECT_EQ(field_of({{"a", {"Hips"}}, {"a", {"Spine"}}}), "clusters[1].name");  // name twice
  EXPECT_EQ(field_of({{"a", {"Hips"}}, {"b", {"Hips"}}}), "clusters[1].roots[0]");
  ClusterDef bad_hook{"b", {"Spine"}};
  bad_hook.hook_rotation = glm::quat(2, 0, 0, 0);
  EXPECT_EQ(field_of({{"a", {"Hips"}}, bad_hook}), "clusters[1].hook_rotation");
}

TEST(Clusters, SkeletonWithoutRolesGetsOneCluster) {
  motion::Skeleton s;
  s.add_joint("a", -1, {0, 1, 0});
  s.add_joint("b", 0, {0, 0.5f, 0});
  const Rig rig = make_rig("plain", s);
  EXPECT_EQ(rig.clusters.count(), 1);
  EXPECT_EQ(rig.clusters.joints_of(0).size(), 2u);
}

TEST(Rig, InverseBindTimesBindIsIdentity) {
  const Rig& rig = humanoid_rig();
  const auto B = reference_bind(rig);
  for (std::size_t j = 0; j < B.size(); ++j) {
    const Mat3x4 m = mat3x4_from(rig.bind_rotations[j], rig.bind_positions[j]) * rig.inverse_bind[j];
    EXPECT_LT(palette_error(m, glm::dmat4(1.0)), 1e-6) << j;
    EXPECT_LT(glm::length(glm::dvec3(rig.bind_positions[j]) - glm::dvec3(B[j][3])), 1e-6) << j;
  }
}

TEST(Mannequin, IsValidClosedAndCoversTheSkeleton) {
  const Rig& rig = humanoid_rig();
  const SkinnedMesh& m = rig.mesh;
  EXPECT_NO_THROW(m.validate());
  EXPECT_GT(m.vertex_count(), 1000);
  EXPECT_GT(m.triangle_count(), 2000);
  // Every capsule is closed: each edge is shared by exactly two triangles,
  // once in each direction (consistent winding).
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (std::size_t t = 0; t < m.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k)
      ++edges[{m.indices[t + static_cast<std::size_t>(k)], m.indices[t + static_cast<std::size_t>((k + 1) % 3)]}];
  for (const auto& [e, n] : edges) {
    ASSERT_EQ(n, 1);
    ASSERT_EQ(edges.count({e.second, e.first}), 1u);
  }
  // Outward: each face normal agrees with its vertices' normals.
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    const glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
    const glm::vec3 n = glm::cross(b - a, c - a);
    ASSERT_GE(glm::dot(n, m.normals[m.indices[t]] + m.normals[m.indices[t + 1]] + m.normals[m.indices[t + 2]]), 0.0f);
  }
  // Height and extent of a 1.75 m T-posed adult (head top ~1.75 m + skull radius, soles near 0).
  float lo = 1e9f, hi = -1e9f, wx = 0.0f;
  for (const glm::vec3& p : m.positions) {
    lo = std::min(lo, p.y);
    hi = std::max(hi, p.y);
    wx = std::max(wx, std::abs(p.x));
  }
  EXPECT_NEAR(hi, 1.85f, 0.06f);
  EXPECT_LT(lo, 0.05f);
  EXPECT_GT(wx, 0.8f);  // finger tips of the T-pose
  // Every joint that moves a bone influences some vertex.
  std::set<int> used;
  for (std::size_t v = 0; v < m.joints.size(); ++v)
    for (int k = 0; k < 4; ++k)
      if (m.weights[v][k] > 0.0f) used.insert(m.joints[v][k]);
  for (int j = 0; j < dj::Count; ++j) EXPECT_TRUE(used.count(j)) << rig.skeleton.names[static_cast<std::size_t>(j)];
}

TEST(Mannequin, WeightsBlendSmoothlyAtJoints) {
  const Rig& rig = humanoid_rig();
  const SkinnedMesh& m = rig.mesh;
  // Vertices at the knee are shared half and half between thigh and shank joints.
  const glm::vec3 knee = rig.bind_positions[dj::LeftLeg];
  int shared = 0;
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    if (glm::length(glm::vec2(m.positions[v].x - knee.x, m.positions[v].z - knee.z)) > 0.1f ||
        std::abs(m.positions[v].y - knee.y) > 0.005f)
      continue;
    float w_thigh = 0.0f, w_knee = 0.0f;
    for (int k = 0; k < 4; ++k) {
      if (m.joints[v][k] == dj::LeftUpLeg) w_thigh += m.weights[v][k];
      if (m.joints[v][k] == dj::LeftLeg) w_knee += m.weights[v][k];
    }
    EXPECT_NEAR(w_thigh, 0.5f, 0.02f);
    EXPECT_NEAR(w_knee, 0.5f, 0.02f);
    ++shared;
  }
  EXPECT_GT(shared, 10);
}

TEST(Mannequin, OptionsAreValidated) {
  MannequinOptions o;
  o.sides = 2;
  EXPECT_THROW(make_mannequin(motion::default_skeleton(), o), Error);
  o = {};
  o.blend = 0.7f;
  try {
    make_mannequin(motion::default_skeleton(), o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "mannequin.blend");
  }
}

TEST(Skinning, RestPoseReproducesTheBindPose) {
  const Rig& rig = humanoid_rig();
  std::vector<Mat3x4> palette(rig.inverse_bind.size());
  for (std::size_t j = 0; j < palette.size(); ++j)
    palette[j] = mat3x4_from(rig.bind_rotations[j], rig.bind_positions[j]) * rig.inverse_bind[j];
  std::vector<glm::vec3> p(rig.mesh.positions.size()), n(p.size());
  skin_reference(rig.mesh, palette, p, n);
  for (std::size_t v = 0; v < p.size(); ++v) {
    ASSERT_LT(glm::length(p[v] - rig.mesh.positions[v]), 1e-5f) << v;
    ASSERT_LT(glm::length(n[v] - rig.mesh.normals[v]), 1e-5f) << v;
  }
}

TEST(Skinning, KernelMatchesReferenceForManyCharactersOnAnyThreadCount) {
  const Rig& rig = humanoid_rig();
  const std::size_t J = rig.inverse_bind.size();
  constexpr int kChars = 5;
  std::vector<Mat3x4> palettes;
  std::vector<Index> offsets;
  for (int c = 0; c < kChars; ++c) {
    offsets.push_back(static_cast<Index>(palettes.size()));
    std::vector<glm::dquat> local(J);
    for (std::size_t j = 0; j < J; ++j) local[j] = glm::dquat(wiggle(static_cast<int>(j), c * 7));
    const auto ref = reference_palette(rig, local, glm::dvec3(rig.skeleton.offsets[0]), glm::dvec3(c, 0, -c), 0.3 * c);
    for (const glm::dmat4& m : ref) {
      Mat3x4 x;
      x.r0 = glm::vec4(m[0][0], m[1][0], m[2][0], m[3][0]);
      x.r1 = glm::vec4(m[0][1], m[1][1], m[2][1], m[3][1]);
      x.r2 = glm::vec4(m[0][2], m[1][2], m[2][2], m[3][2]);
      palettes.push_back(x);
    }
  }
  const SkinnedMesh& mesh = rig.mesh;
  const auto V = static_cast<std::size_t>(mesh.vertex_count());
  std::vector<glm::vec3> want(V * kChars);
  for (int c = 0; c < kChars; ++c)
    skin_reference(
        mesh,
        std::span<const Mat3x4>(palettes).subspan(static_cast<std::size_t>(offsets[static_cast<std::size_t>(c)]), J),
        std::span<glm::vec3>(want).subspan(V * static_cast<std::size_t>(c), V), {});
  std::vector<std::vector<glm::vec3>> results;
  for (int threads : {1, 2, 5}) {
    ScopedExecution exec(Backend::Cpu, threads);
    std::vector<glm::vec3> got(V * kChars), normals(V * kChars);
    SkinJob job;
    job.positions = mesh.positions;
    job.normals = mesh.normals;
    job.joints = mesh.joints;
    job.weights = mesh.weights;
    job.joint_count = mesh.joint_count;
    job.palettes = palettes;
    job.palette_offsets = offsets;
    job.out_positions = got;
    job.out_normals = normals;
    job.run();
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], want[i]) << i;
    results.push_back(normals);
  }
  EXPECT_EQ(results[0], results[1]);
  EXPECT_EQ(results[0], results[2]);
  SkinJob bad;
  bad.positions = mesh.positions;
  bad.joint_count = mesh.joint_count;
  try {
    bad.validate();
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "SkinJob.normals");
  }
}

TEST(Rig, TooManyJointsIsAnError) {
  motion::Skeleton s;
  s.add_joint("root", -1, {0, 0, 0});
  for (int j = 1; j <= kMaxRigJoints; ++j)
    s.add_joint(std::string(1, 'j').append(std::to_string(j)), j - 1, {0, 0.1f, 0});
  EXPECT_THROW(make_rig("long", s), Error);
}

}  // namespace
}  // namespace throng::anim
