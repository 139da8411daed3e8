// Which backend and how many CPU threads parallel_for uses, chosen at run time.
#pragma once

#include <string>
#include <string_view>

namespace throng {

enum class Backend { Cpu, Cuda };
enum class BackendChoice { Auto, Cpu, Cuda };

const char* to_string(Backend b);
// Parses "auto", "cpu" or "cuda"; throws Error naming the bad value.
BackendChoice parse_backend_choice(std::string_view text);

// Resolves a choice to a backend. Auto picks CUDA when a GPU is usable, else
// the CPU, and says so once per process. An explicit "cuda" without a usable
// GPU is an Error.
Backend resolve_backend(BackendChoice choice);

// The process-wide settings read by parallel_for. threads <= 0 means all cores.
void configure_execution(Backend backend, int threads);
Backend current_backend();
int current_threads();  // resolved thread count (>= 1)
int hardware_threads();

// Overrides the settings for a scope (tests, benchmarks), then restores them.
class ScopedExecution {
 public:
  ScopedExecution(Backend backend, int threads);
  ~ScopedExecution();
  ScopedExecution(const ScopedExecution&) = delete;
  ScopedExecution& operator=(const ScopedExecution&) = delete;

 private:
  Backend saved_backend_;
  int saved_threads_;
};

// Waits until the work queued on the GPU has finished (CUDA launches return
// before their kernels run); nothing to do on the CPU backend. Host reads of
// device buffers wait by themselves: this is for timing a stretch of work.
void finish_device_work();

// True when this build has the CUDA backend and a device answers.
bool cuda_usable();
// A one-line description of the GPU situation, for `throng info`.
std::string cuda_status();

}  // namespace throng
