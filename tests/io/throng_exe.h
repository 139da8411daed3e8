// Running the built `throng` executable from a test, as a user runs it.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

namespace throng::io::testing {

// The executable, looked up next to this test's build folder.
inline std::optional<std::filesystem::path> find_throng() {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  for (int up = 0; up < 3 && !ec; ++up, dir = dir.parent_path())
    if (fs::is_regular_file(dir / "throng")) return dir / "throng";
  return std::nullopt;
}

struct Result {
  int code;
  std::string out;
};
// Runs `throng --backend cpu --log-level warn ARGS`; stdout (and stderr unless told not to).
inline Result run(const std::filesystem::path& exe, const std::string& args, bool with_stderr = true) {
  const std::string cmd = exe.string() + " --backend cpu --log-level warn " + args + (with_stderr ? " 2>&1" : " 2>/dev/null");
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
