// A motion set from the user's BVH files, as scenario files name it (the
// `motion` key of `throng run` / `throng view` scenarios and of `throng
// animate` files): the clips of one skeleton, their up axis and length unit,
// turned into the speed blend space every character is animated from.
//
//   motion: default                       # the built-in set (motion/default_set.h)
//   motion: [walk.bvh, run.bvh]           # clips, paths relative to the scenario file
//   motion:
//     clips: [walk.bvh, {file: jog.bvh, name: jog, skip_frames: 1}]
//     up_axis: auto                       # auto | y | z  (Blender's exports are z)
//     units: auto                         # auto | m | cm | mm | in | cmu
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/yaml_reader.h"
#include "motion/locomotion.h"
#include "motion/units.h"
#include "motion/up_axis.h"

namespace throng::io {

struct MotionClipSource {
  std::string file;              // BVH, relative to the scenario file's folder
  std::string name;              // defaults to the file's stem
  std::int32_t skip_frames = 0;  // leading frames the cycle search ignores (a T-pose)
  bool operator==(const MotionClipSource&) const = default;
};

struct MotionSetSpec {
  std::vector<MotionClipSource> clips;     // empty: the default motion set
  std::optional<motion::UpAxis> up_axis;   // nullopt: detected per clip
  std::optional<motion::LengthUnit> unit;  // nullopt: detected per clip
  bool is_default() const { return clips.empty(); }
  bool operator==(const MotionSetSpec&) const = default;
};

// The `motion` value at `path` (any of the three forms above); errors at
// the value's line and column.
MotionSetSpec read_motion_set(YamlReader& reader, const YAML::Node& node, const std::string& path);

// The blend space of a motion set: the default set, or each clip read
// (folder / file unless absolute), turned Y-up, its cycle found and
// prepared. Errors name the clip's file and say what is wrong with it;
// `field` ("motion") is where the set was given. Logs each clip's cycle.
motion::BlendSpace1D load_motion_set(const MotionSetSpec& spec, const std::filesystem::path& folder,
                                     const std::string& field);

}  // namespace throng::io
