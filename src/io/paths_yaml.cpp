#include "io/paths_yaml.h"

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "io/yaml_reader.h"

namespace throng::io {

namespace {

constexpr double kMaxCoordinate = 1.0e6;  // m
constexpr std::size_t kMaxPoints = 1'000'000;
constexpr std::size_t kAnyCount = std::numeric_limits<std::size_t>::max();

// The paths schema over the shared vocabulary (io/yaml_reader.h).
class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;

  PathsFile read(const YAML::Node& root) {
    expect_map(root, "", {"machine", "radius", "world", "paths"});
    PathsFile out;
    if (root["machine"]) out.machine = text(root["machine"], "machine");
    if (root["radius"]) out.radius = real_in(root["radius"], "radius", 0, 100);
    if (const YAML::Node w = root["world"]) world(w, "world", out);
    each_item(required(root, "", "paths"), "paths", 1, kAnyCount, "paths",
              [&](const YAML::Node& p, const std::string& pp) { out.paths.push_back(entry(p, pp, out)); });
    return out;
  }

 private:
  glm::vec2 point(const YAML::Node& n, const std::string& path) {
    visit(n, path);
    if (!n.IsSequence() || n.size() != 2) fail(n, path, "expected a point [x, y], got " + kind(n));
    return {real_in(n[0], item(path, 0), -kMaxCoordinate, kMaxCoordinate),
            real_in(n[1], item(path, 1), -kMaxCoordinate, kMaxCoordinate)};
  }
  std::vector<glm::vec2> points(const YAML::Node& n, const std::string& path, std::size_t at_least) {
    std::vector<glm::vec2> out;
    each_item(n, path, at_least, kMaxPoints, "points [x, y]",
              [&](const YAML::Node& p, const std::string& pp) { out.push_back(point(p, pp)); });
    return out;
  }

  void world(const YAML::Node& w, const std::string& path, PathsFile& out) {
    expect_map(w, path, {"bounds", "circles", "polygons"});
    out.has_world = true;
    if (w["bounds"]) {
      const std::string bp = child(path, "bounds");
      const std::vector<glm::vec2> b = points(w["bounds"], bp, 2);
      if (b.size() != 2 || !(b[1].x > b[0].x && b[1].y > b[0].y))
        fail(w["bounds"], bp, "bounds are [[xmin, ymin], [xmax, ymax]] with max > min");
      out.has_walkable = true;
      out.walkable.outer = sim::rect_ring(b[0], b[1]);
    }
    if (const YAML::Node cs = w["circles"]) {
      each_item(cs, child(path, "circles"), 0, kAnyCount, "circles {center, radius}",
                [&](const YAML::Node& c, const std::string& cp) {
                  expect_map(c, cp, {"center", "radius"});
                  const glm::vec2 center = point(required(c, cp, "center"), child(cp, "center"));
                  out.circles.push_back(
                      {center, real_in(required(c, cp, "radius"), child(cp, "radius"), 1e-3, kMaxCoordinate)});
                });
    }
    if (const YAML::Node ps = w["polygons"]) {
      each_item(ps, child(path, "polygons"), 0, kAnyCount, "polygons (lists of points)",
                [&](const YAML::Node& p, const std::string& pp) {
                  sim::Polygon poly;
                  poly.outer = points(p, pp, 3);
                  if (sim::find_self_intersection(poly.outer))
                    fail(p, pp, "polygon is self-intersecting or has a zero-length edge");
                  out.polygons.push_back(std::move(poly));
                });
    }
  }

  PathEntry entry(const YAML::Node& p, const std::string& path, const PathsFile& file) {
    expect_map(p, path, {"name", "points", "from", "to", "speed", "marks"});
    PathEntry e;
    e.where = where(p, path);
    e.name = p["name"] ? text(p["name"], child(path, "name")) : "path" + std::to_string(file.paths.size());
    if (p["points"]) {
      if (p["from"] || p["to"]) fail(p, path, "a path has either 'points' or 'from' and 'to'");
      e.points = points(p["points"], child(path, "points"), 2);
    } else {
      if (!p["from"] || !p["to"]) fail(p, path, "a path needs 'points', or 'from' and 'to' to plan between");
      if (!file.has_world) fail(p, path, "a planned path ('from', 'to') needs a 'world'");
      e.planned = true;
      e.from = point(p["from"], child(path, "from"));
      e.to = point(p["to"], child(path, "to"));
    }
    if (p["speed"]) e.speed = real_in(p["speed"], child(path, "speed"), 0, 10);
    if (const YAML::Node ms = p["marks"])
      each_item(ms, child(path, "marks"), 0, kAnyCount, "marks {from, to, state}",
                [&](const YAML::Node& m, const std::string& mp) { e.marks.push_back(mark(m, mp)); });
    return e;
  }

  // A stretch of the path (arc lengths in m) played in one state.
  path::PathMark mark(const YAML::Node& m, const std::string& path) {
    expect_map(m, path, {"from", "to", "state"});
    path::PathMark mark;
    mark.from = real_in(required(m, path, "from"), child(path, "from"), 0, kMaxCoordinate);
    mark.to = real_in(required(m, path, "to"), child(path, "to"), 0, kMaxCoordinate);
    if (!(mark.to > mark.from)) fail(m, path, "a mark needs from < to");
    mark.state = text(required(m, path, "state"), child(path, "state"));
    return mark;
  }
};

}  // namespace

PathsFile parse_paths(std::string_view text, const std::string& name) {
  const YAML::Node root = load_yaml(std::string(text), name);
  try {
    return Reader(name).read(root);
  } catch (const YAML::Exception& e) {
    throw yaml_error(e, name);
  }
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
