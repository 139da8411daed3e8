#include "render/video.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <sys/wait.h>
#include <vector>

#include "anim/crowd_animator.h"
#include "core/error.h"
#include "motion/locomotion.h"
#include "render/camera_path.h"
#include "render/image.h"
#include "render/recorder.h"
#include "sim/world.h"
#include "tests/render/overlay_pixels.h"
#include "tests/render/video_probe.h"

namespace throng::render {
namespace {

using throng::testing::probe_video;
using throng::testing::VideoProbe;

std::string temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("throng_video_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

Image solid(std::int32_t w, std::int32_t h, std::uint8_t shade) {
  Image im(w, h);
  for (std::size_t i = 0; i < im.rgba.size(); ++i)
    im.rgba[i] = (i % 4 == 3) ? 255 : static_cast<std::uint8_t>(shade + i % 7);
  return im;
}

class VideoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!ffmpeg_available()) GTEST_FAIL() << "ffmpeg is missing: bash scripts/setup.sh --deps installs it";
  }
};

TEST_F(VideoTest, WritesAPlayableMp4) {
  const std::string dir = temp_dir("plain");
  VideoSpec spec;
  spec.path = dir + "/clip.mp4";
  spec.width = 64;
  spec.height = 48;
  spec.fps = 25.0;
  {
    VideoWriter w(spec);
    for (int f = 0; f < 50; ++f) w.write(solid(64, 48, static_cast<std::uint8_t>(f * 4)));
    EXPECT_EQ(w.frames_written(), 50);
    w.finish();
  }
  const VideoProbe p = probe_video(spec.path);
  EXPECT_EQ(p.codec, "h264") << p;
  EXPECT_EQ(p.pix_fmt, "yuv420p") << p;
  EXPECT_EQ(p.width, 64) << p;
  EXPECT_EQ(p.height, 48) << p;
  EXPECT_EQ(p.frames, 50) << p;
  EXPECT_NEAR(p.duration, 2.0, 0.05) << p;
}

// Destroyed without finish() (an error elsewhere ended the run), the writer
// lets ffmpeg close the file and keeps it under a name that says it is
// incomplete; the final name never holds a partial video.
TEST_F(VideoTest, AnUnfinishedVideoStaysPartial) {
  const std::string dir = temp_dir("partial");
  VideoSpec spec;
  spec.path = dir + "/clip.mp4";
  spec.width = 64;
  spec.height = 48;
  {
    VideoWriter w(spec);
    for (int f = 0; f < 10; ++f) w.write(solid(64, 48, static_cast<std::uint8_t>(f * 20)));
  }
  EXPECT_FALSE(std::filesystem::exists(spec.path));
  const VideoProbe p = probe_video(spec.path + ".partial");
  EXPECT_EQ(p.codec, "h264") << p;
  EXPECT_EQ(p.frames, 10) << p;
}

TEST_F(VideoTest, BadSpecsAndFramesAreErrors) {
  VideoSpec spec;
  spec.path = temp_dir("bad") + "/x.mp4";
  spec.width = 63;
  EXPECT_THROW(spec.validate(), Error);
  spec.width = 64;
  spec.fps = 0.0;
  EXPECT_THROW(spec.validate(), Error);
  spec.fps = 30.0;
  spec.ffmpeg = "/nonexistent/ffmpeg";
  try {
    VideoWriter w(spec);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "video.ffmpeg");
  }
  spec.ffmpeg = "ffmpeg";
  VideoWriter w(spec);
  EXPECT_THROW(w.write(solid(32, 32, 0)), Error);  // wrong size
}

TEST_F(VideoTest, FfmpegFailureIsReportedNotFatal) {
  VideoSpec spec;
  spec.path = "/nonexistent-folder/x.mp4";  // ffmpeg cannot open it
  spec.width = 320;
  spec.height = 240;
  VideoWriter w(spec);
  bool failed = false;
  try {
    // ffmpeg exits at once; writing into the closed pipe must not kill us.
    for (int f = 0; f < 200 && !failed; ++f) w.write(solid(320, 240, 0));
    w.finish();
  } catch (const Error& e) {
    failed = true;
    EXPECT_NE(std::string(e.what()).find("ffmpeg"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(failed);
}

// Characters on a grid walking, posed by the locomotion stage for each frame's camera.
struct WalkingGrid {
  motion::BlendSpace1D space = motion::make_default_blend_space();
  anim::CrowdAnimator crowd;
  explicit WalkingGrid(Index n) : crowd(space, n) {
    std::vector<glm::vec3> at;
    std::vector<float> yaws, speeds;
    for (Index i = 0; i < n; ++i) {
      at.emplace_back(2.0f * static_cast<float>(i % 7) - 6.0f, 0.0f, 2.0f * static_cast<float>(i / 7) - 6.0f);
      yaws.push_back(0.3f * static_cast<float>(i));
      speeds.push_back(0.5f + 0.05f * static_cast<float>(i));
    }
    crowd.place(at, yaws);
    crowd.set_speeds(speeds);
  }
};

TEST_F(VideoTest, RecorderWritesVideoOfAWalkingCrowdWithTheWorldsObstacles) {
  WalkingGrid grid(40);
  RecordSpec spec;
  spec.folder = temp_dir("recorder");
  spec.width = 160;
  spec.height = 90;
  spec.fps = 10.0;
  spec.options.mode = RenderMode::Skinned;
  Recorder rec(spec, make_crowd_rigs(grid.space.skeleton()));
  sim::WorldSpec world;
  world.circles.push_back({{0.0f, 12.0f}, 1.5f});
  world.circle_fields.push_back("world.obstacles[0]");
  rec.set_world(sim::World::build(world, 4.0f));
  const CameraPath path = framing_orbit(glm::vec3(0.0f), 12.0f, Camera{});
  for (int f = 0; f < 15; ++f) {
    const Camera camera = path.at(f / spec.fps);
    grid.crowd.animate({static_cast<float>(1.0 / spec.fps), &camera, true});
    const RenderStats s = rec.add_frame(camera, poses_of(grid.crowd));
    EXPECT_EQ(s.characters, 40);
    EXPECT_GT(s.visible, 30);
    EXPECT_EQ(s.instances, s.visible);  // one mannequin each
  }
  const std::string file = rec.finish();
  EXPECT_EQ(file, spec.folder + "/crowd.mp4");
  const VideoProbe p = probe_video(file);
  EXPECT_EQ(p.width, 160) << p;
  EXPECT_EQ(p.height, 90) << p;
  EXPECT_EQ(p.frames, 15) << p;
  EXPECT_NEAR(p.duration, 1.5, 0.05) << p;
}

TEST_F(VideoTest, RecorderWritesNumberedPngFrames) {
  WalkingGrid grid(5);
  grid.crowd.animate({0.1f, nullptr, true});
  RecordSpec spec;
  spec.output = RecordOutput::Frames;
  spec.folder = temp_dir("frames") + "/nested";
  spec.width = 81;  // odd sizes are fine for PNG
  spec.height = 45;
  Recorder rec(spec, make_crowd_rigs(grid.space.skeleton()));
  const CameraPath path = framing_flyover(glm::vec3(0.0f), 8.0f, Camera{}, 1.0f);
  for (int f = 0; f < 3; ++f) rec.add_frame(path.at(0.5 * f), poses_of(grid.crowd), {});
  EXPECT_EQ(rec.finish(), spec.folder);
  for (int f = 0; f < 3; ++f) {
    const Image im = read_png(spec.folder + "/frame_0000" + std::to_string(f) + ".png");
    EXPECT_EQ(im.width, 81);
    EXPECT_EQ(im.height, 45);
  }
  EXPECT_FALSE(std::filesystem::exists(spec.folder + "/frame_00003.png"));
  RecordSpec bad = spec;
  bad.output = RecordOutput::Video;
  try {
    bad.validate();
    FAIL() << "odd video width accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "render.width");
  }
}

// The acceptance: `throng run circle --agents 1000 --render video` writes a
// playable MP4 of the simulated, animated crowd. Kept short: 2 simulated
// seconds at 12 fps and 160x90 (1000 agents, 20 steps, 25 frames with the
// first).
TEST_F(VideoTest, ThrongRunRendersTheCircleAsAVideo) {
  const std::string dir = temp_dir("run");
  const std::string cmd = std::string(THRONG_EXE) +
                          " --threads 2 run circle --agents 1000 --seconds 2 --render video --width 160 --height 90 " +
                          "--fps 12 --camera orbit --no-trajectories --quiet --out '" + dir + "' 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  char buf[512];
  while (pipe && fgets(buf, sizeof buf, pipe.get()) != nullptr) out += buf;
  ASSERT_EQ(pclose(pipe.release()), 0) << out;
  EXPECT_NE(out.find(dir + "/crowd.mp4 (25 frames, 160x90 at 12 fps)"), std::string::npos) << out;
  const VideoProbe p = probe_video(dir + "/crowd.mp4");
  EXPECT_EQ(p.codec, "h264") << p;
  EXPECT_EQ(p.width, 160) << p;
  EXPECT_EQ(p.height, 90) << p;
  EXPECT_EQ(p.frames, 25) << p;
  EXPECT_NEAR(p.duration, 25.0 / 12.0, 0.05) << p;
}

// `throng ARGS`, stdout and stderr into `out`; the exit status, -1 when killed.
int run_throng(const std::string& args, std::string& out) {
  const std::string cmd = std::string(THRONG_EXE) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[512];
  while (fgets(buf, sizeof buf, pipe) != nullptr) out += buf;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Where the characters are in a frame: the pixels that differ between two
// drawings of it, one with every agent at the finest joint LOD and one with
// every agent at the coarsest (LOD colours; nothing else depends on LOD).
struct Crowd {
  std::int64_t pixels = 0;
  double x = 0.0, y = 0.0;  // their centroid, pixels from the top left
};
Crowd crowd_in(const Image& fine, const Image& coarse) {
  EXPECT_EQ(fine.width, coarse.width);
  EXPECT_EQ(fine.height, coarse.height);
  Crowd c;
  for (std::int32_t y = 0; y < std::min(fine.height, coarse.height); ++y)
    for (std::int32_t x = 0; x < std::min(fine.width, coarse.width); ++x)
      if (colour_distance(fine, x, y, coarse.pixel(x, y)) > 16) {
        ++c.pixels;
        c.x += x;
        c.y += y;
      }
  if (c.pixels > 0) {
    c.x /= static_cast<double>(c.pixels);
    c.y /= static_cast<double>(c.pixels);
  }
  return c;
}

// `throng run --camera follow`: the scenario camera's direction, aimed at the
// crowd and close enough to frame it. A small group walking far from the
// target of the scenario camera, drawn under that camera kept fixed and
// under follow: under follow the characters are in the middle of every
// frame and cover many more pixels than under the fixed camera.
TEST(ThrongRunCamera, FollowKeepsTheCrowdInTheMiddleOfTheFrame) {
  const std::string dir = temp_dir("follow");
  const std::string scenario = dir + "/aside.yaml";
  std::ofstream(scenario) << "name: aside\nseed: 3\ndt: 0.1\nduration: 2\n"
                             "world:\n  walkable: {rect: {min: [-40, -30], max: [40, 30]}}\n"
                             "groups:\n  - name: walkers\n    count: 12\n    radius: 0.25\n"
                             "    speed: {mean: 1.3, stddev: 0.1, min: 1.0, max: 1.6}\n"
                             "    spawn: {rect: {min: [22, 6], max: [28, 12]}}\n    goal: {offset: [8, 0]}\n"
                             "camera:\n  position: [0, -45, 40]\n  target: [0, 0, 0]\n  fov_degrees: 50\n";
  constexpr int kFrames = 5;  // 2 simulated seconds at 2 fps, the first frame included
  const auto frames = [&](const std::string& camera, const std::string& lod) {
    const std::string out_dir = dir + "/" + camera + "_" + lod;
    std::string out;
    const int code = run_throng("--backend cpu --threads 2 run '" + scenario +
                                    "' --seconds 2 --render frames --width 160 --height 90 --fps 2 "
                                    "--no-trajectories --quiet --lod-colours --camera " +
                                    camera + " --lod-thresholds " +
                                    (lod == "fine" ? "0.002,0.001" : "100000000,10000000") + " --out '" + out_dir + "'",
                                out);
    EXPECT_EQ(code, 0) << out;
    std::vector<Image> images;
    for (int f = 0; f < kFrames; ++f) images.push_back(read_png(out_dir + "/frame_0000" + std::to_string(f) + ".png"));
    EXPECT_FALSE(std::filesystem::exists(out_dir + "/frame_0000" + std::to_string(kFrames) + ".png"));
    return images;
  };
  const std::vector<Image> follow_fine = frames("follow", "fine"), follow_coarse = frames("follow", "coarse");
  const std::vector<Image> fixed_fine = frames("fixed", "fine"), fixed_coarse = frames("fixed", "coarse");
  for (int f = 0; f < kFrames; ++f) {
    const auto i = static_cast<std::size_t>(f);
    const Crowd follow = crowd_in(follow_fine[i], follow_coarse[i]);
    const Crowd fixed = crowd_in(fixed_fine[i], fixed_coarse[i]);
    const double w = follow_fine[i].width, h = follow_fine[i].height;
    EXPECT_GT(fixed.pixels, 0) << "frame " << f;  // seen, small, by the scenario camera
    EXPECT_GT(follow.pixels, static_cast<std::int64_t>(w * h / 50)) << "frame " << f;
    EXPECT_GT(follow.pixels, 5 * fixed.pixels) << "frame " << f;
    EXPECT_LT(std::abs(follow.x - 0.5 * w), 0.15 * w) << "frame " << f << ": the crowd's centre at x " << follow.x;
    EXPECT_LT(std::abs(follow.y - 0.5 * h), 0.2 * h) << "frame " << f << ": the crowd's centre at y " << follow.y;
    // The scenario camera sees the group off to the side.
    EXPECT_GT(std::abs(fixed.x - 0.5 * w), 0.15 * w) << "frame " << f << ": the crowd's centre at x " << fixed.x;
  }
  std::filesystem::remove_all(dir);
}

// `throng run --render frames --routes K`: the routes K agents will walk,
// drawn on the ground in kRouteColour. The maze under a fixed camera with
// and without them: the frames differ, and nearly every differing pixel
// turned towards the routes' colour.
// The first frame of `throng run SCENARIO --render frames` (320 x 180, a
// fixed camera, one simulated second) with `extra` options, in dir/name.
Image first_run_frame(const std::string& dir, const std::string& name, const std::string& scenario,
                      const std::string& extra) {
  const std::string out_dir = dir + "/" + name;
  std::string out;
  const int code = run_throng("--backend cpu --threads 2 run " + scenario +
                                  " --seconds 1 --render frames --width 320 --height 180 --fps 1 --camera fixed "
                                  "--no-trajectories --quiet " +
                                  extra + " --out '" + out_dir + "'",
                              out);
  EXPECT_EQ(code, 0) << out;
  return read_png(out_dir + "/frame_00000.png");
}

TEST(ThrongRunRoutes, DrawsTheRoutesOfASampleOfAgents) {
  const std::string dir = temp_dir("routes");
  const Image plain = first_run_frame(dir, "plain", "maze", ""),
              routed = first_run_frame(dir, "routes", "maze", "--routes 12");
  const testing::OverlayPixels o = testing::overlay_pixels(routed, plain, kRouteColour);
  std::printf("  %lld pixels differ, %lld of them towards the routes' colour\n", static_cast<long long>(o.differing),
              static_cast<long long>(o.towards));
  EXPECT_GT(o.towards, 100);
  EXPECT_GT(o.towards, o.differing * 9 / 10);
  std::string out;
  EXPECT_NE(run_throng("run maze --routes 3 --seconds 1 --no-trajectories --quiet --out '" + dir + "/x'", out), 0);
  EXPECT_NE(out.find("--routes: needs --render"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

// `throng run --render frames --field-lines M`: the navigation fields'
// lines of equal walking distance, M m apart, drawn on the ground in
// kFieldColour. The crossing (planning: field) with and without them.
TEST(ThrongRunRoutes, DrawsTheFieldsLinesOfEqualDistance) {
  const std::string dir = temp_dir("field_lines");
  const Image plain = first_run_frame(dir, "plain", "crossing --agents 40", ""),
              lined = first_run_frame(dir, "lines", "crossing --agents 40", "--field-lines 5");
  const testing::OverlayPixels o = testing::overlay_pixels(lined, plain, kFieldColour);
  std::printf("  %lld pixels differ, %lld of them towards the field lines' colour\n",
              static_cast<long long>(o.differing), static_cast<long long>(o.towards));
  EXPECT_GT(o.towards, 100);
  EXPECT_GT(o.towards, o.differing * 9 / 10);
  std::string out;
  EXPECT_NE(run_throng("run crossing --field-lines 0 --render frames --seconds 1 --quiet --out '" + dir + "/x'", out),
            0);
  EXPECT_NE(out.find("--field-lines"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace throng::render
