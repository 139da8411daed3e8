// Foot skating: how far a planted foot slides.
//
// For each foot contact (motion/cycle.h: the foot is low and slow), the
// slide is the horizontal path length, summed frame to frame, of the foot
// joint that stays put: per step, the smaller displacement of the ankle and
// the toe among those still near the ground. A foot rolling from heel to
// ball keeps one of them pinned and does not count as sliding.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "motion/clip.h"
#include "motion/cycle.h"
#include "motion/fk.h"
#include "motion/skeleton.h"

namespace throng::motion {

// What the body does during a foot contact, from its hips (the thighs'
// mid-point travelling, the line between them facing, averaged over +-0.3 s
// against the pelvis' swing): turning (over 0.5 rad/s), stepping sideways (over 0.25 m/s across the facing and more than
// half the speed along it), starting or stopping (speed changing by over
// 0.3 m/s), standing (under 0.1 m/s), else walking straight; in that order.
enum class GaitRegime : std::uint8_t { Straight, Turning, SideStep, StartStop, Standing };
inline constexpr int kGaitRegimes = 5;
const char* to_string(GaitRegime regime);  // "straight", "turning", "side_step", "start_stop", "standing"

// With no contact measured the figures are NaN, not zero: nothing was
// measured, so no bound on them can hold by accident (NaN < x is false), and
// JSON writes them as null.
struct FootSkatingReport {
  std::int32_t contacts = 0;
  std::vector<Index> characters;  // recorders: the tracked characters with a contact measured
  double mean_cm = std::numeric_limits<double>::quiet_NaN();
  double p95_cm = std::numeric_limits<double>::quiet_NaN();  // nearest-rank 95th percentile over contacts
  double max_cm = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> slides_cm;  // per contact: left foot's, then right's
  // Per contact, the GaitRegime (as slides_cm); empty where not classified
  // (no thigh roles, or a report summarised from slides alone).
  std::vector<std::uint8_t> regimes;

  bool measured() const { return contacts > 0; }
};

// "mean 0.42 cm, p95 0.90 cm over 120 contacts", or "no contacts measured".
std::string describe(const FootSkatingReport& r);

FootSkatingReport measure_foot_skating(const ModelSpaceClip& model, const ContactReport& contacts,
                                       const FeetJoints& feet);

// Convenience: FK, contacts from the skeleton's roles, then the measure.
FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const Clip& clip, const ContactOptions& options = {});

// For joints already posed (e.g. a synthesised character's world joints per
// frame, sampled every frame_time seconds): contacts from the skeleton's
// roles, then the measure.
FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const ModelSpaceClip& posed, double frame_time,
                                       const ContactOptions& options = {});

// Mean, p95 and max of per-contact slides (cm), e.g. pooled over characters.
FootSkatingReport summarise_foot_skating(std::vector<double> slides_cm);

// The world joints of a few characters of a crowd recorded frame by frame,
// then measured together (per character measure_foot_skating, slides pooled).
//   recorder.track({3, 17}, crowd_size, joints);
//   each frame: for t: copy character tracked()[t]'s joints into append(t); then end_frame();
//   recorder.measure(skeleton, frame_time)
// A frame appended with feet_synthesised = false (joint LOD held the legs
// instead of synthesising them) is not measured: each character's frames
// are measured in runs of frames whose feet were synthesised; a run that
// LOD cut short counts if it lasts 1.5 s (the ground is not known otherwise).
class FootSkatingRecorder {
 public:
  struct Frame {
    std::span<glm::vec3> positions;  // joint_count each, world
    std::span<glm::quat> rotations;
  };
  // Starts over with these characters; one outside [0, character_count) is
  // an Error at field "track".
  void track(std::vector<Index> characters, Index character_count, std::int32_t joint_count);
  const std::vector<Index>& tracked() const { return tracked_; }
  // Room for tracked()[t]'s joints of the frame being recorded.
  Frame append(std::size_t t, bool feet_synthesised = true);
  void end_frame() { ++frames_; }
  std::int32_t frames() const { return frames_; }
  // Fewer than 3 frames or frame_time not positive: no contacts.
  FootSkatingReport measure(const Skeleton& skeleton, double frame_time, const ContactOptions& options = {}) const;

 private:
  std::vector<Index> tracked_;
  std::int32_t joints_ = 0;
  std::int32_t frames_ = 0;
  std::vector<std::vector<glm::vec3>> positions_;
  std::vector<std::vector<glm::quat>> rotations_;
  std::vector<std::vector<std::uint8_t>> synthesised_;  // per tracked character, per frame
};

}  // namespace throng::motion
