// Checks for long runs as a frame stage (`throng run --check-every K`,
// scripts/soak.sh): every K frames, and at the last, it counts agents with a
// non-finite position or velocity, agents whose disc leaves free space (the
// crowd metrics' obstacle penetrations), the deepest pair overlap (the crowd
// metrics' overlaps) and the process's resident memory; writes one JSON
// line per check; throws Error at the first check that finds a non-finite
// agent, a penetration or an overlap beyond the bound. Memory is judged at
// the end: resident memory may grow by at most `max_rss_growth` from the
// end of the warm-up to the last check (failure() says so; the run still
// writes its files).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "sim/frame_loop.h"
#include "sim/metrics.h"

namespace throng::sim {

struct SoakOptions {
  std::int64_t every = 1000;            // frames between checks
  std::int64_t max_steps = 0;           // the run's length: the warm-up is a fraction of it
  float overlap_bound = kOverlapBound;  // m: a deeper pair overlap fails
  float penetration_tolerance = 1e-3f;  // m: as the crowd metrics count penetrations
  double warmup_fraction = 0.1;         // of max_steps: buffers and caches reach their size
  double max_rss_growth = 0.05;         // fraction, from the end of the warm-up to the last check
  std::string report;                   // JSON-lines file, one line per check; empty = none
};

struct SoakCheck {
  std::int64_t step = 0;
  double time = 0;          // simulated s
  double wall_seconds = 0;  // since the first check
  Index active = 0;
  Index non_finite = 0;
  Index penetrations = 0;
  OverlapStats overlaps;
  std::uint64_t rss_bytes = 0;
};

class SoakCheckStage : public FrameStage {
 public:
  explicit SoakCheckStage(SoakOptions options);
  std::string name() const override { return "sim.soak_checks"; }
  void after_step(const Simulation& sim, const FrameInfo& frame) override;
  // The "soak" section of stats.json: the bounds, the figures, the verdict.
  void finish(const Simulation& sim, nlohmann::json& stats) override;

  const std::vector<SoakCheck>& checks() const { return checks_; }
  // Resident memory growth from the end of the warm-up to the last check
  // (0 before two checks).
  double rss_growth() const;
  // Empty when the run held its bounds; else why not, for stderr.
  std::string failure() const;

 private:
  SoakCheck measure(const Simulation& sim, const FrameInfo& frame) const;
  // The first check's message when it breaks a bound, else empty.
  std::string violation(const SoakCheck& c) const;
  const SoakCheck* warmed_up() const;  // the baseline of rss_growth, or null

  SoakOptions options_;
  std::vector<SoakCheck> checks_;  // a few hundred at most: kept whole
  std::ofstream report_;
  std::int64_t start_ns_ = -1;
};

}  // namespace throng::sim
