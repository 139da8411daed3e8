// throng view [SCENARIO|NAME]: the interactive viewer (render/viewer.h) on
// characters animated by the locomotion stage: a formation (`formation`, or
// an animate scenario file as `throng animate` reads it).
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/formation.h"
#include "core/error.h"

#if defined(THRONG_HAVE_RENDER)
#include "render/renderer.h"
#include "render/viewer.h"
#endif

namespace throng::app {

#if defined(THRONG_HAVE_RENDER)
namespace {

// A formation walking (rings or a grid), pillars around it, the rings as paths.
class FormationScene final : public render::ViewerScene {
 public:
  FormationScene(io::AnimateSpec spec, const std::filesystem::path& folder) : crowd_(std::move(spec), folder) {}
  std::string title() const override { return "throng: " + crowd_.spec().name; }
  anim::CrowdAnimator& animator() override { return crowd_.animator(); }
  void advance(double dt, const Camera& camera) override { crowd_.advance(static_cast<float>(dt), crowd_.spec().lod ? &camera : nullptr); }
  glm::vec3 centre() const override { return glm::vec3(0.0f); }
  float extent() const override { return crowd_.formation().extent; }
  std::string status() const override { return fmt::format("formation, {:.1f} s", crowd_.time()); }
  void decorate(render::Renderer& renderer) const override {
    const float extent = crowd_.formation().extent;
    std::vector<sim::Circle> pillars;
    for (int k = 0; k < 8; ++k) {
      const float a = 6.2831853f * static_cast<float>(k) / 8.0f;
      pillars.push_back({(extent + 4.0f) * glm::vec2(std::cos(a), std::sin(a)), 1.2f});
    }
    renderer.set_obstacles({}, pillars, render::ObstacleStyle{});
    const io::AnimateSpec& s = crowd_.spec();
    if (s.shape != io::AnimateSpec::Shape::Circle) return;
    std::vector<render::MapPolyline> rings;
    for (float r = s.radius; r <= extent + 1e-3f; r += s.ring_spacing) {
      render::MapPolyline ring;
      for (int k = 0; k <= 96; ++k) {
        const float a = 6.2831853f * static_cast<float>(k) / 96.0f;
        ring.push_back(r * glm::vec2(std::cos(a), std::sin(a)));
      }
      rings.push_back(ring);
    }
    renderer.set_paths(rings);
  }

 private:
  FormationCrowd crowd_;
};

}  // namespace
#endif

void add_view_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("view", "Open the viewer: the crowd in a window, orbit/pan/zoom, LOD panel");
#if defined(THRONG_HAVE_RENDER)
  static render::ViewerOptions o;
  static std::string scenario = "formation";
  static std::string layout;
  static std::string mode = "skinned";
  static Index agents = 0;
  static std::vector<float> thresholds;
  static bool headless = false;
  static std::string render_output;
  static std::string out_dir = "out/view";
  static double fps = 30.0;
  cmd->add_option("scenario", scenario, "Animate scenario file or built-in name (formation)");
  cmd->add_option("--agents", agents, "How many characters (overrides the scenario)")->check(CLI::Range(Index{1}, Index{1} << 24));
  cmd->add_option("--layout", layout, "Formation: ring (walking round rings) or grid (overrides the scenario)")
      ->check(CLI::IsMember({"ring", "grid"}));
  cmd->add_option("--mode", mode, "Render mode: skinned (the mannequin) or joints (a sphere per bone)")->check(CLI::IsMember({"skinned", "joints"}));
  cmd->add_flag("!--no-lod-colours", o.lod_colours, "Clothing colours instead of joint-LOD levels (L toggles)");
  cmd->add_option("--width", o.width, "Window width, pixels");
  cmd->add_option("--height", o.height, "Window height, pixels");
  cmd->add_option("--frames", o.frames, "Quit after this many frames, at 1/30 s each (0 = when closed)");
  cmd->add_option("--screenshot", o.screenshot, "Save the last frame as PNG (with --frames)");
  cmd->add_option("--speed", o.speed, "Animation speed factor");
  cmd->add_flag("--paused", o.paused, "Start paused (space toggles, period steps)");
  cmd->add_flag("!--no-panel", o.panel, "Hide the ImGui panel");
  cmd->add_flag("--bins", o.bins, "Show agents per 4 m cell as a heat map");
  cmd->add_flag("--headless", headless, "No window: render --frames frames offscreen (EGL), for videos and screenshots");
  cmd->add_option("--render", render_output, "With --headless: write DIR/crowd.mp4 (video) or DIR/frame_NNNNN.png (frames)")
      ->check(CLI::IsMember({"video", "frames"}));
  cmd->add_option("--out", out_dir, "Folder for --render (default out/view)");
  cmd->add_option("--fps", fps, "With --headless: frames per second of the video")->check(CLI::Range(1.0, 240.0));
  cmd->add_option("--lod-thresholds", thresholds, "Joint-LOD thresholds in square pixels, decreasing (default 1000,30)")->delimiter(',');
  cmd->callback([&g] {
    if (!o.screenshot.empty() && o.frames == 0) throw Error("--screenshot needs --frames N (the frame to save)", at_field("--screenshot"));
    if (headless && o.frames == 0) throw Error("--headless needs --frames N", at_field("--frames"));
    for (std::size_t i = 0; i < thresholds.size(); ++i)
      if (!(thresholds[i] > 0.0f) || !std::isfinite(thresholds[i]) || (i > 0 && !(thresholds[i] < thresholds[i - 1])))
        throw Error("thresholds must be positive and decreasing", at_field("--lod-thresholds"));
    std::filesystem::path folder;
    io::AnimateSpec spec = load_animate_spec(scenario, folder);  // a bad name fails before any window opens
    if (agents > 0) spec.characters = agents;
    if (!layout.empty()) spec.shape = layout == "grid" ? io::AnimateSpec::Shape::Grid : io::AnimateSpec::Shape::Circle;
    if (!thresholds.empty()) spec.lod_thresholds = thresholds;
    o.mode = render::parse_render_mode(mode, "--mode");
    if (!render_output.empty() && !headless) throw Error("--render needs --headless", at_field("--render"));
    apply_global_options(g);
    FormationScene scene(std::move(spec), folder);
    if (headless) {
      render::HeadlessViewOptions h;
      h.record.output = render_output.empty() ? render::RecordOutput::None : render::parse_record_output(render_output, "--render");
      h.record.folder = out_dir;
      h.record.width = o.width;
      h.record.height = o.height;
      h.record.fps = fps;
      h.record.options.mode = o.mode;
      h.record.options.lod_colours = o.lod_colours;
      h.record.options.bins = false;
      h.frames = o.frames;
      h.screenshot = o.screenshot;
      h.speed = o.speed;
      if (render_output.empty() && h.screenshot.empty()) throw Error("--headless writes nothing without --render or --screenshot", at_field("--headless"));
      const render::HeadlessViewResult r = render::record_view(scene, h);
      if (!r.output.empty()) std::printf("view: %lld frames in %s\n", static_cast<long long>(r.frames), r.output.c_str());
      if (!h.screenshot.empty()) std::printf("view: screenshot %s\n", h.screenshot.c_str());
      return;
    }
    const render::ViewerResult r = render::run_viewer(scene, o);
    if (!o.screenshot.empty()) spdlog::info("view: {} frames, screenshot {}", r.frames, o.screenshot);
  });
#else
  cmd->callback([&g] {
    apply_global_options(g);
    throw Error("this build has no renderer (configured with -DTHRONG_RENDER=OFF)");
  });
#endif
}

}  // namespace throng::app
