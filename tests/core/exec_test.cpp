#include "core/exec.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace throng {

TEST(Exec, ParseBackendChoice) {
  EXPECT_EQ(parse_backend_choice("auto"), BackendChoice::Auto);
  EXPECT_EQ(parse_backend_choice("cpu"), BackendChoice::Cpu);
  EXPECT_EQ(parse_backend_choice("cuda"), BackendChoice::Cuda);
  EXPECT_THROW(parse_backend_choice("gpu"), Error);
}

TEST(Exec, AutoFallsBackToCpuWithoutGpu) {
  const Backend b = resolve_backend(BackendChoice::Auto);
  EXPECT_EQ(b, cuda_usable() ? Backend::Cuda : Backend::Cpu);
  if (!cuda_usable()) {
    EXPECT_THROW(resolve_backend(BackendChoice::Cuda), Error);
  }
}

TEST(Exec, ScopedExecutionRestores) {
  configure_execution(Backend::Cpu, 0);
  EXPECT_EQ(current_threads(), hardware_threads());
  {
    ScopedExecution s(Backend::Cpu, 3);
    EXPECT_EQ(current_threads(), 3);
  }
  EXPECT_EQ(current_threads(), hardware_threads());
}

}  // namespace throng
