// The 1D locomotion blend space (host, once): BlendSpace1D sorts prepared
// clips (motion/locomotion_clip.h) by speed and packs them into one motion
// texture plus the small tables that per-frame code reads through a
// BlendSpaceView: per-clip speed, stride, turn and period, foot-event sync
// markers per pair of neighbouring clips, each joint's sync group, mean
// rotations, and the leg chains of the foot-planting IK (motion/leg_ik.h).
// BlendSpaceTables puts the tables in device memory.
#pragma once

#include <array>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "core/buffer.h"
#include "core/config.h"
#include "motion/clip.h"
#include "motion/locomotion_clip.h"
#include "motion/motion_texture.h"
#include "motion/skeleton.h"

namespace throng::motion {

// ---------------------------------------------------------------------------
// Tables shared by host and device code

inline constexpr int kMaxSyncMarkers = 4;

// Phases in clip a and in clip b that a blend of the two aligns: foot
// events both clips have, in the same cyclic order. Stored unwrapped from
// the first: a[0] <= a[k] < a[0] + 1 increasing (b likewise). The canonical
// phase of marker k at weight w is a[k] + w (b[k] - a[k]); between markers
// each clip's phase follows linearly (circularly, marker count wraps to 0).
// count 1 with a[0] = b[0] = 0: no warp.
struct SyncMarkers {
  std::int32_t count = 1;
  float a[kMaxSyncMarkers] = {0.0f, 0.0f, 0.0f, 0.0f};
  float b[kMaxSyncMarkers] = {0.0f, 0.0f, 0.0f, 0.0f};
};

// Three warps per pair of clips. The body (root, spine, arms) aligns the
// touchdowns, so its phase stays the cycle's; each leg (the thigh's subtree)
// aligns its own touchdown and liftoff, so that a foot is down in the blend
// exactly when it is down in both clips. Walks blended with walks align all
// four events everywhere (the three warps agree); a walk blended with a run
// cannot align both feet's liftoffs with one warp (double support against
// flight puts them in a different order), hence one per leg.
inline constexpr int kSyncGroups = 3;  // body, left leg, right leg
struct SegmentSync {
  SyncMarkers group[kSyncGroups];
};
SegmentSync sync_markers(const LocomotionClip& a, const LocomotionClip& b);

// The joints from the skeleton root down to one ankle (thigh, knee, ankle
// last), for the leg IK that plants the feet of a blend; count 0 = none.
inline constexpr int kMaxLegChain = 8;
struct LegChain {
  std::int32_t count = 0;
  std::int32_t joints[kMaxLegChain] = {};
  float ball[3] = {0.0f, 0.0f, 0.0f};  // ball of the foot in the ankle's frame (toe joint or end site)
  bool has_ball = false;
  // The knee's hinge in the thigh's frame: the axis it bends about (the
  // IK bends the knee the same way as the clips do, even from straight).
  float hinge[3] = {1.0f, 0.0f, 0.0f};
};

// The knee's hinge in the thigh's frame from clips' knee rotations: the mean
// of thigh x shin over their frames, weighted by how much the knee bends.
glm::vec3 knee_hinge(const glm::vec3& knee_offset, const glm::vec3& ankle_offset, const std::vector<const Clip*>& clips,
                     std::int32_t knee);

struct ClipInfo {
  std::int32_t first_row = 0;            // of the clip's frames in the stacked texture
  std::int32_t rows = 0;                 // frames per cycle
  float speed = 0.0f;                    // m/s at scale 1
  float stride = 0.0f;                   // m per cycle
  float turn = 0.0f;                     // rad per cycle
  float period = 1.0f;                   // s per cycle
  float ankle_ground[2] = {0.0f, 0.0f};  // lowest ankle heights (m)
  // Per leg, the phases of its touchdown and lift-off (the clip's foot
  // events); -1 where the clip has none (idle: both feet stay down).
  float contact[2][2] = {{-1.0f, -1.0f}, {-1.0f, -1.0f}};
};

// What per-character code reads, by pointer (host or device memory).
struct BlendSpaceView {
  std::int32_t joint_count = 0;
  std::int32_t clip_count = 0;
  MotionTextureView texture;                  // every clip's cycle, stacked by rows
  const ClipInfo* clips = nullptr;            // clip_count, by increasing speed
  const SegmentSync* sync = nullptr;          // per segment: max(clip_count - 1, 1)
  const std::uint8_t* joint_group = nullptr;  // joint_count: 0 body, 1 left leg, 2 right leg
  const glm::quat* mean_rotations = nullptr;  // clip_count * joint_count
  const std::int32_t* parents = nullptr;      // joint_count
  const glm::vec3* offsets = nullptr;         // joint_count, rest offsets (m)
  LegChain legs[2];                           // left, right: plant_legs
  bool plant_feet = true;
  // Blend weights snapped to the centres of buckets this wide (0 = exact):
  // with a motion cache every character shows its bucket's blend, so a
  // cached cycle is exactly what it would synthesise (speed stays exact,
  // the cadence follows the snapped stride).
  float quantum = 0.0f;
  std::int32_t quantum_buckets = 1;

  THRONG_HOST_DEVICE std::int32_t segment_count() const { return clip_count > 1 ? clip_count - 1 : 1; }
};

// ---------------------------------------------------------------------------
// The blend space

struct BlendSpaceOptions {
  TexelFormat format = TexelFormat::Float32;  // of the motion texture (fp16 halves it, w = 0/1 then not bit-exact)
  // Leg IK in blends: each ankle goes exactly where the two clips' ankles
  // lerp to (plant_legs). Needs thigh -> knee -> ankle parent chains.
  bool plant_feet = true;
};

// Clips of one skeleton sorted by speed (strictly increasing after sorting;
// Error otherwise, or when joint counts differ). Segment k blends clips k and
// k + 1. The speed coordinate x runs over [0, clip_count - 1].
class BlendSpace1D {
 public:
  BlendSpace1D(Skeleton skeleton, std::vector<LocomotionClip> clips, const BlendSpaceOptions& options = {});

  const Skeleton& skeleton() const { return skeleton_; }
  const std::vector<LocomotionClip>& clips() const { return clips_; }
  std::int32_t clip_count() const { return static_cast<std::int32_t>(clips_.size()); }
  std::int32_t segment_count() const { return clip_count() > 1 ? clip_count() - 1 : 1; }
  std::int32_t joint_count() const { return skeleton_.joint_count(); }
  std::int32_t max_frames() const;  // longest cycle, frames
  float min_speed() const { return clip_infos_.front().speed; }
  float max_speed() const { return clip_infos_.back().speed; }
  const std::vector<SegmentSync>& sync() const { return sync_; }
  const std::vector<std::uint8_t>& joint_groups() const { return joint_group_; }
  const MotionTexture& texture() const { return texture_; }
  const std::vector<ClipInfo>& clip_infos() const { return clip_infos_; }
  const std::vector<glm::quat>& mean_rotations() const { return mean_rotations_; }
  // The tables in host memory (valid while this object lives, unmoved).
  BlendSpaceView view() const;

 private:
  Skeleton skeleton_;
  std::vector<LocomotionClip> clips_;
  MotionTexture texture_;
  std::vector<ClipInfo> clip_infos_;
  std::vector<SegmentSync> sync_;
  std::vector<std::uint8_t> joint_group_;
  std::vector<glm::quat> mean_rotations_;
  std::array<LegChain, 2> legs_{};
  bool plant_feet_ = true;
};

// The blend space's tables in the memory that kernels read.
class BlendSpaceTables {
 public:
  BlendSpaceTables() = default;
  explicit BlendSpaceTables(const BlendSpace1D& space, Memory memory = current_memory());
  BlendSpaceView view() const { return view_; }

 private:
  Buffer<float> texels_f32_;
  Buffer<std::uint16_t> texels_f16_;
  Buffer<ClipInfo> clips_;
  Buffer<SegmentSync> sync_;
  Buffer<std::uint8_t> joint_group_;
  Buffer<glm::quat> mean_rotations_;
  Buffer<std::int32_t> parents_;
  Buffer<glm::vec3> offsets_;
  BlendSpaceView view_;
};

// The project's own set: idle, walk_slow, walk, walk_fast, run_slow and
// run_fast of the default skeleton (motion/default_set.h), 0 to 4.5 m/s.
BlendSpace1D make_default_blend_space();

}  // namespace throng::motion
