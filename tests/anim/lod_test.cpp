// Body parts, LOD levels, joint masks and masked synthesis against brute
// force: forward kinematics of random poses, double-precision projection
// per character, set unions of joints, counting by hand.
#include "anim/lod.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <random>
#include <set>
#include <string>

#include "anim/motion_cache.h"
#include "anim/sphere_projection.h"
#include "core/error.h"
#include "core/exec.h"
#include "motion/fk.h"
#include "motion/roles.h"

namespace throng::anim {
namespace {

using motion::Role;
using motion::Skeleton;

// A CMU-style humanoid (metres, Y up, T-pose): clavicles, fingers and toes.
Skeleton humanoid() {
  Skeleton s;
  const auto add = [&s](const char* name, int parent, glm::vec3 offset) { return s.add_joint(name, parent, offset); };
  const int hips = add("Hips", -1, {0, 0, 0});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string n = side == 0 ? "Left" : "Right";
    const int up = add((n + "UpLeg").c_str(), hips, {0.1f * x, -0.05f, 0});
    const int leg = add((n + "Leg").c_str(), up, {0, -0.42f, 0});
    const int foot = add((n + "Foot").c_str(), leg, {0, -0.42f, 0});
    const int toe = add((n + "ToeBase").c_str(), foot, {0, -0.05f, 0.12f});
    s.end_sites[static_cast<std::size_t>(toe)] = {0, 0, 0.05f};
    s.has_end_site[static_cast<std::size_t>(toe)] = 1;
  }
  const int spine = add("Spine", hips, {0, 0.1f, 0});
  const int spine1 = add("Spine1", spine, {0, 0.15f, 0});
  const int neck = add("Neck", spine1, {0, 0.2f, 0});
  const int head = add("Head", neck, {0, 0.1f, 0});
  s.end_sites[static_cast<std::size_t>(head)] = {0, 0.15f, 0};
  s.has_end_site[static_cast<std::size_t>(head)] = 1;
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string n = side == 0 ? "Left" : "Right";
    const int clavicle = add((n + "Shoulder").c_str(), spine1, {0.05f * x, 0.15f, 0});
    const int arm = add((n + "Arm").c_str(), clavicle, {0.15f * x, 0, 0});
    const int fore = add((n + "ForeArm").c_str(), arm, {0.28f * x, 0, 0});
    const int hand = add((n + "Hand").c_str(), fore, {0.25f * x, 0, 0});
    const int finger = add((n + "HandIndex1").c_str(), hand, {0.08f * x, 0, 0});
    s.end_sites[static_cast<std::size_t>(finger)] = {0.04f * x, 0, 0};
    s.has_end_site[static_cast<std::size_t>(finger)] = 1;
  }
  motion::assign_roles(s);
  return s;
}

glm::quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  return glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
}

std::vector<int> thread_counts() { return {1, 2, hardware_threads(), 7}; }

TEST(BodyParts, PartitionDepthsAndAnchorsOfAHumanoid) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  ASSERT_EQ(parts.joint_count, s.joint_count());
  std::vector<int> seen(static_cast<std::size_t>(s.joint_count()), 0);
  for (BodyPart p : kAllBodyParts)
    for (std::int32_t j : parts.joints_of(p)) {
      ++seen[static_cast<std::size_t>(j)];
      EXPECT_EQ(parts.part_of[static_cast<std::size_t>(j)], static_cast<std::uint8_t>(p));
    }
  for (int c : seen) EXPECT_EQ(c, 1);
  const auto part_of = [&](const char* name) {
    return static_cast<BodyPart>(parts.part_of[static_cast<std::size_t>(s.find(name))]);
  };
  EXPECT_EQ(part_of("LeftArm"), BodyPart::LeftArm);
  EXPECT_EQ(part_of("LeftHandIndex1"), BodyPart::LeftArm);
  EXPECT_EQ(part_of("RightForeArm"), BodyPart::RightArm);
  EXPECT_EQ(part_of("LeftShoulder"), BodyPart::Torso);  // the clavicle
  EXPECT_EQ(part_of("Head"), BodyPart::Torso);
  EXPECT_EQ(part_of("Hips"), BodyPart::Torso);
  EXPECT_EQ(part_of("LeftUpLeg"), BodyPart::LeftLeg);
  EXPECT_EQ(part_of("RightToeBase"), BodyPart::RightLeg);
  EXPECT_EQ(parts.depth[static_cast<std::size_t>(s.find("LeftArm"))], 0);
  EXPECT_EQ(parts.depth[static_cast<std::size_t>(s.find("LeftHandIndex1"))], 3);
  EXPECT_EQ(parts.depth[static_cast<std::size_t>(s.find("Head"))], 4);
  EXPECT_EQ(parts.anchor(BodyPart::LeftArm).joint_a, s.find("LeftForeArm"));
  EXPECT_EQ(parts.anchor(BodyPart::RightLeg).joint_a, s.find("RightLeg"));
  EXPECT_EQ(parts.anchor(BodyPart::Torso).joint_a, s.find("Hips"));
  EXPECT_EQ(parts.anchor(BodyPart::Torso).joint_b, s.find("Neck"));
  // Straight limbs in the rest pose: the radius is the longest chain from the centre joint.
  EXPECT_NEAR(parts.anchor(BodyPart::LeftArm).radius, 0.25f + 0.08f + 0.04f, 1e-5f);  // elbow -> fingertip
  EXPECT_NEAR(parts.anchor(BodyPart::LeftLeg).radius, 0.42f + std::hypot(0.05f, 0.12f) + 0.05f,
              1e-5f);  // knee -> toe tip
  // Mid-spine (0.225 above the hips) to the head's end site: 0.5 * (0.45 + 0.25) + 0.5 * 0.25.
  EXPECT_NEAR(parts.anchor(BodyPart::Torso).radius, 0.475f, 1e-5f);
  // Rest spheres stand on the ground: the knee is 0.42 + 0.05 above the sole... of the foot joint.
  EXPECT_NEAR(parts.rest_spheres[static_cast<std::size_t>(BodyPart::LeftLeg)].y, 0.42f + 0.05f, 1e-5f);
  EXPECT_NEAR(bone_path_length(s, s.find("LeftHand"), s.find("RightHand")),
              2 * (0.25f + 0.28f + 0.15f + std::hypot(0.05f, 0.15f)), 1e-5f);
}

// The bound holds in every pose: brute force over random poses.
TEST(BodyParts, SpheresContainTheirPartInRandomPoses) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  const std::int32_t J = s.joint_count();
  std::mt19937 rng(3);
  std::vector<glm::quat> local(static_cast<std::size_t>(J));
  std::vector<glm::vec3> pos(static_cast<std::size_t>(J));
  std::vector<glm::quat> rot(static_cast<std::size_t>(J));
  double tightest = 0;  // largest distance / radius seen
  for (int trial = 0; trial < 500; ++trial) {
    for (auto& q : local) q = random_rotation(rng);
    motion::fk_pose(J, s.parents.data(), s.offsets.data(), local.data(), nullptr, glm::vec3(1, 2, 3), pos.data(),
                    rot.data());
    for (BodyPart p : kAllBodyParts) {
      const SphereAnchor& a = parts.anchor(p);
      const glm::vec3 c = anchor_centre(a, pos.data());
      for (std::int32_t j : parts.joints_of(p)) {
        const auto jj = static_cast<std::size_t>(j);
        std::vector<glm::vec3> points = {pos[jj]};
        if (s.has_end_site[jj]) points.push_back(pos[jj] + rot[jj] * s.end_sites[jj]);
        for (const glm::vec3& x : points) {
          const float dist = glm::length(x - c);
          ASSERT_LE(dist, a.radius * (1 + 1e-5f) + 1e-6f) << to_string(p) << " joint " << s.names[jj];
          tightest = std::max(tightest, static_cast<double>(dist / a.radius));
        }
      }
    }
  }
  EXPECT_GT(tightest, 0.8);  // and it is not absurdly loose
}

TEST(BodyParts, MissingRolesAreNamed) {
  Skeleton s = humanoid();
  s.roles[static_cast<std::size_t>(Role::LeftElbow)] = -1;
  try {
    make_body_parts(s);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "roles.left_elbow") << e.what();
  }
  s = humanoid();
  s.roles[static_cast<std::size_t>(Role::Neck)] = -1;
  s.roles[static_cast<std::size_t>(Role::Head)] = -1;
  EXPECT_THROW(make_body_parts(s), Error);
  // A knee that sits inside the left arm makes the limbs overlap.
  s = humanoid();
  s.roles[static_cast<std::size_t>(Role::LeftThigh)] = s.find("LeftForeArm");
  s.roles[static_cast<std::size_t>(Role::LeftKnee)] = s.find("LeftHand");
  EXPECT_THROW(make_body_parts(s), Error);
}

TEST(LodConfig, DefaultLevelsDropTheDeepestJointsFirst) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  const LodConfig c = make_lod_config(parts, {2000.0f, 200.0f});
  EXPECT_EQ(c.level_count, 3);
  EXPECT_EQ(c.mask_words, 1);
  const auto names = [&](BodyPart p, int l) {
    std::vector<std::string> out;
    for (std::int32_t j : c.synthesised_joints(p, l)) out.push_back(s.names[static_cast<std::size_t>(j)]);
    return out;
  };
  EXPECT_EQ(names(BodyPart::LeftArm, 0),
            (std::vector<std::string>{"LeftArm", "LeftForeArm", "LeftHand", "LeftHandIndex1"}));
  EXPECT_EQ(names(BodyPart::LeftArm, 1), (std::vector<std::string>{"LeftArm", "LeftForeArm"}));
  EXPECT_TRUE(names(BodyPart::LeftArm, 2).empty());
  EXPECT_EQ(names(BodyPart::Torso, 2), (std::vector<std::string>{"Hips"}));
  EXPECT_EQ(c.threshold(BodyPart::RightLeg, 1), 200.0f);
  EXPECT_NO_THROW(c.validate(parts));
  // One level (no thresholds): everything, always.
  const LodConfig one = make_lod_config(parts, {});
  EXPECT_EQ(one.level_count, 1);
  for (BodyPart p : kAllBodyParts) EXPECT_EQ(one.synthesised_joints(p, 0), parts.joints_of(p));
}

TEST(LodConfig, ValidateNamesTheBadField) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  const auto expect_field = [&](const LodConfig& c, const std::string& field) {
    try {
      c.validate(parts);
      ADD_FAILURE() << "no error for " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.location().field, field) << e.what();
    }
  };
  LodConfig c = make_lod_config(parts, {2000.0f, 200.0f});
  c.set_thresholds(BodyPart::LeftLeg, {100.0f, 300.0f});
  expect_field(c, "lod.left_leg.thresholds[1]");
  c = make_lod_config(parts, {2000.0f, 200.0f});
  c.set_synthesised_joints(BodyPart::Torso, 0, {0, s.find("LeftHand")});
  expect_field(c, "lod.torso.levels[0]");
  c = make_lod_config(parts, {2000.0f, 200.0f});
  c.set_synthesised_joints(BodyPart::LeftArm, 2, {s.find("LeftHand")});  // not at level 1
  expect_field(c, "lod.left_arm.levels[2]");
  c = make_lod_config(parts, {2000.0f, 200.0f});
  c.set_synthesised_joints(BodyPart::Torso, 2, {});
  expect_field(c, "lod.torso.levels[2]");
  EXPECT_THROW(make_lod_config(parts, std::vector<float>(16, 1.0f)), Error);
  EXPECT_THROW(c.set_thresholds(BodyPart::Torso, {1.0f}), Error);
  EXPECT_THROW(c.set_synthesised_joints(BodyPart::Torso, 0, {99}), Error);
}

// A crowd scattered over a square, with random headings and scales.
struct Crowd {
  std::vector<glm::vec3> positions;
  std::vector<float> headings;
  std::vector<float> scales;
};

Crowd scatter(Index n, float half_extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> xz(-half_extent, half_extent), h(-3.14159f, 3.14159f), sc(0.8f, 1.2f);
  Crowd c;
  for (Index i = 0; i < n; ++i) {
    c.positions.emplace_back(xz(rng), 0.0f, xz(rng));
    c.headings.push_back(h(rng));
    c.scales.push_back(sc(rng));
  }
  return c;
}

Camera street_camera() {
  Camera cam;
  cam.position = {-5.0f, 1.8f, 30.0f};
  cam.target = {3.0f, 1.0f, 0.0f};
  cam.width = 1280;
  cam.height = 720;
  cam.fov_y = 0.9f;
  cam.far_plane = 300.0f;
  return cam;
}

// World spheres of a crowd from root transforms, with glm's matrices.
std::vector<glm::vec4> world_spheres(const Crowd& crowd, const BodyParts& parts) {
  std::vector<glm::vec4> out;
  for (std::size_t i = 0; i < crowd.positions.size(); ++i) {
    glm::mat4 m = glm::translate(glm::mat4(1.0f), crowd.positions[i]);
    m = glm::rotate(m, crowd.headings[i], glm::vec3(0, 1, 0));
    m = glm::scale(m, glm::vec3(crowd.scales[i]));
    for (const glm::vec4& t : parts.rest_spheres)
      out.emplace_back(glm::vec3(m * glm::vec4(glm::vec3(t), 1.0f)), t.w * crowd.scales[i]);
  }
  return out;
}

struct LodOutput {
  std::vector<std::uint8_t> levels;
  std::vector<std::uint32_t> masks;
  std::vector<float> coverage;
};

LodOutput run_lod(const CameraView& view, const LodConfig& config, const std::vector<glm::vec4>* spheres,
                  const Crowd* crowd, const BodyParts& parts) {
  const Index n = spheres != nullptr ? static_cast<Index>(spheres->size()) / kBodyPartCount
                                     : static_cast<Index>(crowd->positions.size());
  LodOutput out;
  out.levels.resize(static_cast<std::size_t>(n * kBodyPartCount));
  out.masks.resize(static_cast<std::size_t>(n * config.mask_words));
  out.coverage.resize(static_cast<std::size_t>(n * kBodyPartCount));
  const LodTables tables(config, Memory::Host);
  LodJob job;
  job.camera = view;
  job.set_tables(tables);
  if (spheres != nullptr) {
    job.spheres = *spheres;
  } else {
    job.roots.positions = crowd->positions;
    job.roots.headings = crowd->headings;
    job.roots.scales = crowd->scales;
    job.template_spheres = parts.rest_spheres;
  }
  job.levels = out.levels;
  job.joint_masks = out.masks;
  job.coverage = out.coverage;
  job.run();
  return out;
}

TEST(LodJob, MatchesPerCharacterDoublePrecisionReference) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  LodConfig config = make_lod_config(parts, {3000.0f, 800.0f, 150.0f, 20.0f});
  config.set_thresholds(BodyPart::Torso, {6000.0f, 1500.0f, 300.0f, 40.0f});
  const Crowd crowd = scatter(3000, 60.0f, 11);
  const std::vector<glm::vec4> spheres = world_spheres(crowd, parts);
  const Camera cam = street_camera();
  const CameraView view = make_camera_view(cam);
  const LodOutput got = run_lod(view, config, &spheres, nullptr, parts);
  const glm::dmat4 V = glm::dmat4(view_matrix(cam));
  std::vector<int> level_seen(static_cast<std::size_t>(config.level_count), 0);
  int borderline = 0;
  for (std::size_t i = 0; i < crowd.positions.size(); ++i) {
    std::set<std::int32_t> expected_joints;
    for (int p = 0; p < kBodyPartCount; ++p) {
      const glm::vec4 sp = spheres[i * kBodyPartCount + static_cast<std::size_t>(p)];
      const glm::dvec3 c = glm::dvec3(V * glm::dvec4(glm::dvec3(glm::vec3(sp)), 1.0));
      SphereImage kind{};
      double area = sphere_ellipse_area(c, double(sp.w), double(view.focal_px), &kind);
      if (kind == SphereImage::Inside || kind == SphereImage::Unbounded) area = 1280.0 * 720.0;
      if (sphere_outside_view(glm::vec3(c), sp.w, view)) area = 0.0;
      area = std::min(area, 1280.0 * 720.0);
      int level = 0;
      const auto part = static_cast<BodyPart>(p);
      while (level < config.level_count - 1 && area < config.threshold(part, level)) ++level;
      const int got_level = got.levels[i * kBodyPartCount + static_cast<std::size_t>(p)];
      if (got_level != level) {
        // Only a float-vs-double hair's breadth from a threshold may differ.
        const float t = config.threshold(part, std::min(level, got_level));
        EXPECT_NEAR(area, t, 1e-4 * t) << "character " << i << " part " << p;
        ++borderline;
      }
      EXPECT_NEAR(got.coverage[i * kBodyPartCount + static_cast<std::size_t>(p)], area, 1e-4 * area + 1e-3);
      ++level_seen[static_cast<std::size_t>(got_level)];
      for (std::int32_t j : config.synthesised_joints(part, got_level)) expected_joints.insert(j);
    }
    for (std::int32_t j = 0; j < s.joint_count(); ++j)
      ASSERT_EQ(joint_synthesised(&got.masks[i], j), expected_joints.count(j) == 1)
          << "character " << i << " joint " << j;
  }
  EXPECT_LE(borderline, 2);
  for (int l = 0; l < config.level_count; ++l) EXPECT_GT(level_seen[static_cast<std::size_t>(l)], 0) << "level " << l;
}

TEST(LodJob, RootTransformsGiveTheSameLevelsAsWorldSpheres) {
  const BodyParts parts = make_body_parts(humanoid());
  const LodConfig config = make_lod_config(parts, {2000.0f, 200.0f});
  const Crowd crowd = scatter(2000, 50.0f, 5);
  const std::vector<glm::vec4> spheres = world_spheres(crowd, parts);
  const CameraView view = make_camera_view(street_camera());
  const LodOutput a = run_lod(view, config, &spheres, nullptr, parts);
  const LodOutput b = run_lod(view, config, nullptr, &crowd, parts);
  int differ = 0;
  for (std::size_t i = 0; i < a.levels.size(); ++i) {
    EXPECT_NEAR(a.coverage[i], b.coverage[i], 1e-4f * a.coverage[i] + 1e-3f);
    differ += a.levels[i] != b.levels[i];
  }
  EXPECT_LE(differ, 2);
}

TEST(LodJob, IdenticalForAnyThreadCount) {
  const BodyParts parts = make_body_parts(humanoid());
  const LodConfig config = make_lod_config(parts, {2500.0f, 600.0f, 100.0f});
  const Crowd crowd = scatter(50000, 120.0f, 9);
  const CameraView view = make_camera_view(street_camera());
  LodOutput reference;
  LodHistogram reference_h;
  for (int t : thread_counts()) {
    ScopedExecution exec(Backend::Cpu, t);
    const LodOutput o = run_lod(view, config, nullptr, &crowd, parts);
    const LodHistogram h = lod_histogram(Span<const std::uint8_t>(o.levels.data(), static_cast<Index>(o.levels.size())),
                                         Span<const std::uint32_t>(o.masks.data(), static_cast<Index>(o.masks.size())),
                                         config.level_count, config.joint_count);
    if (reference.levels.empty()) {
      reference = o;
      reference_h = h;
      continue;
    }
    EXPECT_EQ(o.levels, reference.levels) << t;
    EXPECT_EQ(o.masks, reference.masks) << t;
    EXPECT_EQ(std::memcmp(o.coverage.data(), reference.coverage.data(), o.coverage.size() * sizeof(float)), 0) << t;
    EXPECT_EQ(h.level_counts, reference_h.level_counts) << t;
    EXPECT_EQ(h.joints_synthesised, reference_h.joints_synthesised) << t;
  }
}

TEST(LodJob, MoreLevelsAsACharacterWalksAway) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  // Seven levels, thresholds a factor 3 apart.
  std::vector<float> thresholds;
  for (float t = 20000.0f; thresholds.size() < 6; t /= 3.0f) thresholds.push_back(t);
  const LodConfig config = make_lod_config(parts, thresholds);
  ASSERT_EQ(config.level_count, 7);
  Camera cam;
  cam.position = {0, 1.5f, 0};
  cam.target = {0, 1.0f, -10.0f};
  cam.far_plane = 2000.0f;
  const CameraView view = make_camera_view(cam);
  Crowd walker;
  for (int i = 0; i < 400; ++i) {
    walker.positions.emplace_back(0.3f, 0.0f, -2.0f - 1.0f * static_cast<float>(i));
    walker.headings.push_back(0.0f);
    walker.scales.push_back(1.0f);
  }
  const LodOutput o = run_lod(view, config, nullptr, &walker, parts);
  int previous_joints = s.joint_count() + 1;
  std::set<int> levels_seen;
  for (std::size_t i = 0; i < walker.positions.size(); ++i) {
    int joints = 0;
    for (std::int32_t j = 0; j < s.joint_count(); ++j) joints += joint_synthesised(&o.masks[i], j);
    EXPECT_LE(joints, previous_joints) << "step " << i;
    previous_joints = joints;
    for (int p = 0; p < kBodyPartCount; ++p) {
      levels_seen.insert(o.levels[i * kBodyPartCount + static_cast<std::size_t>(p)]);
      if (i > 0) {
        EXPECT_GE(o.levels[i * kBodyPartCount + static_cast<std::size_t>(p)],
                  o.levels[(i - 1) * kBodyPartCount + static_cast<std::size_t>(p)]);
      }
    }
  }
  EXPECT_EQ(levels_seen.size(), 7u);
  EXPECT_EQ(previous_joints, 1);  // only the root, far away
}

TEST(LodJob, BadSpansAreNamed) {
  const BodyParts parts = make_body_parts(humanoid());
  const LodConfig config = make_lod_config(parts, {2000.0f, 200.0f});
  const LodTables tables(config, Memory::Host);
  std::vector<glm::vec4> spheres(10);
  std::vector<std::uint8_t> levels(10);
  std::vector<std::uint32_t> masks(3);  // should be 2
  LodJob job;
  job.camera = make_camera_view(street_camera());
  job.set_tables(tables);
  job.spheres = spheres;
  job.levels = levels;
  job.joint_masks = masks;
  try {
    job.run();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "LodJob.joint_masks") << e.what();
  }
  masks.resize(2);
  job.joint_masks = masks;
  std::vector<float> headings(2);
  job.roots.headings = headings;  // both inputs given
  EXPECT_THROW(job.run(), Error);
}

TEST(LodHistogram, MatchesCountingByHand) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  const LodConfig config = make_lod_config(parts, {2000.0f, 500.0f, 100.0f});
  const Crowd crowd = scatter(9000, 80.0f, 2);  // more than two histogram blocks
  const LodOutput o = run_lod(make_camera_view(street_camera()), config, nullptr, &crowd, parts);
  const LodHistogram h = lod_histogram(Span<const std::uint8_t>(o.levels.data(), static_cast<Index>(o.levels.size())),
                                       Span<const std::uint32_t>(o.masks.data(), static_cast<Index>(o.masks.size())),
                                       config.level_count, config.joint_count);
  std::vector<Index> levels(static_cast<std::size_t>(kBodyPartCount * config.level_count), 0);
  std::vector<Index> joints(static_cast<std::size_t>(s.joint_count() + 1), 0);
  std::vector<Index> per_joint(static_cast<std::size_t>(s.joint_count()), 0);
  Index total = 0;
  for (std::size_t i = 0; i < crowd.positions.size(); ++i) {
    for (int p = 0; p < kBodyPartCount; ++p)
      ++levels[static_cast<std::size_t>(p * config.level_count + o.levels[i * 5 + static_cast<std::size_t>(p)])];
    int k = 0;
    for (std::int32_t j = 0; j < s.joint_count(); ++j)
      if (joint_synthesised(&o.masks[i], j)) {
        ++k;
        ++per_joint[static_cast<std::size_t>(j)];
      }
    ++joints[static_cast<std::size_t>(k)];
    total += k;
  }
  EXPECT_EQ(h.characters, 9000);
  EXPECT_EQ(h.level_counts, levels);
  EXPECT_EQ(h.joints_synthesised, joints);
  EXPECT_EQ(h.total_joints_synthesised, total);
  EXPECT_EQ(h.per_joint(config), per_joint);
  EXPECT_GT(h.mean_joints_synthesised(), 1.0);
  EXPECT_LT(h.mean_joints_synthesised(), s.joint_count());
}

TEST(LodSpheresJob, CentresFollowPosedJointsAndRadiiScale) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  const std::int32_t J = s.joint_count();
  const Index n = 50;
  std::mt19937 rng(4);
  std::vector<glm::vec3> positions(static_cast<std::size_t>(n * J));
  std::vector<glm::quat> rotations(static_cast<std::size_t>(n * J));
  std::vector<glm::quat> local(static_cast<std::size_t>(J));
  std::vector<float> scales;
  for (Index c = 0; c < n; ++c) {
    for (auto& q : local) q = random_rotation(rng);
    motion::fk_pose(J, s.parents.data(), s.offsets.data(), local.data(), nullptr,
                    glm::vec3(static_cast<float>(c), 1, 0), positions.data() + c * J, rotations.data() + c * J);
    scales.push_back(1.0f + 0.01f * static_cast<float>(c));
  }
  std::vector<glm::vec4> spheres(static_cast<std::size_t>(n * kBodyPartCount));
  LodSpheresJob job;
  job.joint_count = J;
  job.anchors = parts.anchors;
  job.joint_positions = positions;
  job.scales = scales;
  job.spheres = spheres;
  job.run();
  const std::int32_t elbow = s.role(Role::RightElbow), hips = s.role(Role::Hips), neck = s.role(Role::Neck);
  for (Index c = 0; c < n; ++c) {
    const glm::vec4 arm = spheres[static_cast<std::size_t>(c * 5 + 1)];
    EXPECT_EQ(glm::vec3(arm), positions[static_cast<std::size_t>(c * J + elbow)]);
    EXPECT_FLOAT_EQ(arm.w, parts.anchor(BodyPart::RightArm).radius * scales[static_cast<std::size_t>(c)]);
    const glm::vec3 mid =
        0.5f * (positions[static_cast<std::size_t>(c * J + hips)] + positions[static_cast<std::size_t>(c * J + neck)]);
    EXPECT_LT(glm::length(glm::vec3(spheres[static_cast<std::size_t>(c * 5 + 2)]) - mid), 1e-5f);
  }
}

TEST(MaskedPose, MaskedJointsAreNeverEvaluatedAndHoldTheParentFrame) {
  const Skeleton s = humanoid();
  const BodyParts parts = make_body_parts(s);
  const LodConfig config = make_lod_config(parts, {2000.0f, 200.0f});
  const std::int32_t J = s.joint_count();
  std::mt19937 rng(8);
  std::vector<glm::quat> local(static_cast<std::size_t>(J));
  for (auto& q : local) q = random_rotation(rng);
  // Every combination of part levels: 3^5 masks.
  for (int code = 0; code < 243; ++code) {
    std::uint32_t mask = 0;
    int rest = code;
    for (BodyPart p : kAllBodyParts) {
      mask |= config.mask(p, rest % 3)[0];
      rest /= 3;
    }
    std::vector<int> calls(static_cast<std::size_t>(J), 0);
    const MaskedPose pose = synthesise_with_mask(
        s, Span<const std::uint32_t>(&mask, 1),
        [&](std::int32_t j) {
          ++calls[static_cast<std::size_t>(j)];
          return local[static_cast<std::size_t>(j)];
        },
        glm::vec3(0, 1, 0));
    EXPECT_EQ(pose.evaluated, popcount32(mask));
    for (std::int32_t j = 0; j < J; ++j) {
      const auto jj = static_cast<std::size_t>(j);
      ASSERT_EQ(calls[jj], joint_synthesised(&mask, j) ? 1 : 0) << "joint " << j;
      if (joint_synthesised(&mask, j) || j == 0) continue;
      const auto pp = static_cast<std::size_t>(s.parents[jj]);
      EXPECT_LT(std::abs(std::abs(glm::dot(pose.rotations[jj], pose.rotations[pp])) - 1.0f), 1e-6f);
      EXPECT_LT(glm::length(pose.positions[jj] - (pose.positions[pp] + pose.rotations[pp] * s.offsets[jj])), 1e-6f);
    }
  }
  // The full mask is plain forward kinematics.
  const std::uint32_t all = (1u << J) - 1u;
  const MaskedPose full = synthesise_with_mask(
      s, Span<const std::uint32_t>(&all, 1), [&](std::int32_t j) { return local[static_cast<std::size_t>(j)]; },
      glm::vec3(2, 1, 0));
  std::vector<glm::vec3> fp(static_cast<std::size_t>(J));
  std::vector<glm::quat> fr(static_cast<std::size_t>(J));
  motion::fk_pose(J, s.parents.data(), s.offsets.data(), local.data(), nullptr, glm::vec3(2, 1, 0), fp.data(),
                  fr.data());
  EXPECT_EQ(full.evaluated, J);
  for (std::size_t j = 0; j < fp.size(); ++j) {
    EXPECT_EQ(full.positions[j], fp[j]);
    EXPECT_EQ(full.rotations[j], fr[j]);
  }
  // Held rotations replace identity for masked joints.
  const std::uint32_t root_only = 1u;
  std::vector<glm::quat> held(static_cast<std::size_t>(J));
  for (auto& q : held) q = random_rotation(rng);
  const MaskedPose h = synthesise_with_mask(
      s, Span<const std::uint32_t>(&root_only, 1), [&](std::int32_t j) { return local[static_cast<std::size_t>(j)]; },
      glm::vec3(0), held);
  std::vector<glm::quat> mixed = held;
  mixed[0] = local[0];
  motion::fk_pose(J, s.parents.data(), s.offsets.data(), mixed.data(), nullptr, glm::vec3(0), fp.data(), fr.data());
  EXPECT_EQ(h.evaluated, 1);
  for (std::size_t j = 0; j < fp.size(); ++j) EXPECT_EQ(h.rotations[j], fr[j]);
}

}  // namespace
}  // namespace throng::anim
