#include "sim/frame_loop.h"

#include <chrono>
#include <map>

#include "core/timing.h"

namespace throng::sim {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }
}  // namespace

RunResult FrameLoop::run(const RunControl& control) {
  const auto start = Clock::now();
  stage_ms_.assign(stages_.size(), 0.0);
  result_ = {};
  auto interrupted = [&] { return control.interrupt != nullptr && control.interrupt->load(std::memory_order_relaxed); };
  auto all_arrived = [&] { return control.stop_when_arrived && sim_.all_arrived(); };
  auto run_stages = [&](const FrameInfo& f, bool first) {
    for (std::size_t k = 0; k < stages_.size(); ++k) {
      const auto t = Clock::now();
      if (first)
        stages_[k]->start(sim_, f);
      else
        stages_[k]->after_step(sim_, f);
      stage_ms_[k] += ms_since(t);
    }
    if (control.progress) control.progress(sim_, f);
  };

  FrameInfo f{sim_.steps_done(), sim_.time(), control.max_steps <= 0 || interrupted()};
  run_stages(f, true);
  while (!f.last) {
    sim_.step();
    ++result_.steps;
    result_.all_arrived = all_arrived();
    result_.interrupted = interrupted();
    f = {sim_.steps_done(), sim_.time(),
         result_.steps >= control.max_steps || result_.all_arrived || result_.interrupted};
    run_stages(f, false);
  }
  result_.interrupted = result_.interrupted || (result_.steps == 0 && interrupted());
  result_.all_arrived = sim_.all_arrived();
  result_.simulated_seconds = sim_.time();
  result_.wall_seconds = ms_since(start) / 1000.0;
  return result_;
}

void FrameLoop::finish(nlohmann::json& stats) {
  std::vector<std::pair<std::string, double>> frame_stage_ms;
  for (std::size_t k = 0; k < stages_.size(); ++k) {
    stages_[k]->finish(sim_, stats);
    frame_stage_ms.emplace_back(stages_[k]->name(), k < stage_ms_.size() ? stage_ms_[k] : 0.0);
  }
  const ScenarioSpec& spec = sim_.spec();
  stats["run"] = {{"scenario", spec.name},
                  {"agents", sim_.agent_count()},
                  {"steps", result_.steps},
                  {"dt", spec.dt},
                  {"simulated_seconds", result_.simulated_seconds},
                  {"wall_seconds", result_.wall_seconds},
                  {"seed", spec.seed},
                  {"model", to_string(spec.model.kind)},
                  {"scheduler", to_string(sim_.scheduler())},
                  {"backend", to_string(current_backend())},
                  {"threads", current_threads()},
                  {"interrupted", result_.interrupted},
                  {"all_arrived", result_.all_arrived}};
  stats["timings"] = timings_section(result_.steps, frame_stage_ms);
}

nlohmann::json timings_section(std::int64_t steps, const std::vector<std::pair<std::string, double>>& frame_stage_ms) {
  struct Stage {
    double ms = 0;
    std::int64_t bytes = 0;
  };
  std::map<std::string, Stage> sim_stages;
  nlohmann::json kernels = nlohmann::json::array();
  double step_total = 0;
  std::int64_t step_bytes = 0;
  for (const KernelStat& k : KernelTimings::global().stats()) {
    kernels.push_back({{"name", k.name},
                       {"count", k.count},
                       {"total_ms", k.total_ms},
                       {"median_ms", k.median_ms},
                       {"bytes", k.bytes}});
    if (k.name == "sim.step") {
      step_total = k.total_ms;
      continue;
    }
    if (k.name.rfind("sim.", 0) != 0) continue;
    step_bytes += k.bytes;
    const std::size_t dot = k.name.find('.', 4);
    const std::string stage = k.name.substr(4, dot == std::string::npos ? std::string::npos : dot - 4);
    if (stage == "bin" || stage == "sense" || stage == "steer" || stage == "sense_steer" || stage == "move") {
      sim_stages[stage].ms += k.total_ms;
      sim_stages[stage].bytes += k.bytes;
    }
  }
  const double per = steps > 0 ? 1.0 / static_cast<double>(steps) : 0.0;
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, s] : sim_stages)
    stages["sim." + name] = {
        {"total_ms", s.ms}, {"ms_per_step", s.ms * per}, {"bytes_per_step", static_cast<double>(s.bytes) * per}};
  for (const auto& [name, ms] : frame_stage_ms) stages[name] = {{"total_ms", ms}, {"ms_per_step", ms * per}};
  // bytes: the step's kernels' estimate of the memory they move (core/parallel.h, count_traffic).
  return {{"step_ms", step_total * per},
          {"step_bytes", static_cast<double>(step_bytes) * per},
          {"stages", stages},
          {"kernels", kernels}};
}

}  // namespace throng::sim
