#include "motion/motion_texture.h"

#include <string>

#include "core/error.h"

namespace throng::motion {

MotionTextureView MotionTexture::view() const {
  MotionTextureView v;
  v.format = format;
  v.width = width();
  v.height = height();
  v.texels_f32 = texels_f32.data();
  v.texels_f16 = texels_f16.data();
  v.parents = parents.data();
  return v;
}

MotionTexture make_motion_texture(const Skeleton& skeleton, const Clip& clip, TexelFormat format) {
  skeleton.validate();
  const std::int32_t J = skeleton.joint_count();
  const auto frames = static_cast<std::size_t>(clip.frame_count);
  const auto joints = static_cast<std::size_t>(J);
  if (clip.joint_count != J || clip.rotations.size() != frames * joints || clip.root_positions.size() != frames ||
      (!clip.translations.empty() && clip.translations.size() != frames * joints))
    throw Error("motion texture: clip (" + std::to_string(clip.joint_count) + " joints, " +
                std::to_string(clip.frame_count) + " frames) does not match the skeleton (" + std::to_string(J) +
                " joints) or its own arrays");
  MotionTexture t;
  t.format = format;
  t.joint_count = J;
  t.frame_count = clip.frame_count;
  t.frame_time = clip.frame_time;
  t.parents = skeleton.parents;
  const std::size_t n = frames * joints * 2 * 4;
  std::vector<float> f32(n);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t j = 0; j < joints; ++j) {
      const std::size_t k = f * joints + j;
      float* texel = &f32[k * 8];
      const glm::quat& q = clip.rotations[k];
      texel[0] = q.x;
      texel[1] = q.y;
      texel[2] = q.z;
      texel[3] = q.w;
      const bool root = skeleton.parents[j] < 0;
      const glm::vec3 o =
          root ? clip.root_positions[f] : (clip.translations.empty() ? skeleton.offsets[j] : clip.translations[k]);
      texel[4] = o.x;
      texel[5] = o.y;
      texel[6] = o.z;
      texel[7] = root ? 1.0f : 0.0f;
    }
  }
  if (format == TexelFormat::Float32) {
    t.texels_f32 = std::move(f32);
  } else {
    t.texels_f16.resize(n);
    for (std::size_t i = 0; i < n; ++i) t.texels_f16[i] = float_to_half(f32[i]);
  }
  return t;
}

}  // namespace throng::motion
