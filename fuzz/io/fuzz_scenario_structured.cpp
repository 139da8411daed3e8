// Structure-aware libFuzzer target: the input bytes choose the pieces of a
// valid-looking scenario (a walkable rectangle, obstacles of every kind,
// groups with spawn regions, goals, waypoints and arrival behaviours, one of
// the steering models with parameters drawn inside their documented ranges,
// the scheduler and the time step), written as YAML so the reader's
// validation runs on it too. A scenario the reader refuses must be refused
// with an error that says where; one it accepts is built and stepped 50
// times, and after every step the soak checks (sim/soak_stage.h) must hold:
// no non-finite agent, no agent outside free space, no pair overlapping
// beyond the model's bound (with the default contact passes or more).
// Random bytes rarely make such scenarios through fuzz_scenario; this
// target makes nearly every input one.
// THRONG_FUZZ_PRINT=1 prints each input's scenario and whether it was
// refused (to read a finding: ./fuzz_scenario_structured CRASH_FILE).
#include <fuzzer/FuzzedDataProvider.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "io/scenario_yaml.h"
#include "sim/soak_stage.h"

namespace {

using throng::Error;

struct Box {
  float x0, y0, x1, y1;
};

// A coordinate inside the box, on a 5 cm lattice so that the YAML text
// carries it exactly.
float coordinate(FuzzedDataProvider& in, float lo, float hi) {
  const int steps = static_cast<int>((hi - lo) / 0.05f);
  return lo + 0.05f * static_cast<float>(in.ConsumeIntegralInRange(0, steps));
}

std::string point(FuzzedDataProvider& in, const Box& b) {
  return fmt::format("[{:g}, {:g}]", coordinate(in, b.x0, b.x1), coordinate(in, b.y0, b.y1));
}

std::string rect(FuzzedDataProvider& in, const Box& b, float max_side) {
  const float x = coordinate(in, b.x0, b.x1 - 0.2f), y = coordinate(in, b.y0, b.y1 - 0.2f);
  const float w = 0.2f + coordinate(in, 0, max_side), h = 0.2f + coordinate(in, 0, max_side);
  return fmt::format("{{rect: {{min: [{:g}, {:g}], max: [{:g}, {:g}]}}}}", x, y, std::min(x + w, b.x1),
                     std::min(y + h, b.y1));
}

std::string obstacle(FuzzedDataProvider& in, const Box& b) {
  switch (in.ConsumeIntegralInRange(0, 2)) {
    case 0: return rect(in, b, 4);
    case 1: return fmt::format("{{circle: {{center: {}, radius: {:g}}}}}", point(in, b), 0.1f + coordinate(in, 0, 2));
    default: {  // star-shaped round a centre (angles in order): simple, maybe thin or concave
      const float cx = coordinate(in, b.x0, b.x1), cy = coordinate(in, b.y0, b.y1);
      const int n = in.ConsumeIntegralInRange(3, 7);
      std::string ring;
      for (int i = 0; i < n; ++i) {
        const float angle =
            6.2831853f * (static_cast<float>(i) + 0.9f * in.ConsumeProbability<float>()) / static_cast<float>(n);
        const float r = 0.2f + coordinate(in, 0, 3);
        ring += fmt::format("{}[{:.2f}, {:.2f}]", i ? ", " : "", cx + r * std::cos(angle), cy + r * std::sin(angle));
      }
      return fmt::format("{{polygon: [{}]}}", ring);
    }
  }
}

std::string goal(FuzzedDataProvider& in, const Box& b) {
  switch (in.ConsumeIntegralInRange(0, 3)) {
    case 0: return fmt::format("{{point: {}}}", point(in, b));
    case 1: return fmt::format("{{random: {}}}", rect(in, b, 6));
    case 2:  // the start reflected through a point: crowds that meet head-on
      return fmt::format("{{mirror: [{:g}, {:g}]}}", 0.5f * (b.x0 + b.x1), 0.5f * (b.y0 + b.y1));
    default: return fmt::format("{{offset: [{:g}, {:g}]}}", coordinate(in, -5, 5), coordinate(in, -5, 5));
  }
}

// Model parameters inside the ranges docs/scenarios.md documents.
// max_speed keeps dt * max_speed below 0.9 x the smallest radius (0.15 m),
// as the reader demands.
std::string model(FuzzedDataProvider& in, float dt) {
  const char* types[] = {"priority", "collision_free_speed", "ttc", "social_force"};
  const int type = in.ConsumeIntegralInRange(0, 3);
  const float fastest = 0.9f * 0.15f / dt - 0.01f;
  const float max_speed = std::min(fastest, 1.0f + 0.25f * static_cast<float>(in.ConsumeIntegralInRange(0, 6)));
  std::string m = fmt::format("model:\n  type: {}\n  max_speed: {:.2f}\n", types[type], max_speed);
  if (in.ConsumeBool()) m += fmt::format("  contact_iterations: {}\n", in.ConsumeIntegralInRange(0, 8));
  if (in.ConsumeBool())
    m += fmt::format("  contact_extra_iterations: {}\n  contact_tolerance: {:g}\n", in.ConsumeIntegralInRange(0, 16),
                     0.01f * static_cast<float>(in.ConsumeIntegralInRange(1, 10)));
  switch (type) {
    case 0:
      if (in.ConsumeBool())
        m += fmt::format("  personal_space: {:g}\n  probe_margin: {:g}\n", 0.05f * in.ConsumeIntegralInRange(0, 6),
                         0.05f * in.ConsumeIntegralInRange(0, 4));
      break;
    case 1:
      if (in.ConsumeBool())
        m += fmt::format("  time_gap: {:g}\n  avoid_strength: {:g}\n  turn_time: {:g}\n",
                         0.25f * in.ConsumeIntegralInRange(1, 8), 0.5f * in.ConsumeIntegralInRange(0, 10),
                         0.1f * in.ConsumeIntegralInRange(0, 10));
      break;
    case 2:
      if (in.ConsumeBool())
        m += fmt::format("  ttc_strength: {:g}\n  ttc_side_bias: {:g}\n", 0.5f * in.ConsumeIntegralInRange(0, 10),
                         0.5f * in.ConsumeIntegralInRange(0, 20));
      break;
    default:
      if (in.ConsumeBool())
        m += fmt::format("  sf_anisotropy: {:g}\n  sf_side_bias: {:g}\n  sf_max_substep: {:g}\n",
                         0.25f * in.ConsumeIntegralInRange(0, 4), 0.5f * in.ConsumeIntegralInRange(0, 20),
                         0.005f * in.ConsumeIntegralInRange(1, 4));
      break;
  }
  return m;
}

std::string scenario_yaml(FuzzedDataProvider& in) {
  const float w = 4.0f + coordinate(in, 0, 36), h = 4.0f + coordinate(in, 0, 36);
  const Box b{0, 0, w, h};
  const char* schedulers[] = {"double_buffer", "four_colour"};
  const float dt = in.ConsumeBool() ? 0.1f : 0.05f;
  std::string y =
      fmt::format("name: structured\nseed: {}\ndt: {:g}\nscheduler: {}\nplanning: {}\nstop_when_arrived: false\n",
                  in.ConsumeIntegralInRange(0, 1000), dt, schedulers[in.ConsumeIntegralInRange(0, 1)],
                  in.ConsumeBool() ? "roadmap" : "none");
  y += model(in, dt);
  y += fmt::format("world:\n  walkable: {{rect: {{min: [0, 0], max: [{:g}, {:g}]}}}}\n", w, h);
  const int obstacles = in.ConsumeIntegralInRange(0, 8);
  if (obstacles > 0) {
    y += "  obstacles:\n";
    for (int i = 0; i < obstacles; ++i) y += "    - " + obstacle(in, b) + "\n";
  }
  y += "groups:\n";
  const int groups = in.ConsumeIntegralInRange(1, 3);
  const char* arrivals[] = {"stop", "despawn", "loop"};
  for (int g = 0; g < groups; ++g) {
    const float radius = 0.15f + 0.05f * static_cast<float>(in.ConsumeIntegralInRange(0, 3));
    const float x = coordinate(in, 0, w - 1), y0 = coordinate(in, 0, h - 1);
    const float sx = std::min(1.0f + coordinate(in, 0, 10), w - x), sy = std::min(1.0f + coordinate(in, 0, 10), h - y0);
    // Up to about half of what a square packing holds: usually placeable.
    const int room = static_cast<int>(sx * sy / (8.0f * radius * radius));
    y += fmt::format(
        "  - name: g{}\n    count: {}\n    radius: {:g}\n    spawn: {{rect: {{min: [{:g}, {:g}], max: [{:g}, "
        "{:g}]}}}}\n    goal: {}\n    on_arrival: {}\n",
        g, in.ConsumeIntegralInRange(0, std::clamp(room, 1, 60)), radius, x, y0, x + sx, y0 + sy, goal(in, b),
        arrivals[in.ConsumeIntegralInRange(0, 2)]);
    if (in.ConsumeBool())
      y += fmt::format("    speed: {{mean: {:g}, stddev: 0.2, min: 0.5, max: 1.0}}\n",
                       0.5f + 0.1f * in.ConsumeIntegralInRange(0, 5));
    if (in.ConsumeBool()) y += fmt::format("    waypoints:\n      - {{point: {}}}\n", point(in, b));
  }
  return y;
}

}  // namespace

// The simulation logs its set-up (routes planned, agents without one) at
// info and warn; per input that would bury libFuzzer's own lines.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::err);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace throng;
  FuzzedDataProvider in(data, size);
  const std::string text = scenario_yaml(in);
  static const bool print = std::getenv("THRONG_FUZZ_PRINT") != nullptr;
  if (print) std::fprintf(stderr, "---\n%s", text.c_str());
  io::ScenarioReadLimits limits;
  limits.scenario.max_agents = 400;
  std::unique_ptr<sim::Simulation> sim;
  try {
    const io::LoadedScenario s = io::parse_scenario(text, "structured.yaml", limits);
    sim::SimulationOptions options;
    options.limits = limits.scenario;
    sim = io::build_simulation(s, options);
  } catch (const Error& e) {
    // Refusing is fine (a spawn region may be walled in); refusing without
    // saying where is not.
    if (e.location().line <= 0 && e.location().field.empty()) {
      std::fprintf(stderr, "unlocated error: %s\n%s", e.what(), text.c_str());
      std::abort();
    }
    if (print) std::fprintf(stderr, "refused: %s\n", e.what());
    return 0;
  }
  sim::SoakOptions checks;
  checks.every = 1;
  checks.max_steps = 50;
  // The 8 cm bound is what the models keep to with the default contact
  // passes (docs/simulation.md, "Acceptance"); with fewer passes or a
  // looser tolerance a user has traded it for speed, and only the other
  // checks hold.
  const sim::ModelParams& model = sim->spec().model;
  const sim::ModelParams defaults;
  if (model.contact_iterations < defaults.contact_iterations ||
      model.contact_extra_iterations < defaults.contact_extra_iterations ||
      model.contact_tolerance > defaults.contact_tolerance)
    checks.overlap_bound = INFINITY;
  sim::SoakCheckStage stage(checks);
  try {
    for (std::int64_t k = 1; k <= 50; ++k) {
      sim->step();
      stage.after_step(*sim, {k, sim->time(), k == 50});
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\nscenario:\n%s", e.what(), text.c_str());
    std::abort();
  }
  return 0;
}
