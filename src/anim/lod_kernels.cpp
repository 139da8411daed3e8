// LOD kernels: compiled by nvcc in CUDA builds, by g++ otherwise.
#include "anim/lod.h"
#include "anim/sphere_projection.h"
#include "core/error.h"
#include "core/parallel.h"

namespace throng::anim {

namespace {

// Plain arrays travel into kernels by value; std::array's members are host-only in CUDA.
struct Anchors {
  SphereAnchor a[kBodyPartCount];
};
struct Templates {
  glm::vec4 s[kBodyPartCount];
};

constexpr Index kHistogramBlock = 4096;

}  // namespace

void LodSpheresJob::run() const {
  validate();
  Anchors anchor_table{};
  for (int p = 0; p < kBodyPartCount; ++p) anchor_table.a[p] = anchors[static_cast<std::size_t>(p)];
  parallel_for(
      "anim.lod_spheres", character_count(),
      THRONG_JOB_LAMBDA(Index c) {
        const glm::vec3* joints = joint_positions.data() + c * joint_count;
        const float s = scales.empty() ? 1.0f : scales[c];
        for (int p = 0; p < kBodyPartCount; ++p)
          spheres[c * kBodyPartCount + p] =
              glm::vec4(anchor_centre(anchor_table.a[p], joints), s * anchor_table.a[p].radius);
      },
      256);
}

namespace {

// A character's root transform: rotation about +Y by the heading (as its
// cosine and sine), then scale, then translation to the root.
struct RootFrame {
  float cos_h = 1.0f, sin_h = 0.0f, scale = 1.0f;
  glm::vec3 root{0.0f};
  THRONG_HOST_DEVICE glm::vec4 place(glm::vec4 t) const {
    const glm::vec3 turned(cos_h * t.x + sin_h * t.z, t.y, -sin_h * t.x + cos_h * t.z);
    return glm::vec4(root + scale * turned, scale * t.w);
  }
};

// Character c's level per body part (from each part's sphere, given or
// placed from its root, its screen coverage and thresholds), then its joint mask: the OR of its parts' masks at their
// levels (parts partition the joints).
THRONG_HOST_DEVICE inline void classify_character(const LodJob& job, const Templates& tmpl, Index c) {
  const std::int32_t L = job.level_count;
  const std::int32_t W = job.mask_words;
  const bool from_roots = job.spheres.empty();
  RootFrame frame;
  if (from_roots) {
    frame.cos_h = glm::cos(job.roots.headings[c]);
    frame.sin_h = glm::sin(job.roots.headings[c]);
    frame.scale = job.roots.scales.empty() ? 1.0f : job.roots.scales[c];
    frame.root = job.roots.positions[c];
  }
  int level_of[kBodyPartCount];
  for (int p = 0; p < kBodyPartCount; ++p) {
    const glm::vec4 s = from_roots ? frame.place(tmpl.s[p]) : job.spheres[c * kBodyPartCount + p];
    const float area =
        sphere_pixel_coverage(to_camera_space(job.camera, glm::vec3(s)), s.w, job.camera, job.cull_outside_view);
    const float* part_thresholds = job.thresholds.data() + p * (L - 1);
    int level = 0;
    while (level < L - 1 && !(area >= part_thresholds[level])) ++level;
    level_of[p] = level;
    job.levels[c * kBodyPartCount + p] = static_cast<std::uint8_t>(level);
    if (!job.coverage.empty()) job.coverage[c * kBodyPartCount + p] = area;
  }
  for (std::int32_t w = 0; w < W; ++w) {
    std::uint32_t bits = 0u;
    for (int p = 0; p < kBodyPartCount; ++p) bits |= job.part_masks[(static_cast<Index>(p) * L + level_of[p]) * W + w];
    job.joint_masks[c * W + w] = bits;
  }
}

}  // namespace

void LodJob::run() const {
  validate();
  Templates tmpl{};
  for (int p = 0; p < kBodyPartCount; ++p) tmpl.s[p] = template_spheres[static_cast<std::size_t>(p)];
  parallel_for(
      "anim.lod", character_count(), THRONG_JOB_LAMBDA(Index c) { classify_character(*this, tmpl, c); }, 256);
}

LodHistogram lod_histogram(Span<const std::uint8_t> levels, Span<const std::uint32_t> joint_masks,
                           std::int32_t level_count, std::int32_t joint_count) {
  if (level_count < 1 || level_count > kMaxLodLevels)
    throw Error("must be in [1, " + std::to_string(kMaxLodLevels) + "]", at_field("lod_histogram.level_count"));
  if (joint_count < 1 || joint_count > kMaxLodJoints)
    throw Error("must be in [1, " + std::to_string(kMaxLodJoints) + "]", at_field("lod_histogram.joint_count"));
  if (levels.size() % kBodyPartCount != 0)
    throw Error("size must be a multiple of 5", at_field("lod_histogram.levels"));
  const Index n = levels.size() / kBodyPartCount;
  const std::int32_t W = mask_word_count(joint_count);
  if (joint_masks.size() != n * W)
    throw Error("has " + std::to_string(joint_masks.size()) + " words, expected " + std::to_string(n * W),
                at_field("lod_histogram.joint_masks"));

  LodHistogram h;
  h.level_count = level_count;
  h.joint_count = joint_count;
  h.characters = n;
  h.level_counts.assign(static_cast<std::size_t>(kBodyPartCount * level_count), 0);
  h.joints_synthesised.assign(static_cast<std::size_t>(joint_count) + 1, 0);
  if (n == 0) return h;

  // Each block of characters counts into its own row; rows are summed in
  // order on the host. Integer counts: the same for any thread count.
  const Index row = static_cast<Index>(kBodyPartCount) * level_count + joint_count + 1;
  const Index blocks = (n + kHistogramBlock - 1) / kHistogramBlock;
  Buffer<Index> partial(blocks * row, current_memory());
  const auto rows = partial.span();
  const std::int32_t L = level_count;
  const std::int32_t J = joint_count;
  parallel_for(
      "anim.lod_histogram", blocks,
      THRONG_LAMBDA(Index b) {
        Index* counts = rows.data() + b * row;
        for (Index i = 0; i < row; ++i) counts[i] = 0;
        const Index end = (b + 1) * kHistogramBlock < n ? (b + 1) * kHistogramBlock : n;
        for (Index c = b * kHistogramBlock; c < end; ++c) {
          for (int p = 0; p < kBodyPartCount; ++p) {
            const int level = levels[c * kBodyPartCount + p];
            ++counts[p * L + (level < L ? level : L - 1)];
          }
          std::int32_t k = 0;
          for (std::int32_t w = 0; w < W; ++w) k += popcount32(joint_masks[c * W + w]);
          ++counts[kBodyPartCount * L + (k < J ? k : J)];
        }
      },
      1);
  const std::vector<Index> all = partial.to_vector();
  for (Index b = 0; b < blocks; ++b) {
    const Index* counts = all.data() + b * row;
    for (int i = 0; i < kBodyPartCount * L; ++i) h.level_counts[static_cast<std::size_t>(i)] += counts[i];
    for (std::int32_t k = 0; k <= J; ++k)
      h.joints_synthesised[static_cast<std::size_t>(k)] += counts[kBodyPartCount * L + k];
  }
  for (std::int32_t k = 0; k <= J; ++k)
    h.total_joints_synthesised += k * h.joints_synthesised[static_cast<std::size_t>(k)];
  return h;
}

}  // namespace throng::anim
