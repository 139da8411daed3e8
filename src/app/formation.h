// Characters in a formation (rings or a grid) animated by the locomotion
// stage alone, as the animate scenarios describe them (io/animate_yaml.h):
// what `throng animate` measures and `throng view formation` shows.
#pragma once

#include <cstdint>
#include <filesystem>
#include <glm/vec3.hpp>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "anim/crowd_animator.h"
#include "core/camera.h"
#include "io/animate_yaml.h"
#include "motion/locomotion.h"

namespace throng::app {

// A scenario file, or a built-in name; `folder` receives the file's folder
// (clip paths are relative to it). Error naming "scenario" otherwise.
io::AnimateSpec load_animate_spec(const std::string& what, std::filesystem::path& folder);

// Where everyone stands, faces and turns.
struct Formation {
  std::vector<glm::vec3> positions;
  std::vector<float> yaws, curvatures, rings;  // rings: the circle each keeps to (0 on the grid)
  float extent = 0.0f;                         // m from the centre to the farthest character
};
Formation make_formation(const io::AnimateSpec& spec);

// The blend space, the formation and the animator, with speeds drawn per
// character from the scenario's seed and redrawn every change_every_s.
class FormationCrowd {
 public:
  FormationCrowd(io::AnimateSpec spec, const std::filesystem::path& folder);
  FormationCrowd(const FormationCrowd&) = delete;
  FormationCrowd& operator=(const FormationCrowd&) = delete;

  const io::AnimateSpec& spec() const { return spec_; }
  const motion::BlendSpace1D& space() const { return space_; }
  const Formation& formation() const { return formation_; }
  anim::CrowdAnimator& animator() { return *crowd_; }
  double time() const { return time_; }

  // One frame of dt seconds (speeds redrawn first when their time is up);
  // the camera drives the joint LOD (null: every joint synthesised).
  const anim::FrameStats& advance(float dt, const Camera* camera);

 private:
  void draw_speeds();

  io::AnimateSpec spec_;
  motion::BlendSpace1D space_;
  Formation formation_;
  std::unique_ptr<anim::CrowdAnimator> crowd_;
  std::mt19937 rng_;
  std::vector<float> speeds_;
  double time_ = 0.0;
  double next_draw_ = 0.0;
};

}  // namespace throng::app
