// The crowd simulation at scale: one step (bin, sense, steer, move) of the
// built-in plaza (1200 m x 1200 m, 3000 obstacles) with 10^3 to 10^6 agents,
// for every steering model under both schedulers, and the naive O(N^2)
// reference (every agent senses every other; contacts still binned) up to
// 10^4 agents. Rows: sim/plaza_step/<model>/<scheduler>. And the disc
// (disc_scenario_text below) with RVO2's example body and step, the layout
// the RVO2 driver of ../shared/peers (rvo_circle.cc, `disk`) times, for the
// default model and the paper's: sim/disc_step/<model>, and
// beside it at 10^5 and 10^6 the same step without the shortcuts that
// change no bit (sim/disc_step/<model>/reference), and the same disc with
// its agents listed in a random order (sim/disc_step/<model>/shuffled).
// Items are agent-steps, so items/s is agent-steps per second and the
// median ns is the time of one step. The counter bytes_per_agent_step is
// the step's kernels' estimate of the memory they move (core/parallel.h,
// count_traffic: each array a kernel passes over counted at its size).
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bench/registry.h"
#include "core/exec.h"
#include "core/timing.h"
#include "io/scenario_yaml.h"
#include "sim/crowd.h"
#include "sim/simulation.h"
#include "sim/world.h"

namespace throng::bench {

namespace {

enum class Variant { DoubleBuffer, FourColour, AllPairs };

// Building a plaza of 10^6 agents takes seconds: each size, variant and
// backend is built once per process and keeps stepping across repetitions
// (the crowd is in steady motion: agents loop between random places).
sim::Simulation& plaza(Index n, sim::ModelKind model, Variant variant) {
  static std::map<std::tuple<Index, sim::ModelKind, Variant, Backend>, std::unique_ptr<sim::Simulation>> cache;
  auto& slot = cache[{n, model, variant, current_backend()}];
  if (!slot) {
    io::LoadedScenario s = io::load_builtin_scenario("plaza");
    sim::scale_agent_counts(s.spec, n);
    s.spec.model.kind = model;
    s.spec.scheduler =
        variant == Variant::FourColour ? sim::SchedulerKind::FourColour : sim::SchedulerKind::DoubleBuffer;
    // The rows time the step; routes for 10^6 agents would take a minute and
    // a half to plan first (the path/route_plan/plaza rows time planning).
    s.spec.planning = sim::PlanningKind::None;
    sim::SimulationOptions options;
    if (variant == Variant::AllPairs) options.neighbours = sim::NeighbourSearch::AllPairs;
    slot = io::build_simulation(s, options);
    slot->run(5);  // past the first steps from rest
  }
  return *slot;
}

// N agents on a disc at 16 m^2 each (radius sqrt(16 N / pi)), each walking
// to its antipode, with RVO2's example body and step: radius 1.5 m,
// preferred speed 1 m/s, dt 0.25 s, no obstacles, no route planning.
// `spawn`: the group's spawn region; empty for the disc itself.
std::string disc_scenario_text(Index n, sim::ModelKind model, const std::string& spawn = "") {
  const double radius = std::sqrt(16.0 * static_cast<double>(n) / 3.14159265358979);
  const std::string where = spawn.empty() ? fmt::format("{{disc: {{center: [0, 0], radius: {:.2f}}}}}", radius) : spawn;
  return fmt::format(R"(name: disc
seed: 1
dt: 0.25
duration: 100000
planning: none
model: {{type: {}, max_speed: 2.0, max_radius: 1.5}}
groups:
  - count: {}
    radius: 1.5
    speed: 1.0
    spawn: {}
    goal: {{mirror: [0, 0]}}
    on_arrival: stop
)",
                     sim::to_string(model), n, where);
}

// The disc's agents in a random order (spawn: points, the disc's own
// spawn positions shuffled with a fixed seed): the same crowd, but agent
// indices say nothing of where agents stand, as after long runs, timed
// entries or many groups. What a step reads of an agent by its index is
// then a miss; the sim/disc_step/<model>/shuffled rows time that.
std::string shuffled_disc_text(Index n, sim::ModelKind model) {
  const sim::ScenarioSpec spec = io::parse_scenario(disc_scenario_text(n, model), "disc").spec;
  std::vector<glm::vec2> p = sim::spawn_crowd(spec, sim::World::build(spec.world, spec.model.query_radius())).position;
  std::mt19937 rng(1);
  for (std::size_t k = p.size(); k > 1; --k) std::swap(p[k - 1], p[rng() % k]);  // Fisher-Yates
  std::string points = "{points: [";
  for (std::size_t k = 0; k < p.size(); ++k) points += fmt::format("{}[{}, {}]", k > 0 ? ", " : "", p[k].x, p[k].y);
  return disc_scenario_text(n, model, points + "]}");
}

// The disc as it is; the step without its shortcuts (Reference: hashed
// bins counted with atomics, every contact pass, the far look through every
// cell; sim::SimulationOptions), the same bits at what
// they cost before the shortcuts; its agents in a random order (Shuffled,
// shuffled_disc_text).
enum class DiscKind { Plain, Reference, Shuffled };
std::unique_ptr<sim::Simulation> fresh_disc(Index n, sim::ModelKind model, DiscKind kind) {
  static std::map<std::pair<Index, sim::ModelKind>, std::string> shuffled;  // (made once: 10^6 points take seconds)
  sim::SimulationOptions options;
  options.dense_bins = options.skip_idle_contact_passes = options.skip_far_cells_walking_along =
      kind != DiscKind::Reference;
  if (kind == DiscKind::Reference) options.bin_counting = sim::BinCounting::Atomic;
  std::string text;
  if (kind == DiscKind::Shuffled) {
    std::string& t = shuffled[{n, model}];
    if (t.empty()) t = shuffled_disc_text(n, model);
    text = t;
  } else {
    text = disc_scenario_text(n, model);
  }
  auto sim = io::build_simulation(io::parse_scenario(text, "disc"), options);
  sim->run(4);  // 1 s: past the first steps from rest
  return sim;
}

// The disc is timed over the same part of its walk at every N: from 1 s to
// kDiscTimedUntil, as the RVO2 driver times 30 steps after 5 (7.5 s to
// 8.75 s in). Past it the crowd is started anew, untimed. A small disc
// stepped on through a benchmark's many iterations would otherwise be
// timed through its crush at the centre (a 10^3 disc's agents meet there
// after about 70 s), a large one only on its first steps: per-agent costs
// of different sizes would compare different crowds.
constexpr double kDiscTimedUntil = 10.0;  // s of simulated time
sim::Simulation& disc(Index n, sim::ModelKind model, DiscKind kind) {
  static std::map<std::tuple<Index, sim::ModelKind, DiscKind, Backend>, std::unique_ptr<sim::Simulation>> cache;
  auto& slot = cache[{n, model, kind, current_backend()}];
  if (!slot || slot->time() >= kDiscTimedUntil) slot = fresh_disc(n, model, kind);
  return *slot;
}

// The bytes the timed steps' kernels counted (count_traffic), set aside
// while the timing is paused.
class TimedBytes {
 public:
  void pause() { counted_ += now() - from_; }
  void resume() { from_ = now(); }
  void report(benchmark::State& state, Index n) {
    pause();
    const double agent_steps = static_cast<double>(state.iterations()) * static_cast<double>(n);
    if (agent_steps > 0) state.counters["bytes_per_agent_step"] = static_cast<double>(counted_) / agent_steps;
  }

 private:
  static std::int64_t now() { return KernelTimings::global().bytes_under("sim."); }
  std::int64_t counted_ = 0, from_ = now();
};

Body disc_step(sim::ModelKind model, DiscKind kind) {
  return [model, kind](benchmark::State& state, Index n) {
    sim::Simulation* sim = &disc(n, model, kind);
    TimedBytes bytes;
    for (auto _ : state) {
      if (sim->time() >= kDiscTimedUntil) {
        state.PauseTiming();
        bytes.pause();
        sim = &disc(n, model, kind);
        bytes.resume();
        state.ResumeTiming();
      }
      sim->step();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * n);
    bytes.report(state, n);
  };
}

Body step(sim::ModelKind model, Variant variant) {
  return [model, variant](benchmark::State& state, Index n) {
    sim::Simulation& sim = plaza(n, model, variant);
    TimedBytes bytes;
    for (auto _ : state) sim.step();
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * n);
    bytes.report(state, n);
  };
}

void register_sim(const Options& options) {
  const std::vector<Index> sizes = {1000, 10000, 100000, 1000000};
  for (const sim::ModelKind model : {sim::ModelKind::Priority, sim::ModelKind::CollisionFreeSpeed, sim::ModelKind::Ttc,
                                     sim::ModelKind::SocialForce}) {
    const std::string prefix = std::string("sim/plaza_step/") + sim::to_string(model);
    add(options, {prefix + "/double_buffer", sizes, step(model, Variant::DoubleBuffer), true});
    add(options, {prefix + "/four_colour", sizes, step(model, Variant::FourColour), true});
    add(options, {prefix + "/all_pairs_reference", {1000, 10000}, step(model, Variant::AllPairs), true});
  }
  for (const sim::ModelKind model : {sim::ModelKind::CollisionFreeSpeed, sim::ModelKind::Priority}) {
    const std::string prefix = std::string("sim/disc_step/") + sim::to_string(model);
    add(options, {prefix, sizes, disc_step(model, DiscKind::Plain), true});
    add(options, {prefix + "/reference", {100000, 1000000}, disc_step(model, DiscKind::Reference), true});
    add(options, {prefix + "/shuffled", {10000, 100000, 1000000}, disc_step(model, DiscKind::Shuffled), true});
  }
}

const bool registered = register_suite("sim", &register_sim);

}  // namespace
}  // namespace throng::bench
