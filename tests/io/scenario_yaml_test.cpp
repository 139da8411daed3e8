// Scenario YAML: the schema read into a ScenarioSpec, the built-ins (the
// examples/ files themselves), and the malformed corpus (tests/data/
// scenario_bad): every file gives one clear error at its file:line:column
// and key path, none crashes.
#include "io/scenario_yaml.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/ground.h"
#include "sim/metrics.h"
#include "sim/simulation.h"

namespace throng::io {
namespace {

const std::filesystem::path kRoot = std::filesystem::path(THRONG_SOURCE_DIR);
const std::filesystem::path kCorpus = kRoot / "tests" / "data" / "scenario_bad";

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Expectation {
  std::string file, field, text;
  int line = 0, column = 0;
};

std::vector<Expectation> expectations() {
  std::vector<Expectation> out;
  std::ifstream in(kCorpus / "EXPECTED.txt");
  std::string row;
  while (std::getline(in, row)) {
    if (row.empty() || row[0] == '#') continue;
    std::vector<std::string> cols;
    std::size_t start = 0;
    for (std::size_t tab; (tab = row.find('\t', start)) != std::string::npos; start = tab + 1)
      cols.push_back(row.substr(start, tab - start));
    cols.push_back(row.substr(start));
    EXPECT_EQ(cols.size(), 5u) << row;
    if (cols.size() == 5) out.push_back({cols[0], cols[3], cols[4], std::stoi(cols[1]), std::stoi(cols[2])});
  }
  return out;
}

TEST(ScenarioBadCorpus, EveryFileGivesOneClearErrorAtItsKey) {
  const auto cases = expectations();
  ASSERT_GE(cases.size(), 50u) << "corpus missing at " << kCorpus;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string path = (kCorpus / c.file).string();
    try {
      const LoadedScenario s = read_scenario_file(path);
      build_simulation(s);  // geometry and model errors surface here
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.location().file, path);
      EXPECT_EQ(e.location().line, c.line) << what;
      EXPECT_EQ(e.location().column, c.column) << what;
      EXPECT_EQ(e.location().field, c.field) << what;
      EXPECT_NE(what.find(path + ":" + std::to_string(c.line) + ":" + std::to_string(c.column)), std::string::npos)
          << what;
      EXPECT_NE(what.find(c.text), std::string::npos) << "\n  got:    " << what << "\n  wanted: " << c.text;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    }
  }
}

TEST(ScenarioBadCorpus, EveryFileIsListed) {
  std::set<std::string> listed;
  for (const auto& c : expectations()) listed.insert(c.file);
  for (const auto& entry : std::filesystem::directory_iterator(kCorpus))
    if (entry.path().extension() == ".yaml") {
      EXPECT_TRUE(listed.count(entry.path().filename().string())) << entry.path();
    }
}

// Every prefix of a valid file (a truncated download) and many single-byte
// changes either read or give a located Error; none crashes or hangs.
TEST(ScenarioBadCorpus, TruncationsAndByteFlipsNeverCrash) {
  const std::string text = slurp(kRoot / "examples" / "bottleneck.yaml");
  ASSERT_NO_THROW(parse_scenario(text, "valid.yaml"));
  ScenarioReadLimits small;
  small.scenario.max_agents = 400;
  auto attempt = [&](std::string_view t, const char* name) {
    try {
      LoadedScenario s = parse_scenario(t, name, small);
      if (s.spec.total_agents() <= 400) build_simulation(s);
    } catch (const Error& e) {
      EXPECT_TRUE(e.location().line > 0 || !e.location().field.empty()) << e.what();
    }
  };
  for (std::size_t n = 0; n < text.size(); n += 11) attempt(std::string_view(text).substr(0, n), "prefix.yaml");
  std::string flipped = text;
  for (std::size_t i = 0; i < text.size(); i += 9) {
    for (char c : {'\0', '[', ':', '9', '\n'}) {
      flipped[i] = c;
      attempt(flipped, "flipped.yaml");
    }
    flipped[i] = text[i];
  }
}

TEST(ScenarioYaml, EveryKeyOfTheSchema) {
  const std::string text = R"(name: all
description: every key once
seed: 42
scheduler: four_colour
planning: none
dt: 0.05
steps: 120
stop_when_arrived: false
model:
  type: priority
  pred_time: 1.5
  max_speed: 1.8
  max_force: 5
  personal_space: 0.2
  lane_half_width: 1.0
  relaxation_time: 0.4
  probe_margin: 0.15
  contact_iterations: 3
  contact_extra_iterations: 5
  contact_tolerance: 0.02
world:
  walkable:
    polygon: [[-50, -50], [50, -50], [50, 50], [-50, 50]]
    holes:
      - [[-1, -1], [1, -1], [1, 1], [-1, 1]]
  obstacles:
    - polygon: [[10, 10], [12, 10], [12, 12]]
    - rect: {min: [20, 20], max: [22, 25]}
    - circle: {center: [-20, 5], radius: 1.5}
  scatter:
    - count: 3
      region: {rect: {min: [30, -40], max: [45, -30]}}
      size: [1, 2]
      clearance: 1
      seed: 9
groups:
  - name: first
    count: 12
    radius: 0.3
    speed: {mean: 1.2, stddev: 0.1, min: 0.9, max: 1.5}
    spawn: {disc: {center: [-30, -30], radius: 4}}
    waypoints:
      - [0, -30]
      - {offset: [5, 5]}
    goal: {random: {rect: {min: [30, 30], max: [40, 40]}}}
    on_arrival: loop
    arrival_radius: 0.8
  - count: 8
    speed: 1.1
    spawn: {ring: {center: [0, 20], spacing: 1.5}}
    goal: {mirror: [0, 20]}
  - count: 4
    spawn: {polygon: [[-40, 30], [-35, 30], [-35, 35]]}
    goal: {point: [-10, 40]}
    on_arrival: despawn
  - spawn:
      points:
        - [-20, -20]
        - [-19.5, -20]
    goal: {point: [-10, -20]}
camera:
  position: [0, -30, 20]
  target: [0, 0, 1]
  fov_degrees: 45
  width: 640
  height: 480
  near: 0.5
  far: 500
measurement: {rect: {min: [-5, 10], max: [5, 15]}}
outputs:
  dir: out/all
  every: 4
  trajectories: false
  stats: true
)";
  const LoadedScenario l = parse_scenario(text, "all.yaml");
  const sim::ScenarioSpec& s = l.spec;
  EXPECT_EQ(s.name, "all");
  EXPECT_EQ(s.description, "every key once");
  EXPECT_EQ(s.seed, 42u);
  EXPECT_EQ(s.scheduler, sim::SchedulerKind::FourColour);
  EXPECT_EQ(s.planning, sim::PlanningKind::None);
  EXPECT_FLOAT_EQ(s.dt, 0.05f);
  EXPECT_EQ(s.step_count(), 120);
  EXPECT_FALSE(s.stop_when_arrived);
  EXPECT_FLOAT_EQ(s.model.pred_time, 1.5f);
  EXPECT_FLOAT_EQ(s.model.max_speed, 1.8f);
  EXPECT_FLOAT_EQ(s.model.max_force, 5.0f);
  EXPECT_FLOAT_EQ(s.model.personal_space, 0.2f);
  EXPECT_FLOAT_EQ(s.model.lane_half_width, 1.0f);
  EXPECT_FLOAT_EQ(s.model.relaxation_time, 0.4f);
  EXPECT_FLOAT_EQ(s.model.probe_margin, 0.15f);
  EXPECT_EQ(s.model.contact_iterations, 3);
  EXPECT_EQ(s.model.contact_extra_iterations, 5);
  EXPECT_FLOAT_EQ(s.model.contact_tolerance, 0.02f);
  ASSERT_TRUE(s.world.has_walkable);
  EXPECT_EQ(s.world.walkable.outer.size(), 4u);
  EXPECT_EQ(s.world.walkable.holes.size(), 1u);
  ASSERT_EQ(s.world.polygons.size(), 2u);  // the polygon and the rect
  EXPECT_EQ(s.world.polygons[1].outer[2], glm::vec2(22, 25));
  EXPECT_EQ(s.world.polygon_fields[1], "world.obstacles[1]");
  ASSERT_EQ(s.world.circles.size(), 1u);
  EXPECT_EQ(s.world.circle_fields[0], "world.obstacles[2]");
  EXPECT_FLOAT_EQ(s.world.circles[0].radius, 1.5f);
  ASSERT_EQ(s.world.scatters.size(), 1u);
  EXPECT_EQ(s.world.scatters[0].count, 3);
  EXPECT_FLOAT_EQ(s.world.scatters[0].max_size, 2.0f);
  EXPECT_EQ(s.world.scatters[0].seed, 9u);
  ASSERT_EQ(s.groups.size(), 4u);
  const sim::GroupSpec& g = s.groups[0];
  EXPECT_EQ(g.name, "first");
  EXPECT_EQ(g.count, 12);
  EXPECT_FLOAT_EQ(g.radius, 0.3f);
  EXPECT_FLOAT_EQ(g.speed.stddev, 0.1f);
  EXPECT_EQ(g.spawn.kind, sim::Region::Kind::disc);
  ASSERT_EQ(g.waypoints.size(), 2u);
  EXPECT_EQ(g.waypoints[0].kind, sim::GoalSpec::Kind::Point);
  EXPECT_EQ(g.waypoints[1].kind, sim::GoalSpec::Kind::Offset);
  EXPECT_EQ(g.goal.kind, sim::GoalSpec::Kind::Random);
  EXPECT_EQ(g.arrival, sim::ArrivalBehaviour::Loop);
  EXPECT_FLOAT_EQ(g.arrival_radius, 0.8f);
  EXPECT_FLOAT_EQ(s.groups[1].speed.min, 1.1f);  // one number: everyone at that speed
  EXPECT_FLOAT_EQ(s.groups[1].speed.max, 1.1f);
  EXPECT_EQ(s.groups[1].spawn.kind, sim::Region::Kind::ring);
  EXPECT_EQ(s.groups[1].goal.kind, sim::GoalSpec::Kind::Mirror);
  EXPECT_EQ(s.groups[2].spawn.kind, sim::Region::Kind::polygon);
  EXPECT_EQ(s.groups[2].arrival, sim::ArrivalBehaviour::Despawn);
  EXPECT_EQ(s.groups[3].spawn.kind, sim::Region::Kind::points);  // count left out: one agent per point
  EXPECT_EQ(s.groups[3].count, 2);
  EXPECT_EQ(s.groups[3].spawn.points[1], glm::vec2(-19.5f, -20));
  // The camera is given on the map (z up) and kept in the Y-up world.
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_EQ(s.camera->position, world_from_map({0, -30, 20}));
  EXPECT_EQ(s.camera->position, glm::vec3(0, 20, 30));
  EXPECT_EQ(s.camera->target, glm::vec3(0, 1, 0));
  EXPECT_NEAR(s.camera->fov_y, 45.0f * 0.0174532925f, 1e-6f);
  EXPECT_EQ(s.camera->width, 640);
  EXPECT_FLOAT_EQ(s.camera->far_plane, 500.0f);
  ASSERT_EQ(s.measurement.areas.size(), 1u);  // the single-rect form
  EXPECT_EQ(s.measurement.areas[0].name, "area");
  EXPECT_EQ(s.measurement.areas[0].rect.min, glm::vec2(-5, 10));
  EXPECT_EQ(s.measurement.areas[0].rect.max, glm::vec2(5, 15));
  EXPECT_TRUE(s.measurement.lines.empty());
  EXPECT_EQ(s.outputs.dir, "out/all");
  EXPECT_EQ(s.outputs.every, 4);
  EXPECT_FALSE(s.outputs.trajectories);
  // Every key's position is known.
  EXPECT_EQ(l.source.locate("groups[0].waypoints[1]").line, 44);
  EXPECT_EQ(l.source.locate("groups[2].spawn.polygon[1]").line, 53);
  EXPECT_EQ(l.source.locate("groups[3].spawn.points[1]").line, 59);  // each point, though not recorded as a key
  EXPECT_EQ(l.source.locate("groups[3].spawn.points[1]").column, 11);
  EXPECT_EQ(l.source.locate("groups[3].spawn.points[7]").line, 58);  // beyond the list: where the list starts
  // And it all builds and runs.
  const auto sim = build_simulation(l);
  EXPECT_EQ(sim->agent_count(), 26);
  const std::vector<glm::vec2> at = sim->positions();
  EXPECT_NE(std::find(at.begin(), at.end(), glm::vec2(-19.5f, -20)), at.end());
  sim->run(5);
}

constexpr const char* kOneGroup = R"(name: m
groups:
  - count: 4
    spawn: {rect: {min: [0, 0], max: [5, 5]}}
    goal: {point: [20, 2]}
)";

TEST(ScenarioYaml, TrajectoryOutputsLongAndShortForms) {
  const std::string head = "groups:\n  - count: 1\n    spawn: {points: [[0, 0]]}\n    goal: {point: [5, 0]}\n";
  const LoadedScenario map_form =
      parse_scenario(head + "outputs:\n  trajectories: {format: sqlite, every: 7}\n", "t.yaml");
  EXPECT_EQ(map_form.trajectory_format, TrajectoryFormat::Sqlite);
  EXPECT_EQ(map_form.spec.outputs.every, 7);
  EXPECT_TRUE(map_form.spec.outputs.trajectories);
  const LoadedScenario format_only =
      parse_scenario(head + "outputs:\n  every: 3\n  trajectories:\n    format: pedpy\n", "t.yaml");
  EXPECT_EQ(format_only.trajectory_format, TrajectoryFormat::Pedpy);
  EXPECT_EQ(format_only.spec.outputs.every, 3);  // the stride where it always was
  const LoadedScenario short_form = parse_scenario(head + "outputs: {every: 3, trajectories: true}\n", "t.yaml");
  EXPECT_EQ(short_form.trajectory_format, TrajectoryFormat::Csv);
  EXPECT_EQ(short_form.spec.outputs.every, 3);
  EXPECT_TRUE(short_form.spec.outputs.trajectories);
  EXPECT_FALSE(parse_scenario(head + "outputs: {trajectories: false}\n", "t.yaml").spec.outputs.trajectories);
  EXPECT_EQ(parse_scenario(head, "t.yaml").trajectory_format, TrajectoryFormat::Csv);
  try {
    parse_scenario(head + "outputs:\n  trajectories: {format: hdf5}\n", "t.yaml");
    FAIL() << "accepted hdf5";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "outputs.trajectories.format");
    EXPECT_EQ(e.location().line, 6);
    EXPECT_NE(e.message().find("unknown trajectory format 'hdf5': expected csv, pedpy or sqlite"), std::string::npos)
        << e.message();
  }
  try {
    parse_scenario(head + "outputs:\n  trajectories: {fromat: csv}\n", "t.yaml");
    FAIL() << "accepted fromat";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "outputs.trajectories.fromat");
    EXPECT_NE(e.message().find("did you mean 'format'"), std::string::npos) << e.message();
  }
}

TEST(ScenarioYaml, MeasurementAreasAndLines) {
  const std::string text = std::string(kOneGroup) + R"(measurement:
  voronoi_cutoff: 1.5
  areas:
    - {name: door, rect: {min: [1, 2], max: [3, 4]}}
    - rect: {min: [-1, -1], max: [0, 0]}
  lines:
    - {name: exit, from: [10, 0], to: [10, 5]}
    - {from: [0, 0], to: [1, 1]}
)";
  const sim::MeasurementSpec m = parse_scenario(text, "m.yaml").spec.measurement;
  EXPECT_FLOAT_EQ(m.voronoi_cutoff, 1.5f);
  ASSERT_EQ(m.areas.size(), 2u);
  EXPECT_EQ(m.areas[0].name, "door");
  EXPECT_EQ(m.areas[0].rect.min, glm::vec2(1, 2));
  EXPECT_EQ(m.areas[0].rect.max, glm::vec2(3, 4));
  EXPECT_EQ(m.areas[1].name, "area1");  // unnamed: by position
  ASSERT_EQ(m.lines.size(), 2u);
  EXPECT_EQ(m.lines[0].name, "exit");
  EXPECT_EQ(m.lines[0].from, glm::vec2(10, 0));
  EXPECT_EQ(m.lines[0].to, glm::vec2(10, 5));
  EXPECT_EQ(m.lines[1].name, "line1");

  // Only lines: the areas stay to the default (the stage's 10 m square).
  const sim::MeasurementSpec lines_only =
      parse_scenario(std::string(kOneGroup) + "measurement: {lines: [{from: [0, 0], to: [0, 1]}]}\n", "l.yaml")
          .spec.measurement;
  EXPECT_TRUE(lines_only.areas.empty());
  EXPECT_EQ(lines_only.lines.size(), 1u);
  EXPECT_FLOAT_EQ(lines_only.voronoi_cutoff, 2.0f);
}

// Parsing the one-group scenario with `model` fails with a message naming
// the model that owns the misplaced parameter.
void expect_owner_named(const std::string& model, const std::string& owner) {
  std::string message = "no error";
  try {
    parse_scenario(std::string(kOneGroup) + "model: " + model + "\n", "a.yaml");
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(owner), std::string::npos) << message;
}
// Pre-movement: one number (every agent waits that long) or a distribution
// (normal and lognormal: min defaults to 0, max to the mean + 4 stddev).
TEST(ScenarioYaml, PremovementForms) {
  using Kind = sim::PremovementSpec::Kind;
  auto read = [](const std::string& value) {
    return parse_scenario(std::string(kOneGroup) + "    premovement: " + value + "\n", "p.yaml")
        .spec.groups[0]
        .premovement;
  };
  const sim::PremovementSpec none = parse_scenario(kOneGroup, "p.yaml").spec.groups[0].premovement;
  EXPECT_EQ(none.kind, Kind::none);
  auto expect = [](const sim::PremovementSpec& p, Kind kind, std::array<float, 4> mean_stddev_min_max) {
    EXPECT_EQ(p.kind, kind);
    const std::array<float, 4> got = {p.mean, p.stddev, p.min, p.max};
    for (std::size_t k = 0; k < got.size(); ++k) EXPECT_FLOAT_EQ(got[k], mean_stddev_min_max[k]) << k;
  };
  expect(read("12.5"), Kind::uniform, {0, 0, 12.5f, 12.5f});
  expect(read("{distribution: uniform, min: 10, max: 100}"), Kind::uniform, {0, 0, 10, 100});
  expect(read("{distribution: normal, mean: 30, stddev: 5}"), Kind::normal, {30, 5, 0, 50});
  expect(read("{distribution: lognormal, mean: 20, stddev: 8, min: 1, max: 90}"), Kind::lognormal, {20, 8, 1, 90});
  EXPECT_THROW(read("{distribution: normal, mean: 30}"), Error);  // stddev is required
  EXPECT_THROW(read("{distribution: uniform, min: 1}"), Error);   // max too
  EXPECT_THROW(read("{min: 1, max: 2}"), Error);                  // and the distribution
}

// Inflow: a rate (from 0 and without end unless given) or listed times (the
// count may then be left out: one agent per time).
TEST(ScenarioYaml, InflowForms) {
  const std::string head = "groups:\n  - spawn: {rect: {min: [0, 0], max: [5, 5]}}\n    goal: {point: [20, 2]}\n";
  const sim::GroupSpec rate =
      parse_scenario(head + "    count: 8\n    inflow: {rate: 2.5, from: 3, until: 9}\n", "i.yaml").spec.groups[0];
  EXPECT_TRUE(rate.inflow.enabled);
  EXPECT_EQ(rate.count, 8);
  EXPECT_FLOAT_EQ(rate.inflow.rate, 2.5f);
  EXPECT_FLOAT_EQ(rate.inflow.from, 3.0f);
  EXPECT_FLOAT_EQ(rate.inflow.until, 9.0f);
  EXPECT_FLOAT_EQ(rate.inflow.entry_time(2), 3.8f);
  const sim::GroupSpec open = parse_scenario(head + "    count: 8\n    inflow: {rate: 1}\n", "i.yaml").spec.groups[0];
  EXPECT_FLOAT_EQ(open.inflow.from, 0.0f);
  EXPECT_TRUE(std::isinf(open.inflow.until));
  const sim::GroupSpec listed = parse_scenario(head + "    inflow: {times: [1, 2, 4]}\n", "i.yaml").spec.groups[0];
  EXPECT_EQ(listed.count, 3);
  EXPECT_EQ(listed.inflow.times, (std::vector<float>{1, 2, 4}));
  EXPECT_THROW(parse_scenario(head + "    inflow: {rate: 1}\n", "i.yaml"), Error);  // count is required with a rate
  EXPECT_THROW(parse_scenario(head + "    inflow: {times: []}\n", "i.yaml"), Error);
  EXPECT_THROW(parse_scenario(head + "    count: 2\n    inflow: {times: [1], rate: 2}\n", "i.yaml"), Error);
}

// A goal of exits: points with widths (1 m by default), nearest unless the
// choice says quickest, reconsidered every 2 s unless given.
TEST(ScenarioYaml, ExitsGoal) {
  const std::string head = "groups:\n  - count: 4\n    spawn: {rect: {min: [0, 0], max: [5, 5]}}\n";
  const sim::GoalSpec nearest =
      parse_scenario(head + "    goal: {exits: [{point: [20, 2], width: 1.5}, {point: [-9, 3]}]}\n", "e.yaml")
          .spec.groups[0]
          .goal;
  EXPECT_EQ(nearest.kind, sim::GoalSpec::Kind::Exits);
  EXPECT_EQ(nearest.choice, sim::ExitChoice::Nearest);
  ASSERT_EQ(nearest.exits.size(), 2u);
  EXPECT_EQ(nearest.exits[0].point, glm::vec2(20, 2));
  EXPECT_FLOAT_EQ(nearest.exits[0].width, 1.5f);
  EXPECT_FLOAT_EQ(nearest.exits[1].width, 1.0f);
  EXPECT_FLOAT_EQ(nearest.reconsider_s, 2.0f);
  // Agents leave by their exit unless the group says otherwise.
  EXPECT_EQ(parse_scenario(head + "    goal: {exits: [{point: [20, 2]}]}\n", "e.yaml").spec.groups[0].arrival,
            sim::ArrivalBehaviour::Despawn);
  EXPECT_EQ(parse_scenario(head + "    goal: {exits: [{point: [20, 2]}]}\n    on_arrival: stop\n", "e.yaml")
                .spec.groups[0]
                .arrival,
            sim::ArrivalBehaviour::Stop);
  const sim::GoalSpec quickest =
      parse_scenario(head + "    goal: {exits: [{point: [20, 2]}], choice: quickest, reconsider: 5}\n", "e.yaml")
          .spec.groups[0]
          .goal;
  EXPECT_EQ(quickest.choice, sim::ExitChoice::Quickest);
  EXPECT_FLOAT_EQ(quickest.reconsider_s, 5.0f);
}

// Named exits (a point and width, or a door line: its middle and length)
// that goals name; gates and waits on waypoints.
TEST(ScenarioYaml, NamedExitsGatesAndWaits) {
  const std::string text = R"(exits:
  - {name: east, point: [30, 2], width: 1.2}
  - {name: north, from: [10, 20], to: [13, 24]}
groups:
  - count: 4
    spawn: {rect: {min: [0, 0], max: [5, 5]}}
    waypoints:
      - {gate: [[8, -1], [8, 6]]}
      - {random: {rect: {min: [12, 0], max: [16, 4]}}, wait: 7.5}
      - {point: [18, 2], wait: 2}
    goal: {exits: [north, {from: [30, 8], to: [30, 10]}, east], choice: quickest}
)";
  const sim::GroupSpec g = parse_scenario(text, "j.yaml").spec.groups[0];
  ASSERT_EQ(g.waypoints.size(), 3u);
  EXPECT_EQ(g.waypoints[0].kind, sim::GoalSpec::Kind::Gate);
  EXPECT_EQ(g.waypoints[0].value, glm::vec2(8, -1));
  EXPECT_EQ(g.waypoints[0].gate_to, glm::vec2(8, 6));
  EXPECT_EQ(g.waypoints[0].wait_s, 0.0f);
  EXPECT_EQ(g.waypoints[1].kind, sim::GoalSpec::Kind::Random);
  EXPECT_FLOAT_EQ(g.waypoints[1].wait_s, 7.5f);
  EXPECT_FLOAT_EQ(g.waypoints[2].wait_s, 2.0f);
  ASSERT_EQ(g.goal.exits.size(), 3u);
  EXPECT_EQ(g.goal.exits[0].name, "north");
  EXPECT_EQ(g.goal.exits[0].point, glm::vec2(11.5f, 22.0f));
  EXPECT_FLOAT_EQ(g.goal.exits[0].width, 5.0f);
  EXPECT_EQ(g.goal.exits[1].point, glm::vec2(30, 9));
  EXPECT_FLOAT_EQ(g.goal.exits[1].width, 2.0f);
  EXPECT_EQ(g.goal.exits[2].name, "east");
  EXPECT_FLOAT_EQ(g.goal.exits[2].width, 1.2f);
  EXPECT_EQ(g.goal.choice, sim::ExitChoice::Quickest);
  // An exit named before any are given says where to name them.
  try {
    parse_scenario("groups:\n  - count: 4\n    spawn: {rect: {min: [0, 0], max: [5, 5]}}\n    goal: {exits: [east]}\n",
                   "n.yaml");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("none; name them in the top-level 'exits'"), std::string::npos) << e.what();
  }
}

TEST(ScenarioYaml, TtcModelKeys) {
  const std::string text = std::string(kOneGroup) + R"(model:
  type: ttc
  ttc_strength: 2.0
  ttc_time_horizon: 4
  ttc_relaxation_time: 0.6
  ttc_sensing_radius: 5
  ttc_max_acceleration: 15
  ttc_side_bias: 0.25
)";
  const sim::ModelParams m = parse_scenario(text, "ttc.yaml").spec.model;
  EXPECT_EQ(m.kind, sim::ModelKind::Ttc);
  const std::vector<std::pair<float, float>> read = {{m.ttc.strength, 2.0f},          {m.ttc.time_horizon, 4.0f},
                                                     {m.ttc.relaxation_time, 0.6f},   {m.ttc.sensing_radius, 5.0f},
                                                     {m.ttc.max_acceleration, 15.0f}, {m.ttc.side_bias, 0.25f},
                                                     {m.query_radius(), 5.0f}};
  for (const auto& [got, want] : read) EXPECT_FLOAT_EQ(got, want);
  // A parameter of another model names its owner, either way round.
  expect_owner_named("{type: ttc, time_gap: 1}", "'time_gap' is a parameter of the collision_free_speed model");
  expect_owner_named("{type: priority, ttc_strength: 1}", "'ttc_strength' is a parameter of the ttc model");
  // Without a type (the collision-free speed model by default) the error
  // says how to keep the priority model's parameters.
  expect_owner_named("{pred_time: 1}", "model.type is collision_free_speed (the default; add 'type: priority')");
}

// Bodies larger than the default 0.5 m (RVO2's example walkers, 1.5 m)
// with model.max_radius: the collision-free speed model's bins grow to hold
// them, and such a crowd walks to its goals without overlapping: 40 agents
// in a 32 m square (about 26 m^2 each) walk 60 m east, all in about 62 s.
TEST(ScenarioYaml, MaxRadiusAdmitsLargerBodies) {
  const std::string text = R"(name: large
dt: 0.25
duration: 120
planning: none
model: {max_speed: 2.0, max_radius: 1.5}
groups:
  - count: 40
    radius: 1.5
    speed: 1.0
    spawn: {rect: {min: [0, 0], max: [32, 32]}}
    goal: {offset: [60, 0]}
    on_arrival: despawn
)";
  const LoadedScenario l = parse_scenario(text, "large.yaml");
  EXPECT_FLOAT_EQ(l.spec.model.max_radius(), 1.5f);
  EXPECT_FLOAT_EQ(l.spec.model.query_radius(), 2.0f * 1.5f + 0.5f * 4.0f * 2.0f);  // 2 r + avoid_time / 2 * max_speed
  const auto sim = build_simulation(l);
  float deepest = 0.0f;
  for (int step = 0; step < 480; ++step) {
    sim->step();
    const sim::CrowdState& c = sim->crowd();
    deepest = std::max(deepest,
                       sim::measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), 0.0f, 6.0f).max_depth);
  }
  EXPECT_EQ(sim->arrived_count(), 40);
  EXPECT_LT(deepest, 0.1f * 1.5f);  // a tenth of the radius, as the 8 cm of 0.25 m bodies is a third
}

TEST(ScenarioYaml, SocialForceModelKeys) {
  const std::string text = std::string(kOneGroup) + R"(model:
  type: social_force
  sf_mass: 70
  sf_relaxation_time: 0.4
  sf_strength: 1500
  sf_range: 0.1
  sf_body_stiffness: 1.0e5
  sf_friction: 2.0e5
  sf_anisotropy: 0.3
  sf_sensing_radius: 3
  sf_max_substep: 0.02
  sf_side_bias: 1
)";
  const sim::ModelParams m = parse_scenario(text, "sf.yaml").spec.model;
  EXPECT_EQ(m.kind, sim::ModelKind::SocialForce);
  const std::vector<std::pair<float, float>> read = {
      {m.sf.mass, 70.0f},          {m.sf.relaxation_time, 0.4f}, {m.sf.strength, 1500.0f}, {m.sf.range, 0.1f},
      {m.sf.body_stiffness, 1e5f}, {m.sf.friction, 2e5f},        {m.sf.anisotropy, 0.3f},  {m.sf.sensing_radius, 3.0f},
      {m.sf.max_substep, 0.02f},   {m.sf.side_bias, 1.0f},       {m.query_radius(), 3.0f}};
  for (const auto& [got, want] : read) EXPECT_FLOAT_EQ(got, want);
  // A parameter of another model names its owner, either way round.
  expect_owner_named("{type: social_force, ttc_strength: 1}", "'ttc_strength' is a parameter of the ttc model");
  expect_owner_named("{type: ttc, sf_mass: 80}", "'sf_mass' is a parameter of the social_force model");
}

TEST(ScenarioYaml, MeasurementListsAreBounded) {
  for (const char* list : {"areas", "lines"}) {
    std::string text = std::string(kOneGroup) + "measurement:\n  " + list + ":\n";
    for (int i = 0; i < 1001; ++i)
      text += std::string(list) == "areas" ? "    - {rect: {min: [0, 0], max: [1, 1]}}\n"
                                           : "    - {from: [0, 0], to: [1, 1]}\n";
    try {
      parse_scenario(text, "many.yaml");
      ADD_FAILURE() << list << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.location().field, std::string("measurement.") + list);
      EXPECT_EQ(e.location().line, 8);  // the list's first item
      EXPECT_NE(std::string(e.what()).find(std::string("has more than 1000 ") + list), std::string::npos) << e.what();
    }
  }
}

TEST(ScenarioYaml, CameraLookingStraightDownHasNorthUp) {
  const LoadedScenario l = parse_scenario(
      "groups: [{count: 1, spawn: {rect: {min: [0, 0], max: [1, 1]}}, goal: [5, 5]}]\ncamera: {position: [3, 4, 50], "
      "target: [3, 4, 0]}\n",
      "down.yaml");
  ASSERT_TRUE(l.spec.camera);
  l.spec.camera->validate();
  EXPECT_EQ(l.spec.camera->up, world_from_map({0, 1, 0}));
}

TEST(BuiltinScenarios, AreTheExamplesFiles) {
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(kRoot / "examples"))
    if (entry.path().extension() == ".yaml") files.insert(entry.path().stem().string());
  const std::vector<std::string> names = builtin_scenario_names();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()), files);
  for (const char* required : {"circle", "crossing", "corridor", "bottleneck", "plaza"})
    EXPECT_TRUE(files.count(required)) << required;
  for (const std::string& n : names)
    EXPECT_EQ(*builtin_scenario_text(n), slurp(kRoot / "examples" / (n + ".yaml"))) << n;
}

TEST(BuiltinScenarios, EachReadsBuildsAndRuns) {
  for (const std::string& n : builtin_scenario_names()) {
    SCOPED_TRACE(n);
    LoadedScenario l = load_scenario(n);
    EXPECT_EQ(l.spec.name, n);
    EXPECT_FALSE(l.spec.description.empty());
    EXPECT_EQ(l.source.file, "builtin:" + n);
    if (l.spec.total_agents() > 2000) sim::scale_agent_counts(l.spec, 2000);  // plaza ships with 10^5
    const auto sim = build_simulation(l);
    const std::vector<glm::vec2> start = sim->positions();
    sim->run(3);
    // It ran: three steps, every position finite, the crowd under way, nobody
    // in an obstacle. (Each built-in's outcome run to its end, with
    // arrivals and overlaps at every step: tests/sim/builtin_outcomes_test.cpp.)
    EXPECT_EQ(sim->steps_done(), 3);
    const std::vector<glm::vec2> now = sim->positions();
    ASSERT_EQ(now.size(), start.size());
    EXPECT_TRUE(
        std::all_of(now.begin(), now.end(), [](glm::vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }));
    EXPECT_NE(now, start);
    const sim::CrowdState& c = sim->crowd();
    EXPECT_EQ(sim::count_obstacle_penetrations(sim->world(), c.position.span(), c.radius.span(), c.flags.span(), 1e-3f),
              0);
    // A file path reads the same scenario.
    const LoadedScenario from_file = load_scenario((kRoot / "examples" / (n + ".yaml")).string());
    EXPECT_EQ(from_file.spec.total_agents(), load_scenario(n).spec.total_agents());
  }
  EXPECT_EQ(load_scenario("circle").spec.total_agents(), 1000);
  EXPECT_EQ(load_scenario("crossing").spec.total_agents(), 2000);
}

TEST(BuiltinScenarios, UnknownNamesListTheBuiltins) {
  try {
    load_scenario("circel");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("built-ins: bottleneck, circle"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_scenario("no/such/file.yaml"), Error);
}

}  // namespace
}  // namespace throng::io
