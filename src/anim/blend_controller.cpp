#include "anim/blend_controller.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "motion/default_set.h"

namespace throng::anim {

namespace {

using motion::BlendPoint;
using motion::BlendSpaceView;

// A character's pose in its own frame (position 0, yaw 0, scale 1) as
// per-character synthesis makes it (motion::synthesise_pose): the blend with
// its leg IK; the root's rotation includes the blend's frame, the root sits
// at its offset from the path point, lowered by the IK's pelvis drop.
void synthesise_local(const BlendSpaceView& v, const BlendPoint& p, float phase, Pose& out) {
  const motion::CharacterFrame f = motion::character_frame_at(v, p, phase, glm::vec3(0.0f), 0.0f, 1.0f);
  out.local.resize(static_cast<std::size_t>(v.joint_count));
  const motion::PlantedLegs legs = motion::synthesise_locals(v, f, nullptr, out.local.data());
  out.local[0] = f.frame * out.local[0];
  out.root = f.root_position - glm::vec3(0.0f, legs.pelvis_drop, 0.0f);
}

BlendPoint point_at(const BlendSpaceView& v, float speed) {
  return motion::blend_point(v, motion::blend_coordinate(v, speed));
}

// The canonical phase of a foot's touchdown in a blend: the clips' event
// phases lerped by w along the shorter way round (a clip without the event,
// idle, takes the other's); -1 when neither has it.
float touchdown_phase(const motion::BlendSpace1D& space, const BlendPoint& p, motion::FootEvent e) {
  const float a = space.clips()[static_cast<std::size_t>(p.a)].event(e);
  const float b = space.clips()[static_cast<std::size_t>(p.b)].event(e);
  if (a < 0.0f && b < 0.0f) return -1.0f;
  if (a < 0.0f) return b;
  if (b < 0.0f) return a;
  return motion::wrap_phase(a + p.w * motion::phase_lead(b, a));
}

// ORs the footstep events whose phase lies in (from, from + advanced].
void footsteps(const motion::BlendSpace1D& space, const BlendPoint& p, float from, float advanced, std::int32_t left,
               std::int32_t right, EventMask& events) {
  const std::pair<std::int32_t, motion::FootEvent> feet[2] = {{left, motion::FootEvent::LeftDown},
                                                              {right, motion::FootEvent::RightDown}};
  for (const auto& [id, e] : feet) {
    if (id < 0) continue;
    const float at = touchdown_phase(space, p, e);
    if (at < 0.0f) continue;
    if (std::floor(from + advanced - at) > std::floor(from - at)) events |= EventMask{1} << id;
  }
}

void check_event(std::int32_t id, const char* field) {
  if (id < -1 || id >= kMaxEventNames) throw Error("must be an event id in [0, 32) or -1", at_field(field));
}

void check_phase(float phase, const char* field) {
  if (!(phase >= 0.0f && phase < 1.0f)) throw Error("must be in [0, 1)", at_field(field));
}

float read_parameter(const ParameterSet& params, const std::string& name, float fallback) {
  return params.has(name) ? params.get(name) : fallback;
}

}  // namespace

// ---- 1D ---------------------------------------------------------------------

void Blend1DOptions::validate() const {
  if (!(std::isfinite(speed) && speed >= 0.0f)) throw Error("must be finite and >= 0 m/s", at_field("blend1d.speed"));
  check_phase(start_phase, "blend1d.phase");
  check_event(footstep_left, "blend1d.footstep_left");
  check_event(footstep_right, "blend1d.footstep_right");
}

Blend1DController::Blend1DController(std::shared_ptr<const motion::BlendSpace1D> space, Blend1DOptions options)
    : space_(std::move(space)), options_(std::move(options)) {
  if (!space_) throw Error("needs a blend space", at_field("blend1d.space"));
  options_.validate();
  reset();
}

void Blend1DController::reset() {
  speed_ = options_.speed;
  phase_ = options_.start_phase;
  time_ = 0.0;
}

float Blend1DController::cycles_per_second() const {
  const BlendSpaceView v = space_->view();
  return motion::cycle_rate(v, point_at(v, speed_), speed_);
}

double Blend1DController::duration() const {
  const float rate = cycles_per_second();
  return rate > 0.0f ? 1.0 / rate : 0.0;
}

void Blend1DController::advance(float dt, const ParameterSet& params, EventMask& events) {
  const float s = read_parameter(params, options_.parameter, options_.speed);
  speed_ = s > 0.0f ? s : 0.0f;  // also NaN
  const BlendSpaceView v = space_->view();
  const BlendPoint p = point_at(v, speed_);
  const float advanced = motion::cycle_rate(v, p, speed_) * (dt > 0.0f ? dt : 0.0f);
  footsteps(*space_, p, phase_, advanced, options_.footstep_left, options_.footstep_right, events);
  phase_ = motion::wrap_phase(phase_ + advanced);
  time_ += dt;
}

void Blend1DController::evaluate(Pose& out) const {
  const BlendSpaceView v = space_->view();
  synthesise_local(v, point_at(v, speed_), phase_, out);
}

// ---- 2D ---------------------------------------------------------------------

void Blend2DOptions::validate() const {
  if (!(std::isfinite(speed) && speed >= 0.0f)) throw Error("must be finite and >= 0 m/s", at_field("blend2d.speed"));
  if (!std::isfinite(turn)) throw Error("must be finite (rad/s)", at_field("blend2d.turn"));
  check_phase(start_phase, "blend2d.phase");
  check_event(footstep_left, "blend2d.footstep_left");
  check_event(footstep_right, "blend2d.footstep_right");
}

Blend2DController::Blend2DController(std::shared_ptr<const motion::BlendSpace1D> speeds,
                                     std::shared_ptr<const motion::BlendSpace1D> turn_left,
                                     std::shared_ptr<const motion::BlendSpace1D> turn_right, Blend2DOptions options)
    : speeds_(std::move(speeds)),
      left_(std::move(turn_left)),
      right_(std::move(turn_right)),
      options_(std::move(options)) {
  if (!speeds_) throw Error("needs a speed blend space", at_field("blend2d.clips"));
  if (!left_ || !right_)
    throw Error("needs a turning clip to each side", at_field(!left_ ? "blend2d.turn_left" : "blend2d.turn_right"));
  options_.validate();
  const std::int32_t J = speeds_->joint_count();
  for (const auto& [space, field] :
       {std::pair{left_.get(), "blend2d.turn_left"}, std::pair{right_.get(), "blend2d.turn_right"}}) {
    if (space->joint_count() != J)
      throw Error("has " + std::to_string(space->joint_count()) + " joints, the speed clips " + std::to_string(J),
                  at_field(field));
    if (space->clip_count() != 1) throw Error("must be one turning clip", at_field(field));
  }
  if (!(left_->clip_infos()[0].turn > 0.0f))
    throw Error("must turn left (positive turn per cycle)", at_field("blend2d.turn_left"));
  if (!(right_->clip_infos()[0].turn < 0.0f))
    throw Error("must turn right (negative turn per cycle)", at_field("blend2d.turn_right"));
  reset();
}

void Blend2DController::reset() {
  speed_ = options_.speed;
  turn_ = options_.turn;
  phase_ = options_.start_phase;
  time_ = 0.0;
}

float Blend2DController::turn_weight() const {
  const motion::ClipInfo& clip = turn_space().clip_infos()[0];
  const float clip_rate = clip.turn / clip.period;  // rad/s, same sign as turn_
  const float h = std::min(turn_ / clip_rate, 1.0f);
  const BlendSpaceView v = speeds_->view();
  const float g = 1.0f - std::abs(motion::blend_coordinate(v, speed_) - motion::blend_coordinate(v, clip.speed));
  return std::clamp(h * g, 0.0f, 1.0f);
}

float Blend2DController::cycles_per_second() const {
  const BlendSpaceView vs = speeds_->view();
  const BlendSpaceView vt = turn_space().view();
  const float straight = motion::cycle_rate(vs, point_at(vs, speed_), speed_);
  const float turning = motion::cycle_rate(vt, BlendPoint{}, speed_);
  return straight + turn_weight() * (turning - straight);
}

double Blend2DController::duration() const {
  const float rate = cycles_per_second();
  return rate > 0.0f ? 1.0 / rate : 0.0;
}

void Blend2DController::advance(float dt, const ParameterSet& params, EventMask& events) {
  const float s = read_parameter(params, options_.speed_parameter, options_.speed);
  speed_ = s > 0.0f ? s : 0.0f;
  const float t = read_parameter(params, options_.turn_parameter, options_.turn);
  turn_ = std::isfinite(t) ? t : 0.0f;
  const float advanced = cycles_per_second() * (dt > 0.0f ? dt : 0.0f);
  const BlendSpaceView vs = speeds_->view();
  footsteps(*speeds_, point_at(vs, speed_), phase_, advanced, options_.footstep_left, options_.footstep_right, events);
  phase_ = motion::wrap_phase(phase_ + advanced);
  time_ += dt;
}

void Blend2DController::evaluate(Pose& out) const {
  const BlendSpaceView vs = speeds_->view();
  synthesise_local(vs, point_at(vs, speed_), phase_, out);
  const float u = turn_weight();
  if (u <= 0.0f) return;
  Pose turning;
  synthesise_local(turn_space().view(), BlendPoint{}, phase_, turning);
  const motion::SlerpAt towards_turn(u);
  for (std::size_t j = 0; j < out.local.size(); ++j) out.local[j] = towards_turn(out.local[j], turning.local[j]);
  out.root += u * (turning.root - out.root);
}

// ---- blend spaces -------------------------------------------------------------

std::shared_ptr<const motion::BlendSpace1D> make_turn_space(const motion::Skeleton& skeleton, const motion::Clip& clip,
                                                            const std::string& name, bool cyclic) {
  motion::LocomotionOptions options;
  options.straighten = false;  // the turn is the point
  options.clean_contacts = !cyclic;
  motion::LocomotionClip prepared = cyclic ? motion::prepare_locomotion_cycle(skeleton, clip, name, options)
                                           : motion::prepare_locomotion_clip(skeleton, clip, name, options);
  std::vector<motion::LocomotionClip> clips;
  clips.push_back(std::move(prepared));
  return std::make_shared<const motion::BlendSpace1D>(skeleton, std::move(clips));
}

const DefaultBlendSpaces& default_blend_spaces() {
  static const DefaultBlendSpaces spaces = [] {
    DefaultBlendSpaces s;
    s.speeds = std::make_shared<const motion::BlendSpace1D>(motion::make_default_blend_space());
    const motion::Skeleton skeleton = motion::default_skeleton();
    for (const motion::DefaultMotion& m : motion::make_default_motions(skeleton)) {
      if (m.spec.name == "walk_turn_left") s.turn_left = make_turn_space(skeleton, m.clip, m.spec.name, true);
      if (m.spec.name == "walk_turn_right") s.turn_right = make_turn_space(skeleton, m.clip, m.spec.name, true);
    }
    if (!s.turn_left || !s.turn_right)
      throw Error("the default set has no walk_turn_left / walk_turn_right", at_field("default_blend_spaces"));
    return s;
  }();
  return spaces;
}

}  // namespace throng::anim
