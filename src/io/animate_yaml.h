// `throng animate` scenarios: characters in a formation animated by the
// locomotion stage alone (no crowd simulation), as YAML. The schema, with
// every key optional and its default, is examples/animate/formation.yaml and
// docs/locomotion.md. Errors name file:line:column and the key.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/motion_set.h"

namespace throng::io {

struct AnimateSpec {
  std::string name = "formation_circle";
  std::string source;  // the file read, or "built-in"
  std::int64_t characters = 1000;

  enum class Shape : std::uint8_t { Circle, Grid };
  Shape shape = Shape::Circle;
  float radius = 12.0f;       // m: the innermost ring (circle)
  float ring_spacing = 1.6f;  // m between rings (circle)
  float spacing = 1.3f;       // m between neighbours on a ring, or on the grid
  bool clockwise = false;     // circle: walking direction seen from above

  float speed_min = 0.8f;  // m/s, each character draws its own
  float speed_max = 2.4f;
  float change_every_s = 5.0f;  // redraw speeds this often (0: never)
  float scale_min = 1.0f;       // uniform scale per character
  float scale_max = 1.0f;

  MotionSetSpec motion;     // io/motion_set.h; default: the built-in set
  bool paper_mode = false;  // mode: paper (w changes at cycle ends) | continuous

  float duration_s = 10.0f;
  float fps = 60.0f;
  std::uint32_t seed = 1;

  float camera_radius = 0.0f;         // m from the centre; 0: just outside the formation
  float camera_elevation = 14.0f;     // m
  float camera_angular_speed = 0.1f;  // rad/s
  float camera_fov_deg = 50.0f;
  std::int32_t width = 1920;
  std::int32_t height = 1080;

  bool lod = true;
  std::vector<float> lod_thresholds{1000.0f, 30.0f};  // square pixels, decreasing
  bool cache = true;
  float bucket_width = 0.05f;
  float cache_capacity_mb = 20.0f;
  std::int32_t skating_characters = 16;  // characters whose foot skating is measured

  std::string output = "out/formation_circle";  // folder for stats.json
  bool operator==(const AnimateSpec&) const = default;
};

// Reads a scenario file; paths inside stay relative to its folder (resolved
// by the caller with the file's folder). Error with file:line:column.
AnimateSpec read_animate_spec(const std::string& path);
AnimateSpec parse_animate_spec(std::string_view text, const std::string& name);

// Built-in scenarios by name: "formation" (the same as examples/animate/formation.yaml).
std::vector<std::string> builtin_animate_specs();
AnimateSpec builtin_animate_spec(std::string_view name);  // Error for an unknown name

}  // namespace throng::io
