#include "core/cuda_runtime.h"

#include "core/error.h"

#if defined(THRONG_HAVE_CUDA)
#include <cuda_runtime_api.h>
#endif

namespace throng::cuda {

#if defined(THRONG_HAVE_CUDA)

static void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw Error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(e));
}

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
  check(cudaMemcpy(dst, src, bytes, k), "cudaMemcpy");
}

void synchronize(const char* what) {
  check(cudaGetLastError(), what);
  check(cudaDeviceSynchronize(), what);
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

#endif

}  // namespace throng::cuda
