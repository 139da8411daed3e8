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
// Waits for the device and turns a pending launch/execution error into an Error.
void synchronize(const char* what);

}  // namespace throng::cuda
