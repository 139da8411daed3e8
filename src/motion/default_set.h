// The project's own motion set: a 22-joint humanoid of a 1.75 m adult and
// procedural locomotion cycles (idle, walks, runs, turning walks) whose
// cadence, stride and contact timing follow motion/biomech.h.
//
// Convention: Y up, the rest pose is a T-pose facing +Z (the character's
// left is +X), metres, seconds. Every clip holds whole strides sampled at
// `fps`; frame `frame_count` would equal frame 0 moved by the cycle's rigid
// root motion, so the clip loops seamlessly in its heading frame.
//
// How a cycle is made: the root follows a straight or circular path at the
// mean speed; each foot is planted at positions fixed in the world, stays
// there (ankle pinned from touchdown to heel-off, ball of the foot pinned
// from foot-flat to toe-off), swings to the next plant on a C1 Hermite arc
// with clearance, and the legs reach it by analytic two-bone IK. The pelvis
// bobs, sways, rotates and lists; the thorax counter-rotates; the arms swing
// against the legs. See docs/default_motions.md.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "motion/biomech.h"
#include "motion/clip.h"
#include "motion/skeleton.h"

namespace throng::motion {

// Joint indices of default_skeleton(), in file order.
namespace default_joint {
enum : std::int32_t {
  Hips,
  Spine,
  Spine1,
  Spine2,
  Neck,
  Head,
  LeftShoulder,  // clavicle
  LeftArm,
  LeftForeArm,
  LeftHand,
  RightShoulder,
  RightArm,
  RightForeArm,
  RightHand,
  LeftUpLeg,
  LeftLeg,
  LeftFoot,
  LeftToeBase,
  RightUpLeg,
  RightLeg,
  RightFoot,
  RightToeBase,
  Count
};
}  // namespace default_joint

// Mixamo-style names, T-pose, proportions of a 1.75 m adult (segment
// lengths after Drillis & Contini as tabulated by Winter), roles and spine
// chain filled directly, end sites at head top, finger tips and toe tips.
// Soles at y = 0 in the rest pose.
Skeleton default_skeleton();

struct LocomotionSpec {
  std::string name;
  biomech::Gait gait = biomech::Gait::Walk;
  double speed = 1.35;     // mean root speed along the path, m/s (0 for Stand)
  double turn_rate = 0.0;  // rad/s about +Y; positive turns left (towards +X)
  double fps = 60.0;
  std::int32_t strides = 1;    // whole cycles in the clip (Stand: whole idle periods)
  double idle_period_s = 4.0;  // Stand only: one breath / weight-shift cycle
  // Throws Error naming the field when a value is out of its range
  // (speed must suit the gait: walk 0.5-2.2 m/s, run 1.8-7 m/s).
  void validate() const;
};

// Timing the generator uses, from the biomechanics relations. The stride
// period is rounded to whole frames so clips are exactly cyclic; cadence
// and stride are the figures after that rounding, speed is kept exact.
struct LocomotionTargets {
  double target_cadence = 0.0;  // steps/min from biomech, before rounding
  double cadence = 0.0;         // steps/min actually generated
  double period_s = 0.0;        // one stride (two steps), or the idle period
  std::int32_t period_frames = 0;
  double stride_length = 0.0;    // m per stride (speed * period)
  double duty_factor = 1.0;      // fraction of the stride each foot is down
  double turn_per_stride = 0.0;  // rad
};

// Evaluates a cycle at any time t (seconds, any real value): the pose at
// t + period equals the pose at t with the root moved by the cycle's rigid
// motion. Needs a T-pose skeleton facing +Z with every limb role, the spine
// chain and clavicles (parents of the shoulders) set, e.g. default_skeleton().
class LocomotionGenerator {
 public:
  LocomotionGenerator(const Skeleton& skeleton, const LocomotionSpec& spec);
  ~LocomotionGenerator();
  LocomotionGenerator(LocomotionGenerator&&) noexcept;
  LocomotionGenerator& operator=(LocomotionGenerator&&) noexcept;

  const LocomotionTargets& targets() const;
  const LocomotionSpec& spec() const;
  // local_rotations has joint_count entries.
  void pose_at(double t, std::span<glm::quat> local_rotations, glm::vec3& root_position) const;
  // Frames 0..frames-1 at the spec's fps, starting at t = 0 (left heel strike).
  Clip sample(std::int32_t frames) const;
  // The spec's whole strides: period_frames * strides frames.
  Clip make_clip() const;

  // Where the generator puts the pelvis: rest root height minus the drop it
  // chose so that every foot target is reachable (m), for reports.
  double pelvis_drop() const;

 private:
  struct Model;
  std::unique_ptr<Model> model_;
};

struct DefaultMotion {
  LocomotionSpec spec;
  LocomotionTargets targets;
  std::string description;
  Clip clip;
};

// idle, walk_slow, walk, walk_fast, run_slow, run_fast, walk_turn_left,
// walk_turn_right (speeds and turn rates in docs/default_motions.md).
std::vector<LocomotionSpec> default_motion_specs();
// Every clip of default_motion_specs() on `skeleton` (default_skeleton()).
std::vector<DefaultMotion> make_default_motions(const Skeleton& skeleton);

}  // namespace throng::motion
