// The motion state machine of the path layer.
//
// States have names and motion segments: a clip and a start frame. For a
// locomotion state every segment covers the same root arc length
// d = k * spacing, and its root trajectory is resampled at `spacing` into k
// points, expressed in the segment's own frame (first point at the origin,
// initial direction +x on the map), ready to be matched against k points of a
// path. Other states (idle) have a duration in frames instead.
//
// States belong to groups, groups to parent groups (e.g. walk_left and
// run_left in L; F, L and R in locomotion). An edge from a state or group to
// a state or group allows every state under the first to be followed by every
// state under the second: children inherit their ancestors' edges. Between
// two segments the playback blends over `transition_frames` (about 8).
//
// The data format (YAML) is read by io/state_machine_yaml.h; the default
// machine, data/motion/default_machine.yaml, is built from the default motion
// set plus a few generated clips (running turns, sharper walking turns).
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/vec2.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/buffer.h"
#include "core/error.h"
#include "motion/clip.h"
#include "motion/default_set.h"
#include "motion/skeleton.h"

namespace throng::path {

// v turned counter-clockwise by `angle` radians (map coordinates).
inline glm::vec2 rotate_ccw(glm::vec2 v, float angle) {
  const float c = std::cos(angle), s = std::sin(angle);
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}

// ---- the data file, as plain data (io/state_machine_yaml fills it) ----------

struct ClipSpec {
  std::string name;
  motion::LocomotionSpec spec;  // what the generator makes (from the default set or given)
  Location where;
};

struct SegmentSpec {
  std::string clip;
  double start_frame = 0;  // where the segment starts in the clip
  double frames = 0;       // non-locomotion states: length in frames (0 = the clip's period)
  Location where;
};

struct StateSpec {
  std::string name;
  std::string group;  // may be empty
  bool locomotion = true;
  std::vector<SegmentSpec> segments;
  Location where;
};

struct StateGroupSpec {
  std::string name;
  std::string parent;  // may be empty
  Location where;
};

struct EdgeSpec {
  std::string from, to;  // state or group names
  float cost = 0.0f;     // added to every transition it allows (m of path error)
  Location where;
};

struct StateMachineSpec {
  std::string name = "machine";
  double fps = 60.0;
  float spacing = 0.0225f;               // s, m
  std::int32_t points_per_segment = 64;  // k
  std::int32_t transition_frames = 8;
  float pose_weight = 1.0f;  // transition cost per metre of mean joint mismatch, times k
  std::string start_state;   // the sequence starts after this state ("" = free)
  std::string end_state;     // and ends before it
  std::vector<ClipSpec> clips;
  std::vector<StateGroupSpec> groups;
  std::vector<StateSpec> states;
  std::vector<EdgeSpec> edges;
};

// ---- the built machine ----------------------------------------------------------

struct MotionSegment {
  std::string name;  // "walk_forward/0"
  std::int32_t state = 0;
  std::int32_t clip = 0;
  double start_time = 0;  // s, in the clip's own timeline (frame / fps)
  double duration = 0;    // s: time to cover d (locomotion) or the given frames
  float speed = 0;        // m/s: mean root speed over the segment
  // Locomotion: k points at arc length 0, s, ..., (k-1)s in the segment's
  // frame, and the clip time of each. The segment's frame maps a map point x
  // (the ground projection of the smoothed root) to R(-heading) (x - origin).
  std::vector<glm::vec2> trajectory;
  std::vector<double> times;
  glm::vec2 origin{0.0f};
  float heading = 0.0f;       // rad, map heading of the smoothed root at start
  glm::vec2 end_point{0.0f};  // where the segment ends (arc length d), in its frame
  float end_heading = 0.0f;   // rad, in its frame
};

struct MachineState {
  std::string name;
  std::int32_t group = -1;
  bool locomotion = true;
  std::vector<std::int32_t> segments;
};

struct MachineGroup {
  std::string name;
  std::int32_t parent = -1;
};

// One generated clip with the generator that made it, so poses and the root
// can be evaluated at any time (before frame 0 too: clips are cyclic).
struct MachineClip {
  std::string name;
  std::shared_ptr<const motion::LocomotionGenerator> generator;
  motion::Clip clip;  // frames at the machine's fps, covering every segment and its transitions
  double fps = 60.0;
  double time_of_first_frame = 0;  // s: generator time of clip frame 0 (negative: padding before t = 0)
  std::int32_t period_frames = 0;
  // Ground (map) point of the root smoothed over one period, at time t.
  glm::vec2 smoothed_root(double t) const;
  glm::vec2 raw_root(double t) const;
};

class MotionGraph {
 public:
  // Generates the clips and every segment's trajectory; throws Error with
  // the file location of the offending entry.
  static MotionGraph build(const StateMachineSpec& spec, const motion::Skeleton& skeleton);

  const StateMachineSpec& spec() const { return spec_; }
  const motion::Skeleton& skeleton() const { return skeleton_; }
  float spacing() const { return spec_.spacing; }
  std::int32_t k() const { return spec_.points_per_segment; }
  float segment_length() const { return spec_.spacing * static_cast<float>(spec_.points_per_segment); }

  const std::vector<MachineClip>& clips() const { return clips_; }
  const std::vector<MachineState>& states() const { return states_; }
  const std::vector<MachineGroup>& groups() const { return groups_; }
  const std::vector<MotionSegment>& segments() const { return segments_; }
  std::int32_t segment_count() const { return static_cast<std::int32_t>(segments_.size()); }
  std::int32_t state_index(const std::string& name) const;   // -1 when absent
  std::int32_t start_state() const { return start_state_; }  // -1 = none
  std::int32_t end_state() const { return end_state_; }

  // May state b follow state a?
  bool allowed(std::int32_t a, std::int32_t b) const {
    return allowed_[static_cast<std::size_t>(a) * states_.size() + static_cast<std::size_t>(b)] != 0;
  }
  float edge_cost(std::int32_t a, std::int32_t b) const {
    return edge_cost_[static_cast<std::size_t>(a) * states_.size() + static_cast<std::size_t>(b)];
  }
  // Cost of segment b after segment a: INFINITY when their states may not
  // follow each other, else edge cost + pose_weight * k * mean joint mismatch
  // between a's last pose and b's first (in each root's heading frame).
  float transition_cost(std::int32_t a, std::int32_t b) const {
    return transition_[static_cast<std::size_t>(a) * segments_.size() + static_cast<std::size_t>(b)];
  }
  // Locomotion segments only, in order: what the matching grid holds.
  const std::vector<std::int32_t>& locomotion_segments() const { return locomotion_; }

  // Pose of segment `seg` at `t` seconds after its start (may be negative or
  // past its end: clips are cyclic), local rotations and the root in the
  // clip's world frame.
  void pose(std::int32_t seg, double t, std::vector<glm::quat>& rotations, glm::vec3& root) const;

 private:
  StateMachineSpec spec_;
  motion::Skeleton skeleton_;
  std::vector<MachineClip> clips_;
  std::vector<MachineState> states_;
  std::vector<MachineGroup> groups_;
  std::vector<MotionSegment> segments_;
  std::vector<std::int32_t> locomotion_;
  std::vector<std::uint8_t> allowed_;
  std::vector<float> edge_cost_;
  std::vector<float> transition_;
  std::int32_t start_state_ = -1, end_state_ = -1;
};

}  // namespace throng::path
