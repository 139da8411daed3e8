// Controllers: what writes a stream's pose each frame. A controller is a
// host object (virtual calls are fine here: a stream is evaluated once per
// frame for thousands of agents); it advances its own time, says which
// events it crossed, and evaluates a pose.
//
// Provided: ClipPlayer (loop, rate, events), LayeredController (per-bone
// masks, override and additive layers), StateMachine (conditions on
// parameters, cross-fades). Blends over a parameter (1D speed, 2D speed x
// turn) plug in through the same interface (docs/streams.md, "Controllers").
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "anim/pose.h"
#include "motion/clip.h"
#include "motion/skeleton.h"

namespace throng::anim {

// Events are small integers; a frame's events are a bit mask, so at most 32
// distinct event names per crowd.
using EventMask = std::uint32_t;
inline constexpr std::int32_t kMaxEventNames = 32;

class EventNames {
 public:
  // The id of a name, adding it when new; Error when all 32 are taken or the name is empty.
  std::int32_t intern(const std::string& name);
  std::int32_t find(std::string_view name) const;  // -1 when absent
  const std::string& name(std::int32_t id) const;
  std::int32_t size() const { return static_cast<std::int32_t>(names_.size()); }
  // "footstep_left|footstep_right"
  std::string describe(EventMask mask) const;

 private:
  std::vector<std::string> names_;
};

// Named values fed by the simulation (speed, turn, waiting, anything else).
class ParameterSet {
 public:
  void set(const std::string& name, float value);  // Error for a non-finite value
  float get(std::string_view name, float fallback = 0.0f) const;
  bool has(std::string_view name) const;
  const std::vector<std::pair<std::string, float>>& values() const { return values_; }

 private:
  std::vector<std::pair<std::string, float>> values_;
};

struct ClipEvent {
  float time = 0.0f;  // seconds from the clip's start
  std::int32_t id = 0;
};

// A clip as controllers play it.
struct AnimClip {
  std::string name;
  std::shared_ptr<const motion::Clip> clip;
  // A looping clip's last frame flows into its first (motion::CachedCycle's
  // convention), so it lasts frame_count frames; a one-shot clip lasts
  // frame_count - 1 and holds its last frame.
  bool loop = true;
  std::vector<ClipEvent> events;  // sorted by time, in [0, duration)

  double duration() const;
  // Error naming the field: no clip, no frames, bad frame time, event times
  // outside [0, duration) or unsorted, event ids outside [0, 32).
  void validate() const;
};

// The pose at time t (seconds; wrapped for loops, clamped otherwise): SLERP
// of neighbouring frames, root position interpolated. Across a loop's wrap
// the root follows the last frame's step, so the root stays within one
// cycle. Animated non-root translations are not used (rest offsets are).
void sample_clip(const AnimClip& clip, double t, Pose& out);

// Footstep events at the onsets of foot contacts (motion/cycle.h), named
// "footstep_left" and "footstep_right". A looping clip's contact that runs
// through its last frame into frame 0 starts where it starts, not at 0.
// Needs the ankle roles; Error otherwise.
std::vector<ClipEvent> footstep_events(const motion::Skeleton& skeleton, const AnimClip& clip, EventNames& names);

class Controller {
 public:
  virtual ~Controller() = default;
  virtual std::int32_t joint_count() const = 0;
  // Back to time 0 (and to the initial state).
  virtual void reset() = 0;
  // Moves time on by dt seconds reading the parameters; ORs the events
  // crossed into `events`.
  virtual void advance(float dt, const ParameterSet& params, EventMask& events) = 0;
  // The current pose; out.local has joint_count() entries.
  virtual void evaluate(Pose& out) const = 0;
  virtual std::unique_ptr<Controller> clone() const = 0;
  // Seconds played since reset; the length of one cycle or of the whole
  // motion (0 when it has none); a one-shot motion that reached its end.
  virtual double time() const = 0;
  virtual double duration() const { return 0.0; }
  virtual bool finished() const { return false; }
};

class ClipPlayer final : public Controller {
 public:
  // rate: playback speed (1 = as recorded, negative plays backwards).
  explicit ClipPlayer(AnimClip clip, float rate = 1.0f, double start_time = 0.0);
  std::int32_t joint_count() const override { return clip_.clip->joint_count; }
  void reset() override { time_ = start_; }
  void advance(float dt, const ParameterSet& params, EventMask& events) override;
  void evaluate(Pose& out) const override { sample_clip(clip_, time_, out); }
  std::unique_ptr<Controller> clone() const override { return std::make_unique<ClipPlayer>(*this); }
  double time() const override { return time_; }
  double duration() const override { return clip_.duration(); }
  bool finished() const override;
  const AnimClip& clip() const { return clip_; }
  float rate() const { return rate_; }
  void set_rate(float rate);  // Error when not finite

 private:
  AnimClip clip_;
  float rate_ = 1.0f;
  double start_ = 0.0;
  double time_ = 0.0;
};

// Per-joint weights in [0, 1] for layers.
struct BoneMask {
  std::vector<float> weights;
  static BoneMask all(std::int32_t joints, float weight = 1.0f);
  // The subtrees of the named joints (Error naming an unknown joint).
  static BoneMask subtrees(const motion::Skeleton& skeleton, const std::vector<std::string>& roots,
                           float weight = 1.0f);
};

enum class LayerMode : std::uint8_t {
  Override,  // rotation <- slerp(rotation, layer, w)
  Additive,  // rotation <- rotation * slerp(1, reference^-1 * layer, w)
};

struct Layer {
  std::unique_ptr<Controller> controller;
  LayerMode mode = LayerMode::Override;
  float weight = 1.0f;
  std::string weight_parameter;  // when set, the weight is this parameter (clamped to [0, 1]) each frame
  BoneMask mask;                 // joint_count weights
  // Additive only: the pose whose difference to the layer is added
  // (joint_count rotations); empty means identity (the layer holds deltas).
  std::vector<glm::quat> reference;
};

// A base controller with layers applied in order. Events come from the
// base and from every layer whose weight is at least 1/2.
class LayeredController final : public Controller {
 public:
  explicit LayeredController(std::unique_ptr<Controller> base);
  LayeredController(const LayeredController& other);
  // Error naming "layers[i].<field>" for a mask or reference of the wrong
  // size, a weight outside [0, 1], a controller of another joint count.
  void add_layer(Layer layer);
  std::int32_t layer_count() const { return static_cast<std::int32_t>(layers_.size()); }
  Layer& layer(std::int32_t i) { return layers_[static_cast<std::size_t>(i)]; }

  std::int32_t joint_count() const override { return base_->joint_count(); }
  void reset() override;
  void advance(float dt, const ParameterSet& params, EventMask& events) override;
  void evaluate(Pose& out) const override;
  std::unique_ptr<Controller> clone() const override { return std::make_unique<LayeredController>(*this); }
  double time() const override { return base_->time(); }
  double duration() const override { return base_->duration(); }
  bool finished() const override { return base_->finished(); }

 private:
  std::unique_ptr<Controller> base_;
  std::vector<Layer> layers_;
  std::vector<float> weights_;  // effective weight of each layer this frame
  mutable Pose scratch_;
};

enum class Compare : std::uint8_t { Less, LessEqual, Greater, GreaterEqual, Equal, NotEqual };
const char* to_string(Compare c);  // "<", "<=", ...

// parameter <op> value. Besides the crowd's parameters a condition may read
// "state_time" (seconds in the current state), "state_phase" (state time /
// its controller's duration) and "state_finished" (1 when a one-shot state
// reached its end).
struct Condition {
  std::string parameter;
  Compare op = Compare::Greater;
  float value = 0.0f;
  bool holds(float x) const;
};

// States with a controller each; transitions fire when all their conditions
// hold, checked in the order added after the current state has advanced
// (from a specific state or from any state). The target restarts from time
// 0 and is cross-faded in over `fade` seconds, both states advancing; while
// a cross-fade runs no other transition fires. Events come from the state
// with the larger weight; entering a state may fire its own event.
class StateMachine final : public Controller {
 public:
  static constexpr std::int32_t kAnyState = -1;

  StateMachine() = default;
  StateMachine(const StateMachine& other);
  // Errors name "states[i]..." / "transitions[i]...".
  std::int32_t add_state(std::string name, std::unique_ptr<Controller> controller, std::int32_t enter_event = -1);
  void add_transition(std::int32_t from, std::int32_t to, std::vector<Condition> conditions, float fade);
  std::int32_t find_state(std::string_view name) const;
  void set_initial_state(std::int32_t state);

  std::int32_t state() const { return current_; }
  const std::string& state_name(std::int32_t state) const { return states_[static_cast<std::size_t>(state)].name; }
  std::int32_t state_count() const { return static_cast<std::int32_t>(states_.size()); }
  std::int32_t fading_from() const { return fading_from_; }  // -1 unless a cross-fade runs
  float fade_weight() const;                                 // weight of the current state, 1 when not fading
  double state_time() const { return state_time_; }

  std::int32_t joint_count() const override;
  void reset() override;
  void advance(float dt, const ParameterSet& params, EventMask& events) override;
  void evaluate(Pose& out) const override;
  std::unique_ptr<Controller> clone() const override { return std::make_unique<StateMachine>(*this); }
  double time() const override { return time_; }
  double duration() const override;
  bool finished() const override;

 private:
  struct State {
    std::string name;
    std::unique_ptr<Controller> controller;
    std::int32_t enter_event = -1;
  };
  struct Transition {
    std::int32_t from = kAnyState;
    std::int32_t to = 0;
    std::vector<Condition> conditions;
    float fade = 0.0f;
  };
  float read(const std::string& parameter, const ParameterSet& params) const;

  std::vector<State> states_;
  std::vector<Transition> transitions_;
  std::int32_t initial_ = 0;
  std::int32_t current_ = 0;
  std::int32_t fading_from_ = -1;
  float fade_time_ = 0.0f;
  float fade_elapsed_ = 0.0f;
  double state_time_ = 0.0;
  double time_ = 0.0;
  mutable Pose scratch_;
};

}  // namespace throng::anim
