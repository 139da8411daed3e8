#include "io/yaml_reader.h"

#include <fmt/format.h>
#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "core/spelling.h"

namespace throng::io {

namespace {

Location location(const std::string& file, const YAML::Mark& m, const std::string& path) {
  return Location{file, m.is_null() ? 0 : m.line + 1, m.is_null() ? 0 : m.column + 1, path};
}

}  // namespace

YAML::Node load_yaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    throw Error("lists and maps nested too deeply", location(file, e.mark, {}));
  } catch (const YAML::Exception& e) {
    const int line = e.mark.is_null() ? 1 : e.mark.line + 1, column = e.mark.is_null() ? 0 : e.mark.column + 1;
    throw Error("YAML syntax: " + e.msg, Location{file, line, column, {}});
  }
}

Error yaml_error(const YAML::Exception& e, const std::string& file) {
  return Error("YAML: " + e.msg,
               Location{file, e.mark.is_null() ? 1 : e.mark.line + 1, e.mark.is_null() ? 0 : e.mark.column + 1, {}});
}

std::string shown(std::string_view s) {
  constexpr std::size_t kShown = 40;
  std::string out;
  for (char c : s.substr(0, kShown))
    out += (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) ? '?' : c;
  return "'" + out + (s.size() > kShown ? "...'" : "'");
}

std::string child(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}
std::string item(const std::string& path, std::size_t i) { return fmt::format("{}[{}]", path, i); }

Location YamlReader::where(const YAML::Node& n, const std::string& path) const {
  return location(file_, n.Mark(), path);
}

void YamlReader::fail(const YAML::Node& n, const std::string& path, const std::string& message) const {
  throw Error(message, where(n, path));
}

void YamlReader::fail_at(const YAML::Mark& m, const std::string& path, const std::string& message) const {
  throw Error(message, location(file_, m, path));
}

void YamlReader::fail_budget(const YAML::Node& n, const std::string& path) const {
  fail(n, path, fmt::format("the file has more than {} YAML values", rules_.max_nodes));
}

void YamlReader::visit(const YAML::Node& n, const std::string& path) {
  if (++nodes_ > rules_.max_nodes) fail_budget(n, path);
  const YAML::Mark m = n.Mark();
  if (marks_ != nullptr && !m.is_null()) marks_->emplace(path, std::make_pair(m.line + 1, m.column + 1));
}

std::string YamlReader::kind(const YAML::Node& n) {
  if (n.IsMap()) return "a map";
  if (n.IsSequence()) return "a list";
  if (n.IsNull()) return "nothing";
  return "the value " + shown(n.Scalar());
}

std::vector<std::string> YamlReader::keys_of(const YAML::Node& n, const std::string& path,
                                             const std::vector<std::string_view>& allowed) const {
  std::vector<std::string> keys;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const YAML::Node key = it->first;
    if (!key.IsScalar()) fail(key, path, "keys must be plain words, got " + kind(key));
    const std::string& k = key.Scalar();
    const std::string where = child(path, k);
    if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
      const std::string close = closest_name(k, allowed);
      const std::string hint = close.empty() ? "" : fmt::format(" (did you mean '{}'?)", close);
      fail_at(key.Mark(), where, fmt::format("unknown key {}{}; expected one of {}", shown(k), hint, join(allowed)));
    }
    if (std::find(keys.begin(), keys.end(), k) != keys.end())
      fail_at(key.Mark(), where, fmt::format("duplicate key {}", shown(k)));
    keys.push_back(k);
  }
  return keys;
}

void YamlReader::expect_map(const YAML::Node& n, const std::string& path,
                            const std::vector<std::string_view>& allowed) {
  visit(n, path);
  if (!n.IsMap()) fail(n, path, "expected a map with keys " + join(allowed) + ", got " + kind(n));
  keys_of(n, path, allowed);
}

std::string YamlReader::one_of(const YAML::Node& n, const std::string& path,
                               std::initializer_list<std::string_view> kinds,
                               std::initializer_list<std::string_view> extra) {
  visit(n, path);
  if (!n.IsMap()) fail(n, path, "expected a map with one of the keys " + join(kinds) + ", got " + kind(n));
  std::vector<std::string_view> allowed(kinds);
  allowed.insert(allowed.end(), extra.begin(), extra.end());
  std::string found;
  for (const std::string& k : keys_of(n, path, allowed)) {
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) continue;
    if (!found.empty())
      fail(n, child(path, k), fmt::format("give only one of {} (found '{}' and '{}')", join(kinds), found, k));
    found = k;
  }
  if (found.empty()) fail(n, path, "needs one of the keys " + join(kinds));
  return found;
}

void YamlReader::expect_list(const YAML::Node& n, const std::string& path, std::size_t min_size, std::size_t max_size,
                             const char* what) {
  visit(n, path);
  if (!n.IsSequence()) fail(n, path, fmt::format("expected a list of {}, got {}", what, kind(n)));
  if (n.size() < min_size)
    fail(n, path,
         min_size == 1 ? fmt::format("must not be empty: give at least one of the {}", what)
                       : fmt::format("needs at least {} {}, got {}", min_size, what, n.size()));
  if (n.size() > max_size) fail(n, path, fmt::format("has more than {} {}", max_size, what));
}

YAML::Node YamlReader::required(const YAML::Node& map, const std::string& path, const char* key) const {
  const YAML::Node n = map[key];
  if (!n) fail(map, path, fmt::format("missing required key '{}'", key));
  return n;
}

std::string YamlReader::number_problem(const YAML::Node& n, double* out) const {
  if (!n.IsScalar()) return "expected a number, got " + kind(n);
  if (n.Tag() == "!" && !rules_.quoted_numbers) return "expected a number, got the quoted string " + shown(n.Scalar());
  std::string_view text = n.Scalar();
  std::string_view bare = text;
  if (!bare.empty() && (bare[0] == '+' || bare[0] == '-')) bare.remove_prefix(1);
  for (std::string_view special : {".inf", ".Inf", ".INF", ".nan", ".NaN", ".NAN"})
    if (bare == special) return "the number must be finite, got " + shown(text);
  if (!text.empty() && text[0] == '+') text.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty())
    return "expected a number, got " + shown(n.Scalar());
  if (!std::isfinite(v)) return "the number must be finite, got " + shown(n.Scalar());  // inf, nan
  if (std::fabs(v) > 3.0e38)
    return "the number " + shown(n.Scalar()) + " is too large: values are single precision (up to 3.4e38)";
  *out = v;
  return {};
}

double YamlReader::number(const YAML::Node& n, const std::string& path) {
  visit(n, path);
  double v = 0;
  if (const std::string problem = number_problem(n, &v); !problem.empty()) fail(n, path, problem);
  return v;
}

double YamlReader::number_in(const YAML::Node& n, const std::string& path, double lo, double hi) {
  const double v = number(n, path);
  if (v < lo || v > hi) fail(n, path, fmt::format("must be in [{}, {}], got {}", lo, hi, v));
  return v;
}

std::int64_t YamlReader::integer(const YAML::Node& n, const std::string& path, std::int64_t lo, std::int64_t hi) {
  const double v = number(n, path);
  if (v != std::floor(v) || std::fabs(v) > 9.0e15) fail(n, path, "expected a whole number, got " + shown(n.Scalar()));
  const auto i = static_cast<std::int64_t>(v);
  if (i < lo || i > hi) fail(n, path, fmt::format("must be in [{}, {}], got {}", lo, hi, i));
  return i;
}

bool YamlReader::boolean(const YAML::Node& n, const std::string& path) {
  visit(n, path);
  if (n.IsScalar() && n.Tag() != "!") {
    const std::string& s = n.Scalar();
    if (s == "true" || s == "True" || s == "TRUE") return true;
    if (s == "false" || s == "False" || s == "FALSE") return false;
  }
  fail(n, path, "expected true or false, got " + kind(n));
}

bool YamlReader::loose_boolean(const YAML::Node& n, const std::string& path) {
  visit(n, path);
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) fail(n, path, "expected true or false, got " + kind(n));
  return v;
}

std::string YamlReader::text(const YAML::Node& n, const std::string& path) {
  visit(n, path);
  if (!n.IsScalar()) fail(n, path, "expected a string, got " + kind(n));
  if (n.Scalar().size() > rules_.max_text)
    fail(n, path, fmt::format("the string is longer than {} characters", rules_.max_text));
  return n.Scalar();
}

std::string YamlReader::word(const YAML::Node& n, const std::string& path,
                             std::initializer_list<std::string_view> choices) {
  const std::string s = text(n, path);
  if (std::find(choices.begin(), choices.end(), s) == choices.end())
    fail(n, path, fmt::format("expected one of {}, got {}", join(choices), shown(s)));
  return s;
}

}  // namespace throng::io
