// The path layer end to end, for `throng match` and the benchmarks:
// polylines -> C1 spline resampled at the machine's spacing -> curves ->
// matching grid -> greedy, repaired greedy and DP sequences -> playback
// with deviation. Plus a random obstacle field with planned paths.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "motion/clip.h"
#include "path/match.h"
#include "path/planner.h"
#include "path/spline.h"
#include "path/state_machine.h"
#include "sim/world.h"

namespace throng::path {

struct PathInput {
  std::string name;
  std::vector<glm::vec2> points;
  float speed = 0.0f;  // desired, m/s (0 = any)
  std::vector<PathMark> marks;
};

struct SequenceStats {
  double path_error = 0;     // mean distance per point over all curves, m
  double total_cost = 0;     // sum over the legal sequences
  std::int64_t illegal = 0;  // forbidden transitions (and marked curves given another state)
  std::int64_t paths_with_illegal = 0;
};

struct PathResult {
  std::string name;
  float length = 0;         // m, of the resampled spline
  std::int32_t points = 0;  // resampled points
  std::int32_t curves = 0;
  std::int32_t greedy_illegal = 0;
  double greedy_error = 0, dp_error = 0;         // m per point
  double deviation_mean = 0, deviation_max = 0;  // playback (DP), m
  double duration_s = 0;                         // playback
  std::vector<std::string> dp_states;            // state of each curve's segment, DP
};

struct MatchRunOptions {
  MatchOptions match;
  float max_knot_spacing = 1.0f;  // resampling
  std::int32_t keep_clips = 0;    // playback clips kept for the first N paths (BVH export)
};

struct MatchRun {
  std::vector<PathResult> paths;
  std::int64_t curves = 0, motions = 0;
  SequenceStats greedy, repaired, dp;
  double deviation_mean = 0;  // over all matched frames of all paths, m
  double deviation_max = 0;
  // Wall-clock milliseconds per stage.
  double resample_ms = 0, grid_ms = 0, sequences_ms = 0, playback_ms = 0;
  std::vector<motion::Clip> clips;  // the kept playback clips
};

MatchRun match_paths(const MotionGraph& machine, const std::vector<PathInput>& inputs,
                     const MatchRunOptions& options = {});

// A walkable rectangle with obstacles scattered by the simulation's own
// scatter (circles and rotated boxes) and an L-shaped wall.
struct RandomWorldOptions {
  float width = 60.0f, height = 40.0f;  // m
  std::int64_t obstacles = 70;
  float min_size = 0.8f, max_size = 3.5f, gap = 1.2f;  // m
  std::uint64_t seed = 1;
};
sim::World random_obstacle_world(const RandomWorldOptions& options);

// `count` (start, goal) pairs in free space with clearance >= radius + 0.1 m,
// at least `min_distance` apart, deterministic for a seed.
std::vector<PathQuery> random_queries(const Planner& planner, std::int64_t count, std::uint64_t seed,
                                      float min_distance = 15.0f);

}  // namespace throng::path
