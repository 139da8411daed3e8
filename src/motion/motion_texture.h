// Motion textures (the 2019 paper's layout): a clip packed as an RGBA image.
//
//   row y = frame, width = 2 * joints, two texels per joint j:
//     x = 2j     local orientation, unit quaternion, RGBA = (x, y, z, w)
//     x = 2j + 1 offset from the parent in metres, RGBA = (x, y, z, 0);
//                for the root its global position, RGBA = (x, y, z, 1)
//   plus the parent index array (parents before children, root = -1).
// Joints whose translation is animated store that frame's translation in
// their offset texel, so FK from the texture needs nothing else.
// Texels are fp32 or fp16 (IEEE binary16, motion/half.h).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <vector>

#include "core/config.h"
#include "motion/clip.h"
#include "motion/fk.h"
#include "motion/half.h"
#include "motion/skeleton.h"

namespace throng::motion {

enum class TexelFormat : std::uint8_t { Float32, Float16 };

// A non-owning view of a motion texture's arrays (host or device memory),
// usable inside kernels.
struct MotionTextureView {
  TexelFormat format = TexelFormat::Float32;
  std::int32_t width = 0;                     // texels per row = 2 * joints
  std::int32_t height = 0;                    // rows = frames
  const float* texels_f32 = nullptr;          // 4 floats per texel
  const std::uint16_t* texels_f16 = nullptr;  // 4 halves per texel
  const std::int32_t* parents = nullptr;

  THRONG_HOST_DEVICE std::int32_t joint_count() const { return width / 2; }

  // texelFetch semantics: integer coordinates, no filtering, no wrapping.
  // Outside the image it returns (0, 0, 0, 0), as robust buffer access does.
  THRONG_HOST_DEVICE glm::vec4 texel_fetch(std::int32_t x, std::int32_t y) const {
    if (x < 0 || y < 0 || x >= width || y >= height) return glm::vec4(0.0f);
    const std::size_t i =
        (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4;
    if (format == TexelFormat::Float32)
      return glm::vec4(texels_f32[i], texels_f32[i + 1], texels_f32[i + 2], texels_f32[i + 3]);
    return glm::vec4(half_to_float(texels_f16[i]), half_to_float(texels_f16[i + 1]), half_to_float(texels_f16[i + 2]),
                     half_to_float(texels_f16[i + 3]));
  }
};

// FK of one row: model-space position and rotation of every joint. The
// quaternion texel is renormalised (fp16 rounding leaves it slightly off unit).
THRONG_HOST_DEVICE inline void fk_from_texture(const MotionTextureView& tex, std::int32_t frame,
                                               glm::vec3* out_positions, glm::quat* out_rotations) {
  const std::int32_t joints = tex.joint_count();
  for (std::int32_t j = 0; j < joints; ++j) {
    const glm::vec4 r = tex.texel_fetch(2 * j, frame);
    const glm::vec4 t = tex.texel_fetch(2 * j + 1, frame);
    const glm::quat q = glm::normalize(glm::quat(r.w, r.x, r.y, r.z));
    const glm::vec3 offset(t.x, t.y, t.z);
    const std::int32_t p = tex.parents[j];
    if (p < 0) {
      out_positions[j] = offset;
      out_rotations[j] = q;
    } else {
      out_positions[j] = out_positions[p] + out_rotations[p] * offset;
      out_rotations[j] = out_rotations[p] * q;
    }
  }
}

// An owning motion texture in host memory.
struct MotionTexture {
  TexelFormat format = TexelFormat::Float32;
  std::int32_t joint_count = 0;
  std::int32_t frame_count = 0;
  float frame_time = 1.0f / 30.0f;
  std::vector<float> texels_f32;          // Float32: width * height * 4
  std::vector<std::uint16_t> texels_f16;  // Float16: width * height * 4
  std::vector<std::int32_t> parents;

  std::int32_t width() const { return 2 * joint_count; }
  std::int32_t height() const { return frame_count; }
  std::size_t bytes() const { return texels_f32.size() * sizeof(float) + texels_f16.size() * sizeof(std::uint16_t); }
  MotionTextureView view() const;
  glm::vec4 texel_fetch(std::int32_t x, std::int32_t y) const { return view().texel_fetch(x, y); }
};

// Packs a clip; throws Error when clip and skeleton disagree.
MotionTexture make_motion_texture(const Skeleton& skeleton, const Clip& clip, TexelFormat format);

// Model-space frames of every joint for every row, in parallel over frames
// (same layout as forward_kinematics(skeleton, clip)).
ModelSpaceClip forward_kinematics(const MotionTexture& texture);

}  // namespace throng::motion
