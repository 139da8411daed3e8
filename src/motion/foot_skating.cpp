#include "motion/foot_skating.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
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

const char* to_string(GaitRegime regime) {
  switch (regime) {
    case GaitRegime::Straight: return "straight";
    case GaitRegime::Turning: return "turning";
    case GaitRegime::SideStep: return "side_step";
    case GaitRegime::StartStop: return "start_stop";
    case GaitRegime::Standing: return "standing";
  }
  return "?";
}

namespace {

// The hips' ground point and facing (radians about +Y, 0 = +Z) in a frame.
struct Hips {
  glm::dvec2 at{0.0};
  double facing = 0.0;
};
Hips hips_at(const ModelSpaceClip& m, std::int32_t frame, std::int32_t left, std::int32_t right) {
  const glm::dvec3 l(m.position(frame, left)), r(m.position(frame, right));
  // Facing +Z with +Y up, the left thigh is on the +X side: forward = (l - r) x up.
  const glm::dvec3 forward = glm::cross(l - r, glm::dvec3(0.0, 1.0, 0.0));
  return {{0.5 * (l.x + r.x), 0.5 * (l.z + r.z)}, std::atan2(forward.x, forward.z)};
}

// The hips' facing averaged over +-0.3 s about a frame: the pelvis swings
// left and right with every step, a running stride's by 10 degrees or more.
double mean_facing(const ModelSpaceClip& m, double frame_time, std::int32_t frame, std::int32_t left,
                   std::int32_t right) {
  const auto half = static_cast<std::int32_t>(std::lround(0.3 / frame_time));
  glm::dvec2 sum(0.0);
  for (std::int32_t f = std::max(0, frame - half); f <= std::min(m.frame_count - 1, frame + half); ++f) {
    const double a = hips_at(m, f, left, right).facing;
    sum += glm::dvec2(std::sin(a), std::cos(a));
  }
  return std::atan2(sum.x, sum.y);
}

GaitRegime classify_contact(const ModelSpaceClip& m, double frame_time, const ContactInterval& c, std::int32_t left,
                            std::int32_t right) {
  // At least two frames apart: a one-frame contact is measured across its
  // neighbours.
  std::int32_t first = c.begin, last = c.end - 1;
  if (last <= first) {
    first = std::max(0, first - 1);
    last = std::min(m.frame_count - 1, last + 1);
    if (last <= first) return GaitRegime::Standing;
  }
  const Hips a = hips_at(m, first, left, right), b = hips_at(m, last, left, right);
  const double seconds = static_cast<double>(last - first) * frame_time;
  const glm::dvec2 velocity = (b.at - a.at) / seconds;
  const double facing = mean_facing(m, frame_time, first, left, right);
  const double turn =
      std::remainder(mean_facing(m, frame_time, last, left, right) - facing, 2.0 * std::numbers::pi) / seconds;
  const glm::dvec2 forward(std::sin(facing), std::cos(facing));
  const double along = glm::dot(velocity, forward);
  const double across = std::abs(velocity.x * forward.y - velocity.y * forward.x);
  const auto speed_at = [&](std::int32_t f) {
    return glm::length(hips_at(m, f + 1, left, right).at - hips_at(m, f, left, right).at) / frame_time;
  };
  const double speed_change = std::abs(speed_at(last - 1) - speed_at(first));
  if (std::abs(turn) > 0.5) return GaitRegime::Turning;
  if (across > 0.25 && across > 0.5 * std::abs(along)) return GaitRegime::SideStep;
  if (speed_change > 0.3) return GaitRegime::StartStop;
  if (glm::length(velocity) < 0.1) return GaitRegime::Standing;
  return GaitRegime::Straight;
}

}  // namespace

FootSkatingReport measure_foot_skating(const Skeleton& skeleton, const ModelSpaceClip& posed, double frame_time,
                                       const ContactOptions& options) {
  const FeetJoints feet = FeetJoints::from_roles(skeleton);
  const ContactReport contacts = detect_foot_contacts(skeleton, posed, frame_time, feet, options);
  FootSkatingReport r = measure_foot_skating(posed, contacts, feet);
  const std::int32_t left = skeleton.role(Role::LeftThigh), right = skeleton.role(Role::RightThigh);
  if (left < 0 || right < 0) return r;
  // The same order as the slides: the left foot's contacts, then the right's.
  for (const FootContacts& fc : contacts.feet)
    for (const ContactInterval& c : fc.intervals)
      r.regimes.push_back(static_cast<std::uint8_t>(classify_contact(posed, frame_time, c, left, right)));
  if (r.regimes.size() != r.slides_cm.size()) r.regimes.clear();
  return r;
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
  std::vector<std::uint8_t> regimes;
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
        regimes.insert(regimes.end(), r.regimes.begin(), r.regimes.end());
      }
      begin = end + 1;
    }
    if (slides.size() > before) characters.push_back(tracked_[t]);
  }
  FootSkatingReport r = summarise_foot_skating(std::move(slides));
  r.characters = std::move(characters);
  if (regimes.size() == r.slides_cm.size()) r.regimes = std::move(regimes);
  return r;
}

}  // namespace throng::motion
