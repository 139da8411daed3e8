// Shared pieces of the command line (app/commands.h): readable range checks,
// the joint-LOD thresholds flag, options that need another option, the BVH
// writers' --order and --units.
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
#include "io/bvh_writer.h"
#include "motion/rotation.h"
#include "motion/units.h"

namespace throng::app {

namespace {

// 16777216 rather than 1.67772e+07; 0.01 rather than 0.010000.
std::string number(double v) {
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15)
    return fmt::format("{}", static_cast<long long>(v));
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
  return number_check([lo, hi](double v) { return v >= lo && v <= hi; },
                      "must be between " + number(lo) + " and " + number(hi),
                      "in [" + number(lo) + ", " + number(hi) + "]");
}

void check_lod_thresholds(const std::vector<float>& thresholds, const std::string& flag) {
  const std::size_t most = static_cast<std::size_t>(anim::kMaxLodLevels - 1);
  if (thresholds.size() > most)
    throw Error(fmt::format("at most {} thresholds, got {}", most, thresholds.size()), at_field(flag));
  for (std::size_t i = 0; i < thresholds.size(); ++i) {
    const float t = thresholds[i];
    if (!(t > 0.0f) || !std::isfinite(t))
      throw Error(fmt::format("thresholds must be positive square pixels, got {}", number(static_cast<double>(t))),
                  at_field(flag));
    if (i > 0 && !(t < thresholds[i - 1]))
      throw Error(fmt::format("thresholds must decrease (finest level first, e.g. 1000,30), got {} after {}",
                              number(static_cast<double>(t)), number(static_cast<double>(thresholds[i - 1]))),
                  at_field(flag));
  }
}

void refuse_unless(const CLI::App& cmd, bool given, const std::vector<std::string>& options, const std::string& needs) {
  if (given) return;
  for (const std::string& name : options)
    if (cmd.count(name) > 0) throw Error("needs " + needs, at_field(name));
}

io::BvhWriteOptions bvh_write_options(const std::string& order, const std::string& units) {
  io::BvhWriteOptions w;
  const auto o = motion::parse_euler_order(order);
  if (!o) throw Error("unknown rotation order '" + order + "' (XYZ, XZY, YXZ, YZX, ZXY, ZYX)", at_field("--order"));
  w.order = *o;
  const auto u = motion::parse_length_unit(units);
  if (!u) throw Error("unknown unit '" + units + "' (m, cm, mm, in, cmu)", at_field("--units"));
  w.unit = *u;
  return w;
}

}  // namespace throng::app
