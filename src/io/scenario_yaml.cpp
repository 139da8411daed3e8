#include "io/scenario_yaml.h"

#include <fmt/ranges.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include "core/ground.h"
#include "io/embedded.h"
#include "io/yaml_reader.h"
#include "path/distance_field.h"
#include "path/route_planner.h"

namespace throng::io {

namespace {

using sim::GoalSpec;
using sim::Region;

constexpr double kDegrees = 0.017453292519943295;

// The scenario schema over the shared vocabulary (io/yaml_reader.h), plus
// what only scenarios have: points and rings within the extent limit, and
// the positions of spawn points kept for errors found later.
class Reader : public YamlReader {
 public:
  Reader(const std::string& file, const ScenarioReadLimits& limits, ScenarioSource& source)
      : YamlReader(file, YamlReadRules{limits.max_nodes, kMaxText, false}, &source.marks),
        limits_(limits),
        source_(source) {}

  glm::vec2 point(const YAML::Node& n, const std::string& path) {
    visit(n, path);
    return coordinates(n, [&] { return path; });
  }

  // [x, y] within the extent limit. Vertices of rings come here directly:
  // counted against the node budget but not recorded, and their key path is
  // only spelled out for an error (a polygon may have a million of them).
  template <class PathFn>
  glm::vec2 coordinates(const YAML::Node& n, const PathFn& path) {
    if (!n.IsSequence() || n.size() != 2) fail(n, path(), "expected a point [x, y], got " + kind(n));
    spend(n, 2, path);
    double xy[2];
    for (int k = 0; k < 2; ++k) {
      const YAML::Node c = n[k];
      if (const std::string problem = number_problem(c, &xy[k]); !problem.empty())
        fail(c, item(path(), static_cast<std::size_t>(k)), problem);
    }
    const double max_extent = limits_.scenario.max_extent;
    if (std::fabs(xy[0]) > max_extent || std::fabs(xy[1]) > max_extent)
      fail(n, path(), fmt::format("coordinates must be within +-{} m", max_extent));
    return {static_cast<float>(xy[0]), static_cast<float>(xy[1])};
  }

  glm::vec3 point3(const YAML::Node& n, const std::string& path) {
    visit(n, path);
    if (!n.IsSequence() || n.size() != 3) fail(n, path, "expected a point [x, y, z], got " + kind(n));
    return {real(n[0], item(path, 0)), real(n[1], item(path, 1)), real(n[2], item(path, 2))};
  }

  sim::Ring ring(const YAML::Node& n, const std::string& path) {
    expect_list(n, path, 3, static_cast<std::size_t>(limits_.scenario.max_vertices), "points [x, y]");
    vertices_ += static_cast<std::int64_t>(n.size());
    if (vertices_ > limits_.scenario.max_vertices)
      fail(n, path, fmt::format("the scenario has more than {} polygon vertices", limits_.scenario.max_vertices));
    sim::Ring r;
    r.reserve(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) {
      count(1);
      r.push_back(coordinates(n[i], [&] { return item(path, i); }));
    }
    return r;
  }

  // Spawn points [[x, y], ...]: each item's position is kept in the compact
  // per-list table (a file may list a million of them), so errors found
  // when the crowd is placed ("groups[0].spawn.points[3]") get its line.
  std::vector<glm::vec2> points(const YAML::Node& n, const std::string& path) {
    expect_list(n, path, 1, static_cast<std::size_t>(limits_.scenario.max_agents), "points [x, y]");
    std::vector<glm::vec2> out;
    out.reserve(n.size());
    std::vector<std::pair<int, int>>& marks = source_.item_marks[path];
    marks.clear();
    marks.reserve(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) {
      count(1);
      const YAML::Node p = n[i];
      out.push_back(coordinates(p, [&] { return item(path, i); }));
      const YAML::Mark m = p.Mark();
      marks.emplace_back(m.is_null() ? 0 : m.line + 1, m.is_null() ? 0 : m.column + 1);
    }
    return out;
  }

  std::vector<sim::Ring> holes(const YAML::Node& n, const std::string& path) {
    expect_list(n, path, 0, static_cast<std::size_t>(limits_.scenario.max_obstacles), "holes");
    std::vector<sim::Ring> out;
    for (std::size_t i = 0; i < n.size(); ++i) out.push_back(ring(n[i], item(path, i)));
    return out;
  }

  sim::Polygon rect_polygon(const YAML::Node& n, const std::string& path) {
    expect_map(n, path, {"min", "max"});
    const glm::vec2 lo = point(required(n, path, "min"), child(path, "min"));
    const glm::vec2 hi = point(required(n, path, "max"), child(path, "max"));
    if (!(hi.x > lo.x && hi.y > lo.y)) fail(n, path, "a rect needs max > min in x and in y");
    return {sim::rect_ring(lo, hi), {}};
  }

  // {polygon: [...], holes: [...]} or {rect: {min, max}}.
  sim::Polygon area(const YAML::Node& n, const std::string& path) {
    const std::string k = one_of(n, path, {"polygon", "rect"}, {"holes"});
    sim::Polygon p = k == "rect" ? rect_polygon(n["rect"], child(path, "rect"))
                                 : sim::Polygon{ring(n["polygon"], child(path, "polygon")), {}};
    if (n["holes"]) p.holes = holes(n["holes"], child(path, "holes"));
    return p;
  }

  sim::Circle circle(const YAML::Node& n, const std::string& path) {
    expect_map(n, path, {"center", "radius"});
    sim::Circle c;
    c.center = point(required(n, path, "center"), child(path, "center"));
    c.radius = real(required(n, path, "radius"), child(path, "radius"));
    return c;
  }

  Region region(const YAML::Node& n, const std::string& path) {
    const std::string k = one_of(n, path, {"rect", "disc", "ring", "polygon", "points"});
    const std::string sub = child(path, k);
    const YAML::Node v = n[k];
    Region r;
    if (k == "rect") {
      r.kind = Region::Kind::rect;
      const sim::Polygon p = rect_polygon(v, sub);
      r.min = p.outer[0];
      r.max = p.outer[2];
    } else if (k == "disc") {
      r.kind = Region::Kind::disc;
      expect_map(v, sub, {"center", "radius"});
      r.center = point(required(v, sub, "center"), child(sub, "center"));
      r.radius = real(required(v, sub, "radius"), child(sub, "radius"));
    } else if (k == "ring") {
      r.kind = Region::Kind::ring;
      expect_map(v, sub, {"center", "radius", "spacing"});
      r.center = v["center"] ? point(v["center"], child(sub, "center")) : glm::vec2(0.0f);
      if (v["radius"].IsDefined() == v["spacing"].IsDefined())
        fail(v, sub, "a ring needs one of 'radius' or 'spacing'");
      if (v["radius"]) r.radius = real(v["radius"], child(sub, "radius"));
      if (v["spacing"]) r.spacing = real(v["spacing"], child(sub, "spacing"));
    } else if (k == "points") {
      r.kind = Region::Kind::points;
      r.points = points(v, sub);
    } else {
      r.kind = Region::Kind::polygon;
      r.polygon.outer = ring(v, sub);
    }
    return r;
  }

  GoalSpec goal(const YAML::Node& n, const std::string& path) {
    GoalSpec g;
    if (n.IsSequence()) {  // a bare [x, y] is a point
      g.value = point(n, path);
      return g;
    }
    const std::string k = one_of(n, path, {"point", "offset", "mirror", "random", "exits", "gate", "direction"},
                                 {"choice", "reconsider", "wait"});
    const std::string sub = child(path, k);
    if (k == "exits") {
      if (n["wait"]) fail(n["wait"], child(path, "wait"), "agents leave by an exit: it takes no wait");
      return exits(n, path);
    }
    if (n["choice"] || n["reconsider"])
      fail(n["choice"] ? n["choice"] : n["reconsider"], child(path, n["choice"] ? "choice" : "reconsider"),
           "only a goal of exits takes a choice");
    if (n["wait"]) g.wait_s = real(n["wait"], child(path, "wait"));
    if (k == "random") {
      g.kind = GoalSpec::Kind::Random;
      g.region = region(n[k], sub);
    } else if (k == "gate") {  // [[x, y], [x, y]]: its two ends
      g.kind = GoalSpec::Kind::Gate;
      expect_list(n[k], sub, 2, 2, "ends [x, y] (a gate is two points)");
      const std::vector<glm::vec2> ends = points(n[k], sub);
      g.value = ends[0];
      g.gate_to = ends[1];
    } else if (k == "direction") {  // [x, y]: any length but zero
      g.kind = GoalSpec::Kind::Direction;
      const glm::vec2 d = point(n[k], sub);
      const float length = std::sqrt(d.x * d.x + d.y * d.y);
      if (!(length > 0.0f) || !std::isfinite(length)) fail(n[k], sub, "a direction needs a vector that is not zero");
      g.value = d / length;
    } else {
      g.kind = k == "point" ? GoalSpec::Kind::Point : (k == "offset" ? GoalSpec::Kind::Offset : GoalSpec::Kind::Mirror);
      g.value = point(n[k], sub);
    }
    return g;
  }

  // One exit: {point: [x, y], width: m} or a door line {from: [x, y], to:
  // [x, y]} (its middle and length), with a `name` where `named`.
  sim::ExitSpec exit(const YAML::Node& x, const std::string& xp, bool named) {
    if (named)
      expect_map(x, xp, {"name", "point", "width", "from", "to"});
    else
      expect_map(x, xp, {"point", "width", "from", "to"});
    sim::ExitSpec e;
    if (named) e.name = text(required(x, xp, "name"), child(xp, "name"));
    if (x["from"] || x["to"]) {
      if (x["point"] || x["width"])
        fail(x["point"] ? x["point"] : x["width"], child(xp, x["point"] ? "point" : "width"),
             "give an exit as 'point' and 'width' or as a line 'from' and 'to', not both");
      const glm::vec2 from = point(required(x, xp, "from"), child(xp, "from"));
      const glm::vec2 to = point(required(x, xp, "to"), child(xp, "to"));
      e.point = 0.5f * (from + to);
      e.half = 0.5f * (to - from);
      e.width = glm::length(to - from);
      if (!(e.width > 0)) fail(x["to"], child(xp, "to"), "a door line needs two different ends");
      return e;
    }
    e.point = point(required(x, xp, "point"), child(xp, "point"));
    if (x["width"]) e.width = real(x["width"], child(xp, "width"));
    if (!(e.width > 0)) fail(x["width"], child(xp, "width"), fmt::format("must be > 0 m (got {})", e.width));
    return e;
  }

  // {exits: [EXIT | name of one of the scenario's exits, ...], choice:
  // nearest | quickest, reconsider: s}.
  GoalSpec exits(const YAML::Node& n, const std::string& path) {
    GoalSpec g;
    g.kind = GoalSpec::Kind::Exits;
    each_item(n["exits"], child(path, "exits"), 1, 1000, "exits", [&](const YAML::Node& x, const std::string& xp) {
      if (!x.IsScalar()) {
        g.exits.push_back(exit(x, xp, false));
        return;
      }
      const std::string name = text(x, xp);
      const auto found = std::find_if(named_exits_.begin(), named_exits_.end(),
                                      [&](const sim::ExitSpec& e) { return e.name == name; });
      if (found == named_exits_.end()) {
        std::string known;
        for (const sim::ExitSpec& e : named_exits_) known += (known.empty() ? "" : ", ") + e.name;
        fail(x, xp,
             fmt::format("no exit named {} (the scenario's exits: {})", shown(name),
                         known.empty() ? "none; name them in the top-level 'exits'" : known));
      }
      g.exits.push_back(*found);
    });
    if (n["choice"])
      g.choice = word(n["choice"], child(path, "choice"), {"nearest", "quickest"}) == "quickest"
                     ? sim::ExitChoice::Quickest
                     : sim::ExitChoice::Nearest;
    if (n["reconsider"]) g.reconsider_s = real(n["reconsider"], child(path, "reconsider"));
    return g;
  }

  sim::SpeedSpec speed(const YAML::Node& n, const std::string& path, sim::SpeedSpec s) {
    if (n.IsScalar()) {  // one number: every agent walks at it
      s.mean = s.min = s.max = real(n, path);
      s.stddev = 0.0f;
      return s;
    }
    expect_map(n, path, {"mean", "stddev", "min", "max"});
    if (n["mean"]) s.mean = real(n["mean"], child(path, "mean"));
    if (n["stddev"]) s.stddev = real(n["stddev"], child(path, "stddev"));
    if (n["min"]) s.min = real(n["min"], child(path, "min"));
    if (n["max"]) s.max = real(n["max"], child(path, "max"));
    if (!n["min"]) s.min = std::min(s.min, s.mean);
    if (!n["max"]) s.max = std::max(s.max, s.mean);
    return s;
  }

  // One number: every agent waits that long. A map: `distribution` (uniform
  // needs min and max; normal and lognormal need mean and stddev, and take
  // min, default 0, and max, default the mean plus four spreads).
  sim::PremovementSpec premovement(const YAML::Node& n, const std::string& path) {
    using Kind = sim::PremovementSpec::Kind;
    sim::PremovementSpec p;
    if (n.IsScalar()) {
      p.kind = Kind::uniform;
      p.min = p.max = real(n, path);
      if (p.min < 0) fail(n, path, fmt::format("must be >= 0 s (got {})", p.min));
      return p;
    }
    expect_map(n, path, {"distribution", "mean", "stddev", "min", "max"});
    const std::string d =
        word(required(n, path, "distribution"), child(path, "distribution"), {"uniform", "normal", "lognormal"});
    p.kind = d == "uniform" ? Kind::uniform : (d == "normal" ? Kind::normal : Kind::lognormal);
    if (p.kind == Kind::uniform) {
      for (const char* key : {"mean", "stddev"})
        if (n[key]) fail(n[key], child(path, key), "a uniform distribution takes min and max only");
      p.min = real(required(n, path, "min"), child(path, "min"));
      p.max = real(required(n, path, "max"), child(path, "max"));
      return p;
    }
    p.mean = real(required(n, path, "mean"), child(path, "mean"));
    p.stddev = real(required(n, path, "stddev"), child(path, "stddev"));
    p.min = n["min"] ? real(n["min"], child(path, "min")) : 0.0f;
    p.max = n["max"] ? real(n["max"], child(path, "max")) : p.mean + 4.0f * p.stddev;
    return p;
  }

  // {rate: P/s, from: s (0), until: s (none)} or {times: [s, ...]}.
  sim::InflowSpec inflow(const YAML::Node& n, const std::string& path) {
    sim::InflowSpec in;
    in.enabled = true;
    if (n.IsMap() && n["times"]) {
      expect_map(n, path, {"times"});
      each_item(n["times"], child(path, "times"), 1, static_cast<std::size_t>(limits_.scenario.max_agents),
                "entry times", [&](const YAML::Node& t, const std::string& tp) { in.times.push_back(real(t, tp)); });
      return in;
    }
    expect_map(n, path, {"rate", "from", "until"});
    in.rate = real(required(n, path, "rate"), child(path, "rate"));
    if (n["from"]) in.from = real(n["from"], child(path, "from"));
    if (n["until"]) in.until = real(n["until"], child(path, "until"));
    return in;
  }

  // `type` picks the model; the other keys are that model's parameters or
  // those every model shares. A parameter of another model is an error that
  // says which type it belongs to.
  sim::ModelParams model(const YAML::Node& n, const std::string& path) {
    static const std::vector<std::string_view> shared = {
        "type", "max_speed", "max_radius", "contact_iterations", "contact_extra_iterations", "contact_tolerance"};
    static const std::vector<std::string_view> priority = {"pred_time",       "max_force",       "personal_space",
                                                           "lane_half_width", "relaxation_time", "probe_margin"};
    static const std::vector<std::string_view> cfs = {
        "time_gap",   "neighbour_strength", "neighbour_range", "wall_strength",     "wall_range", "avoid_strength",
        "avoid_time", "side_margin",        "turn_time",       "anticipation_time", "lane_width"};
    static const std::vector<std::string_view> ttc = {"ttc_strength",         "ttc_time_horizon",
                                                      "ttc_relaxation_time",  "ttc_sensing_radius",
                                                      "ttc_max_acceleration", "ttc_side_bias"};
    static const std::vector<std::string_view> sf = {
        "sf_mass",     "sf_relaxation_time", "sf_strength",       "sf_range",       "sf_body_stiffness",
        "sf_friction", "sf_anisotropy",      "sf_sensing_radius", "sf_max_substep", "sf_side_bias"};
    visit(n, path);
    if (!n.IsMap()) fail(n, path, "expected a map (model.type and its parameters), got " + kind(n));
    sim::ModelParams m;
    if (n["type"])
      m.kind = sim::parse_model_kind(
          word(n["type"], child(path, "type"), {"collision_free_speed", "priority", "ttc", "social_force"}),
          child(path, "type"));
    auto keys_of_model = [&](sim::ModelKind k) -> const std::vector<std::string_view>& {
      if (k == sim::ModelKind::SocialForce) return sf;
      return k == sim::ModelKind::Priority ? priority : (k == sim::ModelKind::Ttc ? ttc : cfs);
    };
    const std::vector<std::string_view>& own = keys_of_model(m.kind);
    std::vector<std::string_view> allowed = shared;
    allowed.insert(allowed.end(), own.begin(), own.end());
    for (auto it = n.begin(); it != n.end(); ++it) {
      const YAML::Node key = it->first;
      if (!key.IsScalar()) continue;
      for (const sim::ModelKind owner : {sim::ModelKind::CollisionFreeSpeed, sim::ModelKind::Priority,
                                         sim::ModelKind::Ttc, sim::ModelKind::SocialForce}) {
        const std::vector<std::string_view>& keys = keys_of_model(owner);
        if (owner == m.kind || std::find(keys.begin(), keys.end(), key.Scalar()) == keys.end()) continue;
        fail_at(key.Mark(), child(path, key.Scalar()),
                fmt::format("'{}' is a parameter of the {} model, and this scenario's model.type is {}{}", key.Scalar(),
                            to_string(owner), to_string(m.kind),
                            n["type"] ? "" : fmt::format(" (the default; add 'type: {}')", to_string(owner))));
      }
    }
    keys_of(n, path, allowed);
    auto opt = [&](const char* key, float& out) {
      if (n[key]) out = real(n[key], child(path, key));
    };
    opt("max_speed", m.max_speed);
    opt("max_radius", m.body_radius_limit);
    opt("pred_time", m.pred_time);
    opt("max_force", m.max_force);
    opt("personal_space", m.personal_space);
    opt("lane_half_width", m.lane_half_width);
    opt("relaxation_time", m.relaxation_time);
    opt("probe_margin", m.probe_margin);
    opt("time_gap", m.cfs.time_gap);
    opt("neighbour_strength", m.cfs.neighbour_strength);
    opt("neighbour_range", m.cfs.neighbour_range);
    opt("wall_strength", m.cfs.wall_strength);
    opt("wall_range", m.cfs.wall_range);
    opt("avoid_strength", m.cfs.avoid_strength);
    opt("avoid_time", m.cfs.avoid_time);
    opt("side_margin", m.cfs.side_margin);
    opt("turn_time", m.cfs.turn_time);
    opt("anticipation_time", m.cfs.anticipation_time);
    opt("lane_width", m.cfs.lane_width);
    opt("ttc_strength", m.ttc.strength);
    opt("ttc_time_horizon", m.ttc.time_horizon);
    opt("ttc_relaxation_time", m.ttc.relaxation_time);
    opt("ttc_sensing_radius", m.ttc.sensing_radius);
    opt("ttc_max_acceleration", m.ttc.max_acceleration);
    opt("ttc_side_bias", m.ttc.side_bias);
    opt("sf_mass", m.sf.mass);
    opt("sf_relaxation_time", m.sf.relaxation_time);
    opt("sf_strength", m.sf.strength);
    opt("sf_range", m.sf.range);
    opt("sf_body_stiffness", m.sf.body_stiffness);
    opt("sf_friction", m.sf.friction);
    opt("sf_anisotropy", m.sf.anisotropy);
    opt("sf_sensing_radius", m.sf.sensing_radius);
    opt("sf_max_substep", m.sf.max_substep);
    opt("sf_side_bias", m.sf.side_bias);
    if (n["contact_iterations"])
      m.contact_iterations =
          static_cast<std::int32_t>(integer(n["contact_iterations"], child(path, "contact_iterations"), 0, 64));
    if (n["contact_extra_iterations"])
      m.contact_extra_iterations = static_cast<std::int32_t>(
          integer(n["contact_extra_iterations"], child(path, "contact_extra_iterations"), 0, 64));
    opt("contact_tolerance", m.contact_tolerance);
    return m;
  }

  // periodic: x, y, or a list of them ([x], [x, y]): the axes that wrap.
  void periodic(const YAML::Node& n, const std::string& path, sim::WorldSpec& w) {
    if (n.IsSequence()) expect_list(n, path, 1, 2, "axes x, y");
    const std::size_t count = n.IsSequence() ? n.size() : 1;
    for (std::size_t k = 0; k < count; ++k) {
      const YAML::Node a = n.IsSequence() ? n[k] : n;
      const std::string ap = n.IsSequence() ? item(path, k) : path;
      const std::string axis = text(a, ap);
      if (axis != "x" && axis != "y") fail(a, ap, fmt::format("an axis is x or y (got '{}')", axis));
      bool& wraps = axis == "x" ? w.periodic_x : w.periodic_y;
      if (wraps) fail(a, ap, fmt::format("axis {} is named twice", axis));
      wraps = true;
    }
  }

  void world(const YAML::Node& n, const std::string& path, sim::WorldSpec& w) {
    expect_map(n, path, {"walkable", "periodic", "obstacles", "scatter"});
    if (n["walkable"]) {
      w.has_walkable = true;
      w.walkable = area(n["walkable"], child(path, "walkable"));
    }
    if (const YAML::Node p = n["periodic"]) periodic(p, child(path, "periodic"), w);
    std::int64_t obstacles = 0;
    if (const YAML::Node list = n["obstacles"]) {
      const std::string lp = child(path, "obstacles");
      expect_list(list, lp, 0, static_cast<std::size_t>(limits_.scenario.max_obstacles), "obstacles");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string ip = item(lp, i);
        const std::string k = one_of(list[i], ip, {"polygon", "rect", "circle"}, {"holes"});
        if (k == "circle") {
          if (list[i]["holes"]) fail(list[i]["holes"], child(ip, "holes"), "a circle has no holes");
          w.circles.push_back(circle(list[i]["circle"], child(ip, "circle")));
          w.circle_fields.push_back(ip);
        } else {
          w.polygons.push_back(area(list[i], ip));
          w.polygon_fields.push_back(ip);
        }
        ++obstacles;
      }
    }
    if (const YAML::Node list = n["scatter"]) {
      const std::string lp = child(path, "scatter");
      expect_list(list, lp, 0, 1000, "scattered obstacle fields");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string ip = item(lp, i);
        const YAML::Node s = list[i];
        expect_map(s, ip, {"count", "region", "size", "clearance", "seed"});
        sim::ScatterSpec spec;
        spec.count = integer(required(s, ip, "count"), child(ip, "count"), 0, limits_.scenario.max_obstacles);
        obstacles += spec.count;
        if (obstacles > limits_.scenario.max_obstacles)
          fail(s, ip, fmt::format("the scenario has more than {} obstacles", limits_.scenario.max_obstacles));
        const std::string rp = child(ip, "region");
        spec.region = region(required(s, ip, "region"), rp);
        if (spec.region.kind != Region::Kind::rect) fail(s["region"], rp, "obstacles are scattered in a rect");
        if (const YAML::Node size = s["size"]) {
          const std::string sp = child(ip, "size");
          visit(size, sp);
          if (!size.IsSequence() || size.size() != 2)
            fail(size, sp, "expected [min, max] in metres, got " + kind(size));
          spec.min_size = real(size[0], item(sp, 0));
          spec.max_size = real(size[1], item(sp, 1));
        }
        if (s["clearance"]) spec.clearance = real(s["clearance"], child(ip, "clearance"));
        if (s["seed"])
          spec.seed = static_cast<std::uint64_t>(integer(s["seed"], child(ip, "seed"), 0, std::int64_t{1} << 53));
        w.scatters.push_back(spec);
        w.scatter_fields.push_back(ip);
      }
    }
  }

  sim::GroupSpec group(const YAML::Node& n, const std::string& path, const sim::ModelParams& model) {
    expect_map(n, path,
               {"name", "count", "radius", "speed", "spawn", "waypoints", "goal", "on_arrival", "arrival_radius",
                "premovement", "inflow"});
    sim::GroupSpec g;
    if (n["name"]) g.name = text(n["name"], child(path, "name"));
    // count may be left out when the group spawns at points (one agent per
    // point) or enters at listed times (one agent per time).
    const YAML::Node spawn = required(n, path, "spawn");
    const bool at_points = spawn.IsMap() && spawn["points"];
    if (n["inflow"]) g.inflow = inflow(n["inflow"], child(path, "inflow"));
    if (!n["count"] && !g.inflow.times.empty()) g.count = static_cast<std::int64_t>(g.inflow.times.size());
    if (n["count"] || (!at_points && g.inflow.times.empty()))
      g.count = integer(required(n, path, "count"), child(path, "count"), 0, limits_.scenario.max_agents);
    if (n["radius"]) g.radius = real(n["radius"], child(path, "radius"));
    // Unless given, speeds stay within the model's maximum.
    g.speed.max = std::min(g.speed.max, model.max_speed);
    g.speed.min = std::min(g.speed.min, g.speed.max);
    g.speed.mean = std::min(g.speed.mean, g.speed.max);
    if (n["speed"]) g.speed = speed(n["speed"], child(path, "speed"), g.speed);
    g.spawn = region(spawn, child(path, "spawn"));
    if (g.spawn.kind == Region::Kind::points) {
      const auto given = static_cast<std::int64_t>(g.spawn.points.size());
      if (!n["count"]) g.count = given;
      if (g.count != given)
        fail(spawn["points"], child(path, "spawn.points"),
             fmt::format("{} points for a count of {}: give one point per agent (or leave count out)", given, g.count));
    }
    if (const YAML::Node list = n["waypoints"]) {
      const std::string lp = child(path, "waypoints");
      expect_list(list, lp, 0, static_cast<std::size_t>(limits_.scenario.max_waypoints), "waypoints");
      for (std::size_t i = 0; i < list.size(); ++i) g.waypoints.push_back(goal(list[i], item(lp, i)));
    }
    g.goal = goal(required(n, path, "goal"), child(path, "goal"));
    // Agents leave by their exit unless told to stand there.
    if (g.goal.kind == GoalSpec::Kind::Exits) g.arrival = sim::ArrivalBehaviour::Despawn;
    if (n["on_arrival"]) {
      const std::string a = word(n["on_arrival"], child(path, "on_arrival"), {"stop", "despawn", "loop"});
      g.arrival = a == "stop" ? sim::ArrivalBehaviour::Stop
                              : (a == "despawn" ? sim::ArrivalBehaviour::Despawn : sim::ArrivalBehaviour::Loop);
    }
    if (n["arrival_radius"]) g.arrival_radius = real(n["arrival_radius"], child(path, "arrival_radius"));
    if (n["premovement"]) g.premovement = premovement(n["premovement"], child(path, "premovement"));
    return g;
  }

  Camera camera(const YAML::Node& n, const std::string& path) {
    expect_map(n, path, {"position", "target", "fov_degrees", "width", "height", "near", "far", "motion", "period"});
    Camera c;
    const glm::vec3 eye = point3(required(n, path, "position"), child(path, "position"));
    const glm::vec3 target = point3(required(n, path, "target"), child(path, "target"));
    c.position = world_from_map(eye);
    c.target = world_from_map(target);
    // Looking straight down: put the map's north (+y) at the top of the image.
    const glm::vec3 d = target - eye;
    if (std::fabs(d.x) + std::fabs(d.y) <= 1e-4f * std::fabs(d.z)) c.up = world_from_map(glm::vec3(0.0f, 1.0f, 0.0f));
    if (n["fov_degrees"])
      c.fov_y = static_cast<float>(real_in(n["fov_degrees"], child(path, "fov_degrees"), 1.0, 179.0) * kDegrees);
    if (n["width"]) c.width = static_cast<std::int32_t>(integer(n["width"], child(path, "width"), 1, 1 << 15));
    if (n["height"]) c.height = static_cast<std::int32_t>(integer(n["height"], child(path, "height"), 1, 1 << 15));
    if (n["near"]) c.near_plane = real(n["near"], child(path, "near"));
    if (n["far"]) c.far_plane = real(n["far"], child(path, "far"));
    try {
      c.validate();
    } catch (const Error& e) {
      // Camera names its own fields; say it in the file's words.
      std::string field = e.location().field;
      for (const auto& [from, to] :
           {std::pair<std::string_view, std::string_view>{"camera.fov_y", "camera.fov_degrees"},
            {"camera.near_plane", "camera.near"},
            {"camera.far_plane", "camera.far"},
            {"camera.up", "camera.target"}})
        if (field == from) field = to;
      const std::string key = field.substr(field.find('.') + 1);
      fail(n[key] ? n[key] : n, field, e.message());
    }
    return c;
  }

  // {rect: {min, max}} (one area, the older form), or
  // {areas: [{name, rect}], lines: [{name, from, to}], voronoi_cutoff}.
  sim::MeasurementSpec measurement(const YAML::Node& n, const std::string& path) {
    constexpr std::size_t kMaxItems = 1000;
    sim::MeasurementSpec m;
    if (!(n.IsMap() && (n["areas"] || n["lines"] || n["voronoi_cutoff"]))) {
      // A misspelt key is told apart from both forms' keys.
      if (n.IsMap() && !n["rect"] && !n["disc"] && !n["ring"] && !n["polygon"])
        expect_map(n, path, {"rect", "areas", "lines", "voronoi_cutoff"});
      const Region r = region(n, path);
      if (r.kind != Region::Kind::rect) fail(n, path, "the measurement area is a rect");
      sim::Aabb box;
      box.add(r.min);
      box.add(r.max);
      m.areas.push_back({"area", box});
      return m;
    }
    if (n["rect"])
      fail(n["rect"], child(path, "rect"), "give either 'rect' (one area) or 'areas' and 'lines', not both");
    expect_map(n, path, {"areas", "lines", "voronoi_cutoff"});
    // Names label the results in stats.json: each names one thing.
    auto name_of = [&](const YAML::Node& item_node, const std::string& ip, std::vector<std::string>& taken,
                       const std::string& fallback) {
      const YAML::Node given = item_node["name"];
      const std::string np = child(ip, "name");
      const std::string name = given ? text(given, np) : fallback;
      if (name.empty()) fail(given, np, "must not be empty");
      if (std::find(taken.begin(), taken.end(), name) != taken.end())
        fail(given ? given : item_node, given ? np : ip, fmt::format("duplicate name {}", shown(name)));
      taken.push_back(name);
      return name;
    };
    std::vector<std::string> names;
    if (const YAML::Node list = n["areas"]) {
      const std::string lp = child(path, "areas");
      expect_list(list, lp, 0, kMaxItems, "areas");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string ip = item(lp, i);
        expect_map(list[i], ip, {"name", "rect"});
        const sim::Polygon p = rect_polygon(required(list[i], ip, "rect"), child(ip, "rect"));
        sim::Aabb box;
        box.add(p.outer[0]);
        box.add(p.outer[2]);
        m.areas.push_back({name_of(list[i], ip, names, fmt::format("area{}", i)), box});
      }
    }
    names.clear();
    if (const YAML::Node list = n["lines"]) {
      const std::string lp = child(path, "lines");
      expect_list(list, lp, 0, kMaxItems, "lines");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string ip = item(lp, i);
        expect_map(list[i], ip, {"name", "from", "to"});
        sim::MeasurementLine l;
        l.from = point(required(list[i], ip, "from"), child(ip, "from"));
        l.to = point(required(list[i], ip, "to"), child(ip, "to"));
        if (!(sim::length_of(l.to - l.from) > 0.0f))
          fail(list[i]["to"], child(ip, "to"), "the line has no length: 'to' equals 'from'");
        l.name = name_of(list[i], ip, names, fmt::format("line{}", i));
        m.lines.push_back(l);
      }
    }
    if (n["voronoi_cutoff"]) m.voronoi_cutoff = real_in(n["voronoi_cutoff"], child(path, "voronoi_cutoff"), 0.1, 100.0);
    return m;
  }

  // `trajectories` is true/false (the short form), or a map with `format`
  // and `every`; `outputs.every` (the older place for the stride) stays
  // accepted, but not together with `trajectories.every`.
  sim::OutputSpec outputs(const YAML::Node& n, const std::string& path, TrajectoryFormat& format) {
    expect_map(n, path, {"dir", "every", "trajectories", "stats"});
    sim::OutputSpec o;
    if (n["dir"]) o.dir = text(n["dir"], child(path, "dir"));
    if (n["every"]) o.every = integer(n["every"], child(path, "every"), 1, limits_.scenario.max_steps);
    if (const YAML::Node t = n["trajectories"]; t && t.IsMap()) {
      const std::string tp = child(path, "trajectories");
      expect_map(t, tp, {"format", "every"});
      if (t["format"]) format = parse_trajectory_format(text(t["format"], child(tp, "format")), child(tp, "format"));
      if (t["every"]) {
        if (n["every"])
          fail(t["every"], child(tp, "every"),
               fmt::format("give the stride once: {} or {}", child(path, "every"), child(tp, "every")));
        o.every = integer(t["every"], child(tp, "every"), 1, limits_.scenario.max_steps);
      }
    } else if (t) {
      o.trajectories = boolean(t, child(path, "trajectories"));
    }
    if (n["stats"]) o.stats = boolean(n["stats"], child(path, "stats"));
    return o;
  }

  // The scenario's named exits, which groups' goals name.
  void named_exits(const YAML::Node& n, const std::string& path) {
    each_item(n, path, 1, 1000, "exits", [&](const YAML::Node& x, const std::string& xp) {
      sim::ExitSpec e = exit(x, xp, true);
      if (e.name.empty()) fail(x["name"], child(xp, "name"), "must not be empty");
      for (const sim::ExitSpec& other : named_exits_)
        if (other.name == e.name) fail(x["name"], child(xp, "name"), fmt::format("duplicate name {}", shown(e.name)));
      named_exits_.push_back(std::move(e));
    });
  }

  sim::ScenarioSpec scenario(const YAML::Node& root, const std::string& default_name, TrajectoryFormat& format,
                             MotionSetSpec& motion) {
    expect_map(root, "",
               {"name", "description", "seed", "scheduler", "planning", "dt", "duration", "steps", "stop_when_arrived",
                "model", "world", "exits", "groups", "camera", "measurement", "outputs", "motion"});
    sim::ScenarioSpec s;
    s.name = root["name"] ? text(root["name"], "name") : default_name;
    if (root["description"]) s.description = text(root["description"], "description");
    if (root["seed"]) s.seed = static_cast<std::uint64_t>(integer(root["seed"], "seed", 0, std::int64_t{1} << 53));
    if (root["scheduler"])
      s.scheduler = sim::parse_scheduler(
          word(root["scheduler"], "scheduler", {"double_buffer", "four_colour", "four_color"}), "scheduler");
    if (root["planning"]) {
      const std::string p = word(root["planning"], "planning", {"roadmap", "field", "quickest", "none"});
      s.planning = p == "none"       ? sim::PlanningKind::None
                   : p == "field"    ? sim::PlanningKind::Field
                   : p == "quickest" ? sim::PlanningKind::Quickest
                                     : sim::PlanningKind::Roadmap;
    }
    if (root["dt"]) s.dt = real_in(root["dt"], "dt", 1e-4, 10.0);
    if (root["duration"]) s.duration = real_in(root["duration"], "duration", 1e-3, 1e9);
    if (root["steps"]) s.steps = integer(root["steps"], "steps", 1, limits_.scenario.max_steps);
    if (s.step_count() > limits_.scenario.max_steps)
      fail(root["duration"] ? root["duration"] : root, "duration",
           fmt::format("duration / dt exceeds {} steps", limits_.scenario.max_steps));
    if (root["stop_when_arrived"]) s.stop_when_arrived = boolean(root["stop_when_arrived"], "stop_when_arrived");
    if (root["model"]) s.model = model(root["model"], "model");
    if (root["world"]) world(root["world"], "world", s.world);
    if (root["exits"]) named_exits(root["exits"], "exits");
    const YAML::Node groups = required(root, "", "groups");
    expect_list(groups, "groups", 1, static_cast<std::size_t>(limits_.max_groups), "groups");
    std::int64_t agents = 0;
    for (std::size_t i = 0; i < groups.size(); ++i) {
      s.groups.push_back(group(groups[i], item("groups", i), s.model));
      agents += s.groups.back().count;
      if (agents > limits_.scenario.max_agents)
        fail(groups[i], item("groups", i),
             fmt::format("the scenario has more than {} agents", limits_.scenario.max_agents));
    }
    if (root["camera"]) {
      s.camera = camera(root["camera"], "camera");
      const YAML::Node& c = root["camera"];
      if (c["motion"]) s.camera_motion = word(c["motion"], "camera.motion", {"fixed", "orbit", "flyover"});
      if (c["period"]) s.camera_period_s = real_in(c["period"], "camera.period", 0.1, 1e6);
    }
    if (const YAML::Node m = root["measurement"]) s.measurement = measurement(m, "measurement");
    if (root["outputs"]) s.outputs = outputs(root["outputs"], "outputs", format);
    if (root["motion"]) motion = read_motion_set(*this, root["motion"], "motion");
    return s;
  }

 private:
  static constexpr std::size_t kMaxText = 4096;  // characters of one string

  ScenarioReadLimits limits_;
  ScenarioSource& source_;
  std::vector<sim::ExitSpec> named_exits_;  // the top-level `exits`, read before the groups
  std::int64_t vertices_ = 0;
};

std::string stem_of(const std::string& name) {
  std::string stem = std::filesystem::path(name).stem().string();
  return stem.empty() ? "scenario" : stem;
}

}  // namespace

Location ScenarioSource::locate(const std::string& field) const {
  std::string key = field;
  // Drop trailing parts ("[3]", ".radius", " (shape 5)") until a recorded key remains.
  while (!key.empty()) {
    if (const auto it = marks.find(key); it != marks.end())
      return Location{file, it->second.first, it->second.second, field};
    if (key.back() == ']') {
      const std::size_t open = key.rfind('[');
      if (const auto it = item_marks.find(std::string_view(key).substr(0, open));
          open != std::string::npos && it != item_marks.end()) {
        std::size_t i = 0;
        const auto [end, ec] = std::from_chars(key.data() + open + 1, key.data() + key.size() - 1, i);
        if (ec == std::errc() && end == key.data() + key.size() - 1 && i < it->second.size() && it->second[i].first > 0)
          return Location{file, it->second[i].first, it->second[i].second, field};
      }
    }
    const std::size_t cut = key.find_last_of(".[ ");
    if (cut == std::string::npos || cut == 0) break;
    key.resize(cut);
  }
  return Location{file, 0, 0, field};
}

Error ScenarioSource::located(const Error& e) const {
  const Location& where = e.location();
  if (where.field.empty() || where.line > 0) return e;
  return Error(e.message(), locate(where.field));
}

LoadedScenario parse_scenario(std::string_view text, const std::string& name, const ScenarioReadLimits& limits) {
  if (text.size() > limits.max_file_bytes)
    throw Error(fmt::format("the file is larger than {} bytes", limits.max_file_bytes), Location{name, 1, 1, {}});
  LoadedScenario out;
  out.source.file = name;
  const YAML::Node root = load_yaml(std::string(text), name);
  if (!root || root.IsNull())
    throw Error("the file is empty; a scenario needs at least 'groups'", Location{name, 1, 1, {}});
  try {
    Reader reader(name, limits, out.source);
    out.spec = reader.scenario(root, stem_of(name), out.trajectory_format, out.motion);
  } catch (const YAML::Exception& e) {
    throw yaml_error(e, name);  // yaml-cpp's own checks (e.g. a bad conversion) still get a position
  } catch (const Error& e) {
    throw out.source.located(e);
  }
  return out;
}

std::filesystem::path LoadedScenario::motion_folder() const {
  if (source.file.rfind("builtin:", 0) == 0) return {};
  return std::filesystem::path(source.file).parent_path();
}

LoadedScenario read_scenario_file(const std::string& path, const ScenarioReadLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw Error("cannot read the scenario file: " + ec.message(), Location{path, 0, 0, {}});
  if (size > limits.max_file_bytes)
    throw Error(fmt::format("the file is larger than {} bytes", limits.max_file_bytes), Location{path, 0, 0, {}});
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open the scenario file", Location{path, 0, 0, {}});
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_scenario(ss.str(), path, limits);
}

std::vector<std::string> builtin_scenario_names() { return kBuiltinScenarios.names(); }

std::optional<std::string_view> builtin_scenario_text(std::string_view name) { return kBuiltinScenarios.find(name); }

LoadedScenario load_builtin_scenario(std::string_view name, const ScenarioReadLimits& limits) {
  const auto text = builtin_scenario_text(name);
  if (!text) {
    throw Error(
        fmt::format("no built-in scenario '{}' (built-ins: {})", name, fmt::join(builtin_scenario_names(), ", ")),
        at_field("scenario"));
  }
  LoadedScenario s = parse_scenario(*text, "builtin:" + std::string(name), limits);
  return s;
}

LoadedScenario load_scenario(const std::string& name_or_path, const ScenarioReadLimits& limits) {
  if (builtin_scenario_text(name_or_path)) return load_builtin_scenario(name_or_path, limits);
  std::error_code ec;
  if (std::filesystem::is_regular_file(name_or_path, ec)) return read_scenario_file(name_or_path, limits);
  if (std::filesystem::is_directory(name_or_path, ec))
    throw Error("is a folder, not a scenario file (give the .yaml file inside it)", Location{name_or_path, 0, 0, {}});
  const bool looks_like_path =
      name_or_path.find('/') != std::string::npos || name_or_path.find('.') != std::string::npos;
  if (looks_like_path) throw Error("no such scenario file", Location{name_or_path, 0, 0, {}});
  return load_builtin_scenario(name_or_path, limits);  // throws, listing the built-ins
}

std::unique_ptr<sim::Simulation> build_simulation(const LoadedScenario& scenario,
                                                  const sim::SimulationOptions& options) {
  try {
    // `planning: roadmap` (the default): routes over the Voronoi roadmap for
    // groups with a goal and no waypoints (or the caller's planner);
    // `planning: none`: straight to the goal.
    if (scenario.spec.planning == sim::PlanningKind::None) {
      sim::SimulationOptions straight = options;
      straight.planner = nullptr;
      return std::make_unique<sim::Simulation>(scenario.spec, straight);
    }
    // `planning: field`: a navigation field per target, no routes
    // (`quickest`: weighed again by the crowd's density as it walks).
    if (scenario.spec.planning == sim::PlanningKind::Field || scenario.spec.planning == sim::PlanningKind::Quickest) {
      sim::SimulationOptions fields = options;
      fields.planner = nullptr;
      fields.replanner = nullptr;
      if (fields.fields == nullptr) fields.fields = std::make_shared<const path::FastMarchingFieldBuilder>();
      const auto t0 = std::chrono::steady_clock::now();
      auto simulation = std::make_unique<sim::Simulation>(scenario.spec, fields);
      const sim::NavigationFields& f = simulation->fields();
      if (f.count() > 0)
        spdlog::info("planning: {} navigation field(s) ({:.1f} MB, cell {:.2f} m); world, crowd and fields in {:.2f} s",
                     f.count(), static_cast<double>(f.bytes()) / 1e6, static_cast<double>(f.grid(0).cell),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      return simulation;
    }
    if (options.planner != nullptr) return std::make_unique<sim::Simulation>(scenario.spec, options);
    const auto planner = std::make_shared<const path::RoadmapRoutePlanner>();
    sim::SimulationOptions planned = options;
    planned.planner = planner.get();
    planned.replanner = planner;  // the run keeps it to plan again for agents pushed off their routes
    auto simulation = std::make_unique<sim::Simulation>(scenario.spec, planned);
    if (const path::RoutePlannerStats st = planner->stats(); st.queries > 0)
      spdlog::info(
          "planning: {} of {} agents routed over the roadmap, {} straight, {} without a route ({} roadmap(s) in {:.2f} "
          "s, "
          "queries {:.2f} s)",
          st.planned, st.queries, st.straight, st.fallback, st.roadmaps, st.build_seconds, st.plan_seconds);
    return simulation;
  } catch (const Error& e) {
    throw scenario.source.located(e);
  }
}

}  // namespace throng::io
