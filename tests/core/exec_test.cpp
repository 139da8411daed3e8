#include "core/exec.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>
#include <string>

#include "core/error.h"

namespace throng {

TEST(Exec, ParseBackendChoice) {
  EXPECT_EQ(parse_backend_choice("auto"), BackendChoice::Auto);
  EXPECT_EQ(parse_backend_choice("cpu"), BackendChoice::Cpu);
  EXPECT_EQ(parse_backend_choice("cuda"), BackendChoice::Cuda);
  EXPECT_THROW(parse_backend_choice("gpu"), Error);
}

// Without a usable GPU `auto` takes the CPU and says so once per process,
// in a log line (stderr) naming why; asked twice, it says nothing more. The
// only caller in this executable is this test, so its first run sees the
// notice (a repeated run, --gtest_repeat, sees none).
TEST(Exec, AutoFallsBackToCpuWithoutGpuAndSaysSoOnce) {
  static int runs = 0;
  const bool first = runs++ == 0;
  std::ostringstream said;
  const auto saved = spdlog::default_logger();
  spdlog::set_default_logger(
      std::make_shared<spdlog::logger>("exec_test", std::make_shared<spdlog::sinks::ostream_sink_mt>(said)));
  const Backend b = resolve_backend(BackendChoice::Auto);
  const Backend again = resolve_backend(BackendChoice::Auto);
  spdlog::set_default_logger(saved);
  EXPECT_EQ(b, cuda_usable() ? Backend::Cuda : Backend::Cpu);
  EXPECT_EQ(again, b);
  const std::string log = said.str();
  std::size_t notices = 0;
  for (std::size_t at = 0; (at = log.find("using the CPU backend", at)) != std::string::npos; ++at) ++notices;
  if (cuda_usable()) {
    EXPECT_EQ(notices, 0u) << log;
    return;
  }
  EXPECT_EQ(notices, first ? 1u : 0u) << log;
  if (first) {
    EXPECT_NE(log.find("no usable GPU (" + cuda_status() + ")"), std::string::npos) << log;
  }
  EXPECT_THROW(resolve_backend(BackendChoice::Cuda), Error);
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
