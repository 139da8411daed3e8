#include "sim/soak_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/memory_budget.h"

namespace throng::sim {

namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

double mib(std::uint64_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

nlohmann::json check_json(const SoakCheck& c) {
  return {{"step", c.step},
          {"time_s", c.time},
          {"wall_s", c.wall_seconds},
          {"active", c.active},
          {"non_finite", c.non_finite},
          {"penetrations", c.penetrations},
          {"max_overlap_m", c.overlaps.max_depth},
          {"overlap_pairs", c.overlaps.pairs},
          {"rss_mib", mib(c.rss_bytes)}};
}

}  // namespace

SoakCheckStage::SoakCheckStage(SoakOptions options) : options_(std::move(options)) {
  if (options_.every < 1) throw Error("must be >= 1", at_field("--check-every"));
  if (!options_.report.empty()) {
    report_.open(options_.report, std::ios::trunc);
    if (!report_) throw Error("cannot write the soak report " + options_.report, at_field("--out"));
  }
}

SoakCheck SoakCheckStage::measure(const Simulation& sim, const FrameInfo& frame) const {
  const CrowdState& c = sim.crowd();
  SoakCheck s;
  s.step = frame.frame;
  s.time = frame.time;
  s.wall_seconds = static_cast<double>(now_ns() - start_ns_) * 1e-9;
  s.active = sim.active_count();
  s.non_finite = count_non_finite(c.position.span(), c.velocity.span());
  // With a NaN about, the bins cannot place the agents: report it alone.
  if (s.non_finite == 0) {
    s.penetrations = count_obstacle_penetrations(sim.world(), c.position.span(), c.radius.span(), c.flags.span(),
                                                 options_.penetration_tolerance);
    s.overlaps = measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), options_.overlap_bound,
                                  sim.contact_cell(), sim.world().periodic());
  }
  s.rss_bytes = resident_memory_bytes();
  return s;
}

std::string SoakCheckStage::violation(const SoakCheck& c) const {
  if (c.non_finite > 0) return fmt::format("{} agents with a non-finite position or velocity", c.non_finite);
  if (c.penetrations > 0)
    return fmt::format(
        "{} agents outside free space (discs into an obstacle by more than {:g} mm, or outside the walkable area)",
        c.penetrations, 1000.0 * options_.penetration_tolerance);
  if (c.overlaps.pairs > 0)
    return fmt::format("{} pairs overlap by more than the model's bound of {:g} cm (deepest {:.1f} cm)",
                       c.overlaps.pairs, 100.0 * options_.overlap_bound, 100.0 * c.overlaps.max_depth);
  return {};
}

void SoakCheckStage::after_step(const Simulation& sim, const FrameInfo& frame) {
  if (frame.frame % options_.every != 0 && !frame.last) return;
  if (!checks_.empty() && checks_.back().step == frame.frame) return;  // the last frame fell on a check
  if (start_ns_ < 0) start_ns_ = now_ns();
  checks_.push_back(measure(sim, frame));
  if (report_.is_open()) report_ << check_json(checks_.back()).dump() << '\n' << std::flush;
  // Fail at once: the steps after a broken state only hide where it began.
  if (const std::string why = violation(checks_.back()); !why.empty())
    throw Error(fmt::format("soak check at step {} ({:.1f} s simulated): {}{}", frame.frame, frame.time, why,
                            options_.report.empty() ? "" : " (every check: " + options_.report + ")"));
}

const SoakCheck* SoakCheckStage::warmed_up() const {
  const auto warmup =
      static_cast<std::int64_t>(std::ceil(options_.warmup_fraction * static_cast<double>(options_.max_steps)));
  for (const SoakCheck& c : checks_)
    if (c.step >= warmup && &c != &checks_.back()) return &c;
  return nullptr;
}

double SoakCheckStage::rss_growth() const {
  const SoakCheck* base = warmed_up();
  if (base == nullptr || base->rss_bytes == 0) return 0.0;
  return static_cast<double>(checks_.back().rss_bytes) / static_cast<double>(base->rss_bytes) - 1.0;
}

std::string SoakCheckStage::failure() const {
  if (rss_growth() <= options_.max_rss_growth) return {};
  return fmt::format("resident memory grew by {:.1f}% from step {} to step {} ({:.1f} -> {:.1f} MiB), more than {:g}%",
                     100.0 * rss_growth(), warmed_up()->step, checks_.back().step, mib(warmed_up()->rss_bytes),
                     mib(checks_.back().rss_bytes), 100.0 * options_.max_rss_growth);
}

void SoakCheckStage::finish(const Simulation& sim, nlohmann::json& stats) {
  float max_overlap = 0.0f;
  std::uint64_t peak = 0;
  for (const SoakCheck& c : checks_) {
    max_overlap = std::max(max_overlap, c.overlaps.max_depth);
    peak = std::max(peak, c.rss_bytes);
  }
  const SoakCheck* base = warmed_up();
  auto rss_at = [](const SoakCheck* c) {
    return c != nullptr ? nlohmann::json(mib(c->rss_bytes)) : nlohmann::json(nullptr);
  };
  stats["soak"] = {{"checks", checks_.size()},
                   {"check_every_steps", options_.every},
                   {"steps", checks_.empty() ? 0 : checks_.back().step},
                   {"agents", sim.agent_count()},
                   {"overlap_bound_m", options_.overlap_bound},
                   {"max_overlap_m", max_overlap},
                   {"penetration_tolerance_m", options_.penetration_tolerance},
                   {"rss_mib",
                    {{"first", rss_at(checks_.empty() ? nullptr : &checks_.front())},
                     {"after_warmup", rss_at(base)},
                     {"warmup_step", base != nullptr ? nlohmann::json(base->step) : nlohmann::json(nullptr)},
                     {"end", rss_at(checks_.empty() ? nullptr : &checks_.back())},
                     {"peak", mib(peak)},
                     {"growth", rss_growth()},
                     {"max_growth", options_.max_rss_growth}}},
                   {"passed", failure().empty()},
                   {"failure", failure()}};
}

}  // namespace throng::sim
