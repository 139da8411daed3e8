// The locomotion and pose stages for N characters (frame stages 5 to 7):
// speed -> blend and phase, root motion (Eq. 10), pixel-coverage joint LOD,
// the speed-keyed motion cache, and per-character synthesis of the joints
// that LOD keeps, written as world transforms for the renderer.
//
// The per-character work is motion/locomotion.h's; here it runs as
// parallel_for kernels over structure-of-arrays spans (crowd_animator_kernels.cpp,
// CUDA-compatible), and CrowdAnimator owns the buffers and runs a frame:
//
//   const motion::BlendSpace1D space = motion::make_default_blend_space();
//   CrowdAnimator crowd(space, n);                 // buffers, LOD tables, cache
//   crowd.place(positions, yaws, scales, phases);  // once
//   crowd.set_speeds(speeds);                      // any frame
//   crowd.animate({dt, &camera});                  // one frame, all characters
//   crowd.joint_positions(), crowd.joint_rotations()  // [c * J + j], world
//
// Driven by the simulation instead: crowd.drive_from_map(positions,
// velocities, headings) (map coordinates, core/ground.h), then animate with
// integrate_root = false. Output layout and memory: docs/locomotion.md.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <span>
#include <vector>

#include "anim/foot_lock.h"
#include "anim/lod.h"
#include "anim/motion_cache.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "core/span.h"
#include "motion/foot_skating.h"
#include "motion/locomotion.h"

namespace throng::anim {

// Stage 5: speed -> blend, phase advance, root motion, per character.
struct LocomoteJob {
  motion::BlendSpaceView blend;
  motion::LocomotionStep step;
  Span<const float> speeds;      // m/s to show (world)
  Span<const float> turn_rates;  // rad/s, + = left; empty = 0
  Span<const float> curvatures;  // rad per metre travelled; empty = 0
  Span<const float> scales;      // empty = 1
  Span<glm::vec3> positions;     // in/out: world, on the ground (the path point)
  Span<float> yaws;              // in/out: radians about +Y
  Span<float> phases;            // in/out: [0, 1)
  Span<float> blend_speeds;      // in/out: the speed the blend shows (scale 1); < 0 = unset

  Index character_count() const { return positions.size(); }
  void validate() const;  // Error naming the span whose size is wrong
  void run() const;       // parallel_for "anim.locomote"
};

// The simulation's agents (map: ground x, y; headings CCW from +x) as
// world root positions, yaws and speeds (|velocity|), core/ground.h.
struct MapInputJob {
  Span<const glm::vec2> map_positions;
  Span<const glm::vec2> map_velocities;
  Span<const float> map_headings;
  Span<glm::vec3> positions;
  Span<float> yaws;
  Span<float> speeds;

  Index character_count() const { return map_positions.size(); }
  void validate() const;
  void run() const;  // parallel_for "anim.from_map"
};

// The motion cache's device side as PoseJob reads it (CycleCacheTable::view()).
struct CycleCacheView {
  Span<const std::int32_t> slots;  // per key (segment * bucket_count + bucket): slot or -1; empty = no cache
  Span<const glm::quat> cycles;    // slots * frames * J local rotations
  Span<const float> drops;         // slots * frames pelvis drops (m, scale 1)
  std::int32_t frames = 0;
  float bucket_width = 0.05f;
  std::int32_t bucket_count = 20;
};

// Characters as PoseJob poses them: root on the ground, heading (radians
// about +Y), size (scales, or empty for 1), gait phase and the speed the
// blend shows.
struct CharacterGait {
  Span<const glm::vec3> positions;
  Span<const float> yaws, scales, phases, blend_speeds;
};

// Stage 7: the pose of every character in world space. Joints whose mask bit
// is off are not synthesised (no sampling, no SLERP): they hold the mean
// rotation of the clip with the larger weight. A character whose cache key
// has a slot reads that cached cycle at its phase instead of synthesising.
// Its characters are the CharacterGait it derives from (positions, yaws,
// scales, phases, blend_speeds).
struct PoseJob : CharacterGait {
  motion::BlendSpaceView blend;
  Span<const std::uint32_t> joint_masks;  // characters * mask_word_count(J); empty = every joint
  CycleCacheView cache;                   // empty slots = no cache
  // J = F * O (optional): per joint the fixed bone-aligned shape F (joint_shapes).
  Span<const glm::mat4x3> joint_shapes;
  // Outputs, character-major [c * J + j].
  Span<glm::vec3> joint_positions;
  Span<glm::quat> joint_rotations;
  Span<glm::mat4x3> draw_matrices;  // optional, with joint_shapes
  Span<std::int32_t> evaluated;     // optional, per character: joints synthesised
  Span<std::uint8_t> from_cache;    // optional, per character: 1 = read the cache
  // Foot locking (anim/foot_lock.h) right after each pose, before its draw
  // matrices, as FootLockJob over the same characters would: optional,
  // empty locks = feet as posed.
  Span<FootLock> locks;  // in/out: characters * 2 (left, right)
  FootLockConfig lock_config;
  float lock_dt = 0.0f;  // s since the last frame

  Index character_count() const { return positions.size(); }
  void validate() const;
  void run() const;  // parallel_for "anim.pose"
};

// The PoseJob of every joint of these characters (no LOD masks, no cache,
// no draw matrices): what each pose source of the locomotion layer starts
// from.
PoseJob make_pose_job(const motion::BlendSpaceView& blend, const CharacterGait& gait, Span<glm::vec3> joint_positions,
                      Span<glm::quat> joint_rotations);

// Sums of PoseJob's per-character counters (deterministic).
struct PoseTotals {
  Index joints_synthesised = 0;
  Index from_cache = 0;
};
PoseTotals pose_totals(Span<const std::int32_t> evaluated, Span<const std::uint8_t> from_cache);

// The cache key of a blend: segment * bucket_count + bucket of w.
THRONG_HOST_DEVICE inline std::int32_t cache_key(const motion::BlendPoint& p, float bucket_width,
                                                 std::int32_t bucket_count) {
  return p.segment * bucket_count + cache_bucket(p.w, bucket_width, bucket_count);
}

// Characters per cache key this frame (deterministic counts), from their
// blend speeds: keys = segment_count * bucket_count entries.
std::vector<Index> cache_key_counts(const motion::BlendSpaceView& blend, Span<const float> blend_speeds,
                                    float bucket_width, std::int32_t bucket_count);

// Per joint the paper's F: a unit sphere squashed into an ellipsoid along the
// bone to the joint's children (their mean offset, or its end site): centre
// at mid-bone, half-length along the bone, radius `thickness` times the bone
// length (at least min_radius). J = O * F with O the joint's world transform
// (draw_matrix). A leaf without end site gets a sphere of min_radius.
std::vector<glm::mat4x3> joint_shapes(const motion::Skeleton& skeleton, float thickness = 0.18f,
                                      float min_radius = 0.02f);

// O * F for a joint at world position p, rotation q, uniform scale s.
THRONG_HOST_DEVICE inline glm::mat4x3 draw_matrix(const glm::vec3& p, const glm::quat& q, float s,
                                                  const glm::mat4x3& shape) {
  const glm::mat3 r = glm::mat3_cast(q) * s;
  glm::mat4x3 out;
  for (int c = 0; c < 3; ++c) out[c] = r * shape[c];
  out[3] = r * shape[3] + p;
  return out;
}

// One character's J draw matrices from its world joints.
THRONG_HOST_DEVICE inline void character_draw_matrices(std::int32_t J, const glm::vec3* p, const glm::quat* q, float s,
                                                       const glm::mat4x3* shapes, glm::mat4x3* out) {
  for (std::int32_t j = 0; j < J; ++j) out[j] = draw_matrix(p[j], q[j], s, shapes[j]);
}

// The motion cache with a device mirror: MotionCache (motion_cache.h) keeps
// keys, FIFO order, byte capacity and counters; the table keeps each held
// cycle in a slot of one device buffer, and a slot per key, for PoseJob.
// Cycles are frames x joints local rotations at the bucket's centre w,
// synthesised exactly as per-character synthesis (leg IK included).
// Frames per cached cycle by default: 60 per second of the longest moving
// clip's period (idle blends take the walk's period; 75 for the default set).
inline constexpr double kCacheSamplesPerSecond = 60.0;
std::int32_t default_cache_frames(const motion::BlendSpace1D& space);

class CycleCacheTable {
 public:
  // frames: per cached cycle; 0 = default_cache_frames(space).
  CycleCacheTable(const motion::BlendSpace1D& space, MotionCacheConfig config, std::int32_t frames = 0);

  const MotionCache& cache() const { return cache_; }
  std::int32_t frames() const { return frames_; }
  std::int32_t key_count() const { return key_count_; }
  std::int32_t slot_count() const { return slot_count_; }
  std::int32_t bucket_count() const { return cache_.bucket_count(); }
  float bucket_width() const { return cache_.config().bucket_width; }
  Span<const std::int32_t> slots() const { return slots_.span(); }
  Span<const glm::quat> cycles() const { return cycles_.span(); }
  Span<const float> drops() const { return drops_.span(); }
  CycleCacheView view() const { return {slots(), cycles(), drops(), frames(), bucket_width(), bucket_count()}; }

  // One frame: counts[key] characters look their key up (hits and misses
  // count characters); up to max_new missing cycles are synthesised and
  // stored (FIFO evictions free their slots). Returns how many were stored.
  std::int32_t update(const std::vector<Index>& counts, std::int32_t max_new);
  // The cycle of a key, synthesised (host), for tests and the table; with
  // drops, also the pelvis drop of each frame (motion::PlantedLegs).
  CachedCycle synthesise(std::int32_t segment, float w, std::vector<float>* drops = nullptr) const;
  // Angle between a cached read and per-character synthesis over a grid of
  // w and phases in every segment: what caching costs.
  QuantisationError quantisation_error(std::int32_t w_samples = 41, std::int32_t phase_samples = 48) const;
  void reset_counters() { cache_.reset_counters(); }

 private:
  const motion::BlendSpace1D* space_;
  MotionCache cache_;
  std::int32_t frames_ = 0;
  std::int32_t key_count_ = 0;
  std::int32_t slot_count_ = 0;
  std::vector<std::int32_t> host_slots_;  // per key
  std::vector<std::int32_t> free_slots_;
  Buffer<std::int32_t> slots_;
  Buffer<glm::quat> cycles_;
  Buffer<float> drops_;
};

struct CrowdAnimatorConfig {
  bool hold_until_cycle_end = false;  // the paper's mode; default continuous
  bool lod = true;                    // pixel-coverage joint LOD (needs a camera per frame)
  std::vector<float> lod_thresholds = default_lod_thresholds();
  bool cache = true;
  MotionCacheConfig cache_config;
  std::int32_t cache_frames = 0;  // per cached cycle; 0 = default_cache_frames
  std::int32_t max_new_cycles_per_frame = 16;
  bool draw_matrices = false;  // also write J = F * O (48 bytes per joint)
  // Planted feet stay where they landed (anim/foot_lock.h), after the pose.
  bool foot_lock = true;
  FootLockConfig foot_lock_config;
  void validate() const;
};

struct FrameInput {
  float dt = 1.0f / 60.0f;
  const Camera* camera = nullptr;  // null: every joint synthesised
  bool integrate_root = true;      // false after drive_from_map
};

struct FrameStats {
  Index characters = 0;
  Index joints_synthesised = 0;  // sum over characters (LOD)
  Index from_cache = 0;          // characters that read a cached cycle
  std::int32_t cycles_stored = 0;
  std::optional<LodHistogram> lod;  // when LOD ran
  MotionCacheStats cache;           // cumulative
};

// Everything one crowd needs, per frame: LocomoteJob, LodJob, the cache
// update, PoseJob (feet locked in it). Buffers live in current_memory().
class CrowdAnimator {
 public:
  CrowdAnimator(const motion::BlendSpace1D& space, Index count, CrowdAnimatorConfig config = {});

  Index count() const { return count_; }
  std::int32_t joint_count() const { return joints_; }
  const motion::BlendSpace1D& blend_space() const { return *space_; }
  const CrowdAnimatorConfig& config() const { return config_; }

  // Initial state from host arrays (count entries each; empty scales = 1,
  // empty phases = 0). Yaws in radians about +Y (core/ground.h).
  void place(std::span<const glm::vec3> positions, std::span<const float> yaws, std::span<const float> scales = {},
             std::span<const float> phases = {});
  // Inputs from host arrays (count entries each).
  void set_speeds(std::span<const float> speeds);
  void set_turn_rates(std::span<const float> turn_rates);
  void set_curvatures(std::span<const float> curvatures);
  // Inputs from device spans of the simulation's arrays (map coordinates).
  void drive_from_map(Span<const glm::vec2> positions, Span<const glm::vec2> velocities, Span<const float> headings);

  const FrameStats& animate(const FrameInput& input);
  const FrameStats& last_frame() const { return stats_; }

  // State and outputs (current_memory()).
  Span<const FootLock> foot_locks() const { return locks_.span(); }  // [c * 2 + leg]; empty without foot_lock
  Span<const glm::vec3> positions() const { return position_.span(); }
  Span<const float> yaws() const { return yaw_.span(); }
  Span<const float> phases() const { return phase_.span(); }
  Span<const float> blend_speeds() const { return blend_speed_.span(); }
  Span<const float> scales() const { return scale_.span(); }
  Span<float> speeds() { return speed_.span(); }
  Span<const glm::vec3> joint_positions() const { return joint_position_.span(); }
  Span<const glm::quat> joint_rotations() const { return joint_rotation_.span(); }
  Span<const glm::mat4x3> draw_matrices() const { return draw_.span(); }
  Span<const std::int32_t> evaluated() const { return evaluated_.span(); }
  Span<const std::uint32_t> joint_masks() const { return masks_.span(); }
  // Joint-LOD level per character and body part (characters * 5, LodJob's
  // layout); empty without LOD. Written by animate() when given a camera.
  Span<const std::uint8_t> lod_levels() const { return levels_.span(); }
  const LodConfig* lod_config() const { return lod_config_ ? &*lod_config_ : nullptr; }
  // New joint-LOD thresholds from the next frame on (a viewer's sliders);
  // same rules as CrowdAnimatorConfig::lod_thresholds. Needs config().lod.
  void set_lod_thresholds(const std::vector<float>& thresholds);
  const CycleCacheTable* cache() const { return cache_ ? &*cache_ : nullptr; }

  // Foot skating of some characters: their world joints are recorded every
  // frame from now on; foot_skating() measures contacts over what was recorded.
  void track(std::vector<Index> characters);
  motion::FootSkatingReport foot_skating(const motion::ContactOptions& options = {}) const;

 private:
  const motion::BlendSpace1D* space_;
  CrowdAnimatorConfig config_;
  Index count_ = 0;
  std::int32_t joints_ = 0;
  motion::BlendSpaceTables tables_;
  Buffer<glm::vec3> position_;
  Buffer<float> yaw_, scale_, phase_, blend_speed_, speed_, turn_rate_, curvature_;
  Buffer<glm::vec3> joint_position_;
  Buffer<glm::quat> joint_rotation_;
  Buffer<glm::mat4x3> draw_;
  Buffer<glm::mat4x3> shapes_;
  Buffer<std::int32_t> evaluated_;
  Buffer<std::uint8_t> from_cache_;
  Buffer<std::uint8_t> levels_;
  Buffer<std::uint32_t> masks_;
  Buffer<FootLock> locks_;  // characters * 2, with config.foot_lock
  std::optional<BodyParts> parts_;
  std::optional<LodConfig> lod_config_;
  std::optional<LodTables> lod_tables_;
  std::optional<CycleCacheTable> cache_;
  FrameStats stats_;
  // Foot-skating probe.
  motion::FootSkatingRecorder skating_;
  float track_dt_ = 0.0f;
};

}  // namespace throng::anim
