// Controllers that blend locomotion clips by parameters, on the locomotion
// blend space (motion/blend_space.h): the pose is what per-character
// synthesis gives (the same blend_point, warp_phase, blended_rotation and
// leg IK), so a stream played by one of these shows exactly what an agent
// synthesised at the same speed and phase would show.
//
// * Blend1DController: speed (parameter "speed", m/s) through a
//   BlendSpace1D; the phase advances by dt / duration(speed), duration being
//   the blended cycle's period at that speed (motion::cycle_rate).
// * Blend2DController: speed x turn rate (parameters "speed" and "turn",
//   rad/s, + = left). The speed axis is a BlendSpace1D of straight clips;
//   the turn axis is a turning clip to each side (the default set's
//   walk_turn_left / walk_turn_right), recorded at one walking speed. The
//   pose is slerp(speed blend, turning clip, u) per joint with u = h * g:
//   h = |turn| / the turning clip's own turn rate (at most 1), g = 1 at the
//   turning clip's speed falling linearly to 0 at the neighbouring clips of
//   the speed axis. So turn 0 gives the 1D speed blend exactly, and at the
//   turning clip's speed a full turn gives that clip exactly.
//
// Both fire footstep events (optional ids) when the phase crosses the
// blend's left and right touchdowns (docs/streams.md, "Controllers").
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "anim/controller.h"
#include "motion/locomotion.h"

namespace throng::anim {

struct Blend1DOptions {
  std::string parameter = "speed";  // m/s (at scale 1), read at every advance
  float speed = 0.0f;               // used while the parameter is not set (and before the first advance)
  float start_phase = 0.0f;         // [0, 1): 0 is the left touchdown
  std::int32_t footstep_left = -1;  // event ids fired at the touchdowns, -1 for none
  std::int32_t footstep_right = -1;
  void validate() const;  // Error naming "blend1d.<field>"
};

class Blend1DController final : public Controller {
 public:
  explicit Blend1DController(std::shared_ptr<const motion::BlendSpace1D> space, Blend1DOptions options = {});

  std::int32_t joint_count() const override { return space_->joint_count(); }
  void reset() override;
  void advance(float dt, const ParameterSet& params, EventMask& events) override;
  void evaluate(Pose& out) const override;
  std::unique_ptr<Controller> clone() const override { return std::make_unique<Blend1DController>(*this); }
  double time() const override { return time_; }
  double duration() const override;  // the blended cycle's period at the current speed; 0 if it does not cycle

  const motion::BlendSpace1D& space() const { return *space_; }
  const Blend1DOptions& options() const { return options_; }
  float speed() const { return speed_; }
  float phase() const { return phase_; }
  float cycles_per_second() const;

 private:
  std::shared_ptr<const motion::BlendSpace1D> space_;
  Blend1DOptions options_;
  float speed_ = 0.0f;
  float phase_ = 0.0f;
  double time_ = 0.0;
};

struct Blend2DOptions {
  std::string speed_parameter = "speed";  // m/s
  std::string turn_parameter = "turn";    // rad/s, + = left
  float speed = 0.0f;                     // while the parameters are not set
  float turn = 0.0f;
  float start_phase = 0.0f;
  std::int32_t footstep_left = -1;
  std::int32_t footstep_right = -1;
  void validate() const;  // Error naming "blend2d.<field>"
};

class Blend2DController final : public Controller {
 public:
  // speeds: straight clips by speed. turn_left / turn_right: one turning
  // clip each (single-clip blend spaces, make_turn_space), turning left
  // (positive turn per cycle) and right (negative); same skeleton.
  Blend2DController(std::shared_ptr<const motion::BlendSpace1D> speeds,
                    std::shared_ptr<const motion::BlendSpace1D> turn_left,
                    std::shared_ptr<const motion::BlendSpace1D> turn_right, Blend2DOptions options = {});

  std::int32_t joint_count() const override { return speeds_->joint_count(); }
  void reset() override;
  void advance(float dt, const ParameterSet& params, EventMask& events) override;
  void evaluate(Pose& out) const override;
  std::unique_ptr<Controller> clone() const override { return std::make_unique<Blend2DController>(*this); }
  double time() const override { return time_; }
  double duration() const override;

  float speed() const { return speed_; }
  float turn() const { return turn_; }
  float phase() const { return phase_; }
  // How much of the turning clip the pose holds now (u above), in [0, 1].
  float turn_weight() const;
  float cycles_per_second() const;

 private:
  const motion::BlendSpace1D& turn_space() const { return turn_ >= 0.0f ? *left_ : *right_; }

  std::shared_ptr<const motion::BlendSpace1D> speeds_, left_, right_;
  Blend2DOptions options_;
  float speed_ = 0.0f;
  float turn_ = 0.0f;
  float phase_ = 0.0f;
  double time_ = 0.0;
};

// One turning clip as a single-clip blend space for Blend2DController: the
// cycle is prepared keeping its turn (not straightened); `cyclic` says the
// clip is already exactly one cycle (the default set), otherwise the loop
// is found (prepare_locomotion_clip) and the contacts cleaned.
std::shared_ptr<const motion::BlendSpace1D> make_turn_space(const motion::Skeleton& skeleton, const motion::Clip& clip,
                                                            const std::string& name, bool cyclic);

// The default set on the default skeleton: its speed blend space
// (motion::make_default_blend_space) and walk_turn_left / walk_turn_right.
struct DefaultBlendSpaces {
  std::shared_ptr<const motion::BlendSpace1D> speeds, turn_left, turn_right;
};
const DefaultBlendSpaces& default_blend_spaces();

}  // namespace throng::anim
