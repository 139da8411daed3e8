#include "core/buffer.h"

#include <gtest/gtest.h>

#include <numeric>

#include "core/cuda_runtime.h"
#include "core/error.h"

namespace throng {

TEST(Buffer, HostRoundTrip) {
  std::vector<int> v(1000);
  std::iota(v.begin(), v.end(), -500);
  Buffer<int> b(v, Memory::Host);
  EXPECT_EQ(b.size(), 1000);
  EXPECT_EQ(b[0], -500);
  EXPECT_EQ(b.to_vector(), v);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.data()) % 64, 0u) << "host buffers are cache-line aligned";
}

TEST(Buffer, ZerosAndMove) {
  auto b = Buffer<double>::zeros(17);
  for (Index i = 0; i < b.size(); ++i) EXPECT_EQ(b[i], 0.0);
  Buffer<double> c = std::move(b);
  EXPECT_EQ(c.size(), 17);
  EXPECT_EQ(b.size(), 0);  // NOLINT(bugprone-use-after-move): moved-from is empty by contract
  EXPECT_EQ(b.data(), nullptr);
}

TEST(Buffer, EmptyIsValid) {
  Buffer<float> b(0);
  EXPECT_TRUE(b.empty());
  EXPECT_TRUE(b.to_vector().empty());
  b.copy_from(std::vector<float>{1, 2, 3});
  EXPECT_EQ(b.to_vector(), (std::vector<float>{1, 2, 3}));
}

TEST(Buffer, SpanIsAView) {
  Buffer<int> b(std::vector<int>{1, 2, 3}, Memory::Host);
  Span<int> s = b.span();
  s[1] = 20;
  EXPECT_EQ(b[1], 20);
  Span<const int> cs = s;
  EXPECT_EQ(cs.size(), 3);
  EXPECT_EQ(cs.subspan(1, 2)[1], 3);
}

#if defined(THRONG_CHECK_BOUNDS)
TEST(Buffer, OutOfRangeIsAnErrorInCheckedBuilds) {
  Buffer<int> b(4);
  EXPECT_THROW(b.span()[4], Error);
  EXPECT_THROW(b.span()[-1], Error);
}
#endif

TEST(Buffer, CudaDeviceMemoryWithoutGpuIsAClearError) {
  if (cuda::device_count() > 0) GTEST_SKIP() << "a GPU is present; covered by CudaDeviceRoundTrip";
  EXPECT_THROW(Buffer<int>(10, Memory::Device), Error);
}

TEST(Buffer, CudaDeviceRoundTrip) {
  if (cuda::device_count() == 0) GTEST_SKIP() << "no usable GPU on this machine: " << cuda::runtime_error_text();
  std::vector<float> v(4097);
  std::iota(v.begin(), v.end(), 0.5f);
  Buffer<float> d(v, Memory::Device);
  EXPECT_EQ(d.memory(), Memory::Device);
  EXPECT_EQ(d.to_vector(), v);
  EXPECT_EQ(d.to(Memory::Host).to_vector(), v);
  EXPECT_EQ(d.to(Memory::Device).to_vector(), v);
}

}  // namespace throng
