// Reading YAML with one vocabulary for every io reader (scenarios, animate
// scenarios, animation streams, state machines, paths): every error names
// file:line:column and the key path ("groups[0].speed.mean"), and the same
// mistake gives the same message whichever file it is in: an unknown key
// ("unknown key 'cout' (did you mean 'count'?); expected one of ..."), a
// duplicate key, a missing required key, a number that is not finite or out
// of range, a word that is not among the choices, a syntax error.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"

namespace throng::io {

// Parses YAML text; syntax errors become Errors at file:line:column.
YAML::Node load_yaml(const std::string& text, const std::string& file);
// What yaml-cpp throws while a parsed tree is read (a conversion), as an Error at its mark.
Error yaml_error(const YAML::Exception& e, const std::string& file);

// s quoted for a message: at most 40 characters, printable ASCII only, so a
// message stays one readable line whatever the file holds.
std::string shown(std::string_view s);
// Key paths: child("groups[0]", "speed") is "groups[0].speed"; item("groups", 2) is "groups[2]".
std::string child(const std::string& path, std::string_view key);
std::string item(const std::string& path, std::size_t i);

// "a, b, c".
template <class Words>
std::string join(const Words& words) {
  std::string s;
  for (std::string_view w : words) s.append(s.empty() ? "" : ", ").append(w);
  return s;
}

// What one read accepts: hostile-input guards, and whether a quoted number
// ('3') counts as a number.
struct YamlReadRules {
  std::int64_t max_nodes =
      std::numeric_limits<std::int64_t>::max();  // values visited (an alias counts each time it is used)
  std::size_t max_text = std::numeric_limits<std::size_t>::max();  // characters of one string
  bool quoted_numbers = true;
};

// Key path -> 1-based (line, column) of its value.
using YamlMarks = std::map<std::string, std::pair<int, int>, std::less<>>;

class YamlReader {
 public:
  // With `marks`, every visited value's position is recorded there by key path.
  explicit YamlReader(std::string file, YamlReadRules rules = {}, YamlMarks* marks = nullptr)
      : file_(std::move(file)), rules_(rules), marks_(marks) {}

  const std::string& file() const { return file_; }

  // ---- failing at a value (its line and column, 0 when unknown) with its key path
  Location where(const YAML::Node& n, const std::string& path = {}) const;
  [[noreturn]] void fail(const YAML::Node& n, const std::string& path, const std::string& message) const;
  [[noreturn]] void fail_at(const YAML::Mark& m, const std::string& path, const std::string& message) const;
  // Runs f; an Error from a library (which names at most a field, no line)
  // is reported at n, its field before its message.
  template <class F>
  auto at(const YAML::Node& n, const std::string& path, F f) -> decltype(f()) {
    try {
      return f();
    } catch (const Error& e) {
      if (e.location().line > 0) throw;
      fail(n, path, e.location().field.empty() ? e.message() : e.location().field + ": " + e.message());
    }
  }

  // ---- the node budget: every value read passes through visit (aliases
  // make a small file look big); values read in bulk (the points of a
  // polygon) are counted without being recorded.
  void visit(const YAML::Node& n, const std::string& path);
  void count(std::int64_t values) { nodes_ += values; }
  template <class PathFn>
  void spend(const YAML::Node& n, std::int64_t values, const PathFn& path) {
    nodes_ += values;
    if (nodes_ > rules_.max_nodes) fail_budget(n, path());
  }

  // ---- shapes
  // "a map", "a list", "nothing" or "the value 'x'".
  static std::string kind(const YAML::Node& n);
  // The keys of map n, each in `allowed` and none twice; an unknown key is
  // an error at the key, with the nearest allowed key as a hint.
  std::vector<std::string> keys_of(const YAML::Node& n, const std::string& path,
                                   const std::vector<std::string_view>& allowed) const;
  // A map whose keys are all in `allowed`.
  void expect_map(const YAML::Node& n, const std::string& path, const std::vector<std::string_view>& allowed);
  // A map with exactly one of the keys `kinds` (and optionally some of `extra`); returns that key.
  std::string one_of(const YAML::Node& n, const std::string& path, std::initializer_list<std::string_view> kinds,
                     std::initializer_list<std::string_view> extra = {});
  // A list of min_size to max_size `what`.
  void expect_list(const YAML::Node& n, const std::string& path, std::size_t min_size, std::size_t max_size,
                   const char* what);
  // expect_list, then f(item, its key path) for each item.
  template <class F>
  void each_item(const YAML::Node& n, const std::string& path, std::size_t min_size, std::size_t max_size,
                 const char* what, const F& f) {
    expect_list(n, path, min_size, max_size, what);
    for (std::size_t i = 0; i < n.size(); ++i) f(n[i], item(path, i));
  }
  // map[key], an error at the map when it is missing.
  YAML::Node required(const YAML::Node& map, const std::string& path, const char* key) const;

  // ---- scalars
  // Why n is not a finite number, or "" when it is (then *out holds it).
  // Nothing beyond single precision (3.4e38) is a number; neither is a
  // quoted string unless the rules allow it.
  std::string number_problem(const YAML::Node& n, double* out) const;
  double number(const YAML::Node& n, const std::string& path);
  double number_in(const YAML::Node& n, const std::string& path, double lo, double hi);
  float real(const YAML::Node& n, const std::string& path) { return static_cast<float>(number(n, path)); }
  float real_in(const YAML::Node& n, const std::string& path, double lo, double hi) {
    return static_cast<float>(number_in(n, path, lo, hi));
  }
  // A whole number in [lo, hi] (1e6 is one; 2.5 is not).
  std::int64_t integer(const YAML::Node& n, const std::string& path, std::int64_t lo, std::int64_t hi);
  // true or false (True, TRUE, False, FALSE), nothing else.
  bool boolean(const YAML::Node& n, const std::string& path);
  // YAML 1.1 booleans: true/false, yes/no, on/off, y/n, each in lower,
  // Capitalised or UPPER case, quoted or not (the animate, stream and state
  // machine files).
  bool loose_boolean(const YAML::Node& n, const std::string& path);
  // A scalar of at most max_text characters.
  std::string text(const YAML::Node& n, const std::string& path);
  // text that is one of `choices`.
  std::string word(const YAML::Node& n, const std::string& path, std::initializer_list<std::string_view> choices);

 private:
  [[noreturn]] void fail_budget(const YAML::Node& n, const std::string& path) const;

  std::string file_;
  YamlReadRules rules_;
  YamlMarks* marks_ = nullptr;
  std::int64_t nodes_ = 0;
};

}  // namespace throng::io
