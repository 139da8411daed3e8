#include "path/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "path/host_parallel.h"
#include "path/playback.h"
#include "core/random.h"

namespace throng::path {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void add(SequenceStats& s, const Sequence& q, std::int32_t curves, std::int32_t k, double& error_sum) {
  s.illegal += q.illegal;
  s.paths_with_illegal += q.illegal > 0;
  if (q.illegal == 0) s.total_cost += q.total();
  error_sum += q.path_error * curves * k;
}
}  // namespace

MatchRun match_paths(const MotionGraph& machine, const std::vector<PathInput>& inputs, const MatchRunOptions& options) {
  MatchRun run;
  const auto n = static_cast<Index>(inputs.size());
  ResampleOptions ro;
  ro.spacing = machine.spacing();
  ro.max_knot_spacing = std::max(options.max_knot_spacing, machine.spacing());
  ro.validate();

  auto t0 = std::chrono::steady_clock::now();
  std::vector<ResampledPath> resampled(inputs.size());
  std::vector<std::string> errors(inputs.size());
  host_parallel_for("path.resample", n, [&](Index i) {
    const auto u = static_cast<std::size_t>(i);
    try {
      resampled[u] = resample_path(inputs[u].points, ro, inputs[u].marks);
    } catch (const Error& e) {
      errors[u] = e.message();
    }
  });
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (!errors[i].empty())
      throw Error(errors[i], at_field("paths[" + std::to_string(i) + "] (" + inputs[i].name + ")"));
  run.resample_ms = ms_since(t0);

  std::vector<float> speeds;
  for (const PathInput& p : inputs) speeds.push_back(p.speed);
  const CurveSet curves = cut_paths(resampled, machine, speeds);
  run.curves = curves.curve_count();
  run.motions = static_cast<std::int64_t>(machine.locomotion_segments().size());

  t0 = std::chrono::steady_clock::now();
  MatchGrid grid(machine, curves, options.match);
  grid.match();
  const std::vector<float> cost = grid.cost();
  const std::vector<std::int32_t> best = grid.best();
  run.grid_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  const std::vector<Sequence> greedy = greedy_sequences(machine, curves, cost, best);
  const std::vector<Sequence> repaired = repaired_greedy_sequences(machine, curves, cost);
  const std::vector<Sequence> dp = dp_sequences(machine, curves, cost);
  run.sequences_ms = ms_since(t0);

  const std::int32_t k = machine.k();
  double eg = 0, er = 0, ed = 0;
  run.paths.resize(inputs.size());
  for (std::size_t p = 0; p < inputs.size(); ++p) {
    const std::int32_t c = curves.path_begin[p + 1] - curves.path_begin[p];
    add(run.greedy, greedy[p], c, k, eg);
    add(run.repaired, repaired[p], c, k, er);
    add(run.dp, dp[p], c, k, ed);
    PathResult& r = run.paths[p];
    r.name = inputs[p].name;
    r.length = resampled[p].spline_length;
    r.points = static_cast<std::int32_t>(resampled[p].points.size());
    r.curves = c;
    r.greedy_illegal = greedy[p].illegal;
    r.greedy_error = greedy[p].path_error;
    r.dp_error = dp[p].path_error;
    for (std::int32_t s : dp[p].segments)
      r.dp_states.push_back(
          machine.states()[static_cast<std::size_t>(machine.segments()[static_cast<std::size_t>(s)].state)].name);
  }
  const double points = std::max<double>(1.0, static_cast<double>(run.curves) * k);
  run.greedy.path_error = eg / points;
  run.repaired.path_error = er / points;
  run.dp.path_error = ed / points;

  // Playback of the DP sequences; clips kept only for the first few paths.
  t0 = std::chrono::steady_clock::now();
  run.clips.resize(static_cast<std::size_t>(std::clamp<Index>(options.keep_clips, 0, n)));
  std::vector<std::int64_t> frames(inputs.size(), 0);
  std::vector<double> dev_sum(inputs.size(), 0.0);
  host_parallel_for("path.playback", n, [&](Index i) {
    const auto u = static_cast<std::size_t>(i);
    if (dp[u].segments.empty()) return;
    Playback pb = play(machine, resampled[u], dp[u]);
    run.paths[u].deviation_mean = pb.deviation_mean;
    run.paths[u].deviation_max = pb.deviation_max;
    run.paths[u].duration_s = pb.clip.duration();
    frames[u] = pb.matched_frames;
    dev_sum[u] = pb.deviation_mean * pb.matched_frames;
    if (u < run.clips.size()) run.clips[u] = std::move(pb.clip);
  });
  std::int64_t total_frames = 0;
  double total_dev = 0;
  for (std::size_t p = 0; p < inputs.size(); ++p) {
    total_frames += frames[p];
    total_dev += dev_sum[p];
    run.deviation_max = std::max(run.deviation_max, run.paths[p].deviation_max);
  }
  run.deviation_mean = total_frames > 0 ? total_dev / static_cast<double>(total_frames) : 0.0;
  run.playback_ms = ms_since(t0);
  return run;
}

sim::World random_obstacle_world(const RandomWorldOptions& o) {
  sim::WorldSpec spec;
  spec.has_walkable = true;
  spec.walkable.outer = sim::rect_ring({0, 0}, {o.width, o.height});
  sim::ScatterSpec sc;
  sc.count = o.obstacles;
  sc.region.kind = sim::Region::Kind::rect;
  sc.region.min = {1.0f, 1.0f};
  sc.region.max = {o.width - 1.0f, o.height - 1.0f};
  sc.min_size = o.min_size;
  sc.max_size = o.max_size;
  sc.clearance = o.gap;
  sc.seed = o.seed;
  spec.scatters.push_back(sc);
  spec.scatter_fields.push_back("world.scatter[0]");
  return sim::World::build(spec, 4.0f, {}, Memory::Host);
}

std::vector<PathQuery> random_queries(const Planner& planner, std::int64_t count, std::uint64_t seed,
                                      float min_distance) {
  const sim::Aabb b = planner.space().bounds();
  if (b.empty()) throw Error("the planner's free space is empty", at_field("random_queries"));
  Rng rng(seed, 0x9a7);
  const float need = planner.options().radius + 0.1f;
  auto sample = [&]() -> glm::vec2 {
    for (int attempt = 0; attempt < 10000; ++attempt) {
      const glm::vec2 p(static_cast<float>(rng.uniform(b.min.x, b.max.x)),
                        static_cast<float>(rng.uniform(b.min.y, b.max.y)));
      if (planner.space().clearance(p) >= need) return p;
    }
    throw Error("found no free point with room for the agent", at_field("random_queries"));
  };
  const float diag = sim::length_of(b.max - b.min);
  const float dist = std::min(min_distance, 0.5f * diag);
  std::vector<PathQuery> out;
  while (static_cast<std::int64_t>(out.size()) < count) {
    const glm::vec2 a = sample();
    glm::vec2 g = sample();
    for (int tries = 0; tries < 100 && sim::length_of(g - a) < dist; ++tries) g = sample();
    out.push_back({a, g});
  }
  return out;
}

}  // namespace throng::path
