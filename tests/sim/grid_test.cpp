// Bins: the counting sort against a sort on the host, neighbour queries
// against brute force, the obstacle halo, sparseness, determinism.
#include "sim/grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "core/exec.h"
#include "sim/agent_grid.h"
#include "sim/crowd.h"
#include "sim/world.h"

namespace throng::sim {
namespace {

std::vector<glm::vec2> random_points(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-extent, extent);
  std::vector<glm::vec2> p(n);
  for (auto& q : p) q = {d(rng), d(rng)};
  return p;
}

struct Binned {
  std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>> cells;
  Index binned = 0;
};

// Reads a grid back through its public view: every occupied slot's cell and items.
Binned read_back(const AgentGrid& g) {
  const GridView v = g.view();
  Binned out;
  out.binned = g.binned_agents();
  for (Index s = 0; s < v.capacity(); ++s) {
    const std::uint64_t key = v.keys[s];
    if (key == kEmptyCell) continue;
    auto& items = out.cells[{key_cx(key), key_cy(key)}];
    for (std::int32_t k = 0; k < v.count[s]; ++k) items.push_back(v.items[v.start[s] + k]);
  }
  return out;
}

TEST(CountingSort, EveryActiveAgentOnceInItsCellInIndexOrder) {
  const float cell = 4.0f;
  // Enough agents for four tasks by slot range on four threads.
  std::vector<glm::vec2> p = random_points(33000, 150.0f, 1);
  // Crowded cells and cell borders too.
  for (int k = 0; k < 500; ++k) p.push_back({1.0f, 1.0f});
  for (int k = 0; k < 50; ++k) p.push_back({4.0f * static_cast<float>(k % 7), -8.0f});
  std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  for (std::size_t i = 0; i < flags.size(); i += 7) flags[i] = 0;  // inactive agents are not binned

  // Reference: (cell, index) pairs sorted on the host.
  std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>> want;
  Index active = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!flags[i]) continue;
    want[{cell_coord(p[i].x, cell), cell_coord(p[i].y, cell)}].push_back(static_cast<std::int32_t>(i));
    ++active;
  }
  // The box of occupied cells (76 x 76) fits the table: dense unless
  // hashing is asked for; both layouts hold the same runs.
  for (const BinCounting counting : {BinCounting::BySlotRange, BinCounting::Atomic})
    for (const bool dense : {true, false})
      for (int threads : {1, 2, 4}) {
        SCOPED_TRACE(dense ? "dense" : "hashed");
        SCOPED_TRACE(counting == BinCounting::Atomic ? "atomic" : "by slot range");
        ScopedExecution exec(Backend::Cpu, threads);
        AgentGrid g(cell);
        g.set_counting(counting);
        g.rebuild(p, flags, dense);
        EXPECT_EQ(g.dense(), dense);
        const Binned got = read_back(g);
        EXPECT_EQ(got.binned, active) << threads;
        EXPECT_EQ(got.cells, want) << threads << " threads";
        EXPECT_EQ(g.occupied_cells(), static_cast<Index>(want.size()));
        // find() reaches every cell; an empty cell is not found, in the box or out of it.
        const GridView v = g.view();
        for (const auto& [c, items] : want) {
          const Index s = v.find(c.first, c.second);
          ASSERT_GE(s, 0);
          EXPECT_EQ(v.count[s], static_cast<std::int32_t>(items.size()));
        }
        EXPECT_EQ(v.find(100000, 100000), -1);
        EXPECT_EQ(v.find(-100000, 3), -1);
        for (std::int32_t x = -40; x <= 40; ++x)
          for (std::int32_t y = -40; y <= 40; ++y)
            if (!want.count({x, y})) {
              ASSERT_EQ(v.find(x, y), -1) << x << ", " << y;
            }
      }
}

// Over a periodic area the dense box spans each wrapping period, and a
// lookup past the seam finds the cell at the other end, as the hashed
// grid's does.
TEST(CountingSort, DenseAndHashedGridsWrapAlike) {
  const Periodic periodic{{0.0f, 0.0f}, {40.0f, 0.0f}};
  std::vector<glm::vec2> p = random_points(400, 20.0f, 6);
  for (auto& q : p) q.x = std::fabs(q.x) * 1.99f;  // inside the period [0, 40)
  const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  AgentGrid dense(4.0f, periodic), hashed(4.0f, periodic);
  dense.rebuild(p, flags);
  hashed.rebuild(p, flags, false);
  ASSERT_TRUE(dense.dense());
  ASSERT_FALSE(hashed.dense());
  EXPECT_EQ(read_back(dense).cells, read_back(hashed).cells);
  const GridView d = dense.view(), h = hashed.view();
  for (std::int32_t x = -12; x <= 22; ++x)
    for (std::int32_t y = -8; y <= 8; ++y) {
      const Index a = d.find(x, y), b = h.find(x, y);
      ASSERT_EQ(a < 0, b < 0) << x << ", " << y;
      if (a >= 0) {
        EXPECT_EQ(d.count[a], h.count[b]);
      }
    }
}

// Agents spread far apart (a box of cells much larger than the table)
// are hashed: memory follows the agents, not the box.
TEST(CountingSort, ASparseCrowdIsHashed) {
  std::vector<glm::vec2> p = {{0.0f, 0.0f}, {5000.0f, 5000.0f}, {10.0f, 10.0f}};
  const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  AgentGrid g(4.0f);
  g.rebuild(p, flags);
  EXPECT_FALSE(g.dense());
  p[1] = {12.0f, 4.0f};
  g.rebuild(p, flags);
  EXPECT_TRUE(g.dense());  // 4 x 3 cells fit the table's 16 slots
  EXPECT_EQ(read_back(g).cells.size(), 3u);
}

// With the simulation's dense box limit, a sparse crowd whose box of cells
// outgrows the hash table but holds at most kDenseCellsPerItem cells per
// agent is dense; a sparser one is hashed again, in the first slots of the
// grown tables. Each rebuild holds
// the runs a hashed grid holds, and the tables stay within the bound.
TEST(CountingSort, ABoxOfUpToSixteenCellsPerAgentIsDense) {
  const Index n = 64;  // a hash table of 128 slots; dense up to 1024 cells
  const std::vector<std::uint8_t> flags(n, kAgentActive);
  AgentGrid g(1.0f), reference(1.0f), table_only(1.0f);
  g.set_dense_box_limit(kDenseCellsPerItem);
  for (const float extent : {14.9f, 20.0f, 14.9f}) {  // boxes of 30 x 30 cells, then 40 x 40
    std::vector<glm::vec2> p = random_points(n, extent, 11);
    p[0] = {-extent, -extent}, p[1] = {extent, extent};
    g.rebuild(p, flags);
    reference.rebuild(p, flags, false);
    table_only.rebuild(p, flags);  // no dense box limit: the hash table's 128 slots
    SCOPED_TRACE(extent);
    EXPECT_EQ(g.dense(), extent < 16.0f);
    EXPECT_FALSE(table_only.dense());
    EXPECT_EQ(read_back(g).cells, read_back(reference).cells);
    EXPECT_LE(g.slots(), std::max<Index>(128, kDenseCellsPerItem * n));
  }
}

// A static grid (the world's walls, circles, polygons) is dense over a
// box of up to twice its hash table's slots, and finds the same runs as
// the hashed table, in the box and out of it.
TEST(StaticGrids, DenseAndHashedFindTheSameItems) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::int32_t> coord(-20, 20), item(0, 99);
  std::vector<std::pair<std::uint64_t, std::int32_t>> pairs;
  for (int k = 0; k < 300; ++k) pairs.push_back({cell_key(coord(rng), coord(rng)), item(rng)});
  const StaticGrid dense(2.0f, pairs, Memory::Host), hashed(2.0f, pairs, Memory::Host, false);
  ASSERT_TRUE(dense.dense());
  ASSERT_FALSE(hashed.dense());
  const GridView d = dense.view(), h = hashed.view();
  for (std::int32_t x = -25; x <= 25; ++x)
    for (std::int32_t y = -25; y <= 25; ++y) {
      const Index a = d.find(x, y), b = h.find(x, y);
      ASSERT_EQ(a < 0, b < 0) << x << ", " << y;
      if (a < 0) continue;
      ASSERT_EQ(d.count[a], h.count[b]);
      for (std::int32_t m = 0; m < d.count[a]; ++m) EXPECT_EQ(d.items[d.start[a] + m], h.items[h.start[b] + m]);
    }
  // The 3 x 3 runs too (a dense row is one run: every slot's start is set).
  for (std::int32_t x = -22; x <= 22; x += 3)
    for (std::int32_t y = -22; y <= 22; y += 5) {
      std::vector<std::int32_t> from_dense, from_hashed;
      for_each_in_cells(d, cells_3x3(d, x, y), [&](std::int32_t k) { from_dense.push_back(k); });
      for_each_in_cells(h, cells_3x3(h, x, y), [&](std::int32_t k) { from_hashed.push_back(k); });
      EXPECT_EQ(from_dense, from_hashed) << x << ", " << y;
    }
  // Two cells far apart: a box of 10^6 cells for 2 occupied is hashed.
  const StaticGrid sparse(2.0f, {{cell_key(0, 0), 1}, {cell_key(999, 999), 2}}, Memory::Host);
  EXPECT_FALSE(sparse.dense());
  EXPECT_GE(sparse.view().find(999, 999), 0);
}

TEST(CountingSort, RebuildAfterMovingAndWithNoAgents) {
  AgentGrid g(2.0f);
  std::vector<glm::vec2> p = random_points(1000, 50.0f, 2);
  std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  g.rebuild(p, flags);
  for (auto& q : p) q += glm::vec2(13.0f, -7.0f);
  g.rebuild(p, flags);
  Index total = 0;
  for (const auto& [c, items] : read_back(g).cells) {
    for (std::int32_t i : items) {
      EXPECT_EQ(cell_coord(p[static_cast<std::size_t>(i)].x, 2.0f), c.first);
      EXPECT_EQ(cell_coord(p[static_cast<std::size_t>(i)].y, 2.0f), c.second);
    }
    total += static_cast<Index>(items.size());
  }
  EXPECT_EQ(total, 1000);
  std::vector<glm::vec2> none;
  std::vector<std::uint8_t> no_flags;
  g.rebuild(none, no_flags);
  EXPECT_EQ(g.binned_agents(), 0);
  EXPECT_EQ(g.view().find(0, 0), -1);
}

// Every agent within one cell side is among the 3x3 cells' items, and the
// cached runs (cells_3x3) visit those items in the same order.
void three_by_three_finds_every_neighbour(bool dense) {
  const float side = 4.0f;
  const std::vector<glm::vec2> p = random_points(3000, 60.0f, 3);
  const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  AgentGrid g(side);
  g.rebuild(p, flags, dense);
  ASSERT_EQ(g.dense(), dense);
  const GridView v = g.view();
  std::mt19937 rng(4);
  for (int q = 0; q < 300; ++q) {
    const std::size_t i = rng() % p.size();
    std::set<std::int32_t> brute, binned;
    for (std::size_t j = 0; j < p.size(); ++j)
      if (length2(p[j] - p[i]) < side * side) brute.insert(static_cast<std::int32_t>(j));
    for_each_in_3x3(v, p[i], [&](std::int32_t j) { binned.insert(j); });
    for (std::int32_t j : brute) ASSERT_TRUE(binned.count(j)) << "agent " << i << " misses neighbour " << j;
    // The 3x3 holds nothing beyond its 3 cells: at most 2 * side * sqrt 2 away.
    for (std::int32_t j : binned) EXPECT_LE(length_of(p[static_cast<std::size_t>(j)] - p[i]), 2.0f * side * 1.4143f);
    // The cached form visits the same items in the same order.
    std::vector<std::int32_t> a, b;
    for_each_in_3x3(v, p[i], [&](std::int32_t j) { a.push_back(j); });
    const Cells3x3 cells = cells_3x3(v, cell_coord(p[i].x, side), cell_coord(p[i].y, side));
    for_each_in_cells(v, cells, [&](std::int32_t j) { b.push_back(j); });
    EXPECT_EQ(a, b);
    // Runs that follow each other in `items` are joined: on a dense grid
    // the three cells of a row are one run.
    if (dense) {
      EXPECT_LE(cells.runs, 3);
    }
    for (int k = 1; k < cells.runs; ++k) EXPECT_NE(cells.start[k - 1] + cells.count[k - 1], cells.start[k]);
  }
  // Around points anywhere, inside the occupied box, on its edge and up to
  // three cells beyond it: the same items in the same order.
  std::uniform_real_distribution<float> anywhere(-3.0f * side, 60.0f + 3.0f * side);
  for (int q = 0; q < 2000; ++q) {
    const glm::vec2 at(anywhere(rng), anywhere(rng));
    std::vector<std::int32_t> a, b;
    for_each_in_3x3(v, at, [&](std::int32_t j) { a.push_back(j); });
    for_each_in_cells(v, cells_3x3(v, cell_coord(at.x, side), cell_coord(at.y, side)),
                      [&](std::int32_t j) { b.push_back(j); });
    ASSERT_EQ(a, b) << "around (" << at.x << ", " << at.y << ")";
  }
}

TEST(Bins, ThreeByThreeFindsEveryNeighbourWithinOneCellSide) {
  for (const bool dense : {true, false}) {
    SCOPED_TRACE(dense ? "dense" : "hashed");
    three_by_three_finds_every_neighbour(dense);
  }
}

// kept_cells against the cells one by one: the items of every cell within
// two of the agent's whose bounds `keep` accepts (a disc of reach and the
// half-plane ahead), row by row, in the same order; and every item within
// the reach and ahead among them; and the same with some slots left out
// by keep_slot; and the same of the 3 x 3. Dense and hashed grids, and a
// periodic area too short for five cells along x (the cells there stay
// within one).
void kept_cells_match_cell_by_cell(AgentGrid& g, const std::vector<glm::vec2>& p, const Periodic& periodic) {
  const GridView v = g.view();
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> turn(0.0f, 6.2831853f);
  std::size_t all_items = 0, slot_items = 0;
  for (int q = 0; q < 400; ++q) {
    const std::size_t i = rng() % p.size();
    const float a = turn(rng), reach = 6.0f;
    const glm::vec2 e0(std::cos(a), std::sin(a)), at = p[i];
    auto keep = [&](const CellBounds& c) {
      const glm::vec2 front(e0.x >= 0.0f ? c.hi.x : c.lo.x, e0.y >= 0.0f ? c.hi.y : c.lo.y);
      return within_reach(c, at, reach * reach) && dot2(front - at, e0) > 0.0f;
    };
    const std::int32_t cx = v.cell_x(at.x), cy = v.cell_y(at.y);
    const std::int32_t rx = v.wrap_x > 0 && v.wrap_x < 6 ? 1 : 2;
    // Some slots left out by what they hold (here: every third), so the
    // runs of a row break anywhere.
    const std::uint32_t salt = rng();
    auto keep_slot = [&](Index s) { return (static_cast<std::uint32_t>(s) + salt) % 3 != 0; };
    auto every_slot = [](Index) { return true; };
    // The items of the cells within r rows and r columns (r - 1 along an
    // axis that wraps in fewer than 2 r + 2 cells) that keep and
    // slot_kept accept, tested one by one.
    auto cell_by_cell = [&](std::int32_t r, const auto& slot_kept) {
      std::vector<std::int32_t> items;
      const std::int32_t rc = v.wrap_x > 0 && v.wrap_x < 2 * r + 2 ? r - 1 : r;
      for (std::int32_t dy = -r; dy <= r; ++dy)
        for (std::int32_t dx = -rc; dx <= rc; ++dx) {
          const Index s = v.find(cx + dx, cy + dy);
          if (s < 0 || !keep(cell_bounds(v, cx + dx, cy + dy, 0.0f)) || !slot_kept(s)) continue;
          for (std::int32_t k = 0; k < v.count[s]; ++k) items.push_back(v.items[v.start[s] + k]);
        }
      return items;
    };
    auto items_of = [&](const auto& runs) {
      std::vector<std::int32_t> items;
      for_each_in_cells(v, runs, [&](std::int32_t j) { items.push_back(j); });
      return items;
    };
    const std::vector<std::int32_t> got = items_of(kept_cells(v, cx, cy, 0.0f, keep));
    const std::vector<std::int32_t> got_slots = items_of(kept_cells(v, cx, cy, 0.0f, keep, keep_slot));
    ASSERT_EQ(cell_by_cell(2, every_slot), got) << "around agent " << i;
    ASSERT_EQ(cell_by_cell(2, keep_slot), got_slots) << "around agent " << i;
    // The 3 x 3 (kept_cells_within<1>), as the priority model's sense picks
    // its cells.
    ASSERT_EQ(cell_by_cell(1, every_slot), items_of(kept_cells_within<1>(v, cx, cy, 0.0f, keep, every_slot)))
        << "around agent " << i;
    all_items += got.size();
    slot_items += got_slots.size();
    const std::set<std::int32_t> kept(got.begin(), got.end());
    for (std::size_t j = 0; j < p.size(); ++j) {
      const glm::vec2 d = periodic.near(p[j], at) - at;
      if (rx == 2 && length2(d) < reach * reach && dot2(d, e0) > 0.0f) {
        EXPECT_TRUE(kept.count(static_cast<std::int32_t>(j))) << "agent " << i << " misses " << j;
      }
    }
  }
  EXPECT_LT(slot_items, all_items);  // keep_slot left some out
}

TEST(Bins, KeptCellsOfTheFiveByFiveAreThoseAcceptedCellByCell) {
  const std::vector<glm::vec2> p = random_points(3000, 60.0f, 7);
  const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  for (const bool dense : {true, false}) {
    SCOPED_TRACE(dense ? "dense" : "hashed");
    AgentGrid g(4.0f);
    g.rebuild(p, flags, dense);
    ASSERT_EQ(g.dense(), dense);
    kept_cells_match_cell_by_cell(g, p, Periodic{});
  }
  SCOPED_TRACE("periodic, 4 cells along x");
  const Periodic periodic{{0.0f, 0.0f}, {16.0f, 0.0f}};
  std::vector<glm::vec2> wrapped = p;
  for (glm::vec2& q : wrapped) q.x = std::fmod(q.x, 16.0f);
  AgentGrid g(4.0f, periodic);
  g.rebuild(wrapped, flags);
  ASSERT_EQ(g.view().wrap_x, 4);
  kept_cells_match_cell_by_cell(g, wrapped, periodic);
}

// A cell that within_reach leaves out holds no item within the reach, also
// for items moved up to the slack since they were binned; around random
// points some of the 3x3 cells are left out.
TEST(Bins, ACellLeftOutOfReachHoldsNothingWithinIt) {
  const float side = 4.0f, slack = 0.5f;
  const std::vector<glm::vec2> binned_at = random_points(3000, 60.0f, 5);
  const std::vector<std::uint8_t> flags(binned_at.size(), kAgentActive);
  AgentGrid g(side);
  g.rebuild(binned_at, flags);
  const GridView v = g.view();
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> jitter(-slack / 1.5f, slack / 1.5f), anywhere(-8.0f, 68.0f);
  std::vector<glm::vec2> p = binned_at;
  for (glm::vec2& q : p) q += glm::vec2(jitter(rng), jitter(rng));
  int left_out = 0;
  for (int k = 0; k < 2000; ++k) {
    const glm::vec2 at(anywhere(rng), anywhere(rng));
    const std::int32_t cx = cell_coord(at.x, side), cy = cell_coord(at.y, side);
    for (std::int32_t dy = -1; dy <= 1; ++dy)
      for (std::int32_t dx = -1; dx <= 1; ++dx) {
        if (within_reach(cell_bounds(v, cx + dx, cy + dy, slack), at, side * side)) continue;
        ++left_out;
        const Index s = v.find(cx + dx, cy + dy);
        for (std::int32_t m = 0; s >= 0 && m < v.count[s]; ++m)
          ASSERT_GE(length2(p[static_cast<std::size_t>(v.items[v.start[s] + m])] - at), side * side);
      }
  }
  EXPECT_GT(left_out, 100);  // 506 of the 18000 cells looked at
}

TEST(Bins, WallHaloFindsEveryWallWithinOneCellOfAPoint) {
  WorldSpec spec;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> d(-40.0f, 40.0f), size(0.5f, 6.0f);
  for (int k = 0; k < 60; ++k) {
    const glm::vec2 c(d(rng), d(rng));
    const float s = size(rng);
    spec.polygons.push_back({{c, c + glm::vec2(s, 0.3f * s), c + glm::vec2(0.2f * s, s)}, {}});
  }
  for (int k = 0; k < 30; ++k) spec.circles.push_back({{d(rng), d(rng)}, 0.2f + 0.05f * static_cast<float>(k)});
  const World w = World::build(spec, 4.0f);
  const WorldView v = w.host_view();
  for (int q = 0; q < 2000; ++q) {
    const glm::vec2 p(d(rng), d(rng));
    std::set<std::int32_t> segs, circles;
    for_each_in_cell(v.segment_grid, p, [&](std::int32_t k) { segs.insert(k); });
    for_each_in_cell(v.circle_grid, p, [&](std::int32_t k) { circles.insert(k); });
    for (std::size_t k = 0; k < w.segments().size(); ++k)
      if (distance_to_segment(p, w.segments()[k].a, w.segments()[k].b) < 4.0f) {
        ASSERT_TRUE(segs.count(static_cast<std::int32_t>(k)));
      }
    for (std::size_t k = 0; k < w.circles().size(); ++k)
      if (length_of(p - w.circles()[k].center) - w.circles()[k].radius < 4.0f) {
        ASSERT_TRUE(circles.count(static_cast<std::int32_t>(k)));
      }
  }
}

// A 10 km scene with a few agents and obstacles at its corners: the grids
// hold what is occupied, not the extent (a dense 4 m grid would have
// 6.25 million cells).
TEST(Bins, MemoryFollowsAgentsAndOccupiedAreaNotTheExtent) {
  std::vector<glm::vec2> p;
  for (int k = 0; k < 100; ++k)
    p.push_back({static_cast<float>(k % 10) * 1000.0f, static_cast<float>(k / 10) * 1000.0f});
  const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  AgentGrid g(4.0f);
  g.rebuild(p, flags);
  EXPECT_EQ(g.occupied_cells(), 100);
  EXPECT_LE(g.bytes(), 100u * 100u);  // a few slots per agent (a dense 4 m grid: 6.25 million cells)

  WorldSpec spec;
  spec.polygons.push_back({rect_ring({0, 0}, {2, 2}), {}});
  spec.polygons.push_back({rect_ring({9990, 9990}, {9992, 9992}), {}});
  spec.circles.push_back({{0, 9990}, 1.0f});
  const World w = World::build(spec, 4.0f);
  const WorldView v = w.host_view();
  Index used = 0;
  for (Index s = 0; s < v.segment_grid.capacity(); ++s) used += v.segment_grid.keys[s] != kEmptyCell;
  EXPECT_LE(used, 2 * 16);  // each square touches at most 2x2 cells, 4x4 with the halo
  EXPECT_LE(v.segment_grid.capacity(), 128);
}

TEST(Bins, CellCoordinatesAreSafeForHugeAndNonFiniteValues) {
  EXPECT_EQ(cell_coord(1e30f, 4.0f), kCellCoordLimit - 1);
  EXPECT_EQ(cell_coord(-1e30f, 4.0f), -kCellCoordLimit);
  EXPECT_EQ(cell_coord(NAN, 4.0f), 0);
  EXPECT_EQ(key_cx(cell_key(-5, 7)), -5);
  EXPECT_EQ(key_cy(cell_key(-5, 7)), 7);
  EXPECT_NE(cell_key(kCellCoordLimit - 1, kCellCoordLimit - 1), kEmptyCell);
}

TEST(Bins, FourColoursKeepSameColourCellsTwoApart) {
  for (std::int32_t x = -3; x <= 3; ++x)
    for (std::int32_t y = -3; y <= 3; ++y)
      for (std::int32_t dx = -2; dx <= 2; ++dx)
        for (std::int32_t dy = -2; dy <= 2; ++dy) {
          if ((dx == 0 && dy == 0) || cell_colour(cell_key(x, y)) != cell_colour(cell_key(x + dx, y + dy))) continue;
          // Same colour, different cell: their 3x3 blocks share no cell of either.
          EXPECT_TRUE(std::abs(dx) >= 2 || std::abs(dy) >= 2);
        }
}

}  // namespace
}  // namespace throng::sim
