// Where the real motion-capture files are: THRONG_SHARED_DIR/data/bvh (CTest
// sets THRONG_SHARED_DIR to ../shared beside the source tree).
//
// Tests that need them open with THRONG_NEED_SHARED_BVH(dir): without the
// data they skip with a message, or fail when THRONG_REQUIRE_SHARED=1 (CI
// sets it: CI always has ../shared, so a skip there would hide that every
// check against real motion capture did not run).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace throng::test {

inline std::optional<std::filesystem::path> shared_bvh_dir() {
  const char* dir = std::getenv("THRONG_SHARED_DIR");
  if (dir == nullptr) return std::nullopt;
  const std::filesystem::path p = std::filesystem::path(dir) / "data" / "bvh";
  if (!std::filesystem::is_directory(p)) return std::nullopt;
  return p;
}

// One shared file's path, or nullopt when the folder or the file is absent.
inline std::optional<std::filesystem::path> shared_bvh(const std::string& file) {
  const auto dir = shared_bvh_dir();
  if (!dir || !std::filesystem::is_regular_file(*dir / file)) return std::nullopt;
  return *dir / file;
}

inline bool shared_data_required() {
  const char* v = std::getenv("THRONG_REQUIRE_SHARED");
  return v != nullptr && std::string(v) == "1";
}

inline std::string missing_shared_data_message() {
  const char* dir = std::getenv("THRONG_SHARED_DIR");
  return std::string("../shared not found: ") + (dir == nullptr
                                                     ? std::string("THRONG_SHARED_DIR is unset (ctest sets it)")
                                                     : "no data/bvh under THRONG_SHARED_DIR=" + std::string(dir));
}

}  // namespace throng::test

// Skips (or, with THRONG_REQUIRE_SHARED=1, fails) the test unless `found`.
#define THRONG_REQUIRE_SHARED_DATA(found)                                       \
  do {                                                                          \
    if (!(found)) {                                                             \
      if (::throng::test::shared_data_required())                               \
        GTEST_FAIL() << ::throng::test::missing_shared_data_message()           \
                     << " (THRONG_REQUIRE_SHARED=1: the data must be present)"; \
      GTEST_SKIP() << ::throng::test::missing_shared_data_message();            \
    }                                                                           \
  } while (0)

// `const auto dir = shared_bvh_dir();` then THRONG_REQUIRE_SHARED_DATA(dir).
#define THRONG_NEED_SHARED_BVH(dir)                  \
  const auto dir = ::throng::test::shared_bvh_dir(); \
  THRONG_REQUIRE_SHARED_DATA(dir)
