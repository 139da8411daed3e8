#pragma once
// Files compiled into the executable (cmake/ThrongEmbed.cmake): the built-in
// scenarios, animate scenarios and the default motion state machine, so
// throng runs with no data folder beside it.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace throng::io {

struct EmbeddedFile {
  const char* name;  // file name without its extension
  const char* text;
  std::size_t size;
};

struct EmbeddedSet {
  const EmbeddedFile* files;
  std::size_t count;

  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < count; ++i) out.emplace_back(files[i].name);
    return out;
  }
  std::optional<std::string_view> find(std::string_view name) const {
    for (std::size_t i = 0; i < count; ++i)
      if (name == files[i].name) return std::string_view(files[i].text, files[i].size);
    return std::nullopt;
  }
};

// Defined in generated sources (src/CMakeLists.txt names the folders).
extern const EmbeddedSet kBuiltinScenarios;         // examples/*.yaml
extern const EmbeddedSet kBuiltinAnimateScenarios;  // examples/animate/*.yaml
extern const EmbeddedSet kBuiltinMotionData;        // data/motion/*.yaml
extern const EmbeddedSet kBuiltinVerification;      // examples/verification/*.yaml (throng verify)

}  // namespace throng::io
