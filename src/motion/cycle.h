// Cycle analysis of locomotion clips: foot contacts, the best loop (frame
// pair with the smallest heading-invariant pose + root-velocity difference),
// cycle length, cadence, stride, speed, turn rate; and closing that loop
// into a seamless cyclic clip.
//
// Y is up. Headings are the twist of the root rotation about +Y, so the
// analysis does not care which way a file's rest pose faces.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "motion/clip.h"
#include "motion/fk.h"
#include "motion/skeleton.h"

namespace throng::motion {

// The points of each foot that can rest on the ground: [0] left, [1] right.
struct FeetJoints {
  std::array<std::int32_t, 2> ankle{-1, -1};
  // Ball or toe point: joint toe[f] plus toe_offset[f] in that joint's frame
  // (the ankle's end site when a skeleton has no toe joint, as in the DAZ
  // conversions of CMU); -1 when unknown.
  std::array<std::int32_t, 2> toe{-1, -1};
  std::array<glm::vec3, 2> toe_offset{glm::vec3(0.0f), glm::vec3(0.0f)};
  // From skeleton.roles; throws Error when an ankle role is missing.
  static FeetJoints from_roles(const Skeleton& skeleton);
};

// Thigh-to-knee plus knee-to-ankle rest length, averaged over both legs
// (from roles; falls back to 0.5 x rest-pose height). Thresholds scale by it.
double leg_length(const Skeleton& skeleton);

// A foot is in contact on a frame when one of its points is low (within
// height_fraction x leg length of that point's own ground level, the
// ground_percentile of its height over the clip) and slow (horizontal speed
// below speed_fraction x leg length per second). Speeds are taken over
// +-smoothing_s so that marker jitter in mocap does not break contacts.
struct ContactOptions {
  double height_fraction = 0.06;  // ~5 cm for a 0.85 m leg
  double speed_fraction = 0.5;    // ~0.42 m/s
  double ground_percentile = 0.05;
  double smoothing_s = 0.05;
  double max_gap_s = 0.1;       // gaps this short inside a contact are filled
  double min_contact_s = 0.05;  // shorter contacts are dropped
  void validate() const;
};

struct ContactInterval {
  std::int32_t begin = 0;  // first frame in contact
  std::int32_t end = 0;    // one past the last
};

struct FootContacts {
  std::vector<ContactInterval> intervals;
  std::vector<std::uint8_t> in_contact;   // per frame, after gap filling
  std::array<double, 2> ground = {0, 0};  // ground level of ankle, toe (m)
};

// World positions of the ankle ([0]) and toe ([1]) points of foot f on every
// frame, averaged over +-smoothing_frames (fewer at the clip's ends). A
// missing toe gives an empty vector.
std::array<std::vector<glm::vec3>, 2> foot_tracks(const ModelSpaceClip& model, const FeetJoints& feet, int foot,
                                                  std::int32_t smoothing_frames);
std::int32_t smoothing_frames(double smoothing_s, double frame_time);

struct ContactReport {
  std::array<FootContacts, 2> feet;  // [0] left, [1] right
  double height_threshold = 0;       // m
  double speed_threshold = 0;        // m/s
  std::int32_t smoothing_frames = 0;
};

ContactReport detect_foot_contacts(const Skeleton& skeleton, const ModelSpaceClip& model, double frame_time,
                                   const FeetJoints& feet, const ContactOptions& options = {});

struct CycleOptions {
  double min_period_s = 0.4;  // a stride of a fast run is ~0.65 s
  double max_period_s = 2.0;  // a slow walk's stride is ~1.3 s; idle needs more
  // Cost = mean squared joint offset from the root in the heading frame (m^2)
  // + (root_velocity_time * root velocity difference)^2
  // + (joint_velocity_time * mean joint velocity difference)^2.
  double root_velocity_time = 0.25;   // s
  double joint_velocity_time = 0.05;  // s
  // A shorter period wins over the overall best when its cost is within
  // this factor (plus 1 mm^2), so a clip with k periods reports one.
  double fundamental_tolerance = 1.5;
  // Loops whose root moves slower than this (m/s) are not considered, so a
  // clip that starts or ends standing still reports its walking part. Set
  // 0 for in-place motions (idle).
  double min_mean_speed = 0.1;
  // Frames from the start of the clip that may not be used (e.g. the T-pose
  // that CMU conversions put in frame 0).
  std::int32_t skip_frames = 0;
  // Analyse the clip as a loop (its last frame continues into its first):
  // Auto does so when the first frame matches the last one extrapolated.
  enum class Loop : std::uint8_t { Auto, Never, Always } loop = Loop::Auto;
  ContactOptions contacts;
  // Refuse clips with more frames x (joints + 1) than this (~100 MB of
  // features); 4 M is 30 minutes of a 30-joint clip at 60 fps.
  std::int64_t max_frame_joints = std::int64_t{1} << 22;
  void validate() const;
};

struct CycleReport {
  bool found = false;            // a period in range was found
  bool input_is_loop = false;    // the clip was analysed as a loop
  std::int32_t start_frame = 0;  // a
  std::int32_t end_frame = 0;    // b: frame b matches frame a (b may exceed the clip for loops)
  std::int32_t period_frames = 0;
  double period_s = 0.0;
  double cost = 0.0;           // pose + velocity difference at (a, b), m^2
  double pose_rms_m = 0.0;     // RMS joint position difference at (a, b)
  std::int32_t steps = 0;      // contact onsets of both feet in [a, b)
  double cadence = 0.0;        // steps per minute
  double stride_length = 0.0;  // m per two steps
  double mean_speed = 0.0;     // m/s along the (possibly curved) path
  double turn_rate = 0.0;      // rad/s, positive = left (about +Y)
  double displacement = 0.0;   // m, root travel over the cycle along the path
  ContactReport contacts;      // over the analysed frames
};

// Finds the best loop of a locomotion clip and measures it. Needs the ankle
// roles (and toes if present) for contacts; without them steps stay 0.
CycleReport analyze_cycle(const Skeleton& skeleton, const Clip& clip, const CycleOptions& options = {});

// Frames a..b-1 of `clip` as a cyclic clip: each joint's rotation (root:
// without its heading) and the root height get the mismatch between frame b
// and frame a spread linearly over the cycle, so the last frame flows into
// the first. Horizontal root motion and heading are kept, so the loop's root
// motion repeats in the heading frame.
Clip make_cyclic(const Clip& clip, std::int32_t a, std::int32_t b);
Clip make_cyclic(const Clip& clip, const CycleReport& report);

// A cyclic clip repeated `copies` times with the root carried on: each copy
// starts where the previous one ended, rotated by its heading change. The
// root step from the last frame to the first is estimated as the mean of
// its neighbours' steps in the heading frame.
Clip repeat_cycle(const Clip& cycle, std::int32_t copies);

// Heading of a root rotation: its twist about +Y, radians.
double heading_of(const glm::quat& root_rotation);

}  // namespace throng::motion
