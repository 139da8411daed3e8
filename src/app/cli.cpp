// Shared pieces of the command line (app/commands.h): readable range checks,
// the joint-LOD thresholds flag, options that need another option, and the
// closest command name for a mistyped one.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "anim/lod.h"
#include "app/commands.h"
#include "core/error.h"

namespace throng::app {

namespace {

// 16777216 rather than 1.67772e+07; 0.01 rather than 0.010000.
std::string number(double v) {
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) return fmt::format("{}", static_cast<long long>(v));
  return fmt::format("{:g}", v);
}

// A validator of one number: `ok` says whether it passes, `rule` is the
// message ("must be at least 1") and `description` what --help shows.
CLI::Validator number_check(std::function<bool(double)> ok, std::string rule, std::string description) {
  return CLI::Validator(
      [ok = std::move(ok), rule = std::move(rule)](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return "expected a number, got '" + text + "'";
        if (!ok(v)) return rule + ", got " + text;
        return {};
      },
      std::move(description));
}

}  // namespace

CLI::Validator at_least(double min) {
  return number_check([min](double v) { return v >= min; }, "must be at least " + number(min), ">= " + number(min));
}

CLI::Validator greater_than(double min) {
  return number_check([min](double v) { return v > min; }, "must be greater than " + number(min), "> " + number(min));
}

CLI::Validator between(double lo, double hi) {
  return number_check([lo, hi](double v) { return v >= lo && v <= hi; }, "must be between " + number(lo) + " and " + number(hi),
                      "in [" + number(lo) + ", " + number(hi) + "]");
}

void check_lod_thresholds(const std::vector<float>& thresholds, const std::string& flag) {
  const std::size_t most = static_cast<std::size_t>(anim::kMaxLodLevels - 1);
  if (thresholds.size() > most)
    throw Error(fmt::format("at most {} thresholds, got {}", most, thresholds.size()), at_field(flag));
  for (std::size_t i = 0; i < thresholds.size(); ++i) {
    const float t = thresholds[i];
    if (!(t > 0.0f) || !std::isfinite(t))
      throw Error(fmt::format("thresholds must be positive square pixels, got {}", number(static_cast<double>(t))), at_field(flag));
    if (i > 0 && !(t < thresholds[i - 1]))
      throw Error(fmt::format("thresholds must decrease (finest level first, e.g. 1000,30), got {} after {}", number(static_cast<double>(t)),
                              number(static_cast<double>(thresholds[i - 1]))),
                  at_field(flag));
  }
}

void refuse_unless(const CLI::App& cmd, bool given, const std::vector<std::string>& options, const std::string& needs) {
  if (given) return;
  for (const std::string& name : options)
    if (cmd.count(name) > 0) throw Error("needs " + needs, at_field(name));
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  // Optimal string alignment: insertions, deletions, substitutions and
  // swaps of neighbours ("rnu" is one step from "run").
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1, 0));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

std::string closest_name(const std::string& word, const std::vector<std::string>& names) {
  std::string best;
  std::size_t best_distance = 3;  // at most two edits...
  for (const std::string& name : names) {
    const std::size_t d = edit_distance(word, name);
    if (d < best_distance && 2 * d < name.size()) {  // ...and fewer than half the name's letters
      best = name;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace throng::app
