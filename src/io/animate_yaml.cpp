#include "io/animate_yaml.h"

#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>

#include "core/error.h"
#include "io/embedded.h"

namespace throng::io {

namespace {

Location where(const std::string& file, const YAML::Node& node, const std::string& field) {
  const YAML::Mark m = node.Mark();
  Location l;
  l.file = file;
  if (m.line >= 0) {
    l.line = m.line + 1;
    l.column = m.column + 1;
  }
  l.field = field;
  return l;
}

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field, const std::string& message) const {
    throw Error(message, where(file_, node, field));
  }

  void keys(const YAML::Node& map, const std::string& field, std::initializer_list<const char*> allowed) const {
    if (!map.IsMap()) fail(map, field, "expected a mapping of keys");
    for (const auto& kv : map) {
      const std::string key = kv.first.as<std::string>();
      bool ok = false;
      std::string list;
      for (const char* a : allowed) {
        ok = ok || key == a;
        list += (list.empty() ? "" : ", ") + std::string(a);
      }
      if (!ok) fail(kv.first, field.empty() ? key : field + "." + key, "unknown key '" + key + "' (expected one of: " + list + ")");
    }
  }

  template <class T>
  T scalar(const YAML::Node& node, const std::string& field, const char* what) const {
    if (!node.IsScalar()) fail(node, field, std::string("expected ") + what);
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail(node, field, std::string("expected ") + what + ", found '" + node.Scalar() + "'");
    }
  }

  float number(const YAML::Node& node, const std::string& field, double lo, double hi) const {
    const double v = scalar<double>(node, field, "a number");
    if (!(std::isfinite(v) && v >= lo && v <= hi))
      fail(node, field, "must be in [" + format(lo) + ", " + format(hi) + "], found " + node.Scalar());
    return static_cast<float>(v);
  }
  std::int64_t integer(const YAML::Node& node, const std::string& field, std::int64_t lo, std::int64_t hi) const {
    const auto v = scalar<std::int64_t>(node, field, "an integer");
    if (v < lo || v > hi) fail(node, field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " + node.Scalar());
    return v;
  }
  bool boolean(const YAML::Node& node, const std::string& field) const { return scalar<bool>(node, field, "true or false"); }
  std::string text(const YAML::Node& node, const std::string& field) const { return scalar<std::string>(node, field, "a string"); }
  std::string choice(const YAML::Node& node, const std::string& field, std::initializer_list<const char*> options) const {
    const std::string v = text(node, field);
    std::string list;
    for (const char* o : options) {
      if (v == o) return v;
      list += (list.empty() ? "" : ", ") + std::string(o);
    }
    fail(node, field, "unknown value '" + v + "' (expected one of: " + list + ")");
  }

  const std::string& file() const { return file_; }

 private:
  static std::string format(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  std::string file_;
};

AnimateSpec parse(const YAML::Node& root, const Reader& r) {
  AnimateSpec s;
  if (root.IsNull()) return s;
  r.keys(root, "", {"name", "characters", "formation", "speed", "scale", "motion", "mode", "duration", "fps", "seed", "camera", "lod",
                    "cache", "foot_skating", "output"});
  if (const auto n = root["name"]) s.name = r.text(n, "name");
  if (const auto n = root["characters"]) s.characters = r.integer(n, "characters", 1, 10'000'000);
  if (const auto f = root["formation"]) {
    r.keys(f, "formation", {"shape", "radius", "ring_spacing", "spacing", "direction"});
    if (const auto n = f["shape"]) s.shape = r.choice(n, "formation.shape", {"circle", "grid"}) == "circle" ? AnimateSpec::Shape::Circle : AnimateSpec::Shape::Grid;
    if (const auto n = f["radius"]) s.radius = r.number(n, "formation.radius", 0.5, 1e5);
    if (const auto n = f["ring_spacing"]) s.ring_spacing = r.number(n, "formation.ring_spacing", 0.3, 100.0);
    if (const auto n = f["spacing"]) s.spacing = r.number(n, "formation.spacing", 0.3, 100.0);
    if (const auto n = f["direction"]) s.clockwise = r.choice(n, "formation.direction", {"ccw", "cw"}) == "cw";
  }
  if (const auto sp = root["speed"]) {
    r.keys(sp, "speed", {"min", "max", "change_every"});
    if (const auto n = sp["min"]) s.speed_min = r.number(n, "speed.min", 0.0, 12.0);
    if (const auto n = sp["max"]) s.speed_max = r.number(n, "speed.max", 0.0, 12.0);
    if (const auto n = sp["change_every"]) s.change_every_s = r.number(n, "speed.change_every", 0.0, 3600.0);
    if (s.speed_min > s.speed_max) r.fail(sp, "speed", "min must not exceed max");
  }
  if (const auto sc = root["scale"]) {
    r.keys(sc, "scale", {"min", "max"});
    if (const auto n = sc["min"]) s.scale_min = r.number(n, "scale.min", 0.1, 10.0);
    if (const auto n = sc["max"]) s.scale_max = r.number(n, "scale.max", 0.1, 10.0);
    if (s.scale_min > s.scale_max) r.fail(sc, "scale", "min must not exceed max");
  }
  if (const auto m = root["motion"]) {
    if (m.IsScalar()) {
      r.choice(m, "motion", {"default"});
    } else if (m.IsSequence()) {
      if (m.size() < 1 || m.size() > 64) r.fail(m, "motion", "expected 1 to 64 clips");
      for (std::size_t i = 0; i < m.size(); ++i) {
        const std::string field = "motion[" + std::to_string(i) + "]";
        const YAML::Node c = m[i];
        AnimateClipSource src;
        if (c.IsScalar()) {
          src.file = r.text(c, field);
        } else {
          r.keys(c, field, {"file", "name", "skip_frames"});
          if (!c["file"]) r.fail(c, field + ".file", "each clip needs a file");
          src.file = r.text(c["file"], field + ".file");
          if (const auto n = c["name"]) src.name = r.text(n, field + ".name");
          if (const auto n = c["skip_frames"]) src.skip_frames = static_cast<std::int32_t>(r.integer(n, field + ".skip_frames", 0, 100000));
        }
        if (src.file.empty()) r.fail(c, field, "empty file name");
        if (src.name.empty()) src.name = std::filesystem::path(src.file).stem().string();
        s.clips.push_back(src);
      }
    } else {
      r.fail(m, "motion", "expected 'default' or a list of BVH clips");
    }
  }
  if (const auto n = root["mode"]) s.paper_mode = r.choice(n, "mode", {"continuous", "paper"}) == "paper";
  if (const auto n = root["duration"]) s.duration_s = r.number(n, "duration", 1e-3, 3600.0);
  if (const auto n = root["fps"]) s.fps = r.number(n, "fps", 1.0, 1000.0);
  if (const auto n = root["seed"]) s.seed = static_cast<std::uint32_t>(r.integer(n, "seed", 0, 0xffffffffll));
  if (const auto c = root["camera"]) {
    r.keys(c, "camera", {"orbit_radius", "elevation", "angular_speed", "fov_deg", "resolution"});
    if (const auto n = c["orbit_radius"]) s.camera_radius = r.number(n, "camera.orbit_radius", 0.0, 1e6);
    if (const auto n = c["elevation"]) s.camera_elevation = r.number(n, "camera.elevation", -1e5, 1e5);
    if (const auto n = c["angular_speed"]) s.camera_angular_speed = r.number(n, "camera.angular_speed", -100.0, 100.0);
    if (const auto n = c["fov_deg"]) s.camera_fov_deg = r.number(n, "camera.fov_deg", 1.0, 179.0);
    if (const auto n = c["resolution"]) {
      if (!n.IsSequence() || n.size() != 2) r.fail(n, "camera.resolution", "expected [width, height]");
      s.width = static_cast<std::int32_t>(r.integer(n[0], "camera.resolution[0]", 1, 16384));
      s.height = static_cast<std::int32_t>(r.integer(n[1], "camera.resolution[1]", 1, 16384));
    }
  }
  if (const auto l = root["lod"]) {
    r.keys(l, "lod", {"enabled", "thresholds"});
    if (const auto n = l["enabled"]) s.lod = r.boolean(n, "lod.enabled");
    if (const auto n = l["thresholds"]) {
      if (!n.IsSequence() || n.size() > 15) r.fail(n, "lod.thresholds", "expected a list of at most 15 areas in square pixels");
      s.lod_thresholds.clear();
      for (std::size_t i = 0; i < n.size(); ++i) {
        const std::string field = "lod.thresholds[" + std::to_string(i) + "]";
        const float t = r.number(n[i], field, 1e-6, 1e9);
        if (!s.lod_thresholds.empty() && !(t < s.lod_thresholds.back())) r.fail(n[i], field, "thresholds must decrease");
        s.lod_thresholds.push_back(t);
      }
    }
  }
  if (const auto c = root["cache"]) {
    r.keys(c, "cache", {"enabled", "bucket_width", "capacity_mb"});
    if (const auto n = c["enabled"]) s.cache = r.boolean(n, "cache.enabled");
    if (const auto n = c["bucket_width"]) s.bucket_width = r.number(n, "cache.bucket_width", 1e-4, 1.0);
    if (const auto n = c["capacity_mb"]) s.cache_capacity_mb = r.number(n, "cache.capacity_mb", 0.0, 65536.0);
  }
  if (const auto f = root["foot_skating"]) {
    r.keys(f, "foot_skating", {"characters"});
    if (const auto n = f["characters"]) s.skating_characters = static_cast<std::int32_t>(r.integer(n, "foot_skating.characters", 0, 10000));
  }
  if (const auto n = root["output"]) s.output = r.text(n, "output");
  return s;
}

}  // namespace

AnimateSpec parse_animate_spec(std::string_view text, const std::string& name) {
  if (text.size() > (std::size_t{1} << 20)) throw Error("scenario file larger than 1 MiB", at_line(name, 0));
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    Location l;
    l.file = name;
    if (e.mark.line >= 0) {
      l.line = e.mark.line + 1;
      l.column = e.mark.column + 1;
    }
    throw Error("not valid YAML: " + e.msg, l);
  }
  AnimateSpec s = parse(root, Reader(name));
  s.source = name;
  return s;
}

AnimateSpec read_animate_spec(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open scenario file", at_line(path, 0));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_animate_spec(text.str(), path);
}

std::vector<std::string> builtin_animate_specs() { return kBuiltinAnimateScenarios.names(); }

AnimateSpec builtin_animate_spec(std::string_view name) {
  const auto text = kBuiltinAnimateScenarios.find(name);
  if (!text) {
    throw Error(fmt::format("no built-in animate scenario '{}' (built-in: {})", name, fmt::join(kBuiltinAnimateScenarios.names(), ", ")),
                at_field("scenario"));
  }
  AnimateSpec s = parse_animate_spec(std::string(*text), "built-in:" + std::string(name));
  s.source = "built-in";
  return s;
}

}  // namespace throng::io
