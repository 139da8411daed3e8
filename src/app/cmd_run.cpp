// throng run [SCENARIO|NAME]: runs a scenario file or a built-in scenario,
// writes DIR/trajectories.csv and DIR/stats.json, prints a summary.
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>

#include "app/commands.h"
#include "core/error.h"
#include "core/exec.h"
#include "core/timing.h"
#include "io/run_outputs.h"
#include "io/scenario_yaml.h"
#include "sim/frame_loop.h"
#include "sim/metrics_stage.h"

namespace throng::app {

namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) { g_interrupted.store(true); }

// SIGINT/SIGTERM end the run after the current frame; restored afterwards.
class InterruptGuard {
 public:
  InterruptGuard() {
    g_interrupted = false;
    struct sigaction sa {};
    sa.sa_handler = on_interrupt;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

struct RunOptions {
  std::string scenario = "circle";
  std::int64_t agents = 0;
  std::int64_t steps = 0;
  double seconds = 0;
  std::optional<std::uint64_t> seed;
  std::string scheduler;
  std::string out;
  std::int64_t every = 0;
  bool no_trajectories = false;
  bool quiet = false;
};

// A bar redrawn in place on a terminal; a plain line every 10% (or 10 s) otherwise.
class Progress {
 public:
  Progress(std::int64_t max_steps, Index agents, bool quiet)
      : max_steps_(max_steps), agents_(agents), quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0), start_(Clock::now()), last_(start_) {}

  void update(const sim::Simulation& sim, const sim::FrameInfo& f) {
    if (quiet_ || f.frame == 0) return;
    const auto now = Clock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    const std::int64_t decile = max_steps_ > 0 ? 10 * f.frame / max_steps_ : 0;
    const bool due = tty_ ? since >= 0.1 : (decile != last_decile_ || since >= 10.0);
    if (!due && !f.last) return;
    last_ = now;
    last_decile_ = decile;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0 ? static_cast<double>(f.frame) / elapsed : 0.0;
    const double fraction = max_steps_ > 0 ? static_cast<double>(f.frame) / static_cast<double>(max_steps_) : 1.0;
    const std::string text = fmt::format("step {}/{}  t={:.1f}s  arrived {}/{}  {:.0f} steps/s  {:.3g} agent-steps/s", f.frame, max_steps_,
                                         f.time, sim.arrived_count(), agents_, rate, rate * static_cast<double>(agents_));
    if (tty_) {
      constexpr int kWidth = 30;
      const int filled = static_cast<int>(fraction * kWidth);
      std::fprintf(stderr, "\r[%s%s] %3.0f%%  %s\033[K", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(kWidth - filled), ' ').c_str(), 100.0 * fraction, text.c_str());
      if (f.last) std::fprintf(stderr, "\n");
    } else {
      std::fprintf(stderr, "progress: %3.0f%%  %s\n", 100.0 * fraction, text.c_str());
    }
    std::fflush(stderr);
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::int64_t max_steps_;
  Index agents_;
  bool quiet_, tty_;
  Clock::time_point start_, last_;
  std::int64_t last_decile_ = 0;
};

double stage_ms(const nlohmann::json& stats, const char* stage) {
  const auto& stages = stats["timings"]["stages"];
  return stages.contains(stage) ? stages[stage]["ms_per_step"].get<double>() : 0.0;
}

void print_summary(const sim::Simulation& sim, const sim::RunResult& r, const nlohmann::json& stats, const std::string& written) {
  const auto& crowd = stats["crowd"];
  const double agent_steps = static_cast<double>(r.steps) * static_cast<double>(sim.agent_count());
  std::printf("%s: %lld agents, %lld steps (%.1f s simulated) in %.2f s: %.3g agent-steps/s, %s, %s x%d%s\n", sim.spec().name.c_str(),
              static_cast<long long>(sim.agent_count()), static_cast<long long>(r.steps), r.simulated_seconds, r.wall_seconds,
              r.wall_seconds > 0 ? agent_steps / r.wall_seconds : 0.0, to_string(sim.scheduler()), to_string(current_backend()),
              current_threads(), r.interrupted ? " (interrupted)" : "");
  const auto& at = crowd["arrival_time_s"];
  std::printf("  arrived %lld/%lld", crowd["arrived"].get<long long>(), static_cast<long long>(sim.agent_count()));
  if (crowd["arrived"].get<long long>() > 0) std::printf(" (mean %.1f s, last %.1f s)", at["mean"].get<double>(), at["max"].get<double>());
  std::printf("; mean speed %.2f m/s\n", crowd["mean_speed_mps"]["over_samples"].get<double>());
  const auto& ov = crowd["overlaps"];
  std::printf("  overlaps deeper than %.0f cm: %lld pairs at most (deepest %.1f cm); minimum separation %s; obstacle penetrations %lld\n",
              100.0 * ov["tolerance_m"].get<double>(), ov["max_pairs"].get<long long>(), 100.0 * ov["max_depth_m"].get<double>(),
              crowd["min_separation_m"].is_null() ? "n/a" : fmt::format("{:.3f} m", crowd["min_separation_m"].get<double>()).c_str(),
              crowd["obstacle_penetrations"]["max"].get<long long>());
  const bool colour = sim.scheduler() == sim::SchedulerKind::FourColour;
  std::printf("  ms per step: %.3f (bin %.3f, %s %.3f, move %.3f)\n", stats["timings"]["step_ms"].get<double>(), stage_ms(stats, "sim.bin"),
              colour ? "sense+steer" : "sense", colour ? stage_ms(stats, "sim.sense_steer") : stage_ms(stats, "sim.sense"),
              stage_ms(stats, "sim.move"));
  if (!written.empty()) std::printf("  wrote %s\n", written.c_str());
}

void run_scenario(const RunOptions& o) {
  io::LoadedScenario loaded = io::load_scenario(o.scenario);
  sim::ScenarioSpec& spec = loaded.spec;
  if (o.agents > 0) sim::scale_agent_counts(spec, o.agents);
  if (o.seed) spec.seed = *o.seed;
  if (!o.scheduler.empty()) spec.scheduler = sim::parse_scheduler(o.scheduler, "--scheduler");
  std::int64_t max_steps = spec.step_count();
  if (o.steps > 0) max_steps = o.steps;
  if (o.seconds > 0) max_steps = static_cast<std::int64_t>(std::ceil(o.seconds / static_cast<double>(spec.dt) - 1e-9));
  if (max_steps > sim::ScenarioLimits{}.max_steps) throw Error("too many steps", at_field("--steps"));

  std::fprintf(stderr, "throng run: %s (%s): %lld agents, up to %lld steps of %.3g s, %s, %s x%d\n", spec.name.c_str(),
               loaded.source.file.c_str(), static_cast<long long>(spec.total_agents()), static_cast<long long>(max_steps),
               static_cast<double>(spec.dt), to_string(spec.scheduler), to_string(current_backend()), current_threads());
  const auto setup_start = std::chrono::steady_clock::now();
  KernelTimings::global().reset();
  std::unique_ptr<sim::Simulation> sim = io::build_simulation(loaded);
  std::fprintf(stderr, "throng run: world and crowd ready in %.2f s\n",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count());

  const std::string dir = !o.out.empty() ? o.out : (!spec.outputs.dir.empty() ? spec.outputs.dir : "out/" + spec.name);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create the output folder: " + ec.message(), at_field("--out", dir));

  sim::FrameLoop loop(*sim);
  sim::MetricsOptions metrics;
  metrics.sample_every = std::max<std::int64_t>(1, std::llround(1.0 / static_cast<double>(spec.dt)));
  if (spec.measurement) metrics.measurement = *spec.measurement;
  loop.emplace<sim::CrowdMetricsStage>(*sim, metrics);
  std::string written;
  if (spec.outputs.trajectories && !o.no_trajectories) {
    const std::int64_t every = o.every > 0 ? o.every : (spec.outputs.every > 0 ? spec.outputs.every : metrics.sample_every);
    loop.emplace<io::TrajectoryWriter>(dir + "/trajectories.csv", every);
    written = dir + "/trajectories.csv";
  }

  Progress progress(max_steps, sim->agent_count(), o.quiet);
  sim::RunControl control;
  control.max_steps = max_steps;
  control.stop_when_arrived = spec.stop_when_arrived;
  control.interrupt = &g_interrupted;
  control.progress = [&](const sim::Simulation& s, const sim::FrameInfo& f) { progress.update(s, f); };
  sim::RunResult result;
  {
    InterruptGuard guard;
    result = loop.run(control);
  }

  nlohmann::json stats;
  loop.finish(stats);
  stats["scenario"] = {{"name", spec.name}, {"description", spec.description}, {"source", loaded.source.file}, {"groups", nlohmann::json::array()}};
  for (const sim::GroupSpec& g : spec.groups) stats["scenario"]["groups"].push_back({{"name", g.name}, {"count", g.count}});
  if (spec.outputs.stats) {
    io::write_json_file(dir + "/stats.json", stats);
    written += (written.empty() ? "" : ", ") + dir + "/stats.json";
  }
  print_summary(*sim, result, stats, written);
  std::fflush(stdout);
  if (result.interrupted) {
    std::fprintf(stderr, "throng run: interrupted after %lld steps; the files above are complete up to that step\n",
                 static_cast<long long>(result.steps));
    std::exit(130);
  }
}

}  // namespace

void add_run_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("run", "Run a scenario (a YAML file or a built-in name); write trajectories and statistics");
  static RunOptions o;
  std::string names;
  for (const std::string& n : io::builtin_scenario_names()) names += (names.empty() ? "" : ", ") + n;
  cmd->add_option("scenario", o.scenario, "Scenario file, or a built-in: " + names)->capture_default_str();
  cmd->add_option("--agents", o.agents, "Total agents (groups keep their proportions)")->check(CLI::PositiveNumber);
  auto* steps = cmd->add_option("--steps", o.steps, "Steps to run (default: the scenario's duration)")->check(CLI::PositiveNumber);
  cmd->add_option("--seconds", o.seconds, "Simulated seconds to run")->check(CLI::PositiveNumber)->excludes(steps);
  cmd->add_option("--seed", o.seed, "Random seed (spawn positions, speeds, random goals)");
  cmd->add_option("--scheduler", o.scheduler, "double_buffer or four_colour (default: the scenario's)")
      ->check(CLI::IsMember({"double_buffer", "four_colour", "four_color"}));
  cmd->add_option("--out", o.out, "Output folder (default: the scenario's, else out/<name>)");
  cmd->add_option("--every", o.every, "Write trajectories every K-th frame (default: the scenario's, else once a simulated second)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-trajectories", o.no_trajectories, "Do not write trajectories.csv");
  cmd->add_flag("--quiet", o.quiet, "No progress display");
  cmd->callback([&g] {
    apply_global_options(g);
    run_scenario(o);
  });
}

}  // namespace throng::app
