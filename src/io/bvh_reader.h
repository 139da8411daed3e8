// BVH (Biovision Hierarchy) motion capture files -> Skeleton + Clip.
//
// Format: HIERARCHY with one ROOT, nested JOINT and End Site blocks, each
// with OFFSET x y z and (not End Site) CHANNELS n followed by n of
// X/Y/Zposition and X/Y/Zrotation in any order; then MOTION, "Frames: N",
// "Frame Time: t" and N rows of values, one row per line, in the order the
// channels were declared (depth first). Rotations are in degrees and compose
// in the listed order: "Zrotation Xrotation Yrotation" is R = Rz * Rx * Ry
// acting on column vectors. Position channels replace the joint's OFFSET on
// their axes (the usual reading of MotionBuilder and CMU files), so a root
// with position channels sits at exactly those values.
//
// Tolerated: CRLF, LF or CR line ends (mixed too), tabs, blank lines,
// trailing whitespace, a UTF-8 byte order mark, scientific notation, a leading '+', keywords in any
// case, "Frames:" / "Time:" with or without a space before the number.
// Everything else is an Error naming file:line:col and what was expected,
// including numbers that are not finite or larger in magnitude than 1e9.
// Lengths are converted to metres (see motion/units.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motion/clip.h"
#include "motion/roles.h"
#include "motion/skeleton.h"
#include "motion/units.h"

namespace throng::io {

enum class BvhChannel : std::uint8_t { Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation };
const char* to_string(BvhChannel c);  // "Xposition"
inline bool is_rotation(BvhChannel c) { return c >= BvhChannel::Xrotation; }
inline int axis_of(BvhChannel c) { return static_cast<int>(c) % 3; }

// Hostile-input guards, checked before anything of that size is allocated.
struct BvhLimits {
  std::int32_t max_joints = 1024;  // ROOT + JOINT blocks
  std::int64_t max_frames = 1'000'000;
  std::uint64_t max_file_bytes = 512ull << 20;
  std::int64_t max_values = 1ll << 28;  // frames * channels
  std::int64_t max_poses = 1ll << 26;   // frames * joints (32 bytes each in the clip)
  std::size_t max_name_length = 256;
};

struct BvhReadOptions {
  std::optional<motion::LengthUnit> unit;  // the file's unit; nullopt = detect
  std::vector<motion::RoleOverride> role_overrides;
  BvhLimits limits;
};

struct BvhFile {
  motion::Skeleton skeleton;  // metres, roles assigned
  motion::Clip clip;          // metres; clip.frame_time = (float)frame_time
  // Per joint, its channels in the order the file lists them.
  std::vector<std::vector<BvhChannel>> channels;
  double frame_time = 0.0;                              // seconds, exactly as written
  motion::LengthUnit unit = motion::LengthUnit::Metre;  // the file's unit
  bool unit_detected = false;                           // guessed (true) or given
  std::int32_t end_site_count = 0;
  std::uint64_t bytes = 0;
  std::string name;  // the path or name used in errors

  std::int32_t channel_count() const;
  // "Xposition Yposition Zposition Zrotation Yrotation Xrotation"
  std::string channel_list(std::int32_t joint) const;
  // Rotation axes in listed order, "ZXY"; "" when the joint has none.
  std::string rotation_order(std::int32_t joint) const;
};

// Reads a file; the path is used in error locations.
BvhFile read_bvh(const std::string& path, const BvhReadOptions& options = {});
// Parses text already in memory; `name` is used in error locations.
BvhFile parse_bvh(std::string_view text, const std::string& name, const BvhReadOptions& options = {});

}  // namespace throng::io
