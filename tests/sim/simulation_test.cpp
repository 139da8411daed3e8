// Whole-simulation tests: the acceptance runs of the built-in circle (1,000
// agents) and crossing (2,000 agents) under both schedulers, their
// statistical agreement, and bitwise determinism across thread counts.
#include "sim/simulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <numeric>
#include <vector>

#include "core/exec.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "sim/metrics.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// Overlap threshold. Agents are discs of radius 0.25 m (shoulder width
// 0.5 m); the contact constraint removes overlaps over four Jacobi passes
// per step but where a jam presses many agents together a few centimetres
// remain for a step or two. We require:
//   - no two agents ever overlap by more than kOverlapLimit = 8 cm (a third
//     of the radius: well inside how far clothing and bodies give in a
//     dense crowd), and
//   - pairs overlapping by more than kOverlapTolerance = 5 cm are rare: at
//     most 0.5% of the agents at any step.
// Overlaps and penetrations are measured after every step (and at the start).
constexpr float kOverlapLimit = 0.08f;
constexpr float kOverlapTolerance = 0.05f;
constexpr double kDeepPairFraction = 0.005;
constexpr float kPenetrationTolerance = 1e-3f;  // m: float error against walls

struct RunRecord {
  std::int64_t steps = 0;
  bool all_arrived = false;
  std::vector<float> arrival_times;
  float max_overlap_depth = 0.0f;
  Index max_deep_pairs = 0;
  Index max_penetrations = 0;
  Index deep_pair_samples = 0;         // sum over samples (steps) of the pairs deeper than the tolerance
  Index touching_samples = 0;          // sum over samples of the pairs in contact (collisions)
  Index samples = 0;                   // the start and every step
  std::int64_t penetration_steps = 0;  // samples with any agent in an obstacle
};

RunRecord run_to_arrival(const ScenarioSpec& spec, SchedulerKind scheduler, std::int64_t max_steps) {
  ScenarioSpec s = spec;
  s.scheduler = scheduler;
  const std::unique_ptr<Simulation> run = test::as_run(s);
  Simulation& sim = *run;
  RunRecord r;
  auto sample = [&] {
    const CrowdState& c = sim.crowd();
    const OverlapStats o =
        measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), kOverlapTolerance, sim.contact_cell());
    r.max_overlap_depth = std::max(r.max_overlap_depth, o.max_depth);
    r.max_deep_pairs = std::max(r.max_deep_pairs, o.pairs);
    r.deep_pair_samples += o.pairs;
    r.touching_samples += o.touching;
    ++r.samples;
    const Index penetrations = count_obstacle_penetrations(sim.world(), c.position.span(), c.radius.span(),
                                                           c.flags.span(), kPenetrationTolerance);
    r.max_penetrations = std::max(r.max_penetrations, penetrations);
    r.penetration_steps += penetrations > 0 ? 1 : 0;
  };
  sample();
  while (!sim.all_arrived() && r.steps < max_steps) {
    sim.step();
    ++r.steps;
    sample();
  }
  r.all_arrived = sim.all_arrived();
  r.arrival_times = sim.arrival_times();
  return r;
}

double mean(const std::vector<float>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

// Two-sample Kolmogorov-Smirnov statistic: the largest gap between the
// empirical distributions.
double ks_statistic(std::vector<float> a, std::vector<float> b) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  double d = 0;
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const float x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] <= x) ++i;
    while (j < b.size() && b[j] <= x) ++j;
    d = std::max(d, std::fabs(static_cast<double>(i) / static_cast<double>(a.size()) -
                              static_cast<double>(j) / static_cast<double>(b.size())));
  }
  return d;
}

void expect_acceptance(const RunRecord& r, Index agents, const char* what) {
  SCOPED_TRACE(what);
  EXPECT_TRUE(r.all_arrived) << "after " << r.steps << " steps";
  EXPECT_EQ(std::count_if(r.arrival_times.begin(), r.arrival_times.end(), [](float t) { return t >= 0.0f; }), agents);
  EXPECT_EQ(r.max_penetrations, 0) << "in " << r.penetration_steps << " steps";
  EXPECT_EQ(r.samples, r.steps + 1);  // the start and every step were measured
  EXPECT_LT(r.max_overlap_depth, kOverlapLimit);
  EXPECT_LE(static_cast<double>(r.max_deep_pairs), kDeepPairFraction * static_cast<double>(agents));
}

// Both schedulers run the same model; their order of updates differs, so
// trajectories differ, but the crowd-level outcome must agree: means of the
// arrival times within `mean_share` of the larger, collisions (pairs in
// contact, per sample) within a factor of two, and where
// `same_distribution`, the arrival-time distributions close (two-sample KS
// statistic below 0.15).
void expect_schedulers_agree(const RunRecord& a, const RunRecord& b, double mean_share, bool same_distribution) {
  const double ma = mean(a.arrival_times), mb = mean(b.arrival_times);
  const double ks = ks_statistic(a.arrival_times, b.arrival_times);
  const double ca = static_cast<double>(a.touching_samples) / static_cast<double>(std::max<Index>(1, a.samples));
  const double cb = static_cast<double>(b.touching_samples) / static_cast<double>(std::max<Index>(1, b.samples));
  std::printf("  mean arrival: double buffer %.1f s, four colour %.1f s; KS statistic %.3f; steps %lld / %lld\n", ma,
              mb, ks, static_cast<long long>(a.steps), static_cast<long long>(b.steps));
  std::printf("  pairs in contact per sample %.2f / %.2f; deepest overlap %.3f / %.3f m\n", ca, cb, a.max_overlap_depth,
              b.max_overlap_depth);
  EXPECT_LT(std::fabs(ma - mb), mean_share * std::max(ma, mb));
  if (same_distribution) {
    EXPECT_LT(ks, 0.15);
  }
  EXPECT_LE(ca, 2.0 * cb + 1.0);
  EXPECT_LE(cb, 2.0 * ca + 1.0);
}

// The acceptance sizes (1,000 and 2,000 agents), one test per scheduler.
// Under the sanitizers (CI sets THRONG_SANITIZED; everything runs several
// times slower) the same scenarios run with 300 and 600 agents: the code
// paths are the same, only the jam is smaller.
void acceptance(const char* name, Index agents, Index sanitized_agents, SchedulerKind scheduler) {
  const Index n = test::sanitized() ? sanitized_agents : agents;
  const ScenarioSpec spec = test::builtin(name, n);
  ASSERT_EQ(spec.total_agents(), n);
  const RunRecord r = run_to_arrival(spec, scheduler, spec.step_count());
  std::printf(
      "  %s, %lld agents, %s: %lld steps, mean arrival %.1f s, deepest overlap %.3f m, pairs deeper than %.2f m at "
      "most %lld\n",
      name, static_cast<long long>(n), to_string(scheduler), static_cast<long long>(r.steps), mean(r.arrival_times),
      r.max_overlap_depth, static_cast<double>(kOverlapTolerance), static_cast<long long>(r.max_deep_pairs));
  expect_acceptance(r, n, to_string(scheduler));
}

TEST(Acceptance, CircleThousandAgentsDoubleBuffer) { acceptance("circle", 1000, 300, SchedulerKind::DoubleBuffer); }
TEST(Acceptance, CircleThousandAgentsFourColour) { acceptance("circle", 1000, 300, SchedulerKind::FourColour); }
TEST(Acceptance, CrossingTwoThousandAgentsDoubleBuffer) {
  acceptance("crossing", 2000, 600, SchedulerKind::DoubleBuffer);
}
TEST(Acceptance, CrossingTwoThousandAgentsFourColour) { acceptance("crossing", 2000, 600, SchedulerKind::FourColour); }

// A crowd pressed into a corner it cannot reach, found by the structure-
// aware scenario fuzzer: 37 agents walk straight at (0, 0), behind a thin
// wedge in the corner of a small room. Agents the crowd squeezed into the
// wedge's sharp angle used to be sent back to where they stood after the
// contact passes (a position too close to a wall is rejected), onto the
// neighbours that had made room: 8.3 cm overlaps at step 41. The passes
// now reject such a position themselves, so neighbours are pushed from
// where the agent stays. Every step, both schedulers: within the bound.
constexpr const char* kCornerJam = R"(
seed: 446
dt: 0.1
planning: none
model: {type: priority, max_speed: 1.25, personal_space: 0.3, probe_margin: 0}
world:
  walkable: {rect: {min: [0, 0], max: [4.35, 8.45]}}
  obstacles:
    - {polygon: [[2.35, 5.43], [0.65, 5.80], [1.68, 4.40]]}
    - {rect: {min: [4.15, 5.8], max: [4.35, 8.45]}}
    - {polygon: [[0.71, 0.77], [0.06, 0.22], [-0.42, -1.83]]}
    - {polygon: [[5.51, 4.17], [3.67, 3.32], [2.62, 2.60], [2.26, 1.11], [3.41, 0.85], [4.87, 0.26]]}
    - {rect: {min: [3.8, 5.15], max: [4.1, 8.45]}}
    - {circle: {center: [3.8, 2.25], radius: 1.95}}
groups:
  - {count: 37, radius: 0.25, spawn: {rect: {min: [0.8, 0.85], max: [4.35, 6.95]}}, goal: {point: [0, 0]}}
)";

TEST(Contacts, ACrowdPressedIntoASharpCornerKeepsTheOverlapBound) {
  const ScenarioSpec spec = io::parse_scenario(kCornerJam, "corner_jam").spec;
  for (const SchedulerKind scheduler : {SchedulerKind::DoubleBuffer, SchedulerKind::FourColour}) {
    const RunRecord r = run_to_arrival(spec, scheduler, 600);
    std::printf("  corner jam, %s: %lld steps, deepest overlap %.3f m\n", to_string(scheduler),
                static_cast<long long>(r.steps), r.max_overlap_depth);
    EXPECT_FALSE(r.all_arrived) << to_string(scheduler);  // the goal lies inside the wedge: the crowd stays pressed
    EXPECT_EQ(r.max_penetrations, 0) << to_string(scheduler);
    EXPECT_LT(r.max_overlap_depth, kOverlapLimit) << to_string(scheduler);
  }
}

// The extra contact passes, counted: agents apart take the fixed passes
// only; a crowd squeezed into an n x n lattice closer than the discs' 0.5 m
// takes more. A 5 x 5 squeeze at 0.42 m (8 cm overlaps) settles below the
// tolerance before the cap; an 8 x 8 one at 0.44 m is still deeper at the
// cap (each agent moves at most 0.9 radius a step, and the Jacobi passes
// converge slowly over many rows) but shallower than after the fixed passes.
struct SqueezeResult {
  std::int32_t passes = 0;
  float deepest = 0.0f;  // m, after the step
};
SqueezeResult squeeze_one_step(SchedulerKind scheduler, int side, float spacing, std::int32_t extra) {
  const Index n = side * side;
  ScenarioSpec spec = test::open_field(n, glm::vec2(0.0f), glm::vec2(8.0f), glm::vec2(50.0f, 0.0f));
  spec.scheduler = scheduler;
  // The priority model walks on at the goal whatever the overlaps, so the
  // passes alone undo the squeeze (the collision-free speed model's
  // repulsion would help them).
  spec.model.kind = ModelKind::Priority;
  spec.model.contact_extra_iterations = extra;
  Simulation sim(spec);
  Span<glm::vec2> p = sim.crowd().position.span();
  for (Index i = 0; i < n; ++i)
    p[i] = glm::vec2(spacing * static_cast<float>(i % side), spacing * static_cast<float>(i / side));
  sim.step();
  const CrowdState& c = sim.crowd();
  return {sim.last_contact_passes(),
          measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), 0.0f, sim.contact_cell()).max_depth};
}

TEST(Contacts, ExtraPassesRunWhileAPairIsDeeperThanTheTolerance) {
  const ModelParams d;
  for (const SchedulerKind scheduler : {SchedulerKind::DoubleBuffer, SchedulerKind::FourColour}) {
    SCOPED_TRACE(to_string(scheduler));
    // Apart, the double buffer stops after a pass that moved nobody.
    const SqueezeResult apart = squeeze_one_step(scheduler, 8, 0.6f, d.contact_extra_iterations);
    EXPECT_EQ(apart.passes, scheduler == SchedulerKind::DoubleBuffer ? 1 : d.contact_iterations);
    EXPECT_EQ(apart.deepest, 0.0f);

    const SqueezeResult small = squeeze_one_step(scheduler, 5, 0.42f, d.contact_extra_iterations);
    EXPECT_GT(small.passes, d.contact_iterations);
    EXPECT_LT(small.passes, d.contact_iterations + d.contact_extra_iterations);
    EXPECT_LE(small.deepest, d.contact_tolerance);

    const SqueezeResult fixed = squeeze_one_step(scheduler, 8, 0.44f, 0);
    const SqueezeResult extra = squeeze_one_step(scheduler, 8, 0.44f, d.contact_extra_iterations);
    std::printf("  %s: 5 x 5 squeeze %d passes, %.4f m; 8 x 8: %d passes, %.4f m, with the extra passes %d, %.4f m\n",
                to_string(scheduler), small.passes, small.deepest, fixed.passes, fixed.deepest, extra.passes,
                extra.deepest);
    EXPECT_EQ(fixed.passes, d.contact_iterations);
    EXPECT_EQ(extra.passes, d.contact_iterations + d.contact_extra_iterations);
    EXPECT_GT(fixed.deepest, d.contact_tolerance);
    EXPECT_LT(extra.deepest, 0.8f * fixed.deepest);
  }
}

// Both schedulers on the same scenario (the circle with 400 agents, 200
// under the sanitizers: a dense jam in a few hundred steps; arrival times
// of several seeds pooled): the statistics agree. Under the priority model
// (three seeds) the whole distribution, means within 10%. Under the
// collision-free speed model (the default) the means only, and not within
// 10%: in its jam the double buffer, where everyone moves on the last
// step's positions, is systematically slower than the four colours. Over
// seeds 1-30 through `throng run circle --agents 400` the per-seed means
// averaged 167.9 s (sd 9.7) against 153.7 s (sd 10.3), 9% apart (200
// agents: 6%); three seeds pooled came out 1-18% apart, so the test pools
// ten (seeds 1-10: 167.4 s against 151.5 s, 9.5%) and allows 15%.
TEST(Schedulers, ArrivalTimesAndCollisionsAgreeStatistically) {
  for (const ModelKind model : {ModelKind::Priority, ModelKind::CollisionFreeSpeed}) {
    SCOPED_TRACE(to_string(model));
    const bool priority = model == ModelKind::Priority;
    const Index agents = test::sanitized() ? 200 : 400;
    const std::uint64_t seeds = priority || test::sanitized() ? 3 : 10;
    RunRecord db, fc;
    for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
      ScenarioSpec spec = test::builtin("circle", agents);
      spec.model.kind = model;
      spec.seed = seed;
      for (auto [scheduler, pooled] :
           {std::pair{SchedulerKind::DoubleBuffer, &db}, std::pair{SchedulerKind::FourColour, &fc}}) {
        const RunRecord r = run_to_arrival(spec, scheduler, spec.step_count());
        expect_acceptance(r, agents, to_string(scheduler));
        pooled->arrival_times.insert(pooled->arrival_times.end(), r.arrival_times.begin(), r.arrival_times.end());
        pooled->steps += r.steps;
        pooled->max_overlap_depth = std::max(pooled->max_overlap_depth, r.max_overlap_depth);
        pooled->deep_pair_samples += r.deep_pair_samples;
        pooled->touching_samples += r.touching_samples;
        pooled->samples += r.samples;
      }
    }
    expect_schedulers_agree(db, fc, priority ? 0.1 : 0.15, priority);
  }
}

// ---- determinism ---------------------------------------------------------------

struct Snapshot {
  std::vector<glm::vec2> position, velocity;
  std::vector<float> heading, arrival;
  std::vector<std::uint8_t> flags;
};

Snapshot run_steps(const ScenarioSpec& spec, SchedulerKind scheduler, int threads, std::int64_t steps,
                   const SimulationOptions& options = {}) {
  ScopedExecution exec(Backend::Cpu, threads);
  ScenarioSpec s = spec;
  s.scheduler = scheduler;
  const std::unique_ptr<Simulation> sim = test::as_run(s, options);
  sim->run(steps);
  return {sim->positions(), sim->velocities(), sim->headings(), sim->arrival_times(), sim->flags()};
}

void expect_identical(const Snapshot& a, const Snapshot& b, int threads) {
  EXPECT_TRUE(test::same_bits(a.position, b.position)) << threads << " threads";
  EXPECT_TRUE(test::same_bits(a.velocity, b.velocity)) << threads << " threads";
  EXPECT_TRUE(test::same_bits(a.heading, b.heading)) << threads << " threads";
  EXPECT_TRUE(test::same_bits(a.arrival, b.arrival)) << threads << " threads";
  EXPECT_TRUE(test::same_bits(a.flags, b.flags)) << threads << " threads";
}

// Calls fn(spec, steps) for every model on each built-in scene (name,
// agents, steps): a third of the agents under the sanitizers.
struct Scene {
  const char* name;
  std::int64_t agents, steps;
};
template <class Fn>
void for_each_model_and_scene(std::initializer_list<Scene> scenes, const Fn& fn) {
  for (const ModelKind model :
       {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc, ModelKind::SocialForce})
    for (const Scene& scene : scenes) {
      SCOPED_TRACE(std::string(scene.name) + ", " + to_string(model));
      ScenarioSpec spec = test::builtin(scene.name, test::sanitized() ? scene.agents / 3 : scene.agents);
      spec.model.kind = model;
      fn(spec, scene.steps);
    }
}

// Dense scenes with walls, doors, arrivals and despawns: the bottleneck room
// and the crossroads (agents meet within the steps run); a third of the
// agents under the sanitizers, and there one thread against four only (the
// slowest test of that run; every count is compared in the plain build).
// Every model.
TEST(Determinism, DoubleBufferIsBitwiseTheSameForOneTwoAndFourThreads) {
  const std::vector<int> threads = test::sanitized() ? std::vector<int>{4} : std::vector<int>{2, 4};
  for_each_model_and_scene({{"bottleneck", 300, 400}, {"crossing", 1200, 500}},
                           [&](const ScenarioSpec& spec, std::int64_t steps) {
                             const Snapshot one = run_steps(spec, SchedulerKind::DoubleBuffer, 1, steps);
                             for (int t : threads)
                               expect_identical(one, run_steps(spec, SchedulerKind::DoubleBuffer, t, steps), t);
                             // And the crowd actually moved.
                             EXPECT_FALSE(test::same_bits(one.position, Simulation(spec).positions()));
                           });
}

// The four-colour batches never let two cells of a batch touch the same
// agents, so they too are independent of the thread count (every model).
TEST(Determinism, FourColourIsBitwiseTheSameForOneTwoAndFourThreads) {
  for (const ModelKind model :
       {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc, ModelKind::SocialForce}) {
    SCOPED_TRACE(to_string(model));
    ScenarioSpec spec = test::builtin("bottleneck", 300);
    spec.model.kind = model;
    const Snapshot one = run_steps(spec, SchedulerKind::FourColour, 1, 400);
    for (int t : {2, 4}) expect_identical(one, run_steps(spec, SchedulerKind::FourColour, t, 400), t);
  }
}

// Four shortcuts that must change no bit, against their reference forms:
// dense bins (a box of cells indexed directly) against hashed ones, and
// bins counted by slot range against atomics and a sort; the
// double buffer's contact passes ending at the first that moved nobody
// and passing over agents whose move cells the pass before left still
// against every pass run by every agent; and the collision-free speed
// model's far look passing over cells whose agents all walk the agent's
// way against looking through every cell. The bottleneck's bins are dense and its jam needs
// every pass; the circle's contact bins are hashed (a ring 100 m across in
// cells of 1 m) and most of its steps move nobody in their second pass;
// the bottleneck's crowd streams to its door.
TEST(Determinism, StepShortcutsChangeNoBit) {
  SimulationOptions reference;
  reference.dense_bins = false;
  reference.bin_counting = BinCounting::Atomic;
  reference.skip_idle_contact_passes = false;
  reference.skip_far_cells_walking_along = false;
  for_each_model_and_scene(
      {{"bottleneck", 300, 300}, {"circle", 300, 300}}, [&](const ScenarioSpec& spec, std::int64_t steps) {
        for (const SchedulerKind scheduler : {SchedulerKind::DoubleBuffer, SchedulerKind::FourColour})
          expect_identical(run_steps(spec, scheduler, 2, steps), run_steps(spec, scheduler, 2, steps, reference), 2);
      });
  // The shortcuts were taken: the circle's steering bins are dense, and a
  // step of agents walking apart ends its contact passes after the first.
  ScenarioSpec spec = test::builtin("circle", 300);
  Simulation sim(spec), full(spec, reference);
  sim.run(5);
  full.run(5);
  EXPECT_TRUE(sim.bins().dense());
  EXPECT_FALSE(full.bins().dense());
  EXPECT_EQ(sim.last_contact_passes(), 1);
  EXPECT_EQ(full.last_contact_passes(), spec.model.contact_iterations);
  // (the circle's default model is the collision-free speed model)
  ASSERT_EQ(spec.model.kind, ModelKind::CollisionFreeSpeed);
  EXPECT_GT(sim.far_cells_summarised(), 0);
  EXPECT_EQ(full.far_cells_summarised(), 0);
}

// Agents of radius 0.25 m at `start` (flags: `state`) in an open world,
// binned in contact cells of 1 m, with their move cells: what the move
// stage's passes read, their anchors and positions both `start`.
struct ContactScene {
  World world = World::build(WorldSpec{}, 1.0f);
  Memory mem = current_memory();
  Buffer<glm::vec2> anchor, position;
  Buffer<float> radius;
  Buffer<std::uint8_t> flags;
  AgentGrid bins{1.0f};
  StepContext ctx;
  AgentArrays a;
  Buffer<MoveCells> cells;
  ContactScene(const std::vector<glm::vec2>& start, const std::vector<std::uint8_t>& state)
      : anchor(std::span<const glm::vec2>(start), mem),
        position(std::span<const glm::vec2>(start), mem),
        radius(std::span<const float>(std::vector<float>(start.size(), 0.25f)), mem),
        flags(std::span<const std::uint8_t>(state), mem),
        cells(static_cast<Index>(start.size()), mem) {
    bins.rebuild(anchor.span(), flags.span());
    ctx.world = world.view();
    ctx.contact_bins = bins.view();
    a.position = position.span();  // sets the agent count
    a.radius = radius.span();
    a.flags = flags.span();
    move_cells(ctx, anchor.span(), cells.span());
  }
  ContactScene(const ContactScene&) = delete;  // ctx and a point into the scene
  ContactScene& operator=(const ContactScene&) = delete;
};

// The contact passes' other shortcut at the kernel: past the first pass an
// agent none of whose move cells holds an agent the pass before moved keeps
// its input, unlooked. Two overlapping pairs far apart and a lone agent:
// the count of moved agents is checked against a plain count, the pass
// after gives with it what it gives without, bit for bit, and a count
// claiming nobody moved leaves even overlapping pairs where they are (so
// the count is what decides).
TEST(ContactPasses, AgentsWhoseMoveCellsStayedStillAreNotLookedAtAgain) {
  const std::vector<glm::vec2> start = {{0.0f, 0.0f}, {0.3f, 0.05f}, {20.0f, 0.0f}, {20.35f, 0.0f}, {40.0f, 0.0f}};
  const Index n = static_cast<Index>(start.size());
  const ContactScene scene(start, std::vector<std::uint8_t>(start.size(), kAgentActive));
  const Memory mem = scene.mem;
  const Buffer<glm::vec2>& anchor = scene.anchor;  // (a pass reads only its input)
  const StepContext& ctx = scene.ctx;
  const AgentArrays& a = scene.a;
  const Buffer<MoveCells>& cells = scene.cells;
  auto pass = [&](const Buffer<glm::vec2>& in, Span<const std::int32_t> moved_before, std::vector<float>* depths) {
    Buffer<glm::vec2> out(n, mem);
    Buffer<float> depth = Buffer<float>::zeros(n, mem);
    contacts_double_buffer(ctx, a, anchor.span(), cells.span(), in.span(), out.span(), depth.span(), moved_before);
    if (depths != nullptr) *depths = depth.to_vector();
    return out;
  };
  const Buffer<glm::vec2> first = pass(anchor, {}, nullptr);
  Buffer<std::int32_t> moved_before(n + 1, mem);
  const Index moved = mark_moved_items(ctx.contact_bins, anchor.span(), first.span(), moved_before.span());
  const std::vector<glm::vec2> p0 = anchor.to_vector(), p1 = first.to_vector();
  Index counted = 0;
  for (Index i = 0; i < n; ++i) counted += test::same_bits(std::vector{p0[i]}, std::vector{p1[i]}) ? 0 : 1;
  EXPECT_EQ(moved, 4);  // both pairs; the lone agent stays
  EXPECT_EQ(moved, counted);
  std::vector<float> depth_with, depth_without;
  const Buffer<glm::vec2> with = pass(first, moved_before.span(), &depth_with);
  const Buffer<glm::vec2> without = pass(first, {}, &depth_without);
  EXPECT_TRUE(test::same_bits(with.to_vector(), without.to_vector()));
  EXPECT_TRUE(test::same_bits(depth_with, depth_without));
  // Told that nobody moved, a pass leaves the overlapping start as it is.
  const std::vector<std::int32_t> none(static_cast<std::size_t>(n + 1), 0);
  const Buffer<std::int32_t> still(std::span<const std::int32_t>(none), mem);
  EXPECT_TRUE(test::same_bits(pass(anchor, still.span(), nullptr).to_vector(), p0));
  EXPECT_FALSE(test::same_bits(pass(anchor, {}, nullptr).to_vector(), p0));
}

// The deepest contact counts the agents active now. The four-colour pass
// visits only binned (active) agents, so an agent that left the crowd keeps
// the depth of its last pass: here a stale 5 m. An overlapping pair and
// that agent: the deepest is the pair's overlap.
TEST(ContactPasses, TheDeepestContactIsAmongTheActiveAgentsOnly) {
  const std::vector<glm::vec2> start = {{0.0f, 0.0f}, {0.3f, 0.05f}, {20.0f, 0.0f}};
  ContactScene scene(start, {kAgentActive, kAgentActive, 0});  // (the four colours move scene.position)
  const std::vector<float> stale = {0.0f, 0.0f, 5.0f};
  Buffer<float> depth(std::span<const float>(stale), scene.mem);
  contacts_four_colour(scene.ctx, scene.a, scene.anchor.span(), scene.cells.span(), depth.span());
  EXPECT_FLOAT_EQ(depth.to_vector()[2], 5.0f);  // not visited
  const float overlap = 0.5f - glm::length(start[1] - start[0]);
  EXPECT_NEAR(deepest_contact(depth.span(), scene.flags.span()), overlap, 1e-6f);
}

// The step counts what its kernels move (count_traffic) under the names it
// times them by, each launch anew: the pass that copies positions moves two
// arrays of every agent's position, the move cells' pass the anchors and
// the cells.
TEST(Simulation, AStepCountsTheMemoryItsKernelsMove) {
  ScenarioSpec spec = test::open_field(400, {0, 0}, {200, 200}, {5, 0});
  Simulation sim(spec);
  sim.step();
  auto& t = KernelTimings::global();
  t.reset();
  sim.step();
  const std::int64_t n = sim.agent_count();
  ASSERT_EQ(sim.last_contact_passes(), 1);
  const auto bytes = [&](const char* name) {
    for (const KernelStat& k : t.stats())
      if (k.name == name) return k.bytes;
    return std::int64_t{-1};
  };
  EXPECT_EQ(bytes("sim.move.copy"), 2 * n * 8);
  EXPECT_EQ(bytes("sim.move.cells"), n * 8 + n * static_cast<std::int64_t>(sizeof(MoveCells)));
  const std::int64_t one = t.bytes_under("sim.");
  EXPECT_GT(one, 100 * n);  // hundreds of bytes per agent-step
  sim.step();
  EXPECT_EQ(bytes("sim.move.copy"), 4 * n * 8);
  EXPECT_GT(t.bytes_under("sim."), one + 100 * n);
}

// The bins against the O(N^2) reference under the priority model: the same
// neighbours, so the same forces and the same trajectories, bit for bit
// (ties in urgency, where the visiting order could matter, do not occur in
// these scenes).
TEST(Bins, SimulationWithBinsMatchesTheAllPairsReference) {
  for (const auto& [name, agents] : {std::pair{"crossing", 800}, std::pair{"circle", 300}}) {
    SCOPED_TRACE(name);
    ScenarioSpec spec = test::builtin(name, test::sanitized() ? agents / 3 : agents);
    spec.model.kind = ModelKind::Priority;
    SimulationOptions reference;
    reference.neighbours = NeighbourSearch::AllPairs;
    Simulation binned(spec), all_pairs(spec, reference);
    binned.run(400);
    all_pairs.run(400);
    EXPECT_TRUE(test::same_bits(binned.positions(), all_pairs.positions()));
    EXPECT_TRUE(test::same_bits(binned.velocities(), all_pairs.velocities()));
  }
}

// The collision-free speed, time-to-collision and social force models sum over their
// neighbours, so the bins' visiting order changes the last bits and
// trajectories drift apart over many steps; one step from the same state
// must agree to float rounding.
TEST(Bins, SummingModelsStepMatchesTheAllPairsReference) {
  for (const ModelKind model : {ModelKind::CollisionFreeSpeed, ModelKind::Ttc, ModelKind::SocialForce})
    for (const auto& [name, agents] : {std::pair{"crossing", 800}, std::pair{"bottleneck", 300}}) {
      SCOPED_TRACE(std::string(name) + ", " + to_string(model));
      ScenarioSpec spec = test::builtin(name, test::sanitized() ? agents / 3 : agents);
      spec.model.kind = model;
      SimulationOptions reference;
      reference.neighbours = NeighbourSearch::AllPairs;
      Simulation binned(spec), all_pairs(spec, reference);
      binned.run(100);  // into the jam, then one step of each from the same state
      test::copy_step_state(all_pairs.crowd(), binned.crowd());
      binned.step();
      all_pairs.step();
      const auto a = binned.velocities(), b = all_pairs.velocities();
      ASSERT_EQ(a.size(), b.size());
      float worst = 0.0f;
      Index moving = 0;
      for (std::size_t i = 0; i < a.size(); ++i) {
        worst = std::max(worst, std::max(std::fabs(a[i].x - b[i].x), std::fabs(a[i].y - b[i].y)));
        moving += glm::length(a[i]) > 0.1f ? 1 : 0;
      }
      EXPECT_LT(worst, 1e-4f);
      EXPECT_GT(moving, static_cast<Index>(a.size()) / 4);
    }
}

TEST(Simulation, DifferentSeedsGiveDifferentCrowdsSameSeedTheSame) {
  ScenarioSpec a = test::builtin("bottleneck", 100);
  ScenarioSpec b = a;
  b.seed = a.seed + 1;
  Simulation sa(a), sa2(a), sb(b);
  EXPECT_TRUE(test::same_bits(sa.positions(), sa2.positions()));
  EXPECT_FALSE(test::same_bits(sa.positions(), sb.positions()));
}

TEST(Simulation, StoppedAgentsStayAndDespawnedAgentsLeave) {
  // Circle agents stop at their goals; crossing agents despawn.
  ScenarioSpec circle = test::builtin("circle", 40);
  Simulation sc(circle);
  while (!sc.all_arrived() && sc.steps_done() < 2000) sc.step();
  ASSERT_TRUE(sc.all_arrived());
  EXPECT_EQ(sc.active_count(), 40);
  const auto before = sc.positions();
  sc.run(20);
  EXPECT_TRUE(test::same_bits(before, sc.positions()));  // nobody pushes them: all stand apart
  for (const glm::vec2 v : sc.velocities()) EXPECT_EQ(v, glm::vec2(0.0f));

  const std::unique_ptr<Simulation> sx = test::as_run(test::builtin("crossing", 40));
  while (!sx->all_arrived() && sx->steps_done() < 3000) sx->step();
  ASSERT_TRUE(sx->all_arrived());
  EXPECT_EQ(sx->active_count(), 0);
}

}  // namespace
}  // namespace throng::sim
