// Skeleton + Clip -> BVH text, with one rotation order for every joint.
//
// The root gets "Xposition Yposition Zposition" and three rotations; other
// joints three rotations, plus position channels first when the clip animates
// their translation (any frame differing from the rest offset). Joints are
// written depth first, children in index order; a skeleton already in that
// order (every skeleton read from BVH) reads back with the same indices.
// Numbers are written as the shortest text that reads back to the same float.
#pragma once

#include <string>

#include "motion/clip.h"
#include "motion/rotation.h"
#include "motion/skeleton.h"
#include "motion/units.h"

namespace throng::io {

struct BvhWriteOptions {
  motion::EulerOrder order = motion::EulerOrder::ZXY;
  motion::LengthUnit unit = motion::LengthUnit::Centimetre;  // of the written numbers
  // Written as "Frame Time:" when > 0 (e.g. the exact value a file had),
  // else clip.frame_time.
  double frame_time = 0.0;
};

// Throws Error when skeleton and clip disagree or hold non-finite values.
std::string write_bvh_string(const motion::Skeleton& skeleton, const motion::Clip& clip,
                             const BvhWriteOptions& options = {});
void write_bvh(const std::string& path, const motion::Skeleton& skeleton, const motion::Clip& clip,
               const BvhWriteOptions& options = {});

}  // namespace throng::io
