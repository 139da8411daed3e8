// Motion textures: layout, texelFetch semantics, and FK from the texture
// against FK from the clip (fp32 to float rounding, fp16 within a bound
// derived from the half-precision rounding of every texel, see below).
#include "motion/motion_texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/exec.h"
#include "tests/motion/random_motion.h"

namespace throng::motion {
namespace {

struct Data {
  Skeleton skeleton;
  Clip clip;
};

Data make_data(unsigned seed, bool translations) {
  std::mt19937 rng(seed);
  Data d;
  d.skeleton = testing::random_skeleton(rng, 24);
  d.clip = testing::random_clip(d.skeleton, 40, rng, translations);
  return d;
}

TEST(MotionTexture, LayoutIsTwoRgbaTexelsPerJointPerFrame) {
  const Data d = make_data(1, true);
  const MotionTexture t = make_motion_texture(d.skeleton, d.clip, TexelFormat::Float32);
  const std::int32_t J = d.skeleton.joint_count();
  EXPECT_EQ(t.width(), 2 * J);
  EXPECT_EQ(t.height(), d.clip.frame_count);
  EXPECT_EQ(t.texels_f32.size(), static_cast<std::size_t>(t.width() * t.height() * 4));
  EXPECT_TRUE(t.texels_f16.empty());
  EXPECT_EQ(t.parents, d.skeleton.parents);
  EXPECT_EQ(t.bytes(), t.texels_f32.size() * 4);
  for (std::int32_t f = 0; f < d.clip.frame_count; ++f)
    for (std::int32_t j = 0; j < J; ++j) {
      const glm::quat q = d.clip.rotation(f, j);
      EXPECT_EQ(t.texel_fetch(2 * j, f), glm::vec4(q.x, q.y, q.z, q.w));
      const glm::vec4 o = t.texel_fetch(2 * j + 1, f);
      if (j == 0) {
        EXPECT_EQ(o, glm::vec4(d.clip.root_positions[static_cast<std::size_t>(f)], 1.0f));
      } else {
        const std::size_t k = static_cast<std::size_t>(f * J + j);
        EXPECT_EQ(o, glm::vec4(d.clip.translations[k], 0.0f));
      }
    }
}

TEST(MotionTexture, TexelFetchOutsideTheImageIsZero) {
  const Data d = make_data(2, false);
  for (TexelFormat format : {TexelFormat::Float32, TexelFormat::Float16}) {
    const MotionTexture t = make_motion_texture(d.skeleton, d.clip, format);
    for (auto [x, y] : {std::pair{-1, 0}, {0, -1}, {t.width(), 0}, {0, t.height()}, {t.width(), t.height()}})
      EXPECT_EQ(t.texel_fetch(x, y), glm::vec4(0.0f)) << x << "," << y;
    // Inside: an offset texel of a non-root joint is the rest offset, w = 0.
    EXPECT_EQ(glm::vec3(t.texel_fetch(3, 5)).y, format == TexelFormat::Float32
                                                    ? d.skeleton.offsets[1].y
                                                    : half_to_float(float_to_half(d.skeleton.offsets[1].y)));
  }
}

TEST(MotionTexture, HalfTexelsAreRoundedFloatTexels) {
  const Data d = make_data(3, true);
  const MotionTexture f32 = make_motion_texture(d.skeleton, d.clip, TexelFormat::Float32);
  const MotionTexture f16 = make_motion_texture(d.skeleton, d.clip, TexelFormat::Float16);
  ASSERT_EQ(f16.texels_f16.size(), f32.texels_f32.size());
  EXPECT_EQ(f16.bytes() * 2, f32.bytes());
  for (std::size_t i = 0; i < f32.texels_f32.size(); ++i)
    ASSERT_EQ(f16.texels_f16[i], float_to_half(f32.texels_f32[i]));
}

double max_position_error(const ModelSpaceClip& a, const ModelSpaceClip& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    worst = std::max(worst, static_cast<double>(glm::length(a.positions[i] - b.positions[i])));
  return worst;
}

TEST(MotionTexture, Float32FkEqualsClipFk) {
  for (bool translations : {false, true}) {
    const Data d = make_data(4, translations);
    const ModelSpaceClip ref = forward_kinematics(d.skeleton, d.clip);
    const ModelSpaceClip tex = forward_kinematics(make_motion_texture(d.skeleton, d.clip, TexelFormat::Float32));
    ASSERT_EQ(tex.positions.size(), ref.positions.size());
    // Only the renormalisation of already unit quaternions differs.
    EXPECT_LT(max_position_error(ref, tex), 1e-5);
    for (std::size_t i = 0; i < ref.rotations.size(); ++i)
      ASSERT_LT(glm::length(ref.rotations[i] - tex.rotations[i]), 1e-5f);
  }
}

// fp16 bound, per joint, from the rounding of each texel (u = 2^-11, the
// half's relative precision):
//  - a quaternion component (|c| <= 1) moves by <= u/2, the quaternion by
//    <= u; renormalised, by <= 2u; as a rotation, by an angle <= 4u = th.
//  - model rotation error: Th_j = Th_parent + th (angles add along the chain).
//  - an offset t moves by <= |t| u (+ 2^-24 for subnormals); the root
//    position likewise.
//  - position error: e_j = e_parent + |t_j| Th_parent + |dt_j|.
// plus 1e-5 m for float arithmetic.
TEST(MotionTexture, Float16FkWithinDerivedBound) {
  const double u = std::ldexp(1.0, -11), th = 4 * u, tiny = std::ldexp(1.0, -24);
  for (bool translations : {false, true}) {
    const Data d = make_data(5, translations);
    const ModelSpaceClip ref = forward_kinematics(d.skeleton, d.clip);
    const ModelSpaceClip tex = forward_kinematics(make_motion_texture(d.skeleton, d.clip, TexelFormat::Float16));
    const std::int32_t J = d.skeleton.joint_count();
    double worst = 0, worst_ratio = 0;
    for (std::int32_t f = 0; f < d.clip.frame_count; ++f) {
      std::vector<double> e(static_cast<std::size_t>(J)), Th(static_cast<std::size_t>(J));
      for (std::int32_t j = 0; j < J; ++j) {
        const std::size_t uj = static_cast<std::size_t>(j);
        const std::int32_t p = d.skeleton.parents[uj];
        const std::size_t k = static_cast<std::size_t>(f * J + j);
        if (p < 0) {
          e[uj] = glm::length(d.clip.root_positions[static_cast<std::size_t>(f)]) * u + tiny;
          Th[uj] = th;
        } else {
          const glm::vec3 t = translations ? d.clip.translations[k] : d.skeleton.offsets[uj];
          const std::size_t up = static_cast<std::size_t>(p);
          e[uj] = e[up] + glm::length(t) * Th[up] + glm::length(t) * u + tiny;
          Th[uj] = Th[up] + th;
        }
        const double err = glm::length(tex.positions[k] - ref.positions[k]);
        ASSERT_LE(err, e[uj] + 1e-5) << "frame " << f << " joint " << j;
        worst = std::max(worst, err);
        worst_ratio = std::max(worst_ratio, err / (e[uj] + 1e-5));
      }
    }
    std::printf("fp16 FK: max position error %.3g m (%.0f%% of its bound)\n", worst, 100 * worst_ratio);
    EXPECT_GT(worst, 0.0);  // fp16 really rounded something
  }
}

TEST(MotionTexture, SameResultForAnyThreadCount) {
  const Data d = make_data(6, false);
  const MotionTexture t = make_motion_texture(d.skeleton, d.clip, TexelFormat::Float16);
  ModelSpaceClip one, all;
  {
    ScopedExecution e(Backend::Cpu, 1);
    one = forward_kinematics(t);
  }
  {
    ScopedExecution e(Backend::Cpu, 0);
    all = forward_kinematics(t);
  }
  EXPECT_EQ(one.positions, all.positions);
}

TEST(MotionTexture, MismatchedClipIsAnError) {
  Data d = make_data(7, false);
  d.clip.root_positions.pop_back();
  EXPECT_THROW(make_motion_texture(d.skeleton, d.clip, TexelFormat::Float32), Error);
}

}  // namespace
}  // namespace throng::motion
