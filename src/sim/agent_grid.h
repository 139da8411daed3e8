// The agents' bins: AgentGrid rebuilds a grid (grid.h) of the crowd's
// positions every step by a counting sort (kernels in grid_kernels.cpp).
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>

#include "core/buffer.h"
#include "core/periodic.h"
#include "core/span.h"
#include "sim/grid.h"

namespace throng::sim {

// How AgentGrid::rebuild counts agents into their cells on the CPU. By
// slot range: each task owns a range of slots and passes over every agent
// in index order, counting (then placing) those whose cell is in its range:
// no atomic, and each cell's run comes out in index order with no sort.
// Atomic: a locked add per agent, placement in any order, then each run
// sorted; what the device does (the CPU's reference for it). Both give the
// same bins.
enum class BinCounting : std::uint8_t { BySlotRange, Atomic };

// Agents binned by position, rebuilt each step (kernels in grid_kernels.cpp).
class AgentGrid {
 public:
  AgentGrid() = default;
  explicit AgentGrid(float cell_size) : asked_(cell_size), cell_size_(cell_size), cell_size_y_(cell_size) {}
  // Over a periodic area: cells at least cell_size wide, tiling each
  // wrapping period in an even number of them (at least four: throws
  // Error when the period is shorter than four cell sides).
  AgentGrid(float cell_size, const Periodic& periodic);
  // Bins every agent whose flags[i] has bit 0 (active) set, by positions[i].
  // Spans in current_memory(). Dense when the box of the occupied cells has
  // at most max(hash table slots, the dense box limit per agent) cells,
  // unless `allow_dense` is false (tests compare both); tables only grow.
  void rebuild(Span<const glm::vec2> positions, Span<const std::uint8_t> flags, bool allow_dense = true);
  // The CPU's way of counting (the device always counts with atomics).
  void set_counting(BinCounting counting) { counting_ = counting; }
  // Cells per agent a dense box may have beyond the hash table's slots (0,
  // the default: none; the simulation's bins: kDenseCellsPerItem).
  void set_dense_box_limit(Index cells_per_agent) { dense_box_limit_ = cells_per_agent; }
  bool dense() const { return dense_nx_ > 0; }
  // The table's slots in use: a dense grid's box of cells, else the whole table.
  Index slots() const { return dense() ? Index{dense_nx_} * dense_ny_ : table_; }
  GridView view() const;
  // The side asked for; the view's cells are at least as wide (wider along
  // a periodic axis, to tile its period).
  float cell_size() const { return asked_; }
  const Periodic& periodic() const { return periodic_; }
  Index binned_agents() const { return binned_; }
  Index occupied_cells() const;  // counts on the host (for tests and stats)
  // Memory held by the tables, bytes.
  std::size_t bytes() const;

 private:
  void choose_layout(GridView& cells, Span<const glm::vec2> positions, Span<const std::uint8_t> flags,
                     bool allow_dense);
  // Fills count, start and items (and a dense grid's keys) from slot_of by
  // slot range (BinCounting), `cells` the layout choose_layout recorded;
  // returns the agents binned.
  Index place_by_slot_range(const GridView& cells, Index slots);

  float asked_ = 1.0f, cell_size_ = 1.0f, cell_size_y_ = 1.0f;
  Periodic periodic_;
  std::int32_t wrap_x_ = 0, wrap_y_ = 0;
  std::uint64_t mask_ = 0;
  Index table_ = 0;  // the hash table's slots (0 before the first rebuild)
  Index dense_box_limit_ = 0;
  std::int32_t dense_x0_ = 0, dense_y0_ = 0, dense_nx_ = 0, dense_ny_ = 0;  // as GridView's
  Index binned_ = 0;
  BinCounting counting_ = BinCounting::BySlotRange;
  Buffer<std::uint64_t> keys_;
  Buffer<std::int32_t> start_, count_, cursor_, items_, slot_of_agent_;
};

}  // namespace throng::sim
