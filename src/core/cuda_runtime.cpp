#include "core/cuda_runtime.h"

#include "core/error.h"

#if defined(THRONG_HAVE_CUDA)
#include <cuda_runtime_api.h>

#include <cstdlib>
#include <mutex>
#include <vector>

#include "core/timing.h"
#endif

namespace throng::cuda {

#if defined(THRONG_HAVE_CUDA)

static void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(e));
}

static bool wait_after_each_launch() {
  static const bool wait = [] {
    const char* v = std::getenv("THRONG_CUDA_SYNC");
    return v != nullptr && std::string(v) == "1";
  }();
  return wait;
}

// For calls that may report a fault of a queued kernel: unless every launch
// is waited for, it may belong to any launch since the last wait.
static void check_wait(cudaError_t e, const char* what) {
  if (e == cudaSuccess) return;
  if (wait_after_each_launch()) check(e, what);
  throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(e) +
              " (kernels run asynchronously, so the fault may lie in an earlier launch; THRONG_CUDA_SYNC=1 waits "
              "after each launch and names the kernel)");
}

namespace {
// Event pairs of launches whose times have not been read yet, in launch
// order, and a pool of pairs to reuse. At most kMaxQueued pairs wait: then the
// host waits for the device and reads them, which bounds the memory.
struct LaunchEvents {
  cudaEvent_t start = nullptr, stop = nullptr;
  std::string description;
};
struct LaunchLog {
  std::mutex mutex;
  std::vector<LaunchEvents> slots;
  std::vector<int> queued, idle;
};
constexpr std::size_t kMaxQueued = 4096;

LaunchLog& launch_log() {
  static LaunchLog log;
  return log;
}

// Records the times of the queued launches that have finished, oldest first
// (the default stream runs them in order), and returns their event pairs to
// the pool; the caller holds the lock. Stops at the first launch not done.
void read_finished(LaunchLog& log) {
  std::size_t done = 0;
  cudaError_t fault = cudaSuccess;
  for (; done < log.queued.size(); ++done) {
    LaunchEvents& e = log.slots[static_cast<std::size_t>(log.queued[done])];
    const cudaError_t state = cudaEventQuery(e.stop);
    if (state == cudaErrorNotReady) {
      cudaGetLastError();  // "not ready" is an answer, not an error
      break;
    }
    float ms = 0;
    if (state == cudaSuccess) fault = cudaEventElapsedTime(&ms, e.start, e.stop);
    if (state != cudaSuccess || fault != cudaSuccess) {
      fault = state != cudaSuccess ? state : fault;
      ++done;  // its pair is given back with the others; the fault is raised below
      break;
    }
    KernelTimings::global().record(e.description, ms);
  }
  log.idle.insert(log.idle.end(), log.queued.begin(), log.queued.begin() + static_cast<std::ptrdiff_t>(done));
  log.queued.erase(log.queued.begin(), log.queued.begin() + static_cast<std::ptrdiff_t>(done));
  check_wait(fault, "reading kernel times");
}

void read_finished_launches() {
  LaunchLog& log = launch_log();
  std::lock_guard lock(log.mutex);
  read_finished(log);
}
}  // namespace

bool compiled() { return true; }

int device_count() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no driver" error
    return 0;
  }
  return n;
}

std::string device_name(int device) {
  cudaDeviceProp prop{};
  check(cudaGetDeviceProperties(&prop, device), "cudaGetDeviceProperties");
  return prop.name;
}

std::string runtime_error_text() {
  int n = 0;
  cudaError_t e = cudaGetDeviceCount(&n);
  cudaGetLastError();
  if (e != cudaSuccess) return cudaGetErrorString(e);
  return n == 0 ? "no CUDA device" : "";
}

void* malloc_device(std::size_t bytes) {
  void* p = nullptr;
  check(cudaMalloc(&p, bytes), "cudaMalloc");
  return p;
}

void free_device(void* p) noexcept { cudaFree(p); }

void copy(void* dst, const void* src, std::size_t bytes, Copy kind) {
  cudaMemcpyKind k = kind == Copy::HostToDevice   ? cudaMemcpyHostToDevice
                     : kind == Copy::DeviceToHost ? cudaMemcpyDeviceToHost
                                                  : cudaMemcpyDeviceToDevice;
  check_wait(cudaMemcpy(dst, src, bytes, k), "cudaMemcpy");
  if (kind == Copy::DeviceToHost) read_finished_launches();  // the copy waited for them
}

void synchronize(const char* what) {
  check(cudaGetLastError(), what);
  check_wait(cudaDeviceSynchronize(), what);
  read_finished_launches();
}

int launch_begin(const char* description) {
  LaunchLog& log = launch_log();
  std::lock_guard lock(log.mutex);
  int slot = 0;
  if (log.idle.empty()) {
    LaunchEvents e;
    check(cudaEventCreate(&e.start), "cudaEventCreate");
    check(cudaEventCreate(&e.stop), "cudaEventCreate");
    slot = static_cast<int>(log.slots.size());
    log.slots.push_back(std::move(e));
  } else {
    slot = log.idle.back();
    log.idle.pop_back();
  }
  LaunchEvents& e = log.slots[static_cast<std::size_t>(slot)];
  e.description = description;
  const cudaError_t recorded = cudaEventRecord(e.start, nullptr);
  if (recorded != cudaSuccess) log.idle.push_back(slot);
  check_wait(recorded, description);
  return slot;
}

void launch_end(int slot) {
  LaunchLog& log = launch_log();
  bool wait = false;
  std::string waiting_for;  // the description, copied only when the host waits below
  {
    std::lock_guard lock(log.mutex);
    LaunchEvents& e = log.slots[static_cast<std::size_t>(slot)];
    // A launch error (bad configuration, too many resources) is this
    // launch's; a sticky fault reported here may be an earlier kernel's.
    cudaError_t status = cudaGetLastError();
    if (status == cudaSuccess) status = cudaEventRecord(e.stop, nullptr);
    if (status != cudaSuccess) {
      log.idle.push_back(slot);
      check_wait(status, e.description.c_str());
    }
    log.queued.push_back(slot);
    wait = log.queued.size() >= kMaxQueued || wait_after_each_launch();
    if (wait) waiting_for = e.description;
  }
  if (wait) synchronize(waiting_for.c_str());
}

void collect_launch_times() {
  {
    std::lock_guard lock(launch_log().mutex);
    if (launch_log().queued.empty()) return;
  }
  synchronize("waiting for queued kernels");
}

#else

[[noreturn]] static void absent() { throw Error("this build of throng has no CUDA backend"); }

bool compiled() { return false; }
int device_count() { return 0; }
std::string device_name(int) { absent(); }
std::string runtime_error_text() { return "built without CUDA"; }
void* malloc_device(std::size_t) { absent(); }
void free_device(void*) noexcept {}
void copy(void*, const void*, std::size_t, Copy) { absent(); }
void synchronize(const char*) { absent(); }
int launch_begin(const char*) { absent(); }
void launch_end(int) { absent(); }
void collect_launch_times() {}

#endif

}  // namespace throng::cuda
