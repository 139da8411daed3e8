// The frame loop: stage order, frame numbering, stopping, interruption,
// and the stats sections.
#include "sim/frame_loop.h"

#include <gtest/gtest.h>

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
  EXPECT_EQ(log, (std::vector<std::string>{"a start 0", "b start 0", "a 1", "b 1", "a 2", "b 2", "a 3 last", "b 3 last"}));
  EXPECT_EQ(progress_calls, 4);
  nlohmann::json stats;
  loop.finish(stats);
  EXPECT_TRUE(stats.contains("a") && stats.contains("b"));
  EXPECT_EQ(stats["run"]["steps"], 3);
  EXPECT_EQ(stats["run"]["agents"], 20);
  EXPECT_TRUE(stats["timings"]["stages"].contains("a"));
  for (const char* stage : {"sim.bin", "sim.sense", "sim.steer", "sim.move"}) EXPECT_TRUE(stats["timings"]["stages"].contains(stage)) << stage;
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
  for (const char* section : {"crowd", "density_histogram", "fundamental_diagram", "run", "timings"}) EXPECT_TRUE(stats.contains(section)) << section;
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

}  // namespace
}  // namespace throng::sim
