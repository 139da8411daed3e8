// Length units of motion files. Everything inside throng is in metres.
#pragma once

#include <optional>
#include <string_view>

#include "motion/skeleton.h"

namespace throng::motion {

enum class LengthUnit : std::uint8_t {
  Metre,
  Centimetre,
  Millimetre,
  Inch,
  // The CMU ASF length unit, (1/0.45) inch = 0.056444 m, used by the CMU
  // BVH conversions of the MotionBuilder and 3ds Max releases.
  CmuAsf,
};

double metres_per_unit(LengthUnit unit);
const char* to_string(LengthUnit unit);  // "m", "cm", "mm", "in", "cmu"
// Parses "m", "cm", "mm", "in" and "cmu" (also "metres", "inches", ...).
std::optional<LengthUnit> parse_length_unit(std::string_view text);

// The unit that makes a skeleton, given in file units with roles assigned,
// look like an adult human: leg length (thigh to ankle) near 0.85 m when the
// legs are known, else the rest pose's largest extent near 1.7 m. Picks the
// nearest candidate on a log scale.
struct UnitGuess {
  LengthUnit unit = LengthUnit::Metre;
  double measured = 0.0;   // the length measured, in file units
  bool from_legs = false;  // leg length (true) or rest-pose extent
};
UnitGuess guess_length_unit(const Skeleton& skeleton_in_file_units);

}  // namespace throng::motion
