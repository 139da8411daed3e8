// throng run [SCENARIO|NAME]: runs a scenario file or a built-in scenario,
// animates every agent with the locomotion stage (app/sim_locomotion.h),
// writes DIR/trajectories.{csv,txt,sqlite} (--trajectory-format), the walkable
// area (DIR/geometry.wkt, .geojson) and DIR/stats.json, with --render a video or
// PNG frames under the scenario's camera, and prints a summary.
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>

#include "app/commands.h"
#include "app/sim_locomotion.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/memory_budget.h"
#include "core/exec.h"
#include "core/timing.h"
#include "io/routes_output.h"
#include "io/run_outputs.h"
#include "io/scenario_yaml.h"
#include "io/walkable_area.h"
#include "sim/frame_loop.h"
#include "sim/metrics_stage.h"
#include "sim/soak_stage.h"

#if defined(THRONG_HAVE_RENDER)
#include "render/camera_path.h"
#include "render/recorder.h"
#endif

namespace throng::app {

namespace {

extern "C" void on_interrupt(int) { interrupt_flag().store(true); }

// SIGINT/SIGTERM end set-up at its next check (core/interrupt.h) and the run
// after the current frame; the previous handlers come back afterwards.
class InterruptGuard {
 public:
  InterruptGuard() {
    interrupt_flag() = false;
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
  struct sigaction old_int_ {
  }, old_term_{};
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
  std::string trajectory_format;               // empty = the scenario's, else csv
  std::optional<io::TrajectoryFormat> format;  // trajectory_format, checked
  bool no_trajectories = false;
  std::int64_t check_every = 0;  // soak checks every K steps; 0 = none
  bool quiet = false;
  // Locomotion: on by default up to kAnimateUpTo agents.
  bool animate = false;
  bool no_animate = false;
  bool no_lod = false;
  std::string animation = "auto";  // exact | streams | auto (streams from kStreamsFrom agents)
  bool lod_colours = false;        // render: colour characters by joint-LOD level (a debug view)
  std::vector<float> lod_thresholds;
  // Rendering (video or frames) under the scenario's camera.
  std::string render;
  bool no_render = false;
  std::string render_mode = "skinned";
  std::int32_t width = 640;
  std::int32_t height = 360;
  double fps = 24.0;
  double render_speed = 1.0;    // simulated seconds per video second
  double render_seconds = 0.0;  // simulated seconds rendered; 0 = the whole run
  std::string camera;           // fixed | orbit | flyover; empty = the scenario's, else orbit
  double camera_period = 0.0;   // video seconds per orbit or fly-over; 0 = the scenario's, else 40
  Index routes = 0;             // agents whose routes are drawn on the ground (io::sample_routes)
  float field_lines = 0.0f;     // m between the drawn lines of equal walking distance; 0: none
  bool demo = false;            // no scenario named: the built-in demo
};

// Above this many agents `throng run` leaves the locomotion stage off unless
// --animate or --animation asks for it (docs/render.md: its cost per agent and frame).
constexpr std::int64_t kAnimateUpTo = 200000;

// The demo (`throng run` with no scenario) writes a short time-lapse video.
constexpr double kDemoRenderSpeed = 50.0;

// A bar redrawn in place on a terminal; a plain line every 10% (or 10 s) otherwise.
class Progress {
 public:
  Progress(std::int64_t max_steps, Index agents, bool quiet)
      : max_steps_(max_steps),
        agents_(agents),
        quiet_(quiet),
        tty_(isatty(STDERR_FILENO) != 0),
        start_(Clock::now()),
        last_(start_) {}

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
    const std::string text =
        fmt::format("step {}/{}  t={:.1f}s  arrived {}/{}  {:.0f} steps/s  {:.3g} agent-steps/s", f.frame, max_steps_,
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

// The kernels' estimate of the memory a step moves (from the arrays'
// sizes, stats.json's timings.step_bytes), per agent and at what rate.
void print_memory_moved(const nlohmann::json& timings, Index agents) {
  const double bytes = timings["step_bytes"].get<double>(), ms = timings["step_ms"].get<double>();
  if (bytes > 0 && agents > 0 && ms > 0)
    std::printf("  memory moved per step: %.0f bytes per agent (estimated from the arrays' sizes), %.2f GB/s\n",
                bytes / static_cast<double>(agents), gigabytes_per_second(bytes, ms));
}

void print_summary(const sim::Simulation& sim, const sim::RunResult& r, const nlohmann::json& stats,
                   const std::string& written) {
  const auto& crowd = stats["crowd"];
  const double agent_steps = static_cast<double>(r.steps) * static_cast<double>(sim.agent_count());
  std::printf("%s: %lld agents, %lld steps (%.1f s simulated) in %.2f s: %.3g agent-steps/s, %s model, %s, %s x%d%s\n",
              sim.spec().name.c_str(), static_cast<long long>(sim.agent_count()), static_cast<long long>(r.steps),
              r.simulated_seconds, r.wall_seconds, r.wall_seconds > 0 ? agent_steps / r.wall_seconds : 0.0,
              to_string(sim.spec().model.kind), to_string(sim.scheduler()), to_string(current_backend()),
              current_threads(), r.interrupted ? " (interrupted)" : "");
  const auto& at = crowd["arrival_time_s"];
  std::printf("  arrived %lld/%lld", crowd["arrived"].get<long long>(), static_cast<long long>(sim.agent_count()));
  if (crowd["arrived"].get<long long>() > 0)
    std::printf(" (mean %.1f s, last %.1f s)", at["mean"].get<double>(), at["max"].get<double>());
  if (const auto waiting = crowd["not_entered_at_end"].get<long long>(); waiting > 0)
    std::printf("; %lld still waiting to enter", waiting);
  if (const auto replanned = crowd["replanned"].get<long long>(); replanned > 0)
    std::printf("; %lld route(s) planned again", replanned);
  std::printf("; mean speed %.2f m/s\n", crowd["mean_speed_mps"]["over_samples"].get<double>());
  const auto& ov = crowd["overlaps"];
  std::printf(
      "  overlaps deeper than %.0f cm: %lld pairs at most (deepest %.1f cm); minimum separation %s; obstacle "
      "penetrations %lld\n",
      100.0 * ov["tolerance_m"].get<double>(), ov["max_pairs"].get<long long>(),
      100.0 * ov["max_depth_m"].get<double>(),
      crowd["min_separation_m"].is_null() ? "n/a"
                                          : fmt::format("{:.3f} m", crowd["min_separation_m"].get<double>()).c_str(),
      crowd["obstacle_penetrations"]["max"].get<long long>());
  const auto& stuck = stats["stuck_agents"];
  std::printf("  stuck agents (at rest over %.0f s with the way ahead free): %lld", stuck["threshold_s"].get<double>(),
              stuck["agents"].get<long long>());
  if (stuck["agents"].get<long long>() > 0)
    std::printf(" (at most %lld at once, first at %.1f s)", stuck["max_at_once"].get<long long>(),
                stuck["first_time_s"].get<double>());
  std::printf("\n");
  const bool colour = sim.scheduler() == sim::SchedulerKind::FourColour;
  std::printf("  ms per step: %.3f (bin %.3f, %s %.3f, move %.3f)\n", stats["timings"]["step_ms"].get<double>(),
              stage_ms(stats, "sim.bin"), colour ? "sense+steer" : "sense",
              colour ? stage_ms(stats, "sim.sense_steer") : stage_ms(stats, "sim.sense"), stage_ms(stats, "sim.move"));
  print_memory_moved(stats["timings"], sim.agent_count());
  if (stats.contains("locomotion")) {
    const auto& l = stats["locomotion"];
    std::printf("  locomotion (%s): %lld frames, median %.3f ms per frame", l["path"].get<std::string>().c_str(),
                l["frames"].get<long long>(), l["frame_ms"]["median"].get<double>());
    if (l.contains("joints_synthesised_per_character"))
      std::printf("; joints synthesised %.1f of %d per agent", l["joints_synthesised_per_character"].get<double>(),
                  l["joints"].get<int>());
    if (l.contains("streams")) {
      const auto& st = l["streams"];
      std::printf("; %d streams in use, %.1f agents exact per frame", st["streams_in_use"].get<int>(),
                  st["exact_per_frame"].get<double>());
      const auto& e = st["sharing_error_cm"];
      if (e["agents"].get<long long>() > 0)
        std::printf(
            "\n  sharing error (worst joint per agent, %lld sampled): steady p95 %.2f cm, max %.2f cm; with the %lld "
            "cross-fading between streams p95 %.2f cm, max %.2f cm",
            e["agents"].get<long long>(), e["steady_p95"].get<double>(), e["steady_max"].get<double>(),
            e["fading"].get<long long>(), e["p95"].get<double>(), e["max"].get<double>());
    }
    if (l.contains("cache")) std::printf("; cache hits %.1f%%", 100.0 * l["cache"]["hit_rate"].get<double>());
    const auto& skate = l["foot_skating_cm"];
    // Exact synthesis measures only the legs that joint LOD synthesises; streams every sampled agent's.
    const char* unmeasured = l["path"] == "exact" ? "; legs that joint LOD holds are not measured" : "";
    if (skate["contacts"].get<int>() > 0) {
      std::printf(
          "\n  foot skating: mean %.2f cm, p95 %.2f cm over %d contacts of %d agents (of %d sampled%s)\n    by "
          "what the body does (mean / p95 cm, contacts):",
          skate["mean"].get<double>(), skate["p95"].get<double>(), skate["contacts"].get<int>(),
          skate["agents_measured"].get<int>(), skate["agents"].get<int>(), unmeasured);
      for (int k = 0; k < motion::kGaitRegimes; ++k) {
        const char* regime = motion::to_string(static_cast<motion::GaitRegime>(k));
        const auto& f = skate["by_regime"][regime];
        if (f["contacts"].get<int>() > 0)
          std::printf(" %s %.2f / %.2f (%d);", regime, f["mean"].get<double>(), f["p95"].get<double>(),
                      f["contacts"].get<int>());
      }
      std::printf("\n");
    } else {
      std::printf("\n  foot skating: no contacts measured (%d agents sampled%s)\n", skate["agents"].get<int>(),
                  unmeasured);
    }
  }
  if (stats.contains("soak")) {
    const auto& s = stats["soak"];
    const auto& rss = s["rss_mib"];
    std::printf(
        "  soak checks: %lld, every %lld steps; deepest overlap %.1f cm (bound %.0f cm); resident memory %.1f -> %.1f "
        "MiB",
        s["checks"].get<long long>(), s["check_every_steps"].get<long long>(), 100.0 * s["max_overlap_m"].get<double>(),
        100.0 * s["overlap_bound_m"].get<double>(), rss["first"].get<double>(), rss["end"].get<double>());
    if (!rss["after_warmup"].is_null())
      std::printf(" (%+.1f%% after step %lld)", 100.0 * rss["growth"].get<double>(),
                  rss["warmup_step"].get<long long>());
    std::printf("\n");
  }
  if (!written.empty()) std::printf("  wrote %s\n", written.c_str());
}

// stats.json's "scenario": name, description, source and groups.
nlohmann::json scenario_section(const io::LoadedScenario& loaded) {
  const sim::ScenarioSpec& spec = loaded.spec;
  nlohmann::json section = {{"name", spec.name},
                            {"description", spec.description},
                            {"source", loaded.source.file},
                            {"groups", nlohmann::json::array()}};
  for (const sim::GroupSpec& g : spec.groups) section["groups"].push_back({{"name", g.name}, {"count", g.count}});
  return section;
}

// stats.json of a run interrupted before its first step: what was asked for,
// how far set-up came, and `interrupted: true` as after any Ctrl-C.
nlohmann::json interrupted_setup_stats(const io::LoadedScenario& loaded, const Interrupted& e, double seconds) {
  const sim::ScenarioSpec& spec = loaded.spec;
  nlohmann::json stats;
  stats["run"] = {{"scenario", spec.name},
                  {"agents", spec.total_agents()},
                  {"steps", 0},
                  {"dt", spec.dt},
                  {"simulated_seconds", 0.0},
                  {"wall_seconds", seconds},
                  {"seed", spec.seed},
                  {"model", to_string(spec.model.kind)},
                  {"scheduler", to_string(spec.scheduler)},
                  {"backend", to_string(current_backend())},
                  {"threads", current_threads()},
                  {"interrupted", true},
                  {"interrupted_during", e.during()},
                  {"all_arrived", false}};
  stats["scenario"] = scenario_section(loaded);
  return stats;
}

// Applies --agents, --seed and --scheduler to the scenario; returns the
// steps to run (--steps, else --seconds over dt rounded up, else the scenario's).
std::int64_t apply_run_options(sim::ScenarioSpec& spec, const RunOptions& o) {
  if (o.agents > 0) sim::scale_agent_counts(spec, o.agents);
  if (o.seed) spec.seed = *o.seed;
  if (!o.scheduler.empty()) spec.scheduler = sim::parse_scheduler(o.scheduler, "--scheduler");
  std::int64_t max_steps = spec.step_count();
  if (o.steps > 0) max_steps = o.steps;
  if (o.seconds > 0) max_steps = static_cast<std::int64_t>(std::ceil(o.seconds / static_cast<double>(spec.dt) - 1e-9));
  if (max_steps > sim::ScenarioLimits{}.max_steps) throw Error("too many steps", at_field("--steps"));
  return max_steps;
}

// Announces the run on stderr, makes the output folder (--out, else the
// scenario's outputs.dir, else out/NAME) and returns it.
std::string make_output_dir(const io::LoadedScenario& loaded, const RunOptions& o, std::int64_t max_steps) {
  const sim::ScenarioSpec& spec = loaded.spec;
  std::fprintf(stderr, "throng run: %s (%s): %lld agents, up to %lld steps of %.3g s, %s model, %s, %s x%d\n",
               spec.name.c_str(), loaded.source.file.c_str(), static_cast<long long>(spec.total_agents()),
               static_cast<long long>(max_steps), static_cast<double>(spec.dt), to_string(spec.model.kind),
               to_string(spec.scheduler), to_string(current_backend()), current_threads());
  const std::string dir = !o.out.empty() ? o.out : (!spec.outputs.dir.empty() ? spec.outputs.dir : "out/" + spec.name);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create the output folder: " + ec.message(), at_field("--out", dir));
  return dir;
}

// Memory budget before set-up: bytes per agent (simulation, plus locomotion
// when it will run) times the scenario's agents.
void check_run_budget(const sim::ScenarioSpec& spec, const RunOptions& o) {
  const std::int64_t total = spec.total_agents();
  const bool animate_planned = !o.no_animate && (o.animate || !o.render.empty() || total <= kAnimateUpTo);
  check_memory_budget(
      static_cast<double>(total) * (kSimBytesPerAgent + (animate_planned ? kLocomotionBytesPerAgent : 0.0)),
      fmt::format("{} agents{}", total, animate_planned ? ", animated" : ""), o.agents > 0 ? "--agents" : "groups");
}

// Set-up: the world and the crowd, kernel timings reset. Interrupted, it
// writes DIR/stats.json (when the scenario writes stats), says so and exits 130.
std::unique_ptr<sim::Simulation> build_or_exit(const io::LoadedScenario& loaded, const std::string& dir) {
  const sim::ScenarioSpec& spec = loaded.spec;
  const auto setup_start = std::chrono::steady_clock::now();
  KernelTimings::global().reset();
  std::unique_ptr<sim::Simulation> sim;
  try {
    sim = io::build_simulation(loaded);
  } catch (const Interrupted& e) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    if (spec.outputs.stats) io::write_json_file(dir + "/stats.json", interrupted_setup_stats(loaded, e, seconds));
    std::fprintf(stderr, "throng run: interrupted while %s, %.2f s into set-up; nothing was simulated%s\n",
                 e.during().c_str(), seconds, spec.outputs.stats ? (" (wrote " + dir + "/stats.json)").c_str() : "");
    std::exit(130);
  }
  std::fprintf(stderr, "throng run: world and crowd ready in %.2f s\n",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count());
  return sim;
}

// The output stages' results: the soak stage (null without --check-every),
// the files written so far (", "-separated) and the geometry files.
struct RunOutputs {
  const sim::SoakCheckStage* soak = nullptr;
  std::string written;
  std::optional<io::GeometryFiles> geometry_files;
};

// Output stages: crowd metrics sampled once a simulated second, soak checks
// every --check-every steps (DIR/soak.jsonl), trajectories every K-th frame
// beside the walkable area (DIR/geometry.wkt, .geojson, written now).
RunOutputs add_output_stages(sim::FrameLoop& loop, const sim::Simulation& sim, const io::LoadedScenario& loaded,
                             const RunOptions& o, const std::string& dir, std::int64_t max_steps) {
  const sim::ScenarioSpec& spec = loaded.spec;
  RunOutputs out;
  sim::MetricsOptions metrics;
  metrics.sample_every = std::max<std::int64_t>(1, std::llround(1.0 / static_cast<double>(spec.dt)));
  metrics.measurement = spec.measurement;
  loop.emplace<sim::CrowdMetricsStage>(sim, metrics);
  if (o.check_every > 0) {
    sim::SoakOptions checks;
    checks.every = o.check_every;
    checks.max_steps = max_steps;
    checks.report = dir + "/soak.jsonl";
    out.soak = &loop.emplace<sim::SoakCheckStage>(checks);
  }
  if (spec.outputs.trajectories && !o.no_trajectories) {
    io::TrajectoryOutput t;
    t.format = o.format.value_or(loaded.trajectory_format);
    t.path = dir + "/" + io::trajectory_file_name(t.format);
    t.every = o.every > 0 ? o.every : (spec.outputs.every > 0 ? spec.outputs.every : metrics.sample_every);
    t.dt = static_cast<double>(spec.dt);
    // The walkable area goes beside the trajectories (and into the SQLite
    // file): analysis tools need both.
    const std::vector<sim::Polygon> area = io::walkable_area(sim);
    t.geometry_wkt = io::to_wkt(area);
    out.geometry_files = io::write_geometry_files(dir, area);
    out.written = t.path + ", " + out.geometry_files->wkt + ", " + out.geometry_files->geojson;
    loop.emplace<io::TrajectoryWriter>(std::move(t));
  }
  return out;
}

// What rendering leaves for the end of the run: a call that ends the video
// and returns what it wrote (empty without --render), and the median
// character height (px) of each rendered frame.
struct RenderHooks {
  std::function<std::string()> finish_render;
  std::shared_ptr<std::vector<float>> character_px = std::make_shared<std::vector<float>>();
};

#if defined(THRONG_HAVE_RENDER)
// The rendering camera, from `start` (the scenario's, at the video's size):
// --camera, else the scenario's camera.motion, else one that follows the
// crowd; lo.camera returns it at each simulated time (s).
void set_render_camera(LocomotionStageOptions& lo, const Camera& start, const RunOptions& o,
                       const sim::ScenarioSpec& spec, const sim::Simulation* simulation) {
  const std::string motion =
      !o.camera.empty() ? o.camera : (!spec.camera_motion.empty() ? spec.camera_motion : "follow");
  const double speed = o.render_speed;
  if (motion == "follow") {
    const auto follow = std::make_shared<FollowCamera>(start, 0.5 * speed);  // eases over half a video second
    lo.camera = [follow, simulation](double t) { return follow->at(*simulation, t); };
  } else {
    const double period =
        o.camera_period > 0.0 ? o.camera_period : (spec.camera_period_s > 0.0f ? spec.camera_period_s : 40.0);
    const auto path = std::make_shared<render::CameraPath>(
        render::animate_camera(start, render::parse_camera_kind(motion, "--camera"), static_cast<float>(period)));
    lo.camera = [path, speed](double t) { return path->at(t / speed); };
  }
}

// --render: a recorder of o.width x o.height pixels at o.fps writing into
// `dir`, fed by lo.on_frame, its camera set by set_render_camera; hooks
// receive its finish call and the characters' size per frame.
void attach_recorder(LocomotionStageOptions& lo, const Camera& lod_camera, const RunOptions& o,
                     const sim::ScenarioSpec& spec, const sim::Simulation& sim, const std::string& dir,
                     RenderHooks& hooks) {
  render::RecordSpec record;
  record.output = render::parse_record_output(o.render, "--render");
  record.folder = dir;
  record.width = o.width;
  record.height = o.height;
  record.fps = o.fps;
  record.options.mode = render::parse_render_mode(o.render_mode, "--render-mode");
  record.options.lod_colours = o.lod_colours;
  record.validate();
  Camera start = lod_camera;
  start.width = o.width;
  start.height = o.height;
  const double speed = o.render_speed;
  const sim::Simulation* simulation = &sim;
  set_render_camera(lo, start, o, spec, simulation);
  // A video frame every `speed / fps` simulated seconds; the animation
  // runs at least once a step (feet stay planted in a time-lapse) and
  // every `per_video`-th frame is drawn.
  const double frame_time = speed / o.fps;
  const auto per_video = std::max<std::int64_t>(1, std::llround(frame_time / static_cast<double>(spec.dt)));
  lo.fps = static_cast<double>(per_video) / frame_time;
  const double until = o.render_seconds > 0.0 ? o.render_seconds : std::numeric_limits<double>::infinity();
  auto recorder = std::make_shared<std::unique_ptr<render::Recorder>>();
  // Where --routes agents will walk, as `throng route` traces them.
  std::vector<render::MapPolyline> routes;
  if (o.routes > 0)
    for (io::AgentRoute& r : io::sample_routes(sim, o.routes)) routes.push_back(std::move(r.points));
  std::vector<render::MapPolyline> field_lines;
  if (o.field_lines > 0.0f) field_lines = io::field_lines(sim, o.field_lines);
  lo.on_frame = [recorder, record, per_video, until, simulation, routes, field_lines, character_px = hooks.character_px,
                 anim_fps = lo.fps](double t, const Camera* camera, SimulationLocomotion& moved) {
    if (std::llround(t * anim_fps) % per_video != 0 || t > until + 1e-9) return;
    ScopedTimer timer("render.frame");
    character_px->push_back(median_character_px(*camera, *simulation));
    if (!*recorder) {
      *recorder = std::make_unique<render::Recorder>(record, render::make_crowd_rigs(moved.skeleton()));
      (*recorder)->set_world(simulation->world());
      (*recorder)->set_routes(routes);
      (*recorder)->set_field_lines(field_lines);
    }
    (*recorder)->add_frame(*camera, moved.streamed() ? render::poses_of(moved.streams(), simulation->crowd())
                                                     : render::poses_of(moved.animator(), simulation->crowd()));
  };
  hooks.finish_render = [recorder, record] {
    if (!*recorder) return std::string();
    const Index frames = (*recorder)->frames();
    const std::string wrote = (*recorder)->finish();
    return fmt::format("{} ({} frames, {}x{} at {:g} fps)", wrote, frames, record.width, record.height, record.fps);
  };
  std::fprintf(stderr, "throng run: rendering %s (%s, %dx%d, %g fps, %gx speed) into %s\n", o.render.c_str(),
               o.render_mode.c_str(), o.width, o.height, o.fps, speed, dir.c_str());
}
#endif

// Streams for --animation streams, and for auto from kStreamsFrom agents
// unless what streams do not give is asked for: every joint (--no-lod),
// joints to draw (--render-mode joints) or joint-LOD colours.
bool animate_by_streams(const RunOptions& o, Index agents) {
  const AnimationPath path = parse_animation_path(o.animation, "--animation");
  const bool rendered = !o.render.empty();
  const char* needs_exact = o.no_lod                                ? "--no-lod"
                            : rendered && o.render_mode == "joints" ? "--render-mode joints"
                            : rendered && o.lod_colours             ? "--lod-colours"
                                                                    : nullptr;
  if (needs_exact == nullptr) return use_streams(path, agents);
  if (path == AnimationPath::Streams)
    throw Error(fmt::format("streams share poses between agents and give palettes, not joints or LOD levels: {} needs "
                            "--animation exact",
                            needs_exact),
                at_field("--animation"));
  return false;
}

// The locomotion stage, on by default up to kAnimateUpTo agents: joint LOD
// under the scenario's camera and, with --render, the recorder.
RenderHooks add_locomotion_stage(sim::FrameLoop& loop, const sim::Simulation& sim, const sim::ScenarioSpec& spec,
                                 std::shared_ptr<const motion::BlendSpace1D> motion_set, const RunOptions& o,
                                 const std::string& dir) {
  RenderHooks hooks;
  const Index n = sim.agent_count();
  if (o.no_animate && !o.render.empty())
    throw Error("--render draws the animated agents: drop --no-animate", at_field("--render"));
  const bool animate = !o.no_animate && (o.animate || o.animation != "auto" || !o.render.empty() || n <= kAnimateUpTo);
  if (!animate && !o.no_animate)
    std::fprintf(stderr,
                 "throng run: %lld agents: locomotion off above %lld agents (--animate or --animation turns it on; see "
                 "docs/render.md "
                 "for its cost)\n",
                 static_cast<long long>(n), static_cast<long long>(kAnimateUpTo));
  if (!animate) return hooks;
  LocomotionStageOptions lo;
  lo.locomotion.space = std::move(motion_set);
  lo.locomotion.lod_thresholds = o.lod_thresholds;
  const Camera lod_camera = scenario_camera(sim);  // the camera that renders is the one LOD measures with
  lo.camera = [lod_camera](double) { return lod_camera; };
  lo.lod = !o.no_lod;
  lo.locomotion.streams = animate_by_streams(o, n);
  if (!o.render.empty()) {
#if defined(THRONG_HAVE_RENDER)
    attach_recorder(lo, lod_camera, o, spec, sim, dir, hooks);
#else
    throw Error("this build has no renderer (configured with -DTHRONG_RENDER=OFF)", at_field("--render"));
#endif
  }
  loop.emplace<LocomotionStage>(sim, std::move(lo));
  return hooks;
}

// The run: up to max_steps steps (fewer when everyone arrived and the
// scenario stops then, or after Ctrl-C), progress on stderr unless quiet.
sim::RunResult run_steps(sim::FrameLoop& loop, const sim::Simulation& sim, const sim::ScenarioSpec& spec,
                         std::int64_t max_steps, bool quiet) {
  Progress progress(max_steps, sim.agent_count(), quiet);
  sim::RunControl control;
  control.max_steps = max_steps;
  control.stop_when_arrived = spec.stop_when_arrived;
  control.interrupt = &interrupt_flag();
  control.progress = [&](const sim::Simulation& s, const sim::FrameInfo& f) { progress.update(s, f); };
  return loop.run(control);
}

// stats.json's content: the stages' sections, the geometry files, the
// rendered characters' median size (px) and the scenario; the video's
// description joins outputs.written.
nlohmann::json run_stats(sim::FrameLoop& loop, const io::LoadedScenario& loaded, RunOutputs& outputs,
                         const RenderHooks& hooks) {
  std::string& written = outputs.written;
  nlohmann::json stats;
  loop.finish(stats);
  if (outputs.geometry_files)
    stats["trajectories"]["geometry"] = {{"wkt", outputs.geometry_files->wkt},
                                         {"geojson", outputs.geometry_files->geojson}};
  if (hooks.finish_render) {
    const std::string rendered = hooks.finish_render();
    if (!rendered.empty()) written += (written.empty() ? "" : ", ") + rendered;
  }
  const std::vector<float>& character_px = *hooks.character_px;
  if (!character_px.empty()) {
    // How large the characters came out: the median over rendered frames of
    // each frame's median (a 1.75 m character standing at each agent).
    std::vector<float> px = character_px;
    std::nth_element(px.begin(), px.begin() + static_cast<std::ptrdiff_t>(px.size() / 2), px.end());
    stats["render"] = {{"frames", character_px.size()}, {"median_character_px", px[px.size() / 2]}};
    std::fprintf(stderr, "throng run: characters in the picture: a median %.0f px tall\n",
                 static_cast<double>(px[px.size() / 2]));
  }
  stats["scenario"] = scenario_section(loaded);
  return stats;
}

// Writes DIR/stats.json (when the scenario writes stats) and prints the
// summary; exits 1 on a failed soak check, 130 after Ctrl-C.
void write_and_report(const sim::Simulation& sim, const sim::RunResult& result, const nlohmann::json& stats,
                      const sim::ScenarioSpec& spec, const std::string& dir, RunOutputs& outputs) {
  std::string& written = outputs.written;
  if (spec.outputs.stats) {
    io::write_json_file(dir + "/stats.json", stats);
    written += (written.empty() ? "" : ", ") + dir + "/stats.json";
  }
  if (outputs.soak != nullptr) written += (written.empty() ? "" : ", ") + dir + "/soak.jsonl";
  print_summary(sim, result, stats, written);
  std::fflush(stdout);
  if (outputs.soak != nullptr && !outputs.soak->failure().empty()) {
    std::fprintf(stderr, "throng: error: soak check: %s\n", outputs.soak->failure().c_str());
    std::exit(1);
  }
  if (result.interrupted) {
    std::fprintf(stderr, "throng run: interrupted after %lld steps; the files above are complete up to that step\n",
                 static_cast<long long>(result.steps));
    std::exit(130);
  }
}

void run_scenario(const RunOptions& o) {
  // Ctrl-C from here on: set-up stops at its next check, the run after its frame.
  const InterruptGuard guard;
  io::LoadedScenario loaded = io::load_scenario(o.scenario);
  sim::ScenarioSpec& spec = loaded.spec;
  const std::int64_t max_steps = apply_run_options(spec, o);
  // The user's own clips are read (and refused) before any work; null = the default set.
  std::shared_ptr<const motion::BlendSpace1D> motion_set;
  if (!o.no_animate && !loaded.motion.is_default()) motion_set = load_scenario_motion(loaded);
  const std::string dir = make_output_dir(loaded, o, max_steps);
  check_run_budget(spec, o);
  const std::unique_ptr<sim::Simulation> sim = build_or_exit(loaded, dir);

  sim::FrameLoop loop(*sim);
  RunOutputs outputs = add_output_stages(loop, *sim, loaded, o, dir, max_steps);
  const RenderHooks hooks = add_locomotion_stage(loop, *sim, spec, motion_set, o, dir);
  const sim::RunResult result = run_steps(loop, *sim, spec, max_steps, o.quiet);
  const nlohmann::json stats = run_stats(loop, loaded, outputs, hooks);
  write_and_report(*sim, result, stats, spec, dir, outputs);
}

// How agents are animated: on or off, exact or through streams, joint LOD.
void add_locomotion_options(CLI::App& cmd, RunOptions& o) {
  auto* no_animate = cmd.add_flag("--no-animate", o.no_animate, "Skip the locomotion stage (agents are not animated)");
  cmd.add_flag("--animate", o.animate, fmt::format("Animate even above {} agents", kAnimateUpTo))->excludes(no_animate);
  cmd.add_option("--animation", o.animation,
                 fmt::format("How agents are animated: exact (per-agent synthesis), streams (far agents share a few "
                             "speed-bucket streams, exact near the camera) or auto (streams from {} agents)",
                             kStreamsFrom))
      ->check(CLI::IsMember({"auto", "exact", "streams"}))
      ->capture_default_str();
  cmd.add_flag("--no-lod", o.no_lod, "Synthesise every joint of every agent (no joint LOD)");
  cmd.add_option("--lod-thresholds", o.lod_thresholds,
                 "Joint-LOD thresholds in square pixels, decreasing (default 1000,30)")
      ->delimiter(',');
}

}  // namespace

void add_run_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd =
      app.add_subcommand("run", "Run a scenario (a YAML file or a built-in name); write trajectories and statistics");
  static RunOptions o;
  std::string names;
  for (const std::string& n : io::builtin_scenario_names()) names += (names.empty() ? "" : ", ") + n;
  cmd->add_option("scenario", o.scenario, "Scenario file, or a built-in: " + names)->capture_default_str();
  cmd->add_option("--agents", o.agents, "Total agents (groups keep their proportions)")->check(at_least(1));
  auto* steps =
      cmd->add_option("--steps", o.steps, "Steps to run (default: the scenario's duration)")->check(at_least(1));
  cmd->add_option("--seconds", o.seconds, "Simulated seconds to run")->check(greater_than(0))->excludes(steps);
  cmd->add_option("--seed", o.seed, "Random seed (spawn positions, speeds, random goals)");
  cmd->add_option("--scheduler", o.scheduler, "double_buffer or four_colour (default: the scenario's)")
      ->check(CLI::IsMember({"double_buffer", "four_colour", "four_color"}));
  cmd->add_option("--out", o.out, "Output folder (default: the scenario's, else out/<name>)");
  cmd->add_option("--every", o.every,
                  "Write trajectories every K-th frame (default: the scenario's, else once a simulated second)")
      ->check(at_least(1));
  cmd->add_option("--trajectory-format", o.trajectory_format,
                  "Trajectory file format: csv (trajectories.csv), pedpy (trajectories.txt) or sqlite "
                  "(trajectories.sqlite, JuPedSim's "
                  "schema); default: the scenario's outputs.trajectories.format, else csv");
  cmd->add_flag("--no-trajectories", o.no_trajectories,
                "Write no trajectories (nor geometry.wkt and geometry.geojson)");
  cmd->add_flag("--quiet", o.quiet, "No progress display");
  cmd->add_option(
         "--check-every", o.check_every,
         "Soak checks every K steps: fail on a non-finite agent, one outside free space, an overlap beyond 8 cm, or "
         "resident "
         "memory growing over 5% after the first tenth of the run; DIR/soak.jsonl and stats.json's soak section")
      ->check(at_least(1));
  add_locomotion_options(*cmd, o);
  cmd->add_option("--render", o.render,
                  "Write DIR/crowd.mp4 (video) or DIR/frame_NNNNN.png (frames) under the scenario's camera")
      ->check(CLI::IsMember({"video", "frames"}));
  cmd->add_flag("--lod-colours", o.lod_colours,
                "Render characters in joint-LOD level colours instead of their clothes (a debug view)");
  cmd->add_flag("--no-render", o.no_render, "The demo: do not write its video");
  cmd->add_option("--render-mode", o.render_mode, "skinned (the mannequin) or joints (a sphere per bone)")
      ->check(CLI::IsMember({"skinned", "joints"}))
      ->capture_default_str();
  cmd->add_option("--width", o.width, "Video width, pixels")->check(between(16, 7680))->capture_default_str();
  cmd->add_option("--height", o.height, "Video height, pixels")->check(between(16, 4320))->capture_default_str();
  cmd->add_option("--fps", o.fps, "Video frames per second")->check(between(1, 240))->capture_default_str();
  auto* speed =
      cmd->add_option("--render-speed", o.render_speed, "Simulated seconds per video second (time-lapse above 1)")
          ->check(between(0.01, 1000))
          ->capture_default_str();
  cmd->add_option("--render-seconds", o.render_seconds,
                  "Render the first S simulated seconds only (default: the whole run)")
      ->check(greater_than(0));
  cmd->add_option("--camera", o.camera,
                  "The scenario's camera kept fixed, orbiting its target, flying over it, or following the crowd from "
                  "its direction "
                  "(default: the scenario's camera.motion, else orbit; the demo follows)")
      ->check(CLI::IsMember({"fixed", "orbit", "flyover", "follow"}));
  cmd->add_option("--camera-period", o.camera_period,
                  "Video seconds per orbit or fly-over (default: the scenario's, else 40)")
      ->check(greater_than(0));
  cmd->add_option("--routes", o.routes,
                  "Draw on the ground the routes of this many agents (spread over the crowd), as `throng route` "
                  "traces them")
      ->check(at_least(1));
  cmd->add_option("--field-lines", o.field_lines,
                  "Draw on the ground the navigation fields' lines of equal walking distance, this many metres apart "
                  "(planning: field or quickest)")
      ->check(greater_than(0));
  cmd->callback([&g, cmd, speed] {
    // The built-in demo (no scenario named) writes a short time-lapse video.
    // (A build without the renderer runs it without a video.)
    o.demo = cmd->get_option("scenario")->count() == 0;
#if defined(THRONG_HAVE_RENDER)
    if (o.demo && o.render.empty() && !o.no_render && !o.no_animate) {
      o.render = "video";
      if (speed->count() == 0) o.render_speed = kDemoRenderSpeed;
    }
#endif
    // Options that only shape the video or frames are refused without them
    // rather than ignored (the demo renders unless --no-render).
    refuse_unless(*cmd, !o.render.empty(),
                  {"--render-mode", "--width", "--height", "--fps", "--render-speed", "--render-seconds", "--camera",
                   "--camera-period", "--lod-colours", "--routes", "--field-lines"},
                  "--render video|frames");
    refuse_unless(*cmd, !o.no_lod, {"--lod-thresholds"}, "joint LOD (it has no effect with --no-lod)");
    refuse_unless(*cmd, !o.no_animate, {"--animation"}, "the locomotion stage (it has no effect with --no-animate)");
    check_lod_thresholds(o.lod_thresholds, "--lod-thresholds");
    // Checked here, like the other flags, before the (possibly long) set-up.
    if (!o.trajectory_format.empty())
      o.format = io::parse_trajectory_format(o.trajectory_format, "--trajectory-format");
    apply_global_options(g);
    run_scenario(o);
  });
}

}  // namespace throng::app
