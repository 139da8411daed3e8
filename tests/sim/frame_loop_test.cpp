// The frame loop: stage order, frame numbering, stopping, interruption,
// and the stats sections.
#include "sim/frame_loop.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "sim/metrics_stage.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// Records what it saw; checks the simulation has stepped before it runs.
class RecordingStage : public FrameStage {
 public:
  RecordingStage(std::string name, std::vector<std::string>& log) : name_(std::move(name)), log_(log) {}
  std::string name() const override { return name_; }
  void start(const Simulation& sim, const FrameInfo& f) override {
    log_.push_back(name_ + " start " + std::to_string(f.frame));
    EXPECT_EQ(sim.steps_done(), 0);
  }
  void after_step(const Simulation& sim, const FrameInfo& f) override {
    log_.push_back(name_ + " " + std::to_string(f.frame) + (f.last ? " last" : ""));
    EXPECT_EQ(sim.steps_done(), f.frame);
    EXPECT_DOUBLE_EQ(f.time, sim.time());
  }
  void finish(const Simulation&, nlohmann::json& stats) override { stats[name_] = {{"frames", log_.size()}}; }

 private:
  std::string name_;
  std::vector<std::string>& log_;
};

// The mean speed of the crowd at every frame, by the metric function: the
// reference for the metrics stage's running means.
class MeanSpeedStage : public FrameStage {
 public:
  std::string name() const override { return "test.mean_speed"; }
  void after_step(const Simulation& sim, const FrameInfo&) override {
    speeds.push_back(mean_speed(sim.crowd().velocity.span(), sim.crowd().flags.span()));
  }
  std::vector<double> speeds;
};

// A run with more samples than the series keeps: the series is thinned
// (bounded, evenly spread, the last frame last) while the counts, means and
// maxima still cover every sample taken.
TEST(FrameLoop, MetricsOfALongRunKeepBoundedSeriesAndExactMeans) {
  const ScenarioSpec spec = test::builtin("circle", 12);
  Simulation sim(spec);
  FrameLoop loop(sim);
  MetricsOptions options;
  options.sample_every = 1;
  const auto& metrics = loop.emplace<CrowdMetricsStage>(sim, options);
  const auto& reference = loop.emplace<MeanSpeedStage>();
  RunControl control;
  const std::int64_t steps = static_cast<std::int64_t>(2 * kMaxSeriesSamples + 123);
  control.max_steps = steps;
  control.stop_when_arrived = false;
  loop.run(control);
  nlohmann::json stats;
  loop.finish(stats);
  ASSERT_EQ(reference.speeds.size(), static_cast<std::size_t>(steps + 1));
  EXPECT_EQ(metrics.samples_taken(), static_cast<std::uint64_t>(steps + 1));
  EXPECT_EQ(stats["crowd"]["samples"].get<std::int64_t>(), steps + 1);
  EXPECT_EQ(stats["crowd"]["series_stride"].get<std::int64_t>(), 4);
  double sum = 0;
  for (const double v : reference.speeds) sum += v;
  EXPECT_NEAR(stats["crowd"]["mean_speed_mps"]["over_samples"].get<double>(),
              sum / static_cast<double>(reference.speeds.size()), 1e-9);
  const nlohmann::json& series = stats["measurement"]["areas"][0]["samples"];
  EXPECT_LE(series.size(), kMaxSeriesSamples + 1);
  EXPECT_GE(series.size(), kMaxSeriesSamples / 2);
  EXPECT_EQ(series.size(), stats["fundamental_diagram"]["samples"].size());
  EXPECT_DOUBLE_EQ(series.back()["time"].get<double>(), static_cast<double>(steps) * spec.dt);
  for (std::size_t i = 1; i + 1 < series.size(); ++i)
    EXPECT_NEAR(series[i]["time"].get<double>() - series[i - 1]["time"].get<double>(), 4 * spec.dt, 1e-6) << i;
  // The fundamental diagram's bins count every sample with agents in the area.
  std::int64_t binned = 0;
  for (const auto& b : stats["fundamental_diagram"]["bins"]) binned += b["samples"].get<std::int64_t>();
  EXPECT_GT(binned, static_cast<std::int64_t>(series.size()));
}

TEST(FrameLoop, StagesRunAfterEachStepInOrder) {
  Simulation sim(test::builtin("circle", 20));
  FrameLoop loop(sim);
  std::vector<std::string> log;
  loop.emplace<RecordingStage>("a", log);
  loop.emplace<RecordingStage>("b", log);
  RunControl control;
  control.max_steps = 3;
  int progress_calls = 0;
  control.progress = [&](const Simulation&, const FrameInfo&) { ++progress_calls; };
  const RunResult r = loop.run(control);
  EXPECT_EQ(r.steps, 3);
  EXPECT_FALSE(r.interrupted);
  EXPECT_EQ(log,
            (std::vector<std::string>{"a start 0", "b start 0", "a 1", "b 1", "a 2", "b 2", "a 3 last", "b 3 last"}));
  EXPECT_EQ(progress_calls, 4);
  nlohmann::json stats;
  loop.finish(stats);
  EXPECT_TRUE(stats.contains("a") && stats.contains("b"));
  EXPECT_EQ(stats["run"]["steps"], 3);
  EXPECT_EQ(stats["run"]["agents"], 20);
  EXPECT_TRUE(stats["timings"]["stages"].contains("a"));
  for (const char* stage : {"sim.bin", "sim.sense", "sim.steer", "sim.move"})
    EXPECT_TRUE(stats["timings"]["stages"].contains(stage)) << stage;
}

TEST(FrameLoop, StopsWhenEveryoneHasArrived) {
  Simulation sim(test::builtin("circle", 20));
  FrameLoop loop(sim);
  RunControl control;
  control.max_steps = 100000;
  const RunResult r = loop.run(control);
  EXPECT_TRUE(r.all_arrived);
  EXPECT_LT(r.steps, 2000);
  EXPECT_TRUE(sim.all_arrived());
}

TEST(FrameLoop, AnInterruptEndsTheRunAfterTheCurrentFrame) {
  Simulation sim(test::builtin("circle", 20));
  FrameLoop loop(sim);
  std::vector<std::string> log;
  loop.emplace<RecordingStage>("a", log);
  std::atomic<bool> stop{false};
  RunControl control;
  control.max_steps = 1000;
  control.interrupt = &stop;
  control.progress = [&](const Simulation&, const FrameInfo& f) {
    if (f.frame == 5) stop = true;
  };
  const RunResult r = loop.run(control);
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.steps, 6);
  EXPECT_EQ(log.back(), "a 6 last");
  nlohmann::json stats;
  loop.finish(stats);
  EXPECT_TRUE(stats["run"]["interrupted"].get<bool>());
}

TEST(FrameLoop, MetricsStageWritesItsSections) {
  Simulation sim(test::builtin("circle", 100));
  FrameLoop loop(sim);
  MetricsOptions options;
  options.sample_every = 10;
  const auto& metrics = loop.emplace<CrowdMetricsStage>(sim, options);
  RunControl control;
  control.max_steps = 55;
  loop.run(control);
  EXPECT_EQ(metrics.samples().size(), 7u);  // frames 0, 10, ..., 50 and the last (55)
  nlohmann::json stats;
  loop.finish(stats);
  for (const char* section : {"crowd", "density_histogram", "fundamental_diagram", "run", "timings"})
    EXPECT_TRUE(stats.contains(section)) << section;
  EXPECT_EQ(stats["crowd"]["agents"], 100);
  EXPECT_EQ(stats["crowd"]["obstacle_penetrations"]["max"], 0);
  std::int64_t agent_samples = 0;
  for (const auto& b : stats["density_histogram"]["bins"]) agent_samples += b["agent_samples"].get<std::int64_t>();
  EXPECT_EQ(agent_samples, 7 * 100);
  // The default measurement area: 10 m around the scene's centre.
  EXPECT_EQ(stats["fundamental_diagram"]["samples"].size(), 7u);
  const Aabb area = default_measurement_area(sim);
  EXPECT_NEAR(area.size().x, 10.0f, 1e-4f);
}

// Keeps every frame's positions and flags: the reference for the crossings.
class PositionRecorder : public FrameStage {
 public:
  std::string name() const override { return "test.positions"; }
  void after_step(const Simulation& sim, const FrameInfo& f) override {
    times.push_back(f.time);
    positions.push_back(sim.crowd().position.to_vector());
    flags.push_back(sim.crowd().flags.to_vector());
  }
  std::vector<double> times;
  std::vector<std::vector<glm::vec2>> positions;
  std::vector<std::vector<std::uint8_t>> flags;
};

// Lines see every step, though areas are sampled every 10th frame: the
// circle's walkers cross two lines through the centre, counted as a
// brute-force segment test of each frame pair counts them.
TEST(FrameLoop, MetricsStageMeasuresAreasAndEveryStepsLineCrossings) {
  Simulation sim(test::builtin("circle", 100));
  FrameLoop loop(sim);
  MetricsOptions options;
  options.sample_every = 10;
  const std::vector<MeasurementLine> lines{{"north_south", {0.37f, -30.0f}, {0.37f, 30.0f}},
                                           {"west_east", {-30.0f, -0.53f}, {30.0f, -0.53f}}};
  options.measurement.lines = lines;
  Aabb centre, east;
  centre.add({-3, -3});
  centre.add({3, 3});
  east.add({2, -2});
  east.add({6, 2});
  options.measurement.areas = {{"centre", centre}, {"east", east}};
  const auto& metrics = loop.emplace<CrowdMetricsStage>(sim, options);
  const auto& recorded = loop.emplace<PositionRecorder>();
  RunControl control;
  control.max_steps = 300;
  loop.run(control);

  for (std::size_t l = 0; l < lines.size(); ++l) {
    SCOPED_TRACE(lines[l].name);
    std::vector<double> positive, negative;
    for (std::size_t f = 1; f < recorded.positions.size(); ++f)
      for (std::size_t i = 0; i < recorded.positions[f].size(); ++i) {
        const glm::vec2 p0 = recorded.positions[f - 1][i], p1 = recorded.positions[f][i];
        if (!(recorded.flags[f - 1][i] & kAgentActive) || !(recorded.flags[f][i] & kAgentActive)) continue;
        if (!segments_intersect(p0, p1, lines[l].from, lines[l].to)) continue;
        const bool to_left = cross2(lines[l].to - lines[l].from, p1 - lines[l].from) > 0;
        (to_left ? positive : negative).push_back(recorded.times[f]);
      }
    const CrowdMetricsStage::LineTimes& got = metrics.line_times()[l];
    ASSERT_EQ(got.positive.size(), positive.size());
    ASSERT_EQ(got.negative.size(), negative.size());
    EXPECT_GT(positive.size() + negative.size(), 50u);
    EXPECT_TRUE(std::is_sorted(got.positive.begin(), got.positive.end()));
    for (std::size_t k = 0; k < positive.size(); ++k) {
      EXPECT_LE(got.positive[k], positive[k] + 1e-9);  // within the step that ends at the frame
      EXPECT_GE(got.positive[k], positive[k] - 0.1 - 1e-9);
    }
  }

  nlohmann::json stats;
  loop.finish(stats);
  const nlohmann::json& m = stats["measurement"];
  ASSERT_EQ(m["areas"].size(), 2u);
  EXPECT_EQ(m["areas"][1]["name"], "east");
  EXPECT_EQ(m["areas"][0]["samples"].size(), metrics.samples().size());
  EXPECT_DOUBLE_EQ(m["areas"][0]["area_m2"].get<double>(), 36.0);
  for (const char* key : {"agents", "density", "voronoi_density", "speed", "voronoi_speed", "speed_magnitude",
                          "voronoi_speed_magnitude", "flow", "voronoi_flow"}) {
    EXPECT_TRUE(m["areas"][0]["mean"].contains(key)) << key;
    EXPECT_TRUE(m["areas"][0]["samples"][0].contains(key)) << key;
  }
  double densest = 0;  // everyone meets at the centre
  for (const auto& s : m["areas"][0]["samples"]) densest = std::max(densest, s["voronoi_density"].get<double>());
  EXPECT_GT(densest, 1.0);
  ASSERT_EQ(m["lines"].size(), 2u);
  const nlohmann::json& line = m["lines"][0];
  EXPECT_EQ(line["name"], "north_south");
  EXPECT_DOUBLE_EQ(line["width_m"].get<double>(), 60.0);
  const std::vector<double>& t = metrics.line_times()[0].positive;
  ASSERT_GE(t.size(), 2u);
  EXPECT_EQ(line["positive"]["crossings"], t.size());
  EXPECT_DOUBLE_EQ(line["positive"]["flow_per_s"].get<double>(),
                   static_cast<double>(t.size() - 1) / (t.back() - t.front()));
  EXPECT_DOUBLE_EQ(line["positive"]["specific_flow_per_m_s"].get<double>(),
                   line["positive"]["flow_per_s"].get<double>() / 60.0);
  EXPECT_DOUBLE_EQ(line["positive"]["steady_flow_per_s"].get<double>(), line_flow(t, 60.0).steady_flow);
  EXPECT_DOUBLE_EQ(line["positive"]["steady_specific_flow_per_m_s"].get<double>(),
                   line["positive"]["steady_flow_per_s"].get<double>() / 60.0);
  EXPECT_EQ(line["positive"]["nt"].size(), t.size());
  EXPECT_EQ(line["positive"]["nt"].back()[1], t.size());
  // The fundamental diagram is the first area's, with its Voronoi values.
  EXPECT_EQ(stats["fundamental_diagram"]["area"]["min"][0], -3.0);
  EXPECT_TRUE(stats["fundamental_diagram"]["samples"][0].contains("voronoi_density"));
  EXPECT_TRUE(stats["fundamental_diagram"]["samples"][0].contains("voronoi_speed"));
}

}  // namespace
}  // namespace throng::sim
