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
#include <random>
#include <string>
#include <vector>

#include "anim/locomotion.h"
#include "app/commands.h"
#include "core/camera.h"
#include "core/error.h"
#include "core/timing.h"
#include "io/animate_yaml.h"
#include "io/bvh_reader.h"
#include "motion/locomotion.h"

namespace throng::app {

namespace {

namespace fs = std::filesystem;
constexpr float kPi = std::numbers::pi_v<float>;

template <class T>
std::vector<T> to_host(Span<const T> s) {
  std::vector<T> out(static_cast<std::size_t>(s.size()));
  if (s.size() > 0) detail::copy_bytes(out.data(), Memory::Host, s.data(), current_memory(), out.size() * sizeof(T));
  return out;
}

io::AnimateSpec load_spec(const std::string& what, fs::path& folder) {
  std::error_code ec;
  if (fs::is_regular_file(what, ec)) {
    folder = fs::path(what).parent_path();
    return io::read_animate_spec(what);
  }
  std::string list;
  for (const std::string& name : io::builtin_animate_specs()) {
    if (what == name) return io::builtin_animate_spec(name);
    list += (list.empty() ? "" : ", ") + name;
  }
  throw Error("no such file or built-in scenario '" + what + "' (built-in: " + list + ")", at_field("scenario"));
}

motion::BlendSpace1D load_blend_space(const io::AnimateSpec& spec, const fs::path& folder) {
  if (spec.clips.empty()) return motion::make_default_blend_space();
  std::vector<motion::LocomotionClip> clips;
  motion::Skeleton skeleton;
  for (std::size_t i = 0; i < spec.clips.size(); ++i) {
    const io::AnimateClipSource& src = spec.clips[i];
    const fs::path path = fs::path(src.file).is_absolute() ? fs::path(src.file) : folder / src.file;
    const io::BvhFile file = io::read_bvh(path.string());
    if (i == 0) skeleton = file.skeleton;
    else if (file.skeleton.joint_count() != skeleton.joint_count())
      throw Error("has " + std::to_string(file.skeleton.joint_count()) + " joints, the first clip " + std::to_string(skeleton.joint_count()) +
                      ": clips of a blend space share one skeleton",
                  at_field("motion[" + std::to_string(i) + "]", spec.source));
    motion::LocomotionOptions options;
    options.cycle.skip_frames = src.skip_frames;
    clips.push_back(motion::prepare_locomotion_clip(skeleton, file.clip, src.name, options));
    spdlog::info("{}: cycle of {} frames, {:.2f} m/s, stride {:.2f} m", src.name, clips.back().frame_count(), clips.back().speed,
                 clips.back().stride_m);
  }
  return motion::BlendSpace1D(std::move(skeleton), std::move(clips));
}

// Where everyone stands, faces and turns.
struct Formation {
  std::vector<glm::vec3> positions;
  std::vector<float> yaws, curvatures, rings;  // rings: the circle each keeps to (0 on the grid)
  float extent = 0.0f;                         // m from the centre to the farthest character
};

Formation make_formation(const io::AnimateSpec& s) {
  Formation f;
  const auto n = static_cast<std::size_t>(s.characters);
  if (s.shape == io::AnimateSpec::Shape::Circle) {
    // Rings outward from `radius`, each as full as the spacing allows; the
    // last ring holds the rest, evenly spread.
    std::size_t placed = 0;
    for (int ring = 0; placed < n; ++ring) {
      const float r = s.radius + static_cast<float>(ring) * s.ring_spacing;
      const auto capacity = std::max<std::size_t>(1, static_cast<std::size_t>(2.0f * kPi * r / s.spacing));
      const std::size_t here = std::min(capacity, n - placed);
      for (std::size_t k = 0; k < here; ++k) {
        const float a = 2.0f * kPi * (static_cast<float>(k) + 0.5f * static_cast<float>(ring % 2)) / static_cast<float>(here);
        // Counter-clockwise seen from above: angle a at (cos a, -sin a) in XZ,
        // walking along (-sin a, -cos a), a left turn of curvature 1 / r.
        f.positions.emplace_back(r * std::cos(a), 0.0f, -r * std::sin(a));
        f.yaws.push_back(s.clockwise ? a : a + kPi);
        f.curvatures.push_back(s.clockwise ? -1.0f / r : 1.0f / r);
        f.rings.push_back(r);
      }
      placed += here;
      f.extent = r;
    }
  } else {
    const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
    const float half = 0.5f * s.spacing * static_cast<float>(side - 1);
    for (std::size_t i = 0; i < n; ++i) {
      f.positions.emplace_back(s.spacing * static_cast<float>(i % side) - half, 0.0f, s.spacing * static_cast<float>(i / side) - half);
      f.yaws.push_back(0.0f);
      f.curvatures.push_back(0.0f);
      f.rings.push_back(0.0f);
    }
    f.extent = half * std::numbers::sqrt2_v<float>;
  }
  return f;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::clamp<std::size_t>(rank, 1, v.size()) - 1];
}

void animate(io::AnimateSpec spec, const fs::path& folder, const std::string& out_override, float duration_override,
             std::int64_t characters_override) {
  if (duration_override > 0.0f) spec.duration_s = duration_override;
  if (characters_override > 0) spec.characters = characters_override;
  const std::string out_dir = out_override.empty() ? spec.output : out_override;

  const motion::BlendSpace1D space = load_blend_space(spec, folder);
  const Formation formation = make_formation(spec);
  const Index n = spec.characters;

  anim::CrowdAnimatorConfig config;
  config.hold_until_cycle_end = spec.paper_mode;
  config.lod = spec.lod;
  config.lod_thresholds = spec.lod_thresholds;
  config.cache = spec.cache;
  config.cache_config.bucket_width = spec.bucket_width;
  config.cache_config.capacity_bytes = static_cast<std::size_t>(static_cast<double>(spec.cache_capacity_mb) * 1024.0 * 1024.0);
  anim::CrowdAnimator crowd(space, n, config);

  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> scales(static_cast<std::size_t>(n)), phases(static_cast<std::size_t>(n)), speeds(static_cast<std::size_t>(n));
  for (float& x : scales) x = spec.scale_min + (spec.scale_max - spec.scale_min) * unit(rng);
  for (float& x : phases) x = unit(rng);
  const auto draw_speeds = [&] {
    for (float& v : speeds) v = spec.speed_min + (spec.speed_max - spec.speed_min) * unit(rng);
    crowd.set_speeds(speeds);
  };
  crowd.place(formation.positions, formation.yaws, scales, phases);
  crowd.set_curvatures(formation.curvatures);
  draw_speeds();
  std::vector<Index> tracked;
  const auto skating = std::min<Index>(spec.skating_characters, n);
  for (Index k = 0; k < skating; ++k) tracked.push_back(k * n / skating);
  crowd.track(tracked);

  Camera lens;
  lens.width = spec.width;
  lens.height = spec.height;
  lens.fov_y = spec.camera_fov_deg * kPi / 180.0f;
  lens.far_plane = 10000.0f;
  CameraOrbit orbit;
  orbit.radius = spec.camera_radius > 0.0f ? spec.camera_radius : formation.extent + 15.0f;
  orbit.height = spec.camera_elevation;
  orbit.angular_speed = spec.camera_angular_speed;

  const float dt = 1.0f / spec.fps;
  const auto frames = std::max<std::int64_t>(1, std::llround(static_cast<double>(spec.duration_s) * spec.fps));
  const auto frames_per_speed = spec.change_every_s > 0.0f ? std::max<std::int64_t>(1, std::llround(spec.change_every_s * spec.fps)) : 0;
  spdlog::info("animating {} characters ({} joints, {} clips, {} mode) for {} frames at {} fps", n, space.joint_count(), space.clip_count(),
               spec.paper_mode ? "paper" : "continuous", frames, spec.fps);

  KernelTimings::global().reset();
  std::vector<double> frame_ms;
  std::vector<Index> level_counts, joints_histogram;
  Index joints_total = 0, from_cache = 0;
  std::int64_t stored = 0;
  auto last_report = std::chrono::steady_clock::now();
  for (std::int64_t f = 0; f < frames; ++f) {
    if (frames_per_speed > 0 && f > 0 && f % frames_per_speed == 0) draw_speeds();
    const Camera camera = orbit_camera(orbit, lens, static_cast<float>(f) * dt);
    const auto t0 = std::chrono::steady_clock::now();
    const anim::FrameStats& s = crowd.animate({dt, spec.lod ? &camera : nullptr, true});
    frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    joints_total += s.joints_synthesised;
    from_cache += s.from_cache;
    stored += s.cycles_stored;
    if (s.lod) {
      if (level_counts.empty()) {
        level_counts.assign(s.lod->level_counts.size(), 0);
        joints_histogram.assign(s.lod->joints_synthesised.size(), 0);
      }
      for (std::size_t i = 0; i < level_counts.size(); ++i) level_counts[i] += s.lod->level_counts[i];
      for (std::size_t i = 0; i < joints_histogram.size(); ++i) joints_histogram[i] += s.lod->joints_synthesised[i];
    }
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report > std::chrono::seconds(2)) {
      spdlog::info("frame {}/{} ({:.0f}%)", f + 1, frames, 100.0 * static_cast<double>(f + 1) / static_cast<double>(frames));
      last_report = now;
    }
  }

  // How far anyone strayed from the circle it walks round.
  double drift = 0.0;
  if (spec.shape == io::AnimateSpec::Shape::Circle) {
    const std::vector<glm::vec3> at = to_host(crowd.positions());
    for (std::size_t i = 0; i < at.size(); ++i)
      drift = std::max(drift, std::abs(static_cast<double>(std::hypot(at[i].x, at[i].z)) - formation.rings[i]));
  }
  const motion::FootSkatingReport skate = crowd.foot_skating();
  const double median = percentile(frame_ms, 0.5);
  double mean = 0.0;
  for (double m : frame_ms) mean += m / static_cast<double>(frame_ms.size());
  const double character_frames = static_cast<double>(n) * static_cast<double>(frames);

  nlohmann::json stats;
  stats["scenario"] = {{"name", spec.name}, {"source", spec.source}, {"shape", spec.shape == io::AnimateSpec::Shape::Circle ? "circle" : "grid"}};
  stats["characters"] = n;
  stats["joints"] = space.joint_count();
  stats["frames"] = frames;
  stats["dt"] = dt;
  stats["mode"] = spec.paper_mode ? "paper" : "continuous";
  stats["backend"] = to_string(current_backend());
  stats["threads"] = current_threads();
  nlohmann::json clips = nlohmann::json::array();
  for (const motion::LocomotionClip& c : space.clips())
    clips.push_back({{"name", c.name}, {"speed_mps", c.speed}, {"stride_m", c.stride_m}, {"period_s", c.period_s}, {"frames", c.frame_count()}});
  stats["blend_space"] = clips;
  stats["frame_ms"] = {{"median", median}, {"mean", mean}, {"p95", percentile(frame_ms, 0.95)},
                       {"max", *std::max_element(frame_ms.begin(), frame_ms.end())}};
  stats["characters_per_second"] = median > 0.0 ? static_cast<double>(n) / (median / 1000.0) : 0.0;
  stats["timings"] = nlohmann::json::parse(KernelTimings::global().json());
  stats["joints_synthesised_per_character"] = static_cast<double>(joints_total) / character_frames;
  if (!level_counts.empty()) {
    const anim::LodConfig& lod = *crowd.lod_config();
    nlohmann::json parts;
    for (anim::BodyPart p : anim::kAllBodyParts) {
      std::vector<Index> levels;
      for (int l = 0; l < lod.level_count; ++l) levels.push_back(level_counts[static_cast<std::size_t>(static_cast<int>(p) * lod.level_count + l)]);
      parts[anim::to_string(p)] = levels;
    }
    stats["lod"] = {{"thresholds_px2", spec.lod_thresholds},
                    {"levels", lod.level_count},
                    {"character_frames_per_level", parts},
                    {"joints_synthesised_histogram", joints_histogram}};
  }
  if (const anim::CycleCacheTable* cache = crowd.cache()) {
    const anim::MotionCacheStats& c = cache->cache().stats();
    const anim::QuantisationError q = cache->quantisation_error();
    stats["cache"] = {{"bucket_width", spec.bucket_width},
                      {"capacity_bytes", cache->cache().config().capacity_bytes},
                      {"hits", c.hits},
                      {"misses", c.misses},
                      {"insertions", c.insertions},
                      {"evictions", c.evictions},
                      {"bytes", c.bytes},
                      {"entries", c.entries},
                      {"hit_rate", c.hit_rate()},
                      {"from_cache_fraction", static_cast<double>(from_cache) / character_frames},
                      {"quantisation_error_deg", {{"max", q.max_deg}, {"mean", q.mean_deg}}}};
  }
  stats["foot_skating_cm"] = {{"mean", skate.mean_cm}, {"p95", skate.p95_cm}, {"max", skate.max_cm}, {"contacts", skate.contacts},
                              {"characters", tracked.size()}};
  if (spec.shape == io::AnimateSpec::Shape::Circle) stats["formation"] = {{"max_drift_from_ring_m", drift}};

  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) throw Error("cannot create folder: " + (ec ? ec.message() : std::string("not a folder")), at_line(out_dir, 0));
  const fs::path json_path = fs::path(out_dir) / "stats.json";
  std::ofstream out(json_path, std::ios::binary);
  out << stats.dump(2) << "\n";
  out.close();
  if (!out) throw Error("cannot write stats.json", at_line(json_path.string(), 0));

  std::printf("%s: %lld characters, %d joints, %lld frames at %g fps (%s mode, %s, %d threads)\n", spec.name.c_str(),
              static_cast<long long>(n), space.joint_count(), static_cast<long long>(frames), static_cast<double>(spec.fps),
              spec.paper_mode ? "paper" : "continuous", to_string(current_backend()), current_threads());
  std::printf("  locomotion frame: median %.3f ms, mean %.3f ms (%.3g characters/s)\n", median, mean,
              static_cast<double>(stats["characters_per_second"]));
  std::printf("  joints synthesised: %.1f of %d per character%s\n", static_cast<double>(joints_total) / character_frames, space.joint_count(),
              spec.lod ? " (joint LOD)" : "");
  if (stats.contains("cache"))
    std::printf("  cache: %.1f%% hits, %lld cycles held (%.2f MB), %lld evictions, quantisation error max %.2f deg, mean %.3f deg\n",
                100.0 * static_cast<double>(stats["cache"]["hit_rate"]), static_cast<long long>(stats["cache"]["entries"]),
                static_cast<double>(stats["cache"]["bytes"]) / (1024.0 * 1024.0), static_cast<long long>(stats["cache"]["evictions"]),
                static_cast<double>(stats["cache"]["quantisation_error_deg"]["max"]),
                static_cast<double>(stats["cache"]["quantisation_error_deg"]["mean"]));
  std::printf("  foot skating: mean %.2f cm, p95 %.2f cm over %d contacts of %zu characters\n", skate.mean_cm, skate.p95_cm, skate.contacts,
              tracked.size());
  if (spec.shape == io::AnimateSpec::Shape::Circle) std::printf("  formation: largest drift from a ring %.2g m\n", drift);
  std::printf("  wrote %s\n", json_path.string().c_str());
}

}  // namespace

void add_animate_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("animate", "Animate characters in a formation with the locomotion stage alone (no crowd simulation)");
  static std::string scenario = "formation";
  static std::string out_dir;
  static float duration = 0.0f;
  static std::int64_t characters = 0;
  cmd->add_option("scenario", scenario, "Scenario YAML file or built-in name (formation)");
  cmd->add_option("--out", out_dir, "Folder for stats.json (default: the scenario's output)");
  cmd->add_option("--duration", duration, "Seconds to animate (overrides the scenario)")->check(CLI::PositiveNumber);
  cmd->add_option("--characters", characters, "How many characters (overrides the scenario)")->check(CLI::Range(std::int64_t{1}, std::int64_t{10'000'000}));
  cmd->callback([&g] {
    fs::path folder;
    io::AnimateSpec spec = load_spec(scenario, folder);  // a bad name fails before any backend talk
    apply_global_options(g);
    animate(std::move(spec), folder, out_dir, duration, characters);
  });
}

}  // namespace throng::app
