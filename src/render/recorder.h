// Headless output in one object: an EGL context, an offscreen target, the
// renderer, and either an MP4 (ffmpeg) or numbered PNG frames in a folder.
// What `throng run ... --render video|frames` drives once per frame.
//
//   Recorder rec({.output = RecordOutput::Video, .folder = "out"}, make_crowd_rigs(skeleton));
//   rec.set_world(sim.world());                  // obstacles, once
//   for (...) rec.add_frame(path.at(t), poses_of(animator));   // spec.options: mode, colours...
//   std::string file = rec.finish();             // "out/crowd.mp4"
#pragma once

#include <memory>
#include <string>

#include "render/headless.h"
#include "render/image.h"
#include "render/renderer.h"
#include "sim/world.h"

namespace throng::render {

// Video: FOLDER/crowd.mp4; Frames: FOLDER/frame_00000.png, ...; None:
// nothing written (last_frame() keeps each picture).
enum class RecordOutput : std::uint8_t { Video, Frames, None };
const char* to_string(RecordOutput o);
RecordOutput parse_record_output(const std::string& text, const std::string& field);  // video | frames

struct RecordSpec {
  RecordOutput output = RecordOutput::Video;
  std::string folder = ".";              // created when missing
  std::string video_name = "crowd.mp4";  // Video
  std::string frame_prefix = "frame_";   // Frames: frame_00000.png, ...
  std::int32_t width = 960;
  std::int32_t height = 540;
  double fps = 30.0;
  std::int32_t samples = 4;  // multisampling
  std::int32_t crf = 23;
  HeadlessOptions context;
  RenderOptions options;  // how frames look (mode, LOD colours, grid...) unless add_frame is given others
  void validate() const;  // Error naming the field ("render.width")
};

// The simulation's world on a renderer: obstacles (polygons with holes,
// circles) extruded, and the walkable area's outline as a path line.
void show_world(Renderer& renderer, const sim::World& world, const ObstacleStyle& style = {});

class Recorder {
 public:
  Recorder(const RecordSpec& spec, const CrowdRigs& rigs);
  Recorder(const RecordSpec& spec, const JointRig& rig);  // joint mode only
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  Renderer& renderer();
  const HeadlessContext& context() const;
  // The simulation's world (show_world).
  void set_world(const sim::World& world, const ObstacleStyle& style = {});
  // Routes of agents drawn on the ground (Renderer::set_routes).
  void set_routes(const std::vector<MapPolyline>& routes);
  // Lines of equal walking distance of the navigation fields (Renderer::set_field_lines).
  void set_field_lines(const std::vector<MapPolyline>& lines);
  // Renders one frame with `camera` (its viewport is set to the spec's
  // size) and appends it. The picture stays available in last_frame().
  RenderStats add_frame(const Camera& camera, const CharacterPoses& poses);  // spec.options
  RenderStats add_frame(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options);
  const Image& last_frame() const;
  Index frames() const;
  // Ends the video (or nothing for frames) and returns the file or folder ("" for None).
  std::string finish();

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace throng::render
