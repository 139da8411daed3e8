#include "anim/stream_pool.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace throng::anim {

namespace {

// Host data into part of a buffer in any memory.
template <class T>
void upload(Buffer<T>& dst, Index first, const T* src, Index count) {
  dst.write(first, std::span<const T>(src, static_cast<std::size_t>(count)));
}
template <class T>
void download(const Buffer<T>& src, Index first, T* dst, Index count) {
  src.read(first, std::span<T>(dst, static_cast<std::size_t>(count)));
}

void apply_root_motion(RootMotion mode, Pose& pose) {
  if (mode == RootMotion::InPlace) pose.root.x = pose.root.z = 0.0f;
}

void check_pose(const Pose& pose, std::int32_t joints, const std::string& who) {
  if (pose.joint_count() != joints)
    throw Error(
        "controller wrote " + std::to_string(pose.joint_count()) + " joints, the rig has " + std::to_string(joints),
        at_field(who));
}

}  // namespace

const char* to_string(StreamState s) { return s == StreamState::Running ? "running" : "stopped"; }
const char* to_string(RootMotion r) { return r == RootMotion::InPlace ? "in_place" : "keep"; }

void StreamSpec::validate(std::int32_t rig_count, float frame_rate) const {
  const std::string at = "streams." + (name.empty() ? std::string("?") : name);
  if (name.empty()) throw Error("a stream needs a name", at_field("streams"));
  if (rig < 0 || rig >= rig_count) throw Error("no such rig", at_field(at + ".rig"));
  if (history < 1 || history > 65536) throw Error("must be in [1, 65536] slots", at_field(at + ".history"));
  const double least = static_cast<double>(history) / frame_rate;
  if (time_to_dilate == 0.0f) return;  // automatic
  if (!(time_to_dilate >= least - 1e-6) || !std::isfinite(time_to_dilate))
    throw Error("must be at least history / frame_rate = " + std::to_string(least) +
                    " s, so that offsets never outrun the history (it grows one slot per frame)",
                at_field(at + ".time_to_dilate"));
}

// ---- AnimStream ------------------------------------------------------------------

AnimStream::AnimStream(const Rig& rig, std::int32_t rig_index, StreamSpec spec, std::unique_ptr<Controller> controller,
                       Memory memory)
    : spec_(std::move(spec)),
      joints_(rig.joint_count()),
      controller_(std::move(controller)),
      kinematics_(rig.kinematics()) {
  spec_.rig = rig_index;
  if (!controller_) throw Error("a stream needs a controller", at_field("streams." + spec_.name + ".controller"));
  if (controller_->joint_count() != joints_)
    throw Error("controller has " + std::to_string(controller_->joint_count()) + " joints, rig '" + rig.name +
                    "' has " + std::to_string(joints_),
                at_field("streams." + spec_.name + ".controller"));
  const Index M = spec_.history;
  rotations_ = Buffer<glm::quat>(M * joints_, memory);
  skinning_ = Buffer<Mat3x4>(M * joints_, memory);
  roots_ = Buffer<glm::vec3>(M, memory);
  events_ = Buffer<std::uint32_t>::zeros(M, memory);
  // Every slot starts as the rest pose, so even a read that dilation should
  // have prevented sees a valid pose.
  const Pose rest = rig.rest_pose();
  std::vector<Mat3x4> palette(static_cast<std::size_t>(joints_));
  kinematics_.palette(rest, palette.data());
  for (Index k = 0; k < M; ++k) {
    upload(rotations_, k * joints_, rest.local.data(), joints_);
    upload(skinning_, k * joints_, palette.data(), joints_);
    upload(roots_, k, &rest.root, 1);
  }
  head_ = spec_.history - 1;  // the first pose written lands in slot 0
}

double AnimStream::dilation() const {
  return std::min(dilation_from_ + static_cast<double>(dilation_steps_) * change_rate_, dilation_target_);
}

// The epsilon keeps k * rate that is an integer in exact arithmetic from flooring one below.
std::int32_t AnimStream::max_offset() const { return static_cast<std::int32_t>(std::floor(dilation() + 1e-9)); }

std::size_t AnimStream::pose_bytes() const {
  return static_cast<std::size_t>(rotations_.size()) * sizeof(glm::quat) +
         static_cast<std::size_t>(skinning_.size()) * sizeof(Mat3x4) +
         static_cast<std::size_t>(roots_.size()) * sizeof(glm::vec3);
}

SourceView AnimStream::view() const {
  SourceView v;
  v.rotations = rotations_.data();
  v.skinning = skinning_.data();
  v.roots = roots_.data();
  v.events = events_.data();
  v.joints = joints_;
  v.history = spec_.history;
  v.head = head_;
  v.newest = newest_;
  v.max_offset = max_offset();
  v.rig = spec_.rig;
  return v;
}

Pose AnimStream::pose_at(std::int32_t offset) const {
  Pose p(joints_);
  const std::int32_t slot = (head_ - std::clamp(offset, 0, spec_.history - 1) + spec_.history) % spec_.history;
  download(rotations_, static_cast<Index>(slot) * joints_, p.local.data(), joints_);
  download(roots_, slot, &p.root, 1);
  return p;
}

EventMask AnimStream::events_at(std::int32_t offset) const {
  const std::int32_t slot = (head_ - std::clamp(offset, 0, spec_.history - 1) + spec_.history) % spec_.history;
  EventMask m = 0;
  download(events_, slot, &m, 1);
  return m;
}

void AnimStream::start(float frame_rate) {
  state_ = StreamState::Running;
  controller_->reset();
  written_ = 0;
  dilation_from_ = 0.0;
  dilation_steps_ = 0;
  dilation_target_ = spec_.history - 1;
  change_rate_ = static_cast<double>(spec_.history) / (static_cast<double>(spec_.time_to_dilate) * frame_rate);
}

void AnimStream::fill(float frame_rate, std::int32_t newest_frame, Pose& scratch,
                      std::vector<Mat3x4>& palette_scratch) {
  start(frame_rate);
  const float dt = 1.0f / frame_rate;
  const std::int32_t M = spec_.history;
  for (std::int32_t k = 0; k < M; ++k) {
    EventMask events = 0;
    if (k > 0) controller_->advance(dt, parameters_, events);
    controller_->evaluate(scratch);
    apply_root_motion(spec_.root, scratch);
    write(scratch, events, newest_frame - (M - 1 - k), palette_scratch);
  }
  // Every slot holds a pose of this run: offsets may reach M - 1 now.
  dilation_from_ = M - 1;
  dilation_steps_ = 0;
}

void AnimStream::resize_history(std::int32_t history, float time_to_dilate, float frame_rate) {
  const std::string at = "streams." + spec_.name;
  if (history < 1 || history > 65536) throw Error("must be in [1, 65536] slots", at_field(at + ".history"));
  const std::int32_t old_m = spec_.history;
  // Offsets may reach current_length - 1 now; the growth beyond must take
  // at least one frame per slot.
  const double current_length = max_offset() + 1.0;
  const double growth = std::max(0.0, history - current_length);
  if (time_to_dilate == 0.0f) time_to_dilate = static_cast<float>(2.0 * growth / frame_rate);
  if (!std::isfinite(time_to_dilate) || !(static_cast<double>(time_to_dilate) * frame_rate >= growth - 1e-6) ||
      time_to_dilate < 0.0f)
    throw Error("must be at least " + std::to_string(growth / frame_rate) + " s to grow the history from " +
                    std::to_string(old_m) + " to " + std::to_string(history) +
                    " slots at no more than one slot per frame",
                at_field(at + ".time_to_dilate"));
  const Memory memory = rotations_.memory();
  Buffer<glm::quat> rotations(static_cast<Index>(history) * joints_, memory);
  Buffer<Mat3x4> skinning(static_cast<Index>(history) * joints_, memory);
  Buffer<glm::vec3> roots(history, memory);
  Buffer<std::uint32_t> events = Buffer<std::uint32_t>::zeros(history, memory);
  // The new ring's head is slot 0; offset o goes to slot (-o mod M_new).
  // Slots beyond what is kept get a copy of the oldest kept pose.
  const std::int32_t kept = std::max(1, std::min(std::max(written_, 1), history));
  std::vector<glm::quat> q(static_cast<std::size_t>(joints_));
  std::vector<Mat3x4> m(static_cast<std::size_t>(joints_));
  glm::vec3 r;
  std::uint32_t e = 0;
  for (std::int32_t o = 0; o < history; ++o) {
    const std::int32_t from_o = std::min(o, kept - 1);
    const std::int32_t from = (head_ - from_o + old_m * 2) % old_m;
    download(rotations_, static_cast<Index>(from) * joints_, q.data(), joints_);
    download(skinning_, static_cast<Index>(from) * joints_, m.data(), joints_);
    download(roots_, from, &r, 1);
    download(events_, from, &e, 1);
    if (o >= kept) e = 0;
    const std::int32_t to = (history - o) % history;
    upload(rotations, static_cast<Index>(to) * joints_, q.data(), joints_);
    upload(skinning, static_cast<Index>(to) * joints_, m.data(), joints_);
    upload(roots, to, &r, 1);
    upload(events, to, &e, 1);
  }
  rotations_ = std::move(rotations);
  skinning_ = std::move(skinning);
  roots_ = std::move(roots);
  events_ = std::move(events);
  head_ = 0;
  written_ = std::min(written_, history);
  dilation_from_ = std::min(dilation(), static_cast<double>(history - 1));
  dilation_steps_ = 0;
  dilation_target_ = history - 1;
  change_rate_ = growth > 0.0 ? growth / (static_cast<double>(time_to_dilate) * frame_rate) : 0.0;
  spec_.history = history;
  // A later restart dilates over the new history: keep its time if it still suffices.
  if (static_cast<double>(spec_.time_to_dilate) * frame_rate < history)
    spec_.time_to_dilate = 2.0f * static_cast<float>(history) / frame_rate;
}

void AnimStream::write(const Pose& pose, EventMask events, std::int32_t frame, std::vector<Mat3x4>& palette) {
  check_pose(pose, joints_, "streams." + spec_.name + ".controller");
  head_ = (head_ + 1) % spec_.history;
  palette.resize(static_cast<std::size_t>(joints_));
  kinematics_.palette(pose, palette.data());
  upload(rotations_, static_cast<Index>(head_) * joints_, pose.local.data(), joints_);
  upload(skinning_, static_cast<Index>(head_) * joints_, palette.data(), joints_);
  upload(roots_, head_, &pose.root, 1);
  upload(events_, head_, &events, 1);
  newest_ = frame;
  // D grows only from the second written frame on, so D <= written - 1.
  if (written_ > 0) ++dilation_steps_;
  written_ = std::min(written_ + 1, spec_.history);
}

// ---- StreamPool --------------------------------------------------------------------

StreamPool::StreamPool(float frame_rate, Memory memory) : frame_rate_(frame_rate), memory_(memory) {
  if (!(frame_rate >= 1.0f && frame_rate <= 1000.0f))
    throw Error("must be in [1, 1000] frames per second", at_field("frame_rate"));
}

std::int32_t StreamPool::add(const Rig& rig, std::int32_t rig_index, StreamSpec spec,
                             std::unique_ptr<Controller> controller) {
  spec.rig = rig_index;
  spec.validate(rig_index + 1, frame_rate_);
  if (spec.time_to_dilate == 0.0f) spec.time_to_dilate = 2.0f * static_cast<float>(spec.history) / frame_rate_;
  if (find(spec.name) >= 0) throw Error("stream name used twice", at_field("streams." + spec.name));
  const bool running = spec.running;
  streams_.push_back(std::make_unique<AnimStream>(rig, rig_index, std::move(spec), std::move(controller), memory_));
  if (running) streams_.back()->start(frame_rate_);
  refresh_views();
  return size() - 1;
}

std::int32_t StreamPool::find(const std::string& name) const {
  for (std::size_t i = 0; i < streams_.size(); ++i)
    if (streams_[i]->name() == name) return static_cast<std::int32_t>(i);
  return -1;
}

void StreamPool::start(std::int32_t stream) {
  if (stream < 0 || stream >= size()) throw Error("no stream " + std::to_string(stream), at_field("stream"));
  AnimStream& s = *streams_[static_cast<std::size_t>(stream)];
  if (s.state_ != StreamState::Running) s.start(frame_rate_);
  refresh_views();
}

void StreamPool::start_filled(std::int32_t stream, std::int32_t newest_frame) {
  if (stream < 0 || stream >= size()) throw Error("no stream " + std::to_string(stream), at_field("stream"));
  streams_[static_cast<std::size_t>(stream)]->fill(frame_rate_, newest_frame, scratch_, palette_scratch_);
  refresh_views();
}

void StreamPool::stop(std::int32_t stream) {
  if (stream < 0 || stream >= size()) throw Error("no stream " + std::to_string(stream), at_field("stream"));
  streams_[static_cast<std::size_t>(stream)]->state_ = StreamState::Stopped;
}

void StreamPool::set_history(std::int32_t stream, std::int32_t history, float time_to_dilate) {
  if (stream < 0 || stream >= size()) throw Error("no stream " + std::to_string(stream), at_field("stream"));
  streams_[static_cast<std::size_t>(stream)]->resize_history(history, time_to_dilate, frame_rate_);
  refresh_views();
}

void StreamPool::step(std::int32_t frame) {
  const float dt = 1.0f / frame_rate_;
  for (auto& sp : streams_) {
    AnimStream& s = *sp;
    if (s.state_ != StreamState::Running) continue;
    EventMask events = 0;
    // A (re)started stream shows its time-0 pose first, then advances.
    if (s.written_ > 0) s.controller_->advance(dt, s.parameters_, events);
    s.controller_->evaluate(scratch_);
    apply_root_motion(s.spec_.root, scratch_);
    s.write(scratch_, events, frame, palette_scratch_);
  }
  refresh_views();
}

std::size_t StreamPool::pose_bytes() const {
  std::size_t total = 0;
  for (const auto& s : streams_) total += s->pose_bytes();
  return total;
}

void StreamPool::refresh_views() {
  std::vector<SourceView> v;
  v.reserve(streams_.size());
  for (const auto& s : streams_) v.push_back(s->view());
  if (views_.size() != static_cast<Index>(v.size())) views_ = Buffer<SourceView>(static_cast<Index>(v.size()), memory_);
  upload(views_, 0, v.data(), static_cast<Index>(v.size()));
}

// ---- UniquePool ----------------------------------------------------------------------

UniquePool::UniquePool(float frame_rate, Memory memory) : frame_rate_(frame_rate), memory_(memory) {
  if (!(frame_rate >= 1.0f && frame_rate <= 1000.0f))
    throw Error("must be in [1, 1000] frames per second", at_field("frame_rate"));
}

void UniquePool::set_capacity(const Rig& rig, std::int32_t rig_index, std::int32_t capacity) {
  const std::string at = "unique.capacity." + rig.name;
  if (capacity < 0 || capacity > (1 << 24)) throw Error("must be in [0, 2^24]", at_field(at));
  for (const Slab& s : slabs_)
    if (s.rig == rig_index) throw Error("capacity of this rig already set", at_field(at));
  Slab slab;
  slab.rig = rig_index;
  slab.joints = rig.joint_count();
  slab.first_instance = instance_count();
  slab.capacity = capacity;
  slab.kinematics = rig.kinematics();
  slab.rotations = Buffer<glm::quat>(static_cast<Index>(capacity) * slab.joints, memory_);
  slab.skinning = Buffer<Mat3x4>(static_cast<Index>(capacity) * slab.joints, memory_);
  slab.roots = Buffer<glm::vec3>(capacity, memory_);
  slab.events = Buffer<std::uint32_t>::zeros(capacity, memory_);
  const Pose rest = rig.rest_pose();
  std::vector<Mat3x4> palette(static_cast<std::size_t>(slab.joints));
  slab.kinematics.palette(rest, palette.data());
  for (std::int32_t k = 0; k < capacity; ++k) {
    upload(slab.rotations, static_cast<Index>(k) * slab.joints, rest.local.data(), slab.joints);
    upload(slab.skinning, static_cast<Index>(k) * slab.joints, palette.data(), slab.joints);
    upload(slab.roots, k, &rest.root, 1);
    Instance inst;
    inst.slab = static_cast<std::int32_t>(slabs_.size());
    inst.slot = k;
    instances_.push_back(std::move(inst));
  }
  slabs_.push_back(std::move(slab));
  refresh_views();
}

std::int32_t UniquePool::capacity(std::int32_t rig_index) const {
  for (const Slab& s : slabs_)
    if (s.rig == rig_index) return s.capacity;
  return 0;
}

std::int32_t UniquePool::add_animation(UniqueAnimation animation) {
  const std::string at = "unique.animations." + animation.name;
  if (animation.name.empty()) throw Error("a unique animation needs a name", at_field("unique.animations"));
  if (find_animation(animation.name) >= 0) throw Error("name used twice", at_field(at));
  if (!animation.controller) throw Error("needs a controller", at_field(at + ".controller"));
  const Slab* slab = nullptr;
  for (const Slab& s : slabs_)
    if (s.rig == animation.rig) slab = &s;
  if (slab == nullptr) throw Error("the unique pool has no capacity for this animation's rig", at_field(at + ".rig"));
  if (animation.controller->joint_count() != slab->joints)
    throw Error("controller has " + std::to_string(animation.controller->joint_count()) + " joints, the rig " +
                    std::to_string(slab->joints),
                at_field(at + ".controller"));
  animations_.push_back(std::move(animation));
  return animation_count() - 1;
}

std::int32_t UniquePool::find_animation(const std::string& name) const {
  for (std::size_t i = 0; i < animations_.size(); ++i)
    if (animations_[i].name == name) return static_cast<std::int32_t>(i);
  return -1;
}

std::int32_t UniquePool::acquire(std::int32_t animation) {
  if (animation < 0 || animation >= animation_count())
    throw Error("no unique animation " + std::to_string(animation), at_field("animation"));
  const UniqueAnimation& a = animations_[static_cast<std::size_t>(animation)];
  for (const Slab& s : slabs_) {
    if (s.rig != a.rig) continue;
    for (std::int32_t k = 0; k < s.capacity; ++k) {
      Instance& inst = instances_[static_cast<std::size_t>(s.first_instance + k)];
      if (inst.animation >= 0) continue;
      inst.animation = animation;
      inst.controller = a.controller->clone();
      inst.controller->reset();
      inst.parameters = ParameterSet();
      inst.newest = -1;
      return s.first_instance + k;
    }
    throw Error(
        "the unique pool of rig " + std::to_string(a.rig) + " is full (" + std::to_string(s.capacity) + " instances)",
        at_field("unique.capacity"));
  }
  throw Error("no capacity for the animation's rig", at_field("unique.capacity"));
}

void UniquePool::release(std::int32_t instance) {
  if (!active(instance)) return;
  Instance& inst = instances_[static_cast<std::size_t>(instance)];
  inst.animation = -1;
  inst.controller.reset();
}

bool UniquePool::active(std::int32_t instance) const {
  return instance >= 0 && instance < instance_count() && instances_[static_cast<std::size_t>(instance)].animation >= 0;
}

std::int32_t UniquePool::active_count() const {
  return static_cast<std::int32_t>(
      std::count_if(instances_.begin(), instances_.end(), [](const Instance& i) { return i.animation >= 0; }));
}

const Controller* UniquePool::controller(std::int32_t instance) const {
  return active(instance) ? instances_[static_cast<std::size_t>(instance)].controller.get() : nullptr;
}

ParameterSet& UniquePool::parameters(std::int32_t instance) {
  if (!active(instance))
    throw Error("unique instance " + std::to_string(instance) + " is not active", at_field("instance"));
  return instances_[static_cast<std::size_t>(instance)].parameters;
}

void UniquePool::step(std::int32_t frame) {
  const float dt = 1.0f / frame_rate_;
  for (Instance& inst : instances_) {
    if (inst.animation < 0) continue;
    Slab& slab = slabs_[static_cast<std::size_t>(inst.slab)];
    EventMask events = 0;
    // A new instance shows its time-0 pose first, then advances.
    if (inst.newest >= 0) inst.controller->advance(dt, inst.parameters, events);
    inst.controller->evaluate(scratch_);
    check_pose(scratch_, slab.joints,
               "unique.animations." + animations_[static_cast<std::size_t>(inst.animation)].name);
    apply_root_motion(animations_[static_cast<std::size_t>(inst.animation)].root, scratch_);
    palette_scratch_.resize(static_cast<std::size_t>(slab.joints));
    slab.kinematics.palette(scratch_, palette_scratch_.data());
    upload(slab.rotations, static_cast<Index>(inst.slot) * slab.joints, scratch_.local.data(), slab.joints);
    upload(slab.skinning, static_cast<Index>(inst.slot) * slab.joints, palette_scratch_.data(), slab.joints);
    upload(slab.roots, inst.slot, &scratch_.root, 1);
    upload(slab.events, inst.slot, &events, 1);
    inst.newest = frame;
  }
  refresh_views();
}

std::size_t UniquePool::pose_bytes() const {
  std::size_t total = 0;
  for (const Slab& s : slabs_) total += static_cast<std::size_t>(s.capacity) * pose_slot_bytes(s.joints);
  return total;
}

void UniquePool::refresh_views() {
  std::vector<SourceView> v(instances_.size());
  for (std::size_t i = 0; i < instances_.size(); ++i) {
    const Instance& inst = instances_[i];
    const Slab& s = slabs_[static_cast<std::size_t>(inst.slab)];
    SourceView& w = v[i];
    w.rotations = s.rotations.data() + static_cast<Index>(inst.slot) * s.joints;
    w.skinning = s.skinning.data() + static_cast<Index>(inst.slot) * s.joints;
    w.roots = s.roots.data() + inst.slot;
    w.events = s.events.data() + inst.slot;
    w.joints = s.joints;
    w.history = 1;
    w.head = 0;
    w.newest = inst.animation >= 0 ? inst.newest : -1;
    w.max_offset = 0;
    w.rig = s.rig;
  }
  if (views_.size() != static_cast<Index>(v.size())) views_ = Buffer<SourceView>(static_cast<Index>(v.size()), memory_);
  upload(views_, 0, v.data(), static_cast<Index>(v.size()));
}

}  // namespace throng::anim
