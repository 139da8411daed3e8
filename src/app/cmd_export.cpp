// throng export-default DIR: writes the project's own motion set (the
// default skeleton and its procedural locomotion cycles) as BVH files that
// other tools (Blender, MotionBuilder) open, plus motions.json with each
// clip's targets and what the cycle analysis measures on it.
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <system_error>

#include "app/commands.h"
#include "core/error.h"
#include "io/bvh_writer.h"
#include "io/run_outputs.h"
#include "motion/cycle.h"
#include "motion/default_set.h"
#include "motion/foot_skating.h"
#include "motion/rotation.h"
#include "motion/units.h"

namespace throng::app {

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

double round_to(double v, double step) { return std::round(v / step) * step; }

nlohmann::json describe(const motion::DefaultMotion& m, const motion::Skeleton& skeleton, const std::string& file) {
  using motion::biomech::Gait;
  motion::CycleOptions options;
  if (m.spec.gait == Gait::Stand) {  // an in-place loop of several seconds
    options.min_mean_speed = 0.0;
    options.min_period_s = 0.5 * m.targets.period_s;
    options.max_period_s = 1.5 * m.targets.period_s;
  }
  options.loop = motion::CycleOptions::Loop::Always;
  const motion::CycleReport r = motion::analyze_cycle(skeleton, m.clip, options);
  // Skating over three strides sampled by the generator itself (exact).
  const motion::LocomotionGenerator generator(skeleton, m.spec);
  const motion::FootSkatingReport skate =
      motion::measure_foot_skating(skeleton, generator.sample(3 * m.clip.frame_count));
  nlohmann::json j = {{"name", m.spec.name},
                      {"file", file},
                      {"description", m.description},
                      {"gait", motion::biomech::to_string(m.spec.gait)},
                      {"frames", m.clip.frame_count},
                      {"fps", m.spec.fps},
                      {"duration_s", round_to(m.clip.frame_count / m.spec.fps, 1e-6)},
                      {"speed_mps", m.spec.speed},
                      {"turn_rate_dps", round_to(m.spec.turn_rate * kDegPerRad, 1e-6)},
                      {"cadence_spm", round_to(m.targets.cadence, 1e-3)},
                      {"target_cadence_spm", round_to(m.targets.target_cadence, 1e-3)},
                      {"stride_m", round_to(m.targets.stride_length, 1e-4)},
                      {"duty_factor", round_to(m.targets.duty_factor, 1e-4)}};
  j["measured"] = {{"found", r.found},
                   {"period_frames", r.period_frames},
                   {"cadence_spm", round_to(r.cadence, 1e-3)},
                   {"stride_m", round_to(r.stride_length, 1e-4)},
                   {"speed_mps", round_to(r.mean_speed, 1e-4)},
                   {"turn_rate_dps", round_to(r.turn_rate * kDegPerRad, 1e-3)},
                   {"foot_skating_max_cm", round_to(skate.max_cm, 1e-4)}};
  return j;
}

}  // namespace

void add_export_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd =
      app.add_subcommand("export-default", "Write the default skeleton's locomotion cycles as BVH plus motions.json");
  static std::string dir;
  static std::string order = "ZXY";
  static std::string units = "cm";
  cmd->add_option("dir", dir, "Folder to write (created if missing)")->required();
  cmd->add_option("--order", order, "Rotation order of every joint: XYZ, XZY, YXZ, YZX, ZXY or ZYX (default ZXY)");
  cmd->add_option("--units", units, "Unit of the written files: m, cm, mm, in or cmu (default cm)");
  cmd->callback([&g] {
    apply_global_options(g);
    io::BvhWriteOptions w = bvh_write_options(order, units);
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
      throw Error("cannot create folder: " + (ec ? ec.message() : std::string("not a folder")), at_line(dir, 0));

    const motion::Skeleton skeleton = motion::default_skeleton();
    const auto motions = motion::make_default_motions(skeleton);
    nlohmann::json summary = {
        {"skeleton", {{"joints", skeleton.joint_count()}, {"height_m", 1.75}, {"names", skeleton.names}}},
        {"units", motion::to_string(w.unit)},
        {"rotation_order", motion::to_string(w.order)},
        {"motions", nlohmann::json::array()}};
    for (const auto& m : motions) {
      const std::string file = m.spec.name + ".bvh";
      w.frame_time = 1.0 / m.spec.fps;
      io::write_bvh((fs::path(dir) / file).string(), skeleton, m.clip, w);
      summary["motions"].push_back(describe(m, skeleton, file));
      spdlog::info("{}: {}", file, m.description);
    }
    const fs::path json_path = fs::path(dir) / "motions.json";
    io::write_json_file(json_path.string(), summary);
    spdlog::info("wrote {} clips and motions.json to {}", motions.size(), dir);
  });
}

}  // namespace throng::app
