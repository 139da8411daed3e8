// Animation streams: shared pose histories that many agents read at their
// own offsets (the "skeletal animation for massive crowds" method).
//
// An AnimStream is defined over a rig (skeleton + mesh binding). While it
// runs, its controller writes the pose P once per animation frame into the
// head slot of its history ring PH of the last M poses: P *is* the head slot,
// so pose storage is not duplicated. A Stopped stream keeps its history
// (agents reading it hold still). Streams of different rigs keep poses of
// their own joint count: nothing is padded to the largest skeleton.
//
// When a stream starts, its history holds one pose; agents' offsets may not
// exceed what has been written. Time dilation: the largest readable offset D
// grows from M to M_new - 1 at changeRate = (M_new - M) / (timeToDilate *
// animFrameRate) slots per frame; an agent reads min(its offset, floor(D)).
// changeRate <= 1 is required (the history grows by one slot per frame), so
// timeToDilate >= (M_new - M) / animFrameRate.
//
// The UniquePool holds per-agent animations (a wave, a fall) that are not
// shared: each instance is a controller and a one-slot history, allocated
// per rig from a fixed capacity.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "anim/controller.h"
#include "anim/pose.h"
#include "anim/rig.h"
#include "core/buffer.h"
#include "core/config.h"

namespace throng::anim {

// What kernels read of one pose source (a stream or a unique instance).
// Slot k holds joints local rotations at rotations[k * joints], the root at
// roots[k], the events fired when it was written at events[k], and the
// pose's model-space skinning palette (model_j * inverse_bind_j, computed
// once when the slot is written) at skinning[k * joints].
struct SourceView {
  const glm::quat* rotations = nullptr;
  const Mat3x4* skinning = nullptr;
  const glm::vec3* roots = nullptr;
  const std::uint32_t* events = nullptr;
  std::int32_t joints = 0;
  std::int32_t history = 1;     // M
  std::int32_t head = 0;        // slot of the newest pose (P)
  std::int32_t newest = -1;     // frame number written into the head slot; -1 before the first
  std::int32_t max_offset = 0;  // floor(D): the largest offset agents may read now
  std::int32_t rig = 0;
};

// The slot an agent with this offset reads (offset 0 = newest).
THRONG_HOST_DEVICE inline std::int32_t history_slot(const SourceView& s, std::int32_t offset) {
  std::int32_t o = offset < s.max_offset ? offset : s.max_offset;
  o = o < 0 ? 0 : o;
  const std::int32_t slot = (s.head - o) % s.history;
  return slot < 0 ? slot + s.history : slot;
}
THRONG_HOST_DEVICE inline std::int32_t effective_offset(const SourceView& s, std::int32_t offset) {
  const std::int32_t o = offset < s.max_offset ? offset : s.max_offset;
  return o < 0 ? 0 : o;
}

enum class StreamState : std::uint8_t { Stopped, Running };
const char* to_string(StreamState s);

// The stream's root controller: what happens to the controller's root position.
enum class RootMotion : std::uint8_t {
  InPlace,  // horizontal (x, z) root translation removed, height kept: the agent's transform moves it
  Keep,     // as the controller wrote it
};
const char* to_string(RootMotion r);

struct StreamSpec {
  std::string name;
  std::int32_t rig = 0;
  std::int32_t history = 64;  // M, slots
  RootMotion root = RootMotion::InPlace;
  // Seconds for offsets to spread after a start; 0 picks 2 * history /
  // frame_rate (agents play at half speed while their offsets spread).
  float time_to_dilate = 0.0f;
  bool running = true;                                            // started when added
  void validate(std::int32_t rig_count, float frame_rate) const;  // Error naming "streams.<name>.<field>"
};

class AnimStream {
 public:
  AnimStream(const Rig& rig, std::int32_t rig_index, StreamSpec spec, std::unique_ptr<Controller> controller,
             Memory memory);

  const std::string& name() const { return spec_.name; }
  const StreamSpec& spec() const { return spec_; }
  std::int32_t rig() const { return spec_.rig; }
  std::int32_t joint_count() const { return joints_; }
  std::int32_t history() const { return spec_.history; }
  StreamState state() const { return state_; }
  Controller& controller() { return *controller_; }
  const Controller& controller() const { return *controller_; }
  ParameterSet& parameters() { return parameters_; }
  const ParameterSet& parameters() const { return parameters_; }

  std::int32_t head() const { return head_; }
  std::int32_t newest_frame() const { return newest_; }
  std::int32_t written() const { return written_; }    // slots written since the last start, <= M
  double dilation() const;                             // D
  double change_rate() const { return change_rate_; }  // slots per frame while dilating
  std::int32_t max_offset() const;

  // Bytes of pose history (local rotations, skinning palettes and roots):
  // M * (J * (16 + 48) + 12).
  std::size_t pose_bytes() const;
  // A copy of the pose at an offset (0 = P) from the history, for tests and tools.
  Pose pose_at(std::int32_t offset) const;
  EventMask events_at(std::int32_t offset) const;
  SourceView view() const;

 private:
  friend class StreamPool;
  void start(float frame_rate);
  void fill(float frame_rate, std::int32_t newest_frame, Pose& scratch, std::vector<Mat3x4>& palette_scratch);
  void resize_history(std::int32_t history, float time_to_dilate, float frame_rate);
  void write(const Pose& pose, EventMask events, std::int32_t frame, std::vector<Mat3x4>& palette_scratch);

  StreamSpec spec_;
  std::int32_t joints_ = 0;
  std::unique_ptr<Controller> controller_;
  ParameterSet parameters_;
  StreamState state_ = StreamState::Stopped;
  PoseKinematics kinematics_;
  Buffer<glm::quat> rotations_;   // M * J
  Buffer<Mat3x4> skinning_;       // M * J
  Buffer<glm::vec3> roots_;       // M
  Buffer<std::uint32_t> events_;  // M
  std::int32_t head_ = 0;
  std::int32_t newest_ = -1;
  std::int32_t written_ = 0;
  // D = min(dilation_from_ + dilation_steps_ * change_rate_, dilation_target_):
  // counted, not accumulated, so floor(D) has no drift.
  double dilation_from_ = 0.0;
  std::int64_t dilation_steps_ = 0;
  double dilation_target_ = 0.0;
  double change_rate_ = 0.0;
};

class StreamPool {
 public:
  explicit StreamPool(float frame_rate = 30.0f, Memory memory = current_memory());

  float frame_rate() const { return frame_rate_; }
  // Adds a stream (started when spec.running); returns its index.
  std::int32_t add(const Rig& rig, std::int32_t rig_index, StreamSpec spec, std::unique_ptr<Controller> controller);
  std::int32_t size() const { return static_cast<std::int32_t>(streams_.size()); }
  AnimStream& operator[](std::int32_t i) { return *streams_[static_cast<std::size_t>(i)]; }
  const AnimStream& operator[](std::int32_t i) const { return *streams_[static_cast<std::size_t>(i)]; }
  std::int32_t find(const std::string& name) const;  // -1 when absent

  // Stopped -> Running: the controller restarts from time 0, the history
  // counts as empty and offsets dilate again from 0. Running stays running.
  void start(std::int32_t stream);
  // (Re)starts a stream with its whole history written at once: the
  // controller plays from time 0 for M frames, the newest being frame
  // `newest_frame` (the crowd's last stepped frame, so that the next step
  // writes newest_frame + 1), and agents may read any offset at once (no
  // dilation). For controllers whose past is as good as their present: a
  // locomotion cycle at a fixed speed, started when agents need it.
  void start_filled(std::int32_t stream, std::int32_t newest_frame);
  void stop(std::int32_t stream);
  // Changes M at run time: kept slots keep their offsets; growing dilates
  // from the current D at (M_new - M) / (time_to_dilate * frame_rate)
  // (time_to_dilate 0: two frames per slot).
  void set_history(std::int32_t stream, std::int32_t history, float time_to_dilate);

  // One animation frame: every running stream's controller advances by
  // 1 / frame_rate and writes P (its new head) as frame `frame`.
  void step(std::int32_t frame);

  std::size_t pose_bytes() const;  // sum over streams
  // Every stream's view, in stream order, in the pool's memory; refreshed by step().
  Span<const SourceView> views() const { return views_.span(); }
  void refresh_views();

 private:
  float frame_rate_;
  Memory memory_;
  std::vector<std::unique_ptr<AnimStream>> streams_;
  Buffer<SourceView> views_;
  Pose scratch_;
  std::vector<Mat3x4> palette_scratch_;
};

// Bytes a source of J joints keeps per history slot.
inline std::size_t pose_slot_bytes(std::int32_t joints) {
  return static_cast<std::size_t>(joints) * (sizeof(glm::quat) + sizeof(Mat3x4)) + sizeof(glm::vec3);
}

// A per-agent animation: a template controller cloned for every instance.
struct UniqueAnimation {
  std::string name;
  std::int32_t rig = 0;
  std::unique_ptr<Controller> controller;
  RootMotion root = RootMotion::InPlace;
};

class UniquePool {
 public:
  explicit UniquePool(float frame_rate = 30.0f, Memory memory = current_memory());

  // How many instances each rig may have at once (allocates their slots).
  void set_capacity(const Rig& rig, std::int32_t rig_index, std::int32_t capacity);
  std::int32_t capacity(std::int32_t rig_index) const;
  std::int32_t add_animation(UniqueAnimation animation);  // index; Error for a rig without capacity set
  std::int32_t animation_count() const { return static_cast<std::int32_t>(animations_.size()); }
  const UniqueAnimation& animation(std::int32_t i) const { return animations_[static_cast<std::size_t>(i)]; }
  std::int32_t find_animation(const std::string& name) const;

  // A fresh instance of an animation (its controller at time 0, evaluated
  // at the next step); Error when the rig's capacity is used up.
  std::int32_t acquire(std::int32_t animation);
  void release(std::int32_t instance);
  bool active(std::int32_t instance) const;
  std::int32_t active_count() const;
  std::int32_t instance_count() const { return static_cast<std::int32_t>(instances_.size()); }  // all slots
  const Controller* controller(std::int32_t instance) const;
  ParameterSet& parameters(std::int32_t instance);

  void step(std::int32_t frame);
  std::size_t pose_bytes() const;
  Span<const SourceView> views() const { return views_.span(); }
  void refresh_views();

 private:
  struct Slab {
    std::int32_t rig = -1;
    std::int32_t joints = 0;
    std::int32_t first_instance = 0;
    std::int32_t capacity = 0;
    PoseKinematics kinematics;
    Buffer<glm::quat> rotations;
    Buffer<Mat3x4> skinning;
    Buffer<glm::vec3> roots;
    Buffer<std::uint32_t> events;
  };
  struct Instance {
    std::int32_t slab = 0;
    std::int32_t slot = 0;
    std::int32_t animation = -1;  // -1 when free
    std::int32_t newest = -1;
    std::unique_ptr<Controller> controller;
    ParameterSet parameters;
  };
  float frame_rate_;
  Memory memory_;
  std::vector<Slab> slabs_;
  std::vector<Instance> instances_;
  std::vector<UniqueAnimation> animations_;
  Buffer<SourceView> views_;
  Pose scratch_;
  std::vector<Mat3x4> palette_scratch_;
};

}  // namespace throng::anim
