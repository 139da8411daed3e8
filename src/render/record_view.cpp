// The viewer's scene recorded without a window (render/viewer.h).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "anim/crowd_animator.h"
#include "core/error.h"
#include "render/viewer.h"

namespace throng::render {

CharacterPoses ViewerScene::poses() { return poses_of(animator()); }

void HeadlessViewOptions::validate() const {
  record.validate();
  if (frames < 1) throw Error("must be at least 1", at_field("--frames"));
  if (!(speed > 0.0 && speed <= 100.0)) throw Error("must be within (0, 100]", at_field("--speed"));
  if (!(camera_period > 0.0f) || !std::isfinite(camera_period))
    throw Error("must be positive seconds", at_field("--camera-period"));
  if (camera) camera->validate();
}

HeadlessViewResult record_view(ViewerScene& scene, const HeadlessViewOptions& options) {
  options.validate();
  anim::CrowdAnimator& animator = scene.animator();
  Recorder recorder(options.record, make_crowd_rigs(animator.blend_space().skeleton()));
  scene.decorate(recorder.renderer());
  Camera lens;
  lens.width = options.record.width;
  lens.height = options.record.height;
  lens.far_plane = std::max(1000.0f, 20.0f * scene.extent());
  CameraPath path = framing_orbit(scene.centre(), scene.extent(), lens, options.camera_period);
  if (options.camera) {
    path = *options.camera;
  } else if (const std::optional<Camera> own = scene.camera()) {
    Camera start = *own;
    start.width = lens.width;
    start.height = lens.height;
    path = animate_camera(start, options.camera_kind, options.camera_period);
  }
  const double dt = options.speed / options.record.fps;
  HeadlessViewResult result;
  auto last_report = std::chrono::steady_clock::now();
  for (Index f = 0; f < options.frames; ++f) {
    Camera camera = path.at(static_cast<double>(f) / options.record.fps);
    camera.width = lens.width;  // the camera that draws is the one LOD measures with
    camera.height = lens.height;
    scene.advance(f == 0 ? 0.0 : dt, camera);
    result.last = recorder.add_frame(camera, scene.poses());
    ++result.frames;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report > std::chrono::seconds(2)) {
      spdlog::info("frame {}/{}", f + 1, options.frames);
      last_report = now;
    }
  }
  result.output = recorder.finish();
  if (!options.screenshot.empty()) write_png(options.screenshot, recorder.last_frame());
  return result;
}

}  // namespace throng::render
