#include "core/buffer.h"
#include "core/error.h"
#include "core/parallel.h"
#include "motion/fk.h"

namespace throng::motion {

ModelSpaceClip forward_kinematics(const Skeleton& skeleton, const Clip& clip) {
  const std::int32_t J = skeleton.joint_count();
  if (clip.joint_count != J)
    throw Error("clip has " + std::to_string(clip.joint_count) + " joints, skeleton " + std::to_string(J));
  ModelSpaceClip out;
  out.joint_count = J;
  out.frame_count = clip.frame_count;
  const auto total = static_cast<Index>(clip.frame_count) * J;
  const Memory m = current_memory();
  const Buffer<std::int32_t> parents(std::span<const std::int32_t>(skeleton.parents), m);
  const Buffer<glm::vec3> offsets(std::span<const glm::vec3>(skeleton.offsets), m);
  const Buffer<glm::quat> local(std::span<const glm::quat>(clip.rotations), m);
  const Buffer<glm::vec3> roots(std::span<const glm::vec3>(clip.root_positions), m);
  const Buffer<glm::vec3> translations(std::span<const glm::vec3>(clip.translations), m);
  Buffer<glm::vec3> positions(total, m);
  Buffer<glm::quat> rotations(total, m);
  const bool has_translations = !clip.translations.empty();
  auto P = parents.span();
  auto O = offsets.span();
  auto L = local.span();
  auto R = roots.span();
  auto T = translations.span();
  auto outP = positions.span();
  auto outR = rotations.span();
  parallel_for(
      "motion.fk_clip", clip.frame_count,
      THRONG_LAMBDA(Index f) {
        const Index base = f * J;
        fk_pose(J, P.data(), O.data(), L.data() + base, has_translations ? T.data() + base : nullptr, R[f],
                outP.data() + base, outR.data() + base);
      },
      16);
  out.positions = positions.to_vector();
  out.rotations = rotations.to_vector();
  return out;
}

}  // namespace throng::motion
