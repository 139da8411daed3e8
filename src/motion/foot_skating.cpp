#include "motion/foot_skating.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"

namespace throng::motion {

FootSkatingReport measure_foot_skating(const ModelSpaceClip& m, const ContactReport& contacts, const FeetJoints& feet) {
  const std::int32_t F = m.frame_count;
  FootSkatingReport r;
  for (int f = 0; f < 2; ++f) {
    const FootContacts& fc = contacts.feet[static_cast<std::size_t>(f)];
    const auto raw = foot_tracks(m, feet, f, 0);
    const std::int32_t k = contacts.smoothing_frames;
    for (const ContactInterval& c : fc.intervals) {
      if (c.begin < 0 || c.end > F || c.begin >= c.end) throw Error("foot skating: contact interval outside the clip");
      // Smoothed inside the contact only (mocap jitter would otherwise add up
      // along the path, and the swing must not leak in).
      auto smoothed = [&](std::size_t p, std::int32_t i) {
        const std::int32_t half = std::min({k, i - c.begin, c.end - 1 - i});
        glm::dvec3 sum(0.0);
        for (std::int32_t d = -half; d <= half; ++d) sum += glm::dvec3(raw[p][static_cast<std::size_t>(i + d)]);
        return sum / static_cast<double>(2 * half + 1);
      };
      double slide = 0.0;
      for (std::int32_t i = c.begin; i + 1 < c.end; ++i) {
        double low_min = std::numeric_limits<double>::infinity(), any_min = low_min;
        for (std::size_t p = 0; p < 2; ++p) {
          if (raw[p].empty()) continue;
          const glm::dvec3 p0 = smoothed(p, i);
          const glm::dvec3 p1 = smoothed(p, i + 1);
          const double d = std::hypot(p1.x - p0.x, p1.z - p0.z);
          any_min = std::min(any_min, d);
          const double ground = fc.ground[p];
          if (p0.y - ground < contacts.height_threshold && p1.y - ground < contacts.height_threshold)
            low_min = std::min(low_min, d);
        }
        slide += std::isfinite(low_min) ? low_min : (std::isfinite(any_min) ? any_min : 0.0);
      }
      r.slides_cm.push_back(100.0 * slide);
    }
  }
  return summarise_foot_skating(std::move(r.slides_cm));
}

FootSkatingReport summarise_foot_skating(std::vector<double> slides_cm) {
  FootSkatingReport r;
  r.slides_cm = std::move(slides_cm);
  r.contacts = static_cast<std::int32_t>(r.slides_cm.size());
  if (r.contacts == 0) return r;
  std::vector<double> sorted = r.slides_cm;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (double s : sorted) sum += s;
  r.mean_cm = sum / static_cast<double>(sorted.size());
  const auto rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(sorted.size())));
  r.p95_cm = sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
  r.max_cm = sorted.back();
  return r;
}

std::string describe(const FootSkatingReport& r) {
  if (!r.measured()) return "no contacts measured";
  return fmt::format("mean {:.2f} cm, p95 {:.2f} cm over {} contacts", r.mean_cm, r.p95_cm, r.contacts);
}

FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const ModelSpaceClip& posed, double frame_time,
                                       const ContactOptions& options) {
  const FeetJoints feet = FeetJoints::from_roles(skeleton);
  const ContactReport contacts = detect_foot_contacts(skeleton, posed, frame_time, feet, options);
  return measure_foot_skating(posed, contacts, feet);
}

FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const Clip& clip, const ContactOptions& options) {
  return measure_foot_skating(skeleton, forward_kinematics(skeleton, clip), clip.frame_time, options);
}

void FootSkatingRecorder::track(std::vector<Index> characters, Index character_count, std::int32_t joint_count) {
  for (const Index c : characters)
    if (c < 0 || c >= character_count)
      throw Error("character " + std::to_string(c) + " is not in [0, " + std::to_string(character_count) + ")",
                  at_field("track"));
  tracked_ = std::move(characters);
  joints_ = joint_count;
  frames_ = 0;
  // Cleared, not freed: the next window fills the same storage, so a long
  // run recording window after window allocates only for the first.
  positions_.resize(tracked_.size());
  rotations_.resize(tracked_.size());
  synthesised_.resize(tracked_.size());
  for (auto& p : positions_) p.clear();
  for (auto& r : rotations_) r.clear();
  for (auto& f : synthesised_) f.clear();
}

FootSkatingRecorder::Frame FootSkatingRecorder::append(std::size_t t, bool feet_synthesised) {
  const auto J = static_cast<std::size_t>(joints_);
  synthesised_[t].push_back(feet_synthesised ? 1 : 0);
  std::vector<glm::vec3>& p = positions_[t];
  std::vector<glm::quat>& r = rotations_[t];
  p.resize(p.size() + J);
  r.resize(r.size() + J);
  return {std::span<glm::vec3>(p).last(J), std::span<glm::quat>(r).last(J)};
}

namespace {
constexpr double kMinRunSeconds = 1.5;  // about a gait cycle and a half
}  // namespace

FootSkatingReport FootSkatingRecorder::measure(const Skeleton& skeleton, double frame_time,
                                               const ContactOptions& options) const {
  std::vector<double> slides;
  std::vector<Index> characters;
  if (frames_ < 3 || !(frame_time > 0.0)) return summarise_foot_skating(slides);
  const auto J = static_cast<std::size_t>(joints_);
  for (std::size_t t = 0; t < tracked_.size(); ++t) {
    const std::vector<std::uint8_t>& feet = synthesised_[t];
    const std::size_t before = slides.size();
    // Each run of frames with synthesised feet, measured on its own. A run
    // that joint LOD cut short must last kMinRunSeconds: the ground its
    // contacts are measured from is a low percentile of its own foot heights.
    const auto shortest = static_cast<std::size_t>(std::max(3.0, std::ceil(kMinRunSeconds / frame_time)));
    for (std::size_t begin = 0; begin < feet.size();) {
      std::size_t end = begin;
      while (end < feet.size() && feet[end] != 0) ++end;
      const bool whole = begin == 0 && end == feet.size();
      if (end - begin >= (whole ? std::size_t{3} : shortest)) {
        ModelSpaceClip posed;
        posed.joint_count = joints_;
        posed.frame_count = static_cast<std::int32_t>(end - begin);
        posed.positions.assign(positions_[t].begin() + static_cast<std::ptrdiff_t>(begin * J),
                               positions_[t].begin() + static_cast<std::ptrdiff_t>(end * J));
        posed.rotations.assign(rotations_[t].begin() + static_cast<std::ptrdiff_t>(begin * J),
                               rotations_[t].begin() + static_cast<std::ptrdiff_t>(end * J));
        const FootSkatingReport r = measure_foot_skating(skeleton, posed, frame_time, options);
        slides.insert(slides.end(), r.slides_cm.begin(), r.slides_cm.end());
      }
      begin = end + 1;
    }
    if (slides.size() > before) characters.push_back(tracked_[t]);
  }
  FootSkatingReport r = summarise_foot_skating(std::move(slides));
  r.characters = std::move(characters);
  return r;
}

}  // namespace throng::motion
