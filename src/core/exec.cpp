#include "core/exec.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "core/cuda_runtime.h"
#include "core/error.h"

namespace throng {

namespace {
std::atomic<Backend> g_backend{Backend::Cpu};
std::atomic<int> g_threads{0};
std::once_flag g_cpu_notice;
}  // namespace

const char* to_string(Backend b) { return b == Backend::Cuda ? "cuda" : "cpu"; }

BackendChoice parse_backend_choice(std::string_view text) {
  if (text == "auto") return BackendChoice::Auto;
  if (text == "cpu") return BackendChoice::Cpu;
  if (text == "cuda") return BackendChoice::Cuda;
  throw Error("unknown backend '" + std::string(text) + "' (expected auto, cpu or cuda)", at_field("backend"));
}

bool cuda_usable() {
  static const bool usable = cuda::compiled() && cuda::device_count() > 0;
  return usable;
}

std::string cuda_status() {
  if (!cuda::compiled()) return "not built (configure with -DTHRONG_CUDA=ON)";
  const int n = cuda::device_count();
  if (n == 0) return "built, but no usable GPU (" + cuda::runtime_error_text() + ")";
  return "built, " + std::to_string(n) + " device(s), device 0: " + cuda::device_name(0);
}

Backend resolve_backend(BackendChoice choice) {
  switch (choice) {
    case BackendChoice::Cpu: return Backend::Cpu;
    case BackendChoice::Cuda:
      if (!cuda_usable()) throw Error("backend 'cuda' requested but " + cuda_status(), at_field("backend"));
      return Backend::Cuda;
    case BackendChoice::Auto: break;
  }
  if (cuda_usable()) return Backend::Cuda;
  std::call_once(g_cpu_notice, [] { spdlog::info("no usable GPU ({}); using the CPU backend", cuda_status()); });
  return Backend::Cpu;
}

int hardware_threads() {
  // Asked once: glibc's hardware_concurrency() opens and reads
  // /sys/devices/system/cpu/online on every call, and current_threads()
  // asks at every launch (a 20-agent step spent most of its time there).
  static const int threads = [] {
    const unsigned n = std::thread::hardware_concurrency();
    return n == 0 ? 1 : static_cast<int>(n);
  }();
  return threads;
}

void configure_execution(Backend backend, int threads) {
  g_backend = backend;
  g_threads = threads;
}

Backend current_backend() { return g_backend; }

int current_threads() {
  const int t = g_threads;
  return t <= 0 ? hardware_threads() : t;
}

void finish_device_work() {
  if (current_backend() == Backend::Cuda) cuda::synchronize("finish_device_work");
}

ScopedExecution::ScopedExecution(Backend backend, int threads) : saved_backend_(g_backend), saved_threads_(g_threads) {
  configure_execution(backend, threads);
}

ScopedExecution::~ScopedExecution() { configure_execution(saved_backend_, saved_threads_); }

}  // namespace throng
