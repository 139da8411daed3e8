#include "core/buffer.h"

#include <cstdlib>
#include <new>
#include <string>

#include "core/cuda_runtime.h"
#include "core/error.h"

namespace throng::detail {

void span_index_out_of_range(Index i, Index n) {
  throw Error("span index " + std::to_string(i) + " out of range [0, " + std::to_string(n) + ")");
}

// Host arrays are aligned to a cache line so SIMD loops and threads line up.
constexpr std::size_t kHostAlignment = 64;

void* allocate_bytes(std::size_t bytes, Memory m) {
  if (m == Memory::Device) return cuda::malloc_device(bytes);
  const std::size_t rounded = (bytes + kHostAlignment - 1) / kHostAlignment * kHostAlignment;
  void* p = std::aligned_alloc(kHostAlignment, rounded);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

void free_bytes(void* p, Memory m) noexcept {
  if (p == nullptr) return;
  if (m == Memory::Device)
    cuda::free_device(p);
  else
    std::free(p);
}

void copy_bytes(void* dst, Memory dst_m, const void* src, Memory src_m, std::size_t bytes) {
  if (dst_m == Memory::Host && src_m == Memory::Host) {
    std::memcpy(dst, src, bytes);
    return;
  }
  const cuda::Copy kind = dst_m == Memory::Device
                              ? (src_m == Memory::Device ? cuda::Copy::DeviceToDevice : cuda::Copy::HostToDevice)
                              : cuda::Copy::DeviceToHost;
  cuda::copy(dst, src, bytes, kind);
}

}  // namespace throng::detail
