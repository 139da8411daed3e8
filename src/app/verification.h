// throng verify: the RiMEA 3.0 verification tests that apply to a 2D,
// single-level engine (docs/verification.md). Each test runs one or more
// scenario files of examples/verification/ (compiled into the executable),
// measures what the guideline's criterion asks, and says pass or fail with
// the measured value beside the criterion; the tests that need stairs or
// several floors are listed as not applicable, with the reason.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>

#include "io/scenario_yaml.h"
#include "render/plot.h"
#include "sim/metrics.h"
#include "sim/scenario.h"

namespace throng::app {

// One criterion of a test: what the guideline asks (in our words) and what
// the run measured.
struct VerifyCheck {
  std::string criterion;
  std::string measured;
  bool pass = false;
};

enum class VerifyStatus : std::uint8_t { pass, fail, not_applicable };
const char* to_string(VerifyStatus s);

struct VerifyResult {
  int number = 0;  // RiMEA 3.0 test number
  std::string title;
  VerifyStatus status = VerifyStatus::fail;
  std::string reason;                  // why not applicable
  std::vector<std::string> scenarios;  // examples/verification/<name>.yaml run
  std::vector<VerifyCheck> checks;
  nlohmann::json figures = nlohmann::json::object();  // the measured values, for report.json
  std::optional<render::Chart> chart;                 // drawn as rimea_NN.png
  double wall_s = 0;                                  // wall-clock time of the test
};

struct VerifyOptions {
  std::optional<sim::ModelKind> model;  // every file's model type replaced by this (its parameters default)
  std::vector<int> only;                // test numbers to run; empty = every test
};

// What one scenario run recorded for the tests to judge.
struct ScenarioObservation {
  sim::ScenarioSpec spec;  // as run (after the model override)
  double end_time = 0;     // s simulated
  std::int64_t agents = 0;
  std::vector<std::int32_t> group;
  std::vector<float> pref_speed;               // m/s
  std::vector<float> start_time;               // s: pre-movement (0: walks at once)
  std::vector<float> arrival_time;             // s, -1 if never arrived
  std::vector<float> first_move;               // s: when the agent first stood 1 cm from its spawn point; -1 never
  std::vector<glm::vec2> last_seen;            // last position while in the scene
  std::vector<sim::LineCrossing> crossings;    // of spec.measurement.lines, step by step (agent order in a step)
  std::vector<std::vector<glm::vec2>> tracks;  // every 0.5 s, when asked for
  std::vector<std::vector<sim::AreaSample>> area_samples;  // per measurement area, one per simulated second
  Index most_in_walls = 0;                                 // most agents at once whose disc entered a wall by over 1 mm
  float deepest_overlap = 0;                               // m, sampled once a second

  // Arrival times of the agents that arrived, in increasing order.
  std::vector<double> arrivals() const;
  // Last arrival (s), or +inf when someone never arrived.
  double evacuation_time() const;
  // Times of the crossings of measurement line `line` in its positive
  // direction (to the left walking from `from` to `to`), in order; of agent
  // `agent` only when given.
  std::vector<double> crossing_times(std::int32_t line, std::optional<Index> agent = {}) const;
  // Each agent's first positive crossing of line `line`, in order (people,
  // not crossings: one who steps back and across again counts once).
  std::vector<double> first_crossings(std::int32_t line) const;
};

struct ObserveOptions {
  bool tracks = false;                 // record every agent's track (small crowds)
  double sample_from_s = 0;            // area samples from this time on
  std::optional<std::int64_t> agents;  // resize the crowd (sim::scale_agent_counts)
  static ObserveOptions with_tracks() {
    ObserveOptions o;
    o.tracks = true;
    return o;
  }
};

// Loads examples/verification/<name>.yaml (the embedded copy), with the
// model override of `o` applied.
io::LoadedScenario load_verification_scenario(const std::string& name, const VerifyOptions& o);
// Runs it to its end (or until everyone has arrived, when the file says
// so), on the CPU scheduler and threads of the process.
ScenarioObservation observe(const io::LoadedScenario& scenario, const ObserveOptions& options = {});

// A RiMEA test: `run` is empty for the tests that do not apply (the
// reason is in `not_applicable`).
struct VerifyTest {
  int number = 0;
  std::string title;
  std::string not_applicable;
  std::function<VerifyResult(const VerifyOptions&)> run;
};
// Every RiMEA 3.0 test, 1 to 15, in order (verification_tests.cpp).
const std::vector<VerifyTest>& verification_tests();

// Runs the selected tests (progress on stderr); an unknown number in
// `only` is an Error naming --only.
std::vector<VerifyResult> run_verification(const VerifyOptions& o);
// Writes report.md, report.json and one rimea_NN.png per test with a chart
// into `dir` (created); returns the paths written.
std::vector<std::string> write_verification_report(const std::string& dir, const std::vector<VerifyResult>& results,
                                                   const VerifyOptions& o);

}  // namespace throng::app
