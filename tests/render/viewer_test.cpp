// `throng view` in a real window on a virtual X server (Xvfb, started here
// on a free display), quitting by itself after N frames with a screenshot.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "render/image.h"
#include "render/renderer.h"
#include "tests/render/overlay_pixels.h"
#include "tests/shared_data.h"

extern char** environ;

namespace throng::render {
namespace {

// An Xvfb server on a display it picks (-displayfd), ended with the object.
class VirtualDisplay {
 public:
  VirtualDisplay() {
    int fds[2];
    if (pipe(fds) != 0) return;
    const std::string fd = std::to_string(fds[1]);
    std::vector<std::string> args = {"Xvfb",        "-displayfd", fd,    "-screen", "0",
                                     "1024x768x24", "-nolisten",  "tcp", "-noreset"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    pid_t pid = -1;
    const int rc = posix_spawnp(&pid, "Xvfb", &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    if (rc != 0) {
      close(fds[0]);
      return;
    }
    pid_ = pid;
    // Xvfb writes the display number once it accepts connections.
    pollfd p{fds[0], POLLIN, 0};
    std::string number;
    while (poll(&p, 1, 30000) > 0) {
      char c = 0;
      if (read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    close(fds[0]);
    if (!number.empty()) display_ = ":" + number;
  }
  ~VirtualDisplay() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      int status = 0;
      waitpid(pid_, &status, 0);
    }
  }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

// Colours (RGB) in a picture: a real scene has many, a cleared one a few.
std::size_t distinct_colours(const Image& im) {
  std::set<std::uint32_t> colours;
  for (std::size_t i = 0; i < im.rgba.size(); i += 4)
    colours.insert(static_cast<std::uint32_t>(im.rgba[i]) << 16 | static_cast<std::uint32_t>(im.rgba[i + 1]) << 8 |
                   im.rgba[i + 2]);
  return colours.size();
}

// Pixels that differ between a picture with joint-LOD colours (--lod-colours)
// and the same with clothing colours (the default): those of characters, as
// everything else (sky, ground, obstacles) is drawn the same in both.
std::int64_t character_pixels(const Image& lod, const Image& clothes) {
  const ImageDifference d = compare_images(lod, clothes);
  return std::llround(d.fraction_differing * static_cast<double>(lod.width) * static_cast<double>(lod.height));
}

int run(const std::string& command, std::string& output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[512];
  while (fgets(buf, sizeof buf, pipe) != nullptr) output += buf;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Viewer, RendersUnderXvfbAndQuitsWithAScreenshot) {
  VirtualDisplay x;
  ASSERT_FALSE(x.display().empty()) << "Xvfb did not start: install it (package xvfb, bash scripts/setup.sh --deps)";
  const std::string shot = (std::filesystem::temp_directory_path() / "throng_viewer_test.png").string();
  std::filesystem::remove(shot);
  std::string out;
  const int code = run(
      "DISPLAY=" + x.display() + " " + THRONG_EXE +
          " --threads 2 view bottleneck --agents 150 --bins --frames 12 --width 480 --height 270 --screenshot " + shot,
      out);
  ASSERT_EQ(code, 0) << out;
  EXPECT_NE(out.find("12 frames"), std::string::npos) << out;
  ASSERT_TRUE(std::filesystem::exists(shot)) << out;
  const Image im = read_png(shot);
  EXPECT_EQ(im.width, 480);
  EXPECT_EQ(im.height, 270);
  // A real picture: the panel, the ground, characters in their clothes.
  EXPECT_GT(distinct_colours(im), 200u);
}

// The viewer animates a scenario's own motion-capture clips (CMU subject
// 16's walk and jog, 43 joints) and draws them.
TEST(Viewer, HeadlessDrawsAScenariosOwnMotionCaptureClips) {
  THRONG_NEED_SHARED_BVH(bvh);
  const auto dir = std::filesystem::temp_directory_path() / "throng_viewer_cmu";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto scenario = dir / "cmu.yaml";
  FILE* f = std::fopen(scenario.string().c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fprintf(f,
               "name: cmu\ngroups:\n  - {count: 40, spawn: {ring: {center: [0, 0], spacing: 1.0}}, goal: {mirror: "
               "[0, 0]}}\ncamera: {position: [-9, -9, 4], target: [0, 0, 0.8], fov_degrees: 40}\n"
               "motion: [%s, %s]\n",
               (*bvh / "cmu_16_15_walk_daz.bvh").string().c_str(),
               (*bvh / "cmu_16_36_run_jog_daz.bvh").string().c_str());
  std::fclose(f);
  std::string out;
  const std::string command = std::string(THRONG_EXE) + " view " + scenario.string() +
                              " --headless --render frames --frames 3 --width 160 --height 90 --out ";
  ASSERT_EQ(run(command + dir.string() + " --lod-colours", out), 0) << out;
  // The clips' cycles, found as the viewer loads them (the default set logs none).
  EXPECT_NE(out.find("cmu_16_15_walk_daz: cycle of"), std::string::npos) << out;
  EXPECT_NE(out.find("cmu_16_36_run_jog_daz: cycle of"), std::string::npos) << out;
  out.clear();
  ASSERT_EQ(run(command + (dir / "clothes").string(), out), 0) << out;
  const Image im = read_png((dir / "frame_00002.png").string());
  const Image clothes = read_png((dir / "clothes" / "frame_00002.png").string());
  ASSERT_EQ(clothes.width, im.width);
  EXPECT_GT(character_pixels(im, clothes), im.width * im.height / 100);
  std::filesystem::remove_all(dir);
}

// Without a window: a scenario simulated and animated, written as PNG
// frames under its camera set in motion; the formation of throng animate
// as a screenshot. Each is drawn twice, in joint-LOD colours and in
// clothing colours, so the pixels that differ are the characters': a
// picture of the ground alone, or a cleared one, fails.
TEST(Viewer, HeadlessWritesFramesOfAScenarioAndScreenshotsOfTheFormation) {
  const auto dir = std::filesystem::temp_directory_path() / "throng_viewer_headless";
  std::filesystem::remove_all(dir);
  std::string out;
  const std::string frames =
      std::string(THRONG_EXE) +
      " --threads 2 view corridor --agents 120 --headless --render frames --frames 3 --width 160 --height 90 "
      "--camera flyover --out ";
  ASSERT_EQ(run(frames + dir.string() + " --lod-colours", out), 0) << out;
  EXPECT_NE(out.find("3 frames"), std::string::npos) << out;
  out.clear();
  ASSERT_EQ(run(frames + (dir / "clothes").string(), out), 0) << out;
  for (int f = 0; f < 3; ++f) {
    const std::string name = "frame_0000" + std::to_string(f) + ".png";
    const Image im = read_png((dir / name).string());
    EXPECT_EQ(im.width, 160);
    EXPECT_EQ(im.height, 90);
    EXPECT_GT(distinct_colours(im), 100u) << name;  // sky, lit ground, grid, characters
    const Image clothes = read_png((dir / "clothes" / name).string());
    ASSERT_EQ(clothes.width, im.width);
    ASSERT_EQ(clothes.height, im.height);
    // 120 characters on a 100 m corridor seen whole: a few pixels each
    // (about 3% of the picture).
    EXPECT_GT(character_pixels(im, clothes), im.width * im.height / 70) << name;
  }
  const std::string shot = (dir / "formation.png").string();
  const std::string clothes_shot = (dir / "formation_clothes.png").string();
  const std::string formation =
      std::string(THRONG_EXE) +
      " view formation --layout grid --agents 50 --headless --frames 2 --width 160 --height 90 ";
  out.clear();
  ASSERT_EQ(run(formation + "--lod-colours --screenshot " + shot, out), 0) << out;
  out.clear();
  ASSERT_EQ(run(formation + "--screenshot " + clothes_shot, out), 0) << out;
  const Image im = read_png(shot);
  EXPECT_EQ(im.width, 160);
  EXPECT_EQ(im.height, 90);
  EXPECT_GT(distinct_colours(im), 100u);
  // 50 characters framed whole: about 6% of the picture is theirs.
  EXPECT_GT(character_pixels(im, read_png(clothes_shot)), im.width * im.height / 40);
  out.clear();
  EXPECT_EQ(
      run(std::string(THRONG_EXE) + " view corridor --layout grid --headless --frames 2 --screenshot " + shot, out), 1)
      << out;
  EXPECT_NE(out.find("--layout"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

TEST(Viewer, NoDisplayIsAClearError) {
  std::string out;
  const int code = run(std::string("env -u DISPLAY -u WAYLAND_DISPLAY ") + THRONG_EXE + " view --frames 1", out);
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("throng: error: cannot open a window"), std::string::npos) << out;
}

TEST(Viewer, BadOptionsAreErrors) {
  std::string out;
  int code = run(std::string(THRONG_EXE) + " view --screenshot x.png", out);
  EXPECT_NE(code, 0);
  EXPECT_EQ(code, 1) << out;  // throng::Error, not a crash
  EXPECT_NE(out.find("--frames"), std::string::npos) << out;
  out.clear();
  code = run(std::string(THRONG_EXE) + " view --lod-thresholds 10,100 --frames 1", out);
  EXPECT_NE(code, 0);
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("--lod-thresholds"), std::string::npos) << out;
  EXPECT_NE(out.find("thresholds must decrease"), std::string::npos) << out;
}

// --routes K: the routes of K agents drawn on the ground of the scene, as
// `throng run --render --routes` draws them: the maze's screenshot with and
// without them differs, every differing pixel nearer the routes' colour.
// The overlay that `extra` asks for, in a headless screenshot of
// `scenario` (320 x 180, fixed camera, first frame) against the same
// screenshot without it: over 100 pixels differ and nine in ten of them
// turned towards `colour`.
void expect_overlay_in_screenshot(const std::string& name, const std::string& scenario, const std::string& extra,
                                  glm::vec4 colour) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string view = std::string(THRONG_EXE) + " --threads 2 view " + scenario +
                           " --headless --frames 1 --width 320 --height 180 --camera fixed ";
  std::string out;
  ASSERT_EQ(run(view + "--screenshot " + (dir / "plain.png").string(), out), 0) << out;
  ASSERT_EQ(run(view + extra + " --screenshot " + (dir / "overlay.png").string(), out), 0) << out;
  const Image plain = read_png((dir / "plain.png").string()), with = read_png((dir / "overlay.png").string());
  ASSERT_EQ(plain.width, with.width);
  const testing::OverlayPixels o = testing::overlay_pixels(with, plain, colour);
  EXPECT_GT(o.towards, 100) << o.differing;
  EXPECT_GT(o.towards, o.differing * 9 / 10);
  std::filesystem::remove_all(dir);
}

TEST(Viewer, HeadlessDrawsTheRoutesOfASampleOfAgents) {
  expect_overlay_in_screenshot("throng_viewer_routes", "maze", "--routes 12", kRouteColour);
  std::string out;
  EXPECT_NE(run(std::string(THRONG_EXE) + " view formation --headless --frames 1 --routes 3 --screenshot " +
                    (std::filesystem::temp_directory_path() / "throng_viewer_no_routes.png").string(),
                out),
            0);
  EXPECT_NE(out.find("--routes is for scenarios"), std::string::npos) << out;
}

// --field-lines M: the navigation fields' lines of equal walking distance,
// as `throng run --render --field-lines` draws them (the crossing's fields).
TEST(Viewer, HeadlessDrawsTheFieldsLinesOfEqualDistance) {
  expect_overlay_in_screenshot("throng_viewer_field_lines", "crossing --agents 40", "--field-lines 5", kFieldColour);
}

}  // namespace
}  // namespace throng::render
