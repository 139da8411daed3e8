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
#include "io/yaml_reader.h"
#include "motion/default_set.h"

namespace throng::io {

namespace {

using anim::AnimClip;
using anim::Controller;

// Builds a crowd while walking the YAML tree over the shared vocabulary
// (io/yaml_reader.h); every error names the node and its key path
// ("streams[2].controller.blend1d.speed").
class Reader : public YamlReader {
 public:
  Reader(std::string name, const StreamsYamlOptions& options) : YamlReader(std::move(name)), options_(options) {}

  std::unique_ptr<anim::StreamCrowd> read(const YAML::Node& root) {
    if (!root.IsMap())
      fail(root, "", "expected a mapping with 'rigs', 'clips', 'streams' (see docs/streams.md), got " + kind(root));
    keys_of(root, "", {"frame_rate", "seed", "events", "rigs", "clips", "streams", "unique"});
    anim::StreamCrowdConfig config;
    if (root["frame_rate"]) config.frame_rate = real_in(root["frame_rate"], "frame_rate", 1.0, 1000.0);
    if (root["seed"]) config.seed = static_cast<std::uint64_t>(integer(root["seed"], "seed", 0, std::int64_t{1} << 53));
    crowd_ = std::make_unique<anim::StreamCrowd>(config);
    each(root["events"], "events", [&](const YAML::Node& e, const std::string& path) {
      at(e, path, [&] { crowd_->event_names().intern(text(e, path)); });
    });
    const YAML::Node rigs = required(root, "", "rigs");
    each(rigs, "rigs", [&](const YAML::Node& r, const std::string& path) { read_rig(r, path); });
    if (crowd_->rig_count() == 0) fail(rigs, "rigs", "at least one rig is needed");
    each(root["clips"], "clips", [&](const YAML::Node& c, const std::string& path) { read_clip(c, path); });
    each(root["streams"], "streams", [&](const YAML::Node& s, const std::string& path) { read_stream(s, path); });
    each(root["unique"], "unique", [&](const YAML::Node& u, const std::string& path) { read_unique(u, path); });
    return std::move(crowd_);
  }

 private:
  struct NamedClip {
    AnimClip clip;
    std::int32_t rig = 0;
    bool cycle = false;  // exactly one cycle (a default motion, uncut): no loop search for blends
  };

  // ---- what this format adds to the shared vocabulary
  // f(item, its key path) for each item of list n (none when n is absent).
  template <class F>
  void each(const YAML::Node& n, const std::string& path, const F& f) {
    if (n) each_item(n, path, 0, static_cast<std::size_t>(options_.limits.max_items), "items", f);
  }
  std::string name_of(const YAML::Node& n, const std::string& path) {
    const std::string s = text(n, path);
    if (s.empty()) fail(n, path, "a name must not be empty");
    return s;
  }
  std::vector<std::string> names_of(const YAML::Node& n, const std::string& path) {
    std::vector<std::string> out;
    each(n, path, [&](const YAML::Node& j, const std::string& jp) { out.push_back(name_of(j, jp)); });
    return out;
  }
  std::string path_of(const YAML::Node& n, const std::string& path) {
    const std::filesystem::path p(text(n, path));
    return p.is_absolute() ? p.string() : (std::filesystem::path(options_.base_dir) / p).string();
  }
  std::int32_t rig_of(const YAML::Node& n, const std::string& path) {
    const std::string r = text(n, path);
    const std::int32_t i = crowd_->find_rig(r);
    if (i < 0) fail(n, path, "no rig named '" + r + "'");
    return i;
  }
  void count_pose_bytes(const YAML::Node& n, const std::string& path, std::size_t bytes) {
    pose_bytes_ += bytes;
    if (pose_bytes_ > options_.limits.max_pose_bytes)
      fail(n, path,
           "pose memory would exceed " + std::to_string(options_.limits.max_pose_bytes) + " bytes (" +
               std::to_string(pose_bytes_) + ")");
  }

  // ---- rigs
  void read_rig(const YAML::Node& r, const std::string& path) {
    if (!r.IsMap())
      fail(r, path, "expected a rig: {name, skeleton: default | bvh: FILE, clusters, unique_capacity}, got " + kind(r));
    keys_of(r, path, {"name", "skeleton", "bvh", "unit", "clusters", "unique_capacity"});
    const std::string name = name_of(required(r, path, "name"), child(path, "name"));
    if (crowd_->find_rig(name) >= 0) fail(r["name"], child(path, "name"), "rig '" + name + "' defined twice");
    motion::Skeleton skeleton;
    if (r["skeleton"] && r["bvh"]) fail(r, path, "give either 'skeleton: default' or 'bvh: FILE', not both");
    if (r["skeleton"]) {
      const std::string sp = child(path, "skeleton");
      if (text(r["skeleton"], sp) != "default") fail(r["skeleton"], sp, "the only built-in skeleton is 'default'");
      skeleton = motion::default_skeleton();
    } else if (r["bvh"]) {
      skeleton = read_bvh_at(r, path).skeleton;
    } else {
      fail(r, path, "a rig needs 'skeleton: default' or 'bvh: FILE'");
    }
    std::vector<anim::ClusterDef> clusters;
    each(r["clusters"], child(path, "clusters"),
         [&](const YAML::Node& c, const std::string& cp) { clusters.push_back(read_cluster(c, cp)); });
    const std::int32_t index =
        at(r, path, [&] { return crowd_->add_rig(anim::make_rig(name, std::move(skeleton), std::move(clusters))); });
    if (const YAML::Node capacity = r["unique_capacity"]) {
      const std::string cp = child(path, "unique_capacity");
      const auto cap = static_cast<std::int32_t>(integer(capacity, cp, 0, 1 << 24));
      const anim::Rig& rig = crowd_->rig(index);
      count_pose_bytes(capacity, cp, static_cast<std::size_t>(cap) * anim::pose_slot_bytes(rig.joint_count()));
      at(capacity, cp, [&] { crowd_->uniques().set_capacity(rig, index, cap); });
    }
  }

  anim::ClusterDef read_cluster(const YAML::Node& c, const std::string& path) {
    if (!c.IsMap())
      fail(c, path,
           "expected a cluster: {name, roots: [joint...], hook_rotation_deg: [x, y, z], hook_translation: [x, y, z]}, "
           "got " +
               kind(c));
    keys_of(c, path, {"name", "roots", "hook_rotation_deg", "hook_translation"});
    anim::ClusterDef d;
    d.name = name_of(required(c, path, "name"), child(path, "name"));
    d.roots = names_of(required(c, path, "roots"), child(path, "roots"));
    if (c["hook_rotation_deg"]) {
      const glm::dvec3 e = vec3(c["hook_rotation_deg"], child(path, "hook_rotation_deg"), -360.0, 360.0) *
                           (3.14159265358979323846 / 180.0);
      d.hook_rotation = glm::quat(glm::dquat(glm::dvec3(e)));
    }
    if (c["hook_translation"])
      d.hook_translation = glm::vec3(vec3(c["hook_translation"], child(path, "hook_translation"), -100.0, 100.0));
    return d;
  }

  glm::dvec3 vec3(const YAML::Node& n, const std::string& path, double lo, double hi) {
    if (!n.IsSequence() || n.size() != 3) fail(n, path, "expected [x, y, z], got " + kind(n));
    return {number_in(n[0], item(path, 0), lo, hi), number_in(n[1], item(path, 1), lo, hi),
            number_in(n[2], item(path, 2), lo, hi)};
  }

  // The BVH file of map n's `bvh`, in n's `unit` when given.
  BvhFile read_bvh_at(const YAML::Node& n, const std::string& path) {
    BvhReadOptions o;
    if (const YAML::Node unit = n["unit"]) {
      const std::string u = text(unit, child(path, "unit"));
      o.unit = motion::parse_length_unit(u);
      if (!o.unit) fail(unit, child(path, "unit"), "unknown unit '" + u + "' (m, cm, mm, in, cmu)");
    }
    const YAML::Node file = n["bvh"];
    if (!options_.allow_files) fail(file, child(path, "bvh"), "reading files is not allowed here");
    const std::string bvh = path_of(file, child(path, "bvh"));
    try {
      return read_bvh(bvh, o);
    } catch (const Error& e) {
      fail(file, child(path, "bvh"), "cannot read '" + bvh + "': " + e.what());
    }
  }

  // ---- clips
  void read_clip(const YAML::Node& c, const std::string& path) {
    if (!c.IsMap())
      fail(c, path,
           "expected a clip: {name, rig, default: NAME | bvh: FILE, frames, loop, footsteps, events}, got " + kind(c));
    keys_of(c, path, {"name", "rig", "default", "bvh", "unit", "frames", "loop", "footsteps", "events"});
    const std::string name = name_of(required(c, path, "name"), child(path, "name"));
    if (clips_.count(name)) fail(c["name"], child(path, "name"), "clip '" + name + "' defined twice");
    NamedClip out;
    out.rig = rig_of(required(c, path, "rig"), child(path, "rig"));
    const anim::Rig& rig = crowd_->rig(out.rig);
    out.clip.name = name;
    motion::Clip clip = source_clip(c, path, rig);
    out.cycle = c["default"] && !c["frames"];
    if (c["frames"]) clip = frames_of(c["frames"], child(path, "frames"), clip);
    out.clip.clip = std::make_shared<motion::Clip>(std::move(clip));
    out.clip.loop = c["loop"] ? loose_boolean(c["loop"], child(path, "loop")) : true;
    if (c["footsteps"] && loose_boolean(c["footsteps"], child(path, "footsteps")))
      out.clip.events = at(c["footsteps"], child(path, "footsteps"),
                           [&] { return anim::footstep_events(rig.skeleton, out.clip, crowd_->event_names()); });
    if (c["events"]) {
      each(c["events"], child(path, "events"), [&](const YAML::Node& e, const std::string& ep) {
        if (!e.IsMap()) fail(e, ep, "expected an event: {name, time}, got " + kind(e));
        keys_of(e, ep, {"name", "time"});
        anim::ClipEvent ev;
        ev.id = at(e, ep,
                   [&] { return crowd_->event_names().intern(name_of(required(e, ep, "name"), child(ep, "name"))); });
        ev.time = real_in(required(e, ep, "time"), child(ep, "time"), 0.0, out.clip.duration());
        out.clip.events.push_back(ev);
      });
      std::stable_sort(out.clip.events.begin(), out.clip.events.end(),
                       [](const auto& a, const auto& b) { return a.time < b.time; });
    }
    at(c, path, [&] { out.clip.validate(); });
    clips_[name] = std::move(out);
  }

  // The motion of clip c: a default motion on the rig's skeleton, or a BVH file of the same skeleton.
  motion::Clip source_clip(const YAML::Node& c, const std::string& path, const anim::Rig& rig) {
    if (c["default"] && c["bvh"]) fail(c, path, "give either 'default: NAME' or 'bvh: FILE', not both");
    if (const YAML::Node d = c["default"]) {
      const std::string dp = child(path, "default");
      const std::string motion_name = text(d, dp);
      std::vector<std::string> known;
      for (const auto& s : motion::default_motion_specs()) {
        if (s.name == motion_name)
          return at(d, dp, [&] { return motion::LocomotionGenerator(rig.skeleton, s).make_clip(); });
        known.push_back(s.name);
      }
      fail(d, dp, "no default motion '" + motion_name + "' (known: " + join(known) + ")");
    }
    if (!c["bvh"]) fail(c, path, "a clip needs 'default: NAME' or 'bvh: FILE'");
    BvhFile f = read_bvh_at(c, path);
    if (f.skeleton.names != rig.skeleton.names)
      fail(c["bvh"], child(path, "bvh"),
           "its skeleton (" + std::to_string(f.skeleton.joint_count()) + " joints) is not rig '" + rig.name + "'s (" +
               std::to_string(rig.joint_count()) + " joints, same names in the same order needed)");
    return std::move(f.clip);
  }

  // Frames [first, end) of clip.
  motion::Clip frames_of(const YAML::Node& fr, const std::string& path, const motion::Clip& clip) {
    if (!fr.IsSequence() || fr.size() != 2)
      fail(fr, path, "expected [first, end): frames first..end-1, got " + kind(fr));
    const auto first = static_cast<std::int32_t>(integer(fr[0], item(path, 0), 0, clip.frame_count - 1));
    const auto end = static_cast<std::int32_t>(integer(fr[1], item(path, 1), first + 1, clip.frame_count));
    motion::Clip cut;
    cut.resize(end - first, clip.joint_count);
    cut.frame_time = clip.frame_time;
    for (std::int32_t f = first; f < end; ++f) {
      for (std::int32_t j = 0; j < clip.joint_count; ++j) cut.rotation(f - first, j) = clip.rotation(f, j);
      cut.root_positions[static_cast<std::size_t>(f - first)] = clip.root_positions[static_cast<std::size_t>(f)];
    }
    return cut;
  }

  const NamedClip& named_clip(const YAML::Node& n, const std::string& path, std::int32_t rig) {
    const std::string name = text(n, path);
    auto it = clips_.find(name);
    if (it == clips_.end()) fail(n, path, "no clip named '" + name + "'");
    if (it->second.rig != rig)
      fail(n, path,
           "clip '" + name + "' is of rig '" + crowd_->rig(it->second.rig).name + "', not '" + crowd_->rig(rig).name +
               "'");
    return it->second;
  }
  const AnimClip& clip_of(const YAML::Node& n, const std::string& path, std::int32_t rig) {
    return named_clip(n, path, rig).clip;
  }

  // ---- blend spaces (shared by every controller that names the same clips)
  motion::LocomotionClip prepared(const YAML::Node& n, const std::string& path, std::int32_t rig) {
    const NamedClip& c = named_clip(n, path, rig);
    const motion::Skeleton& skeleton = crowd_->rig(rig).skeleton;
    motion::LocomotionOptions options;
    options.clean_contacts = !c.cycle;  // the default motions are planted by construction
    return at(n, path, [&] {
      return c.cycle ? motion::prepare_locomotion_cycle(skeleton, *c.clip.clip, c.clip.name, options)
                     : motion::prepare_locomotion_clip(skeleton, *c.clip.clip, c.clip.name, options);
    });
  }

  bool is_default_skeleton(std::int32_t rig) const {
    return crowd_->rig(rig).skeleton.names == motion::default_skeleton().names;
  }

  // `space: default` or `clips: [NAME...]` (straight locomotion clips of the rig, by speed).
  std::shared_ptr<const motion::BlendSpace1D> speed_space(const YAML::Node& n, const std::string& path,
                                                          std::int32_t rig, bool plant_feet) {
    if (n["space"] && n["clips"]) fail(n, path, "give either 'space: default' or 'clips: [...]', not both");
    if (const YAML::Node space = n["space"]) {
      const std::string sp = child(path, "space");
      if (text(space, sp) != "default") fail(space, sp, "the only built-in blend space is 'default'");
      if (!is_default_skeleton(rig)) fail(space, sp, "the default blend space needs a rig with 'skeleton: default'");
      if (!plant_feet)
        fail(n["plant_feet"], child(path, "plant_feet"),
             "the default blend space plants feet; give 'clips' to turn it off");
      return anim::default_blend_spaces().speeds;
    }
    const std::string cp = child(path, "clips");
    const YAML::Node clips = required(n, path, "clips");
    std::string key = std::to_string(rig) + (plant_feet ? "|ik" : "|free");
    for (const std::string& c : names_of(clips, cp)) key += "|" + c;
    auto found = spaces_.find(key);
    if (found != spaces_.end()) return found->second;
    std::vector<motion::LocomotionClip> prepared_clips;
    each(clips, cp,
         [&](const YAML::Node& c, const std::string& ip) { prepared_clips.push_back(prepared(c, ip, rig)); });
    motion::BlendSpaceOptions options;
    options.plant_feet = plant_feet;
    auto space = at(clips, cp, [&] {
      return std::make_shared<const motion::BlendSpace1D>(crowd_->rig(rig).skeleton, std::move(prepared_clips),
                                                          options);
    });
    spaces_[key] = space;
    return space;
  }

  std::shared_ptr<const motion::BlendSpace1D> turn_space(const YAML::Node& n, const std::string& path,
                                                         std::int32_t rig) {
    const std::string key = std::to_string(rig) + "|turn|" + text(n, path);
    auto found = spaces_.find(key);
    if (found != spaces_.end()) return found->second;
    const NamedClip& c = named_clip(n, path, rig);
    auto space = at(
        n, path, [&] { return anim::make_turn_space(crowd_->rig(rig).skeleton, *c.clip.clip, c.clip.name, c.cycle); });
    spaces_[key] = space;
    return space;
  }

  void footstep_ids(const YAML::Node& n, const std::string& path, std::int32_t& left, std::int32_t& right) {
    if (!n || !loose_boolean(n, path)) return;
    left = at(n, path, [&] { return crowd_->event_names().intern("footstep_left"); });
    right = at(n, path, [&] { return crowd_->event_names().intern("footstep_right"); });
  }

  std::unique_ptr<Controller> blend1d(const YAML::Node& n, const std::string& path, std::int32_t rig) {
    if (!n.IsMap())
      fail(n, path,
           "expected {clips: [NAME...] | space: default, parameter, speed, phase, footsteps, plant_feet}, got " +
               kind(n));
    keys_of(n, path, {"clips", "space", "parameter", "speed", "phase", "footsteps", "plant_feet"});
    anim::Blend1DOptions o;
    if (n["parameter"]) o.parameter = name_of(n["parameter"], child(path, "parameter"));
    if (n["speed"]) o.speed = real_in(n["speed"], child(path, "speed"), 0.0, 100.0);
    if (n["phase"]) o.start_phase = real_in(n["phase"], child(path, "phase"), 0.0, 0.999999);
    footstep_ids(n["footsteps"], child(path, "footsteps"), o.footstep_left, o.footstep_right);
    const bool plant = n["plant_feet"] ? loose_boolean(n["plant_feet"], child(path, "plant_feet")) : true;
    auto space = speed_space(n, path, rig, plant);
    return at(n, path, [&] { return std::make_unique<anim::Blend1DController>(std::move(space), o); });
  }

  std::unique_ptr<Controller> blend2d(const YAML::Node& n, const std::string& path, std::int32_t rig) {
    if (!n.IsMap())
      fail(n, path,
           "expected {clips: [NAME...] | space: default, turn_left: CLIP, turn_right: CLIP, speed_parameter, "
           "turn_parameter, speed, "
           "turn, phase, footsteps, plant_feet}, got " +
               kind(n));
    keys_of(n, path,
            {"clips", "space", "turn_left", "turn_right", "speed_parameter", "turn_parameter", "speed", "turn", "phase",
             "footsteps", "plant_feet"});
    anim::Blend2DOptions o;
    if (n["speed_parameter"]) o.speed_parameter = name_of(n["speed_parameter"], child(path, "speed_parameter"));
    if (n["turn_parameter"]) o.turn_parameter = name_of(n["turn_parameter"], child(path, "turn_parameter"));
    if (n["speed"]) o.speed = real_in(n["speed"], child(path, "speed"), 0.0, 100.0);
    if (n["turn"]) o.turn = real_in(n["turn"], child(path, "turn"), -100.0, 100.0);
    if (n["phase"]) o.start_phase = real_in(n["phase"], child(path, "phase"), 0.0, 0.999999);
    footstep_ids(n["footsteps"], child(path, "footsteps"), o.footstep_left, o.footstep_right);
    const bool plant = n["plant_feet"] ? loose_boolean(n["plant_feet"], child(path, "plant_feet")) : true;
    auto speeds = speed_space(n, path, rig, plant);
    std::shared_ptr<const motion::BlendSpace1D> left, right;
    if (n["space"] && !n["turn_left"] && !n["turn_right"]) {
      left = anim::default_blend_spaces().turn_left;
      right = anim::default_blend_spaces().turn_right;
    } else {
      left = turn_space(required(n, path, "turn_left"), child(path, "turn_left"), rig);
      right = turn_space(required(n, path, "turn_right"), child(path, "turn_right"), rig);
    }
    return at(n, path, [&] {
      return std::make_unique<anim::Blend2DController>(std::move(speeds), std::move(left), std::move(right), o);
    });
  }

  // ---- controllers
  std::unique_ptr<Controller> controller(const YAML::Node& n, const std::string& path, std::int32_t rig, int depth) {
    if (depth > options_.limits.max_controller_depth)
      fail(n, path, "controllers nested deeper than " + std::to_string(options_.limits.max_controller_depth));
    if (!n.IsMap())
      fail(n, path,
           "expected a controller: {clip: NAME, rate}, {blend1d: ...}, {blend2d: ...}, {layered: ...} or "
           "{state_machine: ...}, got " +
               kind(n));
    if (n["clip"]) {
      keys_of(n, path, {"clip", "rate", "start"});
      const float rate = n["rate"] ? real_in(n["rate"], child(path, "rate"), -100.0, 100.0) : 1.0f;
      const double start = n["start"] ? number_in(n["start"], child(path, "start"), -1e6, 1e6) : 0.0;
      const AnimClip& clip = clip_of(n["clip"], child(path, "clip"), rig);
      return at(n, path, [&] { return std::make_unique<anim::ClipPlayer>(clip, rate, start); });
    }
    for (const std::string_view k : {"blend1d", "blend2d", "layered", "state_machine"}) {
      const YAML::Node v = n[std::string(k)];
      if (!v) continue;
      keys_of(n, path, {k});
      const std::string kp = child(path, k);
      if (k == "blend1d") return blend1d(v, kp, rig);
      if (k == "blend2d") return blend2d(v, kp, rig);
      if (k == "layered") return layered(v, kp, rig, depth);
      return state_machine(v, kp, rig, depth);
    }
    fail(n, path, "a controller needs one of 'clip', 'blend1d', 'blend2d', 'layered', 'state_machine'");
  }

  std::unique_ptr<Controller> layered(const YAML::Node& n, const std::string& path, std::int32_t rig, int depth) {
    if (!n.IsMap()) fail(n, path, "expected {base: CONTROLLER, layers: [...]}, got " + kind(n));
    keys_of(n, path, {"base", "layers"});
    auto out = std::make_unique<anim::LayeredController>(
        controller(required(n, path, "base"), child(path, "base"), rig, depth + 1));
    each(n["layers"], child(path, "layers"), [&](const YAML::Node& l, const std::string& lp) {
      anim::Layer layer = read_layer(l, lp, rig, depth);
      at(l, lp, [&] { out->add_layer(std::move(layer)); });
    });
    return out;
  }

  anim::Layer read_layer(const YAML::Node& l, const std::string& path, std::int32_t rig, int depth) {
    if (!l.IsMap())
      fail(l, path,
           "expected a layer: {controller, mode, weight, weight_parameter, mask, mask_weight, reference}, got " +
               kind(l));
    keys_of(l, path, {"controller", "mode", "weight", "weight_parameter", "mask", "mask_weight", "reference"});
    const motion::Skeleton& skeleton = crowd_->rig(rig).skeleton;
    anim::Layer layer;
    layer.controller = controller(required(l, path, "controller"), child(path, "controller"), rig, depth + 1);
    if (l["mode"])
      layer.mode = word(l["mode"], child(path, "mode"), {"override", "additive"}) == "override"
                       ? anim::LayerMode::Override
                       : anim::LayerMode::Additive;
    if (l["weight"]) layer.weight = real_in(l["weight"], child(path, "weight"), 0.0, 1.0);
    if (l["weight_parameter"]) layer.weight_parameter = name_of(l["weight_parameter"], child(path, "weight_parameter"));
    const float mask_weight = l["mask_weight"] ? real_in(l["mask_weight"], child(path, "mask_weight"), 0.0, 1.0) : 1.0f;
    if (l["mask"]) {
      const std::vector<std::string> roots = names_of(l["mask"], child(path, "mask"));
      layer.mask =
          at(l["mask"], child(path, "mask"), [&] { return anim::BoneMask::subtrees(skeleton, roots, mask_weight); });
    } else {
      layer.mask = anim::BoneMask::all(skeleton.joint_count(), mask_weight);
    }
    if (const YAML::Node r = l["reference"]) {
      const std::string rp = child(path, "reference");
      if (!r.IsMap()) fail(r, rp, "expected {clip: NAME, time: SECONDS}, got " + kind(r));
      keys_of(r, rp, {"clip", "time"});
      const AnimClip& clip = clip_of(required(r, rp, "clip"), child(rp, "clip"), rig);
      anim::Pose p;
      anim::sample_clip(clip, r["time"] ? number_in(r["time"], child(rp, "time"), 0.0, 1e6) : 0.0, p);
      layer.reference = p.local;
    }
    return layer;
  }

  anim::Condition condition(const YAML::Node& n, const std::string& path) {
    // "speed > 0.5", "turn<=-0.2", "waiting" (!= 0), "!waiting" (== 0).
    const std::string s = text(n, path);
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
    if (c.parameter.empty())
      fail(n, path, "expected 'parameter OP value' (OP one of < <= > >= == !=) or '[!]parameter', found '" + s + "'");
    skip();
    if (i == s.size()) {
      c.op = negated ? anim::Compare::Equal : anim::Compare::NotEqual;
      c.value = 0.0f;
      return c;
    }
    if (negated) fail(n, path, "'!' only goes before a lone parameter: '" + s + "'");
    static const std::pair<const char*, anim::Compare> ops[] = {
        {"<=", anim::Compare::LessEqual}, {">=", anim::Compare::GreaterEqual}, {"==", anim::Compare::Equal},
        {"!=", anim::Compare::NotEqual},  {"<", anim::Compare::Less},          {">", anim::Compare::Greater}};
    bool found = false;
    for (const auto& [text_op, op] : ops)
      if (s.compare(i, std::char_traits<char>::length(text_op), text_op) == 0) {
        c.op = op;
        i += std::char_traits<char>::length(text_op);
        found = true;
        break;
      }
    if (!found) fail(n, path, "expected a comparison (< <= > >= == !=) after '" + c.parameter + "' in '" + s + "'");
    skip();
    const std::string rest = s.substr(i);
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(rest, &used);
    } catch (const std::exception&) {
      fail(n, path, "expected a number after the comparison in '" + s + "'");
    }
    while (used < rest.size() && std::isspace(static_cast<unsigned char>(rest[used]))) ++used;
    if (used != rest.size() || !std::isfinite(v))
      fail(n, path, "expected a finite number after the comparison in '" + s + "'");
    c.value = static_cast<float>(v);
    return c;
  }

  std::unique_ptr<Controller> state_machine(const YAML::Node& n, const std::string& path, std::int32_t rig, int depth) {
    if (!n.IsMap()) fail(n, path, "expected {initial, states: [...], transitions: [...]}, got " + kind(n));
    keys_of(n, path, {"initial", "states", "transitions"});
    auto sm = std::make_unique<anim::StateMachine>();
    each(required(n, path, "states"), child(path, "states"), [&](const YAML::Node& s, const std::string& sp) {
      if (!s.IsMap()) fail(s, sp, "expected a state: {name, controller, on_enter}, got " + kind(s));
      keys_of(s, sp, {"name", "controller", "on_enter"});
      const std::string name = name_of(required(s, sp, "name"), child(sp, "name"));
      std::int32_t event = -1;
      if (const YAML::Node e = s["on_enter"]) {
        const std::string ep = child(sp, "on_enter");
        event = at(e, ep, [&] { return crowd_->event_names().intern(name_of(e, ep)); });
      }
      auto ctl = controller(required(s, sp, "controller"), child(sp, "controller"), rig, depth + 1);
      at(s, sp, [&] { sm->add_state(name, std::move(ctl), event); });
    });
    auto state = [&](const YAML::Node& x, const std::string& xp) {
      const std::string name = text(x, xp);
      if (name == "any") return anim::StateMachine::kAnyState;
      const std::int32_t i = sm->find_state(name);
      if (i < 0) fail(x, xp, "no state named '" + name + "'");
      return i;
    };
    each(n["transitions"], child(path, "transitions"), [&](const YAML::Node& t, const std::string& tp) {
      if (!t.IsMap()) fail(t, tp, "expected a transition: {from, to, when: [CONDITION...], fade}, got " + kind(t));
      keys_of(t, tp, {"from", "to", "when", "fade"});
      const std::int32_t from = state(required(t, tp, "from"), child(tp, "from"));
      const std::int32_t to = state(required(t, tp, "to"), child(tp, "to"));
      if (to == anim::StateMachine::kAnyState) fail(t["to"], child(tp, "to"), "a transition goes to a named state");
      std::vector<anim::Condition> when;
      if (const YAML::Node w = t["when"]) {
        if (w.IsScalar())
          when.push_back(condition(w, child(tp, "when")));
        else
          each(w, child(tp, "when"),
               [&](const YAML::Node& c, const std::string& cp) { when.push_back(condition(c, cp)); });
      }
      const float fade = t["fade"] ? real_in(t["fade"], child(tp, "fade"), 0.0, 1e3) : 0.2f;
      at(t, tp, [&] { sm->add_transition(from, to, std::move(when), fade); });
    });
    if (n["initial"]) {
      const std::int32_t i = state(n["initial"], child(path, "initial"));
      if (i < 0) fail(n["initial"], child(path, "initial"), "the initial state must be a named state");
      sm->set_initial_state(i);
    }
    return sm;
  }

  anim::RootMotion root_motion(const YAML::Node& n, const std::string& path) {
    return word(n, path, {"in_place", "keep"}) == "in_place" ? anim::RootMotion::InPlace : anim::RootMotion::Keep;
  }

  // ---- streams and unique animations
  void read_stream(const YAML::Node& s, const std::string& path) {
    if (!s.IsMap())
      fail(s, path,
           "expected a stream: {name, rig, history, root, time_to_dilate, running, parameters, controller}, got " +
               kind(s));
    keys_of(s, path, {"name", "rig", "history", "root", "time_to_dilate", "running", "parameters", "controller"});
    anim::StreamSpec spec;
    spec.name = name_of(required(s, path, "name"), child(path, "name"));
    if (crowd_->streams().find(spec.name) >= 0)
      fail(s["name"], child(path, "name"), "stream '" + spec.name + "' defined twice");
    spec.rig = rig_of(required(s, path, "rig"), child(path, "rig"));
    if (s["history"]) spec.history = static_cast<std::int32_t>(integer(s["history"], child(path, "history"), 1, 65536));
    if (s["root"]) spec.root = root_motion(s["root"], child(path, "root"));
    if (s["time_to_dilate"])
      spec.time_to_dilate = real_in(s["time_to_dilate"], child(path, "time_to_dilate"), 0.0, 1e6);
    if (s["running"]) spec.running = loose_boolean(s["running"], child(path, "running"));
    const anim::Rig& rig = crowd_->rig(spec.rig);
    count_pose_bytes(s, path, static_cast<std::size_t>(spec.history) * anim::pose_slot_bytes(rig.joint_count()));
    auto ctl = controller(required(s, path, "controller"), child(path, "controller"), spec.rig, 0);
    const std::int32_t index = at(s, path, [&] { return crowd_->streams().add(rig, spec.rig, spec, std::move(ctl)); });
    if (const YAML::Node p = s["parameters"]) {
      const std::string pp = child(path, "parameters");
      if (!p.IsMap()) fail(p, pp, "expected {name: value, ...}, got " + kind(p));
      for (auto it = p.begin(); it != p.end(); ++it) {
        const std::string name = name_of(it->first, pp);
        crowd_->streams()[index].parameters().set(name, real_in(it->second, child(pp, name), -1e9, 1e9));
      }
    }
  }

  void read_unique(const YAML::Node& u, const std::string& path) {
    if (!u.IsMap()) fail(u, path, "expected a unique animation: {name, rig, root, controller}, got " + kind(u));
    keys_of(u, path, {"name", "rig", "root", "controller"});
    anim::UniqueAnimation a;
    a.name = name_of(required(u, path, "name"), child(path, "name"));
    if (crowd_->uniques().find_animation(a.name) >= 0)
      fail(u["name"], child(path, "name"), "unique animation '" + a.name + "' defined twice");
    a.rig = rig_of(required(u, path, "rig"), child(path, "rig"));
    a.root = u["root"] ? root_motion(u["root"], child(path, "root")) : anim::RootMotion::InPlace;
    if (crowd_->uniques().capacity(a.rig) == 0)
      fail(u["rig"], child(path, "rig"), "rig '" + crowd_->rig(a.rig).name + "' has no unique_capacity");
    a.controller = controller(required(u, path, "controller"), child(path, "controller"), a.rig, 0);
    at(u, path, [&] { crowd_->uniques().add_animation(std::move(a)); });
  }

  StreamsYamlOptions options_;
  std::unique_ptr<anim::StreamCrowd> crowd_;
  std::map<std::string, NamedClip> clips_;
  std::map<std::string, std::shared_ptr<const motion::BlendSpace1D>> spaces_;
  std::size_t pose_bytes_ = 0;
};

}  // namespace

std::unique_ptr<anim::StreamCrowd> parse_stream_crowd(std::string_view text, const std::string& name,
                                                      const StreamsYamlOptions& options) {
  if (text.size() > options.limits.max_file_bytes)
    throw Error("file is larger than " + std::to_string(options.limits.max_file_bytes) + " bytes", at_line(name, 0, 0));
  const YAML::Node root = load_yaml(std::string(text), name);
  try {
    return Reader(name, options).read(root);
  } catch (const YAML::Exception& e) {
    throw yaml_error(e, name);
  }
}

std::unique_ptr<anim::StreamCrowd> load_stream_crowd(const std::string& path, StreamsYamlLimits limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw Error("cannot read: " + ec.message(), at_line(path, 0, 0));
  if (size > limits.max_file_bytes)
    throw Error("file is larger than " + std::to_string(limits.max_file_bytes) + " bytes", at_line(path, 0, 0));
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
