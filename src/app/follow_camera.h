// The camera of `throng run --render`: it follows the crowd, framing the
// active agents as they move.
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "core/camera.h"
#include "sim/simulation.h"

namespace throng::app {

// Nominal standing height of a character (the default mannequin's), m.
constexpr float kCharacterHeight = 1.75f;

// Median height in pixels of the active agents whose feet are in the
// picture, as a character kCharacterHeight tall standing there; 0 when none is.
float median_character_px(const Camera& camera, const sim::Simulation& sim);

// A camera that keeps the scenario camera's viewing direction and field of
// view but aims at the active agents and comes just close enough to frame
// them, eased so the view glides rather than jumps: `throng run --render`
// uses it unless told otherwise. It never stands so far that a character
// would be under `min_character_px` tall: a crowd too wide for that (the
// circle's ring of a few hundred agents) is seen in part, around the agent
// nearest its middle, rather than whole as dots; the crowd converging at the
// centre then fills the frame. As the camera of the locomotion stage it is
// also what joint LOD measures with.
class FollowCamera {
 public:
  // ease_seconds: simulated seconds to close about 63% of the way to a new framing.
  FollowCamera(const Camera& view, double ease_seconds, float min_character_px = 45.0f);
  Camera at(const sim::Simulation& sim, double t);

 private:
  Camera view_;
  glm::vec3 direction_{0.0f, 0.0f, 1.0f};  // from the target towards the camera, unit
  double ease_seconds_ = 1.0;
  float min_character_px_ = 45.0f;
  Index focus_ = -1;  // the agent aimed at when the crowd is too wide to frame whole
  Index focus_agent(const std::vector<glm::vec2>& positions, const std::vector<std::uint8_t>& flags, glm::vec2 middle);
  bool started_ = false;
  double last_t_ = 0.0;
  glm::vec3 target_{0.0f};
  float distance_ = 10.0f;
};

}  // namespace throng::app
