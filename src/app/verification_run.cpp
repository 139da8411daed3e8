// Running one verification scenario and recording what the RiMEA tests
// judge: per agent its start, first movement, arrival, last position and
// line crossings; per measurement area a sample a second; the deepest
// overlap and the agents in walls.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "app/verification.h"
#include "core/buffer.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "io/embedded.h"
#include "sim/simulation.h"

namespace throng::app {

io::LoadedScenario load_verification_scenario(const std::string& name, const VerifyOptions& o) {
  const std::optional<std::string_view> text = io::kBuiltinVerification.find(name);
  if (!text) throw Error("no verification scenario named '" + name + "' in this build");
  io::LoadedScenario loaded = io::parse_scenario(*text, "examples/verification/" + name + ".yaml");
  if (o.model) loaded.spec.model.kind = *o.model;
  return loaded;
}

std::vector<double> ScenarioObservation::arrivals() const {
  std::vector<double> out;
  for (float t : arrival_time)
    if (t >= 0) out.push_back(t);
  std::sort(out.begin(), out.end());
  return out;
}

double ScenarioObservation::evacuation_time() const {
  const std::vector<double> a = arrivals();
  if (a.size() < arrival_time.size() || a.empty()) return std::numeric_limits<double>::infinity();
  return a.back();
}

std::vector<double> ScenarioObservation::crossing_times(std::int32_t line, std::optional<Index> agent) const {
  std::vector<double> out;
  for (const sim::LineCrossing& x : crossings)
    if (x.line == line && x.direction > 0 && (!agent || x.agent == *agent)) out.push_back(x.time);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<double> ScenarioObservation::first_crossings(std::int32_t line) const {
  std::vector<double> first(static_cast<std::size_t>(agents), -1.0);
  for (const sim::LineCrossing& x : crossings) {
    double& t = first.at(static_cast<std::size_t>(x.agent));
    if (x.line == line && x.direction > 0 && (t < 0 || x.time < t)) t = x.time;
  }
  std::vector<double> out;
  for (double t : first)
    if (t >= 0) out.push_back(t);
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

constexpr float kMovedM = 0.01f;      // an agent has started walking once 1 cm from its spawn point
constexpr double kTrackEveryS = 0.5;  // track point spacing
constexpr float kInWallM = 1e-3f;     // a disc entering a wall by more than this counts

// The per-step bookkeeping of observe(): host copies of the state before
// and after each step.
class Recorder {
 public:
  Recorder(const sim::Simulation& sim, const ObserveOptions& options, ScenarioObservation& out)
      : options_(options), out_(out), spawn_(sim.positions()) {
    const std::size_t n = spawn_.size();
    std::vector<sim::Segment> lines;
    for (const sim::MeasurementLine& l : sim.spec().measurement.lines) {
      lines.push_back({l.from, l.to});
      line_bounds_.add(l.from);
      line_bounds_.add(l.to);
    }
    lines_ = Buffer<sim::Segment>(std::span<const sim::Segment>(lines), current_memory());
    remember(sim);
    out_.first_move.assign(n, -1.0f);
    out_.last_seen = spawn_;
    if (options_.tracks) out_.tracks.assign(n, {});
    out_.area_samples.assign(sim.spec().measurement.areas.size(), {});
    track(sim);
  }

  void after_step(const sim::Simulation& sim) {
    const std::vector<glm::vec2> after = sim.positions();
    const std::vector<std::uint8_t> flags = sim.flags();
    const double t1 = sim.time();
    for (std::size_t i = 0; i < after.size(); ++i) {
      if ((flags[i] & sim::kAgentActive) == 0) continue;
      out_.last_seen[i] = after[i];
      if (out_.first_move[i] < 0 && glm::length(after[i] - spawn_[i]) > kMovedM)
        out_.first_move[i] = static_cast<float>(t1);
    }
    const sim::CrowdState& c = sim.crowd();
    if (lines_.size() > 0) {
      const std::vector<sim::LineCrossing> found =
          sim::line_crossings(before_.span(), flags_before_.span(), c.position.span(), c.flags.span(), lines_.span(),
                              line_bounds_, t1 - sim.spec().dt, t1, sim.world().periodic());
      out_.crossings.insert(out_.crossings.end(), found.begin(), found.end());
    }
    remember(sim);
    out_.most_in_walls = std::max(
        out_.most_in_walls,
        sim::count_obstacle_penetrations(sim.world(), c.position.span(), c.radius.span(), c.flags.span(), kInWallM));
    if (every(sim, 1.0)) sample(sim);
    if (options_.tracks && every(sim, kTrackEveryS)) track(sim);
  }

 private:
  // True on the step that ends a whole multiple of `period` seconds.
  static bool every(const sim::Simulation& sim, double period) {
    const auto per = std::max<std::int64_t>(1, std::llround(period / sim.spec().dt));
    return sim.steps_done() % per == 0;
  }
  // The state before the next step, in the crowd's memory (line_crossings
  // runs on the backend).
  void remember(const sim::Simulation& sim) {
    if (lines_.size() == 0) return;
    before_ = sim.crowd().position.to(sim.crowd().position.memory());
    flags_before_ = sim.crowd().flags.to(sim.crowd().flags.memory());
  }
  void sample(const sim::Simulation& sim) {
    const sim::CrowdState& c = sim.crowd();
    const sim::OverlapStats o = sim::measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), 0.0f,
                                                      sim.contact_cell(), sim.world().periodic());
    out_.deepest_overlap = std::max(out_.deepest_overlap, o.max_depth);
    if (sim.time() + 1e-6 < options_.sample_from_s) return;
    const auto& areas = sim.spec().measurement.areas;
    for (std::size_t k = 0; k < areas.size(); ++k)
      out_.area_samples[k].push_back(
          sim::measure_area(c.position.span(), c.velocity.span(), c.goal.span(), c.flags.span(), areas[k].rect));
  }
  void track(const sim::Simulation& sim) {
    if (!options_.tracks) return;
    const std::vector<glm::vec2> p = sim.positions();
    const std::vector<std::uint8_t> f = sim.flags();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (f[i] & sim::kAgentActive) out_.tracks[i].push_back(p[i]);
  }

  ObserveOptions options_;
  ScenarioObservation& out_;
  std::vector<glm::vec2> spawn_;
  Buffer<sim::Segment> lines_;
  sim::Aabb line_bounds_;
  Buffer<glm::vec2> before_;
  Buffer<std::uint8_t> flags_before_;
};

}  // namespace

ScenarioObservation observe(const io::LoadedScenario& scenario, const ObserveOptions& options) {
  io::LoadedScenario loaded = scenario;
  if (options.agents) sim::scale_agent_counts(loaded.spec, *options.agents);
  ScenarioObservation out;
  out.spec = loaded.spec;
  const std::unique_ptr<sim::Simulation> sim = io::build_simulation(loaded);
  // (Read now: a wait at a waypoint rewrites an agent's start time.)
  out.start_time = sim->crowd().start_time.to_vector();
  Recorder recorder(*sim, options, out);
  const std::int64_t steps = loaded.spec.step_count();
  for (std::int64_t k = 0; k < steps; ++k) {
    sim->step();
    recorder.after_step(*sim);
    if (loaded.spec.stop_when_arrived && sim->all_arrived()) break;
  }
  const sim::CrowdState& c = sim->crowd();
  out.end_time = sim->time();
  out.agents = sim->agent_count();
  out.group = c.group.to_vector();
  out.pref_speed = c.pref_speed.to_vector();
  out.arrival_time = sim->arrival_times();
  return out;
}

const char* to_string(VerifyStatus s) {
  switch (s) {
    case VerifyStatus::pass: return "pass";
    case VerifyStatus::fail: return "fail";
    case VerifyStatus::not_applicable: return "not applicable";
  }
  return "?";
}

namespace {

void check_selection(const std::vector<int>& only) {
  const std::vector<VerifyTest>& tests = verification_tests();
  for (int n : only)
    if (std::none_of(tests.begin(), tests.end(), [n](const VerifyTest& t) { return t.number == n; }))
      throw Error(fmt::format("no RiMEA 3.0 test {}: the tests are 1 to 15", n), at_field("--only"));
}

VerifyResult run_one(const VerifyTest& t, const VerifyOptions& o) {
  if (!t.run) {
    VerifyResult r;
    r.number = t.number;
    r.title = t.title;
    r.status = VerifyStatus::not_applicable;
    r.reason = t.not_applicable;
    return r;
  }
  std::fprintf(stderr, "throng verify: test %d: %s\n", t.number, t.title.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  VerifyResult r = t.run(o);
  r.number = t.number;
  r.title = t.title;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const bool all =
      !r.checks.empty() && std::all_of(r.checks.begin(), r.checks.end(), [](const VerifyCheck& c) { return c.pass; });
  r.status = all ? VerifyStatus::pass : VerifyStatus::fail;
  for (const VerifyCheck& c : r.checks)
    std::fprintf(stderr, "  %s  %s: %s\n", c.pass ? "pass" : "FAIL", c.criterion.c_str(), c.measured.c_str());
  std::fprintf(stderr, "throng verify: test %d: %s (%.1f s)\n", t.number, to_string(r.status), r.wall_s);
  return r;
}

}  // namespace

std::vector<VerifyResult> run_verification(const VerifyOptions& o) {
  check_selection(o.only);
  std::vector<VerifyResult> results;
  for (const VerifyTest& t : verification_tests()) {
    if (!o.only.empty() && std::find(o.only.begin(), o.only.end(), t.number) == o.only.end()) continue;
    check_interrupt("verifying");
    results.push_back(run_one(t, o));
  }
  return results;
}

}  // namespace throng::app
