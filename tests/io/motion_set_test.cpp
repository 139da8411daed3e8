// Motion sets from BVH files (io/motion_set.h): the three YAML forms, the
// up axis told from the body (a Z-up file turned Y-up gives the same clip as
// the Y-up file), and refusals that say what is wrong with a clip. The
// clips are the default set's, written as BVH files here.
#include "io/motion_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <unistd.h>

#include "core/error.h"
#include "io/bvh_writer.h"
#include "io/scenario_yaml.h"
#include "motion/default_set.h"
#include "tests/shared_data.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

MotionSetSpec parse(const std::string& yaml) {
  YamlReader reader("motion.yaml");
  const YAML::Node root = YAML::Load(yaml);
  return read_motion_set(reader, root["motion"], "motion");
}

std::string error_of(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(MotionSet, ReadsTheThreeForms) {
  EXPECT_TRUE(parse("motion: default").is_default());
  const MotionSetSpec list = parse("motion: [walk.bvh, {file: jog.bvh, name: fast, skip_frames: 1}]");
  ASSERT_EQ(list.clips.size(), 2u);
  EXPECT_EQ(list.clips[0].name, "walk");
  EXPECT_EQ(list.clips[1].name, "fast");
  EXPECT_EQ(list.clips[1].skip_frames, 1);
  EXPECT_FALSE(list.up_axis);
  EXPECT_FALSE(list.unit);
  const MotionSetSpec map = parse("motion: {clips: [a.bvh], up_axis: z, units: cm}");
  ASSERT_EQ(map.clips.size(), 1u);
  EXPECT_EQ(map.up_axis, motion::UpAxis::Z);
  EXPECT_EQ(map.unit, motion::LengthUnit::Centimetre);
  const MotionSetSpec autos = parse("motion: {clips: [a.bvh], up_axis: auto, units: auto}");
  EXPECT_FALSE(autos.up_axis);
  EXPECT_FALSE(autos.unit);
}

TEST(MotionSet, BadValuesAreLocated) {
  EXPECT_NE(error_of("motion: {clips: [a.bvh], up_axis: x}").find("motion.up_axis"), std::string::npos);
  EXPECT_NE(error_of("motion: {clips: [a.bvh], units: furlongs}").find("expected auto, m, cm"), std::string::npos);
  EXPECT_NE(error_of("motion: {up_axis: z}").find("clips"), std::string::npos);
  EXPECT_NE(error_of("motion: {clips: [a.bvh], speed: 2}").find("speed"), std::string::npos);
  EXPECT_NE(error_of("motion: []").find("motion"), std::string::npos);
  EXPECT_NE(error_of("motion: [{name: x}]").find("file"), std::string::npos);
  const std::string e = error_of("motion:\n  clips: [a.bvh]\n  up_axis: sideways\n");
  EXPECT_NE(e.find("motion.yaml:3:"), std::string::npos) << e;
}

// The inverse of motion::z_up_to_y_up: a Y-up skeleton and clip as a Z-up
// tool would write them.
void y_up_to_z_up(motion::Skeleton& s, motion::Clip& c) {
  const glm::quat r = glm::angleAxis(0.5f * 3.14159265358979f, glm::vec3(1.0f, 0.0f, 0.0f));
  for (glm::vec3& o : s.offsets) o = r * o;
  for (glm::vec3& e : s.end_sites) e = r * e;
  for (glm::vec3& p : c.root_positions) p = r * p;
  for (glm::quat& q : c.rotations) q = glm::normalize(r * q * glm::conjugate(r));
}

class MotionSetFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("throng_motion_set_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    skeleton_ = motion::default_skeleton();
    motions_ = motion::make_default_motions(skeleton_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Default clip `name` (three cycles, so the cycle search has a loop) into
  // dir_/file, Z-up when asked.
  std::string write(const std::string& name, const std::string& file, bool z_up) {
    for (const motion::DefaultMotion& m : motions_)
      if (m.spec.name == name) {
        motion::Skeleton s = skeleton_;
        motion::Clip c = m.clip;
        if (z_up) y_up_to_z_up(s, c);
        write_bvh((dir_ / file).string(), s, c);
        return file;
      }
    ADD_FAILURE() << "no default clip " << name;
    return file;
  }

  fs::path dir_;
  motion::Skeleton skeleton_;
  std::vector<motion::DefaultMotion> motions_;
};

TEST_F(MotionSetFiles, AZUpFileIsDetectedAndGivesTheSameClips) {
  MotionSetSpec y_up, z_up;
  y_up.clips = {{write("walk", "walk_y.bvh", false), "walk", 0}, {write("run_slow", "run_y.bvh", false), "run", 0}};
  z_up.clips = {{write("walk", "walk_z.bvh", true), "walk", 0}, {write("run_slow", "run_z.bvh", true), "run", 0}};
  const motion::BlendSpace1D a = load_motion_set(y_up, dir_, "motion");
  const motion::BlendSpace1D b = load_motion_set(z_up, dir_, "motion");
  ASSERT_EQ(a.clip_count(), 2);
  ASSERT_EQ(b.clip_count(), 2);
  for (std::int32_t k = 0; k < 2; ++k) {
    const motion::LocomotionClip& ca = a.clips()[static_cast<std::size_t>(k)];
    const motion::LocomotionClip& cb = b.clips()[static_cast<std::size_t>(k)];
    std::printf("%s: Y-up %.4f m/s, stride %.4f m; Z-up %.4f m/s, stride %.4f m\n", ca.name.c_str(), ca.speed,
                ca.stride_m, cb.speed, cb.stride_m);
    EXPECT_NEAR(ca.speed, cb.speed, 1e-3) << ca.name;
    EXPECT_NEAR(ca.stride_m, cb.stride_m, 1e-3) << ca.name;
    EXPECT_EQ(ca.frame_count(), cb.frame_count()) << ca.name;
  }
  for (std::int32_t j = 0; j < a.joint_count(); ++j)
    EXPECT_LT(glm::length(a.skeleton().offsets[static_cast<std::size_t>(j)] -
                          b.skeleton().offsets[static_cast<std::size_t>(j)]),
              1e-4f)
        << a.skeleton().names[static_cast<std::size_t>(j)];
  // Told it is Y-up, the Z-up walk (which would lie on its back) is refused.
  MotionSetSpec wrong = z_up;
  wrong.up_axis = motion::UpAxis::Y;
  try {
    load_motion_set(wrong, dir_, "motion");
    ADD_FAILURE() << "a Z-up walk read as Y-up was accepted";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("walk_z.bvh"), std::string::npos) << m;
    EXPECT_NE(m.find("the body stands along +z"), std::string::npos) << m;
    EXPECT_NE(m.find("motion.up_axis is y"), std::string::npos) << m;
  }
}

// A scenario file's clips are found beside it, wherever throng runs from.
TEST_F(MotionSetFiles, AScenariosClipsAreRelativeToItsFile) {
  write("walk", "walk.bvh", false);
  write("run_slow", "run.bvh", false);
  const fs::path scenario = dir_ / "scene.yaml";
  FILE* f = std::fopen(scenario.string().c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(
      "groups:\n  - {count: 2, spawn: {ring: {center: [0, 0], spacing: 1.0}}, goal: {mirror: [0, 0]}}\n"
      "motion: [walk.bvh, run.bvh]\n",
      f);
  std::fclose(f);
  const LoadedScenario loaded = read_scenario_file(scenario.string());
  EXPECT_EQ(loaded.motion_folder(), dir_);
  const motion::BlendSpace1D space = load_motion_set(loaded.motion, loaded.motion_folder(), "motion");
  EXPECT_EQ(space.clip_count(), 2);
  EXPECT_EQ(load_builtin_scenario("circle").motion_folder(), fs::path());
}

TEST_F(MotionSetFiles, RefusalsSayWhatIsWrongWithTheClip) {
  MotionSetSpec standing;
  standing.clips = {{write("idle", "idle.bvh", false), "idle", 0}};
  try {
    load_motion_set(standing, dir_, "motion");
    ADD_FAILURE() << "a standing clip was accepted as locomotion";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("idle.bvh"), std::string::npos) << m;
    EXPECT_NE(m.find("not locomotion"), std::string::npos) << m;
    EXPECT_NE(m.find("the root moves"), std::string::npos) << m;
    EXPECT_EQ(m.find(".h "), std::string::npos) << m;  // no pointer to a header
  }
  MotionSetSpec missing;
  missing.clips = {{"nowhere.bvh", "nowhere", 0}};
  try {
    load_motion_set(missing, dir_, "motion");
    ADD_FAILURE() << "a missing file was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nowhere.bvh"), std::string::npos) << e.what();
  }
}

// Real motion capture that is not a walk or run: CMU 01_01 hops (both feet
// land together) and 13_32's jump (no foot lands once per cycle) are
// refused, saying so; 16_15's walk is taken.
TEST(MotionSetShared, HopsAndJumpsAreNotWalks) {
  THRONG_NEED_SHARED_BVH(bvh);
  const auto refusal = [&](const std::string& file) {
    MotionSetSpec spec;
    spec.clips = {{file, "clip", 1}};
    try {
      load_motion_set(spec, *bvh, "motion");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string hops = refusal("cmu_01_01_hops_turnaround_mb.bvh");
  EXPECT_NE(hops.find("the feet land together"), std::string::npos) << hops;
  EXPECT_NE(hops.find("cmu_01_01_hops_turnaround_mb.bvh"), std::string::npos) << hops;
  const std::string jump = refusal("cmu_13_32_forward_jump_daz.bvh");
  EXPECT_NE(jump.find("not a walk or run"), std::string::npos) << jump;
  EXPECT_EQ(refusal("cmu_16_15_walk_daz.bvh"), "accepted");
}

}  // namespace
}  // namespace throng::io
