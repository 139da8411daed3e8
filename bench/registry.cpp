#include "bench/registry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/exec.h"

namespace throng::bench {

namespace {
struct CaseMeta {
  std::string name;
  Backend backend;
  Index n;
  int threads;
};
std::vector<std::pair<std::string, SuiteFn>>& suites() {
  static std::vector<std::pair<std::string, SuiteFn>> s;
  return s;
}

// Every suite, once per process (Google Benchmark keeps registrations).
void register_all(const Options& options) {
  static bool done = false;
  if (done) return;
  done = true;
  auto list = suites();
  std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [name, fn] : list) fn(options);
}

std::map<std::string, CaseMeta>& metas() {
  static std::map<std::string, CaseMeta> m;
  return m;
}

std::vector<int> thread_counts(const Options& o) {
  if (!o.threads.empty()) return o.threads;
  const int all = hardware_threads();
  return all > 1 ? std::vector<int>{1, all} : std::vector<int>{1};
}

void register_one(const CaseSpec& spec, Index n, Backend backend, int threads) {
  const std::string full = fmt::format("{}/{}/n={}/threads={}", spec.name, to_string(backend), n, threads);
  metas()[full] = {spec.name, backend, n, threads};
  Body body = spec.body;
  benchmark::RegisterBenchmark(full.c_str(),
                               [body, n, backend, threads](benchmark::State& state) {
                                 ScopedExecution exec(backend, threads);
                                 body(state, n);
                               })
      ->UseRealTime()
      ->Unit(benchmark::kNanosecond);
}

class CollectingReporter : public benchmark::BenchmarkReporter {
 public:
  std::vector<Row> rows;
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred) {
        std::fprintf(stderr, "  %s: error: %s\n", r.run_name.function_name.c_str(), r.error_message.c_str());
        continue;
      }
      if (r.run_type != Run::RT_Aggregate || r.aggregate_name != "median") continue;
      auto it = metas().find(r.run_name.function_name);
      if (it == metas().end()) continue;
      Row row{it->second.name,
              to_string(it->second.backend),
              it->second.n,
              it->second.threads,
              r.GetAdjustedRealTime(),
              0,
              static_cast<int>(r.repetitions),
              {}};
      for (const auto& [key, counter] : r.counters) {
        if (key == "items_per_second")
          row.items_per_second = counter.value;
        else
          row.counters.emplace_back(key, counter.value);
      }
      std::fprintf(stderr, "  %-60s %14.0f ns\n", r.run_name.function_name.c_str(), row.median_ns);
      rows.push_back(row);
    }
  }
};
}  // namespace

bool register_suite(const char* name, SuiteFn fn) {
  suites().emplace_back(name, fn);
  return true;
}

void add(const Options& options, CaseSpec spec) {
  for (Index n : spec.sizes) {
    if (options.quick && n > options.quick_max_n) continue;
    for (int t : thread_counts(options)) {
      if (spec.single_thread && t != 1) continue;
      register_one(spec, n, Backend::Cpu, t);
    }
    if (spec.cuda && cuda_usable()) register_one(spec, n, Backend::Cuda, 1);
  }
}

std::vector<Row> run(const Options& options) {
  register_all(options);
  std::vector<std::string> args = {"throng-bench", "--benchmark_filter=" + options.filter,
                                   options.quick ? "--benchmark_min_time=0.02" : "--benchmark_min_time=0.3",
                                   options.quick ? "--benchmark_repetitions=3" : "--benchmark_repetitions=5",
                                   "--benchmark_report_aggregates_only=true"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  int argc = static_cast<int>(argv.size());
  benchmark::Initialize(&argc, argv.data());
  CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return reporter.rows;
}

std::string table(const std::vector<Row>& rows) {
  std::size_t width = 9;
  for (const auto& r : rows) width = std::max(width, r.name.size());
  std::string s = fmt::format("{:<{}}  {:>7}  {:>10}  {:>7}  {:>14}  {:>14}\n", "benchmark", width, "backend", "N",
                              "threads", "median ns", "items/s");
  for (const auto& r : rows) {
    s += fmt::format("{:<{}}  {:>7}  {:>10}  {:>7}  {:>14.0f}  {:>14.4g}", r.name, width, r.backend, r.n, r.threads,
                     r.median_ns, r.items_per_second);
    for (const auto& [key, value] : r.counters) s += fmt::format("  {}={:.4g}", key, value);
    s += "\n";
  }
  return s;
}

std::string json(const std::vector<Row>& rows) {
  nlohmann::json j;
  j["machine"] = {{"hardware_threads", hardware_threads()}, {"cuda", cuda_status()}};
  j["benchmarks"] = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json counters = nlohmann::json::object();
    for (const auto& [key, value] : r.counters) counters[key] = value;
    j["benchmarks"].push_back({{"name", r.name},
                               {"backend", r.backend},
                               {"N", r.n},
                               {"threads", r.threads},
                               {"median_ns", r.median_ns},
                               {"items_per_second", r.items_per_second},
                               {"repetitions", r.repetitions},
                               {"counters", counters}});
  }
  return j.dump(2) + "\n";
}

}  // namespace throng::bench
