#include "io/state_machine_yaml.h"

#include <cmath>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "core/error.h"
#include "io/embedded.h"
#include "io/yaml_fields.h"
#include "motion/default_set.h"

namespace throng::io {

namespace {

struct Reader : YamlFields {
  void expect_map(const YAML::Node& n, const std::string& what) const {
    if (!n.IsMap()) fail(n, what + " must be a mapping");
  }
  std::string string(const YAML::Node& n) const { return scalar(n); }
  std::int32_t integer(const YAML::Node& n, std::int32_t lo, std::int32_t hi) const {
    const double v = number(n, lo, hi);
    if (v != std::floor(v)) fail(n, "expected a whole number");
    return static_cast<std::int32_t>(v);
  }
  bool boolean(const YAML::Node& n) const {
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) fail(n, "expected true or false");
    return v;
  }

  path::ClipSpec clip(const std::string& name, const YAML::Node& n) const {
    expect_map(n, "clip '" + name + "'");
    only_keys(n, {"default", "gait", "speed", "turn_rate_dps", "idle_period_s"});
    path::ClipSpec c;
    c.name = name;
    c.where = where(n);
    c.spec.name = name;
    if (n["default"]) {
      const std::string base = string(n["default"]);
      bool found = false;
      std::string names;
      for (const motion::LocomotionSpec& s : motion::default_motion_specs()) {
        names += (names.empty() ? "" : ", ") + s.name;
        if (s.name == base) {
          c.spec = s;
          c.spec.name = name;
          found = true;
        }
      }
      if (!found) fail(n["default"], "no default motion '" + base + "' (there are: " + names + ")");
    } else if (!n["gait"]) {
      fail(n, "clip '" + name + "' needs 'default' (a clip of the default set) or 'gait'");
    }
    if (n["gait"]) {
      const std::string g = string(n["gait"]);
      if (g == "stand") c.spec.gait = motion::biomech::Gait::Stand;
      else if (g == "walk") c.spec.gait = motion::biomech::Gait::Walk;
      else if (g == "run") c.spec.gait = motion::biomech::Gait::Run;
      else fail(n["gait"], "gait must be stand, walk or run");
      if (c.spec.gait == motion::biomech::Gait::Stand) c.spec.speed = 0;
    }
    if (n["speed"]) c.spec.speed = number(n["speed"], 0, 7);
    if (n["turn_rate_dps"]) c.spec.turn_rate = number(n["turn_rate_dps"], -86, 86) * std::numbers::pi / 180.0;
    if (n["idle_period_s"]) c.spec.idle_period_s = number(n["idle_period_s"], 0.5, 60);
    try {
      c.spec.validate();
    } catch (const Error& e) {
      fail(n, "clip '" + name + "': " + e.message());
    }
    return c;
  }

  path::StateSpec state(const std::string& name, const YAML::Node& n) const {
    expect_map(n, "state '" + name + "'");
    only_keys(n, {"group", "locomotion", "segments"});
    path::StateSpec s;
    s.name = name;
    s.where = where(n);
    if (n["group"]) s.group = string(n["group"]);
    if (n["locomotion"]) s.locomotion = boolean(n["locomotion"]);
    const YAML::Node segs = n["segments"];
    if (!segs || !segs.IsSequence() || segs.size() == 0) fail(n, "state '" + name + "' needs a non-empty list 'segments'");
    for (const auto& seg : segs) {
      expect_map(seg, "a segment");
      only_keys(seg, {"clip", "start", "frames"});
      path::SegmentSpec sp;
      sp.where = where(seg);
      if (!seg["clip"]) fail(seg, "a segment needs 'clip'");
      sp.clip = string(seg["clip"]);
      if (seg["start"]) sp.start_frame = number(seg["start"], 0, 36000);
      if (seg["frames"]) {
        if (s.locomotion) fail(seg["frames"], "a locomotion segment's length is the machine's segment length (points_per_segment x spacing), not frames");
        sp.frames = number(seg["frames"], 1, 36000);
      }
      s.segments.push_back(sp);
    }
    return s;
  }

  path::StateMachineSpec machine(const YAML::Node& root) const {
    path::StateMachineSpec m;
    if (!root.IsMap()) fail(root, "a state machine file must be a mapping");
    only_keys(root, {"name", "fps", "spacing", "points_per_segment", "transition_frames", "pose_weight", "start_state",
                     "end_state", "clips", "groups", "states", "edges"});
    if (root["name"]) m.name = string(root["name"]);
    if (root["fps"]) m.fps = number(root["fps"], 1, 1000);
    if (root["spacing"]) m.spacing = static_cast<float>(number(root["spacing"], 1e-3, 1));
    if (root["points_per_segment"]) m.points_per_segment = integer(root["points_per_segment"], 2, 4096);
    if (root["transition_frames"]) m.transition_frames = integer(root["transition_frames"], 0, 240);
    if (root["pose_weight"]) m.pose_weight = static_cast<float>(number(root["pose_weight"], 0, 1e6));
    if (root["start_state"]) m.start_state = string(root["start_state"]);
    if (root["end_state"]) m.end_state = string(root["end_state"]);
    const YAML::Node clips = root["clips"];
    if (!clips || !clips.IsMap()) fail(root, "a machine needs a mapping 'clips'");
    for (const auto& kv : clips) m.clips.push_back(clip(string(kv.first), kv.second));
    if (const YAML::Node groups = root["groups"]) {
      expect_map(groups, "'groups'");
      for (const auto& kv : groups) {
        path::GroupSpec g;
        g.name = string(kv.first);
        g.where = where(kv.first);
        if (!kv.second.IsNull()) {
          expect_map(kv.second, "group '" + g.name + "'");
          only_keys(kv.second, {"parent"});
          if (kv.second["parent"]) g.parent = string(kv.second["parent"]);
        }
        m.groups.push_back(g);
      }
    }
    const YAML::Node states = root["states"];
    if (!states || !states.IsMap()) fail(root, "a machine needs a mapping 'states'");
    for (const auto& kv : states) m.states.push_back(state(string(kv.first), kv.second));
    if (const YAML::Node edges = root["edges"]) {
      if (!edges.IsSequence()) fail(edges, "'edges' must be a list");
      for (const auto& e : edges) {
        path::EdgeSpec es;
        es.where = where(e);
        if (e.IsSequence()) {
          if (e.size() != 2) fail(e, "an edge is [from, to] or {from, to, cost}");
          es.from = string(e[0]);
          es.to = string(e[1]);
        } else {
          expect_map(e, "an edge");
          only_keys(e, {"from", "to", "cost"});
          if (!e["from"] || !e["to"]) fail(e, "an edge needs 'from' and 'to'");
          es.from = string(e["from"]);
          es.to = string(e["to"]);
          if (e["cost"]) es.cost = static_cast<float>(number(e["cost"], 0, 1e6));
        }
        m.edges.push_back(es);
      }
    }
    return m;
  }
};

}  // namespace

path::StateMachineSpec parse_state_machine(std::string_view text, const std::string& name) {
  const YAML::Node root = load_yaml(std::string(text), name);
  try {
    Reader r;
    r.file = name;
    return r.machine(root);
  } catch (const YAML::Exception& e) {  // conversions of odd scalars
    throw Error(e.msg, at_line(name, e.mark.line + 1, e.mark.column + 1));
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
