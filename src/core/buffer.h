// Owning arrays for structure-of-arrays state, in host or CUDA device memory.
// Kernels never see a Buffer, only its Span.
#pragma once

#include <cstddef>
#include <cstring>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/exec.h"
#include "core/span.h"

namespace throng {

enum class Memory { Host, Device };

// The memory that kernels of the current backend read.
inline Memory current_memory() { return current_backend() == Backend::Cuda ? Memory::Device : Memory::Host; }

namespace detail {
void* allocate_bytes(std::size_t bytes, Memory m);
void free_bytes(void* p, Memory m) noexcept;
void copy_bytes(void* dst, Memory dst_m, const void* src, Memory src_m, std::size_t bytes);
}  // namespace detail

template <class T>
class Buffer {
  static_assert(std::is_trivially_copyable_v<T>, "Buffer holds plain data only");

 public:
  Buffer() = default;
  explicit Buffer(Index n, Memory m = Memory::Host) : memory_(m) { allocate(n); }
  Buffer(std::span<const T> values, Memory m) : memory_(m) {
    allocate(static_cast<Index>(values.size()));
    copy_from(values);
  }
  // Zero-initialised host or device array.
  static Buffer zeros(Index n, Memory m = Memory::Host) {
    Buffer b(n, m);
    std::vector<T> z(static_cast<std::size_t>(n));
    if (m == Memory::Host) {
      if (n > 0) std::memset(static_cast<void*>(b.data_), 0, bytes(n));
    } else {
      b.copy_from(z);
    }
    return b;
  }

  Buffer(Buffer&& o) noexcept { swap(o); }
  Buffer& operator=(Buffer&& o) noexcept {
    Buffer tmp(std::move(o));
    swap(tmp);
    return *this;
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() { detail::free_bytes(data_, memory_); }

  Index size() const { return size_; }
  bool empty() const { return size_ == 0; }
  Memory memory() const { return memory_; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  Span<T> span() { return {data_, size_}; }
  Span<const T> span() const { return {data_, size_}; }

  // Host-side element access; only for host buffers.
  T& operator[](Index i) { return span()[i]; }
  const T& operator[](Index i) const { return span()[i]; }

  void copy_from(std::span<const T> values) {
    const Index n = static_cast<Index>(values.size());
    if (n != size_) resize_discard(n);
    if (n > 0) detail::copy_bytes(data_, memory_, values.data(), Memory::Host, bytes(n));
  }
  std::vector<T> to_vector() const {
    std::vector<T> out(static_cast<std::size_t>(size_));
    if (size_ > 0) detail::copy_bytes(out.data(), Memory::Host, data_, memory_, bytes(size_));
    return out;
  }
  // A copy in memory m.
  Buffer to(Memory m) const {
    Buffer out(size_, m);
    if (size_ > 0) detail::copy_bytes(out.data_, m, data_, memory_, bytes(size_));
    return out;
  }
  // Changes the length; contents are not kept.
  void resize_discard(Index n) {
    if (n == size_) return;
    Buffer tmp(n, memory_);
    swap(tmp);
  }

 private:
  static std::size_t bytes(Index n) { return static_cast<std::size_t>(n) * sizeof(T); }
  void allocate(Index n) {
    size_ = n < 0 ? 0 : n;
    data_ = size_ > 0 ? static_cast<T*>(detail::allocate_bytes(bytes(size_), memory_)) : nullptr;
  }
  void swap(Buffer& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(memory_, o.memory_);
  }

  T* data_ = nullptr;
  Index size_ = 0;
  Memory memory_ = Memory::Host;
};

}  // namespace throng
