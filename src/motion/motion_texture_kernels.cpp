// FK over every row of a motion texture, one frame per parallel index.
#include "core/buffer.h"
#include "core/parallel.h"
#include "motion/motion_texture.h"

namespace throng::motion {

ModelSpaceClip forward_kinematics(const MotionTexture& texture) {
  const std::int32_t J = texture.joint_count;
  const Memory m = current_memory();
  const Buffer<float> f32(std::span<const float>(texture.texels_f32), m);
  const Buffer<std::uint16_t> f16(std::span<const std::uint16_t>(texture.texels_f16), m);
  const Buffer<std::int32_t> parents(std::span<const std::int32_t>(texture.parents), m);
  const auto total = static_cast<Index>(texture.frame_count) * J;
  Buffer<glm::vec3> positions(total, m);
  Buffer<glm::quat> rotations(total, m);
  MotionTextureView view = texture.view();
  view.texels_f32 = f32.data();
  view.texels_f16 = f16.data();
  view.parents = parents.data();
  auto P = positions.span();
  auto R = rotations.span();
  parallel_for(
      "motion.fk_texture", texture.frame_count,
      THRONG_LAMBDA(Index f) {
        fk_from_texture(view, static_cast<std::int32_t>(f), P.data() + f * J, R.data() + f * J);
      },
      16);
  ModelSpaceClip out;
  out.joint_count = J;
  out.frame_count = texture.frame_count;
  out.positions = positions.to_vector();
  out.rotations = rotations.to_vector();
  return out;
}

}  // namespace throng::motion
