// throng view [SCENARIO|NAME]: the interactive viewer (render/viewer.h), or
// with --headless a video or screenshot of the same, on characters animated
// by the locomotion stage: a scenario run by the crowd simulation (a file or
// a built-in, as `throng run` takes them), or the formation of `throng
// animate` (`formation`, or an animate file).
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
#include "io/routes_output.h"
#include "io/scenario_yaml.h"

#if defined(THRONG_HAVE_RENDER)
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <optional>

#include "app/sim_locomotion.h"
#include "core/ground.h"
#include "render/renderer.h"
#include "render/viewer.h"
#include "sim/simulation.h"
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
  void advance(double dt, const Camera& camera) override {
    crowd_.advance(static_cast<float>(dt), crowd_.spec().lod ? &camera : nullptr);
  }
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

// A scenario run by the crowd simulation, one step of dt whenever the
// shown time passes it, agents interpolated between steps and animated by
// the locomotion stage as `throng run` animates them (app/sim_locomotion.h).
class SimulationScene final : public render::ViewerScene {
 public:
  SimulationScene(const io::LoadedScenario& loaded, const std::vector<float>& lod_thresholds, Index routes,
                  float field_lines)
      : sim_(io::build_simulation(loaded)),
        locomotion_(*sim_, locomotion_options(loaded, lod_thresholds)),
        camera_(scenario_camera(*sim_)) {
    // Where `routes` agents will walk, as `throng route` traces them.
    if (routes > 0)
      for (io::AgentRoute& r : io::sample_routes(*sim_, routes)) routes_.push_back(std::move(r.points));
    if (field_lines > 0.0f) field_lines_ = io::field_lines(*sim_, field_lines);
    max_steps_ = sim_->spec().step_count();
    sim::Aabb box = sim_->world().bounds();
    for (const glm::vec2& p : sim_->positions()) box.add(p);
    if (box.empty()) box.add(glm::vec2(0.0f));
    centre_ = world_from_ground(0.5f * (box.min + box.max));
    extent_ = std::max(5.0f, 0.5f * glm::length(box.max - box.min));
  }
  std::string title() const override { return "throng: " + sim_->spec().name; }
  anim::CrowdAnimator& animator() override { return locomotion_.animator(); }
  std::optional<Camera> camera() const override { return camera_; }
  float bin_size() const override { return sim_->bins().cell_size(); }
  glm::vec3 centre() const override { return centre_; }
  float extent() const override { return extent_; }
  std::string status() const override {
    return fmt::format("{}: step {}, {:.1f} s simulated, arrived {}/{}{}", sim_->spec().name, sim_->steps_done(),
                       sim_->time(), sim_->arrived_count(), sim_->agent_count(), finished_ ? " (ended)" : "");
  }
  render::CharacterPoses poses() override { return render::poses_of(locomotion_.animator(), sim_->crowd()); }
  void decorate(render::Renderer& renderer) const override {
    render::show_world(renderer, sim_->world());
    renderer.set_routes(routes_);
    renderer.set_field_lines(field_lines_);
  }
  void advance(double dt, const Camera& camera) override {
    const double step = static_cast<double>(sim_->spec().dt);
    shown_ += dt;
    while (!finished_ && sim_->time() < shown_) {
      locomotion_.remember(*sim_);
      sim_->step();
      finished_ = sim_->steps_done() >= max_steps_ || (sim_->spec().stop_when_arrived && sim_->all_arrived());
    }
    if (finished_) shown_ = std::min(shown_, sim_->time());
    const double alpha = std::clamp(1.0 - (sim_->time() - shown_) / step, 0.0, 1.0);
    locomotion_.animate(*sim_, static_cast<float>(alpha), static_cast<float>(dt), &camera, !finished_);
  }

 private:
  static SimulationLocomotionOptions locomotion_options(const io::LoadedScenario& loaded,
                                                        const std::vector<float>& thresholds) {
    SimulationLocomotionOptions o;
    o.space = load_scenario_motion(loaded);
    o.lod_thresholds = thresholds;
    o.skating_agents = 0;  // measured by throng run, not here
    return o;
  }

  std::unique_ptr<sim::Simulation> sim_;
  SimulationLocomotion locomotion_;
  Camera camera_;
  std::vector<render::MapPolyline> routes_, field_lines_;
  std::int64_t max_steps_ = 0;
  bool finished_ = false;
  double shown_ = 0.0;  // simulated seconds on screen
  glm::vec3 centre_{0.0f};
  float extent_ = 10.0f;
};

// An animate scenario (a formation) rather than a simulation scenario: the
// built-in `formation`, or a file whose top level has a `formation` key.
bool is_formation(const std::string& what) {
  for (const std::string& name : io::builtin_animate_specs())
    if (what == name) return true;
  std::ifstream in(what);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("formation:", 0) == 0) return true;
  return false;
}

// The options of `throng view` (the viewer's own, and the offscreen recording's).
struct ViewArgs {
  render::ViewerOptions o;
  std::string scenario = "circle";
  std::string layout;
  std::string mode = "skinned";
  Index agents = 0;
  std::vector<float> thresholds;
  bool headless = false;
  std::string render_output;
  std::string out_dir = "out/view";
  double fps = 30.0;
  std::string camera_kind;  // empty: the scenario's camera.motion, else orbit
  float camera_period = 0.0f;
  Index routes = 0;          // agents whose routes are drawn (scenarios)
  float field_lines = 0.0f;  // m between the navigation fields' drawn lines (scenarios); 0: none
};

// Adds the command's options to cmd, bound to a.
void add_view_options(CLI::App* cmd, ViewArgs& a) {
  render::ViewerOptions& o = a.o;
  std::string names;
  for (const std::string& n : io::builtin_scenario_names()) names += n + ", ";
  cmd->add_option("scenario", a.scenario,
                  "Scenario file or built-in (" + names + "formation: the locomotion formation of throng animate)")
      ->capture_default_str();
  cmd->add_option("--agents", a.agents, "How many agents (groups keep their proportions)")
      ->check(between(1, static_cast<double>(Index{1} << 24)));
  cmd->add_option("--layout", a.layout, "For formation: ring (walking round rings) or grid")
      ->check(CLI::IsMember({"ring", "grid"}));
  cmd->add_option("--routes", a.routes,
                  "Draw on the ground the routes of this many agents (spread over the crowd), as `throng route` "
                  "traces them")
      ->check(at_least(1));
  cmd->add_option("--field-lines", a.field_lines,
                  "Draw on the ground the navigation fields' lines of equal walking distance, this many metres apart "
                  "(planning: field or quickest)")
      ->check(greater_than(0));
  cmd->add_option("--mode", a.mode, "Render mode: skinned (the mannequin) or joints (a sphere per bone)")
      ->check(CLI::IsMember({"skinned", "joints"}));
  cmd->add_flag("--lod-colours", o.lod_colours, "Joint-LOD level colours instead of clothes, a debug view (L toggles)");
  cmd->add_option("--width", o.width, "Window width, pixels")->check(between(16, 7680));
  cmd->add_option("--height", o.height, "Window height, pixels")->check(between(16, 4320));
  cmd->add_option("--frames", o.frames, "Quit after this many frames, at 1/30 s each (0 = when closed)");
  cmd->add_option("--screenshot", o.screenshot, "Save the last frame as PNG (with --frames)");
  cmd->add_option("--speed", o.speed, "Animation speed factor");
  cmd->add_flag("--paused", o.paused, "Start paused (space toggles, period steps)");
  cmd->add_flag("!--no-panel", o.panel, "Hide the ImGui panel");
  cmd->add_flag("--bins", o.bins, "Show agents per cell (the simulation's bins; 4 m for the formation) as a heat map");
  cmd->add_flag("--headless", a.headless,
                "No window: render --frames frames offscreen (EGL), for videos and screenshots");
  cmd->add_option("--render", a.render_output,
                  "With --headless: write DIR/crowd.mp4 (video) or DIR/frame_NNNNN.png (frames)")
      ->check(CLI::IsMember({"video", "frames"}));
  cmd->add_option("--out", a.out_dir, "Folder for --render (default out/view)");
  cmd->add_option("--fps", a.fps, "With --headless: frames per second of the video")->check(between(1, 240));
  cmd->add_option("--camera", a.camera_kind,
                  "With --headless: the scenario's camera kept fixed, orbiting or flying over (default: the scenario's "
                  "camera.motion, else orbit)")
      ->check(CLI::IsMember({"fixed", "orbit", "flyover"}));
  cmd->add_option("--camera-period", a.camera_period,
                  "With --headless: seconds per orbit or fly-over (default: the scenario's, else 60)")
      ->check(greater_than(0));
  cmd->add_option("--lod-thresholds", a.thresholds,
                  "Joint-LOD thresholds in square pixels, decreasing (default 1000,30)")
      ->delimiter(',');
}

// Refuses combinations that would do nothing (recording options in a
// window, a screenshot without --frames, ...); sets a.o.mode from --mode.
void check_view_args(const CLI::App& cmd, ViewArgs& a) {
  render::ViewerOptions& o = a.o;
  // Options of the offscreen recording are refused in a window, not ignored.
  refuse_unless(cmd, a.headless, {"--fps", "--camera", "--camera-period"},
                "--headless (with --render video|frames or --screenshot)");
  refuse_unless(cmd, !a.render_output.empty(), {"--out"}, "--render video|frames");
  if (!o.screenshot.empty() && o.frames == 0)
    throw Error("--screenshot needs --frames N (the frame to save)", at_field("--screenshot"));
  if (a.headless && o.frames == 0) throw Error("--headless needs --frames N", at_field("--frames"));
  check_lod_thresholds(a.thresholds, "--lod-thresholds");
  if (!a.render_output.empty() && !a.headless) throw Error("--render needs --headless", at_field("--render"));
  if (a.headless && a.render_output.empty() && o.screenshot.empty())
    throw Error("--headless writes nothing without --render or --screenshot", at_field("--headless"));
  o.mode = render::parse_render_mode(a.mode, "--mode");
}

// The scene: the formation (--agents, --layout, --lod-thresholds applied) or
// a simulation scenario (--agents), whose camera motion and period fill in
// --camera and --camera-period when not given. Global options are applied
// after loading, so a bad name or file fails before any backend talk.
std::unique_ptr<render::ViewerScene> make_scene(ViewArgs& a, const GlobalOptions& g) {
  if (is_formation(a.scenario)) {
    std::filesystem::path folder;
    io::AnimateSpec spec = load_animate_spec(a.scenario, folder);
    if (a.agents > 0) spec.characters = a.agents;
    if (!a.layout.empty())
      spec.shape = a.layout == "grid" ? io::AnimateSpec::Shape::Grid : io::AnimateSpec::Shape::Circle;
    if (!a.thresholds.empty()) spec.lod_thresholds = a.thresholds;
    apply_global_options(g);
    if (a.routes > 0) throw Error("--routes is for scenarios, not the formation", at_field("--routes"));
    if (a.field_lines > 0.0f)
      throw Error("--field-lines is for scenarios, not the formation", at_field("--field-lines"));
    return std::make_unique<FormationScene>(std::move(spec), folder);
  }
  if (!a.layout.empty()) throw Error("--layout is for the formation", at_field("--layout"));
  io::LoadedScenario loaded = io::load_scenario(a.scenario);
  if (a.agents > 0) sim::scale_agent_counts(loaded.spec, a.agents);
  apply_global_options(g);
  std::unique_ptr<render::ViewerScene> scene =
      std::make_unique<SimulationScene>(loaded, a.thresholds, a.routes, a.field_lines);
  if (a.camera_kind.empty()) a.camera_kind = loaded.spec.camera_motion;
  if (!(a.camera_period > 0.0f)) a.camera_period = loaded.spec.camera_period_s;
  return scene;
}

// --headless: --frames frames offscreen into the video or frames under
// --out and/or the screenshot; says on stdout what it wrote.
void record_headless(render::ViewerScene& scene, const ViewArgs& a) {
  const render::ViewerOptions& o = a.o;
  render::HeadlessViewOptions h;
  h.record.output =
      a.render_output.empty() ? render::RecordOutput::None : render::parse_record_output(a.render_output, "--render");
  h.record.folder = a.out_dir;
  h.record.width = o.width;
  h.record.height = o.height;
  h.record.fps = a.fps;
  h.record.options.mode = o.mode;
  h.record.options.lod_colours = o.lod_colours;
  h.record.options.bins = false;
  h.frames = o.frames;
  h.screenshot = o.screenshot;
  h.speed = o.speed;
  h.camera_kind = render::parse_camera_kind(a.camera_kind.empty() ? "orbit" : a.camera_kind, "--camera");
  h.camera_period = a.camera_period > 0.0f ? a.camera_period : 60.0f;
  const render::HeadlessViewResult r = render::record_view(scene, h);
  if (!r.output.empty()) std::printf("view: %lld frames in %s\n", static_cast<long long>(r.frames), r.output.c_str());
  if (!h.screenshot.empty()) std::printf("view: screenshot %s\n", h.screenshot.c_str());
}

}  // namespace
#endif

void add_view_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("view", "Open the viewer: the crowd in a window, orbit/pan/zoom, LOD panel");
#if defined(THRONG_HAVE_RENDER)
  static ViewArgs a;
  add_view_options(cmd, a);
  cmd->callback([&g, cmd] {
    check_view_args(*cmd, a);
    // A bad name or file fails before any window opens.
    const std::unique_ptr<render::ViewerScene> scene = make_scene(a, g);
    if (a.headless) {
      record_headless(*scene, a);
      return;
    }
    const render::ViewerResult r = render::run_viewer(*scene, a.o);
    if (!a.o.screenshot.empty()) spdlog::info("view: {} frames, screenshot {}", r.frames, a.o.screenshot);
  });
#else
  cmd->callback([&g] {
    apply_global_options(g);
    throw Error("this build has no renderer (configured with -DTHRONG_RENDER=OFF)");
  });
#endif
}

}  // namespace throng::app
