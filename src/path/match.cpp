#include "path/match.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "path/host_parallel.h"

namespace throng::path {

CurveSet cut_paths(std::span<const ResampledPath> paths, const MotionGraph& machine,
                   std::span<const float> desired_speed) {
  if (!desired_speed.empty() && desired_speed.size() != paths.size())
    throw Error("one desired speed per path expected", at_field("match.speed"));
  CurveSet out;
  out.k = machine.k();
  const auto k = static_cast<std::size_t>(out.k);
  out.path_begin.push_back(0);
  for (std::size_t p = 0; p < paths.size(); ++p) {
    const ResampledPath& path = paths[p];
    if (std::fabs(path.spacing - machine.spacing()) > 1e-6f * machine.spacing())
      throw Error(
          fmt::format("path resampled every {} m, the machine's spacing is {} m", path.spacing, machine.spacing()),
          at_field(fmt::format("paths[{}]", p)));
    std::vector<std::int32_t> state_of_mark;
    for (const std::string& name : path.mark_states) {
      const std::int32_t s = machine.state_index(name);
      if (s < 0) throw Error("mark names unknown state '" + name + "'", at_field(fmt::format("paths[{}].marks", p)));
      state_of_mark.push_back(s);
    }
    const float v = desired_speed.empty() ? 0.0f : desired_speed[p];
    if (!(v >= 0 && std::isfinite(v)))
      throw Error("desired speed must be >= 0", at_field(fmt::format("paths[{}].speed", p)));
    const std::size_t curves = path.points.size() / k;
    for (std::size_t c = 0; c < curves; ++c) {
      std::int32_t required = -1;
      for (std::size_t i = 0; i < k; ++i) {
        out.points.push_back(path.points[c * k + i]);
        const std::int32_t f = path.fixed_state[c * k + i];
        if (required < 0 && f >= 0) required = state_of_mark[static_cast<std::size_t>(f)];
      }
      out.tangents.push_back(path.tangents[c * k]);
      out.required_state.push_back(required);
      out.speed.push_back(v);
    }
    out.path_begin.push_back(out.path_begin.back() + static_cast<std::int32_t>(curves));
  }
  return out;
}

void MatchOptions::validate() const {
  if (!(speed_weight >= 0 && std::isfinite(speed_weight)))
    throw Error("speed weight must be >= 0", at_field("match.speed_weight"));
}

MatchGrid::MatchGrid(const MotionGraph& machine, const CurveSet& curves, const MatchOptions& options) {
  options.validate();
  const Memory mem = current_memory();
  const std::vector<std::int32_t>& loco = machine.locomotion_segments();
  motions_ = static_cast<std::int32_t>(loco.size());
  curves_ = curves.curve_count();
  std::vector<glm::vec2> mp;
  std::vector<std::int32_t> ms;
  std::vector<float> mv;
  for (std::int32_t id : loco) {
    const MotionSegment& s = machine.segments()[static_cast<std::size_t>(id)];
    mp.insert(mp.end(), s.trajectory.begin(), s.trajectory.end());
    ms.push_back(s.state);
    mv.push_back(s.speed);
  }
  motion_points_ = Buffer<glm::vec2>(std::span<const glm::vec2>(mp), mem);
  motion_state_ = Buffer<std::int32_t>(std::span<const std::int32_t>(ms), mem);
  motion_speed_ = Buffer<float>(std::span<const float>(mv), mem);
  curve_points_ = Buffer<glm::vec2>(std::span<const glm::vec2>(curves.points), mem);
  curve_tangents_ = Buffer<glm::vec2>(std::span<const glm::vec2>(curves.tangents), mem);
  curve_state_ = Buffer<std::int32_t>(std::span<const std::int32_t>(curves.required_state), mem);
  curve_speed_ = Buffer<float>(std::span<const float>(curves.speed), mem);
  cost_ = Buffer<float>(Index{curves_} * motions_, mem);
  best_ = Buffer<std::int32_t>(curves_, mem);
  best_cost_ = Buffer<float>(curves_, mem);
  job_ = {.k = machine.k(),
          .motions = motions_,
          .speed_weight = options.speed_weight,
          .motion_points = motion_points_.span(),
          .motion_state = motion_state_.span(),
          .motion_speed = motion_speed_.span(),
          .curve_points = curve_points_.span(),
          .curve_tangents = curve_tangents_.span(),
          .curve_state = curve_state_.span(),
          .curve_speed = curve_speed_.span(),
          .cost = cost_.span()};
}

void MatchGrid::match() {
  if (curves_ == 0) return;
  job_.run();
  BestMotionJob best;
  best.motions = motions_;
  best.cost = cost_.span();
  best.best = best_.span();
  best.best_cost = best_cost_.span();
  best.run();
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double pair_cost(std::span<const float> cost, std::int32_t motions, std::int32_t c, std::int32_t m) {
  const float v = cost[static_cast<std::size_t>(c) * static_cast<std::size_t>(motions) + static_cast<std::size_t>(m)];
  return v >= kNoMatch ? kInf : static_cast<double>(v);
}

// Cheapest legal way into segment b from the start state (seg, cost), or (-1, inf).
std::pair<std::int32_t, double> best_start(const MotionGraph& m, std::int32_t b) {
  if (m.start_state() < 0) return {-1, 0.0};
  std::pair<std::int32_t, double> best{-1, kInf};
  for (std::int32_t a : m.states()[static_cast<std::size_t>(m.start_state())].segments) {
    const double t = m.transition_cost(a, b);
    if (t < best.second) best = {a, t};
  }
  return best;
}
std::pair<std::int32_t, double> best_end(const MotionGraph& m, std::int32_t a) {
  if (m.end_state() < 0) return {-1, 0.0};
  std::pair<std::int32_t, double> best{-1, kInf};
  for (std::int32_t b : m.states()[static_cast<std::size_t>(m.end_state())].segments) {
    const double t = m.transition_cost(a, b);
    if (t < best.second) best = {b, t};
  }
  return best;
}

}  // namespace

Sequence score_sequence(const MotionGraph& machine, const CurveSet& curves, std::span<const float> cost,
                        std::int32_t path, std::span<const std::int32_t> grid_motions) {
  const auto& loco = machine.locomotion_segments();
  const auto motions = static_cast<std::int32_t>(loco.size());
  const std::int32_t c0 = curves.path_begin[static_cast<std::size_t>(path)];
  const std::int32_t n = curves.path_begin[static_cast<std::size_t>(path) + 1] - c0;
  Sequence s;
  if (n == 0) return s;
  double geometric = 0;
  for (std::int32_t c = 0; c < n; ++c) {
    const std::int32_t m = grid_motions[static_cast<std::size_t>(c)];
    const std::int32_t seg = loco[static_cast<std::size_t>(m)];
    s.segments.push_back(seg);
    const double e = pair_cost(cost, motions, c0 + c, m);
    if (e == kInf) {
      ++s.illegal;
    } else {
      s.match_cost += e;
    }
    const MotionSegment& ms = machine.segments()[static_cast<std::size_t>(seg)];
    geometric += curve_motion_distance(
        curves.points.data() + static_cast<std::size_t>(c0 + c) * static_cast<std::size_t>(curves.k),
        curves.tangents[static_cast<std::size_t>(c0 + c)], ms.trajectory.data(), curves.k);
    if (c > 0) {
      const double t = machine.transition_cost(s.segments[static_cast<std::size_t>(c) - 1], seg);
      if (t == kInf) {
        ++s.illegal;
      } else {
        s.transition_cost += t;
      }
    }
  }
  auto [a, ta] = best_start(machine, s.segments.front());
  if (machine.start_state() >= 0) {
    if (ta == kInf) {
      ++s.illegal;
      a = machine.states()[static_cast<std::size_t>(machine.start_state())].segments.front();
    } else {
      s.transition_cost += ta;
    }
  }
  auto [b, tb] = best_end(machine, s.segments.back());
  if (machine.end_state() >= 0) {
    if (tb == kInf) {
      ++s.illegal;
      b = machine.states()[static_cast<std::size_t>(machine.end_state())].segments.front();
    } else {
      s.transition_cost += tb;
    }
  }
  s.start_segment = a;
  s.end_segment = b;
  s.path_error = geometric / (static_cast<double>(n) * curves.k);
  return s;
}

std::vector<Sequence> greedy_sequences(const MotionGraph& machine, const CurveSet& curves, std::span<const float> cost,
                                       std::span<const std::int32_t> best) {
  std::vector<Sequence> out(static_cast<std::size_t>(curves.path_count()));
  for (std::int32_t p = 0; p < curves.path_count(); ++p) {
    const auto c0 = static_cast<std::size_t>(curves.path_begin[static_cast<std::size_t>(p)]);
    const auto c1 = static_cast<std::size_t>(curves.path_begin[static_cast<std::size_t>(p) + 1]);
    out[static_cast<std::size_t>(p)] = score_sequence(machine, curves, cost, p, best.subspan(c0, c1 - c0));
  }
  return out;
}

std::vector<Sequence> repaired_greedy_sequences(const MotionGraph& machine, const CurveSet& curves,
                                                std::span<const float> cost) {
  const auto& loco = machine.locomotion_segments();
  const auto motions = static_cast<std::int32_t>(loco.size());
  std::vector<Sequence> out(static_cast<std::size_t>(curves.path_count()));
  for (std::int32_t p = 0; p < curves.path_count(); ++p) {
    const std::int32_t c0 = curves.path_begin[static_cast<std::size_t>(p)];
    const std::int32_t n = curves.path_begin[static_cast<std::size_t>(p) + 1] - c0;
    std::vector<std::int32_t> chosen;
    for (std::int32_t c = 0; c < n; ++c) {
      std::int32_t arg = -1, any = 0;
      double low = kInf, any_low = kInf;
      for (std::int32_t m = 0; m < motions; ++m) {
        const double e = pair_cost(cost, motions, c0 + c, m);
        if (e < any_low) {
          any_low = e;
          any = m;
        }
        const std::int32_t seg = loco[static_cast<std::size_t>(m)];
        const bool in_ok = c == 0 ? best_start(machine, seg).second < kInf
                                  : machine.transition_cost(loco[static_cast<std::size_t>(chosen.back())], seg) < kInf;
        const bool out_ok = c + 1 < n || best_end(machine, seg).second < kInf;
        if (in_ok && out_ok && e < low) {
          low = e;
          arg = m;
        }
      }
      chosen.push_back(arg >= 0 ? arg : any);
    }
    out[static_cast<std::size_t>(p)] = score_sequence(machine, curves, cost, p, chosen);
  }
  return out;
}

std::vector<Sequence> dp_sequences(const MotionGraph& machine, const CurveSet& curves, std::span<const float> cost) {
  const auto& loco = machine.locomotion_segments();
  const auto M = static_cast<std::int32_t>(loco.size());
  std::vector<Sequence> out(static_cast<std::size_t>(curves.path_count()));
  // Transition costs between grid motions, and into/out of the start/end states.
  std::vector<double> tr(static_cast<std::size_t>(M) * static_cast<std::size_t>(M)), into(static_cast<std::size_t>(M)),
      outof(static_cast<std::size_t>(M));
  for (std::int32_t a = 0; a < M; ++a) {
    into[static_cast<std::size_t>(a)] = best_start(machine, loco[static_cast<std::size_t>(a)]).second;
    outof[static_cast<std::size_t>(a)] = best_end(machine, loco[static_cast<std::size_t>(a)]).second;
    for (std::int32_t b = 0; b < M; ++b)
      tr[static_cast<std::size_t>(a * M + b)] =
          machine.transition_cost(loco[static_cast<std::size_t>(a)], loco[static_cast<std::size_t>(b)]);
  }
  host_parallel_for("path.match_dp", curves.path_count(), [&](Index p) {
    const std::int32_t c0 = curves.path_begin[static_cast<std::size_t>(p)];
    const std::int32_t n = curves.path_begin[static_cast<std::size_t>(p) + 1] - c0;
    if (n == 0) return;
    const auto sM = static_cast<std::size_t>(M);
    std::vector<double> D(static_cast<std::size_t>(n) * sM, kInf);
    std::vector<std::int32_t> from(static_cast<std::size_t>(n) * sM, -1);
    for (std::int32_t m = 0; m < M; ++m)
      D[static_cast<std::size_t>(m)] = pair_cost(cost, M, c0, m) + into[static_cast<std::size_t>(m)];
    for (std::int32_t c = 1; c < n; ++c)
      for (std::int32_t m = 0; m < M; ++m) {
        const double e = pair_cost(cost, M, c0 + c, m);
        if (e == kInf) continue;
        double low = kInf;
        std::int32_t arg = -1;
        for (std::int32_t q = 0; q < M; ++q) {
          const double v = D[static_cast<std::size_t>(c - 1) * sM + static_cast<std::size_t>(q)] +
                           tr[static_cast<std::size_t>(q * M + m)];
          if (v < low) {
            low = v;
            arg = q;
          }
        }
        D[static_cast<std::size_t>(c) * sM + static_cast<std::size_t>(m)] = e + low;
        from[static_cast<std::size_t>(c) * sM + static_cast<std::size_t>(m)] = arg;
      }
    double low = kInf;
    std::int32_t arg = -1;
    for (std::int32_t m = 0; m < M; ++m) {
      const double v =
          D[static_cast<std::size_t>(n - 1) * sM + static_cast<std::size_t>(m)] + outof[static_cast<std::size_t>(m)];
      if (v < low) {
        low = v;
        arg = m;
      }
    }
    std::vector<std::int32_t> chosen(static_cast<std::size_t>(n));
    if (arg < 0) {  // no legal sequence: each curve's best, scored with its violations
      for (std::int32_t c = 0; c < n; ++c) {
        double lo = kInf;
        for (std::int32_t m = 0; m < M; ++m)
          if (pair_cost(cost, M, c0 + c, m) < lo) {
            lo = pair_cost(cost, M, c0 + c, m);
            chosen[static_cast<std::size_t>(c)] = m;
          }
      }
    } else {
      for (std::int32_t c = n - 1; c >= 0; --c) {
        chosen[static_cast<std::size_t>(c)] = arg;
        arg = from[static_cast<std::size_t>(c) * sM + static_cast<std::size_t>(arg)];
      }
    }
    out[static_cast<std::size_t>(p)] = score_sequence(machine, curves, cost, static_cast<std::int32_t>(p), chosen);
  });
  return out;
}

}  // namespace throng::path
