// throng animate [FILE|NAME]: characters in a formation animated by the
// locomotion stage alone (speed blend, root motion, joint LOD under an
// orbiting camera, motion cache), without the crowd simulation. Prints a
// summary and writes DIR/stats.json: locomotion timings, the joint-LOD
// histogram, cache counters and the foot skating measured on some characters.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "anim/crowd_animator.h"
#include "app/commands.h"
#include "app/formation.h"
#include "app/locomotion_stats.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/math.h"
#include "core/memory_budget.h"
#include "core/timing.h"
#include "io/animate_yaml.h"
#include "io/run_outputs.h"
#include "motion/locomotion.h"

namespace throng::app {

namespace {

namespace fs = std::filesystem;

template <class T>
std::vector<T> to_host(Span<const T> s) {
  std::vector<T> out(static_cast<std::size_t>(s.size()));
  copy_to_host(s, std::span<T>(out));
  return out;
}

// Foot skating: tracks spec.skating_characters of the n characters (at most
// n), spread evenly over their indices; returns their indices.
std::vector<Index> track_skating(anim::CrowdAnimator& crowd, const io::AnimateSpec& spec, Index n) {
  std::vector<Index> tracked;
  const auto skating = std::min<Index>(spec.skating_characters, n);
  for (Index k = 0; k < skating; ++k) tracked.push_back(k * n / skating);
  crowd.track(tracked);
  return tracked;
}

// The run: `frames` frames of dt seconds under the orbiting camera (its
// radius, else the formation's extent + 15 m), each frame's locomotion
// time (ms) and stats into `tally`; progress logged every 2 s.
void animate_frames(FormationCrowd& formation_crowd, const io::AnimateSpec& spec, float dt, std::int64_t frames,
                    LocomotionTally& tally) {
  Camera lens;
  lens.width = spec.width;
  lens.height = spec.height;
  lens.fov_y = spec.camera_fov_deg * kPiF / 180.0f;
  lens.far_plane = 10000.0f;
  CameraOrbit orbit;
  orbit.radius = spec.camera_radius > 0.0f ? spec.camera_radius : formation_crowd.formation().extent + 15.0f;
  orbit.height = spec.camera_elevation;
  orbit.angular_speed = spec.camera_angular_speed;

  KernelTimings::global().reset();
  auto last_report = std::chrono::steady_clock::now();
  for (std::int64_t f = 0; f < frames; ++f) {
    const Camera camera = orbit_camera(orbit, lens, static_cast<float>(f) * dt);
    const auto t0 = std::chrono::steady_clock::now();
    const anim::FrameStats& s = formation_crowd.advance(dt, spec.lod ? &camera : nullptr);
    tally.add(s, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report > std::chrono::seconds(2)) {
      spdlog::info("frame {}/{} ({:.0f}%)", f + 1, frames,
                   100.0 * static_cast<double>(f + 1) / static_cast<double>(frames));
      last_report = now;
    }
  }
}

// How far anyone strayed from the circle it walks round (m); 0 for a grid.
double max_ring_drift(const io::AnimateSpec& spec, const anim::CrowdAnimator& crowd, const Formation& formation) {
  double drift = 0.0;
  if (spec.shape == io::AnimateSpec::Shape::Circle) {
    const std::vector<glm::vec3> at = to_host(crowd.positions());
    for (std::size_t i = 0; i < at.size(); ++i)
      drift = std::max(drift, std::abs(static_cast<double>(std::hypot(at[i].x, at[i].z)) - formation.rings[i]));
  }
  return drift;
}

// What the run measured: the foot skating of the tracked characters and the
// largest drift from a ring (m).
struct AnimateMeasures {
  motion::FootSkatingReport skate;
  std::size_t tracked = 0;
  double drift = 0.0;
};

// stats.json: the scenario, counts, frame times (ms), timings, joints
// synthesised, joint LOD, cache, foot skating (cm) and the formation's drift.
nlohmann::json animate_stats(const io::AnimateSpec& spec, const motion::BlendSpace1D& space, anim::CrowdAnimator& crowd,
                             const LocomotionTally& tally, std::int64_t frames, float dt, const AnimateMeasures& m) {
  const Index n = spec.characters;
  const nlohmann::json frame_ms = tally.frame_ms_json();
  const double median = frame_ms["median"].get<double>();
  nlohmann::json stats;
  stats["scenario"] = {{"name", spec.name},
                       {"source", spec.source},
                       {"shape", spec.shape == io::AnimateSpec::Shape::Circle ? "circle" : "grid"}};
  stats["characters"] = n;
  stats["joints"] = space.joint_count();
  stats["frames"] = frames;
  stats["dt"] = dt;
  stats["mode"] = spec.paper_mode ? "paper" : "continuous";
  stats["backend"] = to_string(current_backend());
  stats["threads"] = current_threads();
  nlohmann::json clips = nlohmann::json::array();
  for (const motion::LocomotionClip& c : space.clips())
    clips.push_back({{"name", c.name},
                     {"speed_mps", c.speed},
                     {"stride_m", c.stride_m},
                     {"period_s", c.period_s},
                     {"frames", c.frame_count()}});
  stats["blend_space"] = clips;
  stats["frame_ms"] = frame_ms;
  stats["characters_per_second"] = median > 0.0 ? static_cast<double>(n) / (median / 1000.0) : 0.0;
  stats["timings"] = nlohmann::json::parse(KernelTimings::global().json());
  stats["joints_synthesised_per_character"] = static_cast<double>(tally.joints_synthesised) / tally.character_frames();
  if (nlohmann::json lod = tally.lod_json(crowd, spec.lod_thresholds); !lod.is_null()) stats["lod"] = lod;
  if (nlohmann::json cache = tally.cache_json(crowd); !cache.is_null()) {
    const anim::QuantisationError q = crowd.cache()->quantisation_error();
    cache["quantisation_error_deg"] = {{"max", q.max_deg}, {"mean", q.mean_deg}};
    stats["cache"] = cache;
  }
  stats["foot_skating_cm"] = {{"mean", m.skate.mean_cm},
                              {"p95", m.skate.p95_cm},
                              {"max", m.skate.max_cm},
                              {"contacts", m.skate.contacts},
                              {"characters", m.tracked}};
  if (spec.shape == io::AnimateSpec::Shape::Circle) stats["formation"] = {{"max_drift_from_ring_m", m.drift}};
  return stats;
}

// Writes out_dir/stats.json (the folder made if missing); returns its path.
fs::path write_stats(const std::string& out_dir, const nlohmann::json& stats) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir))
    throw Error("cannot create folder: " + (ec ? ec.message() : std::string("not a folder")), at_line(out_dir, 0));
  const fs::path json_path = fs::path(out_dir) / "stats.json";
  io::write_json_file(json_path.string(), stats);
  return json_path;
}

// The summary on stdout, from stats.json's content and the measures.
void print_animate_summary(const io::AnimateSpec& spec, const motion::BlendSpace1D& space, const LocomotionTally& tally,
                           std::int64_t frames, const nlohmann::json& stats, const AnimateMeasures& m,
                           const fs::path& json_path) {
  const Index n = spec.characters;
  const double median = stats["frame_ms"]["median"].get<double>();
  const double mean = stats["frame_ms"]["mean"].get<double>();
  std::printf("%s: %lld characters, %d joints, %lld frames at %g fps (%s mode, %s, %d threads)\n", spec.name.c_str(),
              static_cast<long long>(n), space.joint_count(), static_cast<long long>(frames),
              static_cast<double>(spec.fps), spec.paper_mode ? "paper" : "continuous", to_string(current_backend()),
              current_threads());
  std::printf("  locomotion frame: median %.3f ms, mean %.3f ms (%.3g characters/s)\n", median, mean,
              static_cast<double>(stats["characters_per_second"]));
  std::printf("  joints synthesised: %.1f of %d per character%s\n",
              static_cast<double>(tally.joints_synthesised) / tally.character_frames(), space.joint_count(),
              spec.lod ? " (joint LOD)" : "");
  if (stats.contains("cache"))
    std::printf(
        "  cache: %.1f%% hits, %lld cycles held (%.2f MB), %lld evictions, quantisation error max %.2f deg, mean %.3f "
        "deg\n",
        100.0 * static_cast<double>(stats["cache"]["hit_rate"]), static_cast<long long>(stats["cache"]["entries"]),
        static_cast<double>(stats["cache"]["bytes"]) / (1024.0 * 1024.0),
        static_cast<long long>(stats["cache"]["evictions"]),
        static_cast<double>(stats["cache"]["quantisation_error_deg"]["max"]),
        static_cast<double>(stats["cache"]["quantisation_error_deg"]["mean"]));
  std::printf("  foot skating: %s of %zu characters\n", motion::describe(m.skate).c_str(), m.tracked);
  if (spec.shape == io::AnimateSpec::Shape::Circle)
    std::printf("  formation: largest drift from a ring %.2g m\n", m.drift);
  std::printf("  wrote %s\n", json_path.string().c_str());
}

void animate(io::AnimateSpec spec, const fs::path& folder, const std::string& out_override, float duration_override,
             std::int64_t characters_override) {
  if (duration_override > 0.0f) spec.duration_s = duration_override;
  if (characters_override > 0) spec.characters = characters_override;
  const std::string out_dir = out_override.empty() ? spec.output : out_override;
  check_memory_budget(static_cast<double>(spec.characters) * kLocomotionBytesPerAgent,
                      fmt::format("{} characters", spec.characters),
                      characters_override > 0 ? "--characters" : "characters");

  FormationCrowd formation_crowd(spec, folder);  // blend space, formation, speeds drawn from the seed
  const motion::BlendSpace1D& space = formation_crowd.space();
  anim::CrowdAnimator& crowd = formation_crowd.animator();
  const Index n = spec.characters;
  const std::vector<Index> tracked = track_skating(crowd, spec, n);

  const float dt = 1.0f / spec.fps;
  const auto frames = std::max<std::int64_t>(1, std::llround(static_cast<double>(spec.duration_s) * spec.fps));
  spdlog::info("animating {} characters ({} joints, {} clips, {} mode) for {} frames at {} fps", n, space.joint_count(),
               space.clip_count(), spec.paper_mode ? "paper" : "continuous", frames, spec.fps);
  LocomotionTally tally;
  animate_frames(formation_crowd, spec, dt, frames, tally);

  AnimateMeasures m;
  m.drift = max_ring_drift(spec, crowd, formation_crowd.formation());
  m.skate = crowd.foot_skating();
  m.tracked = tracked.size();
  const nlohmann::json stats = animate_stats(spec, space, crowd, tally, frames, dt, m);
  const fs::path json_path = write_stats(out_dir, stats);
  print_animate_summary(spec, space, tally, frames, stats, m, json_path);
}

}  // namespace

void add_animate_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand(
      "animate", "Animate characters in a formation with the locomotion stage alone (no crowd simulation)");
  static std::string scenario = "formation";
  static std::string out_dir;
  static float duration = 0.0f;
  static std::int64_t characters = 0;
  cmd->add_option("scenario", scenario, "Scenario YAML file or built-in name (formation)");
  cmd->add_option("--out", out_dir, "Folder for stats.json (default: the scenario's output)");
  cmd->add_option("--duration", duration, "Seconds to animate (overrides the scenario)")->check(greater_than(0));
  cmd->add_option("--characters", characters, "How many characters (overrides the scenario)")->check(between(1, 1e7));
  cmd->callback([&g] {
    fs::path folder;
    io::AnimateSpec spec = load_animate_spec(scenario, folder);  // a bad name fails before any backend talk
    apply_global_options(g);
    animate(std::move(spec), folder, out_dir, duration, characters);
  });
}

}  // namespace throng::app
