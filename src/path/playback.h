// Playback: a matched sequence of motion segments stitched into one
// continuous clip per character, laid along its path.
//
// Segment j (curve j of the path) is placed so its smoothed root starts at
// the curve's first point p_{jk} heading along the tangent there: a map
// point x of the clip goes to p_{jk} + R(theta_j - h_m)(x - o_m), where o_m
// and h_m are the segment's own origin and heading (path/state_machine.h);
// joint rotations turn by the same angle about +Y (a map rotation is a world
// yaw, core/ground.h). Around every boundary between two segments the poses
// are blended over the machine's transition_frames (smoothstep weight,
// slerp per joint, the placed roots interpolated). The start segment (idle)
// stands at the first point facing the path; the end segment stands where
// the last motion ended.
//
// The deviation is the distance, per frame of the matched part, from the
// root's ground projection (the hips, sway included) to the resampled path.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "motion/clip.h"
#include "path/match.h"
#include "path/spline.h"
#include "path/state_machine.h"

namespace throng::path {

struct Playback {
  motion::Clip clip;                   // world (Y-up), the machine's fps
  std::vector<glm::vec2> root_ground;  // per frame, map coordinates
  std::int32_t first_matched_frame = 0, matched_frames = 0;
  double deviation_mean = 0;  // m
  double deviation_max = 0;   // m
};

// `sequence` from greedy_sequences / dp_sequences for this path (its curves
// are the first sequence.segments.size() * k points of `path`).
Playback play(const MotionGraph& machine, const ResampledPath& path, const Sequence& sequence);

}  // namespace throng::path
