// throng view: the interactive viewer (render/viewer.h).
#include <spdlog/spdlog.h>

#include <string>
#include <vector>

#include "app/commands.h"
#include "core/error.h"

#if defined(THRONG_HAVE_RENDER)
#include "render/viewer.h"
#endif

namespace throng::app {

void add_view_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("view", "Open the viewer: the crowd in a window, orbit/pan/zoom, LOD panel");
#if defined(THRONG_HAVE_RENDER)
  static render::ViewerOptions o;
  static std::string layout = "ring";
  static Index agents = 400;
  cmd->add_option("--agents", agents, "Characters in the demo crowd")->check(CLI::Range(Index{0}, Index{1} << 24));
  cmd->add_option("--layout", layout, "Demo crowd layout: ring (walking round rings) or grid")->check(CLI::IsMember({"ring", "grid"}));
  cmd->add_option("--seed", o.crowd.seed, "Seed of the demo crowd");
  cmd->add_option("--width", o.width, "Window width, pixels");
  cmd->add_option("--height", o.height, "Window height, pixels");
  cmd->add_option("--frames", o.frames, "Quit after this many frames, at 1/30 s each (0 = when closed)");
  cmd->add_option("--screenshot", o.screenshot, "Save the last frame as PNG (with --frames)");
  cmd->add_option("--speed", o.speed, "Animation speed factor");
  cmd->add_flag("--paused", o.paused, "Start paused (space toggles, period steps)");
  cmd->add_flag("!--no-panel", o.panel, "Hide the ImGui panel");
  cmd->add_flag("--bins", o.bins, "Show agents per 4 m cell as a heat map");
  cmd->add_option("--lod-thresholds", o.lod_thresholds, "Joint-LOD thresholds in square pixels, decreasing (default 1000,30)")
      ->delimiter(',');
  cmd->callback([&g] {
    apply_global_options(g);
    o.crowd.characters = agents;
    o.crowd.layout = render::parse_demo_layout(layout, "--layout");
    if (!o.screenshot.empty() && o.frames == 0) throw Error("--screenshot needs --frames N (the frame to save)", at_field("--screenshot"));
    const render::ViewerResult r = render::run_viewer(o);
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
