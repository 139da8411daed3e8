#include "anim/controller.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "motion/cycle.h"
#include "motion/fk.h"
#include "motion/phase.h"

namespace throng::anim {

// ---- events and parameters ----------------------------------------------

std::int32_t EventNames::intern(const std::string& name) {
  if (name.empty()) throw Error("an event needs a name", at_field("events"));
  const std::int32_t found = find(name);
  if (found >= 0) return found;
  if (size() >= kMaxEventNames)
    throw Error("event '" + name + "': at most " + std::to_string(kMaxEventNames) + " event names per crowd",
                at_field("events"));
  names_.push_back(name);
  return size() - 1;
}

std::int32_t EventNames::find(std::string_view name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return static_cast<std::int32_t>(i);
  return -1;
}

const std::string& EventNames::name(std::int32_t id) const {
  static const std::string unknown = "?";
  return id >= 0 && id < size() ? names_[static_cast<std::size_t>(id)] : unknown;
}

std::string EventNames::describe(EventMask mask) const {
  std::string out;
  for (std::int32_t i = 0; i < kMaxEventNames; ++i)
    if ((mask >> i) & 1u) {
      if (!out.empty()) out += '|';
      out += name(i);
    }
  return out;
}

void ParameterSet::set(const std::string& name, float value) {
  if (!std::isfinite(value)) throw Error("must be finite", at_field("parameters." + name));
  for (auto& [n, v] : values_)
    if (n == name) {
      v = value;
      return;
    }
  values_.emplace_back(name, value);
}

float ParameterSet::get(std::string_view name, float fallback) const {
  for (const auto& [n, v] : values_)
    if (n == name) return v;
  return fallback;
}

bool ParameterSet::has(std::string_view name) const {
  return std::any_of(values_.begin(), values_.end(), [&](const auto& p) { return p.first == name; });
}

// ---- clips ----------------------------------------------------------------

double AnimClip::duration() const {
  if (!clip || clip->frame_count <= 0) return 0.0;
  const double frames = loop ? clip->frame_count : clip->frame_count - 1;
  return frames * static_cast<double>(clip->frame_time);
}

void AnimClip::validate() const {
  const std::string at = "clips." + (name.empty() ? std::string("?") : name);
  if (!clip) throw Error("has no samples", at_field(at));
  if (clip->frame_count <= 0 || clip->joint_count <= 0) throw Error("has no frames or no joints", at_field(at));
  if (clip->rotations.size() !=
          static_cast<std::size_t>(clip->frame_count) * static_cast<std::size_t>(clip->joint_count) ||
      clip->root_positions.size() != static_cast<std::size_t>(clip->frame_count))
    throw Error("arrays do not match frame and joint counts", at_field(at));
  if (!(clip->frame_time > 0.0f) || !std::isfinite(clip->frame_time))
    throw Error("frame time must be positive", at_field(at + ".frame_time"));
  const double d = duration();
  for (std::size_t i = 0; i < events.size(); ++i) {
    const std::string ef = at + ".events[" + std::to_string(i) + "]";
    if (!(events[i].time >= 0.0f && (events[i].time < d || (d == 0.0 && events[i].time == 0.0f))))
      throw Error("time " + std::to_string(events[i].time) + " s is outside [0, " + std::to_string(d) + ")",
                  at_field(ef));
    if (i > 0 && events[i].time < events[i - 1].time) throw Error("events must be sorted by time", at_field(ef));
    if (events[i].id < 0 || events[i].id >= kMaxEventNames) throw Error("event id out of range", at_field(ef));
  }
}

void sample_clip(const AnimClip& anim, double t, Pose& out) {
  const motion::Clip& c = *anim.clip;
  const std::int32_t N = c.frame_count;
  const std::int32_t J = c.joint_count;
  out.local.resize(static_cast<std::size_t>(J));
  double x = t / static_cast<double>(c.frame_time);
  if (!std::isfinite(x)) x = 0.0;
  std::int32_t f0 = 0, f1 = 0;
  float a = 0.0f;
  if (anim.loop) {
    x -= std::floor(x / N) * N;
    f0 = std::min(static_cast<std::int32_t>(x), N - 1);
    f1 = f0 + 1 < N ? f0 + 1 : 0;
    a = static_cast<float>(x - f0);
  } else {
    x = std::clamp(x, 0.0, static_cast<double>(N - 1));
    f0 = std::min(static_cast<std::int32_t>(x), N - 1);
    f1 = std::min(f0 + 1, N - 1);
    a = static_cast<float>(x - f0);
  }
  const motion::SlerpAt between(a);
  for (std::int32_t j = 0; j < J; ++j)
    out.local[static_cast<std::size_t>(j)] = between(c.rotation(f0, j), c.rotation(f1, j));
  const glm::vec3 r0 = c.root_positions[static_cast<std::size_t>(f0)];
  glm::vec3 r1 = c.root_positions[static_cast<std::size_t>(f1)];
  if (anim.loop && f1 == 0 && N >= 2) r1 = r0 + (r0 - c.root_positions[static_cast<std::size_t>(N - 2)]);
  out.root = glm::mix(r0, r1, a);
}

std::vector<ClipEvent> footstep_events(const motion::Skeleton& skeleton, const AnimClip& clip, EventNames& names) {
  clip.validate();
  const motion::FeetJoints feet = motion::FeetJoints::from_roles(skeleton);
  const motion::ModelSpaceClip model = motion::forward_kinematics(skeleton, *clip.clip);
  const motion::ContactReport report = motion::detect_foot_contacts(skeleton, model, clip.clip->frame_time, feet);
  std::vector<ClipEvent> out;
  for (int f = 0; f < 2; ++f) {
    const std::int32_t id = names.intern(f == 0 ? "footstep_left" : "footstep_right");
    const motion::FootContacts& fc = report.feet[static_cast<std::size_t>(f)];
    for (const motion::ContactInterval& iv : fc.intervals) {
      std::int32_t onset = iv.begin;
      // A loop's contact that wraps through frame 0 started near the end.
      if (clip.loop && onset == 0 && !fc.in_contact.empty() && fc.in_contact.back()) continue;
      if (!clip.loop && onset == 0) continue;  // standing at the start is no step
      out.push_back({static_cast<float>(onset) * clip.clip->frame_time, id});
    }
  }
  std::sort(out.begin(), out.end(), [](const ClipEvent& a, const ClipEvent& b) {
    return a.time < b.time || (a.time == b.time && a.id < b.id);
  });
  return out;
}

// ---- clip player ------------------------------------------------------------

ClipPlayer::ClipPlayer(AnimClip clip, float rate, double start_time)
    : clip_(std::move(clip)), start_(start_time), time_(start_time) {
  clip_.validate();
  set_rate(rate);
  if (!std::isfinite(start_time)) throw Error("must be finite", at_field("clip_player.start_time"));
}

void ClipPlayer::set_rate(float rate) {
  if (!std::isfinite(rate)) throw Error("must be finite", at_field("clip_player.rate"));
  rate_ = rate;
}

bool ClipPlayer::finished() const { return !clip_.loop && (rate_ >= 0.0f ? time_ >= duration() : time_ <= 0.0); }

void ClipPlayer::advance(float dt, const ParameterSet&, EventMask& events) {
  const double d = duration();
  double t0 = time_;
  double t1 = time_ + static_cast<double>(rate_) * dt;
  if (!clip_.loop) {
    t0 = std::clamp(t0, 0.0, d);
    t1 = std::clamp(t1, 0.0, d);
  }
  time_ = t1;
  if (clip_.events.empty() || t0 == t1 || d <= 0.0) return;
  // The playhead passes events at [t0, t1) going forward, (t1, t0] going
  // backward, so an event at the start position fires on the first advance.
  const bool forward = t1 > t0;
  const double lo = forward ? t0 : t1;
  const double hi = forward ? t1 : t0;
  if (clip_.loop && hi - lo >= d) {
    for (const ClipEvent& e : clip_.events) events |= 1u << e.id;
    return;
  }
  const double k_lo = clip_.loop ? std::floor(lo / d) : 0.0;
  const double k_hi = clip_.loop ? std::floor(hi / d) : 0.0;
  for (double k = k_lo; k <= k_hi; k += 1.0)
    for (const ClipEvent& e : clip_.events) {
      const double te = e.time + k * d;
      if (forward ? (te >= lo && te < hi) : (te > lo && te <= hi)) events |= 1u << e.id;
    }
}

// ---- layers -------------------------------------------------------------------

BoneMask BoneMask::all(std::int32_t joints, float weight) {
  BoneMask m;
  m.weights.assign(static_cast<std::size_t>(joints), weight);
  return m;
}

BoneMask BoneMask::subtrees(const motion::Skeleton& skeleton, const std::vector<std::string>& roots, float weight) {
  BoneMask m = all(skeleton.joint_count(), 0.0f);
  std::vector<std::uint8_t> in(static_cast<std::size_t>(skeleton.joint_count()), 0);
  for (std::size_t k = 0; k < roots.size(); ++k) {
    const std::int32_t j = skeleton.find(roots[k]);
    if (j < 0) throw Error("no joint named '" + roots[k] + "'", at_field("mask.joints[" + std::to_string(k) + "]"));
    in[static_cast<std::size_t>(j)] = 1;
  }
  for (std::size_t j = 0; j < in.size(); ++j) {
    const std::int32_t p = skeleton.parents[j];
    if (p >= 0 && in[static_cast<std::size_t>(p)]) in[j] = 1;
    if (in[j]) m.weights[j] = weight;
  }
  return m;
}

LayeredController::LayeredController(std::unique_ptr<Controller> base) : base_(std::move(base)) {
  if (!base_) throw Error("a layered controller needs a base controller", at_field("layers.base"));
}

LayeredController::LayeredController(const LayeredController& other)
    : Controller(other), base_(other.base_->clone()), weights_(other.weights_) {
  for (const Layer& l : other.layers_) {
    Layer copy;
    copy.controller = l.controller->clone();
    copy.mode = l.mode;
    copy.weight = l.weight;
    copy.weight_parameter = l.weight_parameter;
    copy.mask = l.mask;
    copy.reference = l.reference;
    layers_.push_back(std::move(copy));
  }
}

void LayeredController::add_layer(Layer layer) {
  const std::string at = "layers[" + std::to_string(layers_.size()) + "]";
  const auto J = static_cast<std::size_t>(joint_count());
  if (!layer.controller) throw Error("a layer needs a controller", at_field(at + ".controller"));
  if (layer.controller->joint_count() != joint_count())
    throw Error(
        "controller has " + std::to_string(layer.controller->joint_count()) + " joints, the base " + std::to_string(J),
        at_field(at + ".controller"));
  if (!(layer.weight >= 0.0f && layer.weight <= 1.0f)) throw Error("must be in [0, 1]", at_field(at + ".weight"));
  if (layer.mask.weights.empty()) layer.mask = BoneMask::all(joint_count());
  if (layer.mask.weights.size() != J)
    throw Error("has " + std::to_string(layer.mask.weights.size()) + " weights, expected " + std::to_string(J),
                at_field(at + ".mask"));
  for (float w : layer.mask.weights)
    if (!(w >= 0.0f && w <= 1.0f)) throw Error("weights must be in [0, 1]", at_field(at + ".mask"));
  if (layer.mode == LayerMode::Override && !layer.reference.empty())
    throw Error("only additive layers take a reference", at_field(at + ".reference"));
  if (!layer.reference.empty() && layer.reference.size() != J)
    throw Error("has " + std::to_string(layer.reference.size()) + " rotations, expected " + std::to_string(J),
                at_field(at + ".reference"));
  layers_.push_back(std::move(layer));
  weights_.push_back(layers_.back().weight);
}

void LayeredController::reset() {
  base_->reset();
  for (Layer& l : layers_) l.controller->reset();
}

void LayeredController::advance(float dt, const ParameterSet& params, EventMask& events) {
  base_->advance(dt, params, events);
  for (std::size_t i = 0; i < layers_.size(); ++i) {
    Layer& l = layers_[i];
    weights_[i] = l.weight_parameter.empty() ? l.weight : std::clamp(params.get(l.weight_parameter, 0.0f), 0.0f, 1.0f);
    EventMask layer_events = 0;
    l.controller->advance(dt, params, layer_events);
    if (weights_[i] >= 0.5f) events |= layer_events;
  }
}

void LayeredController::evaluate(Pose& out) const {
  base_->evaluate(out);
  for (std::size_t i = 0; i < layers_.size(); ++i) {
    const Layer& l = layers_[i];
    if (weights_[i] <= 0.0f) continue;
    l.controller->evaluate(scratch_);
    for (std::size_t j = 0; j < out.local.size(); ++j) {
      const float w = weights_[i] * l.mask.weights[j];
      if (w <= 0.0f) continue;
      if (l.mode == LayerMode::Override) {
        out.local[j] = motion::slerp_shortest(out.local[j], scratch_.local[j], w);
      } else {
        const glm::quat delta =
            l.reference.empty() ? scratch_.local[j] : glm::inverse(l.reference[j]) * scratch_.local[j];
        out.local[j] = glm::normalize(out.local[j] * motion::slerp_shortest(glm::quat(1, 0, 0, 0), delta, w));
      }
    }
    if (l.mode == LayerMode::Override && !l.mask.weights.empty())
      out.root = glm::mix(out.root, scratch_.root, weights_[i] * l.mask.weights[0]);
  }
}

// ---- state machine --------------------------------------------------------------

const char* to_string(Compare c) {
  switch (c) {
    case Compare::Less: return "<";
    case Compare::LessEqual: return "<=";
    case Compare::Greater: return ">";
    case Compare::GreaterEqual: return ">=";
    case Compare::Equal: return "==";
    case Compare::NotEqual: return "!=";
  }
  return "?";
}

bool Condition::holds(float x) const {
  switch (op) {
    case Compare::Less: return x < value;
    case Compare::LessEqual: return x <= value;
    case Compare::Greater: return x > value;
    case Compare::GreaterEqual: return x >= value;
    case Compare::Equal: return x == value;
    case Compare::NotEqual: return x != value;
  }
  return false;
}

StateMachine::StateMachine(const StateMachine& other)
    : Controller(other),
      transitions_(other.transitions_),
      initial_(other.initial_),
      current_(other.current_),
      fading_from_(other.fading_from_),
      fade_time_(other.fade_time_),
      fade_elapsed_(other.fade_elapsed_),
      state_time_(other.state_time_),
      time_(other.time_) {
  for (const State& s : other.states_) states_.push_back({s.name, s.controller->clone(), s.enter_event});
}

std::int32_t StateMachine::add_state(std::string name, std::unique_ptr<Controller> controller,
                                     std::int32_t enter_event) {
  const std::string at = "states[" + std::to_string(states_.size()) + "]";
  if (name.empty()) throw Error("a state needs a name", at_field(at + ".name"));
  if (find_state(name) >= 0) throw Error("state '" + name + "' defined twice", at_field(at + ".name"));
  if (!controller) throw Error("a state needs a controller", at_field(at + ".controller"));
  if (!states_.empty() && controller->joint_count() != joint_count())
    throw Error("controller has " + std::to_string(controller->joint_count()) + " joints, the first state " +
                    std::to_string(joint_count()),
                at_field(at + ".controller"));
  if (enter_event >= kMaxEventNames) throw Error("event id out of range", at_field(at + ".enter_event"));
  states_.push_back({std::move(name), std::move(controller), enter_event});
  return state_count() - 1;
}

void StateMachine::add_transition(std::int32_t from, std::int32_t to, std::vector<Condition> conditions, float fade) {
  const std::string at = "transitions[" + std::to_string(transitions_.size()) + "]";
  if (from != kAnyState && (from < 0 || from >= state_count())) throw Error("no such state", at_field(at + ".from"));
  if (to < 0 || to >= state_count()) throw Error("no such state", at_field(at + ".to"));
  if (from == to) throw Error("a transition must change state", at_field(at + ".to"));
  if (!(fade >= 0.0f && fade < 1e4f)) throw Error("must be in [0, 1e4) seconds", at_field(at + ".fade"));
  for (std::size_t k = 0; k < conditions.size(); ++k)
    if (!std::isfinite(conditions[k].value) || conditions[k].parameter.empty())
      throw Error("needs a parameter and a finite value", at_field(at + ".when[" + std::to_string(k) + "]"));
  transitions_.push_back({from, to, std::move(conditions), fade});
}

std::int32_t StateMachine::find_state(std::string_view name) const {
  for (std::size_t i = 0; i < states_.size(); ++i)
    if (states_[i].name == name) return static_cast<std::int32_t>(i);
  return -1;
}

void StateMachine::set_initial_state(std::int32_t state) {
  if (state < 0 || state >= state_count()) throw Error("no such state", at_field("initial"));
  initial_ = state;
  reset();
}

std::int32_t StateMachine::joint_count() const { return states_.empty() ? 0 : states_[0].controller->joint_count(); }

void StateMachine::reset() {
  current_ = initial_;
  fading_from_ = -1;
  fade_elapsed_ = fade_time_ = 0.0f;
  state_time_ = time_ = 0.0;
  if (!states_.empty()) states_[static_cast<std::size_t>(current_)].controller->reset();
}

float StateMachine::fade_weight() const {
  if (fading_from_ < 0 || fade_time_ <= 0.0f) return 1.0f;
  return std::clamp(fade_elapsed_ / fade_time_, 0.0f, 1.0f);
}

double StateMachine::duration() const {
  return states_.empty() ? 0.0 : states_[static_cast<std::size_t>(current_)].controller->duration();
}
bool StateMachine::finished() const {
  return !states_.empty() && states_[static_cast<std::size_t>(current_)].controller->finished();
}

float StateMachine::read(const std::string& parameter, const ParameterSet& params) const {
  const Controller& c = *states_[static_cast<std::size_t>(current_)].controller;
  if (parameter == "state_time") return static_cast<float>(state_time_);
  if (parameter == "state_phase") return c.duration() > 0.0 ? static_cast<float>(state_time_ / c.duration()) : 0.0f;
  if (parameter == "state_finished") return c.finished() ? 1.0f : 0.0f;
  return params.get(parameter, 0.0f);
}

void StateMachine::advance(float dt, const ParameterSet& params, EventMask& events) {
  if (states_.empty()) return;
  time_ += dt;
  state_time_ += dt;
  EventMask current_events = 0, source_events = 0;
  states_[static_cast<std::size_t>(current_)].controller->advance(dt, params, current_events);
  if (fading_from_ >= 0) {
    states_[static_cast<std::size_t>(fading_from_)].controller->advance(dt, params, source_events);
    fade_elapsed_ += dt;
    events |= fade_weight() >= 0.5f ? current_events : source_events;
    if (fade_elapsed_ >= fade_time_) fading_from_ = -1;
  } else {
    events |= current_events;
  }
  if (fading_from_ >= 0) return;
  for (const Transition& t : transitions_) {
    if (t.from != kAnyState && t.from != current_) continue;
    if (t.to == current_) continue;
    bool all = true;
    for (const Condition& c : t.conditions) all = all && c.holds(read(c.parameter, params));
    if (!all) continue;
    fading_from_ = t.fade > 0.0f ? current_ : -1;
    fade_time_ = t.fade;
    fade_elapsed_ = 0.0f;
    current_ = t.to;
    state_time_ = 0.0;
    State& s = states_[static_cast<std::size_t>(current_)];
    s.controller->reset();
    if (s.enter_event >= 0) events |= 1u << s.enter_event;
    break;
  }
}

void StateMachine::evaluate(Pose& out) const {
  if (states_.empty()) return;
  states_[static_cast<std::size_t>(current_)].controller->evaluate(out);
  if (fading_from_ < 0) return;
  const float w = fade_weight();
  states_[static_cast<std::size_t>(fading_from_)].controller->evaluate(scratch_);
  const motion::SlerpAt fade(w);
  for (std::size_t j = 0; j < out.local.size(); ++j) out.local[j] = fade(scratch_.local[j], out.local[j]);
  out.root = glm::mix(scratch_.root, out.root, w);
}

}  // namespace throng::anim
