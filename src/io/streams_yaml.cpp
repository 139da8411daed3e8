#include "io/streams_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "anim/blend_controller.h"
#include "core/error.h"
#include "io/bvh_reader.h"
#include "io/yaml_fields.h"
#include "motion/default_set.h"

namespace throng::io {

namespace {

using anim::AnimClip;
using anim::Controller;

// Builds a crowd while walking the YAML tree; every error names the node.
class Reader {
 public:
  Reader(std::string name, const StreamsYamlOptions& options) : fields_{std::move(name)}, options_(options) {}

  std::unique_ptr<anim::StreamCrowd> read(const YAML::Node& root) {
    if (!root.IsMap()) fail(root, "expected a mapping with 'rigs', 'clips', 'streams' (see docs/streams.md)");
    keys(root, {"frame_rate", "seed", "events", "rigs", "clips", "streams", "unique"});
    anim::StreamCrowdConfig config;
    if (root["frame_rate"]) config.frame_rate = static_cast<float>(number(root["frame_rate"], 1.0, 1000.0));
    if (root["seed"]) config.seed = static_cast<std::uint64_t>(integer(root["seed"], 0, std::int64_t{1} << 53));
    crowd_ = std::make_unique<anim::StreamCrowd>(config);
    if (root["events"])
      for (const YAML::Node& e : list(root["events"])) wrap(e, [&] { crowd_->event_names().intern(text(e)); });
    const YAML::Node rigs = need(root, "rigs");
    for (const YAML::Node& r : list(rigs)) read_rig(r);
    if (crowd_->rig_count() == 0) fail(rigs, "at least one rig is needed");
    if (root["clips"])
      for (const YAML::Node& c : list(root["clips"])) read_clip(c);
    if (root["streams"])
      for (const YAML::Node& s : list(root["streams"])) read_stream(s);
    if (root["unique"])
      for (const YAML::Node& u : list(root["unique"])) read_unique(u);
    return std::move(crowd_);
  }

 private:
  struct NamedClip {
    AnimClip clip;
    std::int32_t rig = 0;
    bool cycle = false;  // exactly one cycle (a default motion, uncut): no loop search for blends
  };

  // ---- errors and scalars (io/yaml_fields.h, plus what this format needs)
  [[noreturn]] void fail(const YAML::Node& n, const std::string& message) const { fields_.fail(n, message); }

  // Runs f; an Error from the library (which names a field) is reported at n.
  template <class F>
  auto wrap(const YAML::Node& n, F f) -> decltype(f()) {
    try {
      return f();
    } catch (const Error& e) {
      if (e.location().line > 0) throw;
      std::string msg = e.message();
      if (!e.location().field.empty()) msg = e.location().field + ": " + msg;
      fail(n, msg);
    }
  }

  void keys(const YAML::Node& map, std::initializer_list<const char*> allowed) const { fields_.only_keys(map, allowed); }
  YAML::Node need(const YAML::Node& map, const char* key) const {
    const YAML::Node n = map[key];
    if (!n) fail(map, std::string("missing key '") + key + "'");
    return n;
  }
  std::vector<YAML::Node> list(const YAML::Node& n) const {
    if (!n.IsSequence()) fail(n, "expected a list");
    if (n.size() > static_cast<std::size_t>(options_.limits.max_items))
      fail(n, "more than " + std::to_string(options_.limits.max_items) + " items");
    return std::vector<YAML::Node>(n.begin(), n.end());
  }
  std::string text(const YAML::Node& n) const { return fields_.scalar(n); }
  std::string name_of(const YAML::Node& n) const {
    const std::string s = text(n);
    if (s.empty()) fail(n, "a name must not be empty");
    return s;
  }
  double number(const YAML::Node& n, double lo, double hi) const { return fields_.number(n, lo, hi); }
  std::int64_t integer(const YAML::Node& n, std::int64_t lo, std::int64_t hi) const {
    const double v = number(n, static_cast<double>(lo), static_cast<double>(hi));
    if (v != std::floor(v)) fail(n, "expected a whole number, found '" + n.Scalar() + "'");
    return static_cast<std::int64_t>(v);
  }
  bool boolean(const YAML::Node& n) const {
    const std::string s = text(n);
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
    fail(n, "expected true or false, found '" + s + "'");
  }
  std::string path_of(const YAML::Node& n) const {
    const std::filesystem::path p(text(n));
    return p.is_absolute() ? p.string() : (std::filesystem::path(options_.base_dir) / p).string();
  }
  std::int32_t rig_of(const YAML::Node& n) const {
    const std::string r = text(n);
    const std::int32_t i = crowd_->find_rig(r);
    if (i < 0) fail(n, "no rig named '" + r + "'");
    return i;
  }
  void count_pose_bytes(const YAML::Node& n, std::size_t bytes) {
    pose_bytes_ += bytes;
    if (pose_bytes_ > options_.limits.max_pose_bytes)
      fail(n, "pose memory would exceed " + std::to_string(options_.limits.max_pose_bytes) + " bytes (" + std::to_string(pose_bytes_) + ")");
  }

  // ---- rigs
  void read_rig(const YAML::Node& r) {
    if (!r.IsMap()) fail(r, "expected a rig: {name, skeleton: default | bvh: FILE, clusters, unique_capacity}");
    keys(r, {"name", "skeleton", "bvh", "unit", "clusters", "unique_capacity"});
    const std::string name = name_of(need(r, "name"));
    if (crowd_->find_rig(name) >= 0) fail(r["name"], "rig '" + name + "' defined twice");
    motion::Skeleton skeleton;
    if (r["skeleton"] && r["bvh"]) fail(r, "give either 'skeleton: default' or 'bvh: FILE', not both");
    if (r["skeleton"]) {
      if (text(r["skeleton"]) != "default") fail(r["skeleton"], "the only built-in skeleton is 'default'");
      skeleton = motion::default_skeleton();
    } else if (r["bvh"]) {
      skeleton = read_bvh_at(r["bvh"], r["unit"]).skeleton;
    } else {
      fail(r, "a rig needs 'skeleton: default' or 'bvh: FILE'");
    }
    std::vector<anim::ClusterDef> clusters;
    if (r["clusters"])
      for (const YAML::Node& c : list(r["clusters"])) clusters.push_back(read_cluster(c));
    const std::int32_t index = wrap(r, [&] { return crowd_->add_rig(anim::make_rig(name, std::move(skeleton), std::move(clusters))); });
    if (r["unique_capacity"]) {
      const auto cap = static_cast<std::int32_t>(integer(r["unique_capacity"], 0, 1 << 24));
      const anim::Rig& rig = crowd_->rig(index);
      count_pose_bytes(r["unique_capacity"], static_cast<std::size_t>(cap) * anim::pose_slot_bytes(rig.joint_count()));
      wrap(r["unique_capacity"], [&] { crowd_->uniques().set_capacity(rig, index, cap); });
    }
  }

  anim::ClusterDef read_cluster(const YAML::Node& c) {
    if (!c.IsMap()) fail(c, "expected a cluster: {name, roots: [joint...], hook_rotation_deg: [x, y, z], hook_translation: [x, y, z]}");
    keys(c, {"name", "roots", "hook_rotation_deg", "hook_translation"});
    anim::ClusterDef d;
    d.name = name_of(need(c, "name"));
    for (const YAML::Node& j : list(need(c, "roots"))) d.roots.push_back(name_of(j));
    if (c["hook_rotation_deg"]) {
      const glm::dvec3 e = vec3(c["hook_rotation_deg"], -360.0, 360.0) * (3.14159265358979323846 / 180.0);
      d.hook_rotation = glm::quat(glm::dquat(glm::dvec3(e)));
    }
    if (c["hook_translation"]) d.hook_translation = glm::vec3(vec3(c["hook_translation"], -100.0, 100.0));
    return d;
  }

  glm::dvec3 vec3(const YAML::Node& n, double lo, double hi) const {
    if (!n.IsSequence() || n.size() != 3) fail(n, "expected [x, y, z]");
    return {number(n[0], lo, hi), number(n[1], lo, hi), number(n[2], lo, hi)};
  }

  BvhFile read_bvh_at(const YAML::Node& file, const YAML::Node& unit) const {
    BvhReadOptions o;
    if (unit) {
      o.unit = motion::parse_length_unit(text(unit));
      if (!o.unit) fail(unit, "unknown unit '" + text(unit) + "' (m, cm, mm, in, cmu)");
    }
    if (!options_.allow_files) fail(file, "reading files is not allowed here");
    const std::string path = path_of(file);
    try {
      return read_bvh(path, o);
    } catch (const Error& e) {
      fail(file, "cannot read '" + path + "': " + e.what());
    }
  }

  // ---- clips
  void read_clip(const YAML::Node& c) {
    if (!c.IsMap()) fail(c, "expected a clip: {name, rig, default: NAME | bvh: FILE, frames, loop, footsteps, events}");
    keys(c, {"name", "rig", "default", "bvh", "unit", "frames", "loop", "footsteps", "events"});
    const std::string name = name_of(need(c, "name"));
    if (clips_.count(name)) fail(c["name"], "clip '" + name + "' defined twice");
    NamedClip out;
    out.rig = rig_of(need(c, "rig"));
    const anim::Rig& rig = crowd_->rig(out.rig);
    out.clip.name = name;
    motion::Clip clip;
    if (c["default"] && c["bvh"]) fail(c, "give either 'default: NAME' or 'bvh: FILE', not both");
    if (c["default"]) {
      const std::string motion_name = text(c["default"]);
      const auto specs = motion::default_motion_specs();
      std::string known;
      for (const auto& s : specs) {
        known.append(known.empty() ? "" : ", ").append(s.name);
        if (s.name == motion_name)
          clip = wrap(c["default"], [&] { return motion::LocomotionGenerator(rig.skeleton, s).make_clip(); });
      }
      if (clip.frame_count == 0) fail(c["default"], "no default motion '" + motion_name + "' (known: " + known + ")");
    } else if (c["bvh"]) {
      BvhFile f = read_bvh_at(c["bvh"], c["unit"]);
      if (f.skeleton.names != rig.skeleton.names)
        fail(c["bvh"], "its skeleton (" + std::to_string(f.skeleton.joint_count()) + " joints) is not rig '" + rig.name + "'s (" +
                           std::to_string(rig.joint_count()) + " joints, same names in the same order needed)");
      clip = std::move(f.clip);
    } else {
      fail(c, "a clip needs 'default: NAME' or 'bvh: FILE'");
    }
    out.cycle = c["default"] && !c["frames"];
    if (c["frames"]) {
      const YAML::Node fr = c["frames"];
      if (!fr.IsSequence() || fr.size() != 2) fail(fr, "expected [first, end): frames first..end-1");
      const auto first = static_cast<std::int32_t>(integer(fr[0], 0, clip.frame_count - 1));
      const auto end = static_cast<std::int32_t>(integer(fr[1], first + 1, clip.frame_count));
      motion::Clip cut;
      cut.resize(end - first, clip.joint_count);
      cut.frame_time = clip.frame_time;
      for (std::int32_t f = first; f < end; ++f) {
        for (std::int32_t j = 0; j < clip.joint_count; ++j) cut.rotation(f - first, j) = clip.rotation(f, j);
        cut.root_positions[static_cast<std::size_t>(f - first)] = clip.root_positions[static_cast<std::size_t>(f)];
      }
      clip = std::move(cut);
    }
    out.clip.clip = std::make_shared<motion::Clip>(std::move(clip));
    out.clip.loop = c["loop"] ? boolean(c["loop"]) : true;
    if (c["footsteps"] && boolean(c["footsteps"]))
      out.clip.events = wrap(c["footsteps"], [&] { return anim::footstep_events(rig.skeleton, out.clip, crowd_->event_names()); });
    if (c["events"]) {
      for (const YAML::Node& e : list(c["events"])) {
        if (!e.IsMap()) fail(e, "expected an event: {name, time}");
        keys(e, {"name", "time"});
        anim::ClipEvent ev;
        ev.id = wrap(e, [&] { return crowd_->event_names().intern(name_of(need(e, "name"))); });
        ev.time = static_cast<float>(number(need(e, "time"), 0.0, out.clip.duration()));
        out.clip.events.push_back(ev);
      }
      std::stable_sort(out.clip.events.begin(), out.clip.events.end(), [](const auto& a, const auto& b) { return a.time < b.time; });
    }
    wrap(c, [&] { out.clip.validate(); });
    clips_[name] = std::move(out);
  }

  const NamedClip& named_clip(const YAML::Node& n, std::int32_t rig) const {
    const std::string name = text(n);
    auto it = clips_.find(name);
    if (it == clips_.end()) fail(n, "no clip named '" + name + "'");
    if (it->second.rig != rig)
      fail(n, "clip '" + name + "' is of rig '" + crowd_->rig(it->second.rig).name + "', not '" + crowd_->rig(rig).name + "'");
    return it->second;
  }
  const AnimClip& clip_of(const YAML::Node& n, std::int32_t rig) const { return named_clip(n, rig).clip; }

  // ---- blend spaces (shared by every controller that names the same clips)
  motion::LocomotionClip prepared(const YAML::Node& n, std::int32_t rig) {
    const NamedClip& c = named_clip(n, rig);
    const motion::Skeleton& skeleton = crowd_->rig(rig).skeleton;
    motion::LocomotionOptions options;
    options.clean_contacts = !c.cycle;  // the default motions are planted by construction
    return wrap(n, [&] {
      return c.cycle ? motion::prepare_locomotion_cycle(skeleton, *c.clip.clip, c.clip.name, options)
                     : motion::prepare_locomotion_clip(skeleton, *c.clip.clip, c.clip.name, options);
    });
  }

  bool is_default_skeleton(std::int32_t rig) const { return crowd_->rig(rig).skeleton.names == motion::default_skeleton().names; }

  // `space: default` or `clips: [NAME...]` (straight locomotion clips of the rig, by speed).
  std::shared_ptr<const motion::BlendSpace1D> speed_space(const YAML::Node& n, std::int32_t rig, bool plant_feet) {
    if (n["space"] && n["clips"]) fail(n, "give either 'space: default' or 'clips: [...]', not both");
    if (n["space"]) {
      if (text(n["space"]) != "default") fail(n["space"], "the only built-in blend space is 'default'");
      if (!is_default_skeleton(rig)) fail(n["space"], "the default blend space needs a rig with 'skeleton: default'");
      if (!plant_feet) fail(n["plant_feet"], "the default blend space plants feet; give 'clips' to turn it off");
      return anim::default_blend_spaces().speeds;
    }
    const YAML::Node clips = need(n, "clips");
    std::string key = std::to_string(rig) + (plant_feet ? "|ik" : "|free");
    for (const YAML::Node& c : list(clips)) key += "|" + text(c);
    auto found = spaces_.find(key);
    if (found != spaces_.end()) return found->second;
    std::vector<motion::LocomotionClip> prepared_clips;
    for (const YAML::Node& c : list(clips)) prepared_clips.push_back(prepared(c, rig));
    motion::BlendSpaceOptions options;
    options.plant_feet = plant_feet;
    auto space = wrap(clips, [&] {
      return std::make_shared<const motion::BlendSpace1D>(crowd_->rig(rig).skeleton, std::move(prepared_clips), options);
    });
    spaces_[key] = space;
    return space;
  }

  std::shared_ptr<const motion::BlendSpace1D> turn_space(const YAML::Node& n, std::int32_t rig) {
    const std::string key = std::to_string(rig) + "|turn|" + text(n);
    auto found = spaces_.find(key);
    if (found != spaces_.end()) return found->second;
    const NamedClip& c = named_clip(n, rig);
    auto space = wrap(n, [&] { return anim::make_turn_space(crowd_->rig(rig).skeleton, *c.clip.clip, c.clip.name, c.cycle); });
    spaces_[key] = space;
    return space;
  }

  void footstep_ids(const YAML::Node& n, std::int32_t& left, std::int32_t& right) {
    if (!n || !boolean(n)) return;
    left = wrap(n, [&] { return crowd_->event_names().intern("footstep_left"); });
    right = wrap(n, [&] { return crowd_->event_names().intern("footstep_right"); });
  }

  std::unique_ptr<Controller> blend1d(const YAML::Node& n, std::int32_t rig) {
    if (!n.IsMap()) fail(n, "expected {clips: [NAME...] | space: default, parameter, speed, phase, footsteps, plant_feet}");
    keys(n, {"clips", "space", "parameter", "speed", "phase", "footsteps", "plant_feet"});
    anim::Blend1DOptions o;
    if (n["parameter"]) o.parameter = name_of(n["parameter"]);
    if (n["speed"]) o.speed = static_cast<float>(number(n["speed"], 0.0, 100.0));
    if (n["phase"]) o.start_phase = static_cast<float>(number(n["phase"], 0.0, 0.999999));
    footstep_ids(n["footsteps"], o.footstep_left, o.footstep_right);
    const bool plant = n["plant_feet"] ? boolean(n["plant_feet"]) : true;
    auto space = speed_space(n, rig, plant);
    return wrap(n, [&] { return std::make_unique<anim::Blend1DController>(std::move(space), o); });
  }

  std::unique_ptr<Controller> blend2d(const YAML::Node& n, std::int32_t rig) {
    if (!n.IsMap())
      fail(n, "expected {clips: [NAME...] | space: default, turn_left: CLIP, turn_right: CLIP, speed_parameter, turn_parameter, speed, turn, "
              "phase, footsteps, plant_feet}");
    keys(n, {"clips", "space", "turn_left", "turn_right", "speed_parameter", "turn_parameter", "speed", "turn", "phase", "footsteps",
             "plant_feet"});
    anim::Blend2DOptions o;
    if (n["speed_parameter"]) o.speed_parameter = name_of(n["speed_parameter"]);
    if (n["turn_parameter"]) o.turn_parameter = name_of(n["turn_parameter"]);
    if (n["speed"]) o.speed = static_cast<float>(number(n["speed"], 0.0, 100.0));
    if (n["turn"]) o.turn = static_cast<float>(number(n["turn"], -100.0, 100.0));
    if (n["phase"]) o.start_phase = static_cast<float>(number(n["phase"], 0.0, 0.999999));
    footstep_ids(n["footsteps"], o.footstep_left, o.footstep_right);
    const bool plant = n["plant_feet"] ? boolean(n["plant_feet"]) : true;
    auto speeds = speed_space(n, rig, plant);
    std::shared_ptr<const motion::BlendSpace1D> left, right;
    if (n["space"] && !n["turn_left"] && !n["turn_right"]) {
      left = anim::default_blend_spaces().turn_left;
      right = anim::default_blend_spaces().turn_right;
    } else {
      left = turn_space(need(n, "turn_left"), rig);
      right = turn_space(need(n, "turn_right"), rig);
    }
    return wrap(n, [&] { return std::make_unique<anim::Blend2DController>(std::move(speeds), std::move(left), std::move(right), o); });
  }

  // ---- controllers
  std::unique_ptr<Controller> controller(const YAML::Node& n, std::int32_t rig, int depth) {
    if (depth > options_.limits.max_controller_depth) fail(n, "controllers nested deeper than " + std::to_string(options_.limits.max_controller_depth));
    if (!n.IsMap()) fail(n, "expected a controller: {clip: NAME, rate}, {blend1d: ...}, {blend2d: ...}, {layered: ...} or {state_machine: ...}");
    if (n["clip"]) {
      keys(n, {"clip", "rate", "start"});
      const float rate = n["rate"] ? static_cast<float>(number(n["rate"], -100.0, 100.0)) : 1.0f;
      const double start = n["start"] ? number(n["start"], -1e6, 1e6) : 0.0;
      const AnimClip& clip = clip_of(n["clip"], rig);
      return wrap(n, [&] { return std::make_unique<anim::ClipPlayer>(clip, rate, start); });
    }
    if (n["blend1d"]) {
      keys(n, {"blend1d"});
      return blend1d(n["blend1d"], rig);
    }
    if (n["blend2d"]) {
      keys(n, {"blend2d"});
      return blend2d(n["blend2d"], rig);
    }
    if (n["layered"]) {
      keys(n, {"layered"});
      return layered(n["layered"], rig, depth);
    }
    if (n["state_machine"]) {
      keys(n, {"state_machine"});
      return state_machine(n["state_machine"], rig, depth);
    }
    fail(n, "a controller needs one of 'clip', 'blend1d', 'blend2d', 'layered', 'state_machine'");
  }

  std::unique_ptr<Controller> layered(const YAML::Node& n, std::int32_t rig, int depth) {
    if (!n.IsMap()) fail(n, "expected {base: CONTROLLER, layers: [...]}");
    keys(n, {"base", "layers"});
    auto out = std::make_unique<anim::LayeredController>(controller(need(n, "base"), rig, depth + 1));
    const motion::Skeleton& skeleton = crowd_->rig(rig).skeleton;
    if (n["layers"])
      for (const YAML::Node& l : list(n["layers"])) {
        if (!l.IsMap()) fail(l, "expected a layer: {controller, mode, weight, weight_parameter, mask, mask_weight, reference}");
        keys(l, {"controller", "mode", "weight", "weight_parameter", "mask", "mask_weight", "reference"});
        anim::Layer layer;
        layer.controller = controller(need(l, "controller"), rig, depth + 1);
        if (l["mode"]) {
          const std::string m = text(l["mode"]);
          if (m == "override")
            layer.mode = anim::LayerMode::Override;
          else if (m == "additive")
            layer.mode = anim::LayerMode::Additive;
          else
            fail(l["mode"], "expected 'override' or 'additive', found '" + m + "'");
        }
        if (l["weight"]) layer.weight = static_cast<float>(number(l["weight"], 0.0, 1.0));
        if (l["weight_parameter"]) layer.weight_parameter = name_of(l["weight_parameter"]);
        const float mask_weight = l["mask_weight"] ? static_cast<float>(number(l["mask_weight"], 0.0, 1.0)) : 1.0f;
        if (l["mask"]) {
          std::vector<std::string> roots;
          for (const YAML::Node& j : list(l["mask"])) roots.push_back(name_of(j));
          layer.mask = wrap(l["mask"], [&] { return anim::BoneMask::subtrees(skeleton, roots, mask_weight); });
        } else {
          layer.mask = anim::BoneMask::all(skeleton.joint_count(), mask_weight);
        }
        if (l["reference"]) {
          const YAML::Node r = l["reference"];
          if (!r.IsMap()) fail(r, "expected {clip: NAME, time: SECONDS}");
          keys(r, {"clip", "time"});
          const AnimClip& clip = clip_of(need(r, "clip"), rig);
          anim::Pose p;
          anim::sample_clip(clip, r["time"] ? number(r["time"], 0.0, 1e6) : 0.0, p);
          layer.reference = p.local;
        }
        wrap(l, [&] { out->add_layer(std::move(layer)); });
      }
    return out;
  }

  anim::Condition condition(const YAML::Node& n) const {
    // "speed > 0.5", "turn<=-0.2", "waiting" (!= 0), "!waiting" (== 0).
    const std::string s = text(n);
    std::size_t i = 0;
    auto skip = [&] {
      while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    };
    skip();
    bool negated = false;
    if (i < s.size() && s[i] == '!') {
      negated = true;
      ++i;
      skip();
    }
    const std::size_t start = i;
    while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_')) ++i;
    anim::Condition c;
    c.parameter = s.substr(start, i - start);
    if (c.parameter.empty()) fail(n, "expected 'parameter OP value' (OP one of < <= > >= == !=) or '[!]parameter', found '" + s + "'");
    skip();
    if (i == s.size()) {
      c.op = negated ? anim::Compare::Equal : anim::Compare::NotEqual;
      c.value = 0.0f;
      return c;
    }
    if (negated) fail(n, "'!' only goes before a lone parameter: '" + s + "'");
    static const std::pair<const char*, anim::Compare> ops[] = {{"<=", anim::Compare::LessEqual}, {">=", anim::Compare::GreaterEqual},
                                                                {"==", anim::Compare::Equal},     {"!=", anim::Compare::NotEqual},
                                                                {"<", anim::Compare::Less},       {">", anim::Compare::Greater}};
    bool found = false;
    for (const auto& [text_op, op] : ops)
      if (s.compare(i, std::char_traits<char>::length(text_op), text_op) == 0) {
        c.op = op;
        i += std::char_traits<char>::length(text_op);
        found = true;
        break;
      }
    if (!found) fail(n, "expected a comparison (< <= > >= == !=) after '" + c.parameter + "' in '" + s + "'");
    skip();
    const std::string rest = s.substr(i);
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(rest, &used);
    } catch (const std::exception&) {
      fail(n, "expected a number after the comparison in '" + s + "'");
    }
    while (used < rest.size() && std::isspace(static_cast<unsigned char>(rest[used]))) ++used;
    if (used != rest.size() || !std::isfinite(v)) fail(n, "expected a finite number after the comparison in '" + s + "'");
    c.value = static_cast<float>(v);
    return c;
  }

  std::unique_ptr<Controller> state_machine(const YAML::Node& n, std::int32_t rig, int depth) {
    if (!n.IsMap()) fail(n, "expected {initial, states: [...], transitions: [...]}");
    keys(n, {"initial", "states", "transitions"});
    auto sm = std::make_unique<anim::StateMachine>();
    for (const YAML::Node& s : list(need(n, "states"))) {
      if (!s.IsMap()) fail(s, "expected a state: {name, controller, on_enter}");
      keys(s, {"name", "controller", "on_enter"});
      const std::string name = name_of(need(s, "name"));
      std::int32_t event = -1;
      if (s["on_enter"]) event = wrap(s["on_enter"], [&] { return crowd_->event_names().intern(name_of(s["on_enter"])); });
      auto ctl = controller(need(s, "controller"), rig, depth + 1);
      wrap(s, [&] { sm->add_state(name, std::move(ctl), event); });
    }
    auto state = [&](const YAML::Node& x) {
      const std::string name = text(x);
      if (name == "any") return anim::StateMachine::kAnyState;
      const std::int32_t i = sm->find_state(name);
      if (i < 0) fail(x, "no state named '" + name + "'");
      return i;
    };
    if (n["transitions"])
      for (const YAML::Node& t : list(n["transitions"])) {
        if (!t.IsMap()) fail(t, "expected a transition: {from, to, when: [CONDITION...], fade}");
        keys(t, {"from", "to", "when", "fade"});
        const std::int32_t from = state(need(t, "from"));
        const std::int32_t to = state(need(t, "to"));
        if (to == anim::StateMachine::kAnyState) fail(t["to"], "a transition goes to a named state");
        std::vector<anim::Condition> when;
        if (t["when"]) {
          if (t["when"].IsScalar())
            when.push_back(condition(t["when"]));
          else
            for (const YAML::Node& c : list(t["when"])) when.push_back(condition(c));
        }
        const float fade = t["fade"] ? static_cast<float>(number(t["fade"], 0.0, 1e3)) : 0.2f;
        wrap(t, [&] { sm->add_transition(from, to, std::move(when), fade); });
      }
    if (n["initial"]) {
      const std::int32_t i = state(n["initial"]);
      if (i < 0) fail(n["initial"], "the initial state must be a named state");
      sm->set_initial_state(i);
    }
    return sm;
  }

  anim::RootMotion root_motion(const YAML::Node& n) const {
    const std::string s = text(n);
    if (s == "in_place") return anim::RootMotion::InPlace;
    if (s == "keep") return anim::RootMotion::Keep;
    fail(n, "expected 'in_place' or 'keep', found '" + s + "'");
  }

  // ---- streams and unique animations
  void read_stream(const YAML::Node& s) {
    if (!s.IsMap()) fail(s, "expected a stream: {name, rig, history, root, time_to_dilate, running, parameters, controller}");
    keys(s, {"name", "rig", "history", "root", "time_to_dilate", "running", "parameters", "controller"});
    anim::StreamSpec spec;
    spec.name = name_of(need(s, "name"));
    if (crowd_->streams().find(spec.name) >= 0) fail(s["name"], "stream '" + spec.name + "' defined twice");
    spec.rig = rig_of(need(s, "rig"));
    if (s["history"]) spec.history = static_cast<std::int32_t>(integer(s["history"], 1, 65536));
    if (s["root"]) spec.root = root_motion(s["root"]);
    if (s["time_to_dilate"]) spec.time_to_dilate = static_cast<float>(number(s["time_to_dilate"], 0.0, 1e6));
    if (s["running"]) spec.running = boolean(s["running"]);
    const anim::Rig& rig = crowd_->rig(spec.rig);
    count_pose_bytes(s, static_cast<std::size_t>(spec.history) * anim::pose_slot_bytes(rig.joint_count()));
    auto ctl = controller(need(s, "controller"), spec.rig, 0);
    const std::int32_t index = wrap(s, [&] { return crowd_->streams().add(rig, spec.rig, spec, std::move(ctl)); });
    if (s["parameters"]) {
      const YAML::Node p = s["parameters"];
      if (!p.IsMap()) fail(p, "expected {name: value, ...}");
      for (auto it = p.begin(); it != p.end(); ++it)
        crowd_->streams()[index].parameters().set(name_of(it->first), static_cast<float>(number(it->second, -1e9, 1e9)));
    }
  }

  void read_unique(const YAML::Node& u) {
    if (!u.IsMap()) fail(u, "expected a unique animation: {name, rig, root, controller}");
    keys(u, {"name", "rig", "root", "controller"});
    anim::UniqueAnimation a;
    a.name = name_of(need(u, "name"));
    if (crowd_->uniques().find_animation(a.name) >= 0) fail(u["name"], "unique animation '" + a.name + "' defined twice");
    a.rig = rig_of(need(u, "rig"));
    a.root = u["root"] ? root_motion(u["root"]) : anim::RootMotion::InPlace;
    if (crowd_->uniques().capacity(a.rig) == 0) fail(u["rig"], "rig '" + crowd_->rig(a.rig).name + "' has no unique_capacity");
    a.controller = controller(need(u, "controller"), a.rig, 0);
    wrap(u, [&] { crowd_->uniques().add_animation(std::move(a)); });
  }

  YamlFields fields_;
  StreamsYamlOptions options_;
  std::unique_ptr<anim::StreamCrowd> crowd_;
  std::map<std::string, NamedClip> clips_;
  std::map<std::string, std::shared_ptr<const motion::BlendSpace1D>> spaces_;
  std::size_t pose_bytes_ = 0;
};

}  // namespace

std::unique_ptr<anim::StreamCrowd> parse_stream_crowd(std::string_view text, const std::string& name, const StreamsYamlOptions& options) {
  if (text.size() > options.limits.max_file_bytes)
    throw Error("file is larger than " + std::to_string(options.limits.max_file_bytes) + " bytes", at_line(name, 0, 0));
  const YAML::Node root = load_yaml(std::string(text), name);
  try {
    return Reader(name, options).read(root);
  } catch (const YAML::Exception& e) {
    throw Error(e.msg, at_line(name, e.mark.is_null() ? 0 : e.mark.line + 1, e.mark.is_null() ? 0 : e.mark.column + 1));
  }
}

std::unique_ptr<anim::StreamCrowd> load_stream_crowd(const std::string& path, StreamsYamlLimits limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw Error("cannot read: " + ec.message(), at_line(path, 0, 0));
  if (size > limits.max_file_bytes) throw Error("file is larger than " + std::to_string(limits.max_file_bytes) + " bytes", at_line(path, 0, 0));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open", at_line(path, 0, 0));
  std::ostringstream text;
  text << in.rdbuf();
  StreamsYamlOptions options;
  options.limits = limits;
  options.base_dir = std::filesystem::path(path).parent_path().string();
  if (options.base_dir.empty()) options.base_dir = ".";
  return parse_stream_crowd(text.str(), path, options);
}

}  // namespace throng::io
