// The `throng animate` scenario reader: the example and the built-in agree,
// every key is read, and bad input is an Error naming file:line:column.
#include "io/animate_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/error.h"

namespace throng::io {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_animate_spec(yaml, "test.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(AnimateYaml, TheExampleIsTheBuiltInAndTheDefaults) {
  const std::filesystem::path example =
      std::filesystem::path(THRONG_SOURCE_DIR) / "examples" / "animate" / "formation.yaml";
  AnimateSpec file = read_animate_spec(example.string());
  AnimateSpec builtin = builtin_animate_spec("formation");
  EXPECT_EQ(file.source, example.string());
  EXPECT_EQ(builtin.source, "built-in");
  file.source = builtin.source = "";
  EXPECT_EQ(file, builtin);
  AnimateSpec defaults = parse_animate_spec("", "empty.yaml");
  defaults.source = "";
  EXPECT_EQ(defaults, builtin);  // the example spells out the defaults
  EXPECT_EQ(builtin.characters, 1000);
  EXPECT_EQ(builtin.shape, AnimateSpec::Shape::Circle);
  EXPECT_THROW(builtin_animate_spec("crossing"), Error);
}

TEST(AnimateYaml, ReadsEveryKey) {
  const AnimateSpec s = parse_animate_spec(R"(
name: marching
characters: 250
formation: {shape: grid, radius: 5, ring_spacing: 2, spacing: 1.5, direction: cw}
speed: {min: 1.0, max: 1.5, change_every: 0}
scale: {min: 0.9, max: 1.2}
motion:
  - walk.bvh
  - {file: clips/jog.bvh, name: jog, skip_frames: 1}
mode: paper
duration: 2.5
fps: 30
seed: 7
camera: {orbit_radius: 40, elevation: 9, angular_speed: -0.2, fov_deg: 60, resolution: [640, 360]}
lod: {enabled: false, thresholds: [500, 100, 10]}
cache: {enabled: false, bucket_width: 0.1, capacity_mb: 4}
foot_skating: {characters: 3}
output: out/marching
)",
                                           "full.yaml");
  EXPECT_EQ(s.name, "marching");
  EXPECT_EQ(s.characters, 250);
  EXPECT_EQ(s.shape, AnimateSpec::Shape::Grid);
  EXPECT_FLOAT_EQ(s.radius, 5.0f);
  EXPECT_FLOAT_EQ(s.ring_spacing, 2.0f);
  EXPECT_FLOAT_EQ(s.spacing, 1.5f);
  EXPECT_TRUE(s.clockwise);
  EXPECT_FLOAT_EQ(s.speed_min, 1.0f);
  EXPECT_FLOAT_EQ(s.speed_max, 1.5f);
  EXPECT_FLOAT_EQ(s.change_every_s, 0.0f);
  EXPECT_FLOAT_EQ(s.scale_min, 0.9f);
  EXPECT_FLOAT_EQ(s.scale_max, 1.2f);
  ASSERT_EQ(s.motion.clips.size(), 2u);
  EXPECT_EQ(s.motion.clips[0].file, "walk.bvh");
  EXPECT_EQ(s.motion.clips[0].name, "walk");
  EXPECT_EQ(s.motion.clips[1].name, "jog");
  EXPECT_EQ(s.motion.clips[1].skip_frames, 1);
  EXPECT_TRUE(s.paper_mode);
  EXPECT_FLOAT_EQ(s.duration_s, 2.5f);
  EXPECT_FLOAT_EQ(s.fps, 30.0f);
  EXPECT_EQ(s.seed, 7u);
  EXPECT_FLOAT_EQ(s.camera_radius, 40.0f);
  EXPECT_FLOAT_EQ(s.camera_elevation, 9.0f);
  EXPECT_FLOAT_EQ(s.camera_angular_speed, -0.2f);
  EXPECT_FLOAT_EQ(s.camera_fov_deg, 60.0f);
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 360);
  EXPECT_FALSE(s.lod);
  EXPECT_EQ(s.lod_thresholds, (std::vector<float>{500.0f, 100.0f, 10.0f}));
  EXPECT_FALSE(s.cache);
  EXPECT_FLOAT_EQ(s.bucket_width, 0.1f);
  EXPECT_FLOAT_EQ(s.cache_capacity_mb, 4.0f);
  EXPECT_EQ(s.skating_characters, 3);
  EXPECT_EQ(s.output, "out/marching");
}

TEST(AnimateYaml, ErrorsNameFileLineColumnAndKey) {
  const struct {
    const char* yaml;
    const char* expected;  // a piece of the message
  } cases[] = {
      {"characters: 10\nspeeed: {min: 1}\n", "test.yaml:2:1"},
      {"characters: 10\nspeeed: {min: 1}\n", "unknown key 'speeed'"},
      {"characters: ten\n", "test.yaml:1:13"},
      {"characters: ten\n", "expected a number, got 'ten'"},
      {"characters: 0\n", "must be in [1, 10000000]"},
      {"speed: {min: 2, max: 1}\n", "min must not exceed max"},
      {"mode: sprint\n", "expected one of continuous, paper, got 'sprint'"},
      {"formation:\n  shape: square\n", "test.yaml:2:10"},
      {"duration: .nan\n", "duration"},
      {"lod: {thresholds: [30, 1000]}\n", "thresholds must decrease"},
      {"motion:\n  - {name: walk}\n", "motion[0]: missing required key 'file'"},
      {"motion: 3\n", "expected one of default, got '3'"},
      {"motion: {file: a.bvh}\n", "motion.file: unknown key 'file'; expected one of clips, up_axis, units"},
      {"camera: {resolution: [640]}\n", "expected [width, height]"},
      {"characters: [1, 2\n", "YAML syntax"},
      {"- a list\n- at the top\n", "expected a map with keys name, characters"},
  };
  for (const auto& c : cases) {
    const std::string message = error_of(c.yaml);
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.yaml << " -> " << message;
  }
  EXPECT_THROW(read_animate_spec("/no/such/file.yaml"), Error);
}

}  // namespace
}  // namespace throng::io
