// Pixel-coverage joint LOD: the 2019 method, with any number of levels.
//
// Per character and body part (lod_spheres.h): the part's bounding sphere
// is projected with the frame's camera; its image area in square pixels
// (sphere_projection.h) picks the part's level, the first whose threshold it
// reaches; the part's level selects which of its joints are synthesised.
// The character's joint mask (one bit per joint, 32 joints per word) is the
// union over its five parts. The pose stage evaluates only masked-in joints;
// every other joint holds its parent's frame (see masked_pose below).
//
//   BodyParts parts = make_body_parts(skeleton);
//   LodConfig config = make_lod_config(parts, {2000.0f, 200.0f});  // 3 levels
//   LodTables tables(config);
//   LodJob job;  job.camera = make_camera_view(camera);  job.set_tables(tables);
//   job.spheres = ...;  job.levels = ...;  job.joint_masks = ...;  job.run();
//   LodHistogram h = lod_histogram(job.levels, job.joint_masks, config.level_count, config.joint_count);
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <vector>

#include "anim/lod_spheres.h"
#include "core/buffer.h"
#include "core/camera.h"
#include "core/config.h"
#include "core/span.h"
#include "motion/locomotion.h"

namespace throng::anim {

inline constexpr int kMaxLodLevels = 16;
inline constexpr std::int32_t kMaxLodJoints = 1024;

THRONG_HOST_DEVICE inline std::int32_t mask_word_count(std::int32_t joints) { return (joints + 31) / 32; }
// A null mask keeps every joint.
THRONG_HOST_DEVICE inline bool joint_synthesised(const std::uint32_t* mask, std::int32_t joint) {
  return motion::mask_bit(mask, joint);
}
THRONG_HOST_DEVICE inline std::int32_t popcount32(std::uint32_t x) {
#if defined(__CUDA_ARCH__)
  return __popc(x);
#else
  return __builtin_popcount(x);
#endif
}

struct LodConfig {
  std::int32_t joint_count = 0;
  std::int32_t level_count = 1;  // level 0 is the finest
  std::int32_t mask_words = 0;   // mask_word_count(joint_count)
  // [part * (level_count - 1) + l], square pixels, strictly decreasing per
  // part: a part is at the first level l whose threshold its coverage
  // reaches (>=); below them all it is at the coarsest level.
  std::vector<float> thresholds;
  // [(part * level_count + level) * mask_words + word]: the joints of the
  // part that are synthesised at that level.
  std::vector<std::uint32_t> masks;
  // Parts whose sphere is wholly outside the view frustum count 0 pixels.
  bool cull_outside_view = true;

  float threshold(BodyPart p, int level) const;
  void set_thresholds(BodyPart p, const std::vector<float>& values);  // level_count - 1 values
  const std::uint32_t* mask(BodyPart p, int level) const;
  std::vector<std::int32_t> synthesised_joints(BodyPart p, int level) const;
  void set_synthesised_joints(BodyPart p, int level, const std::vector<std::int32_t>& joints);
  // Throws Error naming the field ("lod.left_arm.thresholds[1]",
  // "lod.torso.levels[2]"): sizes, thresholds positive, finite and
  // decreasing, masks holding only the part's joints, each level a subset
  // of the finer one, the skeleton root synthesised at every level.
  void validate(const BodyParts& parts) const;
};

// Three levels, as in the paper: {1000, 30} square pixels. A part is fully
// synthesised while its sphere covers >= 1000 px (radius ~18 px: a person
// ~100 px tall), and rigid below 30 px (radius ~3 px: ~15 px tall). Pixel
// measures adapt to resolution and field of view by themselves.
std::vector<float> default_lod_thresholds();

// thresholds (square pixels, strictly decreasing) for every part: so
// thresholds.size() + 1 levels. Level l of a part with D + 1 depths below its
// root synthesises the joints fewer than round((D + 1)(L - 1 - l) / (L - 1))
// bones below the root: level 0 all of them, the coarsest none (the torso
// always keeps the skeleton root). Finger and toe tips go first.
LodConfig make_lod_config(const BodyParts& parts, const std::vector<float>& thresholds);

// A LodConfig's tables in the memory that kernels read.
struct LodTables {
  Buffer<float> thresholds;
  Buffer<std::uint32_t> masks;
  std::int32_t joint_count = 0;
  std::int32_t level_count = 1;
  std::int32_t mask_words = 0;
  bool cull_outside_view = true;

  LodTables() = default;
  explicit LodTables(const LodConfig& config, Memory memory = current_memory());
};

// World-space spheres of N characters from their posed joints.
struct LodSpheresJob {
  std::int32_t joint_count = 0;
  std::array<SphereAnchor, kBodyPartCount> anchors{};  // BodyParts::anchors
  Span<const glm::vec3> joint_positions;               // characters * joint_count, world space, character-major
  Span<const float> scales;                            // characters, or empty for scale 1
  Span<glm::vec4> spheres;                             // characters * 5: centre xyz, radius w

  Index character_count() const { return spheres.size() / kBodyPartCount; }
  void validate() const;  // Error naming the span whose size is wrong
  void run() const;       // parallel_for "anim.lod_spheres"
};

// Characters standing at their roots, as LodJob places their spheres.
struct CharacterRoots {
  Span<const glm::vec3> positions;  // on the ground
  Span<const float> headings;       // radians about +Y
  Span<const float> scales;         // or empty for 1
};

// Levels and joint masks of N characters for one camera.
struct LodJob {
  CameraView camera;
  // The spheres, either given in world space ...
  Span<const glm::vec4> spheres;  // characters * 5: centre xyz, radius w
  // ... or placed from each character's root transform and the skeleton's
  // rest spheres: centre = position + scale * Ry(heading) * template.xyz.
  CharacterRoots roots;
  std::array<glm::vec4, kBodyPartCount> template_spheres{};  // BodyParts::rest_spheres

  // Tables (set_tables), in current_memory().
  Span<const float> thresholds;
  Span<const std::uint32_t> part_masks;
  std::int32_t level_count = 1;
  std::int32_t mask_words = 0;
  bool cull_outside_view = true;

  Span<std::uint8_t> levels;        // out: characters * 5, by BodyPart
  Span<std::uint32_t> joint_masks;  // out: characters * mask_words
  Span<float> coverage;             // out, optional: characters * 5 square pixels

  void set_tables(const LodTables& tables);
  Index character_count() const { return levels.size() / kBodyPartCount; }
  void validate() const;
  void run() const;  // parallel_for "anim.lod"
};

// The LodJob of characters at `roots` with a rig's body parts and level
// tables under `camera`, writing levels and joint masks: what each pose
// source of the locomotion layer runs once a frame.
LodJob make_lod_job(const Camera& camera, const LodTables& tables, const BodyParts& parts, const CharacterRoots& roots,
                    Span<std::uint8_t> levels, Span<std::uint32_t> joint_masks);

// One frame's statistics over N characters.
struct LodHistogram {
  std::int32_t level_count = 0;
  std::int32_t joint_count = 0;
  Index characters = 0;
  std::vector<Index> level_counts;        // [part * level_count + level]: characters
  std::vector<Index> joints_synthesised;  // [k], k in [0, joint_count]: characters synthesising k joints
  Index total_joints_synthesised = 0;

  Index at_level(BodyPart p, int level) const {
    return level_counts[static_cast<std::size_t>(static_cast<int>(p) * level_count + level)];
  }
  double mean_joints_synthesised() const {
    return characters > 0 ? static_cast<double>(total_joints_synthesised) / static_cast<double>(characters) : 0.0;
  }
  // Characters that synthesise each joint (joint_count entries).
  std::vector<Index> per_joint(const LodConfig& config) const;
};

// Deterministic (integer counts over fixed blocks); spans in current_memory().
LodHistogram lod_histogram(Span<const std::uint8_t> levels, Span<const std::uint32_t> joint_masks,
                           std::int32_t level_count, std::int32_t joint_count);

// The pose stage's contract with LOD: forward kinematics where joint j's
// local rotation is evaluate(j) when its mask bit is set (a null mask sets
// them all), and otherwise is not evaluated: the joint holds its parent's
// frame (local rotation held_rotations[j], identity when held_rotations is
// null) carried by its rest offset times `scale`. The root's evaluate(0) is
// its world rotation. Returns how many joints were evaluated. evaluate(j)
// runs before out_rotations[j] is written, so it may read local rotations
// stored there.
template <class Evaluate>
THRONG_HOST_DEVICE inline std::int32_t masked_pose(std::int32_t joints, const std::int32_t* parents,
                                                   const glm::vec3* offsets, const std::uint32_t* mask,
                                                   const Evaluate& evaluate, const glm::quat* held_rotations,
                                                   glm::vec3 root_position, glm::vec3* out_positions,
                                                   glm::quat* out_rotations, float scale = 1.0f) {
  std::int32_t evaluated = 0;
  for (std::int32_t j = 0; j < joints; ++j) {
    glm::quat local(1.0f, 0.0f, 0.0f, 0.0f);
    if (joint_synthesised(mask, j)) {
      local = evaluate(j);
      ++evaluated;
    } else if (held_rotations != nullptr) {
      local = held_rotations[j];
    }
    // The recurrence of motion::fk_pose, with the local rotation chosen above.
    const std::int32_t p = parents[j];
    if (p < 0) {
      out_positions[j] = root_position;
      out_rotations[j] = local;
    } else {
      out_positions[j] = out_positions[p] + out_rotations[p] * (scale * offsets[j]);
      out_rotations[j] = out_rotations[p] * local;
    }
  }
  return evaluated;
}

// Host reference over a Skeleton, for tests and tools.
struct MaskedPose {
  std::vector<glm::vec3> positions;  // model space
  std::vector<glm::quat> rotations;
  std::int32_t evaluated = 0;
};
MaskedPose synthesise_with_mask(const motion::Skeleton& skeleton, Span<const std::uint32_t> mask,
                                const std::function<glm::quat(std::int32_t)>& local_rotation, glm::vec3 root_position,
                                Span<const glm::quat> held_rotations = {});

}  // namespace throng::anim
