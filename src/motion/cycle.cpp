#include "motion/cycle.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/math.h"

namespace throng::motion {

namespace {

std::vector<glm::dvec3> rest_positions(const Skeleton& s) {
  std::vector<glm::dvec3> p(static_cast<std::size_t>(s.joint_count()));
  for (std::int32_t j = 0; j < s.joint_count(); ++j) {
    const auto parent = s.parents[static_cast<std::size_t>(j)];
    p[static_cast<std::size_t>(j)] = (parent < 0 ? glm::dvec3(0.0) : p[static_cast<std::size_t>(parent)]) +
                                     glm::dvec3(s.offsets[static_cast<std::size_t>(j)]);
  }
  return p;
}

std::size_t at(std::int32_t frame, std::int32_t joints, std::int32_t joint) {
  return static_cast<std::size_t>(frame) * static_cast<std::size_t>(joints) + static_cast<std::size_t>(joint);
}

double horizontal_distance(const glm::vec3& a, const glm::vec3& b) {
  return std::hypot(static_cast<double>(a.x) - b.x, static_cast<double>(a.z) - b.z);
}

// Heading-invariant features of every frame: joint offsets from the root in
// the root's heading frame (plus the root height), their velocities, and the
// root velocity in the heading frame (plus yaw rate scaled to m/s).
struct Features {
  std::int32_t frames = 0;
  std::int32_t points = 0;       // joints + 1 (root height)
  std::vector<glm::dvec3> pose;  // frames x points
  std::vector<glm::dvec3> pose_velocity;
  std::vector<glm::dvec4> root_velocity;  // x, y, z, yaw rate * leg length
  std::vector<double> heading;            // unwrapped, radians
};

Features compute_features(const ModelSpaceClip& m, double dt, double leg) {
  Features f;
  const std::int32_t F = m.frame_count, J = m.joint_count;
  f.frames = F;
  f.points = J + 1;
  f.pose.resize(static_cast<std::size_t>(F) * static_cast<std::size_t>(f.points));
  f.pose_velocity.resize(f.pose.size());
  f.root_velocity.resize(static_cast<std::size_t>(F));
  f.heading.resize(static_cast<std::size_t>(F));
  double prev = 0.0;
  for (std::int32_t i = 0; i < F; ++i) {
    const double h = heading_of(m.rotations[at(i, J, 0)]);
    f.heading[static_cast<std::size_t>(i)] = i == 0 ? h : prev + wrap_angle(h - prev);
    prev = f.heading[static_cast<std::size_t>(i)];
  }
  for (std::int32_t i = 0; i < F; ++i) {
    const glm::dquat inv = yaw_rotation(-f.heading[static_cast<std::size_t>(i)]);
    const glm::dvec3 root(m.positions[at(i, J, 0)]);
    for (std::int32_t j = 0; j < J; ++j)
      f.pose[at(i, f.points, j)] = inv * (glm::dvec3(m.positions[at(i, J, j)]) - root);
    f.pose[at(i, f.points, J)] = glm::dvec3(0.0, root.y, 0.0);
  }
  for (std::int32_t i = 0; i < F; ++i) {
    const std::int32_t lo = std::max(i - 1, 0), hi = std::min(i + 1, F - 1);
    const double span = (hi - lo) * dt;
    if (span <= 0) continue;
    for (std::int32_t k = 0; k < f.points; ++k)
      f.pose_velocity[at(i, f.points, k)] = (f.pose[at(hi, f.points, k)] - f.pose[at(lo, f.points, k)]) / span;
    const glm::dquat inv = yaw_rotation(-f.heading[static_cast<std::size_t>(i)]);
    const glm::dvec3 v = inv * (glm::dvec3(m.positions[at(hi, J, 0)]) - glm::dvec3(m.positions[at(lo, J, 0)])) / span;
    const double yaw_rate = (f.heading[static_cast<std::size_t>(hi)] - f.heading[static_cast<std::size_t>(lo)]) / span;
    f.root_velocity[static_cast<std::size_t>(i)] = glm::dvec4(v, yaw_rate * leg);
  }
  return f;
}

struct PairCost {
  double total = 0, pose = 0;
};

PairCost pair_cost(const Features& f, std::int32_t a, std::int32_t b, const CycleOptions& o) {
  double pose = 0, vel = 0;
  const glm::dvec3* pa = &f.pose[at(a, f.points, 0)];
  const glm::dvec3* pb = &f.pose[at(b, f.points, 0)];
  const glm::dvec3* va = &f.pose_velocity[at(a, f.points, 0)];
  const glm::dvec3* vb = &f.pose_velocity[at(b, f.points, 0)];
  for (std::int32_t k = 0; k < f.points; ++k) {
    const glm::dvec3 d = pa[k] - pb[k];
    const glm::dvec3 e = va[k] - vb[k];
    pose += glm::dot(d, d);
    vel += glm::dot(e, e);
  }
  pose /= f.points;
  vel /= f.points;
  const glm::dvec4 r = f.root_velocity[static_cast<std::size_t>(a)] - f.root_velocity[static_cast<std::size_t>(b)];
  PairCost c;
  c.pose = pose;
  c.total = pose + o.joint_velocity_time * o.joint_velocity_time * vel +
            o.root_velocity_time * o.root_velocity_time * glm::dot(r, r);
  return c;
}

// Seconds -> whole frames, clamped before the cast (tiny frame times must
// not overflow).
std::int32_t frames_floor(double seconds, double dt) {
  return static_cast<std::int32_t>(std::clamp(std::floor(seconds / dt + 1e-9), 0.0, 1e9));
}
std::int32_t frames_ceil(double seconds, double dt) {
  return static_cast<std::int32_t>(std::clamp(std::ceil(seconds / dt - 1e-9), 0.0, 1e9));
}

void check_frame_time(double dt) {
  if (!(dt >= 1e-5 && dt <= 10.0))
    throw Error("frame time must be in [1e-5, 10] s, got " + std::to_string(dt), at_field("frame_time"));
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

}  // namespace

double heading_of(const glm::quat& q) {
  if (std::abs(q.y) < 1e-9 && std::abs(q.w) < 1e-9) return 0.0;
  return wrap_angle(2.0 * std::atan2(static_cast<double>(q.y), static_cast<double>(q.w)));
}

FeetJoints FeetJoints::from_roles(const Skeleton& s) {
  FeetJoints f;
  f.ankle = {s.role(Role::LeftAnkle), s.role(Role::RightAnkle)};
  f.toe = {s.role(Role::LeftToe), s.role(Role::RightToe)};
  if (f.ankle[0] < 0 || f.ankle[1] < 0) throw Error("foot contacts need the left_ankle and right_ankle roles");
  for (std::size_t k = 0; k < 2; ++k) {
    const auto a = static_cast<std::size_t>(f.ankle[k]);
    if (f.toe[k] < 0 && a < s.has_end_site.size() && s.has_end_site[a]) {
      f.toe[k] = f.ankle[k];
      f.toe_offset[k] = s.end_sites[a];
    }
  }
  return f;
}

std::int32_t smoothing_frames(double smoothing_s, double frame_time) {
  if (!(frame_time > 0)) return 0;
  return std::clamp<std::int32_t>(static_cast<std::int32_t>(std::lround(smoothing_s / frame_time)), 0, 64);
}

std::array<std::vector<glm::vec3>, 2> foot_tracks(const ModelSpaceClip& m, const FeetJoints& feet, int foot,
                                                  std::int32_t k) {
  const std::int32_t F = m.frame_count, J = m.joint_count;
  std::array<std::vector<glm::vec3>, 2> out;
  const auto fi = static_cast<std::size_t>(foot);
  const std::array<std::int32_t, 2> joints{feet.ankle[fi], feet.toe[fi]};
  const std::array<glm::vec3, 2> offsets{glm::vec3(0.0f), feet.toe_offset[fi]};
  for (std::size_t p = 0; p < 2; ++p) {
    const std::int32_t j = joints[p];
    if (j < 0) continue;
    if (j >= J) throw Error("foot joint " + std::to_string(j) + " is not in the clip");
    std::vector<glm::dvec3> raw(static_cast<std::size_t>(F));
    for (std::int32_t i = 0; i < F; ++i)
      raw[static_cast<std::size_t>(i)] = glm::dvec3(m.positions[at(i, J, j)] + m.rotations[at(i, J, j)] * offsets[p]);
    out[p].resize(static_cast<std::size_t>(F));
    for (std::int32_t i = 0; i < F; ++i) {
      const std::int32_t r = std::min({k, i, F - 1 - i});  // symmetric window, shrinking at the ends
      glm::dvec3 sum(0.0);
      for (std::int32_t d = -r; d <= r; ++d) sum += raw[static_cast<std::size_t>(i + d)];
      out[p][static_cast<std::size_t>(i)] = glm::vec3(sum / static_cast<double>(2 * r + 1));
    }
  }
  return out;
}

double leg_length(const Skeleton& s) {
  const auto rest = rest_positions(s);
  const std::array<std::array<Role, 3>, 2> legs{
      {{Role::LeftThigh, Role::LeftKnee, Role::LeftAnkle}, {Role::RightThigh, Role::RightKnee, Role::RightAnkle}}};
  double sum = 0;
  int count = 0;
  for (const auto& leg : legs) {
    const std::int32_t t = s.role(leg[0]), k = s.role(leg[1]), a = s.role(leg[2]);
    if (t < 0 || k < 0 || a < 0) continue;
    sum += glm::length(rest[static_cast<std::size_t>(k)] - rest[static_cast<std::size_t>(t)]) +
           glm::length(rest[static_cast<std::size_t>(a)] - rest[static_cast<std::size_t>(k)]);
    ++count;
  }
  if (count > 0 && sum > 0) return sum / count;
  double lo = 0, hi = 0;
  for (const auto& p : rest) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
  return hi - lo > 0 ? 0.5 * (hi - lo) : 1.0;
}

void ContactOptions::validate() const {
  if (!(height_fraction > 0 && height_fraction < 1))
    throw Error("must be in (0, 1)", at_field("contacts.height_fraction"));
  if (!(speed_fraction > 0 && speed_fraction < 100))
    throw Error("must be in (0, 100)", at_field("contacts.speed_fraction"));
  if (!(ground_percentile >= 0 && ground_percentile <= 1))
    throw Error("must be in [0, 1]", at_field("contacts.ground_percentile"));
  if (!(smoothing_s >= 0 && smoothing_s <= 1)) throw Error("must be in [0, 1] s", at_field("contacts.smoothing_s"));
  if (!(max_gap_s >= 0 && max_gap_s < 10)) throw Error("must be in [0, 10) s", at_field("contacts.max_gap_s"));
  if (!(min_contact_s >= 0 && min_contact_s < 10))
    throw Error("must be in [0, 10) s", at_field("contacts.min_contact_s"));
}

void CycleOptions::validate() const {
  if (!(min_period_s > 0 && min_period_s <= max_period_s && max_period_s <= 60))
    throw Error("need 0 < min_period_s <= max_period_s <= 60", at_field("min_period_s"));
  if (!(root_velocity_time >= 0 && joint_velocity_time >= 0))
    throw Error("must be >= 0", at_field("root_velocity_time"));
  if (!(fundamental_tolerance >= 1)) throw Error("must be >= 1", at_field("fundamental_tolerance"));
  if (skip_frames < 0) throw Error("must be >= 0", at_field("skip_frames"));
  if (!(min_mean_speed >= 0)) throw Error("must be >= 0", at_field("min_mean_speed"));
  if (max_frame_joints < 1) throw Error("must be >= 1", at_field("max_frame_joints"));
  contacts.validate();
}

ContactReport detect_foot_contacts(const Skeleton& skeleton, const ModelSpaceClip& m, double dt, const FeetJoints& feet,
                                   const ContactOptions& o) {
  o.validate();
  check_frame_time(dt);
  const std::int32_t F = m.frame_count;
  const double leg = leg_length(skeleton);
  ContactReport r;
  r.height_threshold = o.height_fraction * leg;
  r.speed_threshold = o.speed_fraction * leg;
  r.smoothing_frames = smoothing_frames(o.smoothing_s, dt);
  const std::int32_t k = std::max<std::int32_t>(1, r.smoothing_frames);
  const std::int32_t gap = frames_floor(o.max_gap_s, dt);
  const std::int32_t min_len = std::max<std::int32_t>(1, frames_ceil(o.min_contact_s, dt));
  for (int f = 0; f < 2; ++f) {
    FootContacts& fc = r.feet[static_cast<std::size_t>(f)];
    fc.in_contact.assign(static_cast<std::size_t>(F), 0);
    const auto tracks = foot_tracks(m, feet, f, 0);
    for (std::size_t p = 0; p < 2; ++p) {
      const std::vector<glm::vec3>& track = tracks[p];
      if (track.empty() || F == 0) continue;
      std::vector<double> heights(static_cast<std::size_t>(F));
      for (std::int32_t i = 0; i < F; ++i) heights[static_cast<std::size_t>(i)] = track[static_cast<std::size_t>(i)].y;
      const double ground = percentile(heights, o.ground_percentile);
      fc.ground[p] = ground;
      for (std::int32_t i = 0; i < F; ++i) {
        const std::int32_t lo = std::max(i - k, 0), hi = std::min(i + k, F - 1);
        const double speed =
            hi > lo ? horizontal_distance(track[static_cast<std::size_t>(hi)], track[static_cast<std::size_t>(lo)]) /
                          ((hi - lo) * dt)
                    : 0.0;
        if (heights[static_cast<std::size_t>(i)] - ground < r.height_threshold && speed < r.speed_threshold)
          fc.in_contact[static_cast<std::size_t>(i)] = 1;
      }
    }
    // Fill short gaps between contact frames, then keep long enough runs.
    std::int32_t last = -1;
    for (std::int32_t i = 0; i < F; ++i) {
      if (!fc.in_contact[static_cast<std::size_t>(i)]) continue;
      if (last >= 0 && i - last - 1 <= gap)
        for (std::int32_t g = last + 1; g < i; ++g) fc.in_contact[static_cast<std::size_t>(g)] = 1;
      last = i;
    }
    for (std::int32_t i = 0; i < F;) {
      if (!fc.in_contact[static_cast<std::size_t>(i)]) {
        ++i;
        continue;
      }
      std::int32_t e = i;
      while (e < F && fc.in_contact[static_cast<std::size_t>(e)]) ++e;
      if (e - i >= min_len)
        fc.intervals.push_back({i, e});
      else
        for (std::int32_t g = i; g < e; ++g) fc.in_contact[static_cast<std::size_t>(g)] = 0;
      i = e;
    }
  }
  return r;
}

namespace {

// Error unless `frames` frames of the clip, times (joints + 1) points, fit
// max_frame_joints: features take 2 x 24 bytes per point and frame, the
// search frames x periods x points.
void check_analysis_size(std::int64_t frames, std::int32_t joint_count, const CycleOptions& o) {
  if (frames * (joint_count + 1) > o.max_frame_joints)
    throw Error("clip too long for cycle analysis: " + std::to_string(frames) + " frames x " +
                    std::to_string(joint_count + 1) + " points exceeds " + std::to_string(o.max_frame_joints),
                at_field("max_frame_joints"));
}

// Whether analyze_cycle takes the clip as one loop: Always yes, Never no;
// Auto, for clips shorter than two of the longest periods (max_p frames)
// plus 2, when frame 0 matches the last frame extrapolated by one step in
// the heading frame (RMS over the feature points below 2% of the leg
// length `leg`, m; dt in s).
bool is_loop(const Skeleton& skeleton, const Clip& input, const CycleOptions& o, double dt, double leg,
             std::int32_t max_p) {
  const std::int32_t N = input.frame_count;
  bool loop = o.loop == CycleOptions::Loop::Always;
  if (o.loop == CycleOptions::Loop::Auto && N < 2 * max_p + 2) {
    const ModelSpaceClip m = forward_kinematics(skeleton, input);
    const Features f = compute_features(m, dt, leg);
    double sum = 0;
    for (std::int32_t k = 0; k < f.points; ++k) {
      const glm::dvec3 extrapolated = 2.0 * f.pose[at(N - 1, f.points, k)] - f.pose[at(N - 2, f.points, k)];
      const glm::dvec3 d = f.pose[at(0, f.points, k)] - extrapolated;
      sum += glm::dot(d, d);
    }
    loop = std::sqrt(sum / f.points) < 0.02 * leg;
  }
  return loop;
}

// The cost of every (a, a + p) over the analysed frames (model m, features
// f): best[p] the lowest pair cost of period p (frames, min_p..p_hi) over
// starts a from skip_frames (loops of N frames: a in the first copy, p <= N)
// whose root covers at least min_mean_speed (m/s) times p dt; best_a[p] that
// start. Periods without one keep cost infinity and start -1.
struct PeriodCosts {
  std::int32_t p_hi = 0;
  std::vector<double> best;
  std::vector<std::int32_t> best_a;
};
PeriodCosts period_costs(const ModelSpaceClip& m, const Features& f, const CycleOptions& o, bool loop, std::int32_t N,
                         std::int32_t min_p, std::int32_t max_p, double dt) {
  const std::int32_t F = m.frame_count;
  const std::int32_t first = std::min(o.skip_frames, F - 1);
  const std::int32_t a_end = loop ? std::min(N, F) : F;  // loops: start in the first copy
  PeriodCosts c;
  c.p_hi = loop ? std::min(max_p, N) : max_p;
  std::vector<double>& best = c.best;
  best.assign(static_cast<std::size_t>(std::max(c.p_hi + 1, 1)), std::numeric_limits<double>::infinity());
  c.best_a.assign(best.size(), -1);
  for (std::int32_t p = min_p; p <= c.p_hi; ++p) {
    for (std::int32_t a = first; a < a_end && a + p < F; ++a) {
      const glm::vec3& ra = m.positions[at(a, m.joint_count, 0)];
      const glm::vec3& rb = m.positions[at(a + p, m.joint_count, 0)];
      if (horizontal_distance(ra, rb) < o.min_mean_speed * p * dt) continue;
      const double cost = pair_cost(f, a, a + p, o).total;
      if (cost < best[static_cast<std::size_t>(p)])
        best[static_cast<std::size_t>(p)] = cost, c.best_a[static_cast<std::size_t>(p)] = a;
    }
  }
  return c;
}

// The fundamental period (frames): the shortest local minimum of the costs
// within fundamental_tolerance of the best (plus 1e-6 m^2), else the
// shortest period with the best cost; -1 when no period has a finite cost.
std::int32_t fundamental_period(const PeriodCosts& c, std::int32_t min_p, const CycleOptions& o) {
  const std::vector<double>& best = c.best;
  const std::int32_t p_hi = c.p_hi;
  double overall = std::numeric_limits<double>::infinity();
  for (std::int32_t p = min_p; p <= p_hi; ++p) overall = std::min(overall, best[static_cast<std::size_t>(p)]);
  if (!std::isfinite(overall)) return -1;
  const double accept = o.fundamental_tolerance * overall + 1e-6;
  std::int32_t period = -1;
  for (std::int32_t p = min_p; p <= p_hi && period < 0; ++p) {
    const double c_p = best[static_cast<std::size_t>(p)];
    if (!(c_p <= accept)) continue;
    const double left = p > min_p ? best[static_cast<std::size_t>(p - 1)] : std::numeric_limits<double>::infinity();
    const double right = p < p_hi ? best[static_cast<std::size_t>(p + 1)] : std::numeric_limits<double>::infinity();
    if (c_p <= left && c_p <= right) period = p;
  }
  if (period < 0) {
    for (std::int32_t p = min_p; p <= p_hi; ++p)
      if (best[static_cast<std::size_t>(p)] == overall) {
        period = p;
        break;
      }
  }
  return period;
}

// The loop (a, a + period) found: frames, seconds (dt in s), cost and pose
// RMS (m), and the root's travel: the chord between a and b (m), turned into
// the arc of a circle when the heading changes (a turning walk), its mean
// speed (m/s) and turn rate (rad/s).
void describe_loop(CycleReport& rep, const ModelSpaceClip& m, const Features& f, const CycleOptions& o, std::int32_t a,
                   std::int32_t period, double dt) {
  const std::int32_t b = a + period;
  const PairCost pc = pair_cost(f, a, b, o);
  rep.found = true;
  rep.start_frame = a;
  rep.end_frame = b;
  rep.period_frames = period;
  rep.period_s = period * dt;
  rep.cost = pc.total;
  rep.pose_rms_m = std::sqrt(pc.pose);
  const double turn = f.heading[static_cast<std::size_t>(b)] - f.heading[static_cast<std::size_t>(a)];
  const double chord = horizontal_distance(m.positions[at(a, m.joint_count, 0)], m.positions[at(b, m.joint_count, 0)]);
  const double half = 0.5 * std::abs(turn);
  rep.displacement = half > 1e-4 && half < kPi ? chord * half / std::sin(half) : chord;
  rep.mean_speed = rep.displacement / rep.period_s;
  rep.turn_rate = turn / rep.period_s;
}

// Steps (contact onsets of both feet) in one period of rep.contacts over F
// analysed frames, and from them cadence (steps per minute) and stride
// length (m per two steps). The motion repeats, so any window of length
// `period` near [a, a + period) counts the same, except that detected onsets
// wander by a frame between strides: the window's ends go as far from every
// onset as possible. A contact running at frame 0 may have begun before the
// clip, so it is no onset.
void count_steps(CycleReport& rep, std::int32_t a, std::int32_t period, std::int32_t F) {
  std::vector<std::int32_t> onsets;
  for (const FootContacts& fc : rep.contacts.feet)
    for (const ContactInterval& c : fc.intervals)
      if (c.begin > 0) onsets.push_back(c.begin);
  const std::int32_t lo = std::max(1, a - period / 2), hi = std::min(F - period, a + period / 2);
  std::int32_t w0 = std::clamp(a, std::min(lo, hi), std::max(lo, hi)), best_margin = -1;
  for (std::int32_t w = lo; w <= hi; ++w) {
    std::int32_t margin = period;
    for (std::int32_t on : onsets) margin = std::min({margin, std::abs(on - w), std::abs(on - (w + period))});
    if (margin > best_margin) best_margin = margin, w0 = w;
  }
  for (std::int32_t on : onsets)
    if (on >= w0 && on < w0 + period) ++rep.steps;
  rep.cadence = rep.steps * 60.0 / rep.period_s;
  rep.stride_length = rep.steps > 0 ? rep.displacement * 2.0 / rep.steps : 0.0;
}

}  // namespace

CycleReport analyze_cycle(const Skeleton& skeleton, const Clip& input, const CycleOptions& o) {
  o.validate();
  skeleton.validate();
  if (input.joint_count != skeleton.joint_count()) throw Error("clip and skeleton differ in joint count");
  check_frame_time(input.frame_time);
  // Refuse what would not fit before allocating.
  check_analysis_size(input.frame_count, input.joint_count, o);
  const double dt = input.frame_time;
  const double leg = leg_length(skeleton);
  CycleReport rep;
  const std::int32_t N = input.frame_count;
  if (N < 3) return rep;

  const std::int32_t max_p = frames_floor(o.max_period_s, dt);
  const std::int32_t min_p = std::max<std::int32_t>(1, frames_ceil(o.min_period_s, dt));
  const bool loop = is_loop(skeleton, input, o, dt, leg, max_p);
  rep.input_is_loop = loop;
  const std::int32_t copies = std::max<std::int32_t>(2, std::min<std::int32_t>(max_p / N + 2, 4096));
  if (loop) check_analysis_size(static_cast<std::int64_t>(N) * copies, input.joint_count, o);
  const Clip clip = loop ? repeat_cycle(input, copies) : input;
  const ModelSpaceClip m = forward_kinematics(skeleton, clip);
  const Features f = compute_features(m, dt, leg);
  const std::int32_t F = clip.frame_count;

  // Contacts (when the feet are known).
  const bool have_feet = skeleton.role(Role::LeftAnkle) >= 0 && skeleton.role(Role::RightAnkle) >= 0;
  if (have_feet) rep.contacts = detect_foot_contacts(skeleton, m, dt, FeetJoints::from_roles(skeleton), o.contacts);

  const PeriodCosts costs = period_costs(m, f, o, loop, N, min_p, max_p, dt);
  const std::int32_t period = fundamental_period(costs, min_p, o);
  if (period < 0) return rep;
  const std::int32_t a = costs.best_a[static_cast<std::size_t>(period)];
  describe_loop(rep, m, f, o, a, period, dt);
  if (have_feet) count_steps(rep, a, period, F);
  return rep;
}

Clip make_cyclic(const Clip& clip, std::int32_t a, std::int32_t b) {
  if (a < 0 || b <= a || b >= clip.frame_count)
    throw Error("make_cyclic: need 0 <= a < b < frame count (a=" + std::to_string(a) + ", b=" + std::to_string(b) +
                ", frames=" + std::to_string(clip.frame_count) + ")");
  const std::int32_t J = clip.joint_count, p = b - a;
  Clip out;
  out.resize(p, J);
  out.frame_time = clip.frame_time;
  const bool has_t = !clip.translations.empty();
  if (has_t) out.translations.assign(static_cast<std::size_t>(p) * static_cast<std::size_t>(J), glm::vec3(0.0f));
  const glm::dquat identity(1, 0, 0, 0);
  // Root: remove the heading, close the rest.
  auto split = [&](std::int32_t frame, double& psi) {
    const glm::dquat q(clip.rotations[at(frame, J, 0)]);
    psi = heading_of(clip.rotations[at(frame, J, 0)]);
    return yaw_rotation(-psi) * q;
  };
  double psi_a, psi_b;
  const glm::dquat sa = split(a, psi_a);
  glm::dquat sb = split(b, psi_b);
  if (glm::dot(sa, sb) < 0) sb = -sb;
  const glm::dquat root_fix = glm::normalize(sa * glm::inverse(sb));
  std::vector<glm::dquat> fix(static_cast<std::size_t>(J), identity);
  for (std::int32_t j = 1; j < J; ++j) {
    const glm::dquat qa(clip.rotations[at(a, J, j)]);
    glm::dquat qb(clip.rotations[at(b, J, j)]);
    if (glm::dot(qa, qb) < 0) qb = -qb;
    fix[static_cast<std::size_t>(j)] = glm::normalize(qa * glm::inverse(qb));
  }
  const glm::vec3 height_fix(
      0.0f, clip.root_positions[static_cast<std::size_t>(a)].y - clip.root_positions[static_cast<std::size_t>(b)].y,
      0.0f);
  for (std::int32_t i = 0; i < p; ++i) {
    const double w = static_cast<double>(i) / p;
    const std::int32_t src = a + i;
    double psi;
    const glm::dquat s = split(src, psi);
    glm::dquat root = yaw_rotation(psi) * glm::slerp(identity, root_fix, w) * s;
    out.rotations[at(i, J, 0)] = glm::quat(glm::normalize(root));
    for (std::int32_t j = 1; j < J; ++j) {
      glm::dquat q =
          glm::slerp(identity, fix[static_cast<std::size_t>(j)], w) * glm::dquat(clip.rotations[at(src, J, j)]);
      out.rotations[at(i, J, j)] = glm::quat(glm::normalize(q));
    }
    out.root_positions[static_cast<std::size_t>(i)] =
        clip.root_positions[static_cast<std::size_t>(src)] + static_cast<float>(w) * height_fix;
    if (has_t)
      for (std::int32_t j = 0; j < J; ++j)
        out.translations[at(i, J, j)] =
            clip.translations[at(src, J, j)] +
            static_cast<float>(w) * (clip.translations[at(a, J, j)] - clip.translations[at(b, J, j)]);
  }
  return out;
}

Clip make_cyclic(const Clip& clip, const CycleReport& report) {
  if (!report.found) throw Error("make_cyclic: the cycle report found no cycle");
  if (report.end_frame < clip.frame_count) return make_cyclic(clip, report.start_frame, report.end_frame);
  const std::int32_t copies = report.end_frame / std::max(clip.frame_count, 1) + 1;
  return make_cyclic(repeat_cycle(clip, copies), report.start_frame, report.end_frame);
}

Clip repeat_cycle(const Clip& cycle, std::int32_t copies) {
  const std::int32_t N = cycle.frame_count, J = cycle.joint_count;
  if (copies < 1 || copies > 4096) throw Error("repeat_cycle: copies must be in [1, 4096]");
  if (N < 3) throw Error("repeat_cycle: a cycle needs at least 3 frames");
  if (static_cast<std::int64_t>(N) * copies * std::max(J, 1) > (std::int64_t{1} << 25))
    throw Error("repeat_cycle: result too long (" + std::to_string(N) + " frames x " + std::to_string(copies) +
                " copies)");
  std::vector<double> psi(static_cast<std::size_t>(N));
  for (std::int32_t i = 0; i < N; ++i) {
    const double h = heading_of(cycle.rotations[at(i, J, 0)]);
    psi[static_cast<std::size_t>(i)] =
        i == 0 ? h : psi[static_cast<std::size_t>(i - 1)] + wrap_angle(h - psi[static_cast<std::size_t>(i - 1)]);
  }
  auto step = [&](std::int32_t i) {  // root step i -> i+1 in the heading frame of i
    const glm::dvec3 d = glm::dvec3(cycle.root_positions[static_cast<std::size_t>(i + 1)] -
                                    cycle.root_positions[static_cast<std::size_t>(i)]);
    return yaw_rotation(-psi[static_cast<std::size_t>(i)]) * glm::dvec3(d.x, 0.0, d.z);
  };
  const glm::dvec3 last_step = 0.5 * (step(N - 2) + step(0));
  const double last_turn =
      0.5 * ((psi[static_cast<std::size_t>(N - 1)] - psi[static_cast<std::size_t>(N - 2)]) + (psi[1] - psi[0]));
  const double turn = psi[static_cast<std::size_t>(N - 1)] + last_turn - psi[0];  // per copy
  const glm::dvec3 r0(cycle.root_positions[0]);
  const glm::dvec3 rN = glm::dvec3(cycle.root_positions[static_cast<std::size_t>(N - 1)]) +
                        yaw_rotation(psi[static_cast<std::size_t>(N - 1)]) * last_step;
  Clip out;
  out.resize(N * copies, J);
  out.frame_time = cycle.frame_time;
  if (!cycle.translations.empty()) out.translations.resize(out.rotations.size());
  glm::dvec3 origin(r0.x, 0.0, r0.z);  // where copy k starts (horizontal)
  double yaw = 0.0;                    // rotation of copy k
  for (std::int32_t k = 0; k < copies; ++k) {
    const glm::dquat ry = yaw_rotation(yaw);
    for (std::int32_t i = 0; i < N; ++i) {
      const std::int32_t o = k * N + i;
      const glm::dvec3 r(cycle.root_positions[static_cast<std::size_t>(i)]);
      const glm::dvec3 rel = ry * glm::dvec3(r.x - r0.x, 0.0, r.z - r0.z);
      out.root_positions[static_cast<std::size_t>(o)] = glm::vec3(origin + rel + glm::dvec3(0.0, r.y, 0.0));
      out.rotations[at(o, J, 0)] = glm::quat(glm::normalize(ry * glm::dquat(cycle.rotations[at(i, J, 0)])));
      for (std::int32_t j = 1; j < J; ++j) out.rotations[at(o, J, j)] = cycle.rotations[at(i, J, j)];
      if (!cycle.translations.empty())
        for (std::int32_t j = 0; j < J; ++j) out.translations[at(o, J, j)] = cycle.translations[at(i, J, j)];
    }
    origin += ry * glm::dvec3(rN.x - r0.x, 0.0, rN.z - r0.z);
    yaw += turn;
  }
  return out;
}

}  // namespace throng::motion
