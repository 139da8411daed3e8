// The up axis of motion files. Everything inside throng is Y-up (the
// ground is the XZ plane, core/ground.h); a Z-up file (Blender's and many
// DCC tools' exports) is turned into Y-up before anything else reads it.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <glm/vec3.hpp>

#include "motion/clip.h"
#include "motion/skeleton.h"

namespace throng::motion {

enum class UpAxis : std::uint8_t { Y, Z };

const char* to_string(UpAxis axis);  // "y", "z"
// "y" or "z" (either case); nullopt otherwise.
std::optional<UpAxis> parse_up_axis(std::string_view text);

// Which way the body stands in a clip's first frame: from the ankles' mid
// point to the head (else the neck), by roles. axis is nullopt without
// those roles, or when neither +Y nor +Z holds at least twice the other two
// components (a lying or crouching pose: the caller asks for up_axis).
struct UpAxisGuess {
  std::optional<UpAxis> axis;
  bool from_roles = false;  // the roles were there (else no guess at all)
  glm::vec3 body{0.0f};     // feet to head, metres as read; without roles the rest pose's extent
};
UpAxisGuess guess_up_axis(const Skeleton& skeleton, const Clip& clip);

// Turns a Z-up skeleton and clip into Y-up in place: +Z becomes +Y, +Y
// becomes -Z, x stays. Rest offsets, root positions and animated
// translations rotate; every local rotation is conjugated, so each joint's
// world pose is the old one rotated.
void z_up_to_y_up(Skeleton& skeleton, Clip& clip);

}  // namespace throng::motion
