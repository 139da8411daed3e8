// The motion state machine, the matching grid (greedy == exhaustive
// reference, same for any thread count), dynamic programming (legal, optimal
// against brute force, never worse than a legal greedy repair) and playback.
#include "path/match.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/exec.h"
#include "path/playback.h"
#include "sim/geometry.h"
#include "core/random.h"
#include "tests/path/path_machine.h"

namespace throng::path {
namespace {

using testing::small_machine;

// A smooth random walk of `n` edges, resampled at the machine's spacing.
ResampledPath random_path(std::uint64_t seed, int n, float turn = 0.6f, std::vector<PathMark> marks = {}) {
  Rng rng(seed);
  std::vector<glm::vec2> p = {{0, 0}};
  float heading = static_cast<float>(rng.uniform(-3.14, 3.14));
  for (int i = 0; i < n; ++i) {
    heading += static_cast<float>(rng.uniform(-turn, turn));
    p.push_back(p.back() + static_cast<float>(rng.uniform(1.0, 3.0)) * glm::vec2(std::cos(heading), std::sin(heading)));
  }
  ResampleOptions o;
  o.spacing = small_machine().spacing();
  return resample_path(p, o, marks);
}

TEST(MotionGraph, SegmentsHaveEqualArcLengthAndTurnTheRightWay) {
  const MotionGraph& m = small_machine();
  const float s = m.spacing();
  ASSERT_EQ(m.locomotion_segments().size(), 7u);
  for (std::int32_t id : m.locomotion_segments()) {
    const MotionSegment& seg = m.segments()[static_cast<std::size_t>(id)];
    const std::string& state = m.states()[static_cast<std::size_t>(seg.state)].name;
    ASSERT_EQ(seg.trajectory.size(), static_cast<std::size_t>(m.k())) << seg.name;
    EXPECT_LT(sim::length_of(seg.trajectory[0]), 1e-5f);
    float arc = 0;
    for (std::size_t i = 1; i < seg.trajectory.size(); ++i) {
      const float step = sim::length_of(seg.trajectory[i] - seg.trajectory[i - 1]);
      EXPECT_NEAR(step, s, 0.01f * s) << seg.name;
      arc += step;
    }
    arc += sim::length_of(seg.end_point - seg.trajectory.back());
    EXPECT_NEAR(arc, m.segment_length(), 0.01f * m.segment_length()) << seg.name;
    EXPECT_NEAR(seg.trajectory[1].y / seg.trajectory[1].x, 0.0f, 0.02f) << seg.name;  // leaves along +x
    const float side = seg.trajectory.back().y;
    if (state == "walk_left") {
      EXPECT_GT(side, 0.05f) << seg.name;
    }
    if (state == "walk_right") {
      EXPECT_LT(side, -0.05f) << seg.name;
    }
    if (state == "walk_forward" || state == "run_forward") {
      EXPECT_NEAR(side, 0.0f, 0.01f) << seg.name;
    }
  }
  // Speeds of the smoothed roots match the clips.
  const std::int32_t walk = m.states()[static_cast<std::size_t>(m.state_index("walk_forward"))].segments[0];
  const std::int32_t run = m.states()[static_cast<std::size_t>(m.state_index("run_forward"))].segments[0];
  EXPECT_NEAR(m.segments()[static_cast<std::size_t>(walk)].speed, 1.35f, 0.03f);
  EXPECT_NEAR(m.segments()[static_cast<std::size_t>(run)].speed, 2.7f, 0.06f);
}

TEST(MotionGraph, ChildrenInheritTheirGroupsEdges) {
  const MotionGraph& m = small_machine();
  auto s = [&](const char* n) { return m.state_index(n); };
  EXPECT_TRUE(m.allowed(s("walk_forward"), s("walk_right")));  // F -> locomotion
  EXPECT_TRUE(m.allowed(s("run_forward"), s("walk_left")));
  EXPECT_TRUE(m.allowed(s("walk_left"), s("run_forward")));  // L -> F
  EXPECT_TRUE(m.allowed(s("walk_left"), s("walk_left")));
  EXPECT_FALSE(m.allowed(s("walk_left"), s("walk_right")));  // no L -> R
  EXPECT_FALSE(m.allowed(s("idle"), s("run_forward")));
  EXPECT_TRUE(m.allowed(s("walk_forward"), s("idle")));
  // Transition costs: finite exactly where allowed; a segment flows into its
  // own continuation (same clip, next stride) with almost no mismatch.
  const std::int32_t w0 = m.states()[static_cast<std::size_t>(s("walk_forward"))].segments[0];
  const std::int32_t l0 = m.states()[static_cast<std::size_t>(s("walk_left"))].segments[0];
  const std::int32_t r0 = m.states()[static_cast<std::size_t>(s("walk_right"))].segments[0];
  EXPECT_TRUE(std::isinf(m.transition_cost(l0, r0)));
  EXPECT_TRUE(std::isfinite(m.transition_cost(w0, r0)));
  // k = 32 points cover half a walking stride: walk/0 ends where walk/1 (32 frames on) starts.
  const std::int32_t w1 = m.states()[static_cast<std::size_t>(s("walk_forward"))].segments[1];
  EXPECT_LT(m.transition_cost(w0, w1), 0.01f);
  EXPECT_LT(m.transition_cost(w0, w1), m.transition_cost(w0, w0));
}

TEST(MotionGraph, BadSpecsNameTheProblem) {
  auto spec = testing::small_machine_spec();
  spec.edges.push_back({"walk_left", "nowhere", 0, at_line("m.yaml", 7, 3)});
  try {
    MotionGraph::build(spec, motion::default_skeleton());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("m.yaml:7:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nowhere"), std::string::npos) << e.what();
  }
  spec = testing::small_machine_spec();
  spec.groups.push_back({"loop_a", "loop_b", {}});
  spec.groups.push_back({"loop_b", "loop_a", {}});
  EXPECT_THROW(MotionGraph::build(spec, motion::default_skeleton()), Error);
  spec = testing::small_machine_spec();
  spec.states[0].segments[0].clip = "missing";
  EXPECT_THROW(MotionGraph::build(spec, motion::default_skeleton()), Error);
}

// ---- the grid ------------------------------------------------------------------

struct Reference {
  std::vector<double> cost;  // [curves * motions]
};
Reference exhaustive(const MotionGraph& m, const CurveSet& cs, double speed_weight) {
  const auto& loco = m.locomotion_segments();
  Reference r;
  for (std::int32_t c = 0; c < cs.curve_count(); ++c)
    for (std::int32_t id : loco) {
      const MotionSegment& seg = m.segments()[static_cast<std::size_t>(id)];
      const std::int32_t req = cs.required_state[static_cast<std::size_t>(c)];
      if (req >= 0 && seg.state != req) {
        r.cost.push_back(std::numeric_limits<double>::infinity());
        continue;
      }
      const glm::vec2 t = cs.tangents[static_cast<std::size_t>(c)];
      const double th = std::atan2(static_cast<double>(t.y), static_cast<double>(t.x));
      const glm::vec2* p = cs.points.data() + static_cast<std::size_t>(c) * static_cast<std::size_t>(cs.k);
      double sum = 0;
      for (std::int32_t i = 0; i < cs.k; ++i) {
        const glm::dvec2 q(seg.trajectory[static_cast<std::size_t>(i)]);
        const glm::dvec2 placed(p[0].x + std::cos(th) * q.x - std::sin(th) * q.y,
                                p[0].y + std::sin(th) * q.x + std::cos(th) * q.y);
        sum += glm::length(glm::dvec2(p[i]) - placed);
      }
      const double v = cs.speed[static_cast<std::size_t>(c)];
      if (v > 0) sum += speed_weight * cs.k * std::fabs(seg.speed - v);
      r.cost.push_back(sum);
    }
  return r;
}

CurveSet random_curves(int paths, std::uint64_t seed, std::vector<float>* speeds = nullptr) {
  std::vector<ResampledPath> ps;
  std::vector<float> v;
  Rng rng(seed);
  for (int i = 0; i < paths; ++i) {
    ps.push_back(random_path(seed * 100 + static_cast<std::uint64_t>(i), 8));
    v.push_back(i % 3 == 0 ? 0.0f : static_cast<float>(rng.uniform(1.0, 3.0)));
  }
  if (speeds) *speeds = v;
  return cut_paths(ps, small_machine(), v);
}

TEST(MatchGrid, GreedyEqualsExhaustiveReference) {
  const MotionGraph& m = small_machine();
  const CurveSet cs = random_curves(12, 3);
  ASSERT_GT(cs.curve_count(), 100);
  MatchOptions o;
  MatchGrid grid(m, cs, o);
  grid.match();
  const std::vector<float> cost = grid.cost();
  const std::vector<std::int32_t> best = grid.best();
  const Reference ref = exhaustive(m, cs, o.speed_weight);
  const std::int32_t M = grid.motions();
  for (std::int32_t c = 0; c < cs.curve_count(); ++c) {
    std::int32_t arg = 0;
    for (std::int32_t j = 0; j < M; ++j) {
      const double r = ref.cost[static_cast<std::size_t>(c * M + j)];
      EXPECT_NEAR(cost[static_cast<std::size_t>(c * M + j)], r, 1e-4 * std::max(1.0, r));
      if (r < ref.cost[static_cast<std::size_t>(c * M + arg)]) arg = j;
    }
    const double chosen = ref.cost[static_cast<std::size_t>(c * M + best[static_cast<std::size_t>(c)])];
    const double optimum = ref.cost[static_cast<std::size_t>(c * M + arg)];
    if (best[static_cast<std::size_t>(c)] != arg) {
      EXPECT_NEAR(chosen, optimum, 1e-4 * std::max(1.0, optimum)) << "curve " << c;
    }
  }
}

TEST(MatchGrid, SameCostsForAnyThreadCount) {
  const MotionGraph& m = small_machine();
  const CurveSet cs = random_curves(10, 4);
  std::vector<std::vector<float>> costs;
  for (int threads : {1, 2, 3}) {
    ScopedExecution scope(Backend::Cpu, threads);
    MatchGrid grid(m, cs);
    grid.match();
    costs.push_back(grid.cost());
  }
  EXPECT_EQ(costs[0], costs[1]);
  EXPECT_EQ(costs[0], costs[2]);
}

TEST(MatchGrid, AMotionsOwnTrajectoryMatchesItself) {
  const MotionGraph& m = small_machine();
  for (std::int32_t id : m.locomotion_segments()) {
    const MotionSegment& seg = m.segments()[static_cast<std::size_t>(id)];
    // The trajectory, rotated and moved, then resampled again.
    std::vector<glm::vec2> pts;
    for (glm::vec2 q : seg.trajectory) pts.push_back(glm::vec2(3, -2) + glm::vec2(-q.y, q.x));  // +90 degrees
    pts.push_back(glm::vec2(3, -2) + glm::vec2(-seg.end_point.y, seg.end_point.x));
    pts.push_back(pts.back() +
                  0.2f * (pts.back() - pts[pts.size() - 2]) / sim::length_of(pts.back() - pts[pts.size() - 2]));
    ResampleOptions o;
    o.spacing = m.spacing();
    o.max_knot_spacing = 0.1f;
    const ResampledPath rp = resample_path(pts, o);
    const CurveSet cs = cut_paths(std::vector<ResampledPath>{rp}, m);
    ASSERT_GE(cs.curve_count(), 1);
    MatchGrid grid(m, cs);
    grid.match();
    const std::int32_t chosen = m.locomotion_segments()[static_cast<std::size_t>(grid.best()[0])];
    const float own = grid.cost()[static_cast<std::size_t>(
        std::find(m.locomotion_segments().begin(), m.locomotion_segments().end(), id) -
        m.locomotion_segments().begin())];
    EXPECT_LT(own / static_cast<float>(m.k()), 0.01f) << seg.name;  // within 1 cm per point
    // Walking and running straight are the same curve: the same group is enough.
    EXPECT_EQ(m.states()[static_cast<std::size_t>(m.segments()[static_cast<std::size_t>(chosen)].state)].group,
              m.states()[static_cast<std::size_t>(seg.state)].group)
        << seg.name;
  }
}

TEST(MatchGrid, MarkedStretchesOnlyAcceptTheirState) {
  const MotionGraph& m = small_machine();
  const ResampledPath rp = random_path(9, 6, 0.6f, {{2.0f, 6.0f, "run_forward"}});
  const CurveSet cs = cut_paths(std::vector<ResampledPath>{rp}, m);
  MatchGrid grid(m, cs);
  grid.match();
  int marked = 0;
  for (std::int32_t c = 0; c < cs.curve_count(); ++c) {
    if (cs.required_state[static_cast<std::size_t>(c)] < 0) continue;
    ++marked;
    const std::int32_t seg =
        m.locomotion_segments()[static_cast<std::size_t>(grid.best()[static_cast<std::size_t>(c)])];
    EXPECT_EQ(m.segments()[static_cast<std::size_t>(seg)].state, m.state_index("run_forward"));
  }
  EXPECT_GE(marked, 2);
  const ResampledPath bad = random_path(9, 6, 0.6f, {{2.0f, 6.0f, "crawl"}});
  EXPECT_THROW(cut_paths(std::vector<ResampledPath>{bad}, m), Error);
}

// ---- sequences -------------------------------------------------------------------

TEST(Sequences, DpIsLegalOptimalAndBeatsRepairedGreedy) {
  const MotionGraph& m = small_machine();
  // Sharp S-bends: greedy follows a left turn with a right turn.
  std::vector<ResampledPath> ps;
  for (int i = 0; i < 16; ++i) ps.push_back(random_path(700 + static_cast<std::uint64_t>(i), 10, 1.2f));
  const CurveSet cs = cut_paths(ps, m);
  MatchGrid grid(m, cs);
  grid.match();
  const std::vector<float> cost = grid.cost();
  const auto greedy = greedy_sequences(m, cs, cost, grid.best());
  const auto repaired = repaired_greedy_sequences(m, cs, cost);
  const auto dp = dp_sequences(m, cs, cost);
  int greedy_illegal = 0;
  for (std::size_t p = 0; p < ps.size(); ++p) {
    greedy_illegal += greedy[p].illegal;
    EXPECT_EQ(dp[p].illegal, 0) << "path " << p;
    EXPECT_EQ(dp[p].segments.size(), greedy[p].segments.size());
    // Greedy has the least match cost; DP pays for legality.
    EXPECT_LE(greedy[p].match_cost, dp[p].match_cost + 1e-3);
    if (repaired[p].illegal == 0) {
      EXPECT_LE(dp[p].total(), repaired[p].total() + 1e-6 * repaired[p].total()) << "path " << p;
    }
    // Every consecutive pair is an edge of the machine.
    for (std::size_t c = 1; c < dp[p].segments.size(); ++c)
      EXPECT_TRUE(m.allowed(m.segments()[static_cast<std::size_t>(dp[p].segments[c - 1])].state,
                            m.segments()[static_cast<std::size_t>(dp[p].segments[c])].state));
  }
  EXPECT_GT(greedy_illegal, 0) << "these S-bends should trip the greedy choice";
}

TEST(Sequences, SameSequencesForAnyThreadCount) {
  const MotionGraph& m = small_machine();
  const CurveSet cs = random_curves(20, 8);
  MatchGrid grid(m, cs);
  grid.match();
  const std::vector<float> cost = grid.cost();
  std::vector<std::vector<Sequence>> runs;
  for (int threads : {1, 3}) {
    ScopedExecution scope(Backend::Cpu, threads);
    runs.push_back(dp_sequences(m, cs, cost));
  }
  for (std::size_t p = 0; p < runs[0].size(); ++p) {
    EXPECT_EQ(runs[0][p].segments, runs[1][p].segments);
    EXPECT_EQ(runs[0][p].total(), runs[1][p].total());
  }
}

TEST(Sequences, DpEqualsBruteForceOnShortPaths) {
  const MotionGraph& m = small_machine();
  const auto& loco = m.locomotion_segments();
  const auto M = static_cast<std::int32_t>(loco.size());
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    // Three curves: 7^3 sequences.
    ResampledPath rp = random_path(seed, 3, 1.0f);
    const std::size_t keep = static_cast<std::size_t>(3 * m.k());
    ASSERT_GE(rp.points.size(), keep);
    rp.points.resize(keep);
    rp.tangents.resize(keep);
    rp.arc.resize(keep);
    rp.fixed_state.resize(keep);
    const CurveSet cs = cut_paths(std::vector<ResampledPath>{rp}, m);
    ASSERT_EQ(cs.curve_count(), 3);
    MatchGrid grid(m, cs);
    grid.match();
    const std::vector<float> cost = grid.cost();
    auto start_cost = [&](std::int32_t seg) {
      double best = INFINITY;
      for (std::int32_t a : m.states()[static_cast<std::size_t>(m.start_state())].segments)
        best = std::min(best, static_cast<double>(m.transition_cost(a, seg)));
      return best;
    };
    auto end_cost = [&](std::int32_t seg) {
      double best = INFINITY;
      for (std::int32_t b : m.states()[static_cast<std::size_t>(m.end_state())].segments)
        best = std::min(best, static_cast<double>(m.transition_cost(seg, b)));
      return best;
    };
    double optimum = INFINITY;
    for (std::int32_t a = 0; a < M; ++a)
      for (std::int32_t b = 0; b < M; ++b)
        for (std::int32_t c = 0; c < M; ++c) {
          const std::int32_t sa = loco[static_cast<std::size_t>(a)], sb = loco[static_cast<std::size_t>(b)],
                             sc = loco[static_cast<std::size_t>(c)];
          const double total = start_cost(sa) + cost[static_cast<std::size_t>(a)] + m.transition_cost(sa, sb) +
                               cost[static_cast<std::size_t>(M + b)] + m.transition_cost(sb, sc) +
                               cost[static_cast<std::size_t>(2 * M + c)] + end_cost(sc);
          optimum = std::min(optimum, total);
        }
    const auto dp = dp_sequences(m, cs, cost);
    ASSERT_TRUE(std::isfinite(optimum));
    EXPECT_NEAR(dp[0].total(), optimum, 1e-5 * optimum) << "seed " << seed;
  }
}

// ---- playback --------------------------------------------------------------------

TEST(Playback, FollowsThePathAndReportsDeviation) {
  const MotionGraph& m = small_machine();
  std::vector<ResampledPath> ps = {random_path(31, 10, 0.4f)};
  const CurveSet cs = cut_paths(ps, m);
  MatchGrid grid(m, cs);
  grid.match();
  const auto dp = dp_sequences(m, cs, grid.cost());
  const Playback pb = play(m, ps[0], dp[0]);
  // Frames: every segment's duration at the machine's fps.
  double total = 0;
  total += m.segments()[static_cast<std::size_t>(dp[0].start_segment)].duration +
           m.segments()[static_cast<std::size_t>(dp[0].end_segment)].duration;
  for (std::int32_t s : dp[0].segments) total += m.segments()[static_cast<std::size_t>(s)].duration;
  EXPECT_EQ(pb.clip.frame_count, static_cast<std::int32_t>(std::floor(total * m.spec().fps)) + 1);
  EXPECT_GT(pb.matched_frames, 0);
  // The character stays near its path: hips sway a few cm, turns are matched
  // by clips of fixed curvature.
  EXPECT_GT(pb.deviation_mean, 0.0);
  EXPECT_LT(pb.deviation_mean, 0.15);
  EXPECT_LT(pb.deviation_max, 0.5);
  EXPECT_GE(pb.deviation_max, pb.deviation_mean);
  // Continuous: no frame-to-frame jump of the root beyond a running step.
  for (std::size_t f = 1; f < pb.root_ground.size(); ++f)
    EXPECT_LT(sim::length_of(pb.root_ground[f] - pb.root_ground[f - 1]), 0.12f) << f;
  // Starts standing at the first point.
  EXPECT_LT(sim::length_of(pb.root_ground[0] - ps[0].points[0]), 0.1f);
  // The character faces along the path where it walks: yaw = heading + pi/2.
  const std::int32_t f = pb.first_matched_frame + pb.matched_frames / 2;
  const glm::vec3 facing = pb.clip.rotation(f, 0) * glm::vec3(0, 0, 1);
  const glm::vec2 dir = sim::normalize_or(
      pb.root_ground[static_cast<std::size_t>(f) + 5] - pb.root_ground[static_cast<std::size_t>(f) - 5], {1, 0});
  const glm::vec2 face_map = sim::normalize_or(glm::vec2(facing.x, -facing.z), {0, 0});
  EXPECT_GT(sim::dot2(dir, face_map), 0.85f);
}

}  // namespace
}  // namespace throng::path
