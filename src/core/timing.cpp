#include "core/timing.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>

#include "core/cuda_runtime.h"

namespace throng {

namespace {
struct Series {
  std::int64_t count = 0, bytes = 0;
  double total = 0, min = 0, max = 0;
  std::vector<double> recent;  // ring buffer of the last kMaxSamples
};
std::mutex g_mutex;
std::map<std::string, Series, std::less<>> g_series;
}  // namespace

KernelTimings& KernelTimings::global() {
  static KernelTimings t;
  return t;
}

static Series& series(std::string_view name) {
  auto it = g_series.find(name);
  if (it == g_series.end()) it = g_series.emplace(std::string(name), Series{}).first;
  return it->second;
}

void KernelTimings::record(std::string_view name, double ms) {
  std::lock_guard lock(g_mutex);
  Series& s = series(name);
  s.min = s.count == 0 ? ms : std::min(s.min, ms);
  s.max = s.count == 0 ? ms : std::max(s.max, ms);
  if (s.recent.size() < kMaxSamples)
    s.recent.push_back(ms);
  else
    s.recent[static_cast<std::size_t>(s.count) % kMaxSamples] = ms;
  s.count++;
  s.total += ms;
}

void KernelTimings::count_bytes(std::string_view name, std::int64_t bytes) {
  std::lock_guard lock(g_mutex);
  series(name).bytes += bytes;
}

std::int64_t KernelTimings::bytes_under(std::string_view prefix) const {
  std::lock_guard lock(g_mutex);
  std::int64_t sum = 0;
  for (const auto& [name, s] : g_series)
    if (name.starts_with(prefix)) sum += s.bytes;
  return sum;
}

static double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

std::vector<KernelStat> KernelTimings::stats() const {
  cuda::collect_launch_times();  // GPU launches still queued count too
  std::vector<KernelStat> out;
  {
    std::lock_guard lock(g_mutex);
    for (const auto& [name, s] : g_series)
      out.push_back({name, s.count, s.total, median(s.recent), s.min, s.max, s.bytes});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const KernelStat& a, const KernelStat& b) { return a.total_ms > b.total_ms; });
  return out;
}

std::string KernelTimings::table() const {
  const auto rows = stats();
  std::size_t width = 6;
  for (const auto& r : rows) width = std::max(width, r.name.size());
  std::string s = fmt::format("{:<{}}  {:>9}  {:>12}  {:>11}  {:>11}  {:>11}  {:>8}\n", "kernel", width, "count",
                              "total ms", "median ms", "min ms", "max ms", "GB/s");
  for (const auto& r : rows) {
    // GB/s: the counted bytes over the time (blank where none are counted).
    const std::string rate = r.bytes > 0 && r.total_ms > 0
                                 ? fmt::format("{:.2f}", gigabytes_per_second(static_cast<double>(r.bytes), r.total_ms))
                                 : "";
    s += fmt::format("{:<{}}  {:>9}  {:>12.3f}  {:>11.4f}  {:>11.4f}  {:>11.4f}  {:>8}\n", r.name, width, r.count,
                     r.total_ms, r.median_ms, r.min_ms, r.max_ms, rate);
  }
  return s;
}

std::string KernelTimings::json() const {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& r : stats())
    j.push_back({{"name", r.name},
                 {"count", r.count},
                 {"total_ms", r.total_ms},
                 {"median_ms", r.median_ms},
                 {"min_ms", r.min_ms},
                 {"max_ms", r.max_ms},
                 {"bytes", r.bytes}});
  return j.dump(2);
}

void KernelTimings::reset() {
  cuda::collect_launch_times();  // launches queued before the reset are not counted after it
  std::lock_guard lock(g_mutex);
  g_series.clear();
}

}  // namespace throng
