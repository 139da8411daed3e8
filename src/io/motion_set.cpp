#include "io/motion_set.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>

#include "core/error.h"
#include "io/bvh_reader.h"

namespace throng::io {

namespace {

MotionClipSource clip_source(YamlReader& r, const YAML::Node& c, const std::string& field) {
  MotionClipSource src;
  if (c.IsScalar()) {
    src.file = r.text(c, field);
  } else {
    r.expect_map(c, field, {"file", "name", "skip_frames"});
    src.file = r.text(r.required(c, field, "file"), field + ".file");
    if (const auto n = c["name"]) src.name = r.text(n, field + ".name");
    if (const auto n = c["skip_frames"])
      src.skip_frames = static_cast<std::int32_t>(r.integer(n, field + ".skip_frames", 0, 100000));
  }
  if (src.file.empty()) r.fail(c, field, "empty file name");
  if (src.name.empty()) src.name = std::filesystem::path(src.file).stem().string();
  return src;
}

void clip_list(YamlReader& r, const YAML::Node& n, const std::string& path, MotionSetSpec& s) {
  r.each_item(n, path, 1, 64, "BVH clips",
              [&](const YAML::Node& c, const std::string& field) { s.clips.push_back(clip_source(r, c, field)); });
}

}  // namespace

MotionSetSpec read_motion_set(YamlReader& r, const YAML::Node& m, const std::string& path) {
  MotionSetSpec s;
  if (m.IsScalar()) {
    r.word(m, path, {"default"});
    return s;
  }
  if (m.IsSequence()) {
    clip_list(r, m, path, s);
    return s;
  }
  if (!m.IsMap())
    r.fail(m, path, "expected 'default', a list of BVH clips or {clips, up_axis, units}, got " + r.kind(m));
  r.expect_map(m, path, {"clips", "up_axis", "units"});
  clip_list(r, r.required(m, path, "clips"), path + ".clips", s);
  if (const auto n = m["up_axis"]) {
    const std::string a = r.word(n, path + ".up_axis", {"auto", "y", "z"});
    if (a != "auto") s.up_axis = motion::parse_up_axis(a);
  }
  if (const auto n = m["units"]) {
    const std::string u = r.text(n, path + ".units");
    if (u != "auto") {
      s.unit = motion::parse_length_unit(u);
      if (!s.unit) r.fail(n, path + ".units", "expected auto, m, cm, mm, in or cmu, got '" + u + "'");
    }
  }
  return s;
}

namespace {

// One clip's file read and turned Y-up (Error naming the file and `field`,
// the clip's key, otherwise).
BvhFile read_clip(const MotionSetSpec& spec, const std::filesystem::path& path, const std::string& field) {
  BvhReadOptions options;
  options.unit = spec.unit;
  BvhFile file = read_bvh(path.string(), options);
  const motion::UpAxisGuess guess = motion::guess_up_axis(file.skeleton, file.clip);
  const Location where{path.string(), 0, 0, field + ".up_axis"};
  const std::string body = fmt::format("feet to head in the first frame: {:.2f}, {:.2f}, {:.2f} m", guess.body.x,
                                       guess.body.y, guess.body.z);
  if (spec.up_axis && guess.axis && *guess.axis != *spec.up_axis)
    throw Error(fmt::format("the body stands along +{} ({}), but motion.up_axis is {}", motion::to_string(*guess.axis),
                            body, motion::to_string(*spec.up_axis)),
                where);
  if (!spec.up_axis && !guess.axis && guess.from_roles)
    throw Error(fmt::format("cannot tell which way is up ({}); give motion.up_axis: y or z", body), where);
  if (!spec.up_axis && !guess.from_roles)
    spdlog::warn(
        "{}: no ankle and head joints to tell the up axis by: taken as y (BVH's usual; motion.up_axis says "
        "otherwise)",
        path.string());
  const motion::UpAxis up = spec.up_axis ? *spec.up_axis : guess.axis.value_or(motion::UpAxis::Y);
  if (up == motion::UpAxis::Z) motion::z_up_to_y_up(file.skeleton, file.clip);
  spdlog::debug("{}: {}-up, unit {}{}", path.string(), motion::to_string(up), motion::to_string(file.unit),
                file.unit_detected ? " (detected)" : "");
  return file;
}

// Why a prepared cycle is no walk or run, or "": one that moves must step
// with each foot once per cycle, the feet landing about half a cycle apart
// (feet landing together hop or jump, which a speed blend of walks and runs
// cannot show).
std::string not_a_gait(const motion::LocomotionClip& c) {
  if (!(c.stride_m > motion::kMinStride)) return {};
  const float left = c.event(motion::FootEvent::LeftDown), right = c.event(motion::FootEvent::RightDown);
  if (left < 0.0f || right < 0.0f)
    return fmt::format(
        "its cycle ({:.2f} s, {:.2f} m/s) does not have each foot land once: not a walk or run (hops, shuffles or "
        "stumbles have no steady steps)",
        c.period_s, c.speed);
  float apart = right - left;
  apart -= std::floor(apart);
  if (apart < 0.25f || apart > 0.75f)
    return fmt::format(
        "the feet land together (right {:.2f} of a cycle after left; a walk or run lands them about 0.5 apart): "
        "hops or jumps, not a walk or run",
        apart);
  return {};
}

}  // namespace

motion::BlendSpace1D load_motion_set(const MotionSetSpec& spec, const std::filesystem::path& folder,
                                     const std::string& field) {
  if (spec.is_default()) return motion::make_default_blend_space();
  std::vector<motion::LocomotionClip> clips;
  motion::Skeleton skeleton;
  for (std::size_t i = 0; i < spec.clips.size(); ++i) {
    const MotionClipSource& src = spec.clips[i];
    const std::filesystem::path path =
        std::filesystem::path(src.file).is_absolute() ? std::filesystem::path(src.file) : folder / src.file;
    const std::string clip_field = field + ".clips[" + std::to_string(i) + "]";
    const BvhFile file = read_clip(spec, path, field);
    if (i == 0)
      skeleton = file.skeleton;
    else if (file.skeleton.joint_count() != skeleton.joint_count())
      throw Error(fmt::format("has {} joints, the first clip {}: the clips of a motion set share one skeleton",
                              file.skeleton.joint_count(), skeleton.joint_count()),
                  Location{path.string(), 0, 0, clip_field});
    motion::LocomotionOptions options;
    options.cycle.skip_frames = src.skip_frames;
    try {
      clips.push_back(motion::prepare_locomotion_clip(skeleton, file.clip, src.name, options));
    } catch (const Error& e) {
      throw Error(e.message(), Location{path.string(), 0, 0, clip_field});
    }
    const motion::LocomotionClip& c = clips.back();
    if (const std::string why = not_a_gait(c); !why.empty())
      throw Error(why, Location{path.string(), 0, 0, clip_field});
    spdlog::info("{}: cycle of {} frames ({:.2f} s), {:.2f} m/s, stride {:.2f} m", src.name, c.frame_count(),
                 c.period_s, c.speed, c.stride_m);
  }
  return motion::BlendSpace1D(std::move(skeleton), std::move(clips));
}

}  // namespace throng::io
