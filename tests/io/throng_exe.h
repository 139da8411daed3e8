// Running the built `throng` executable from a test, as a user runs it.
// THRONG_EXE is its path, given by the build (tests/CMakeLists.txt), which
// also builds it before this test: a missing executable is a failure.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#ifndef THRONG_EXE
#error "THRONG_EXE (the path of the throng executable) is set by tests/CMakeLists.txt"
#endif

namespace throng::io::testing {

inline std::filesystem::path throng_exe() { return THRONG_EXE; }

struct Result {
  int code;  // exit status; -1 when killed by a signal
  std::string out;
};
// Runs `throng --backend cpu --log-level warn ARGS`; stdout (and stderr unless told not to).
inline Result run(const std::filesystem::path& exe, const std::string& args, bool with_stderr = true) {
  const std::string cmd =
      exe.string() + " --backend cpu --log-level warn " + args + (with_stderr ? " 2>&1" : " 2>/dev/null");
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace throng::io::testing
