// The interactive viewer: a GLFW window with the renderer, a camera you
// steer with the mouse, and a Dear ImGui panel. The camera that draws is
// the camera the joint-LOD stage (anim::LodJob) measures pixels with.
//
// Mouse: left drag orbits, right or middle drag pans, wheel zooms.
// Keys: space pauses, period steps one frame while paused, + and - change
// the speed, L toggles LOD colours, Escape or Q quits.
//
// Until the simulation and locomotion feed it, it shows a DemoCrowd.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/demo_crowd.h"

namespace throng::render {

struct ViewerOptions {
  DemoCrowdSpec crowd;
  std::int32_t width = 1280;
  std::int32_t height = 720;
  // Scripted runs (tests, screenshots): quit after this many frames (0 =
  // when the window closes), advancing time by 1/30 s a frame instead of
  // the wall clock, and save the last frame (panel included) as PNG.
  Index frames = 0;
  std::string screenshot;
  bool paused = false;
  double speed = 1.0;
  bool vsync = true;
  bool panel = true;
  bool bins = false;  // start with the agents-per-cell overlay on
  std::vector<float> lod_thresholds;  // empty = anim::default_lod_thresholds()
  void validate() const;  // Error naming the option ("--width")
};

struct ViewerResult {
  Index frames = 0;
  double seconds_shown = 0.0;  // animation time reached
  std::string gl;              // renderer and version of the window's context
};

// Opens the window and runs until closed or options.frames are drawn.
// Throws Error when there is no display or no OpenGL 4.3 context.
ViewerResult run_viewer(const ViewerOptions& options);

}  // namespace throng::render
