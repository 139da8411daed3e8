// Thin wrapper over the CUDA runtime so host code never includes CUDA headers.
// In a build without CUDA every call reports that CUDA is absent.
#pragma once

#include <cstddef>
#include <string>

namespace throng::cuda {

bool compiled();     // the build has the CUDA backend
int device_count();  // 0 when not compiled or no device/driver
std::string device_name(int device);
std::string runtime_error_text();  // why device_count() is 0, if it is

void* malloc_device(std::size_t bytes);  // plain cudaMalloc; throws Error
void free_device(void* p) noexcept;
enum class Copy { HostToDevice, DeviceToHost, DeviceToDevice };
void copy(void* dst, const void* src, std::size_t bytes, Copy kind);
// Waits for the device, turns a pending launch/execution error into an Error,
// and records the times of the launches it waited for (see launch_begin).
void synchronize(const char* what);

// Kernel launches are asynchronous. parallel_for brackets each one:
// launch_begin records a start event on the default stream and returns its
// slot; launch_end checks that the launch was accepted and records the stop
// event. The GPU time between the two is read when the host next waits
// (synchronize, a copy to the host, collect_launch_times) and recorded in
// KernelTimings under the description. THRONG_CUDA_SYNC=1 in the environment
// also waits after every launch, so an execution error names its kernel.
// Everything runs on the legacy default stream and device memory is plain
// cudaMalloc: copies and cudaFree wait for the kernels before them, which is
// what makes a host read, or freeing a temporary buffer, safe.
int launch_begin(const char* description);
void launch_end(int slot);
// Waits for queued launches, if any, and records their times; does nothing
// (and never touches the device) when none is queued.
void collect_launch_times();

}  // namespace throng::cuda
