#include "io/paths_yaml.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/yaml_fields.h"

namespace throng::io {

namespace {

constexpr double kMaxCoordinate = 1.0e6;  // m
constexpr std::size_t kMaxPoints = 1'000'000;

struct Reader : YamlFields {
  glm::vec2 point(const YAML::Node& n) const {
    if (!n.IsSequence() || n.size() != 2) fail(n, "a point is [x, y]");
    return {static_cast<float>(number(n[0], -kMaxCoordinate, kMaxCoordinate)), static_cast<float>(number(n[1], -kMaxCoordinate, kMaxCoordinate))};
  }
  std::vector<glm::vec2> points(const YAML::Node& n, std::size_t at_least) const {
    if (!n.IsSequence()) fail(n, "expected a list of [x, y] points");
    if (n.size() > kMaxPoints) fail(n, "more than 1,000,000 points");
    std::vector<glm::vec2> out;
    for (const auto& p : n) out.push_back(point(p));
    if (out.size() < at_least) fail(n, "needs at least " + std::to_string(at_least) + " points");
    return out;
  }
};

}  // namespace

PathsFile parse_paths(std::string_view text, const std::string& name) {
  Reader r;
  r.file = name;
  const YAML::Node root = load_yaml(std::string(text), name);
  PathsFile out;
  try {
    if (!root.IsMap()) r.fail(root, "a paths file must be a mapping");
    r.only_keys(root, {"machine", "radius", "world", "paths"});
    if (root["machine"]) {
      if (!root["machine"].IsScalar()) r.fail(root["machine"], "expected a file name");
      out.machine = root["machine"].as<std::string>();
    }
    if (root["radius"]) out.radius = static_cast<float>(r.number(root["radius"], 0, 100));
    if (const YAML::Node w = root["world"]) {
      r.only_keys(w, {"bounds", "circles", "polygons"});
      out.has_world = true;
      if (w["bounds"]) {
        const std::vector<glm::vec2> b = r.points(w["bounds"], 2);
        if (b.size() != 2 || !(b[1].x > b[0].x && b[1].y > b[0].y)) r.fail(w["bounds"], "bounds are [[xmin, ymin], [xmax, ymax]] with max > min");
        out.has_walkable = true;
        out.walkable.outer = sim::rect_ring(b[0], b[1]);
      }
      if (const YAML::Node cs = w["circles"]) {
        if (!cs.IsSequence()) r.fail(cs, "'circles' must be a list");
        for (const auto& c : cs) {
          r.only_keys(c, {"center", "radius"});
          if (!c["center"] || !c["radius"]) r.fail(c, "a circle needs 'center' and 'radius'");
          out.circles.push_back({r.point(c["center"]), static_cast<float>(r.number(c["radius"], 1e-3, kMaxCoordinate))});
        }
      }
      if (const YAML::Node ps = w["polygons"]) {
        if (!ps.IsSequence()) r.fail(ps, "'polygons' must be a list of point lists");
        for (const auto& p : ps) {
          sim::Polygon poly;
          poly.outer = r.points(p, 3);
          if (sim::find_self_intersection(poly.outer)) r.fail(p, "polygon is self-intersecting or has a zero-length edge");
          out.polygons.push_back(std::move(poly));
        }
      }
    }
    const YAML::Node paths = root["paths"];
    if (!paths || !paths.IsSequence() || paths.size() == 0) r.fail(root, "a paths file needs a non-empty list 'paths'");
    for (const auto& p : paths) {
      r.only_keys(p, {"name", "points", "from", "to", "speed", "marks"});
      PathEntry e;
      e.where = r.where(p);
      e.name = p["name"] ? p["name"].as<std::string>() : "path" + std::to_string(out.paths.size());
      if (p["points"]) {
        if (p["from"] || p["to"]) r.fail(p, "a path has either 'points' or 'from' and 'to'");
        e.points = r.points(p["points"], 2);
      } else {
        if (!p["from"] || !p["to"]) r.fail(p, "a path needs 'points', or 'from' and 'to' to plan between");
        if (!out.has_world) r.fail(p, "a planned path ('from', 'to') needs a 'world'");
        e.planned = true;
        e.from = r.point(p["from"]);
        e.to = r.point(p["to"]);
      }
      if (p["speed"]) e.speed = static_cast<float>(r.number(p["speed"], 0, 10));
      if (const YAML::Node ms = p["marks"]) {
        if (!ms.IsSequence()) r.fail(ms, "'marks' must be a list");
        for (const auto& m : ms) {
          r.only_keys(m, {"from", "to", "state"});
          if (!m["from"] || !m["to"] || !m["state"]) r.fail(m, "a mark needs 'from', 'to' (arc length, m) and 'state'");
          path::PathMark mark;
          mark.from = static_cast<float>(r.number(m["from"], 0, kMaxCoordinate));
          mark.to = static_cast<float>(r.number(m["to"], 0, kMaxCoordinate));
          if (!(mark.to > mark.from)) r.fail(m, "a mark needs from < to");
          mark.state = m["state"].as<std::string>();
          e.marks.push_back(mark);
        }
      }
      out.paths.push_back(std::move(e));
    }
  } catch (const YAML::Exception& e) {
    throw Error(e.msg, at_line(name, e.mark.line + 1, e.mark.column + 1));
  }
  return out;
}

PathsFile read_paths(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error("cannot open the paths file", at_line(file, 0));
  std::ostringstream ss;
  ss << in.rdbuf();
  PathsFile out = parse_paths(ss.str(), file);
  if (!out.machine.empty()) {
    const std::filesystem::path m(out.machine);
    if (m.is_relative()) out.machine = (std::filesystem::path(file).parent_path() / m).string();
  }
  return out;
}

}  // namespace throng::io
