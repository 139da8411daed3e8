// sim/grid on CUDA against the CPU: AgentGrid::rebuild (the per-step
// counting sort of agents into bins).
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <vector>

#include "sim/crowd.h"
#include "sim/agent_grid.h"
#include "tests/gpu/gpu_test.h"

namespace throng::sim {
namespace {

// Every occupied cell's agents, by cell coordinates. In the hashed layout
// which slot a cell lands in depends on the order in which threads claim
// slots (linear probing with compare-and-swap), on any backend and thread
// count; the contents of each cell do not (they are sorted by agent
// index). The dense layout (the box of occupied cells, 76 x 76 here, fits
// the table) places them by index.
using Cells = std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>>;

struct Result {
  Cells cells;
  Index binned = 0;
  Index occupied = 0;
  Index capacity = 0;
};

TEST(CudaAgentGrid, RebuildMatchesCpu) {
  THRONG_REQUIRE_GPU();
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> d(-150.0f, 150.0f);
  std::vector<glm::vec2> p;
  for (int i = 0; i < 20000; ++i) p.emplace_back(d(rng), d(rng));
  for (int k = 0; k < 500; ++k) p.emplace_back(1.0f, 1.0f);  // a crowded cell (heap sort path)
  for (int k = 0; k < 50; ++k) p.emplace_back(4.0f * static_cast<float>(k % 7), -8.0f);  // cell borders
  std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  for (std::size_t i = 0; i < flags.size(); i += 7) flags[i] = 0;  // inactive agents are not binned
  bool dense = true;
  const auto run = [&](Memory m) {
    const Buffer<glm::vec2> bp = gpu_test::upload(p, m);
    const Buffer<std::uint8_t> bf = gpu_test::upload(flags, m);
    AgentGrid g(4.0f);
    g.rebuild(bp.span(), bf.span(), dense);
    g.rebuild(bp.span(), bf.span(), dense);  // a rebuild over the same tables
    EXPECT_EQ(g.dense(), dense);
    const GridView v = g.view();
    const std::vector<std::uint64_t> keys = gpu_test::download(v.keys, m);
    const std::vector<std::int32_t> start = gpu_test::download(v.start, m), count = gpu_test::download(v.count, m),
                                    items = gpu_test::download(v.items, m);
    Result r;
    r.binned = g.binned_agents();
    r.occupied = g.occupied_cells();
    r.capacity = v.capacity();
    for (std::size_t s = 0; s < keys.size(); ++s) {
      if (keys[s] == kEmptyCell) continue;
      auto& cell = r.cells[{key_cx(keys[s]), key_cy(keys[s])}];
      for (std::int32_t k = 0; k < count[s]; ++k) cell.push_back(items[static_cast<std::size_t>(start[s] + k)]);
    }
    return r;
  };
  for (const bool layout : {true, false}) {
    SCOPED_TRACE(layout ? "dense" : "hashed");
    dense = layout;
    const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
    const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);
    // Integer work on the same positions (cell_coord is a floor of x / cell,
    // a correctly rounded divide on both): every cell and its sorted run equal.
    EXPECT_EQ(gpu.binned, cpu.binned);
    EXPECT_EQ(gpu.occupied, cpu.occupied);
    EXPECT_EQ(gpu.capacity, cpu.capacity);
    EXPECT_EQ(gpu.cells.size(), cpu.cells.size());
    EXPECT_TRUE(gpu.cells == cpu.cells) << "cells and their agents";
  }
}

}  // namespace
}  // namespace throng::sim
