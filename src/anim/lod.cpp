#include "anim/lod.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/check.h"
#include "core/error.h"

namespace throng::anim {

namespace {

std::size_t at(Index i) { return static_cast<std::size_t>(i); }

std::string part_field(BodyPart p, const std::string& rest) { return std::string("lod.") + to_string(p) + "." + rest; }

std::string indexed(const char* name, Index i) { return std::string(name) + "[" + std::to_string(i) + "]"; }

void check_part(BodyPart p) {
  const int i = static_cast<int>(p);
  if (i < 0 || i >= kBodyPartCount) throw Error("no such body part", at_field("lod.part"));
}

}  // namespace

float LodConfig::threshold(BodyPart p, int level) const {
  check_part(p);
  if (level < 0 || level >= level_count - 1)
    throw Error("no threshold for this level", at_field(part_field(p, indexed("thresholds", level))));
  return thresholds[at(static_cast<int>(p) * (level_count - 1) + level)];
}

void LodConfig::set_thresholds(BodyPart p, const std::vector<float>& values) {
  check_part(p);
  if (static_cast<Index>(values.size()) != level_count - 1)
    throw Error("needs " + std::to_string(level_count - 1) + " values, got " + std::to_string(values.size()),
                at_field(part_field(p, "thresholds")));
  for (std::size_t l = 0; l < values.size(); ++l)
    thresholds[at(static_cast<int>(p) * (level_count - 1)) + l] = values[l];
}

const std::uint32_t* LodConfig::mask(BodyPart p, int level) const {
  check_part(p);
  if (level < 0 || level >= level_count)
    throw Error("no such level", at_field(part_field(p, indexed("levels", level))));
  return masks.data() + at((static_cast<Index>(p) * level_count + level) * mask_words);
}

std::vector<std::int32_t> LodConfig::synthesised_joints(BodyPart p, int level) const {
  const std::uint32_t* m = mask(p, level);
  std::vector<std::int32_t> out;
  for (std::int32_t j = 0; j < joint_count; ++j)
    if (joint_synthesised(m, j)) out.push_back(j);
  return out;
}

void LodConfig::set_synthesised_joints(BodyPart p, int level, const std::vector<std::int32_t>& joints) {
  mask(p, level);  // checks the part and the level
  std::uint32_t* words = masks.data() + at((static_cast<Index>(p) * level_count + level) * mask_words);
  std::vector<std::uint32_t> bits(at(mask_words), 0u);
  for (std::int32_t j : joints) {
    if (j < 0 || j >= joint_count)
      throw Error("joint " + std::to_string(j) + " is out of range", at_field(part_field(p, indexed("levels", level))));
    bits[at(j >> 5)] |= 1u << (j & 31);
  }
  std::copy(bits.begin(), bits.end(), words);
}

void LodConfig::validate(const BodyParts& parts) const {
  if (joint_count != parts.joint_count)
    throw Error("has " + std::to_string(joint_count) + " joints, the skeleton " + std::to_string(parts.joint_count),
                at_field("lod.joint_count"));
  if (joint_count <= 0 || joint_count > kMaxLodJoints)
    throw Error("must be in [1, " + std::to_string(kMaxLodJoints) + "]", at_field("lod.joint_count"));
  if (level_count < 1 || level_count > kMaxLodLevels)
    throw Error("must be in [1, " + std::to_string(kMaxLodLevels) + "]", at_field("lod.level_count"));
  if (mask_words != mask_word_count(joint_count))
    throw Error("must be (joint_count + 31) / 32", at_field("lod.mask_words"));
  check_length("lod", "thresholds", static_cast<Index>(thresholds.size()),
               static_cast<Index>(kBodyPartCount) * (level_count - 1));
  check_length("lod", "masks", static_cast<Index>(masks.size()),
               static_cast<Index>(kBodyPartCount) * level_count * mask_words);
  for (BodyPart p : kAllBodyParts) {
    float previous = INFINITY;
    for (int l = 0; l + 1 < level_count; ++l) {
      const float t = threshold(p, l);
      if (!(std::isfinite(t) && t > 0.0f && t < previous))
        throw Error("must be positive, finite and below the previous level's threshold",
                    at_field(part_field(p, indexed("thresholds", l))));
      previous = t;
    }
    for (int l = 0; l < level_count; ++l) {
      const std::uint32_t* m = mask(p, l);
      const std::uint32_t* finer = l > 0 ? mask(p, l - 1) : nullptr;
      const std::string field = part_field(p, indexed("levels", l));
      for (std::int32_t w = 0; w < mask_words; ++w) {
        const std::uint32_t valid =
            w == mask_words - 1 && joint_count % 32 != 0 ? (1u << (joint_count % 32)) - 1u : ~0u;
        if ((m[w] & ~valid) != 0u) throw Error("has bits beyond the last joint", at_field(field));
      }
      for (std::int32_t j = 0; j < joint_count; ++j) {
        if (!joint_synthesised(m, j)) continue;
        if (parts.part_of[at(j)] != static_cast<std::uint8_t>(p))
          throw Error(
              "joint " + std::to_string(j) + " belongs to " + to_string(static_cast<BodyPart>(parts.part_of[at(j)])),
              at_field(field));
        if (finer != nullptr && !joint_synthesised(finer, j))
          throw Error(
              "joint " + std::to_string(j) + " is synthesised here but not at the finer level " + std::to_string(l - 1),
              at_field(field));
      }
      if (p == BodyPart::Torso && !joint_synthesised(m, 0))
        throw Error("the skeleton root must be synthesised at every level", at_field(field));
    }
  }
}

std::vector<float> default_lod_thresholds() { return {1000.0f, 30.0f}; }

LodConfig make_lod_config(const BodyParts& parts, const std::vector<float>& thresholds) {
  LodConfig c;
  c.joint_count = parts.joint_count;
  c.level_count = static_cast<std::int32_t>(thresholds.size()) + 1;
  if (c.level_count > kMaxLodLevels)
    throw Error("at most " + std::to_string(kMaxLodLevels - 1) + " thresholds", at_field("lod.thresholds"));
  if (c.joint_count <= 0 || c.joint_count > kMaxLodJoints)
    throw Error("must be in [1, " + std::to_string(kMaxLodJoints) + "]", at_field("lod.joint_count"));
  c.mask_words = mask_word_count(c.joint_count);
  c.thresholds.assign(at(kBodyPartCount * (c.level_count - 1)), 0.0f);
  c.masks.assign(at(static_cast<Index>(kBodyPartCount) * c.level_count * c.mask_words), 0u);
  const int L = c.level_count;
  for (BodyPart p : kAllBodyParts) {
    c.set_thresholds(p, thresholds);
    std::int32_t max_depth = 0;
    for (std::int32_t j : parts.joints_of(p)) max_depth = std::max(max_depth, parts.depth[at(j)]);
    for (int l = 0; l < L; ++l) {
      const std::int32_t keep =
          L == 1 ? max_depth + 1
                 : static_cast<std::int32_t>(std::lround(static_cast<double>(max_depth + 1) * (L - 1 - l) / (L - 1)));
      std::vector<std::int32_t> joints;
      for (std::int32_t j : parts.joints_of(p))
        if (parts.depth[at(j)] < keep || j == 0) joints.push_back(j);
      c.set_synthesised_joints(p, l, joints);
    }
  }
  c.validate(parts);
  return c;
}

LodTables::LodTables(const LodConfig& config, Memory memory)
    : thresholds(std::span<const float>(config.thresholds), memory),
      masks(std::span<const std::uint32_t>(config.masks), memory),
      joint_count(config.joint_count),
      level_count(config.level_count),
      mask_words(config.mask_words),
      cull_outside_view(config.cull_outside_view) {}

std::vector<Index> LodHistogram::per_joint(const LodConfig& config) const {
  std::vector<Index> out(at(joint_count), 0);
  if (config.level_count != level_count || config.joint_count != joint_count)
    throw Error("histogram and config disagree in levels or joints", at_field("lod"));
  // A part's joints depend only on its level, so the level counts suffice.
  for (BodyPart p : kAllBodyParts)
    for (int l = 0; l < level_count; ++l) {
      const std::uint32_t* m = config.mask(p, l);
      for (std::int32_t j = 0; j < joint_count; ++j)
        if (joint_synthesised(m, j)) out[at(j)] += at_level(p, l);
    }
  return out;
}

void LodSpheresJob::validate() const {
  if (joint_count <= 0) throw Error("must be positive", at_field("LodSpheresJob.joint_count"));
  if (spheres.size() % kBodyPartCount != 0)
    throw Error("size must be a multiple of 5", at_field("LodSpheresJob.spheres"));
  const Index n = character_count();
  check_length("LodSpheresJob", "joint_positions", joint_positions.size(), n * joint_count);
  if (!scales.empty()) check_length("LodSpheresJob", "scales", scales.size(), n);
  for (int p = 0; p < kBodyPartCount; ++p) {
    const SphereAnchor& a = anchors[at(p)];
    if (a.joint_a < 0 || a.joint_a >= joint_count || a.joint_b < 0 || a.joint_b >= joint_count)
      throw Error("joint out of range",
                  at_field(std::string("LodSpheresJob.anchors.") + to_string(static_cast<BodyPart>(p))));
  }
}

LodJob make_lod_job(const Camera& camera, const LodTables& tables, const BodyParts& parts, const CharacterRoots& roots,
                    Span<std::uint8_t> levels, Span<std::uint32_t> joint_masks) {
  LodJob job;
  job.camera = make_camera_view(camera);
  job.roots = roots;
  job.template_spheres = parts.rest_spheres;
  job.set_tables(tables);
  job.levels = levels;
  job.joint_masks = joint_masks;
  return job;
}

void LodJob::set_tables(const LodTables& tables) {
  thresholds = tables.thresholds.span();
  part_masks = tables.masks.span();
  level_count = tables.level_count;
  mask_words = tables.mask_words;
  cull_outside_view = tables.cull_outside_view;
}

void LodJob::validate() const {
  if (!(camera.focal_px > 0.0f && camera.width >= 1.0f && camera.height >= 1.0f))
    throw Error("focal length and viewport must be positive", at_field("LodJob.camera"));
  if (level_count < 1 || level_count > kMaxLodLevels)
    throw Error("must be in [1, " + std::to_string(kMaxLodLevels) + "]", at_field("LodJob.level_count"));
  if (mask_words < 1 || mask_words > mask_word_count(kMaxLodJoints))
    throw Error("must be in [1, " + std::to_string(mask_word_count(kMaxLodJoints)) + "]",
                at_field("LodJob.mask_words"));
  check_length("LodJob", "thresholds", thresholds.size(), static_cast<Index>(kBodyPartCount) * (level_count - 1));
  check_length("LodJob", "part_masks", part_masks.size(),
               static_cast<Index>(kBodyPartCount) * level_count * mask_words);
  if (levels.size() % kBodyPartCount != 0) throw Error("size must be a multiple of 5", at_field("LodJob.levels"));
  const Index n = character_count();
  check_length("LodJob", "joint_masks", joint_masks.size(), n * mask_words);
  if (!coverage.empty()) check_length("LodJob", "coverage", coverage.size(), n * kBodyPartCount);
  const bool from_roots = !roots.positions.empty() || !roots.headings.empty();
  if (from_roots == !spheres.empty())
    throw Error("give either spheres or roots.positions and roots.headings, not both or neither",
                at_field("LodJob.spheres"));
  if (from_roots) {
    check_length("LodJob", "roots.positions", roots.positions.size(), n);
    check_length("LodJob", "roots.headings", roots.headings.size(), n);
    if (!roots.scales.empty()) check_length("LodJob", "roots.scales", roots.scales.size(), n);
  } else {
    check_length("LodJob", "spheres", spheres.size(), n * kBodyPartCount);
  }
}

MaskedPose synthesise_with_mask(const motion::Skeleton& skeleton, Span<const std::uint32_t> mask,
                                const std::function<glm::quat(std::int32_t)>& local_rotation, glm::vec3 root_position,
                                Span<const glm::quat> held_rotations) {
  skeleton.validate();
  const std::int32_t J = skeleton.joint_count();
  check_length("synthesise_with_mask", "mask", mask.size(), mask_word_count(J));
  if (!held_rotations.empty()) check_length("synthesise_with_mask", "held_rotations", held_rotations.size(), J);
  MaskedPose out;
  out.positions.resize(at(J));
  out.rotations.resize(at(J));
  out.evaluated = masked_pose(J, skeleton.parents.data(), skeleton.offsets.data(), mask.data(), local_rotation,
                              held_rotations.empty() ? nullptr : held_rotations.data(), root_position,
                              out.positions.data(), out.rotations.data());
  return out;
}

}  // namespace throng::anim
