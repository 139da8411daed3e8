#include "io/state_machine_yaml.h"

#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/error.h"
#include "io/embedded.h"
#include "io/yaml_reader.h"
#include "motion/default_set.h"

namespace throng::io {

namespace {

constexpr std::size_t kAnyCount = std::numeric_limits<std::size_t>::max();

// The state machine schema over the shared vocabulary (io/yaml_reader.h);
// clips, groups and states are maps by name ("states.walk.segments[0]").
class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;

  path::StateMachineSpec machine(const YAML::Node& root) {
    expect_map(root, "",
               {"name", "fps", "spacing", "points_per_segment", "transition_frames", "pose_weight", "start_state",
                "end_state", "clips", "groups", "states", "edges"});
    path::StateMachineSpec m;
    if (root["name"]) m.name = text(root["name"], "name");
    if (root["fps"]) m.fps = number_in(root["fps"], "fps", 1, 1000);
    if (root["spacing"]) m.spacing = real_in(root["spacing"], "spacing", 1e-3, 1);
    if (root["points_per_segment"])
      m.points_per_segment =
          static_cast<std::int32_t>(integer(root["points_per_segment"], "points_per_segment", 2, 4096));
    if (root["transition_frames"])
      m.transition_frames = static_cast<std::int32_t>(integer(root["transition_frames"], "transition_frames", 0, 240));
    if (root["pose_weight"]) m.pose_weight = real_in(root["pose_weight"], "pose_weight", 0, 1e6);
    if (root["start_state"]) m.start_state = text(root["start_state"], "start_state");
    if (root["end_state"]) m.end_state = text(root["end_state"], "end_state");
    by_name(required(root, "", "clips"), "clips",
            [&](const std::string& name, const YAML::Node& n, const std::string& path) {
              m.clips.push_back(clip(name, n, path));
            });
    if (const YAML::Node groups = root["groups"])
      by_name(groups, "groups", [&](const std::string& name, const YAML::Node& n, const std::string& path) {
        m.groups.push_back(group(name, n, path));
      });
    by_name(required(root, "", "states"), "states",
            [&](const std::string& name, const YAML::Node& n, const std::string& path) {
              m.states.push_back(state(name, n, path));
            });
    if (const YAML::Node edges = root["edges"])
      each_item(edges, "edges", 0, kAnyCount, "edges",
                [&](const YAML::Node& e, const std::string& ep) { m.edges.push_back(edge(e, ep)); });
    return m;
  }

 private:
  // A map of entries by name: f(name, value, key path) for each, in file order.
  template <class F>
  void by_name(const YAML::Node& n, const std::string& path, const F& f) {
    visit(n, path);
    if (!n.IsMap()) fail(n, path, "expected a map of " + path + " by name, got " + kind(n));
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string name = text(it->first, path);
      f(name, it->second, child(path, name));
    }
  }

  // The clip of the default set called `name`.
  motion::LocomotionSpec default_motion(const YAML::Node& n, const std::string& path) {
    const std::string base = text(n, path);
    std::vector<std::string> names;
    for (const motion::LocomotionSpec& s : motion::default_motion_specs()) {
      if (s.name == base) return s;
      names.push_back(s.name);
    }
    fail(n, path, "no default motion " + shown(base) + " (there are: " + join(names) + ")");
  }

  path::ClipSpec clip(const std::string& name, const YAML::Node& n, const std::string& path) {
    expect_map(n, path, {"default", "gait", "speed", "turn_rate_dps", "idle_period_s"});
    path::ClipSpec c;
    c.name = name;
    c.where = where(n, path);
    c.spec.name = name;
    if (n["default"]) {
      c.spec = default_motion(n["default"], child(path, "default"));
      c.spec.name = name;
    } else if (!n["gait"]) {
      fail(n, path, "clip '" + name + "' needs 'default' (a clip of the default set) or 'gait'");
    }
    if (n["gait"]) {
      const std::string g = word(n["gait"], child(path, "gait"), {"stand", "walk", "run"});
      c.spec.gait = g == "stand" ? motion::biomech::Gait::Stand
                                 : (g == "walk" ? motion::biomech::Gait::Walk : motion::biomech::Gait::Run);
      if (c.spec.gait == motion::biomech::Gait::Stand) c.spec.speed = 0;
    }
    if (n["speed"]) c.spec.speed = number_in(n["speed"], child(path, "speed"), 0, 7);
    if (n["turn_rate_dps"])
      c.spec.turn_rate =
          number_in(n["turn_rate_dps"], child(path, "turn_rate_dps"), -86, 86) * std::numbers::pi / 180.0;
    if (n["idle_period_s"]) c.spec.idle_period_s = number_in(n["idle_period_s"], child(path, "idle_period_s"), 0.5, 60);
    at(n, path, [&] { c.spec.validate(); });
    return c;
  }

  path::StateGroupSpec group(const std::string& name, const YAML::Node& n, const std::string& path) {
    path::StateGroupSpec g;
    g.name = name;
    g.where = where(n, path);
    if (!n.IsNull()) {
      expect_map(n, path, {"parent"});
      if (n["parent"]) g.parent = text(n["parent"], child(path, "parent"));
    }
    return g;
  }

  path::StateSpec state(const std::string& name, const YAML::Node& n, const std::string& path) {
    expect_map(n, path, {"group", "locomotion", "segments"});
    path::StateSpec s;
    s.name = name;
    s.where = where(n, path);
    if (n["group"]) s.group = text(n["group"], child(path, "group"));
    if (n["locomotion"]) s.locomotion = loose_boolean(n["locomotion"], child(path, "locomotion"));
    each_item(
        required(n, path, "segments"), child(path, "segments"), 1, kAnyCount, "segments",
        [&](const YAML::Node& seg, const std::string& sp) { s.segments.push_back(segment(seg, sp, s.locomotion)); });
    return s;
  }

  path::SegmentSpec segment(const YAML::Node& seg, const std::string& path, bool locomotion) {
    expect_map(seg, path, {"clip", "start", "frames"});
    path::SegmentSpec sp;
    sp.where = where(seg, path);
    sp.clip = text(required(seg, path, "clip"), child(path, "clip"));
    if (seg["start"]) sp.start_frame = number_in(seg["start"], child(path, "start"), 0, 36000);
    if (seg["frames"]) {
      if (locomotion)
        fail(
            seg["frames"], child(path, "frames"),
            "a locomotion segment's length is the machine's segment length (points_per_segment x spacing), not frames");
      sp.frames = number_in(seg["frames"], child(path, "frames"), 1, 36000);
    }
    return sp;
  }

  // [from, to] or {from, to, cost}.
  path::EdgeSpec edge(const YAML::Node& e, const std::string& path) {
    path::EdgeSpec es;
    es.where = where(e, path);
    if (e.IsSequence()) {
      visit(e, path);
      if (e.size() != 2) fail(e, path, "an edge is [from, to] or {from, to, cost}");
      es.from = text(e[0], item(path, 0));
      es.to = text(e[1], item(path, 1));
      return es;
    }
    expect_map(e, path, {"from", "to", "cost"});
    es.from = text(required(e, path, "from"), child(path, "from"));
    es.to = text(required(e, path, "to"), child(path, "to"));
    if (e["cost"]) es.cost = real_in(e["cost"], child(path, "cost"), 0, 1e6);
    return es;
  }
};

}  // namespace

path::StateMachineSpec parse_state_machine(std::string_view text, const std::string& name) {
  const YAML::Node root = load_yaml(std::string(text), name);
  try {
    return Reader(name).machine(root);
  } catch (const YAML::Exception& e) {  // conversions of odd scalars
    throw yaml_error(e, name);
  }
}

path::StateMachineSpec read_state_machine(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error("cannot open the state machine file", at_line(file, 0));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (ss.str().size() > (16u << 20)) throw Error("state machine file is larger than 16 MiB", at_line(file, 0));
  return parse_state_machine(ss.str(), file);
}

std::string_view default_state_machine_yaml() { return *kBuiltinMotionData.find("default_machine"); }

path::StateMachineSpec default_state_machine_spec() {
  return parse_state_machine(std::string(default_state_machine_yaml()), "default_machine.yaml");
}

}  // namespace throng::io
