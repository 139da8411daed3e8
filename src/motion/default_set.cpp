#include "motion/default_set.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <glm/gtc/quaternion.hpp>
#include <limits>

#include "core/error.h"
#include "core/math.h"

namespace throng::motion {

namespace {

using glm::dquat;
using glm::dvec3;
constexpr double kDeg = kPi / 180.0;
constexpr double kGravity = 9.81;

// --- small math helpers (double precision so cycles close exactly) -------

dquat rot_x(double a) { return glm::angleAxis(a, dvec3(1, 0, 0)); }
dquat rot_y(double a) { return glm::angleAxis(a, dvec3(0, 1, 0)); }
dquat rot_z(double a) { return glm::angleAxis(a, dvec3(0, 0, 1)); }

// The rotation q scaled to a fraction of its angle (about the same axis).
dquat fraction_of(dquat q, double f) {
  if (q.w < 0.0) q = -q;
  const double s = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  if (s < 1e-12) return dquat(1, 0, 0, 0);
  const double angle = 2.0 * std::atan2(s, q.w);
  return glm::angleAxis(angle * f, dvec3(q.x, q.y, q.z) / s);
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}
double smootherstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (x * (6.0 * x - 15.0) + 10.0);
}

// Cubic Hermite on [0,1]: values p0, p1 and end tangents m0, m1 (per unit s).
template <class T>
T hermite(const T& p0, const T& m0, const T& p1, const T& m1, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1;
}
template <class T>
T hermite_derivative(const T& p0, const T& m0, const T& p1, const T& m1, double s) {
  const double s2 = s * s;
  return (6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * p1 + (3 * s2 - 2 * s) * m1;
}

// Swing clearance bump: zero value and slope at both ends, peak 1 at s = 0.4
// (the foot is highest early in swing).
double swing_bump(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * (1.0 - s) * (1.0 - s) * (1.0 - s) / (0.16 * 0.216);
}

// Rotation taking the orthonormal frame (b0, w0, n0) to (b, w, n).
dquat frame_rotation(const dvec3& b0, const dvec3& w0, const dvec3& n0, const dvec3& b, const dvec3& w,
                     const dvec3& n) {
  const glm::dmat3 rest(b0, w0, n0);
  const glm::dmat3 world(b, w, n);
  return glm::normalize(glm::quat_cast(world * glm::transpose(rest)));
}

// Bone frame at rest: bone axis, forward (+Z) made perpendicular, normal.
struct BoneFrame {
  dvec3 b, w, n;
};
BoneFrame rest_bone_frame(const glm::vec3& child_offset) {
  BoneFrame f;
  f.b = glm::normalize(dvec3(child_offset));
  dvec3 fwd(0, 0, 1);
  f.w = fwd - glm::dot(fwd, f.b) * f.b;
  if (glm::length(f.w) < 1e-6) f.w = dvec3(1, 0, 0) - f.b.x * f.b;
  f.w = glm::normalize(f.w);
  f.n = glm::cross(f.b, f.w);
  return f;
}

// Keyed periodic curve on u in [0,1): cubic Hermite between keys with given
// slopes (per unit u); the key at u = 1 must repeat the one at u = 0.
struct Key {
  double u, value, slope;
};
struct KeyedCurve {
  std::vector<Key> keys;
  // Value and derivative d/du at u (wrapped into [0,1)).
  void eval(double u, double& value, double& slope) const {
    u -= std::floor(u);
    std::size_t i = 0;
    while (i + 2 < keys.size() && u >= keys[i + 1].u) ++i;
    const Key& a = keys[i];
    const Key& b = keys[i + 1];
    const double h = b.u - a.u;
    const double s = h > 0 ? (u - a.u) / h : 0.0;
    value = hermite(a.value, a.slope * h, b.value, b.slope * h, s);
    slope = h > 0 ? hermite_derivative(a.value, a.slope * h, b.value, b.slope * h, s) / h : 0.0;
  }
};

// Every amplitude of one gait. Angles in radians, lengths in metres,
// phases as fractions of the stride measured from the left heel strike.
struct Style {
  double duty = 1.0;           // stance fraction of the stride
  double u_flat = 0.0;         // foot flat (cycle fraction after touchdown)
  double u_heel_off = 0.0;     // heel rise
  double pitch_touchdown = 0;  // foot pitch at touchdown (<0 toes up: heel strike)
  double pitch_toe_off = 0;    // foot pitch at toe-off (heel up)
  double pitch_mid_swing = 0;
  double mid_swing_at = 0.8;  // cycle fraction of the mid-swing key
  double toe_out = 0;
  double half_width = 0.06;  // lateral ankle offset from the path
  double lift = 0.05;        // extra swing clearance at the bump peak
  double bob = 0.0;          // pelvis vertical half-amplitude (+: high at mid-stance)
  double sway = 0.0;         // lateral pelvis shift towards the stance foot
  double surge = 0.0;        // forward position oscillation (slowest at mid-stance)
  double pelvis_yaw = 0, pelvis_list = 0, pelvis_tilt = 0;
  double list_peak = 0.12;      // cycle fraction where the left side is highest
  double crouch = 0.0;          // extra pelvis drop below the reach limit
  double lean = 0.0;            // trunk forward pitch
  double thorax_counter = 0.8;  // thorax yaw = -counter * pelvis yaw
  double breathe = 0.0;         // thorax pitch oscillation (idle)
  double head_look = 0.0;       // head yaw oscillation (idle)
  double arm_abduction = 10 * kDeg;
  double arm_flex_mean = 0, arm_flex_amp = 0;
  double elbow_mean = 20 * kDeg, elbow_amp = 0;
  double turn_lean = 0.0;  // roll into the turn
};

Style style_for(const LocomotionSpec& spec, const LocomotionTargets& t) {
  Style s;
  const double v = spec.speed;
  switch (spec.gait) {
    case biomech::Gait::Stand:
      s.half_width = 0.11;
      s.toe_out = 8 * kDeg;
      s.sway = 0.015;
      s.bob = 0.003;
      s.crouch = 0.003;
      s.lean = 1 * kDeg;
      s.breathe = 0.8 * kDeg;
      s.head_look = 4 * kDeg;
      s.arm_abduction = 8 * kDeg;
      s.arm_flex_mean = 2 * kDeg;
      s.arm_flex_amp = 2 * kDeg;
      s.elbow_mean = 12 * kDeg;
      s.elbow_amp = 2 * kDeg;
      break;
    case biomech::Gait::Walk:
      s.duty = t.duty_factor;
      s.u_flat = 0.08;
      s.u_heel_off = s.duty - 0.20;
      s.pitch_touchdown = -(12.0 + 4.0 * v) * kDeg;
      s.pitch_toe_off = (50.0 + 5.0 * v) * kDeg;
      s.pitch_mid_swing = 12 * kDeg;
      s.mid_swing_at = s.duty + 0.35 * (1.0 - s.duty);
      s.toe_out = 6 * kDeg;
      s.half_width = 0.06;
      s.lift = 0.03 + 0.02 * v;
      s.bob = 0.015 + 0.008 * v;
      s.sway = 0.03 - 0.008 * v;
      s.surge = 0.006 + 0.002 * v;
      s.pelvis_yaw = (1.5 + 2.5 * v) * kDeg;
      s.pelvis_list = 4 * kDeg;
      s.pelvis_tilt = 1.5 * kDeg;
      s.list_peak = 0.12;
      s.lean = (2.0 + 1.5 * v) * kDeg;
      s.thorax_counter = 0.8;
      s.arm_abduction = 8 * kDeg;
      s.arm_flex_mean = -4 * kDeg;
      s.arm_flex_amp = (8.0 + 9.0 * v) * kDeg;
      s.elbow_mean = (20.0 + 6.0 * v) * kDeg;
      s.elbow_amp = (6.0 + 4.0 * v) * kDeg;
      break;
    case biomech::Gait::Run: {
      s.duty = t.duty_factor;
      const bool forefoot = v >= 3.5;
      s.pitch_touchdown = forefoot ? 6 * kDeg : -8 * kDeg;
      s.u_flat = (forefoot ? 0.20 : 0.25) * s.duty;
      s.u_heel_off = 0.45 * s.duty;
      s.pitch_toe_off = 65 * kDeg;
      s.pitch_mid_swing = 35 * kDeg;
      s.mid_swing_at = s.duty + 0.3 * (1.0 - s.duty);
      s.toe_out = 4 * kDeg;
      s.half_width = 0.035;
      s.lift = 0.12 + 0.06 * v;
      s.bob = -(0.04 - 0.002 * v);
      s.sway = 0.012;
      s.surge = 0.006;
      s.pelvis_yaw = (5.0 + 1.2 * v) * kDeg;
      s.pelvis_list = 5 * kDeg;
      s.pelvis_tilt = 2 * kDeg;
      s.list_peak = 0.5 * s.duty;
      s.crouch = 0.0;
      s.lean = (4.0 + 1.5 * v) * kDeg;
      s.thorax_counter = 0.9;
      s.arm_abduction = 12 * kDeg;
      s.arm_flex_mean = 5 * kDeg;
      s.arm_flex_amp = (22.0 + 4.0 * v) * kDeg;
      s.elbow_mean = (80.0 + 2.0 * v) * kDeg;
      s.elbow_amp = 12 * kDeg;
      break;
    }
  }
  // Lean into a turn so gravity and the centripetal force balance.
  s.turn_lean = -std::atan(v * spec.turn_rate / kGravity);
  return s;
}

LocomotionTargets targets_for(const LocomotionSpec& spec) {
  LocomotionTargets t;
  if (spec.gait == biomech::Gait::Stand) {
    t.period_frames = std::max<std::int32_t>(1, static_cast<std::int32_t>(std::lround(spec.idle_period_s * spec.fps)));
    t.period_s = t.period_frames / spec.fps;
    return t;
  }
  t.target_cadence = biomech::cadence(spec.gait, spec.speed);
  const double stride_time = 120.0 / t.target_cadence;  // two steps
  t.period_frames = std::max<std::int32_t>(8, static_cast<std::int32_t>(std::lround(stride_time * spec.fps)));
  t.period_s = t.period_frames / spec.fps;
  t.cadence = 120.0 / t.period_s;
  t.stride_length = spec.speed * t.period_s;
  t.duty_factor = biomech::duty_factor(spec.gait, spec.speed, t.period_s);
  t.turn_per_stride = spec.turn_rate * t.period_s;
  return t;
}

std::int32_t require_role(const Skeleton& s, Role r) {
  const std::int32_t j = s.role(r);
  if (j < 0) throw Error(std::string("locomotion generator: skeleton has no '") + to_string(r) + "' joint");
  return j;
}

}  // namespace

// --- skeleton ---------------------------------------------------------------

Skeleton default_skeleton() {
  namespace dj = default_joint;
  Skeleton s;
  s.add_joint("Hips", -1, {0.0f, 0.98f, 0.0f});
  s.add_joint("Spine", dj::Hips, {0.0f, 0.10f, 0.0f});
  s.add_joint("Spine1", dj::Spine, {0.0f, 0.12f, 0.0f});
  s.add_joint("Spine2", dj::Spine1, {0.0f, 0.12f, 0.0f});
  s.add_joint("Neck", dj::Spine2, {0.0f, 0.14f, 0.0f});
  s.add_joint("Head", dj::Neck, {0.0f, 0.10f, 0.02f});
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string p = side == 0 ? "Left" : "Right";
    const std::int32_t clav = s.add_joint(p + "Shoulder", dj::Spine2, {0.03f * x, 0.09f, 0.0f});
    const std::int32_t arm = s.add_joint(p + "Arm", clav, {0.15f * x, 0.01f, 0.0f});
    const std::int32_t fore = s.add_joint(p + "ForeArm", arm, {0.30f * x, 0.0f, 0.0f});
    s.add_joint(p + "Hand", fore, {0.25f * x, 0.0f, 0.0f});
  }
  for (int side = 0; side < 2; ++side) {
    const float x = side == 0 ? 1.0f : -1.0f;
    const std::string p = side == 0 ? "Left" : "Right";
    const std::int32_t up = s.add_joint(p + "UpLeg", dj::Hips, {0.09f * x, -0.055f, 0.0f});
    const std::int32_t leg = s.add_joint(p + "Leg", up, {0.0f, -0.425f, 0.0f});
    const std::int32_t foot = s.add_joint(p + "Foot", leg, {0.0f, -0.42f, 0.0f});
    s.add_joint(p + "ToeBase", foot, {0.0f, -0.055f, 0.14f});
  }
  auto end_site = [&](std::int32_t j, glm::vec3 e) {
    s.end_sites[static_cast<std::size_t>(j)] = e;
    s.has_end_site[static_cast<std::size_t>(j)] = 1;
  };
  end_site(dj::Head, {0.0f, 0.19f, 0.0f});
  end_site(dj::LeftHand, {0.19f, 0.0f, 0.0f});
  end_site(dj::RightHand, {-0.19f, 0.0f, 0.0f});
  end_site(dj::LeftToeBase, {0.0f, -0.005f, 0.06f});
  end_site(dj::RightToeBase, {0.0f, -0.005f, 0.06f});

  auto set = [&](Role r, std::int32_t j) { s.roles[static_cast<std::size_t>(r)] = j; };
  set(Role::Hips, dj::Hips);
  set(Role::Neck, dj::Neck);
  set(Role::Head, dj::Head);
  set(Role::LeftShoulder, dj::LeftArm);
  set(Role::RightShoulder, dj::RightArm);
  set(Role::LeftElbow, dj::LeftForeArm);
  set(Role::RightElbow, dj::RightForeArm);
  set(Role::LeftWrist, dj::LeftHand);
  set(Role::RightWrist, dj::RightHand);
  set(Role::LeftThigh, dj::LeftUpLeg);
  set(Role::RightThigh, dj::RightUpLeg);
  set(Role::LeftKnee, dj::LeftLeg);
  set(Role::RightKnee, dj::RightLeg);
  set(Role::LeftAnkle, dj::LeftFoot);
  set(Role::RightAnkle, dj::RightFoot);
  set(Role::LeftToe, dj::LeftToeBase);
  set(Role::RightToe, dj::RightToeBase);
  s.spine_chain = {dj::Spine, dj::Spine1, dj::Spine2};
  s.validate();
  return s;
}

void LocomotionSpec::validate() const {
  auto bad = [&](const std::string& field, const std::string& why) {
    throw Error("locomotion spec '" + name + "': " + why, at_field(field));
  };
  if (!(fps >= 10.0 && fps <= 480.0)) bad("fps", "fps must be in [10, 480]");
  if (strides < 1 || strides > 64) bad("strides", "strides must be in [1, 64]");
  if (!(std::abs(turn_rate) <= 1.5)) bad("turn_rate", "turn rate must be within +-1.5 rad/s");
  switch (gait) {
    case biomech::Gait::Stand:
      if (speed != 0.0) bad("speed", "a standing clip has speed 0");
      if (turn_rate != 0.0) bad("turn_rate", "a standing clip does not turn");
      if (!(idle_period_s >= 0.5 && idle_period_s <= 20.0)) bad("idle_period_s", "idle period must be in [0.5, 20] s");
      break;
    case biomech::Gait::Walk:
      if (!(speed >= 0.5 && speed <= 2.2)) bad("speed", "walking speed must be in [0.5, 2.2] m/s");
      break;
    case biomech::Gait::Run:
      if (!(speed >= 1.8 && speed <= 7.0)) bad("speed", "running speed must be in [1.8, 7] m/s");
      break;
  }
}

// --- the generator ------------------------------------------------------------

struct LocomotionGenerator::Model {
  Skeleton skeleton;
  LocomotionSpec spec;
  LocomotionTargets targets;
  Style style;
  KeyedCurve pitch;  // foot pitch over one foot cycle, from its touchdown

  enum class Rule : std::uint8_t { Identity, Root, Spine, Neck, Head, UpperArm, Forearm, Thigh, Shin, Foot, Toe };
  std::vector<Rule> rule;
  std::vector<int> joint_side;  // 0 left, 1 right for limb joints
  std::vector<dvec3> rest_pos;
  std::int32_t spine_count = 0;

  struct Leg {
    std::int32_t thigh = -1, knee = -1, ankle = -1, toe = -1;
    double upper = 0, lower = 0;  // bone lengths
    BoneFrame thigh_rest, shin_rest;
    dvec3 ball;               // ankle -> toe joint, rest (model) frame
    dvec3 root_to_hip;        // rest offset of the hip joint from the root
    double ankle_height = 0;  // rest height of the ankle joint
  };
  std::array<Leg, 2> legs;
  double root_height = 0;      // rest root height
  double drop = 0;             // pelvis lowered so every target is reachable
  double touchdown_ahead = 0;  // ankle ahead of the root path at touchdown, m
  double thigh_phase = 0;      // stride phase where the left thigh is most forward

  static constexpr double kReach = 0.998;  // of the leg length: keeps ~7 deg of knee bend

  double period() const { return targets.period_s; }
  bool moving() const { return spec.gait != biomech::Gait::Stand; }
  double heading(double t) const { return spec.turn_rate * t; }
  dvec3 path(double t) const {
    const double v = spec.speed, w = spec.turn_rate;
    if (std::abs(w) < 1e-12) return {0.0, 0.0, v * t};
    return {v / w * (1.0 - std::cos(w * t)), 0.0, v / w * std::sin(w * t)};
  }

  struct Body {
    dvec3 root_pos;
    dquat root_rot, thorax, head;
    double arm_flex[2], elbow[2];
  };
  struct FootPose {
    dvec3 ankle;           // target ankle joint position
    dquat rot;             // foot world rotation
    double toe_pitch = 0;  // toe joint local pitch
    double yaw = 0;
  };

  // `ahead` places the plants (see solve_placement); the pelvis is highest
  // (walk) or lowest (run) when the stance ankle passes under it.
  Body body(double t, double drop_now, double ahead) const {
    const Style& s = style;
    const double phi = t / period();
    const double two_pi = 2.0 * kPi;
    Body b{};
    const double psi = heading(t);
    const dquat yaw_q = rot_y(psi);
    double sway, bob, surge, yaw_p, list, tilt, breathe = 0, look = 0;
    if (moving()) {
      const double mid = ahead / targets.stride_length;  // left ankle under the pelvis
      sway = s.sway * std::cos(two_pi * (phi - mid));
      bob = s.bob * std::cos(2.0 * two_pi * (phi - mid));
      surge = -s.surge * std::sin(2.0 * two_pi * (phi - mid));
      yaw_p = -s.pelvis_yaw * std::cos(two_pi * phi);
      list = s.pelvis_list * std::cos(two_pi * (phi - s.list_peak));
      tilt = s.pelvis_tilt * std::cos(2.0 * two_pi * (phi - mid));
    } else {
      sway = s.sway * std::sin(two_pi * phi);
      bob = s.bob * std::sin(two_pi * phi);
      surge = 0.0;
      yaw_p = 1.5 * kDeg * std::sin(two_pi * phi);
      list = 1.0 * kDeg * std::sin(two_pi * phi);
      tilt = 0.0;
      breathe = s.breathe * std::sin(two_pi * phi);
      look = s.head_look * std::sin(two_pi * phi + 1.0);
    }
    b.root_pos = path(t) + yaw_q * dvec3(sway, 0.0, surge) + dvec3(0.0, root_height - drop_now + bob, 0.0);
    const dquat turn = rot_z(s.turn_lean);
    b.root_rot = yaw_q * turn * rot_y(yaw_p) * rot_x(tilt) * rot_z(list);
    b.thorax = yaw_q * turn * rot_y(-s.thorax_counter * yaw_p) * rot_x(s.lean + breathe) * rot_z(-0.3 * list);
    b.head = yaw_q * rot_z(0.5 * s.turn_lean) * rot_y(look);
    for (int f = 0; f < 2; ++f) {
      // Each arm swings with the opposite leg: the left arm is forward at the
      // right heel strike (phi = 0.5).
      const double phase = two_pi * (phi - thigh_phase - (f == 0 ? 0.5 : 0.0));
      if (moving()) {
        b.arm_flex[f] = s.arm_flex_mean + s.arm_flex_amp * std::cos(phase);
        b.elbow[f] = s.elbow_mean + s.elbow_amp * std::cos(phase);
      } else {
        b.arm_flex[f] = s.arm_flex_mean + s.arm_flex_amp * std::sin(two_pi * phi + f * kPi);
        b.elbow[f] = s.elbow_mean + s.elbow_amp * std::sin(two_pi * phi);
      }
    }
    return b;
  }

  // Plant k of foot f: ankle position (foot flat) and yaw, fixed in the world.
  void plant(int f, double k, double ahead, dvec3& ankle, double& yaw) const {
    const double side = f == 0 ? 1.0 : -1.0;
    const double offset = f == 0 ? 0.0 : 0.5;
    const double t_touch = (k + offset) * period();
    const double t_pass = t_touch + ahead / spec.speed;  // root passes the ankle
    const double psi = heading(t_pass);
    ankle =
        path(t_pass) + rot_y(psi) * dvec3(side * style.half_width, 0.0, 0.0) + dvec3(0.0, legs[f].ankle_height, 0.0);
    yaw = psi + side * style.toe_out;
  }

  // Ankle of a foot rolling about its ball: pinned ball, foot pitched by theta.
  dvec3 ankle_about_ball(const dvec3& plant_ankle, double yaw, double theta, const Leg& leg) const {
    const dquat y = rot_y(yaw);
    const dvec3 ball = plant_ankle + y * leg.ball;
    return ball - y * (rot_x(theta) * leg.ball);
  }
  // d/dtheta of ankle_about_ball.
  dvec3 ankle_about_ball_rate(double yaw, double theta, const Leg& leg) const {
    const dvec3& b = leg.ball;
    const dvec3 d(0.0, -b.y * std::sin(theta) - b.z * std::cos(theta), b.y * std::cos(theta) - b.z * std::sin(theta));
    return -(rot_y(yaw) * d);
  }

  FootPose foot(int f, double t, double ahead) const {
    const Leg& leg = legs[static_cast<std::size_t>(f)];
    FootPose p;
    if (!moving()) {
      const double side = f == 0 ? 1.0 : -1.0;
      p.ankle = dvec3(side * style.half_width, leg.ankle_height, 0.0);
      p.yaw = side * style.toe_out;
      p.rot = rot_y(p.yaw);
      return p;
    }
    const Style& s = style;
    const double u_abs = t / period() - (f == 0 ? 0.0 : 0.5);
    const double k = std::floor(u_abs);
    const double u = u_abs - k;
    double theta, dtheta;
    pitch.eval(u, theta, dtheta);
    dvec3 plant_k;
    double yaw_k;
    plant(f, k, ahead, plant_k, yaw_k);
    if (u < s.duty) {  // stance: ankle pinned, or the ball pinned while the heel is up
      p.ankle = theta > 0.0 ? ankle_about_ball(plant_k, yaw_k, theta, leg) : plant_k;
      p.yaw = yaw_k;
      p.rot = rot_y(yaw_k) * rot_x(theta);
      p.toe_pitch = -std::max(theta, 0.0);
      return p;
    }
    // Swing: Hermite from the toe-off ankle to the next plant, plus clearance.
    dvec3 plant_next;
    double yaw_next;
    plant(f, k + 1.0, ahead, plant_next, yaw_next);
    double theta_off, rate_off, theta_on, rate_on;
    pitch.eval(s.duty, theta_off, rate_off);
    pitch.eval(0.0, theta_on, rate_on);
    const double swing_time = (1.0 - s.duty) * period();
    const double sw = (u - s.duty) / (1.0 - s.duty);
    const dvec3 a0 = ankle_about_ball(plant_k, yaw_k, theta_off, leg);
    const dvec3 v0 = ankle_about_ball_rate(yaw_k, theta_off, leg) * (rate_off / period());
    const dvec3 a1 = theta_on > 0.0 ? ankle_about_ball(plant_next, yaw_next, theta_on, leg) : plant_next;
    const dvec3 v1 =
        theta_on > 0.0 ? ankle_about_ball_rate(yaw_next, theta_on, leg) * (rate_on / period()) : dvec3(0.0);
    p.ankle = hermite(a0, v0 * swing_time, a1, v1 * swing_time, sw) + dvec3(0.0, s.lift * swing_bump(sw), 0.0);
    p.yaw = yaw_k + (yaw_next - yaw_k) * smootherstep(sw);
    p.rot = rot_y(p.yaw) * rot_x(theta);
    p.toe_pitch = -theta_off * (1.0 - smoothstep(sw / 0.35)) - std::max(theta_on, 0.0) * smoothstep((sw - 0.7) / 0.3);
    return p;
  }

  dvec3 hip_position(const Body& b, int f) const {
    return b.root_pos + b.root_rot * legs[static_cast<std::size_t>(f)].root_to_hip;
  }

  // Pelvis drop needed at time t for both legs to reach with `ahead`.
  double needed_drop(double t, double ahead) const {
    const Body b = body(t, 0.0, ahead);
    double need = -std::numeric_limits<double>::infinity();
    for (int f = 0; f < 2; ++f) {
      const Leg& leg = legs[static_cast<std::size_t>(f)];
      const double reach = kReach * (leg.upper + leg.lower);
      const dvec3 h = hip_position(b, f);
      const dvec3 a = foot(f, t, ahead).ankle;
      const double r = std::hypot(h.x - a.x, h.z - a.z);
      if (r >= reach) return std::numeric_limits<double>::infinity();
      need = std::max(need, (h.y - a.y) - std::sqrt(reach * reach - r * r));
    }
    return need;
  }
  double max_needed_drop(double ahead) const {
    const int samples = std::max(64, 4 * targets.period_frames);
    double worst = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < samples; ++i) worst = std::max(worst, needed_drop(period() * i / samples, ahead));
    return worst;
  }

  // Places the plants so that the pelvis can stay as high as possible (the
  // stance leg's extreme reaches at touchdown and toe-off balance), then
  // lowers the pelvis just enough for every target to be reachable.
  void solve_placement() {
    if (!moving()) {
      drop = std::max(0.0, max_needed_drop(0.0)) + style.crouch;
      return;
    }
    const double hi = style.duty * targets.stride_length;
    double best = 0.0, best_drop = std::numeric_limits<double>::infinity();
    constexpr int kGrid = 40;
    for (int i = 0; i <= kGrid; ++i) {
      const double a = hi * i / kGrid;
      const double d = max_needed_drop(a);
      if (d < best_drop) best_drop = d, best = a;
    }
    // Golden-section refinement around the best grid point.
    double lo_a = std::max(0.0, best - hi / kGrid), hi_a = std::min(hi, best + hi / kGrid);
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    for (int it = 0; it < 40; ++it) {
      const double x1 = hi_a - g * (hi_a - lo_a), x2 = lo_a + g * (hi_a - lo_a);
      if (max_needed_drop(x1) < max_needed_drop(x2))
        hi_a = x2;
      else
        lo_a = x1;
    }
    touchdown_ahead = 0.5 * (lo_a + hi_a);
    best_drop = max_needed_drop(touchdown_ahead);
    if (!std::isfinite(best_drop))
      throw Error("locomotion spec '" + spec.name + "': strides too long for the skeleton's legs", at_field("speed"));
    drop = std::max(0.0, best_drop) + style.crouch;
  }

  void build_pitch_curve() {
    const Style& s = style;
    if (!moving()) return;
    const double to_rate = 0.6 * s.pitch_toe_off / (s.duty - s.u_heel_off);
    const double ms_rate = (s.pitch_touchdown - s.pitch_toe_off) / (1.0 - s.duty);
    pitch.keys = {{0.0, s.pitch_touchdown, 0.0},
                  {s.u_flat, 0.0, 0.0},
                  {s.u_heel_off, 0.0, 0.0},
                  {s.duty, s.pitch_toe_off, to_rate},
                  {s.mid_swing_at, s.pitch_mid_swing, ms_rate},
                  {1.0, s.pitch_touchdown, 0.0}};
  }

  Model(const Skeleton& sk, const LocomotionSpec& sp) : skeleton(sk), spec(sp) {
    spec.validate();
    skeleton.validate();
    targets = targets_for(spec);
    style = style_for(spec, targets);
    build_pitch_curve();
    const std::int32_t J = skeleton.joint_count();
    rest_pos.resize(static_cast<std::size_t>(J));
    for (std::int32_t j = 0; j < J; ++j) {
      const auto p = skeleton.parents[static_cast<std::size_t>(j)];
      rest_pos[static_cast<std::size_t>(j)] = (p < 0 ? dvec3(0.0) : rest_pos[static_cast<std::size_t>(p)]) +
                                              dvec3(skeleton.offsets[static_cast<std::size_t>(j)]);
    }
    rule.assign(static_cast<std::size_t>(J), Rule::Identity);
    joint_side.assign(static_cast<std::size_t>(J), 0);
    auto mark = [&](std::int32_t j, Rule r, int s) {
      rule[static_cast<std::size_t>(j)] = r;
      joint_side[static_cast<std::size_t>(j)] = s;
    };
    const std::int32_t hips = require_role(skeleton, Role::Hips);
    if (hips != 0) throw Error("locomotion generator: the hips must be the root joint");
    mark(hips, Rule::Root, 0);
    if (skeleton.spine_chain.empty()) throw Error("locomotion generator: skeleton has no spine chain");
    for (std::int32_t j : skeleton.spine_chain) mark(j, Rule::Spine, 0);
    spine_count = static_cast<std::int32_t>(skeleton.spine_chain.size());
    mark(require_role(skeleton, Role::Neck), Rule::Neck, 0);
    mark(require_role(skeleton, Role::Head), Rule::Head, 0);
    const std::array<Role, 2> shoulders{Role::LeftShoulder, Role::RightShoulder};
    const std::array<Role, 2> elbows{Role::LeftElbow, Role::RightElbow};
    const std::array<Role, 2> thighs{Role::LeftThigh, Role::RightThigh};
    const std::array<Role, 2> knees{Role::LeftKnee, Role::RightKnee};
    const std::array<Role, 2> ankles{Role::LeftAnkle, Role::RightAnkle};
    const std::array<Role, 2> toes{Role::LeftToe, Role::RightToe};
    for (int f = 0; f < 2; ++f) {
      const auto fi = static_cast<std::size_t>(f);
      mark(require_role(skeleton, shoulders[fi]), Rule::UpperArm, f);
      mark(require_role(skeleton, elbows[fi]), Rule::Forearm, f);
      Leg& leg = legs[fi];
      leg.thigh = require_role(skeleton, thighs[fi]);
      leg.knee = require_role(skeleton, knees[fi]);
      leg.ankle = require_role(skeleton, ankles[fi]);
      leg.toe = require_role(skeleton, toes[fi]);
      if (skeleton.parents[static_cast<std::size_t>(leg.knee)] != leg.thigh ||
          skeleton.parents[static_cast<std::size_t>(leg.ankle)] != leg.knee ||
          skeleton.parents[static_cast<std::size_t>(leg.toe)] != leg.ankle)
        throw Error("locomotion generator: thigh, knee, ankle and toe must be a parent-child chain");
      mark(leg.thigh, Rule::Thigh, f);
      mark(leg.knee, Rule::Shin, f);
      mark(leg.ankle, Rule::Foot, f);
      mark(leg.toe, Rule::Toe, f);
      const glm::vec3 knee_off = skeleton.offsets[static_cast<std::size_t>(leg.knee)];
      const glm::vec3 ankle_off = skeleton.offsets[static_cast<std::size_t>(leg.ankle)];
      leg.upper = glm::length(dvec3(knee_off));
      leg.lower = glm::length(dvec3(ankle_off));
      leg.thigh_rest = rest_bone_frame(knee_off);
      leg.shin_rest = rest_bone_frame(ankle_off);
      leg.ball = dvec3(skeleton.offsets[static_cast<std::size_t>(leg.toe)]);
      leg.root_to_hip = rest_pos[static_cast<std::size_t>(leg.thigh)] - rest_pos[0];
      leg.ankle_height = rest_pos[static_cast<std::size_t>(leg.ankle)].y;
    }
    root_height = rest_pos[0].y;
    solve_placement();
    if (moving()) find_thigh_phase();
  }

  // The arms swing with the opposite thigh: the phase of the fundamental of
  // the left knee's forward offset from the hip (the legs do not depend on it).
  void find_thigh_phase() {
    constexpr int kSamples = 64;
    double c = 0, s = 0;
    for (int i = 0; i < kSamples; ++i) {
      const double t = period() * i / kSamples;
      const Body b = body(t, drop, touchdown_ahead);
      const dvec3 hip = hip_position(b, 0);
      const FootPose fp = foot(0, t, touchdown_ahead);
      dquat thigh, shin;
      solve_leg(legs[0], hip, fp.ankle, rot_y(fp.yaw) * dvec3(0, 0, 1), thigh, shin);
      const dvec3 knee_offset = thigh * dvec3(skeleton.offsets[static_cast<std::size_t>(legs[0].knee)]);
      const double forward = glm::dot(knee_offset, rot_y(heading(t)) * dvec3(0, 0, 1));
      const double angle = 2.0 * kPi * i / kSamples;
      c += forward * std::cos(angle);
      s += forward * std::sin(angle);
    }
    thigh_phase = std::atan2(s, c) / (2.0 * kPi);
  }

  // Two-bone IK: world rotations of thigh and shin putting the ankle at
  // `target` (or as near as the leg reaches), the knee bending towards `pole`.
  void solve_leg(const Leg& leg, const dvec3& hip, const dvec3& target, const dvec3& pole, dquat& thigh_world,
                 dquat& shin_world) const {
    const double l1 = leg.upper, l2 = leg.lower;
    dvec3 d = target - hip;
    double dist = glm::length(d);
    const dvec3 u = dist > 1e-9 ? d / dist : dvec3(0, -1, 0);
    dist = std::clamp(dist, std::abs(l1 - l2) + 1e-6, (l1 + l2) * (1.0 - 1e-9));
    dvec3 w = pole - glm::dot(pole, u) * u;
    if (glm::length(w) < 1e-9) w = dvec3(0, 0, 1) - u.z * u;
    w = glm::normalize(w);
    const double cos_a = std::clamp((l1 * l1 + dist * dist - l2 * l2) / (2.0 * l1 * dist), -1.0, 1.0);
    const double sin_a = std::sqrt(1.0 - cos_a * cos_a);
    const dvec3 knee = hip + l1 * (cos_a * u + sin_a * w);
    const dvec3 ankle = hip + dist * u;
    const dvec3 n = glm::normalize(glm::cross(u, w));
    const dvec3 b1 = glm::normalize(knee - hip);
    const dvec3 b2 = glm::normalize(ankle - knee);
    const BoneFrame& r1 = leg.thigh_rest;
    const BoneFrame& r2 = leg.shin_rest;
    thigh_world = frame_rotation(r1.b, r1.w, r1.n, b1, glm::cross(n, b1), n);
    shin_world = frame_rotation(r2.b, r2.w, r2.n, b2, glm::cross(n, b2), n);
  }

  void pose(double t, std::span<glm::quat> out, glm::vec3& root_out) const {
    const std::int32_t J = skeleton.joint_count();
    const Body b = body(t, drop, touchdown_ahead);
    std::vector<dquat> world(static_cast<std::size_t>(J));
    std::vector<dvec3> pos(static_cast<std::size_t>(J));
    std::array<FootPose, 2> feet{foot(0, t, touchdown_ahead), foot(1, t, touchdown_ahead)};
    std::array<dquat, 2> shin_target{};
    const dquat spine_step = fraction_of(glm::inverse(b.root_rot) * b.thorax, 1.0 / spine_count);
    for (std::int32_t j = 0; j < J; ++j) {
      const auto ji = static_cast<std::size_t>(j);
      const std::int32_t p = skeleton.parents[ji];
      const dquat parent_rot = p < 0 ? dquat(1, 0, 0, 0) : world[static_cast<std::size_t>(p)];
      const dvec3 parent_pos = p < 0 ? dvec3(0.0) : pos[static_cast<std::size_t>(p)];
      const int f = joint_side[ji];
      const double sgn = f == 0 ? 1.0 : -1.0;
      dquat local(1, 0, 0, 0);
      switch (rule[ji]) {
        case Rule::Identity: break;
        case Rule::Root: local = b.root_rot; break;
        case Rule::Spine: local = spine_step; break;
        case Rule::Neck: local = fraction_of(glm::inverse(parent_rot) * b.head, 0.5); break;
        case Rule::Head: local = glm::inverse(parent_rot) * b.head; break;
        case Rule::UpperArm:
          // Hang the T-pose arm down (about the forward axis), then swing it
          // about the lateral axis: forward flexion is negative about +X.
          local = rot_x(-b.arm_flex[f]) * rot_z(-sgn * (0.5 * kPi - style.arm_abduction));
          break;
        case Rule::Forearm: local = rot_y(-sgn * b.elbow[f]); break;
        case Rule::Thigh: {
          const Leg& leg = legs[static_cast<std::size_t>(f)];
          const dvec3 hip = parent_pos + parent_rot * dvec3(skeleton.offsets[ji]);
          const FootPose& fp = feet[static_cast<std::size_t>(f)];
          dquat thigh_world;
          solve_leg(leg, hip, fp.ankle, rot_y(fp.yaw) * dvec3(0, 0, 1), thigh_world,
                    shin_target[static_cast<std::size_t>(f)]);
          local = glm::inverse(parent_rot) * thigh_world;
          break;
        }
        case Rule::Shin: local = glm::inverse(parent_rot) * shin_target[static_cast<std::size_t>(f)]; break;
        case Rule::Foot: local = glm::inverse(parent_rot) * feet[static_cast<std::size_t>(f)].rot; break;
        case Rule::Toe: local = rot_x(feet[static_cast<std::size_t>(f)].toe_pitch); break;
      }
      local = glm::normalize(local);
      if (local.w < 0.0) local = -local;  // one hemisphere: smooth curves for interpolation
      world[ji] = glm::normalize(parent_rot * local);
      pos[ji] = p < 0 ? b.root_pos : parent_pos + parent_rot * dvec3(skeleton.offsets[ji]);
      out[ji] = glm::quat(local);
    }
    root_out = glm::vec3(b.root_pos);
  }
};

LocomotionGenerator::LocomotionGenerator(const Skeleton& skeleton, const LocomotionSpec& spec)
    : model_(std::make_unique<Model>(skeleton, spec)) {}
LocomotionGenerator::~LocomotionGenerator() = default;
LocomotionGenerator::LocomotionGenerator(LocomotionGenerator&&) noexcept = default;
LocomotionGenerator& LocomotionGenerator::operator=(LocomotionGenerator&&) noexcept = default;

const LocomotionTargets& LocomotionGenerator::targets() const { return model_->targets; }
const LocomotionSpec& LocomotionGenerator::spec() const { return model_->spec; }
double LocomotionGenerator::pelvis_drop() const { return model_->drop; }

void LocomotionGenerator::pose_at(double t, std::span<glm::quat> local_rotations, glm::vec3& root_position) const {
  if (local_rotations.size() != static_cast<std::size_t>(model_->skeleton.joint_count()))
    throw Error("pose_at: rotation span has " + std::to_string(local_rotations.size()) + " entries, skeleton " +
                std::to_string(model_->skeleton.joint_count()));
  model_->pose(t, local_rotations, root_position);
}

Clip LocomotionGenerator::sample(std::int32_t frames) const {
  if (frames < 1 || frames > 1'000'000) throw Error("sample: frame count must be in [1, 1e6]");
  Clip clip;
  const std::int32_t J = model_->skeleton.joint_count();
  clip.resize(frames, J);
  clip.frame_time = static_cast<float>(1.0 / model_->spec.fps);
  for (std::int32_t f = 0; f < frames; ++f) {
    std::span<glm::quat> row(clip.rotations.data() + static_cast<std::size_t>(f) * static_cast<std::size_t>(J),
                             static_cast<std::size_t>(J));
    model_->pose(f / model_->spec.fps, row, clip.root_positions[static_cast<std::size_t>(f)]);
  }
  return clip;
}

Clip LocomotionGenerator::make_clip() const { return sample(model_->targets.period_frames * model_->spec.strides); }

std::vector<LocomotionSpec> default_motion_specs() {
  using biomech::Gait;
  auto spec = [](std::string name, Gait gait, double speed, double turn) {
    LocomotionSpec s;
    s.name = std::move(name);
    s.gait = gait;
    s.speed = speed;
    s.turn_rate = turn;
    return s;
  };
  const double turn = 30.0 * kDeg;
  return {spec("idle", Gait::Stand, 0.0, 0.0),           spec("walk_slow", Gait::Walk, 1.0, 0.0),
          spec("walk", Gait::Walk, 1.35, 0.0),           spec("walk_fast", Gait::Walk, 1.8, 0.0),
          spec("run_slow", Gait::Run, 2.7, 0.0),         spec("run_fast", Gait::Run, 4.5, 0.0),
          spec("walk_turn_left", Gait::Walk, 1.2, turn), spec("walk_turn_right", Gait::Walk, 1.2, -turn)};
}

std::vector<DefaultMotion> make_default_motions(const Skeleton& skeleton) {
  std::vector<DefaultMotion> out;
  for (const LocomotionSpec& spec : default_motion_specs()) {
    const LocomotionGenerator gen(skeleton, spec);
    DefaultMotion m;
    m.spec = spec;
    m.targets = gen.targets();
    m.clip = gen.make_clip();
    char buf[200];
    if (spec.gait == biomech::Gait::Stand)
      std::snprintf(buf, sizeof buf, "standing idle: weight shift and breathing, %.1f s loop", m.targets.period_s);
    else if (spec.turn_rate != 0.0)
      std::snprintf(buf, sizeof buf, "%s at %.2f m/s, %.1f steps/min, stride %.2f m, turning %s %.0f deg/s",
                    biomech::to_string(spec.gait), spec.speed, m.targets.cadence, m.targets.stride_length,
                    spec.turn_rate > 0 ? "left" : "right", std::abs(spec.turn_rate) / kDeg);
    else
      std::snprintf(buf, sizeof buf, "%s at %.2f m/s, %.1f steps/min, stride %.2f m", biomech::to_string(spec.gait),
                    spec.speed, m.targets.cadence, m.targets.stride_length);
    m.description = buf;
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace throng::motion
