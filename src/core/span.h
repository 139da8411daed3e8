// A pointer + length view usable in kernels on host and device.
#pragma once

#include <span>
#include <type_traits>

#include "core/config.h"

namespace throng {

namespace detail {
[[noreturn]] void span_index_out_of_range(Index i, Index n);
}

template <class T>
struct Span;
template <class X>
struct is_span : std::false_type {};
template <class X>
struct is_span<Span<X>> : std::true_type {};

template <class T>
struct Span {
  T* ptr = nullptr;
  Index count = 0;

  constexpr Span() = default;
  THRONG_HOST_DEVICE constexpr Span(T* p, Index n) : ptr(p), count(n) {}
  // Host containers (std::vector, std::array, std::span) convert implicitly.
  // (Not a Span: copying one must stay the host+device copy constructor.)
  template <class C, class = decltype(std::data(std::declval<C&>())),
            class = std::enable_if_t<!is_span<std::remove_cv_t<C>>::value>>
  Span(C& c) : ptr(std::data(c)), count(static_cast<Index>(std::size(c))) {}
  // Span<T> -> Span<const T>
  template <class U, class = std::enable_if_t<std::is_same_v<const U, T> && !std::is_same_v<U, T>>>
  THRONG_HOST_DEVICE constexpr Span(Span<U> s) : ptr(s.ptr), count(s.count) {}

  THRONG_HOST_DEVICE T& operator[](Index i) const {
#if defined(THRONG_CHECK_BOUNDS) && !defined(__CUDA_ARCH__)
    if (i < 0 || i >= count) detail::span_index_out_of_range(i, count);
#endif
    return ptr[i];
  }
  THRONG_HOST_DEVICE Index size() const { return count; }
  THRONG_HOST_DEVICE bool empty() const { return count == 0; }
  THRONG_HOST_DEVICE T* data() const { return ptr; }
  THRONG_HOST_DEVICE T* begin() const { return ptr; }
  THRONG_HOST_DEVICE T* end() const { return ptr + count; }
  THRONG_HOST_DEVICE Span subspan(Index offset, Index n) const { return Span(ptr + offset, n); }
  std::span<T> std() const { return std::span<T>(ptr, static_cast<std::size_t>(count)); }
};

// Bytes of the elements the spans view, summed: what a pass over each of
// them once moves (KernelTimings::count_bytes).
template <class... T>
std::int64_t bytes_of(const Span<T>&... spans) {
  return (std::int64_t{0} + ... + (static_cast<std::int64_t>(spans.size()) * static_cast<std::int64_t>(sizeof(T))));
}

}  // namespace throng
