// Foot skating: how far a planted foot slides.
//
// For each foot contact (motion/cycle.h: the foot is low and slow), the
// slide is the horizontal path length, summed frame to frame, of the foot
// joint that stays put: per step, the smaller displacement of the ankle and
// the toe among those still near the ground. A foot rolling from heel to
// ball keeps one of them pinned and does not count as sliding.
#pragma once

#include <cstdint>
#include <vector>

#include "motion/clip.h"
#include "motion/cycle.h"
#include "motion/fk.h"
#include "motion/skeleton.h"

namespace throng::motion {

struct FootSkatingReport {
  std::int32_t contacts = 0;
  double mean_cm = 0.0;
  double p95_cm = 0.0;  // nearest-rank 95th percentile over contacts
  double max_cm = 0.0;
  std::vector<double> slides_cm;  // per contact: left foot's, then right's
};

FootSkatingReport measure_foot_skating(const ModelSpaceClip& model, const ContactReport& contacts, const FeetJoints& feet);

// Convenience: FK, contacts from the skeleton's roles, then the measure.
FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const Clip& clip, const ContactOptions& options = {});

// For joints already posed (e.g. a synthesised character's world joints per
// frame, sampled every frame_time seconds): contacts from the skeleton's
// roles, then the measure.
FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const ModelSpaceClip& posed, double frame_time,
                                       const ContactOptions& options = {});

// Mean, p95 and max of per-contact slides (cm), e.g. pooled over characters.
FootSkatingReport summarise_foot_skating(std::vector<double> slides_cm);

}  // namespace throng::motion
