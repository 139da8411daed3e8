// throng export-crowd SCENARIO: runs a scenario with the locomotion stage
// (every joint synthesised, no LOD) and writes the animated crowd as a glTF
// 2.0 binary (io/crowd_gltf.h) that DCC tools import: the skinned mannequin
// once, and per agent an armature keyed at --fps.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "anim/rig.h"
#include "app/commands.h"
#include "app/scenario_choice.h"
#include "app/sim_locomotion.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "io/crowd_gltf.h"
#include "io/scenario_yaml.h"
#include "sim/frame_loop.h"

namespace throng::app {

namespace {

struct ExportOptions {
  ScenarioChoice choice;
  std::string out;
  std::string format = "gltf";
  double seconds = 20.0;
  double fps = 24.0;
  double max_megabytes = 512.0;
};

void export_crowd(const ExportOptions& o) {
  std::error_code ec;
  if (std::filesystem::is_directory(o.choice.scenario, ec))
    throw Error(
        "is a folder: export-crowd runs a scenario (a YAML file or a built-in name); give it the scenario the run "
        "used, with "
        "its --agents and --seed",
        at_field("scenario", o.choice.scenario));
  io::LoadedScenario loaded = o.choice.load();
  sim::ScenarioSpec& spec = loaded.spec;
  const auto steps = static_cast<std::int64_t>(std::ceil(o.seconds / static_cast<double>(spec.dt) - 1e-9));
  const auto frames = static_cast<std::int64_t>(std::floor(o.seconds * o.fps + 1e-9)) + 1;
  const std::string out = !o.out.empty() ? o.out : "out/" + spec.name + "/crowd.glb";
  if (std::filesystem::path(out).extension() != ".glb")
    throw Error("must name a .glb file (glTF 2.0 binary)", at_field("--out", out));

  // The motion set first (its skeleton sizes the file), then size and
  // memory, before any work: the keys dominate both.
  const std::shared_ptr<const motion::BlendSpace1D> motion_set = load_scenario_motion(loaded);
  const anim::Rig probe = anim::make_rig("mannequin", motion_set->skeleton());
  const double bytes = io::CrowdTake::estimate_bytes(probe, spec.total_agents(), frames);
  if (bytes > o.max_megabytes * 1e6)
    throw Error(fmt::format("{} agents x {} frames would write about {:.0f} MB, over --max-size {:g} MB: lower --fps, "
                            "--seconds or --agents, "
                            "or raise --max-size",
                            spec.total_agents(), frames, bytes / 1e6, o.max_megabytes),
                at_field("--max-size"));
  check_memory_budget(
      2.0 * bytes + static_cast<double>(spec.total_agents()) * (kSimBytesPerAgent + kLocomotionBytesPerAgent),
      fmt::format("{} agents, {} frames", spec.total_agents(), frames), "--agents");

  std::fprintf(stderr, "throng export-crowd: %s: %lld agents, %.3g s at %g fps (%lld frames), about %.1f MB\n",
               spec.name.c_str(), static_cast<long long>(spec.total_agents()), o.seconds, o.fps,
               static_cast<long long>(frames), bytes / 1e6);
  std::unique_ptr<sim::Simulation> sim = io::build_simulation(loaded);
  sim::FrameLoop loop(*sim);
  std::optional<io::CrowdTake> take;
  LocomotionStageOptions lo;
  lo.fps = o.fps;
  lo.lod = false;  // every joint of every agent: what a DCC tool shows up close
  lo.locomotion.space = motion_set;
  lo.locomotion.skating_agents = 0;
  lo.on_frame = [&](double, const Camera*, SimulationLocomotion& moved) {
    const anim::CrowdAnimator& crowd = moved.animator();
    if (!take) {
      const Span<const float> s = crowd.scales();
      std::vector<float> scales(static_cast<std::size_t>(crowd.count()), 1.0f);
      for (Index a = 0; a < s.size(); ++a) scales[static_cast<std::size_t>(a)] = s[a];
      take.emplace(anim::make_rig("mannequin", crowd.blend_space().skeleton()), std::move(scales), o.fps);
    }
    if (take->frames() < frames) take->add_frame(crowd.joint_positions(), crowd.joint_rotations());
  };
  loop.emplace<LocomotionStage>(*sim, std::move(lo));
  sim::RunControl control;
  control.max_steps = steps;
  control.stop_when_arrived = false;
  const sim::RunResult result = loop.run(control);
  if (!take) throw Error("the run produced no frame", at_field("--seconds"));

  const std::filesystem::path parent = std::filesystem::path(out).parent_path();
  if (!parent.empty()) {
    std::filesystem::create_directories(parent, ec);
    if (ec) throw Error("cannot create the output folder: " + ec.message(), at_field("--out", parent.string()));
  }
  io::write_crowd_glb(out, *take);
  const auto size = std::filesystem::file_size(out, ec);
  std::printf("wrote %s: %lld agents x %d joints, %d frames at %g fps (%.3g s simulated in %.1f s), %.1f MB\n",
              out.c_str(), static_cast<long long>(take->agents()), take->joints(), take->frames(), o.fps,
              result.simulated_seconds, result.wall_seconds, static_cast<double>(size) / 1e6);
}

}  // namespace

void add_export_crowd_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand(
      "export-crowd",
      "Run a scenario and write its animated crowd as glTF 2.0 (.glb): the skinned mannequin and every agent's "
      "joints keyed at --fps, for Blender, Maya, Houdini or Unreal");
  static ExportOptions o;
  o.choice.add_options(*cmd);
  cmd->add_option("--out", o.out, "The .glb to write (default: out/<scenario>/crowd.glb)");
  cmd->add_option("--format", o.format, "Export format")->check(CLI::IsMember({"gltf"}))->capture_default_str();
  cmd->add_option("--seconds", o.seconds, "Simulated seconds to export")
      ->check(between(0.01, 3600))
      ->capture_default_str();
  cmd->add_option("--fps", o.fps, "Keys per simulated second")->check(between(1, 120))->capture_default_str();
  cmd->add_option("--max-size", o.max_megabytes, "Refuse an export estimated above this many MB")
      ->check(greater_than(0))
      ->capture_default_str();
  cmd->callback([&g] {
    apply_global_options(g);
    export_crowd(o);
  });
}

}  // namespace throng::app
