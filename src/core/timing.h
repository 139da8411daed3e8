// Per-kernel timing, collected by the description given to parallel_for.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace throng {

struct KernelStat {
  std::string name;
  std::int64_t count = 0;
  double total_ms = 0;
  double median_ms = 0;  // over the most recent samples (see KernelTimings)
  double min_ms = 0;
  double max_ms = 0;
  // Bytes the launches read and write, estimated from the sizes of the
  // arrays each one passes over (count_bytes); 0 when none are counted.
  std::int64_t bytes = 0;
};

// The rate of `bytes` moved in `ms` milliseconds, in GB/s (10^9 bytes).
inline double gigabytes_per_second(double bytes, double ms) { return bytes / (ms * 1e6); }

class KernelTimings {
 public:
  // Samples kept per kernel for the median; count and total stay exact.
  static constexpr std::size_t kMaxSamples = 1 << 14;

  static KernelTimings& global();
  void record(std::string_view name, double ms);
  // Adds to the bytes moved under `name`: a launch's estimate of what it
  // reads and writes, each array it passes over counted once at its size
  // (a floor: neighbour reads through the bins read some rows again).
  void count_bytes(std::string_view name, std::int64_t bytes);
  // Bytes counted so far under every name that starts with `prefix`.
  std::int64_t bytes_under(std::string_view prefix) const;
  // By total time, largest first. Waits for GPU launches still queued (and
  // so may throw the Error of a kernel that failed); table() and json() too.
  std::vector<KernelStat> stats() const;
  std::string table() const;  // aligned text, one row per kernel
  std::string json() const;   // [{"name":..,"count":..,...}]
  void reset();               // forgets every series, GPU launches still queued included

 private:
  KernelTimings() = default;
};

// Times a scope and records it under `name` when it ends.
class ScopedTimer {
 public:
  explicit ScopedTimer(const char* name) : name_(name), start_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() {
    const auto d = std::chrono::steady_clock::now() - start_;
    KernelTimings::global().record(name_, std::chrono::duration<double, std::milli>(d).count());
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  const char* name_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace throng
