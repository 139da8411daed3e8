// The benchmark suites behind `throng bench`, on Google Benchmark.
//
// A suite registers cases with add(); every case runs once per problem size
// and per thread count (and on the GPU when asked and one is usable), and is
// reported as one row: name, backend, N, threads, median ns, items/s.
#pragma once

#include <benchmark/benchmark.h>

#include <functional>
#include <string>
#include <vector>

#include "core/config.h"

namespace throng::bench {

struct Options {
  bool quick = false;  // short runs, sizes up to quick_max_n
  Index quick_max_n = 100000;
  std::vector<int> threads;   // CPU thread counts; empty = {1, all}
  std::string filter = ".*";  // regular expression on row names
};

// body(state, n) runs one iteration per `for (auto _ : state)` pass and
// calls state.SetItemsProcessed for the items/s column. A case that runs on
// CUDA ends each iteration with finish_device_work() (core/exec.h), or with a
// call that does so itself (Simulation::step): launches are asynchronous, so
// without it a row would time the launches alone.
using Body = std::function<void(benchmark::State&, Index n)>;

struct CaseSpec {
  std::string name;  // "family/what", e.g. "core/saxpy"
  std::vector<Index> sizes;
  Body body;
  bool cuda = false;           // also run on the CUDA backend when usable
  bool single_thread = false;  // the case is serial by nature: threads = 1 only
};
void add(const Options& options, CaseSpec spec);

// A suite registers itself from its own file (bench/<family>/*_bench.cpp):
//   static const bool registered = throng::bench::register_suite("core", &register_core);
// The suites are linked as an object library, so no registration is dropped.
using SuiteFn = void (*)(const Options& options);
bool register_suite(const char* name, SuiteFn fn);

struct Row {
  std::string name;
  std::string backend;
  Index n = 0;
  int threads = 1;
  double median_ns = 0;         // per iteration, wall clock
  double items_per_second = 0;  // median over repetitions
  int repetitions = 0;
  // A case's other counters (state.counters, e.g. bytes of pose data), medians.
  std::vector<std::pair<std::string, double>> counters;
};

// Registers every suite, runs what matches options.filter, returns rows.
std::vector<Row> run(const Options& options);
std::string table(const std::vector<Row>& rows);
std::string json(const std::vector<Row>& rows);

}  // namespace throng::bench
