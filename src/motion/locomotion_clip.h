// Prepared locomotion clips (host, once per clip). prepare_locomotion_clip
// and prepare_locomotion_cycle turn a clip into one clean cycle: its loop
// found and closed, its root split into a path (a line or an arc, stride_m
// and turn_rad per cycle) and an offset from that path, foot contacts
// cleaned (clean_foot_contacts), foot events found, frame 0 at the left
// touchdown. motion/blend_space.h packs prepared clips for synthesis.
// Conventions: motion/locomotion.h.
#pragma once

#include <array>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <vector>

#include "motion/clip.h"
#include "motion/cycle.h"
#include "motion/skeleton.h"

namespace throng::motion {

// Foot events of a cycle, as phases in [0, 1).
enum class FootEvent : std::uint8_t { LeftDown, LeftUp, RightDown, RightUp };
inline constexpr int kFootEvents = 4;
const char* to_string(FootEvent e);

struct LocomotionOptions {
  CycleOptions cycle;       // raw clips: how the loop is found (e.g. skip_frames)
  ContactOptions contacts;  // foot events of the cycle
  // Take a slight turn out of a clip meant to go straight (real mocap drifts
  // a few degrees per cycle): the path becomes a line, the root keeps its
  // motion relative to the turning path. A speed blend space wants this.
  bool straighten = true;
  // Clips whose root moves less than this per cycle (m) are stationary
  // (idle): no stride, the path point is the root's mean ground position.
  double stationary_below_m = 0.05;
  // Pin the feet during contacts in the cycle's own motion (clean_foot_contacts).
  bool clean_contacts = true;
  double contact_ramp_s = 0.1;  // corrections fade in and out over this before and after a contact
  // A contact goes on after the strict test while the ball stays low and
  // moves slower than contacts.speed_fraction times this (the push-off roll).
  double cleanup_speed_factor = 3.0;
  double max_cleanup_m = 0.04;  // frames that would need a larger correction are left free
  void validate() const;        // Error naming the field
};

// One locomotion cycle ready for synthesis.
struct LocomotionClip {
  std::string name;
  // One cycle: frame i at phase i / frame_count, frame 0 at the left foot's
  // touchdown (when the clip has one). Local joint rotations, except the
  // root's, which is relative to the path's heading at that phase;
  // root_positions hold the root's offset from the path point in the path
  // frame (x left, y up, z forward; its mean over the cycle is 0 in x, z).
  Clip cycle;
  double period_s = 0.0;          // seconds per cycle
  double stride_m = 0.0;          // path length per cycle (two steps)
  double turn_rad = 0.0;          // path heading change per cycle (0 when straightened)
  double speed = 0.0;             // stride / period, m/s
  double turn_removed_rad = 0.0;  // what straightening took out per cycle
  // Phases of the foot events, -1 where the cycle has none (idle) or the
  // contacts are not one per foot per cycle.
  std::array<float, kFootEvents> events{-1.0f, -1.0f, -1.0f, -1.0f};
  // Per joint: the cycle's mean local rotation, what joints that LOD turns
  // off hold instead of being synthesised.
  std::vector<glm::quat> mean_rotations;
  // Lowest height of each ankle joint over the cycle (m): [0] left, [1] right.
  std::array<float, 2> ankle_ground{0.0f, 0.0f};
  // Input frame that became frame 0 (within the input cycle).
  std::int32_t source_start_frame = 0;
  double contact_cleanup_m = 0.0;  // largest ankle correction of clean_foot_contacts

  std::int32_t frame_count() const { return cycle.frame_count; }
  float event(FootEvent e) const { return events[static_cast<std::size_t>(e)]; }
};

// A clip that is already exactly one cycle (frame F would be frame 0 moved
// by the cycle's rigid root motion), e.g. the default set's.
LocomotionClip prepare_locomotion_cycle(const Skeleton& skeleton, const Clip& cycle, std::string name,
                                        const LocomotionOptions& options = {});
// Foot-skate cleanup of a prepared cycle, as motion capture slides (heel
// rocker, marker drift, rescaled skeletons): in the cycle's own motion (its
// path at stride_m per cycle), each contact (motion/cycle.h) pins the ankle
// while the heel is down and the ball of the foot once it is up (the ball
// where it stands when the heel rises); two-bone IK moves thigh and knee to
// reach it and keeps the foot's world rotation. Corrections fade in and out
// over contact_ramp_s around each contact. Returns the largest correction (m).
double clean_foot_contacts(const Skeleton& skeleton, LocomotionClip& clip, const LocomotionOptions& options = {});

// Any locomotion clip: finds the best loop (analyze_cycle), closes it
// (make_cyclic), then prepare_locomotion_cycle. Error when no cycle is found.
LocomotionClip prepare_locomotion_clip(const Skeleton& skeleton, const Clip& clip, std::string name,
                                       const LocomotionOptions& options = {});

}  // namespace throng::motion
