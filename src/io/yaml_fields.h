// Reading YAML fields with file:line:column in every error: the shared
// helpers of the io readers built on yaml-cpp.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <initializer_list>
#include <sstream>
#include <string>

#include "core/error.h"

namespace throng::io {

struct YamlFields {
  std::string file;

  Location where(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    return at_line(file, m.line + 1, m.column + 1);
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& what) const { throw Error(what, where(n)); }

  // n is a mapping whose keys are all among `keys`.
  void only_keys(const YAML::Node& n, std::initializer_list<const char*> keys) const {
    if (!n.IsMap()) fail(n, "expected a mapping");
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      bool known = false;
      std::string list;
      for (const char* k : keys) {
        known |= key == k;
        list += list.empty() ? k : std::string(", ") + k;
      }
      if (!known) fail(kv.first, "unknown key '" + key + "' (expected one of: " + list + ")");
    }
  }
  std::string scalar(const YAML::Node& n) const {
    if (!n.IsScalar()) fail(n, "expected a name");
    return n.as<std::string>();
  }
  // A finite number in [lo, hi].
  double number(const YAML::Node& n, double lo, double hi) const {
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) fail(n, "expected a finite number");
    if (v < lo || v > hi) {
      std::ostringstream s;
      s << "value " << v << " is out of range [" << lo << ", " << hi << "]";
      fail(n, s.str());
    }
    return v;
  }
};

// Parses YAML text; syntax errors become Errors at file:line:column.
inline YAML::Node load_yaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(e.msg, at_line(file, e.mark.line + 1, e.mark.column + 1));
  }
}

}  // namespace throng::io
