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
  // Elements [first, first + out.size()) into host memory, and back from it.
  void read(Index first, std::span<T> out) const {
    copy_range(out.data(), Memory::Host, data_ + first, memory_, out.size());
  }
  void write(Index first, std::span<const T> values) {
    copy_range(data_ + first, memory_, values.data(), Memory::Host, values.size());
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
  static void copy_range(T* dst, Memory dst_m, const T* src, Memory src_m, std::size_t n) {
    if (n > 0) detail::copy_bytes(dst, dst_m, src, src_m, n * sizeof(T));
  }
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

// Copies to.size() elements from a span that kernels of the current
// backend read (current_memory()) into host memory, or into another such span.
template <class From, class To>
void copy_to_host(Span<From> from, std::span<To> to) {
  static_assert(std::is_same_v<std::remove_const_t<From>, To>, "copy_to_host: element types differ");
  if (!to.empty()) detail::copy_bytes(to.data(), Memory::Host, from.data(), current_memory(), to.size() * sizeof(To));
}
template <class From, class To>
void copy_span(Span<From> from, Span<To> to) {
  static_assert(std::is_same_v<std::remove_const_t<From>, To>, "copy_span: element types differ");
  if (!to.empty())
    detail::copy_bytes(to.data(), current_memory(), from.data(), current_memory(),
                       static_cast<std::size_t>(to.size()) * sizeof(To));
}

}  // namespace throng
