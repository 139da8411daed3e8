// Sparse uniform grids: cell (cx, cy) -> a run of item indices.
//
// Cells live in an open-addressing hash table of about twice as many slots
// as items, keyed by the packed cell coordinates, or, where the box of the
// occupied cells is small enough, in that box densely (GridView below).
// Memory grows with the items, never with the extent of the scene (a 10 km
// scene with a few agents costs a few cells). Two builders, one view type:
//   - StaticGrid: built once on the host from (cell, item) pairs (obstacles);
//   - AgentGrid (agent_grid.h): rebuilt every step by a counting sort (each
//     agent's slot -> histogram -> exclusive_scan -> scatter), each cell's
//     run in agent index order so the order inside a bin is deterministic:
//     on the CPU by slot range, with no atomics; on the device with
//     atomics, then a sort inside each cell (BinCounting).
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/vec2.hpp>
#include <utility>
#include <vector>

#include "core/buffer.h"
#include "core/periodic.h"
#include "core/span.h"

namespace throng::sim {

inline constexpr std::uint64_t kEmptyCell = ~std::uint64_t{0};
// Cell coordinates are clamped to +-2^30 so keys never reach kEmptyCell.
inline constexpr std::int32_t kCellCoordLimit = 1 << 30;

THRONG_HOST_DEVICE inline std::int32_t cell_coord(float x, float cell_size) {
  const float c = floorf(x / cell_size);
  // NaN fails both comparisons and lands in cell 0 instead of being UB.
  if (!(c > -static_cast<float>(kCellCoordLimit))) return c != c ? 0 : -kCellCoordLimit;
  if (!(c < static_cast<float>(kCellCoordLimit - 1))) return kCellCoordLimit - 1;
  return static_cast<std::int32_t>(c);
}

THRONG_HOST_DEVICE inline std::uint64_t cell_key(std::int32_t cx, std::int32_t cy) {
  const auto ux = static_cast<std::uint32_t>(cx + kCellCoordLimit);
  const auto uy = static_cast<std::uint32_t>(cy + kCellCoordLimit);
  return (static_cast<std::uint64_t>(ux) << 32) | uy;
}
THRONG_HOST_DEVICE inline std::int32_t key_cx(std::uint64_t key) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(key >> 32)) - kCellCoordLimit;
}
THRONG_HOST_DEVICE inline std::int32_t key_cy(std::uint64_t key) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(key & 0xffffffffu)) - kCellCoordLimit;
}
// Colour of the four-colour batches: cells of one colour are two apart in x
// or y, so their 3x3 neighbourhoods never include each other.
THRONG_HOST_DEVICE inline int cell_colour(std::uint64_t key) { return (key_cx(key) & 1) | ((key_cy(key) & 1) << 1); }

THRONG_HOST_DEVICE inline std::uint64_t mix_key(std::uint64_t k) {
  // splitmix64 finaliser: neighbouring cells land far apart in the table.
  k ^= k >> 30;
  k *= 0xbf58476d1ce4e5b9ull;
  k ^= k >> 27;
  k *= 0x94d049bb133111ebull;
  k ^= k >> 31;
  return k;
}

// Where a cell's probe sequence starts in a table of mask + 1 slots (a power
// of two, at least 16). Cells are grouped in 4 x 4 tiles: a tile is placed
// by a hash, its 16 cells in 16 consecutive slots, so the 3x3 cells around
// an agent lie in a few cache lines and agents near each other in space
// touch the same part of the table.
THRONG_HOST_DEVICE inline std::uint64_t home_slot(std::uint64_t key, std::uint64_t mask) {
  const std::int32_t cx = key_cx(key), cy = key_cy(key);
  const std::uint64_t tile = cell_key(cx >> 2, cy >> 2);
  const auto local = static_cast<std::uint64_t>(((cy & 3) << 2) | (cx & 3));
  return ((mix_key(tile) << 4) | local) & mask;
}

// What kernels see: the table (keys per slot, kEmptyCell when free), the run
// of each slot in `items`, and the cell sides. `items` holds every binned
// item grouped by cell: iterating it visits agents cell by cell, which keeps
// the lookups of neighbouring agents in the same part of memory.
//
// A dense grid (dense_nx > 0) has no hashing: its slots are the cells of the
// box of dense_nx x dense_ny cells from (dense_x0, dense_y0), row by row, so
// a lookup is an index computation and the neighbouring cells of a row are
// neighbouring slots (AgentGrid::rebuild and StaticGrid say when).
//
// Over a periodic area (core/periodic.h) the cells of a wrapping axis tile the
// period exactly, `wrap_x` (or `wrap_y`) of them, an even number so that the
// four colours stay two cells apart across the seam, and cell coordinates
// are taken modulo that count: the cell beyond the last is the first.
// Elsewhere cells are squares of side cell_size from the origin (0, 0).
struct GridView {
  float cell_size = 1.0f;                   // m: the side along x
  float cell_size_y = 1.0f;                 // m: the side along y (differs from cell_size only on a periodic grid)
  glm::vec2 origin{0.0f};                   // m: where cell (0, 0) starts
  std::int32_t wrap_x = 0, wrap_y = 0;      // cells per period along a wrapping axis; 0 elsewhere
  std::uint64_t mask = 0;                   // hashed: capacity - 1 (capacity is a power of two)
  std::int32_t dense_x0 = 0, dense_y0 = 0;  // dense: the first cell of the box
  std::int32_t dense_nx = 0, dense_ny = 0;  // dense: the box's cells along x and y; 0 when hashed
  Span<const std::uint64_t> keys;
  Span<const std::int32_t> start;
  Span<const std::int32_t> count;
  Span<const std::int32_t> items;

  THRONG_HOST_DEVICE Index capacity() const { return keys.size(); }
  THRONG_HOST_DEVICE std::int32_t cell_x(float x) const { return cell_coord(x - origin.x, cell_size); }
  THRONG_HOST_DEVICE std::int32_t cell_y(float y) const { return cell_coord(y - origin.y, cell_size_y); }
  // Where cell (cx, cy) starts, unwrapped: the cell before the first lies
  // before the origin, where the images of the last cell's items are.
  THRONG_HOST_DEVICE glm::vec2 cell_min(std::int32_t cx, std::int32_t cy) const {
    return origin + glm::vec2(static_cast<float>(cx) * cell_size, static_cast<float>(cy) * cell_size_y);
  }
  // Cell (cx, cy) wrapped along the periodic axes.
  THRONG_HOST_DEVICE void wrap(std::int32_t& cx, std::int32_t& cy) const {
    if (wrap_x > 0) cx = ((cx % wrap_x) + wrap_x) % wrap_x;
    if (wrap_y > 0) cy = ((cy % wrap_y) + wrap_y) % wrap_y;
  }
  // The key of cell (cx, cy), wrapped along the periodic axes.
  THRONG_HOST_DEVICE std::uint64_t key_of(std::int32_t cx, std::int32_t cy) const {
    wrap(cx, cy);
    return cell_key(cx, cy);
  }
  // A dense grid's slot of wrapped cell (cx, cy), -1 outside its box.
  THRONG_HOST_DEVICE Index dense_slot(std::int32_t cx, std::int32_t cy) const {
    const std::int64_t x = std::int64_t{cx} - dense_x0, y = std::int64_t{cy} - dense_y0;
    if (x < 0 || y < 0 || x >= dense_nx || y >= dense_ny) return -1;
    return static_cast<Index>(y * dense_nx + x);
  }
  // Slot holding the cell, or -1.
  THRONG_HOST_DEVICE Index find(std::int32_t cx, std::int32_t cy) const {
    if (items.size() == 0) return -1;  // nothing binned (e.g. a world without walls)
    if (dense_nx > 0) {
      wrap(cx, cy);
      const Index s = dense_slot(cx, cy);
      return s >= 0 && count[s] > 0 ? s : -1;
    }
    const std::uint64_t key = key_of(cx, cy);
    std::uint64_t s = home_slot(key, mask);
    for (;;) {
      const std::uint64_t k = keys[static_cast<Index>(s)];
      if (k == key) return static_cast<Index>(s);
      if (k == kEmptyCell) return -1;
      s = (s + 1) & mask;
    }
  }
};

// The item runs of the 3x3 cells around cell (cx, cy), row-major (dy, then
// dx), empty cells left out and runs that follow each other in `items`
// joined (on a dense grid the three cells of a row are one run): the same
// items in the same order as cell by cell, with fewer loops to end. Worth
// keeping when the same neighbourhood is visited several times in a step
// (the contact passes): the table lookups and their cache misses are paid
// once.
template <int kCells>
struct CellRuns {
  std::int32_t start[kCells];
  std::int32_t count[kCells];
  std::int32_t runs = 0;
};
using Cells3x3 = CellRuns<9>;
using Cells5x5 = CellRuns<25>;  // (kept_cells below)
// Appends the run of n items from b, joined to the last run when it follows it.
template <int kCells>
THRONG_HOST_DEVICE inline void add_run(CellRuns<kCells>& c, std::int32_t b, std::int32_t n) {
  if (c.runs > 0 && c.start[c.runs - 1] + c.count[c.runs - 1] == b) {
    c.count[c.runs - 1] += n;
  } else {
    c.start[c.runs] = b;
    c.count[c.runs] = n;
    ++c.runs;
  }
}
// A dense grid that does not wrap: a row's cells are neighbouring slots,
// and every slot's start is set (an empty one's where its items would be),
// so a row of the 3x3 is one lookup of its first and last slot.
THRONG_HOST_DEVICE inline Cells3x3 dense_cells_3x3(const GridView& g, std::int32_t cx, std::int32_t cy) {
  Cells3x3 c;
  const std::int64_t x = std::int64_t{cx} - g.dense_x0;
  const std::int64_t x0 = x - 1 > 0 ? x - 1 : 0, x1 = x + 1 < g.dense_nx - 1 ? x + 1 : g.dense_nx - 1;
  if (g.items.size() == 0 || x0 > x1) return c;
  for (std::int64_t y = std::int64_t{cy} - g.dense_y0 - 1; y <= std::int64_t{cy} - g.dense_y0 + 1; ++y) {
    if (y < 0 || y >= g.dense_ny) continue;
    const auto first = static_cast<Index>(y * g.dense_nx + x0), last = static_cast<Index>(y * g.dense_nx + x1);
    const std::int32_t b = g.start[first], n = g.start[last] + g.count[last] - b;
    if (n > 0) add_run(c, b, n);
  }
  return c;
}
THRONG_HOST_DEVICE inline Cells3x3 cells_3x3(const GridView& g, std::int32_t cx, std::int32_t cy) {
  if (g.dense_nx > 0 && g.wrap_x == 0 && g.wrap_y == 0) return dense_cells_3x3(g, cx, cy);
  Cells3x3 c;
  for (std::int32_t dy = -1; dy <= 1; ++dy)
    for (std::int32_t dx = -1; dx <= 1; ++dx) {
      const Index s = g.find(cx + dx, cy + dy);
      if (s >= 0) add_run(c, g.start[s], g.count[s]);
    }
  return c;
}
// Cell (cx, cy) widened by `slack` on every side (for items that may have
// moved that far since they were binned): its lower and upper corners.
struct CellBounds {
  glm::vec2 lo, hi;
};
THRONG_HOST_DEVICE inline CellBounds cell_bounds(const GridView& g, std::int32_t cx, std::int32_t cy, float slack) {
  const glm::vec2 lo = g.cell_min(cx, cy) - glm::vec2(slack);
  return {lo, lo + glm::vec2(g.cell_size, g.cell_size_y) + glm::vec2(2.0f * slack)};
}
// True when some point of the bounds lies closer to p than sqrt(reach2):
// an item within bounds that fail holds no neighbour within that reach of
// p, in float arithmetic too (each coordinate difference to an item is at
// least the one to the nearest point, and rounding keeps that order). NaN
// p keeps every cell.
THRONG_HOST_DEVICE inline bool within_reach(const CellBounds& c, glm::vec2 p, float reach2) {
  const float nx = p.x < c.lo.x ? c.lo.x : (p.x > c.hi.x ? c.hi.x : p.x);
  const float ny = p.y < c.lo.y ? c.lo.y : (p.y > c.hi.y ? c.hi.y : p.y);
  return !((nx - p.x) * (nx - p.x) + (ny - p.y) * (ny - p.y) >= reach2);
}
// Whether cell bounds c reach within sqrt(reach2) of p and into the
// half-plane ahead of it along e0 (its corner furthest along e0 lies ahead).
THRONG_HOST_DEVICE inline bool cell_ahead_within_reach(const CellBounds& c, glm::vec2 p, glm::vec2 e0, float reach2) {
  const glm::vec2 front(e0.x >= 0.0f ? c.hi.x : c.lo.x, e0.y >= 0.0f ? c.hi.y : c.lo.y);
  return within_reach(c, p, reach2) & ((front.x - p.x) * e0.x + (front.y - p.y) * e0.y > 0.0f);
}
// The item runs of the cells within kRadius of (cx, cy) along each axis
// (kept_cells: the 5 x 5) that keep(cell bounds) accepts, row-major as
// cells_3x3; keep must accept a contiguous stretch of each row (a test of
// distance or of a half-plane, or both). Of those, keep_slot(slot) may
// leave out any (a test of what the cell holds). Along a wrapping axis of
// fewer than 2 kRadius + 2 cells the cells stay within kRadius - 1 of
// (cx, cy), so that none is visited twice. `slack` widens the bounds
// (cell_bounds).
template <int kRadius, class Keep, class KeepSlot>
THRONG_HOST_DEVICE inline CellRuns<(2 * kRadius + 1) * (2 * kRadius + 1)> kept_cells_within(
    const GridView& g, std::int32_t cx, std::int32_t cy, float slack, const Keep& keep, const KeepSlot& keep_slot) {
  CellRuns<(2 * kRadius + 1) * (2 * kRadius + 1)> c;
  if (g.items.size() == 0) return c;
  constexpr std::int32_t kShort = 2 * kRadius + 2;  // a wrapping axis of fewer cells keeps one cell less each way
  const std::int32_t rx = g.wrap_x > 0 && g.wrap_x < kShort ? kRadius - 1 : kRadius;
  const std::int32_t ry = g.wrap_y > 0 && g.wrap_y < kShort ? kRadius - 1 : kRadius;
  const bool dense_row = g.dense_nx > 0 && g.wrap_x == 0 && g.wrap_y == 0;
  for (std::int32_t y = cy - ry; y <= cy + ry; ++y) {
    // The row's stretch: every cell tested, the first and last kept picked
    // without a branch (a scan in from either end mispredicts its exits).
    std::int32_t lo = cx + rx + 1, hi = cx - rx - 1;
    for (std::int32_t x = cx - rx; x <= cx + rx; ++x) {
      const bool kept = keep(cell_bounds(g, x, y, slack));
      lo = kept & (lo > cx + rx) ? x : lo;
      hi = kept ? x : hi;
    }
    if (lo > hi) continue;
    if (!dense_row) {
      for (std::int32_t x = lo; x <= hi; ++x)
        if (const Index s = g.find(x, y); s >= 0 && keep_slot(s)) add_run(c, g.start[s], g.count[s]);
      continue;
    }
    // A dense row's slots follow each other, and so do their items: the
    // runs of neighbouring kept slots join into one.
    const Index a = g.dense_slot(lo > g.dense_x0 ? lo : g.dense_x0, y);
    const Index b = g.dense_slot(hi < g.dense_x0 + g.dense_nx - 1 ? hi : g.dense_x0 + g.dense_nx - 1, y);
    if (a < 0 || b < 0 || a > b) continue;
    for (Index s = a; s <= b; ++s)
      if (g.count[s] > 0 && keep_slot(s)) add_run(c, g.start[s], g.count[s]);
  }
  return c;
}
template <class Keep, class KeepSlot>
THRONG_HOST_DEVICE inline Cells5x5 kept_cells(const GridView& g, std::int32_t cx, std::int32_t cy, float slack,
                                              const Keep& keep, const KeepSlot& keep_slot) {
  return kept_cells_within<2>(g, cx, cy, slack, keep, keep_slot);
}
template <class Keep>
THRONG_HOST_DEVICE inline Cells5x5 kept_cells(const GridView& g, std::int32_t cx, std::int32_t cy, float slack,
                                              const Keep& keep) {
  return kept_cells(g, cx, cy, slack, keep, [](Index) { return true; });
}

// Calls fn(item) for every item of those cells, in order.
template <int kCells, class Fn>
THRONG_HOST_DEVICE inline void for_each_in_cells(const GridView& g, const CellRuns<kCells>& c, Fn&& fn) {
  for (int k = 0; k < c.runs; ++k)
    for (std::int32_t m = 0; m < c.count[k]; ++m) fn(g.items[c.start[k] + m]);
}

// Calls fn(item) for every item of the 3x3 cells around cell (cx, cy), cells
// in row-major order (dy, then dx), items in their stored order.
template <class Fn>
THRONG_HOST_DEVICE inline void for_each_in_3x3(const GridView& g, std::int32_t cx, std::int32_t cy, Fn&& fn) {
  for (std::int32_t dy = -1; dy <= 1; ++dy)
    for (std::int32_t dx = -1; dx <= 1; ++dx) {
      const Index s = g.find(cx + dx, cy + dy);
      if (s < 0) continue;
      const std::int32_t b = g.start[s], n = g.count[s];
      for (std::int32_t k = 0; k < n; ++k) fn(g.items[b + k]);
    }
}
// The same around the cell containing p.
template <class Fn>
THRONG_HOST_DEVICE inline void for_each_in_3x3(const GridView& g, glm::vec2 p, Fn&& fn) {
  for_each_in_3x3(g, g.cell_x(p.x), g.cell_y(p.y), fn);
}
// The same for the one cell containing p. On the world's halo grids (walls,
// circles: see world.h) this finds everything within one cell side of p.
template <class Fn>
THRONG_HOST_DEVICE inline void for_each_in_cell(const GridView& g, glm::vec2 p, Fn&& fn) {
  const Index s = g.find(g.cell_x(p.x), g.cell_y(p.y));
  if (s < 0) return;
  const std::int32_t b = g.start[s], n = g.count[s];
  for (std::int32_t k = 0; k < n; ++k) fn(g.items[b + k]);
}

// Smallest power of two >= 2 * n (load factor <= 1/2), at least 16.
Index grid_capacity_for(Index n);
// The largest dense box of the simulation's AgentGrids, in cells per agent,
// 20 bytes each (docs/simulation.md, the bins).
inline constexpr Index kDenseCellsPerItem = 16;

// Host-built grid from (cell key, item) pairs; uploaded to `memory`. Dense
// when the box of its cells has at most twice as many cells as its hash
// table would have slots (at most twice the memory), unless `allow_dense`
// is false.
class StaticGrid {
 public:
  StaticGrid() = default;
  StaticGrid(float cell_size, std::vector<std::pair<std::uint64_t, std::int32_t>> pairs, Memory memory,
             bool allow_dense = true);
  bool dense() const { return dense_nx_ > 0; }
  GridView view() const;
  // The same tables in host memory (spawning and validation run on the host).
  GridView host_view() const;
  Index occupied_cells() const { return occupied_; }
  Index item_count() const { return static_cast<Index>(host_items_.size()); }

 private:
  float cell_size_ = 1.0f;
  std::uint64_t mask_ = 0;
  std::int32_t dense_x0_ = 0, dense_y0_ = 0, dense_nx_ = 0, dense_ny_ = 0;  // as GridView's
  Index occupied_ = 0;
  std::vector<std::uint64_t> host_keys_;
  std::vector<std::int32_t> host_start_, host_count_, host_items_;
  Buffer<std::uint64_t> keys_;
  Buffer<std::int32_t> start_, count_, items_;

  void choose_dense_box(const std::vector<std::pair<std::uint64_t, std::int32_t>>& pairs, Index most);
  GridView geometry() const;  // the cells and layout, no tables
};

}  // namespace throng::sim
