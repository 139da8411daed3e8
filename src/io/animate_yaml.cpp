#include "io/animate_yaml.h"

#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "io/embedded.h"
#include "io/yaml_reader.h"

namespace throng::io {

namespace {

// The animate schema over the shared vocabulary (io/yaml_reader.h); every
// key is optional.
class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;

  AnimateSpec read(const YAML::Node& root) {
    AnimateSpec s;
    if (root.IsNull()) return s;
    expect_map(root, "",
               {"name", "characters", "formation", "speed", "scale", "motion", "mode", "duration", "fps", "seed",
                "camera", "lod", "cache", "foot_skating", "output"});
    if (const auto n = root["name"]) s.name = text(n, "name");
    if (const auto n = root["characters"]) s.characters = integer(n, "characters", 1, 10'000'000);
    if (const auto f = root["formation"]) formation(f, "formation", s);
    if (const auto sp = root["speed"]) speed(sp, "speed", s);
    if (const auto sc = root["scale"]) scale(sc, "scale", s);
    if (const auto m = root["motion"]) s.motion = read_motion_set(*this, m, "motion");
    if (const auto n = root["mode"]) s.paper_mode = word(n, "mode", {"continuous", "paper"}) == "paper";
    if (const auto n = root["duration"]) s.duration_s = real_in(n, "duration", 1e-3, 3600.0);
    if (const auto n = root["fps"]) s.fps = real_in(n, "fps", 1.0, 1000.0);
    if (const auto n = root["seed"]) s.seed = static_cast<std::uint32_t>(integer(n, "seed", 0, 0xffffffffll));
    if (const auto c = root["camera"]) camera(c, "camera", s);
    if (const auto l = root["lod"]) lod(l, "lod", s);
    if (const auto c = root["cache"]) {
      expect_map(c, "cache", {"enabled", "bucket_width", "capacity_mb"});
      if (const auto n = c["enabled"]) s.cache = loose_boolean(n, "cache.enabled");
      if (const auto n = c["bucket_width"]) s.bucket_width = real_in(n, "cache.bucket_width", 1e-4, 1.0);
      if (const auto n = c["capacity_mb"]) s.cache_capacity_mb = real_in(n, "cache.capacity_mb", 0.0, 65536.0);
    }
    if (const auto f = root["foot_skating"]) {
      expect_map(f, "foot_skating", {"characters"});
      if (const auto n = f["characters"])
        s.skating_characters = static_cast<std::int32_t>(integer(n, "foot_skating.characters", 0, 10000));
    }
    if (const auto n = root["output"]) s.output = text(n, "output");
    return s;
  }

 private:
  void formation(const YAML::Node& f, const std::string& path, AnimateSpec& s) {
    expect_map(f, path, {"shape", "radius", "ring_spacing", "spacing", "direction"});
    if (const auto n = f["shape"])
      s.shape = word(n, child(path, "shape"), {"circle", "grid"}) == "circle" ? AnimateSpec::Shape::Circle
                                                                              : AnimateSpec::Shape::Grid;
    if (const auto n = f["radius"]) s.radius = real_in(n, child(path, "radius"), 0.5, 1e5);
    if (const auto n = f["ring_spacing"]) s.ring_spacing = real_in(n, child(path, "ring_spacing"), 0.3, 100.0);
    if (const auto n = f["spacing"]) s.spacing = real_in(n, child(path, "spacing"), 0.3, 100.0);
    if (const auto n = f["direction"]) s.clockwise = word(n, child(path, "direction"), {"ccw", "cw"}) == "cw";
  }

  void speed(const YAML::Node& sp, const std::string& path, AnimateSpec& s) {
    expect_map(sp, path, {"min", "max", "change_every"});
    if (const auto n = sp["min"]) s.speed_min = real_in(n, child(path, "min"), 0.0, 12.0);
    if (const auto n = sp["max"]) s.speed_max = real_in(n, child(path, "max"), 0.0, 12.0);
    if (const auto n = sp["change_every"]) s.change_every_s = real_in(n, child(path, "change_every"), 0.0, 3600.0);
    if (s.speed_min > s.speed_max) fail(sp, path, "min must not exceed max");
  }

  void scale(const YAML::Node& sc, const std::string& path, AnimateSpec& s) {
    expect_map(sc, path, {"min", "max"});
    if (const auto n = sc["min"]) s.scale_min = real_in(n, child(path, "min"), 0.1, 10.0);
    if (const auto n = sc["max"]) s.scale_max = real_in(n, child(path, "max"), 0.1, 10.0);
    if (s.scale_min > s.scale_max) fail(sc, path, "min must not exceed max");
  }

  void camera(const YAML::Node& c, const std::string& path, AnimateSpec& s) {
    expect_map(c, path, {"orbit_radius", "elevation", "angular_speed", "fov_deg", "resolution"});
    if (const auto n = c["orbit_radius"]) s.camera_radius = real_in(n, child(path, "orbit_radius"), 0.0, 1e6);
    if (const auto n = c["elevation"]) s.camera_elevation = real_in(n, child(path, "elevation"), -1e5, 1e5);
    if (const auto n = c["angular_speed"])
      s.camera_angular_speed = real_in(n, child(path, "angular_speed"), -100.0, 100.0);
    if (const auto n = c["fov_deg"]) s.camera_fov_deg = real_in(n, child(path, "fov_deg"), 1.0, 179.0);
    if (const auto n = c["resolution"]) {
      const std::string rp = child(path, "resolution");
      visit(n, rp);
      if (!n.IsSequence() || n.size() != 2) fail(n, rp, "expected [width, height], got " + kind(n));
      s.width = static_cast<std::int32_t>(integer(n[0], item(rp, 0), 1, 16384));
      s.height = static_cast<std::int32_t>(integer(n[1], item(rp, 1), 1, 16384));
    }
  }

  void lod(const YAML::Node& l, const std::string& path, AnimateSpec& s) {
    expect_map(l, path, {"enabled", "thresholds"});
    if (const auto n = l["enabled"]) s.lod = loose_boolean(n, child(path, "enabled"));
    if (const auto n = l["thresholds"]) {
      const std::string tp = child(path, "thresholds");
      s.lod_thresholds.clear();
      each_item(n, tp, 0, 15, "areas in square pixels", [&](const YAML::Node& a, const std::string& ap) {
        const float t = real_in(a, ap, 1e-6, 1e9);
        if (!s.lod_thresholds.empty() && !(t < s.lod_thresholds.back())) fail(a, ap, "thresholds must decrease");
        s.lod_thresholds.push_back(t);
      });
    }
  }
};

}  // namespace

AnimateSpec parse_animate_spec(std::string_view text, const std::string& name) {
  if (text.size() > (std::size_t{1} << 20)) throw Error("scenario file larger than 1 MiB", at_line(name, 0));
  const YAML::Node root = load_yaml(std::string(text), name);
  AnimateSpec s;
  try {
    s = Reader(name).read(root);
  } catch (const YAML::Exception& e) {
    throw yaml_error(e, name);
  }
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
    throw Error(fmt::format("no built-in animate scenario '{}' (built-in: {})", name,
                            fmt::join(kBuiltinAnimateScenarios.names(), ", ")),
                at_field("scenario"));
  }
  AnimateSpec s = parse_animate_spec(std::string(*text), "built-in:" + std::string(name));
  s.source = "built-in";
  return s;
}

}  // namespace throng::io
