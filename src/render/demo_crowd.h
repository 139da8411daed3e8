// A crowd to look at before the simulation and locomotion stages feed the
// renderer: N characters of the default skeleton, each playing a clip of
// the default motion set (idle, walks, runs) at its own phase, placed on a
// grid (walking straight, wrapping round the grid's extent) or on
// concentric rings (walking round them at the clip's speed). Poses come
// from the joint-LOD pose stage (anim::masked_pose), so coarse LOD
// levels visibly hold joints still.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/buffer.h"
#include "motion/skeleton.h"
#include "render/scene.h"

namespace throng::render {

enum class DemoLayout : std::uint8_t { Grid, Ring };
const char* to_string(DemoLayout l);
DemoLayout parse_demo_layout(const std::string& text, const std::string& field);  // "grid" | "ring"

struct DemoCrowdSpec {
  Index characters = 100;
  DemoLayout layout = DemoLayout::Ring;
  float spacing = 1.6f;      // metres between neighbours
  std::uint64_t seed = 1;    // clip choice, phases, headings
  float idle_fraction = 0.1f;
  void validate() const;     // Error naming the field ("demo.characters")
};

class DemoCrowd {
 public:
  // Builds the default skeleton and motion set (a second or so) in
  // current_memory().
  explicit DemoCrowd(const DemoCrowdSpec& spec);
  ~DemoCrowd();
  DemoCrowd(DemoCrowd&&) noexcept;
  DemoCrowd& operator=(DemoCrowd&&) noexcept;

  const DemoCrowdSpec& spec() const;
  const motion::Skeleton& skeleton() const;
  Index character_count() const;
  std::int32_t joint_count() const;

  // Poses at `seconds`. joint_masks: characters * anim::mask_word_count(J)
  // from the LOD stage, or empty to synthesise every joint.
  void update(double seconds, Span<const std::uint32_t> joint_masks = {});

  // After update(): world-space joint frames (LOD levels left empty).
  CharacterPoses poses() const;
  // Where each character stands on the ground (world, y = 0) and its yaw
  // about +Y: the root transform anim::LodJob takes.
  Span<const glm::vec3> ground_positions() const;
  Span<const float> yaws() const;
  // A ground point and radius that hold the whole crowd (for cameras).
  glm::vec3 centre() const;
  float extent() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace throng::render
