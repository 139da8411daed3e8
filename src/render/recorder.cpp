#include "render/recorder.h"

#include <fmt/format.h>

#include <filesystem>

#include "core/error.h"
#include "render/framebuffer.h"
#include "render/video.h"

namespace throng::render {

const char* to_string(RecordOutput o) {
  switch (o) {
    case RecordOutput::Video: return "video";
    case RecordOutput::Frames: return "frames";
    case RecordOutput::None: return "none";
  }
  return "?";
}

RecordOutput parse_record_output(const std::string& text, const std::string& field) {
  if (text == "video") return RecordOutput::Video;
  if (text == "frames") return RecordOutput::Frames;
  throw Error(fmt::format("unknown render output '{}' (video or frames)", text), at_field(field));
}

void RecordSpec::validate() const {
  if (folder.empty() && output != RecordOutput::None) throw Error("no output folder", at_field("render.folder"));
  if (output == RecordOutput::Video) {
    VideoSpec v;
    v.path = folder + "/" + video_name;
    v.width = width;
    v.height = height;
    v.fps = fps;
    v.crf = crf;
    try {
      v.validate();
    } catch (const Error& e) {
      // Same checks, named after the recorder's fields.
      std::string field = e.location().field;
      if (field.rfind("video.", 0) == 0) field = "render." + field.substr(6);
      throw Error(e.message(), at_field(field));
    }
  } else if (width < 1 || width > 16384 || height < 1 || height > 16384) {
    throw Error(fmt::format("{}x{} is outside 1..16384", width, height), at_field("render.width"));
  }
  if (samples < 0 || samples > 16) throw Error("must be within 0..16", at_field("render.samples"));
  options.validate();
}

struct Recorder::State {
  RecordSpec spec;
  HeadlessContext context;
  OffscreenTarget target;
  Renderer renderer;
  std::unique_ptr<VideoWriter> video;
  Image frame;
  Index frames = 0;
  State(const RecordSpec& s, const CrowdRigs& rigs)
      : spec(s), context(s.context), target(s.width, s.height, s.samples), renderer(rigs) {}
};

Recorder::Recorder(const RecordSpec& spec, const JointRig& rig) : Recorder(spec, CrowdRigs{rig, {}}) {}

Recorder::Recorder(const RecordSpec& spec, const CrowdRigs& rigs) {
  spec.validate();
  std::error_code ec;
  if (spec.output != RecordOutput::None) std::filesystem::create_directories(spec.folder, ec);
  if (ec) throw Error(fmt::format("cannot create the folder: {}", ec.message()), at_field(spec.folder));
  s_ = std::make_unique<State>(spec, rigs);
  if (spec.output == RecordOutput::Video) {
    VideoSpec v;
    v.path = (std::filesystem::path(spec.folder) / spec.video_name).string();
    v.width = spec.width;
    v.height = spec.height;
    v.fps = spec.fps;
    v.crf = spec.crf;
    s_->video = std::make_unique<VideoWriter>(v);
  }
}

Recorder::~Recorder() = default;

Renderer& Recorder::renderer() { return s_->renderer; }
const HeadlessContext& Recorder::context() const { return s_->context; }
const Image& Recorder::last_frame() const { return s_->frame; }
Index Recorder::frames() const { return s_->frames; }

void show_world(Renderer& renderer, const sim::World& world, const ObstacleStyle& style) {
  renderer.set_obstacles(world.polygons(), world.circles(), style);
  if (!world.has_walkable()) return;
  const sim::Ring& ring = world.walkable().outer;
  const Periodic& periodic = world.periodic();
  if (!periodic.wraps()) {
    MapPolyline boundary(ring.begin(), ring.end());
    if (!boundary.empty()) boundary.push_back(boundary.front());
    renderer.set_paths({boundary});
    return;
  }
  // A periodic area's sides at its seams are no walls: only the others are drawn.
  std::vector<MapPolyline> walls;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const glm::vec2 a = ring[k], b = ring[(k + 1) % ring.size()];
    const bool seam = (periodic.period.x > 0.0f && a.x == b.x) || (periodic.period.y > 0.0f && a.y == b.y);
    if (!seam) walls.push_back({a, b});
  }
  renderer.set_paths(walls);
}

void Recorder::set_world(const sim::World& world, const ObstacleStyle& style) {
  s_->context.make_current();
  show_world(s_->renderer, world, style);
}

void Recorder::set_routes(const std::vector<MapPolyline>& routes) {
  s_->context.make_current();
  s_->renderer.set_routes(routes);
}

void Recorder::set_field_lines(const std::vector<MapPolyline>& lines) {
  s_->context.make_current();
  s_->renderer.set_field_lines(lines);
}

RenderStats Recorder::add_frame(const Camera& camera, const CharacterPoses& poses) {
  return add_frame(camera, poses, s_->spec.options);
}

RenderStats Recorder::add_frame(const Camera& camera, const CharacterPoses& poses, const RenderOptions& options) {
  State& s = *s_;
  s.context.make_current();
  Camera c = camera;
  c.width = s.spec.width;
  c.height = s.spec.height;
  s.target.bind();
  const RenderStats stats = s.renderer.render(c, poses, options);
  s.target.read_into(s.frame);
  if (s.video) {
    s.video->write(s.frame);
  } else if (s.spec.output == RecordOutput::Frames) {
    const auto path = std::filesystem::path(s.spec.folder) / fmt::format("{}{:05d}.png", s.spec.frame_prefix, s.frames);
    write_png(path.string(), s.frame);
  }
  ++s.frames;
  return stats;
}

std::string Recorder::finish() {
  if (s_->video) {
    s_->video->finish();
    return s_->video->spec().path;
  }
  return s_->spec.output == RecordOutput::Frames ? s_->spec.folder : std::string();
}

}  // namespace throng::render
