#include "motion/locomotion.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <span>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/error.h"
#include "core/math.h"
#include "motion/default_set.h"

namespace throng::motion {

namespace {

std::size_t at(std::int64_t i) { return static_cast<std::size_t>(i); }

// Element (frame i, joint j) of a ModelSpaceClip's arrays.
std::size_t frame_joint(const ModelSpaceClip& m, std::int32_t i, std::int32_t j) {
  return at(static_cast<std::int64_t>(i) * m.joint_count + j);
}

double wrap_unit(double p) {
  p -= std::floor(p);
  return p < 1.0 ? p : 0.0;
}

Location clip_field(const std::string& name, const std::string& field) {
  return at_field("locomotion." + (name.empty() ? std::string("clip") : name) + (field.empty() ? "" : "." + field));
}

// The normalised mean of unit quaternions, each taken in the hemisphere of
// the first (a good mean for rotations spread over less than ~90 degrees).
glm::quat mean_rotation(const std::vector<glm::quat>& rotations, std::int32_t frames, std::int32_t joints,
                        std::int32_t joint) {
  const glm::dquat first(rotations[at(joint)]);
  glm::dquat sum(0, 0, 0, 0);
  for (std::int32_t f = 0; f < frames; ++f) {
    glm::dquat q(rotations[at(static_cast<std::int64_t>(f) * joints + joint)]);
    if (glm::dot(q, first) < 0) q = -q;
    sum = sum + q;
  }
  const double n = glm::length(sum);
  return n > 1e-12 ? glm::quat(sum / n) : glm::quat(first);
}

// Root-to-ankle chains of both legs for the foot-planting IK; a leg whose
// thigh -> knee -> ankle is not a parent chain (or is too deep) gets none.
std::array<LegChain, 2> leg_chains(const Skeleton& s) {
  std::array<LegChain, 2> legs{};
  const std::array<std::array<Role, 3>, 2> roles{
      {{Role::LeftThigh, Role::LeftKnee, Role::LeftAnkle}, {Role::RightThigh, Role::RightKnee, Role::RightAnkle}}};
  for (std::size_t leg = 0; leg < 2; ++leg) {
    const std::int32_t knee = s.role(roles[leg][1]), ankle = s.role(roles[leg][2]);
    if (knee < 0 || ankle < 0 || s.parents[at(ankle)] != knee) continue;
    const std::int32_t thigh = s.role(roles[leg][0]) >= 0 ? s.role(roles[leg][0]) : s.parents[at(knee)];
    if (thigh <= 0 || s.parents[at(knee)] != thigh) continue;
    std::vector<std::int32_t> chain;
    for (std::int32_t j = ankle; j >= 0; j = s.parents[at(j)]) chain.push_back(j);
    if (chain.size() < 4 || chain.size() > static_cast<std::size_t>(kMaxLegChain)) continue;
    std::reverse(chain.begin(), chain.end());
    legs[leg].count = static_cast<std::int32_t>(chain.size());
    std::copy(chain.begin(), chain.end(), legs[leg].joints);
    // The ball of the foot: the toe joint when it hangs off the ankle, else the ankle's end site.
    const std::int32_t toe = s.role(leg == 0 ? Role::LeftToe : Role::RightToe);
    glm::vec3 ball(0.0f);
    if (toe >= 0 && s.parents[at(toe)] == ankle) {
      ball = s.offsets[at(toe)];
      legs[leg].has_ball = true;
    } else if (s.has_end_site[at(ankle)]) {
      ball = s.end_sites[at(ankle)];
      legs[leg].has_ball = true;
    }
    legs[leg].ball[0] = ball.x;
    legs[leg].ball[1] = ball.y;
    legs[leg].ball[2] = ball.z;
  }
  return legs;
}

}  // namespace

const char* to_string(FootEvent e) {
  switch (e) {
    case FootEvent::LeftDown: return "left_down";
    case FootEvent::LeftUp: return "left_up";
    case FootEvent::RightDown: return "right_down";
    case FootEvent::RightUp: return "right_up";
  }
  return "unknown";
}

void LocomotionOptions::validate() const {
  cycle.validate();
  contacts.validate();
  if (!(std::isfinite(stationary_below_m) && stationary_below_m >= 0.0 && stationary_below_m < 10.0))
    throw Error("must be in [0, 10) m", at_field("locomotion.stationary_below_m"));
  if (!(std::isfinite(contact_ramp_s) && contact_ramp_s >= 0.0 && contact_ramp_s <= 1.0))
    throw Error("must be in [0, 1] s", at_field("locomotion.contact_ramp_s"));
  if (!(std::isfinite(cleanup_speed_factor) && cleanup_speed_factor >= 1.0 && cleanup_speed_factor <= 20.0))
    throw Error("must be in [1, 20]", at_field("locomotion.cleanup_speed_factor"));
  if (!(std::isfinite(max_cleanup_m) && max_cleanup_m > 0.0 && max_cleanup_m <= 1.0))
    throw Error("must be in (0, 1] m", at_field("locomotion.max_cleanup_m"));
}

namespace {

// The cycle repeated `copies` times in its own motion: the root on its path
// (a line, or an arc when the clip turns) at stride_m per cycle.
Clip cycle_in_world(const LocomotionClip& c, std::int32_t copies) {
  const std::int32_t F = c.cycle.frame_count, J = c.cycle.joint_count;
  Clip w;
  w.resize(F * copies, J);
  w.frame_time = c.cycle.frame_time;
  for (std::int32_t i = 0; i < F * copies; ++i) {
    const double phi = static_cast<double>(i) / F;
    const double yaw = c.turn_rad * phi;
    glm::dvec3 path(0.0, 0.0, c.stride_m * phi);
    if (std::abs(c.turn_rad) > 1e-9) {
      const double r = c.stride_m / c.turn_rad;
      path = glm::dvec3(r * (1.0 - std::cos(yaw)), 0.0, r * std::sin(yaw));
    }
    const std::int32_t k = i % F;
    w.root_positions[at(i)] = glm::vec3(path + yaw_rotation(yaw) * glm::dvec3(c.cycle.root_positions[at(k)]));
    w.rotation(i, 0) = glm::quat(glm::normalize(yaw_rotation(yaw) * glm::dquat(c.cycle.rotation(k, 0))));
    for (std::int32_t j = 1; j < J; ++j) w.rotation(i, j) = c.cycle.rotation(k, j);
  }
  return w;
}

// Error (naming the clip's field) unless `cycle` has the skeleton's joints,
// at least 4 frames, a positive frame time and arrays of its frame and joint
// counts.
void check_cycle(const Skeleton& skeleton, const Clip& cycle, const std::string& name) {
  const std::int32_t J = skeleton.joint_count();
  const std::int32_t F = cycle.frame_count;
  if (cycle.joint_count != J)
    throw Error("has " + std::to_string(cycle.joint_count) + " joints, the skeleton " + std::to_string(J),
                clip_field(name, "joints"));
  if (F < 4) throw Error("a cycle needs at least 4 frames, got " + std::to_string(F), clip_field(name, "frames"));
  if (!(std::isfinite(cycle.frame_time) && cycle.frame_time > 0.0f))
    throw Error("frame time must be positive", clip_field(name, "frame_time"));
  if (cycle.rotations.size() != at(static_cast<std::int64_t>(F) * J) || cycle.root_positions.size() != at(F))
    throw Error("arrays do not match its frame and joint counts", clip_field(name, ""));
}

// The path of a cycle: a line or an arc through the cycle's start and end,
// heading psi0 + turn * phase; stationary clips stay at the root's mean
// ground point (stride 0).
struct CyclePath {
  bool stationary = false;
  double turn = 0.0;       // heading change per cycle (rad)
  double psi0 = 0.0;       // heading at phase 0 (rad)
  double stride = 0.0;     // path length per cycle (m)
  glm::dvec3 origin{0.0};  // path point at phase 0 (m, y = 0)

  // The path point at phase phi (one cycle per unit), m.
  glm::dvec3 point(double phi) const {
    glm::dvec3 local(0.0, 0.0, stride * phi);
    if (!stationary && std::abs(turn) > 1e-9) {
      const double r = stride / turn;
      local = glm::dvec3(r * (1.0 - std::cos(turn * phi)), 0.0, r * std::sin(turn * phi));
    }
    return origin + yaw_rotation(psi0) * local;
  }
};

// Fits the path to `ext`, three copies of a cycle of F frames with the root
// carried on (frame F is frame 0 one cycle on): the turn from the root's
// unwrapped heading (rad), the chord from its ground positions (m); a chord
// below stationary_below_m (m) makes the clip stationary.
CyclePath fit_cycle_path(const Clip& ext, std::int32_t F, double stationary_below_m) {
  std::vector<double> psi(at(3 * F));
  for (std::int32_t i = 0; i < 3 * F; ++i) {
    const double h = heading_of(ext.rotation(i, 0));
    psi[at(i)] = i == 0 ? h : psi[at(i - 1)] + wrap_angle(h - psi[at(i - 1)]);
  }
  CyclePath path;
  const double turn = psi[at(F)] - psi[0];
  path.turn = turn;
  const glm::dvec3 r0(ext.root_positions[0]), rF(ext.root_positions[at(F)]);
  const double chord = std::hypot(rF.x - r0.x, rF.z - r0.z);
  path.stationary = chord < stationary_below_m;
  path.origin = glm::dvec3(r0.x, 0.0, r0.z);
  if (path.stationary) {
    double c = 0.0, s = 0.0;
    path.origin = glm::dvec3(0.0);
    for (std::int32_t i = 0; i < F; ++i) {
      const double h = psi[at(i)] - turn * i / F;
      c += std::cos(h);
      s += std::sin(h);
      path.origin += glm::dvec3(ext.root_positions[at(i)].x, 0.0, ext.root_positions[at(i)].z) / static_cast<double>(F);
    }
    path.psi0 = std::atan2(s, c);
  } else {
    path.psi0 = std::atan2(rF.x - r0.x, rF.z - r0.z) - 0.5 * turn;
    const double half = 0.5 * turn;
    path.stride = std::abs(half) > 1e-9 ? chord * half / std::sin(half) : chord;
  }
  return path;
}

// The root of the first F frames of `ext` relative to the path frame at its
// phase: offsets (m; x left, y up, z forward) and root rotations. Centres the
// path under the root (offsets of mean 0 in x and z): a parallel curve, so
// path.stride changes by the lateral shift times the turn.
struct RootOnPath {
  std::vector<glm::dvec3> offset;
  std::vector<glm::quat> rotation;
};
RootOnPath root_on_path(const Clip& ext, std::int32_t F, CyclePath& path) {
  RootOnPath root;
  root.offset.resize(at(F));
  root.rotation.resize(at(F));
  glm::dvec2 mean(0.0);
  for (std::int32_t i = 0; i < F; ++i) {
    const double phi = static_cast<double>(i) / F;
    const glm::dquat to_path = yaw_rotation(-(path.psi0 + path.turn * phi));
    root.offset[at(i)] = to_path * (glm::dvec3(ext.root_positions[at(i)]) - path.point(phi));
    root.rotation[at(i)] = glm::quat(glm::normalize(to_path * glm::dquat(ext.rotation(i, 0))));
    mean += glm::dvec2(root.offset[at(i)].x, root.offset[at(i)].z) / static_cast<double>(F);
  }
  for (glm::dvec3& d : root.offset) d -= glm::dvec3(mean.x, 0.0, mean.y);
  if (!path.stationary) path.stride -= mean.x * path.turn;
  return root;
}

// Frames of the foot events of a prepared cycle (in FootEvent order), from
// the contacts of the cycle in its own motion over the middle of three
// copies; -1 for a foot without exactly one touchdown and one liftoff there.
std::array<std::int32_t, kFootEvents> foot_event_frames(const Skeleton& skeleton, const LocomotionClip& out,
                                                        const ContactOptions& o) {
  const std::int32_t F = out.cycle.frame_count;
  std::array<std::int32_t, kFootEvents> event_frame{-1, -1, -1, -1};
  const ModelSpaceClip model = forward_kinematics(skeleton, cycle_in_world(out, 3));
  const ContactReport contacts =
      detect_foot_contacts(skeleton, model, out.cycle.frame_time, FeetJoints::from_roles(skeleton), o);
  for (int f = 0; f < 2; ++f) {
    std::int32_t downs = 0, ups = 0, down = -1, up = -1;
    for (const ContactInterval& c : contacts.feet[at(f)].intervals) {
      if (c.begin >= F && c.begin < 2 * F) ++downs, down = c.begin - F;
      if (c.end >= F && c.end < 2 * F) ++ups, up = c.end - F;
    }
    if (downs == 1 && ups == 1) {
      event_frame[at(f == 0 ? 0 : 2)] = down;
      event_frame[at(f == 0 ? 1 : 3)] = up;
    }
  }
  return event_frame;
}

// Sets the events' phases and re-phases the cycle so that frame 0 is the
// left touchdown (event_frame[0]; frame 0 stays when there is none). The
// offsets are periodic, so rotating the frame order is exact.
void start_at_left_touchdown(LocomotionClip& out, const std::array<std::int32_t, kFootEvents>& event_frame) {
  const std::int32_t F = out.cycle.frame_count, J = out.cycle.joint_count;
  const std::int32_t k0 = event_frame[0] >= 0 ? event_frame[0] : 0;
  for (int e = 0; e < kFootEvents; ++e)
    if (event_frame[at(e)] >= 0)
      out.events[at(e)] = static_cast<float>(wrap_unit(static_cast<double>(event_frame[at(e)] - k0) / F));
  if (k0 != 0) {
    const Clip before = out.cycle;
    for (std::int32_t i = 0; i < F; ++i) {
      const std::int32_t src = (i + k0) % F;
      for (std::int32_t j = 0; j < J; ++j) out.cycle.rotation(i, j) = before.rotation(src, j);
      out.cycle.root_positions[at(i)] = before.root_positions[at(src)];
    }
  }
  out.source_start_frame = k0;
}

// Lowest height of each ankle over the cycle (m): [0] left, [1] right.
std::array<float, 2> ankle_ground(const Skeleton& skeleton, const Clip& cycle) {
  std::array<float, 2> ground{0.0f, 0.0f};
  const ModelSpaceClip model = forward_kinematics(skeleton, cycle);
  for (std::size_t f = 0; f < 2; ++f) {
    const std::int32_t ankle = skeleton.role(f == 0 ? Role::LeftAnkle : Role::RightAnkle);
    float lowest = model.position(0, ankle).y;
    for (std::int32_t i = 1; i < cycle.frame_count; ++i) lowest = std::min(lowest, model.position(i, ankle).y);
    ground[f] = lowest;
  }
  return ground;
}

// Contacts of one foot (clean_foot_contacts), in frames of `model` (three
// copies of the cycle in its own motion), run on while the ball of the foot
// stays low (contacts' height threshold above its ground, m) and rolls
// slower than cleanup_speed_factor times the contacts' speed threshold
// (m/s; frame_time in s) until the foot leaves or the next contact begins:
// mocap feet roll about toes the skeleton lacks, so the ball moves faster
// than the strict speed limit allows.
std::vector<ContactInterval> rolled_contacts(const ModelSpaceClip& model, const LegChain& chain, const FootContacts& fc,
                                             const ContactReport& contacts, float frame_time,
                                             const LocomotionOptions& o) {
  const std::int32_t ankle = chain.joints[chain.count - 1];
  const glm::vec3 ball(chain.ball[0], chain.ball[1], chain.ball[2]);
  std::vector<ContactInterval> intervals = fc.intervals;
  const double ball_ground = fc.ground[1];
  for (std::size_t k = 0; k < intervals.size() && chain.has_ball; ++k) {
    const std::int32_t limit = k + 1 < intervals.size() ? intervals[k + 1].begin : model.frame_count;
    std::int32_t& e = intervals[k].end;
    while (e < limit) {
      const glm::dvec3 b = glm::dvec3(model.position(e, ankle) + model.rotations[frame_joint(model, e, ankle)] * ball);
      const glm::dvec3 b0 =
          glm::dvec3(model.position(e - 1, ankle) + model.rotations[frame_joint(model, e - 1, ankle)] * ball);
      const double speed = std::hypot(b.x - b0.x, b.z - b0.z) / frame_time;
      if (!(b.y - ball_ground < contacts.height_threshold && speed < o.cleanup_speed_factor * contacts.speed_threshold))
        break;
      ++e;
    }
  }
  return intervals;
}

// The ankle's correction (m, world) on the frames of `model` where a foot is
// pinned, and which frames those are.
struct AnklePins {
  std::vector<glm::dvec3> correction;
  std::vector<std::uint8_t> pinned;
};

// Pins one contact of a foot whose ankle's ground level is `ground` (m).
// Heel down while the ankle is within half kHeelLift of its ground (from
// its first such frame until it rises): the ankle is pinned at its mean
// position there; from then on the ball, where it was with the foot as on
// the last heel-down frame. No heel-down frame (forefoot contact): the ball
// at its mean position. A frame whose correction would exceed max_cleanup_m
// stays free; past the contact's middle it ends the pinning (the foot has
// left, or the data disagrees with a plant).
void pin_contact(const ModelSpaceClip& model, const LegChain& chain, double ground, const ContactInterval& in,
                 double max_cleanup_m, AnklePins& pins) {
  const std::int32_t ankle = chain.joints[chain.count - 1];
  const glm::vec3 ball(chain.ball[0], chain.ball[1], chain.ball[2]);
  const auto rotation = [&](std::int32_t i) { return model.rotations[frame_joint(model, i, ankle)]; };
  glm::dvec3 anchor(0.0);
  std::int32_t down = 0, rise = in.end;
  for (std::int32_t i = in.begin; i < in.end && rise == in.end; ++i) {
    const glm::dvec3 a(model.position(i, ankle));
    if (a.y - ground < 0.5 * kHeelLift) {
      anchor += a;
      ++down;
    } else if (down > 0) {
      rise = i;
    }
  }
  glm::dvec3 ball_anchor(0.0);
  if (down > 0) {
    anchor /= static_cast<double>(down);
    ball_anchor = anchor + glm::dvec3(rotation(rise - 1) * ball);
  } else {
    for (std::int32_t i = in.begin; i < in.end; ++i)
      ball_anchor += glm::dvec3(model.position(i, ankle) + rotation(i) * ball);
    ball_anchor /= static_cast<double>(in.end - in.begin);
  }
  for (std::int32_t i = in.begin; i < in.end; ++i) {
    const bool on_heel = down > 0 && (i < rise || !chain.has_ball);
    const glm::dvec3 target = on_heel ? anchor : ball_anchor - glm::dvec3(rotation(i) * ball);
    const glm::dvec3 corr = target - glm::dvec3(model.position(i, ankle));
    if (glm::length(corr) > max_cleanup_m) {
      if (i > in.begin + (in.end - in.begin) / 2) break;
      continue;
    }
    pins.correction[at(i)] = corr;
    pins.pinned[at(i)] = 1;
  }
}

// Fades corrections in and out: a free frame within `ramp` frames of a
// pinned one takes the nearest pinned frame's correction (the mean of both
// when two are as near), scaled by 1 - d / (ramp + 1) at distance d.
std::vector<glm::dvec3> faded_corrections(const AnklePins& pins, std::int32_t ramp) {
  const auto frames = static_cast<std::int32_t>(pins.pinned.size());
  const std::vector<glm::dvec3>& correction = pins.correction;
  std::vector<glm::dvec3> faded = correction;
  for (std::int32_t i = 0; i < frames; ++i) {
    if (pins.pinned[at(i)]) continue;
    for (std::int32_t d = 1; d <= ramp; ++d) {
      const std::int32_t before = i - d, after = i + d;
      const bool b = before >= 0 && pins.pinned[at(before)], a = after < frames && pins.pinned[at(after)];
      if (!a && !b) continue;
      const glm::dvec3 near =
          b && a ? 0.5 * (correction[at(before)] + correction[at(after)]) : correction[at(b ? before : after)];
      faded[at(i)] = near * (1.0 - static_cast<double>(d) / (ramp + 1));
      break;
    }
  }
  return faded;
}

// Moves one leg's ankle by its faded corrections (m) on the middle copy's
// frames, which are the cycle's: two-bone IK turns thigh and knee, the foot
// keeps its world rotation; writes the local rotations of thigh, knee and
// ankle into c.cycle. Returns `largest` raised to the largest correction.
double correct_leg(const Skeleton& skeleton, const LegChain& chain, const ModelSpaceClip& model,
                   const std::vector<glm::dvec3>& faded, LocomotionClip& c, double largest) {
  const std::int32_t F = c.cycle.frame_count;
  const std::int32_t thigh = chain.joints[chain.count - 3], knee = chain.joints[chain.count - 2],
                     ankle = chain.joints[chain.count - 1];
  const auto rotation = [&](std::int32_t i, std::int32_t j) { return model.rotations[frame_joint(model, i, j)]; };
  const std::int32_t hip_parent = skeleton.parents[at(thigh)];
  const glm::vec3 hinge = knee_hinge(skeleton.offsets[at(knee)], skeleton.offsets[at(ankle)], {&c.cycle}, knee);
  for (std::int32_t k = 0; k < F; ++k) {
    const std::int32_t i = F + k;
    const glm::dvec3& corr = faded[at(i)];
    if (glm::length(corr) < 1e-7) continue;
    largest = std::max(largest, glm::length(corr));
    const glm::vec3 target = model.position(i, ankle) + glm::vec3(corr);
    glm::quat r_thigh = rotation(i, thigh);
    glm::quat r_knee = rotation(i, knee);
    const glm::quat r_foot = rotation(i, ankle);
    if (!two_bone_ik(model.position(i, thigh), skeleton.offsets[at(knee)], skeleton.offsets[at(ankle)], hinge, target,
                     r_thigh, r_knee))
      continue;
    c.cycle.rotation(k, thigh) = glm::normalize(glm::inverse(rotation(i, hip_parent)) * r_thigh);
    c.cycle.rotation(k, knee) = glm::normalize(glm::inverse(r_thigh) * r_knee);
    c.cycle.rotation(k, ankle) = glm::normalize(glm::inverse(r_knee) * r_foot);
  }
  return largest;
}

}  // namespace

LocomotionClip prepare_locomotion_cycle(const Skeleton& skeleton, const Clip& cycle, std::string name,
                                        const LocomotionOptions& o) {
  o.validate();
  skeleton.validate();
  check_cycle(skeleton, cycle, name);
  const std::int32_t J = skeleton.joint_count();
  const std::int32_t F = cycle.frame_count;

  // Three copies with the root carried on: frame F is frame 0 one cycle on.
  const Clip ext = repeat_cycle(cycle, 3);
  CyclePath path = fit_cycle_path(ext, F, o.stationary_below_m);
  const RootOnPath root = root_on_path(ext, F, path);

  LocomotionClip out;
  out.name = std::move(name);
  out.cycle.resize(F, J);
  out.cycle.frame_time = cycle.frame_time;
  for (std::int32_t i = 0; i < F; ++i) {
    for (std::int32_t j = 1; j < J; ++j) out.cycle.rotation(i, j) = cycle.rotation(i, j);
    out.cycle.rotation(i, 0) = root.rotation[at(i)];
    out.cycle.root_positions[at(i)] = glm::vec3(root.offset[at(i)]);
  }
  out.period_s = static_cast<double>(F) * cycle.frame_time;
  out.stride_m = path.stride;
  out.turn_rad = path.turn;
  if (o.straighten) {
    out.turn_removed_rad = path.turn;
    out.turn_rad = 0.0;
  }
  out.speed = path.stride / out.period_s;
  const bool have_feet = skeleton.role(Role::LeftAnkle) >= 0 && skeleton.role(Role::RightAnkle) >= 0;
  if (o.clean_contacts && have_feet && !path.stationary) out.contact_cleanup_m = clean_foot_contacts(skeleton, out, o);

  // Foot events of the (cleaned) cycle; frame 0 at the left touchdown.
  std::array<std::int32_t, kFootEvents> event_frame{-1, -1, -1, -1};
  if (have_feet) event_frame = foot_event_frames(skeleton, out, o.contacts);
  start_at_left_touchdown(out, event_frame);
  out.mean_rotations.resize(at(J));
  for (std::int32_t j = 0; j < J; ++j) out.mean_rotations[at(j)] = mean_rotation(out.cycle.rotations, F, J, j);
  if (have_feet) out.ankle_ground = ankle_ground(skeleton, out.cycle);
  return out;
}

double clean_foot_contacts(const Skeleton& skeleton, LocomotionClip& c, const LocomotionOptions& o) {
  o.validate();
  const std::int32_t F = c.cycle.frame_count, J = c.cycle.joint_count;
  if (J != skeleton.joint_count() || F < 4) throw Error("clip and skeleton disagree", clip_field(c.name, "cycle"));
  if (skeleton.role(Role::LeftAnkle) < 0 || skeleton.role(Role::RightAnkle) < 0) return 0.0;
  const std::array<LegChain, 2> legs = leg_chains(skeleton);
  const Clip world = cycle_in_world(c, 3);
  const ModelSpaceClip model = forward_kinematics(skeleton, world);
  const ContactReport contacts =
      detect_foot_contacts(skeleton, model, c.cycle.frame_time, FeetJoints::from_roles(skeleton), o.contacts);
  const std::int32_t ramp =
      std::max<std::int32_t>(1, static_cast<std::int32_t>(std::lround(o.contact_ramp_s / c.cycle.frame_time)));
  const std::size_t frames = at(3 * F);
  double largest = 0.0;
  for (std::size_t leg = 0; leg < 2; ++leg) {
    const LegChain& chain = legs[leg];
    if (chain.count < 4) continue;
    const FootContacts& fc = contacts.feet[leg];
    // The ankle's correction on every contact frame, then faded in and out.
    AnklePins pins{std::vector<glm::dvec3>(frames, glm::dvec3(0.0)), std::vector<std::uint8_t>(frames, 0)};
    for (const ContactInterval& in : rolled_contacts(model, chain, fc, contacts, c.cycle.frame_time, o))
      pin_contact(model, chain, fc.ground[0], in, o.max_cleanup_m, pins);
    largest = correct_leg(skeleton, chain, model, faded_corrections(pins, ramp), c, largest);
  }
  return largest;
}

namespace {

// Why a clip has no locomotion cycle, in the clip's own figures: how far
// its root travels and in how long, against what a cycle needs.
std::string no_cycle_message(const Clip& clip, const CycleOptions& o) {
  const std::int32_t first = std::clamp(o.skip_frames, 0, std::max(clip.frame_count - 1, 0));
  const double seconds = static_cast<double>(clip.frame_count - 1 - first) * clip.frame_time;
  double travel = 0.0;
  for (std::int32_t f = first + 1; f < clip.frame_count; ++f) {
    const glm::vec3 d = clip.root_positions[at(f)] - clip.root_positions[at(f - 1)];
    travel += std::hypot(static_cast<double>(d.x), static_cast<double>(d.z));
  }
  if (seconds < o.min_period_s)
    return fmt::format("no locomotion cycle: the clip lasts {:.2f} s{}, shorter than a cycle ({:.1f} s at least)",
                       seconds, first > 0 ? fmt::format(" after skip_frames {}", first) : std::string(),
                       o.min_period_s);
  if (travel < o.min_mean_speed * seconds)
    return fmt::format(
        "no locomotion cycle: the root moves {:.2f} m in {:.1f} s ({:.2f} m/s): not locomotion (a walk or run "
        "moves at {:.1f} m/s or more)",
        travel, seconds, travel / seconds, o.min_mean_speed);
  return fmt::format(
      "no locomotion cycle: the root moves {:.2f} m in {:.1f} s, but no stretch of {:.1f} to {:.1f} s repeats "
      "(steady walking or running is needed{})",
      travel, seconds, o.min_period_s, o.max_period_s,
      first > 0 ? std::string() : "; a T-pose at the start can be skipped with skip_frames");
}

}  // namespace

LocomotionClip prepare_locomotion_clip(const Skeleton& skeleton, const Clip& clip, std::string name,
                                       const LocomotionOptions& o) {
  o.validate();
  const CycleReport r = analyze_cycle(skeleton, clip, o.cycle);
  if (!r.found) throw Error(no_cycle_message(clip, o.cycle), clip_field(name, "cycle"));
  LocomotionClip out = prepare_locomotion_cycle(skeleton, make_cyclic(clip, r), std::move(name), o);
  out.source_start_frame += r.start_frame;
  return out;
}

namespace {

// The largest set of events that both clips have in the same cyclic order,
// containing every `required` event and as many `optional` ones as fit
// (earlier ones preferred among sets of equal size); count 1 at phase 0
// (no warp) when a required event is missing.
SyncMarkers aligned_events(const LocomotionClip& a, const LocomotionClip& b, const std::vector<FootEvent>& required,
                           const std::vector<FootEvent>& optional) {
  constexpr float kMinGap = 0.02f;  // of a cycle, between markers in either clip
  SyncMarkers none;
  for (FootEvent e : required)
    if (!(a.event(e) >= 0.0f && b.event(e) >= 0.0f)) return none;
  const auto n = static_cast<unsigned>(optional.size());
  // Subsets of the optional events by decreasing size, then in order.
  std::vector<unsigned> subsets;
  for (unsigned m = 0; m < (1u << n); ++m) subsets.push_back(m);
  std::stable_sort(subsets.begin(), subsets.end(), [](unsigned x, unsigned y) {
    if (std::popcount(x) != std::popcount(y)) return std::popcount(x) > std::popcount(y);
    for (unsigned bit = 0; bit < 8; ++bit) {  // the earliest event decides
      const bool hx = (x >> bit) & 1u, hy = (y >> bit) & 1u;
      if (hx != hy) return hx;
    }
    return false;
  });
  for (unsigned mask : subsets) {
    std::vector<FootEvent> events = required;
    bool present = true;
    for (unsigned i = 0; i < n; ++i) {
      if (((mask >> i) & 1u) == 0u) continue;
      if (!(a.event(optional[i]) >= 0.0f && b.event(optional[i]) >= 0.0f)) present = false;
      events.push_back(optional[i]);
    }
    if (!present || events.empty() || events.size() > static_cast<std::size_t>(kMaxSyncMarkers)) continue;
    // Positions on the circle from the first required event.
    const float a0 = a.event(events[0]), b0 = b.event(events[0]);
    std::vector<std::pair<float, float>> m;
    for (FootEvent e : events)
      m.emplace_back(static_cast<float>(wrap_unit(a.event(e) - a0)), static_cast<float>(wrap_unit(b.event(e) - b0)));
    std::sort(m.begin(), m.end());
    bool ok = true;
    for (std::size_t k = 1; k < m.size(); ++k)
      if (!(m[k].first - m[k - 1].first >= kMinGap && m[k].second - m[k - 1].second >= kMinGap)) ok = false;
    if (!(1.0f - m.back().first >= kMinGap && 1.0f - m.back().second >= kMinGap)) ok = false;
    if (!ok) continue;
    SyncMarkers s;
    s.count = static_cast<std::int32_t>(m.size());
    for (std::size_t k = 0; k < m.size(); ++k) {
      s.a[k] = a0 + m[k].first;
      s.b[k] = b0 + m[k].second;
    }
    return s;
  }
  return none;
}

}  // namespace

glm::vec3 knee_hinge(const glm::vec3& knee_offset, const glm::vec3& ankle_offset, const std::vector<const Clip*>& clips,
                     std::int32_t knee) {
  // In the thigh's frame the thigh is knee_offset and the shin q * ankle_offset.
  glm::dvec3 sum(0.0);
  for (const Clip* c : clips)
    for (std::int32_t f = 0; f < c->frame_count; ++f)
      sum += glm::cross(glm::dvec3(knee_offset), glm::dvec3(c->rotation(f, knee) * ankle_offset));
  const double n = glm::length(sum);
  if (n > 1e-9) return glm::vec3(sum / n);
  // Never bent: any axis across the thigh.
  glm::dvec3 a = glm::cross(glm::dvec3(knee_offset), glm::dvec3(0, 0, 1));
  if (glm::length(a) < 1e-9) a = glm::cross(glm::dvec3(knee_offset), glm::dvec3(1, 0, 0));
  return glm::length(a) > 1e-12 ? glm::vec3(glm::normalize(a)) : glm::vec3(1, 0, 0);
}

SegmentSync sync_markers(const LocomotionClip& a, const LocomotionClip& b) {
  using E = FootEvent;
  SegmentSync s;
  s.group[0] = aligned_events(a, b, {E::LeftDown}, {E::RightDown, E::LeftUp, E::RightUp});
  s.group[1] = aligned_events(a, b, {E::LeftDown, E::LeftUp}, {E::RightDown, E::RightUp});
  s.group[2] = aligned_events(a, b, {E::RightDown, E::RightUp}, {E::LeftDown, E::LeftUp});
  // A leg whose own events are missing follows the body.
  for (int g = 1; g < kSyncGroups; ++g)
    if (s.group[g].count <= 1 && s.group[g].a[0] == 0.0f && s.group[g].b[0] == 0.0f) s.group[g] = s.group[0];
  return s;
}

BlendSpace1D::BlendSpace1D(Skeleton skeleton, std::vector<LocomotionClip> clips, const BlendSpaceOptions& options)
    : skeleton_(std::move(skeleton)), clips_(std::move(clips)), plant_feet_(options.plant_feet) {
  skeleton_.validate();
  const std::int32_t J = skeleton_.joint_count();
  if (clips_.empty()) throw Error("a blend space needs at least one clip", at_field("blend_space.clips"));
  if (clips_.size() > 256) throw Error("at most 256 clips", at_field("blend_space.clips"));
  std::int64_t rows = 0;
  for (const LocomotionClip& c : clips_) {
    const Location where = at_field("blend_space.clips." + c.name);
    if (c.cycle.joint_count != J)
      throw Error("has " + std::to_string(c.cycle.joint_count) + " joints, the skeleton " + std::to_string(J), where);
    if (c.cycle.frame_count < 2 || c.cycle.rotations.size() != at(static_cast<std::int64_t>(c.cycle.frame_count) * J) ||
        c.cycle.root_positions.size() != at(c.cycle.frame_count) || c.mean_rotations.size() != at(J))
      throw Error("is not a prepared cycle (prepare_locomotion_clip)", where);
    if (!(std::isfinite(c.speed) && c.speed >= 0.0 && std::isfinite(c.stride_m) && c.stride_m >= 0.0 &&
          std::isfinite(c.period_s) && c.period_s > 0.0 && std::isfinite(c.turn_rad)))
      throw Error("speed, stride and period must be finite, period positive", where);
    rows += c.cycle.frame_count;
  }
  if (rows > (std::int64_t{1} << 24))
    throw Error("too many frames in all (" + std::to_string(rows) + ")", at_field("blend_space.clips"));
  std::stable_sort(clips_.begin(), clips_.end(),
                   [](const LocomotionClip& a, const LocomotionClip& b) { return a.speed < b.speed; });
  for (std::size_t i = 1; i < clips_.size(); ++i)
    if (!(clips_[i].speed - clips_[i - 1].speed > 1e-3))
      throw Error("clips '" + clips_[i - 1].name + "' and '" + clips_[i].name + "' have the same speed (" +
                      std::to_string(clips_[i].speed) + " m/s): a speed blend space needs distinct speeds",
                  at_field("blend_space.clips"));

  Clip stacked;
  stacked.resize(static_cast<std::int32_t>(rows), J);
  std::int32_t row = 0;
  for (const LocomotionClip& c : clips_) {
    ClipInfo info;
    info.first_row = row;
    info.rows = c.cycle.frame_count;
    info.speed = static_cast<float>(c.speed);
    info.stride = static_cast<float>(c.stride_m);
    info.turn = static_cast<float>(c.turn_rad);
    info.period = static_cast<float>(c.period_s);
    info.ankle_ground[0] = c.ankle_ground[0];
    info.ankle_ground[1] = c.ankle_ground[1];
    info.contact[0][0] = c.event(FootEvent::LeftDown);
    info.contact[0][1] = c.event(FootEvent::LeftUp);
    info.contact[1][0] = c.event(FootEvent::RightDown);
    info.contact[1][1] = c.event(FootEvent::RightUp);
    clip_infos_.push_back(info);
    std::copy(c.cycle.rotations.begin(), c.cycle.rotations.end(),
              stacked.rotations.begin() + static_cast<std::ptrdiff_t>(row) * J);
    std::copy(c.cycle.root_positions.begin(), c.cycle.root_positions.end(), stacked.root_positions.begin() + row);
    mean_rotations_.insert(mean_rotations_.end(), c.mean_rotations.begin(), c.mean_rotations.end());
    row += c.cycle.frame_count;
  }
  texture_ = make_motion_texture(skeleton_, stacked, options.format);
  legs_ = leg_chains(skeleton_);
  std::vector<const Clip*> cycles;
  for (const LocomotionClip& c : clips_) cycles.push_back(&c.cycle);
  for (LegChain& leg : legs_) {
    if (leg.count < 4) continue;
    const std::int32_t knee = leg.joints[leg.count - 2], ankle = leg.joints[leg.count - 1];
    const glm::vec3 h = knee_hinge(skeleton_.offsets[at(knee)], skeleton_.offsets[at(ankle)], cycles, knee);
    leg.hinge[0] = h.x;
    leg.hinge[1] = h.y;
    leg.hinge[2] = h.z;
  }
  // The leg groups: each thigh's subtree (the joints its warp moves).
  joint_group_.assign(static_cast<std::size_t>(J), 0);
  for (std::size_t leg = 0; leg < 2; ++leg) {
    if (legs_[leg].count < 4) continue;
    const std::int32_t thigh = legs_[leg].joints[legs_[leg].count - 3];
    for (std::int32_t j = thigh; j < J; ++j)
      for (std::int32_t p = j; p >= 0; p = skeleton_.parents[at(p)])
        if (p == thigh) {
          joint_group_[at(j)] = static_cast<std::uint8_t>(1 + leg);
          break;
        }
  }
  if (clips_.size() == 1) {
    sync_.push_back(SegmentSync{});
  } else {
    for (std::size_t k = 0; k + 1 < clips_.size(); ++k) sync_.push_back(sync_markers(clips_[k], clips_[k + 1]));
  }
}

std::int32_t BlendSpace1D::max_frames() const {
  std::int32_t m = 0;
  for (const ClipInfo& c : clip_infos_) m = std::max(m, c.rows);
  return m;
}

BlendSpaceView BlendSpace1D::view() const {
  BlendSpaceView v;
  v.joint_count = joint_count();
  v.clip_count = clip_count();
  v.texture = texture_.view();
  v.clips = clip_infos_.data();
  v.sync = sync_.data();
  v.joint_group = joint_group_.data();
  v.mean_rotations = mean_rotations_.data();
  v.parents = skeleton_.parents.data();
  v.offsets = skeleton_.offsets.data();
  v.legs[0] = legs_[0];
  v.legs[1] = legs_[1];
  v.plant_feet = plant_feet_;
  return v;
}

BlendSpaceTables::BlendSpaceTables(const BlendSpace1D& space, Memory memory)
    : texels_f32_(std::span<const float>(space.texture().texels_f32), memory),
      texels_f16_(std::span<const std::uint16_t>(space.texture().texels_f16), memory),
      clips_(std::span<const ClipInfo>(space.clip_infos()), memory),
      sync_(std::span<const SegmentSync>(space.sync()), memory),
      joint_group_(std::span<const std::uint8_t>(space.joint_groups()), memory),
      mean_rotations_(std::span<const glm::quat>(space.mean_rotations()), memory),
      parents_(std::span<const std::int32_t>(space.skeleton().parents), memory),
      offsets_(std::span<const glm::vec3>(space.skeleton().offsets), memory) {
  view_ = space.view();
  view_.texture.texels_f32 = texels_f32_.data();
  view_.texture.texels_f16 = texels_f16_.data();
  view_.texture.parents = parents_.data();
  view_.clips = clips_.data();
  view_.sync = sync_.data();
  view_.joint_group = joint_group_.data();
  view_.mean_rotations = mean_rotations_.data();
  view_.parents = parents_.data();
  view_.offsets = offsets_.data();
}

BlendSpace1D make_default_blend_space() {
  Skeleton skeleton = default_skeleton();
  std::vector<LocomotionClip> clips;
  for (const DefaultMotion& m : make_default_motions(skeleton)) {
    if (m.spec.turn_rate != 0.0) continue;  // a speed blend space goes straight
    LocomotionOptions options;
    options.clean_contacts = false;  // planted by construction
    clips.push_back(prepare_locomotion_cycle(skeleton, m.clip, m.spec.name, options));
  }
  return BlendSpace1D(std::move(skeleton), std::move(clips));
}

ModelSpaceClip animate_character(const BlendSpace1D& space, LocomotionCharacter c, float speed, float turn_rate,
                                 const LocomotionStep& step, std::int32_t frames) {
  if (frames < 1 || frames > 10'000'000) throw Error("must be in [1, 1e7]", at_field("animate_character.frames"));
  if (!(std::isfinite(step.dt) && step.dt > 0.0f)) throw Error("must be positive", at_field("animate_character.dt"));
  const BlendSpaceView v = space.view();
  const std::int32_t J = v.joint_count;
  ModelSpaceClip out;
  out.joint_count = J;
  out.frame_count = frames;
  out.positions.resize(at(static_cast<std::int64_t>(frames) * J));
  out.rotations.resize(out.positions.size());
  for (std::int32_t f = 0; f < frames; ++f) {
    advance_locomotion(v, step, speed, turn_rate, 0.0f, c.scale, c.position, c.yaw, c.phase, c.blend_speed);
    const CharacterFrame frame = character_frame(v, c.blend_speed, c.phase, c.position, c.yaw, c.scale);
    synthesise_pose(v, frame, out.positions.data() + static_cast<std::ptrdiff_t>(f) * J,
                    out.rotations.data() + static_cast<std::ptrdiff_t>(f) * J);
  }
  return out;
}

FootSkatingReport locomotion_foot_skating(const BlendSpace1D& space, float speed, double seconds,
                                          const LocomotionStep& step, const ContactOptions& contacts) {
  if (!(std::isfinite(seconds) && seconds > 0.0 && seconds < 3600.0))
    throw Error("must be in (0, 3600) s", at_field("locomotion_foot_skating.seconds"));
  const auto frames = static_cast<std::int32_t>(std::ceil(seconds / step.dt));
  LocomotionStep s = step;
  s.integrate_root = true;
  const ModelSpaceClip track = animate_character(space, LocomotionCharacter{}, speed, 0.0f, s, frames);
  return measure_foot_skating(space.skeleton(), track, step.dt, contacts);
}

}  // namespace throng::motion
