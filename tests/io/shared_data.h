// Where the real motion-capture files are: THRONG_SHARED_DIR/data/bvh (CTest
// sets THRONG_SHARED_DIR to ../shared); nullopt when absent, so tests skip.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <optional>

namespace throng::io {

inline std::optional<std::filesystem::path> shared_bvh_dir() {
  const char* dir = std::getenv("THRONG_SHARED_DIR");
  if (dir == nullptr) return std::nullopt;
  const std::filesystem::path p = std::filesystem::path(dir) / "data" / "bvh";
  if (!std::filesystem::is_directory(p)) return std::nullopt;
  return p;
}

}  // namespace throng::io
