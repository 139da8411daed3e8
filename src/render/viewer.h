// The interactive viewer: a GLFW window with the renderer, a camera you
// steer with the mouse, and a Dear ImGui panel. The camera that draws is
// the camera the joint-LOD stage measures pixels with: every frame the
// scene is animated (anim::CrowdAnimator: locomotion, LOD, cache, pose) for
// the camera about to draw it.
//
// Mouse: left drag orbits, right or middle drag pans, wheel zooms.
// Keys: space pauses, period steps one frame, + and - change the speed,
// L toggles LOD colours, M switches joints / skinned, Escape or Q quits.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "render/camera_path.h"
#include "render/recorder.h"
#include "render/scene.h"

namespace throng::anim {
class CrowdAnimator;
}

namespace throng::render {

class Renderer;

// What the viewer shows: characters animated by the locomotion stage and
// moved by whatever drives them (a formation, the crowd simulation).
class ViewerScene {
 public:
  virtual ~ViewerScene() = default;
  virtual std::string title() const = 0;
  // The characters' animator: poses, LOD levels and thresholds, stats.
  virtual anim::CrowdAnimator& animator() = 0;
  // Moves the scene on by dt seconds and animates it for `camera` (dt = 0
  // while paused: the pose is redone for a camera that moved).
  virtual void advance(double dt, const Camera& camera) = 0;
  // A ground disc (world, y = 0) holding the scene, to frame it.
  virtual glm::vec3 centre() const = 0;
  virtual float extent() const = 0;
  // What to draw after advance(): by default the animator's poses.
  virtual CharacterPoses poses();
  // The scene's own camera (a scenario's), if it has one: the viewer starts
  // there and headless views set it in motion (animate_camera).
  virtual std::optional<Camera> camera() const { return std::nullopt; }
  // Side of the cells of the agents-per-cell overlay (the simulation's bins).
  virtual float bin_size() const { return 4.0f; }
  // Static parts (obstacles, paths), given to the renderer once.
  virtual void decorate(Renderer& renderer) const {}
  // Extra lines for the panel (simulation time, agents arrived...).
  virtual std::string status() const { return {}; }
};

struct ViewerOptions {
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
  RenderMode mode = RenderMode::Skinned;
  bool lod_colours = false;  // joint-LOD level colours instead of clothes (a debug view)
  void validate() const;     // Error naming the option ("--width")
};

struct ViewerResult {
  Index frames = 0;
  double seconds_shown = 0.0;  // animation time reached
  std::string gl;              // renderer and version of the window's context
};

// Opens the window and runs until closed or options.frames are drawn.
// Throws Error when there is no display or no OpenGL 4.3 context.
ViewerResult run_viewer(ViewerScene& scene, const ViewerOptions& options);

// The same scene without a window (EGL, no display needed): `frames`
// frames of 1/record.fps seconds each, written as the RecordSpec says (a
// video, PNG frames, or nothing), and the last frame as a PNG when
// `screenshot` is given. The camera: `camera` when given, else the scene's
// camera set in motion (camera_kind, one turn or pass per camera_period
// seconds), else an orbit framing the scene.
struct HeadlessViewOptions {
  RecordSpec record;  // output, folder, size, fps; its options: mode, colours
  Index frames = 90;
  std::string screenshot;
  std::optional<CameraPath> camera;
  CameraPath::Kind camera_kind = CameraPath::Kind::Orbit;
  float camera_period = 60.0f;
  double speed = 1.0;  // animation seconds per video second
  void validate() const;
};
struct HeadlessViewResult {
  Index frames = 0;
  std::string output;  // the video or frames folder ("" for none)
  RenderStats last;
};
HeadlessViewResult record_view(ViewerScene& scene, const HeadlessViewOptions& options);

}  // namespace throng::render
