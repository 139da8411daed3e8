// The collision-free speed model: its terms against closed forms, then
// small encounters run through the whole simulation (head-on, crossing,
// blind corner, four ways, a circle), each agent arriving within 1.5x its
// unhindered time without overlapping a neighbour by more than 1 cm.
#include "sim/collision_free_speed.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "encounters.h"
#include "sim/sense.h"
#include "sim/simulation.h"
#include "sim/world.h"

namespace throng::sim {
namespace {

constexpr float kEps = 1e-5f;
const CollisionFreeSpeedParams kParams{};

TEST(CollisionFreeSpeed, SpeedKeepsTheTimeGapWithinZeroAndTheFreeSpeed) {
  EXPECT_FLOAT_EQ(cfs_speed(INFINITY, 1.3f, 0.75f), 1.3f);
  EXPECT_FLOAT_EQ(cfs_speed(0.3f, 1.3f, 0.75f), 0.4f);
  EXPECT_FLOAT_EQ(cfs_speed(-0.1f, 1.3f, 0.75f), 0.0f);
  EXPECT_FLOAT_EQ(cfs_speed(2.0f, 1.3f, 1.0f), 1.3f);
}

TEST(CollisionFreeSpeed, GapCountsOnlyNeighboursInFrontInsideTheBodyCorridor) {
  const glm::vec2 east(1.0f, 0.0f);
  EXPECT_NEAR(cfs_gap_ahead({0, 0}, 0.2f, east, {1.0f, 0.0f}, 0.2f), 0.6f, kEps);  // dead ahead
  EXPECT_NEAR(cfs_gap_ahead({0, 0}, 0.2f, east, {1.0f, 0.39f}, 0.2f), std::hypot(1.0f, 0.39f) - 0.4f, kEps);  // grazing
  EXPECT_TRUE(std::isinf(cfs_gap_ahead({0, 0}, 0.2f, east, {1.0f, 0.41f}, 0.2f)));  // passes beside
  EXPECT_TRUE(std::isinf(cfs_gap_ahead({0, 0}, 0.2f, east, {-1.0f, 0.0f}, 0.2f)));  // behind
}

TEST(CollisionFreeSpeed, RepulsionIsTheStrengthAtContactAndDecaysOverItsRange) {
  const CfsAgent me{
      {0.0f, 0.0f}, {0.0f, 0.0f}, 0.2f, {0.0f, 1.0f}};  // walking north: no anticipation of a neighbour east
  const glm::vec2 at_contact = cfs_neighbour_push(me, {0.4f, 0.0f}, {0.0f, 0.0f}, 0.2f, false, kParams);
  EXPECT_NEAR(at_contact.x, -kParams.neighbour_strength, 1e-4f);
  EXPECT_NEAR(at_contact.y, 0.0f, kEps);
  const glm::vec2 one_range = cfs_neighbour_push(me, {0.5f, 0.0f}, {0.0f, 0.0f}, 0.2f, false, kParams);
  EXPECT_NEAR(one_range.x, -kParams.neighbour_strength * std::exp(-1.0f), 1e-4f);
  // The wall: strength b at contact, pointing away from the wall.
  const glm::vec2 wall = cfs_wall_push(me, {0.0f, -0.2f}, kParams);
  EXPECT_NEAR(wall.y, kParams.wall_strength, 1e-4f);
  EXPECT_NEAR(wall.x, 0.0f, kEps);
}

TEST(CollisionFreeSpeed, OncomingNeighboursArePassedOnTheRightAndFollowersAreNotDodged) {
  const CfsAgent me{{0.0f, 0.0f}, {1.3f, 0.0f}, 0.2f, {1.0f, 0.0f}};
  // Head-on, 1.6 m apart, closing at 2.6 m/s: 0.46 s to contact.
  const glm::vec2 head_on = cfs_neighbour_push(me, {1.6f, 0.0f}, {-1.3f, 0.0f}, 0.2f, false, kParams);
  const float tau = 1.2f / 2.6f;
  EXPECT_NEAR(head_on.y, -kParams.avoid_strength * (1.0f - tau / kParams.avoid_time), 1e-4f);  // to the right
  // Oncoming slightly to our right: we go left.
  EXPECT_GT(cfs_neighbour_push(me, {1.6f, -0.2f}, {-1.3f, 0.0f}, 0.2f, false, kParams).y, 0.0f);
  // A slower walker ahead in our direction: no sideways push at all.
  EXPECT_NEAR(cfs_neighbour_push(me, {1.6f, 0.0f}, {0.5f, 0.0f}, 0.2f, false, kParams).y, 0.0f, kEps);
  // Someone parked at their goal ahead: passed like an oncoming walker.
  EXPECT_LT(cfs_neighbour_push(me, {1.6f, 0.0f}, {0.0f, 0.0f}, 0.2f, true, kParams).y, 0.0f);
  // One of our own stream merging into our line from ahead on the left
  // (closing in, but walking our way): repelled, not dodged.
  const glm::vec2 merging(0.3f, 0.6f);
  const float dist = std::hypot(merging.x, merging.y);
  const float repulsion = kParams.neighbour_strength * std::exp((0.4f - dist) / kParams.neighbour_range);
  EXPECT_NEAR(cfs_neighbour_push(me, merging, {1.0f, -0.8f}, 0.2f, false, kParams).y, -repulsion * merging.y / dist,
              1e-4f);
}

TEST(CollisionFreeSpeed, CrossersArePassedBehindWhereTheyWillBe) {
  const CfsAgent me{{0.0f, 0.0f}, {1.3f, 0.0f}, 0.2f, {1.0f, 0.0f}};
  // A crosser ahead and 0.3 m to our right, walking north (to our left):
  // judged by where it is, we would dodge left, in front of it. Closing
  // speed along the line between us: (1.3, 1.3) . (1, -0.3)/|.|, gap to
  // contact |(1, -0.3)| - 0.4; it will be 1.3 tau further left, so it counts
  // as on our left and we turn right, behind it.
  const glm::vec2 d(1.0f, -0.3f), w(0.0f, 1.3f);
  const float dist = std::hypot(d.x, d.y), closing = (1.3f * d.x - 1.3f * d.y) / dist;
  const float tau = (dist - 0.4f) / closing, lateral = d.y + 1.3f * tau, band = 0.4f + kParams.side_margin;
  ASSERT_GT(lateral, 0.01f);
  ASSERT_LT(lateral, band);
  const glm::vec2 f = cfs_neighbour_push(me, d, w, 0.2f, false, kParams);
  const float repulsion = kParams.neighbour_strength * std::exp((0.4f - dist) / kParams.neighbour_range);
  const float push = kParams.avoid_strength * (1.0f - tau / kParams.avoid_time) * (1.0f - lateral / band);
  EXPECT_NEAR(f.y, -repulsion * d.y / dist - push, 1e-4f);  // to the right
  // The same neighbour walking at us head-on (oncoming, not crossing) is
  // judged where it is: on our right, so we go left.
  EXPECT_GT(cfs_neighbour_push(me, d, {-1.3f, 0.0f}, 0.2f, false, kParams).y, 0.0f);
}

// A neighbour ahead along the goal direction but behind the direction the
// agent walks, walking its way and so crossing its goal direction, is not
// anticipated; the same neighbour ahead of the walk is.
TEST(CollisionFreeSpeed, ANeighbourBehindTheWalkedDirectionIsNotAnticipated) {
  // Walking south-south-west, goal to the west; the neighbour north-west of us,
  // a third of a metre behind along our walk, walking south-west as well.
  const glm::vec2 walk = glm::normalize(glm::vec2(-0.4f, -0.9f)) * 1.3f;  // 66 degrees off the goal
  const CfsAgent me{{0.0f, 0.0f}, walk, 0.2f, {-1.0f, 0.0f}};
  const glm::vec2 d(-0.25f, 0.55f), w = walk * 1.1f;  // closing in slowly from behind
  ASSERT_GT(dot2(d, me.e0), 0.0f);
  ASSERT_LT(dot2(d, me.v), 0.0f);
  const float dist = length_of(d);
  const glm::vec2 repulsion =
      d * (-kParams.neighbour_strength * std::exp((0.4f - dist) / kParams.neighbour_range) / dist);
  const glm::vec2 f = cfs_neighbour_push(me, d, w, 0.2f, false, kParams);
  EXPECT_NEAR(f.x, repulsion.x, 1e-4f);
  EXPECT_NEAR(f.y, repulsion.y, 1e-4f);
  // Walking west instead, the same neighbour is ahead of the walk too and
  // crosses it: anticipated (a push beyond the repulsion).
  const CfsAgent west{{0.0f, 0.0f}, {-1.3f, 0.0f}, 0.2f, {-1.0f, 0.0f}};
  const glm::vec2 crossing = cfs_neighbour_push(west, d, {0.0f, -1.3f}, 0.2f, false, kParams);
  EXPECT_GT(length_of(crossing - repulsion), 0.1f);
}

// The far look: an oncoming walker beyond the query radius and within
// cfs_far_reach pushes a freely walking agent to the right, by A_ij alone;
// not one walking slowly or among more than kCfsFarCrowd neighbours; and
// the binned search's 5 x 5 cells find what all pairs find.
TEST(CollisionFreeSpeed, FreeWalkersAnticipateOncomingWalkersBeyondTheQueryRadius) {
  ModelParams m;  // the default model
  m.max_speed = 1.5f;
  const float query = m.query_radius(), reach = cfs_far_reach(m);
  ASSERT_LT(query + 1.0f, reach);
  ASSERT_LE(reach, 2.0f * query);
  const float at = query + 0.5f;  // beyond the query radius
  const CfsAgent me{{0.0f, 0.0f}, {1.3f, 0.0f}, 0.2f, {1.0f, 0.0f}};
  glm::vec2 f;
  ASSERT_TRUE(cfs_far_push(me, {at, 0.0f}, {-1.3f, 0.0f}, 0.2f, false, m.cfs, f));
  const float tau = (at - 0.4f) / 2.6f;
  EXPECT_NEAR(f.y, -m.cfs.avoid_strength * (1.0f - tau / m.cfs.avoid_time), 1e-4f);
  EXPECT_EQ(f.x, 0.0f);
  EXPECT_FALSE(cfs_far_push(me, {at, 0.0f}, {1.0f, 0.0f}, 0.2f, false, m.cfs, f));  // walking our way
  EXPECT_TRUE(cfs_looks_far(me, 1.3f, kCfsFarCrowd, m.cfs));
  EXPECT_FALSE(cfs_looks_far(me, 1.3f, kCfsFarCrowd + 1, m.cfs));
  EXPECT_FALSE(cfs_looks_far({{0.0f, 0.0f}, {0.6f, 0.0f}, 0.2f, {1.0f, 0.0f}}, 1.3f, 0, m.cfs));
  // Through the whole sense: the oncoming walker at `at` turns us right,
  // from all pairs and from the bins alike.
  const std::vector<glm::vec2> p{{0.0f, 0.0f}, {at, 0.0f}}, v{{1.3f, 0.0f}, {-1.3f, 0.0f}};
  const std::vector<float> r{0.2f, 0.2f};
  const std::vector<std::uint8_t> flags(2, kAgentActive);
  const NeighbourArrays n{Span<const glm::vec2>(p), Span<const glm::vec2>(v), Span<const float>(r),
                          Span<const std::uint8_t>(flags), Periodic{}};
  const World world = World::build(WorldSpec{}, query);
  auto all = [&](const auto& fn) { for_each_active_candidate(n, fn); };
  auto far_all = [&](glm::vec2, float, const auto& fn) { fn(n, all); };
  auto none = [&](glm::vec2, float, const auto&) {};
  const glm::vec2 looked = collision_free_velocity(world.view(), 0, me, 1.3f, 0.1f, n, m, all, far_all);
  const glm::vec2 blind = collision_free_velocity(world.view(), 0, me, 1.3f, 0.1f, n, m, all, none);
  EXPECT_LT(looked.y, -1e-3f);
  EXPECT_EQ(blind.y, 0.0f);
  AgentGrid bins(query);
  bins.rebuild(Span<const glm::vec2>(p), Span<const std::uint8_t>(flags));
  const GridView g = bins.view();
  auto far_binned = [&](glm::vec2 e0, float reach2, const auto& fn) {
    auto keep = [&](const CellBounds& c) { return cell_ahead_within_reach(c, p[0], e0, reach2); };
    const Cells5x5 cells = kept_cells(g, g.cell_x(0.0f), g.cell_y(0.0f), 0.0f, keep);
    fn(n, [&](const auto& c) { for_each_binned_candidate(g, cells, n, c); });
  };
  EXPECT_EQ(collision_free_velocity(world.view(), 0, me, 1.3f, 0.1f, n, m, all, far_binned), looked);
}

// A cell the far look passes over (cfs_cell_walks_along) holds nobody its
// push would anticipate: cells of walkers in streams of every spread, some
// slow, a few parked, against goal directions round the stream's, each
// walker pushing from offsets all round the agent.
TEST(CollisionFreeSpeed, FarLookPassesOverOnlyCellsWhoseAgentsNobodyAnticipates) {
  const ModelParams m;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto direction = [](float angle) { return glm::vec2(std::cos(angle), std::sin(angle)); };
  int passed = 0, kept = 0;
  for (int cell = 0; cell < 3000; ++cell) {
    const float stream = 6.2831853f * u(rng), spread = 1.5f * u(rng);
    std::vector<glm::vec2> w(1 + rng() % 8);
    std::vector<bool> parked(w.size());
    CellHeadings h;
    for (std::size_t j = 0; j < w.size(); ++j) {
      const float speed = u(rng) < 0.1f ? 0.05f * u(rng) : 2.0f * u(rng);
      w[j] = speed * direction(stream + spread * (2.0f * u(rng) - 1.0f));
      parked[j] = u(rng) < 0.02f;
      add_heading(h, w[j], parked[j]);
    }
    const glm::vec2 e0 = direction(stream + 1.6f * (2.0f * u(rng) - 1.0f));
    if (!cfs_cell_walks_along(h, e0)) {
      ++kept;
      continue;
    }
    ++passed;
    for (std::size_t j = 0; j < w.size(); ++j) {
      EXPECT_FALSE(parked[j]);
      for (int k = 0; k < 24; ++k) {
        const CfsAgent me{{0.0f, 0.0f}, 2.0f * u(rng) * direction(6.2831853f * u(rng)), 0.2f + u(rng), e0};
        const glm::vec2 q = (0.5f + 11.0f * u(rng)) * direction(6.2831853f * u(rng));
        glm::vec2 f;
        EXPECT_FALSE(cfs_far_push(me, q, w[j], 0.2f + u(rng), false, m.cfs, f)) << "cell " << cell;
      }
    }
  }
  EXPECT_GT(passed, 500);
  EXPECT_GT(kept, 500);
  // Where a push can come from, the cell is kept: somebody parked, a
  // walker 70 degrees off e0, or one of infinite speed; walkers within 50
  // degrees, or too slow to be coming whichever way they walk, are passed
  // over.
  const glm::vec2 e0(1.0f, 0.0f);
  CellHeadings h;
  EXPECT_TRUE(cfs_cell_walks_along(h, e0));  // nobody
  add_heading(h, direction(0.87f), false);
  add_heading(h, direction(-0.87f), false);
  add_heading(h, 0.03f * direction(3.0f), false);
  EXPECT_TRUE(cfs_cell_walks_along(h, e0));
  CellHeadings with_parked = h, with_crosser = h, with_infinite = h;
  add_heading(with_parked, glm::vec2(0.0f), true);
  add_heading(with_crosser, direction(1.22f), false);
  add_heading(with_infinite, glm::vec2(-INFINITY, 0.0f), false);
  EXPECT_FALSE(cfs_cell_walks_along(with_parked, e0));
  EXPECT_FALSE(cfs_cell_walks_along(with_crosser, e0));
  EXPECT_FALSE(cfs_cell_walks_along(with_infinite, e0));  // (it would push: coming, against)
  glm::vec2 f;
  EXPECT_TRUE(
      cfs_far_push({{0.0f, 0.0f}, {1.0f, 0.0f}, 0.2f, e0}, {9.0f, 0.0f}, {-INFINITY, 0.0f}, 0.2f, false, m.cfs, f));
  EXPECT_FALSE(cfs_cell_walks_along(h, -e0));
}

// Through the bins: a stream walking east with oncoming and crossing
// walkers and a parked agent among it, each agent's velocity the same bit for bit with
// the far look passing over cells (summarise_cell_headings) as without,
// from far fewer candidates.
void expect_same_velocities_passing_over_cells(bool dense) {
  const ModelParams m;
  const float query = m.query_radius();
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::vec2> p, v;
  for (int k = 0; k < 1500; ++k) {
    p.emplace_back(200.0f * u(rng), 60.0f * u(rng));
    // One in fifty oncoming, one in twenty crossing 60-80 degrees off east.
    const float speed = k % 50 == 0 ? -1.2f : 1.0f + 0.4f * u(rng);
    const float cross = (k % 2 == 0 ? 1.0f : -1.0f) * (1.05f + 0.35f * u(rng));
    v.push_back(k % 20 == 0 ? 1.3f * glm::vec2(std::cos(cross), std::sin(cross))
                            : glm::vec2(speed, 0.3f * (u(rng) - 0.5f)));
  }
  std::vector<float> r(p.size(), 0.25f);
  std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  flags[700] |= kAgentStopped;
  AgentGrid bins(query);
  bins.rebuild(Span<const glm::vec2>(p), Span<const std::uint8_t>(flags), dense);
  ASSERT_EQ(bins.dense(), dense);
  const GridView g = bins.view();
  const auto items = static_cast<std::size_t>(g.items.size());
  std::vector<glm::vec2> bp(items), bv(items);
  std::vector<float> br(items);
  std::vector<std::uint8_t> bf(items);
  std::vector<glm::vec2> crowd_v = v;
  std::vector<std::uint8_t> crowd_f = flags;
  AgentArrays a;
  a.position = Span<glm::vec2>(p);
  a.velocity = Span<glm::vec2>(crowd_v);
  a.radius = Span<const float>(r);
  a.flags = Span<std::uint8_t>(crowd_f);
  const BinnedState copy{Span<glm::vec2>(bp), Span<glm::vec2>(bv), Span<float>(br), Span<std::uint8_t>(bf), {}};
  StepContext ctx;
  ctx.bins = g;
  gather_binned_state(ctx, a, {}, copy);
  std::vector<CellHeadings> headings(static_cast<std::size_t>(g.capacity()));
  summarise_cell_headings(g, copy, Span<CellHeadings>(headings));
  const NeighbourArrays n{Span<const glm::vec2>(bp),
                          Span<const glm::vec2>(bv),
                          Span<const float>(br),
                          Span<const std::uint8_t>(bf),
                          Periodic{},
                          g.items};
  const World world = World::build(WorldSpec{}, query);
  long visited_all = 0, visited_kept = 0;
  int looked_far = 0;
  for (Index k = 0; k < static_cast<Index>(items); k += 3) {
    const glm::vec2 at = bp[static_cast<std::size_t>(k)];
    const std::int32_t cx = g.cell_x(at.x), cy = g.cell_y(at.y);
    auto near = [&](const auto& fn) { for_each_binned_candidate(g, cells_3x3(g, cx, cy), n, fn); };
    auto far_through = [&](bool skip, long* visited) {
      return [&, skip, visited](glm::vec2 e0, float reach2, const auto& fn) {
        auto keep = [&](const CellBounds& c) { return cell_ahead_within_reach(c, at, e0, reach2); };
        auto keep_slot = [&](Index s) {
          return !skip || !cfs_cell_walks_along(headings[static_cast<std::size_t>(s)], e0);
        };
        const Cells5x5 cells = kept_cells(g, cx, cy, 0.0f, keep, keep_slot);
        for (int run = 0; run < cells.runs; ++run) *visited += cells.count[run];
        fn(n, [&](const auto& c) { for_each_binned_candidate(g, cells, n, c); });
      };
    };
    const CfsAgent me{at, bv[static_cast<std::size_t>(k)], 0.25f, {1.0f, 0.0f}};
    const glm::vec2 all =
        collision_free_velocity(world.view(), k, me, 1.3f, 0.25f, n, m, near, far_through(false, &visited_all));
    const glm::vec2 kept =
        collision_free_velocity(world.view(), k, me, 1.3f, 0.25f, n, m, near, far_through(true, &visited_kept));
    EXPECT_EQ(all, kept) << "agent " << g.items[k];
    auto blind = [](glm::vec2, float, const auto&) {};
    looked_far += all != collision_free_velocity(world.view(), k, me, 1.3f, 0.25f, n, m, near, blind) ? 1 : 0;
  }
  EXPECT_GT(looked_far, 10);  // the far look changed some velocities
  EXPECT_LT(visited_kept * 3, visited_all);
}

TEST(CollisionFreeSpeed, FarLookPassingOverCellsGivesTheSameVelocities) {
  for (const bool dense : {true, false}) {
    SCOPED_TRACE(dense ? "dense bins" : "hashed bins");
    expect_same_velocities_passing_over_cells(dense);
  }
}

TEST(CollisionFreeSpeed, WallsSlideTheGoalDirectionAndTurnsTakeTime) {
  const glm::vec2 wall_normal(-1.0f, 0.0f);  // a wall east of the agent
  const glm::vec2 slid = cfs_slide_along_wall(glm::normalize(glm::vec2(1.0f, -1.0f)), wall_normal);
  EXPECT_NEAR(slid.x, 0.0f, kEps);
  EXPECT_NEAR(slid.y, -1.0f, kEps);
  const glm::vec2 away = cfs_slide_along_wall({-1.0f, 0.0f}, wall_normal);  // walking away: unchanged
  EXPECT_NEAR(away.x, -1.0f, kEps);
  const glm::vec2 head_on = cfs_slide_along_wall({1.0f, 0.0f}, wall_normal);  // straight in: follow it to the right
  EXPECT_NEAR(head_on.x, 0.0f, kEps);
  EXPECT_NEAR(head_on.y, -1.0f, kEps);
  // Turning towards the goal (north): from east, half-way in one step of
  // dt = turn_time / 2.
  const glm::vec2 north(0.0f, 1.0f);
  const glm::vec2 t = cfs_turn({1.0f, 0.0f}, north, north, 0.15f, 0.3f);
  EXPECT_NEAR(t.x, std::sqrt(0.5f), kEps);
  EXPECT_NEAR(t.y, std::sqrt(0.5f), kEps);
  EXPECT_NEAR(cfs_turn({0.0f, 0.0f}, north, north, 0.1f, 0.3f).y, 1.0f, kEps);  // from rest: at once
  // Walking away from the goal, wanted straight back to it: the blend's
  // turn at 150 degrees, atan2(a / 2, 1 - a - a cos 30) = 23.79 degrees at
  // a = 1/3, to the right.
  const float turn = 23.79f * kPiF / 180.0f;
  const glm::vec2 back = cfs_turn({1.0f, 0.0f}, {-1.0f, 0.0f}, {-1.0f, 0.0f}, 0.1f, 0.3f);
  EXPECT_NEAR(back.x, std::cos(turn), 1e-4f);
  EXPECT_NEAR(back.y, -std::sin(turn), 1e-4f);
  // Almost straight back, a hair to the left: as much, to the left.
  const glm::vec2 to_goal = glm::normalize(glm::vec2(-1.0f, 1e-3f));
  const glm::vec2 nearly = cfs_turn({1.0f, 0.0f}, to_goal, to_goal, 0.1f, 0.3f);
  EXPECT_NEAR(nearly.x, std::cos(turn), 1e-4f);
  EXPECT_NEAR(nearly.y, std::sin(turn), 1e-4f);
  EXPECT_NEAR(glm::length(nearly), 1.0f, kEps);
  // Either side of 150 degrees (the blend below, the fixed turn above) the
  // step turns within half a degree of the same angle.
  auto turned = [](float degrees) {
    const float w = degrees * kPiF / 180.0f;
    const glm::vec2 wanted(std::cos(w), std::sin(w));
    const glm::vec2 walked = cfs_turn({1.0f, 0.0f}, wanted, wanted, 0.1f, 0.3f);
    return std::atan2(walked.y, walked.x) * 180.0f / kPiF;
  };
  EXPECT_NEAR(turned(149.9f), turned(150.1f), 0.5f);
  EXPECT_GT(turned(179.0f), 23.0f);  // the blend alone: 1 degree
  // Pushed straight back, away from the goal ahead: it keeps facing the goal.
  const glm::vec2 pushed = cfs_turn({1.0f, 0.0f}, {-1.0f, 0.0f}, {1.0f, 0.0f}, 0.1f, 0.3f);
  EXPECT_NEAR(pushed.x, 1.0f, kEps);
  EXPECT_NEAR(pushed.y, 0.0f, kEps);
}

TEST(CollisionFreeSpeed, NearItsAimAnAgentSlidingAlongAWallSlowsByTheTurn) {
  const glm::vec2 e0 = glm::normalize(glm::vec2(1.0f, -1.0f));
  const glm::vec2 slid(0.0f, -1.0f);  // a wall east turned e0 by 45 degrees
  EXPECT_NEAR(cfs_slide_speed(slid, e0, 1.0f, 1.8f), 1.8f * std::sqrt(0.5f), kEps);
  EXPECT_EQ(cfs_slide_speed(slid, e0, kCfsSlideNear, 1.8f), 1.8f);  // far from its aim: full speed
  EXPECT_EQ(cfs_slide_speed(e0, e0, 1.0f, 1.8f), 1.8f);             // no wall turned it
  // Goal straight through the wall (turned 90 degrees, or the head-on
  // case's right turn): the floor, never a stop.
  EXPECT_NEAR(cfs_slide_speed(slid, {1.0f, 0.0f}, 1.0f, 1.8f), kCfsSlideSlowest * 1.8f, kEps);
}

TEST(CollisionFreeSpeed, NearItsAimAnAgentTurningSharplySlows) {
  const glm::vec2 e0(0.0f, 1.0f);
  const auto at_degrees = [](float d) { return glm::vec2(std::sin(d * kPiF / 180.0f), std::cos(d * kPiF / 180.0f)); };
  EXPECT_EQ(cfs_turn_speed(at_degrees(0.0f), e0, 1.0f, 1.8f), 1.8f);
  EXPECT_EQ(cfs_turn_speed(at_degrees(55.0f), e0, 1.0f, 1.8f), 1.8f);  // a mild turn: full speed
  EXPECT_NEAR(cfs_turn_speed(at_degrees(70.0f), e0, 1.0f, 1.8f), 1.8f * 2.0f * std::cos(70.0f * kPiF / 180.0f), kEps);
  EXPECT_NEAR(cfs_turn_speed(at_degrees(120.0f), e0, 1.0f, 1.8f), kCfsSlideSlowest * 1.8f, kEps);  // the floor
  EXPECT_EQ(cfs_turn_speed(at_degrees(120.0f), e0, kCfsSlideNear, 1.8f), 1.8f);  // far from its aim: full speed
}

// Walking north at 1.3 m/s with its goal 60 degrees off to the east
// (right), an agent yields to a walker beside it on that side, a little
// ahead, walking north too: it falls back to kCfsYieldShare of that
// walker's speed. Not to one on the other side, one behind, one further
// than kCfsYieldGap, one walking another way or slower than
// kCfsYieldSpeed; and not at all with its goal within 45 degrees of its
// heading or below kCfsYieldSpeed itself.
TEST(CollisionFreeSpeed, AWalkerAbreastOnTheGoalsSideIsLetGoFirst) {
  const glm::vec2 goal_east_of_north(std::sin(60.0f * kPiF / 180.0f), std::cos(60.0f * kPiF / 180.0f));
  const CfsAgent me{{0.0f, 0.0f}, {0.0f, 1.3f}, 0.2f, goal_east_of_north};
  const CfsYield yield = cfs_yield(me);
  EXPECT_EQ(yield.side, -1.0f);  // the goal lies to the right of the heading
  EXPECT_NEAR(yield.heading.y, 1.0f, kEps);
  const glm::vec2 north(0.0f, 1.2f);
  EXPECT_NEAR(cfs_yield_speed(me, yield, {0.6f, 0.1f}, north, 0.2f), kCfsYieldShare * 1.2f, kEps);
  EXPECT_TRUE(std::isinf(cfs_yield_speed(me, yield, {-0.6f, 0.1f}, north, 0.2f)));        // on the other side
  EXPECT_TRUE(std::isinf(cfs_yield_speed(me, yield, {0.6f, -0.1f}, north, 0.2f)));        // behind: it yields to us
  EXPECT_TRUE(std::isinf(cfs_yield_speed(me, yield, {0.4f, 0.45f}, north, 0.2f)));        // more ahead than beside
  EXPECT_TRUE(std::isinf(cfs_yield_speed(me, yield, {0.75f, 0.1f}, north, 0.2f)));        // gap 0.36 m: too far
  EXPECT_TRUE(std::isinf(cfs_yield_speed(me, yield, {0.6f, 0.1f}, {0.9f, 0.9f}, 0.2f)));  // 45 degrees off our way
  EXPECT_TRUE(std::isinf(cfs_yield_speed(me, yield, {0.6f, 0.1f}, {0.0f, 0.7f}, 0.2f)));  // slower than the floor
  const glm::vec2 goal_40_degrees(std::sin(40.0f * kPiF / 180.0f), std::cos(40.0f * kPiF / 180.0f));
  EXPECT_EQ(cfs_yield({{0.0f, 0.0f}, {0.0f, 1.3f}, 0.2f, goal_40_degrees}).side, 0.0f);
  EXPECT_EQ(cfs_yield({{0.0f, 0.0f}, {0.0f, 0.7f}, 0.2f, goal_east_of_north}).side, 0.0f);
  EXPECT_EQ(cfs_yield({{0.0f, 0.0f}, {0.0f, 1.3f}, 0.2f, {-goal_east_of_north.x, goal_east_of_north.y}}).side, 1.0f);
}

// (Which agent goes first, slid by a wall or the lower index near one, the
// caller decides: collision_free_velocity.)
TEST(CollisionFreeSpeed, NeighboursBehindAndBesideWaitForABlockedAgentThatGoesFirst) {
  const CfsAgent me{{0.0f, 0.0f}, {0.0f, 0.0f}, 0.25f, {1.0f, 0.0f}};
  EXPECT_TRUE(cfs_waits_for(me, {-0.1f, 0.5f}, false));   // behind: waits for any agent
  EXPECT_FALSE(cfs_waits_for(me, {0.4f, 0.3f}, true));    // 37 degrees off e0: ahead, holds the agent
  EXPECT_TRUE(cfs_waits_for(me, {0.2f, 0.46f}, true));    // 66 degrees off: beside, waits for one that goes first
  EXPECT_FALSE(cfs_waits_for(me, {0.2f, 0.46f}, false));  // and holds one that does not
}

// The gap passes read only the neighbours that the pushes' pass kept as
// close enough to hold the agent's speed (and walk every candidate again
// past kCfsHolders of them). Either way the speed must be the time-gap
// speed over every neighbour: in a light lattice (a few kept), in a dense
// one of small bodies (far more than kCfsHolders within reach) and in a
// light one with an anticipated gap and narrower lanes; the velocity's
// length against cfs_speed over all neighbours along its direction.
TEST(CollisionFreeSpeed, SpeedHoldsForEveryNeighbourWhetherFewOrManyAreNear) {
  ModelParams m;
  m.kind = ModelKind::CollisionFreeSpeed;
  const World world = World::build(WorldSpec{}, m.query_radius());
  struct Lattice {
    float spacing, radius;
    bool overflows;
    float anticipation, lane_width;
  };
  for (const Lattice l : {Lattice{0.6f, 0.25f, false, 0.0f, 1.0f}, Lattice{0.2f, 0.05f, true, 0.0f, 1.0f},
                          Lattice{0.6f, 0.25f, false, 0.5f, 0.8f}}) {
    SCOPED_TRACE(l.spacing);
    m.cfs.anticipation_time = l.anticipation;
    m.cfs.lane_width = l.lane_width;
    std::vector<glm::vec2> p{{0.0f, 0.0f}}, v{{1.0f, 0.0f}};
    std::vector<float> r{0.1f};
    for (int i = -12; i <= 12; ++i)
      for (int j = -12; j <= 12; ++j)
        if (i != 0 || j != 0) {
          p.emplace_back(l.spacing * (static_cast<float>(i) + 0.07f * static_cast<float>(j)),
                         l.spacing * static_cast<float>(j));
          v.emplace_back(-0.2f, 0.05f * static_cast<float>(i % 3));
          r.push_back(l.radius);
        }
    const std::vector<std::uint8_t> f(p.size(), kAgentActive);
    const NeighbourArrays n{Span<const glm::vec2>(p), Span<const glm::vec2>(v), Span<const float>(r),
                            Span<const std::uint8_t>(f), Periodic{}};
    const float v0 = 1.3f, dt = 0.1f;
    const float hold = r[0] + m.max_radius() + v0 * m.cfs.time_gap + m.max_speed * l.anticipation;
    Index near = 0;
    for (const glm::vec2 q : p) near += glm::length(q) < hold ? 1 : 0;
    EXPECT_EQ(near - 1 > kCfsHolders, l.overflows) << near - 1 << " neighbours within " << hold << " m";
    auto all = [&](const auto& fn) { for_each_active_candidate(n, fn); };
    auto far = [&](glm::vec2, float, const auto& fn) { fn(n, all); };
    const CfsAgent me{p[0], v[0], r[0], {1.0f, 0.0f}};
    const glm::vec2 got = collision_free_velocity(world.view(), 0, me, v0, dt, n, m, all, far);
    const float speed = glm::length(got);
    ASSERT_GT(speed, kCfsBlockedSpeed);  // walking: no fallback, so the direction is known
    const glm::vec2 e = got / speed;
    float gap = INFINITY, gap_now = INFINITY;
    for (std::size_t j = 1; j < p.size(); ++j) {
      gap = std::min(gap, cfs_gap_ahead(p[0], r[0], e, p[j] + v[j] * l.anticipation, r[j], l.lane_width));
      gap_now = std::min(gap_now, cfs_gap_ahead(p[0], r[0], e, p[j], r[j]));
    }
    std::printf(
        "  lattice %.2f m, t_a %.1f s, lane width %.1f: %lld neighbours within %.2f m, speed %.4f m/s (gap %.4f "
        "m)\n",
        l.spacing, l.anticipation, l.lane_width, static_cast<long long>(near - 1), hold, speed, gap);
    EXPECT_NEAR(speed, std::min(cfs_speed(gap, v0, m.cfs.time_gap), gap_now / dt), 1e-5f);
    EXPECT_LT(speed, v0);  // someone holds it
  }
}

// ---- encounters -------------------------------------------------------------------

using encounters::Walker;
void expect_encounter_resolves(const std::string& what, const std::vector<Walker>& walkers, const WorldSpec& world = {},
                               double slowest = 1.5) {
  encounters::expect_encounter_resolves(ModelKind::CollisionFreeSpeed, what, walkers, world, slowest);
}

TEST(CollisionFreeSpeed, HeadOnPairOnOneLinePassesWithoutDeadlock) {
  expect_encounter_resolves("head-on", encounters::head_on_pair());
}

TEST(CollisionFreeSpeed, NinetyDegreeCrossingResolves) {
  expect_encounter_resolves("crossing", encounters::crossing_pair());
}

TEST(CollisionFreeSpeed, FourWaysMeetingInTheMiddleResolve) {
  expect_encounter_resolves("four ways", encounters::four_ways());
}

// All twenty meet in the middle at once and queue round it, laid out at
// four turns of the ring as for the other models: 1.48, 1.30, 1.30, 1.24x
// measured (1.42, 1.37, 1.59, 1.43x before the far look and the rule on
// neighbours behind the walked direction; the priority model 1.64x at
// radius 8 m).
TEST(CollisionFreeSpeed, TwentyOnACircleReachTheirAntipodes) {
  encounters::expect_circle_resolves(ModelKind::CollisionFreeSpeed, 1.5);
}

// The same circle at 40 turns over the ring's whole period, every layout
// within the 1.5x aim. Measured: median 1.33x, worst 1.499x (6.3 degrees;
// an arrival one step later would be 1.507x); before the far look and the
// rule on neighbours behind the walked direction median 1.43x, worst
// 1.62x, 9 beyond. Finer spacings still find layouts beyond it
// (scripts/circle_of_twenty.py: 1 of 200 at 1.64x, 3 of 199, 5 of 201;
// docs/simulation.md). Results are the same bits on every instruction set
// (no fused multiply-adds), so the bound does not hang on rounding.
constexpr double kCircleMedian = 1.40;
TEST(CollisionFreeSpeed, TwentyOnACircleRoundTheRing) {
  std::vector<double> worst = encounters::expect_circle_resolves_round_the_ring(ModelKind::CollisionFreeSpeed, 40, 1.5);
  std::sort(worst.begin(), worst.end());
  std::printf("  collision_free_speed, circle of 20 at 40 turns: median %.2fx, worst %.3fx\n", worst[worst.size() / 2],
              worst.back());
  EXPECT_LE(worst[worst.size() / 2], kCircleMedian);
}

// The L corridor of encounters.h: the walkers meet at the corner without
// seeing each other.
TEST(CollisionFreeSpeed, BlindCornerPairPasses) {
  // 1.46x measured.
  expect_encounter_resolves("blind corner", encounters::blind_corner_pair(), encounters::l_corridor());
}

}  // namespace
}  // namespace throng::sim
