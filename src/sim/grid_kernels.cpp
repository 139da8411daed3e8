// Per-step agent binning: the counting sort of the perception layer.
#include <algorithm>
#include <limits>

#include "core/exec.h"
#include "core/parallel.h"
#include "core/reduce.h"
#include "sim/agent_grid.h"
#include "sim/atomics.h"

namespace throng::sim {

namespace {
// Ascending sort of a short run of indices in place: insertion sort for small
// runs, heap sort (no recursion, O(n log n)) for crowded cells.
THRONG_HOST_DEVICE inline void sift_down(std::int32_t* a, std::int32_t root, std::int32_t n) {
  for (;;) {
    std::int32_t child = 2 * root + 1;
    if (child >= n) return;
    if (child + 1 < n && a[child + 1] > a[child]) ++child;
    if (a[root] >= a[child]) return;
    const std::int32_t t = a[root];
    a[root] = a[child];
    a[child] = t;
    root = child;
  }
}
THRONG_HOST_DEVICE inline void sort_run(std::int32_t* a, std::int32_t n) {
  if (n <= 32) {
    for (std::int32_t i = 1; i < n; ++i) {
      const std::int32_t v = a[i];
      std::int32_t j = i - 1;
      while (j >= 0 && a[j] > v) {
        a[j + 1] = a[j];
        --j;
      }
      a[j + 1] = v;
    }
    return;
  }
  for (std::int32_t i = n / 2 - 1; i >= 0; --i) sift_down(a, i, n);
  for (std::int32_t end = n - 1; end > 0; --end) {
    const std::int32_t t = a[0];
    a[0] = a[end];
    a[end] = t;
    sift_down(a, 0, end);
  }
}

// The box of the cells holding active agents (x0 > x1 when none does).
struct CellBox {
  std::int32_t x0, y0, x1, y1;
};
struct CellOfAgent {
  GridView cells;
  Span<const glm::vec2> positions;
  Span<const std::uint8_t> flags;
  THRONG_HOST_DEVICE CellBox operator()(Index i) const {
    if ((flags[i] & 1u) == 0) return {kCellCoordLimit, kCellCoordLimit, -kCellCoordLimit, -kCellCoordLimit};
    std::int32_t cx = cells.cell_x(positions[i].x), cy = cells.cell_y(positions[i].y);
    cells.wrap(cx, cy);
    return {cx, cy, cx, cy};
  }
};
struct Enclose {
  THRONG_HOST_DEVICE CellBox operator()(const CellBox& a, const CellBox& b) const {
    return {a.x0 < b.x0 ? a.x0 : b.x0, a.y0 < b.y0 ? a.y0 : b.y0, a.x1 > b.x1 ? a.x1 : b.x1, a.y1 > b.y1 ? a.y1 : b.y1};
  }
};

// The key of a dense grid's slot s. Slots are numbered in 32 bits
// (slot_of): a 32-bit division.
THRONG_HOST_DEVICE inline std::uint64_t dense_slot_key(const GridView& cells, Index s) {
  const auto s32 = static_cast<std::uint32_t>(s), nx = static_cast<std::uint32_t>(cells.dense_nx);
  const auto x = static_cast<std::int32_t>(s32 % nx), y = static_cast<std::int32_t>(s32 / nx);
  return cell_key(cells.dense_x0 + x, cells.dense_y0 + y);
}

// The slot of each active agent's cell (-1 for inactive agents), its count
// raised unless `count` is empty. A dense grid's slot is the cell's index in
// the box, no hashing; a hashed grid finds or claims the cell's slot by
// probing.
struct CountCells {
  GridView cells;
  Span<const glm::vec2> positions;
  Span<const std::uint8_t> flags;
  Span<std::uint64_t> keys;
  Span<std::int32_t> count, slot_of;
  THRONG_HOST_DEVICE void operator()(Index i) const {
    if ((flags[i] & 1u) == 0) {
      slot_of[i] = -1;
      return;
    }
    std::int32_t cx = cells.cell_x(positions[i].x), cy = cells.cell_y(positions[i].y);
    cells.wrap(cx, cy);
    const Index s = cells.dense_nx > 0 ? cells.dense_slot(cx, cy) : claim(cells.key_of(cx, cy));
    slot_of[i] = static_cast<std::int32_t>(s);
    if (!count.empty()) atomic_fetch_add(&count[s], 1);
  }
  THRONG_HOST_DEVICE Index claim(std::uint64_t key) const {
    std::uint64_t s = home_slot(key, cells.mask);
    for (;;) {
      std::uint64_t found = atomic_load(&keys[static_cast<Index>(s)]);
      if (found == kEmptyCell) found = atomic_compare_swap(&keys[static_cast<Index>(s)], kEmptyCell, key);
      if (found == kEmptyCell || found == key) return static_cast<Index>(s);
      s = (s + 1) & cells.mask;
    }
  }
};
}  // namespace

void AgentGrid::rebuild(Span<const glm::vec2> positions, Span<const std::uint8_t> flags, bool allow_dense) {
  const Index n = positions.size();
  const Index cap = grid_capacity_for(n);
  const Memory m = current_memory();
  if (items_.size() != n || items_.memory() != m) {
    items_ = Buffer<std::int32_t>(n, m);
    slot_of_agent_ = Buffer<std::int32_t>(n, m);
  }
  mask_ = static_cast<std::uint64_t>(cap - 1);
  table_ = cap;
  GridView cells;  // the cell geometry only (its tables are being built)
  cells.cell_size = cell_size_;
  cells.cell_size_y = cell_size_y_;
  if (periodic_.wraps()) cells.origin = periodic_.origin;
  cells.wrap_x = wrap_x_;
  cells.wrap_y = wrap_y_;
  cells.mask = mask_;
  choose_layout(cells, positions, flags, allow_dense);
  const Index slots = this->slots();
  // The tables grow to the largest layout asked for (a hashed table, or a
  // dense box within the limit) and stay.
  if (keys_.size() < slots || keys_.memory() != m) {
    keys_ = Buffer<std::uint64_t>(slots, m);
    start_ = Buffer<std::int32_t>(slots, m);
    count_ = Buffer<std::int32_t>(slots, m);
    cursor_ = Buffer<std::int32_t>(slots, m);
  }
  auto keys = keys_.span().subspan(0, slots);
  auto start = start_.span().subspan(0, slots);
  auto count = count_.span().subspan(0, slots);
  auto cursor = cursor_.span().subspan(0, slots);
  auto items = items_.span();
  auto slot_of = slot_of_agent_.span();

  // On the CPU, count and place by slot range (BinCounting): no atomic
  // but the hashed grid's claims, and runs in index order as placed. Its
  // cursors are reset where counted (a sparse box has far more cells than
  // agents).
  const bool by_range = counting_ == BinCounting::BySlotRange && current_backend() == Backend::Cpu;
  parallel_for(
      "sim.bin.clear", slots, THRONG_LAMBDA(Index s) {
        keys[s] = kEmptyCell;
        count[s] = 0;
        if (!by_range) cursor[s] = 0;
      });
  if (by_range)
    count_traffic("sim.bin.clear", keys, count);
  else
    count_traffic("sim.bin.clear", keys, count, cursor);
  if (by_range) {
    parallel_for("sim.bin.slot", n, CountCells{cells, positions, flags, keys, {}, slot_of});
    count_traffic("sim.bin.slot", positions, flags, keys, slot_of);
    binned_ = place_by_slot_range(cells, slots);
  } else {
    parallel_for("sim.bin.count", n, CountCells{cells, positions, flags, keys, count, slot_of});
    count_traffic("sim.bin.count", positions, flags, keys, count, count, slot_of);
    binned_ = exclusive_scan("sim.bin.scan", Span<const std::int32_t>(count), start);
    count_traffic("sim.bin.scan", count, start);
    // Scatter in arbitrary order; the next pass sorts each run by agent index.
    parallel_for(
        "sim.bin.scatter", n, THRONG_LAMBDA(Index i) {
          const std::int32_t s = slot_of[i];
          if (s < 0) return;
          const std::int32_t k = atomic_fetch_add(&cursor[s], 1);
          items[start[s] + k] = static_cast<std::int32_t>(i);
        });
    count_traffic("sim.bin.scatter", slot_of, cursor, cursor, start, items);
  }
  if (by_range) return;
  // Sort the atomic path's runs by agent index, and give a dense grid's
  // occupied slots their keys, for the slot-by-slot launches of the four
  // colours.
  const bool is_dense = dense();
  parallel_for(
      "sim.bin.sort", slots, THRONG_LAMBDA(Index s) {
        const std::int32_t c = count[s];
        if (c > 1) sort_run(items.data() + start[s], c);
        if (is_dense && c > 0) keys[s] = dense_slot_key(cells, s);
      });
  count_traffic("sim.bin.sort", keys, count, start, items, items);
}

// A few tasks, each over every agent: reading slot_of again per task costs
// less than a locked add per agent, but not for small crowds. Host code
// (host_parallel_for) kept in this file so that exclusive_scan and its
// kernels are compiled by nvcc, with their CUDA branch, in CUDA builds.
Index AgentGrid::place_by_slot_range(const GridView& cells, Index slots) {
  const Index n = slot_of_agent_.size();
  const Index tasks = std::max<Index>(1, std::min<Index>({n / 8192, current_threads(), slots}));
  const Span<const std::int32_t> slot_of = slot_of_agent_.span();
  const Span<std::int32_t> count = count_.span().subspan(0, slots), start = start_.span().subspan(0, slots),
                           cursor = cursor_.span().subspan(0, slots), items = items_.span();
  // Task t's slots: [first(t), first(t + 1)). An agent not binned has slot -1.
  const auto first = [&](Index t) { return slots * t / tasks; };
  const auto in = [](std::int32_t s, Index lo, Index hi) {
    return static_cast<std::uint64_t>(s - lo) < static_cast<std::uint64_t>(hi - lo);
  };
  // A dense grid's occupied slots get their keys here (the hashed grid's
  // were claimed while finding the slots), for the slot-by-slot launches of
  // the four colours: a pass over every slot of a sparse box cost more.
  const bool is_dense = dense();
  const Span<std::uint64_t> keys = keys_.span();
  host_parallel_for("sim.bin.count", tasks, [&](Index t) {
    const Index lo = first(t), hi = first(t + 1);
    for (Index i = 0; i < n; ++i) {
      const std::int32_t s = slot_of[i];
      if (!in(s, lo, hi) || count[s]++ > 0) continue;
      cursor[s] = 0;
      if (is_dense) keys[s] = dense_slot_key(cells, s);
    }
  });
  const Index binned = exclusive_scan("sim.bin.scan", Span<const std::int32_t>(count), start);
  host_parallel_for("sim.bin.place", tasks, [&](Index t) {
    const Index lo = first(t), hi = first(t + 1);
    for (Index i = 0; i < n; ++i) {
      const std::int32_t s = slot_of[i];
      if (in(s, lo, hi)) items[start[s] + cursor[s]++] = static_cast<std::int32_t>(i);
    }
  });
  for (Index t = 0; t < tasks; ++t) {  // every task reads every agent's slot
    count_traffic("sim.bin.count", slot_of);
    count_traffic("sim.bin.place", slot_of);
  }
  count_traffic("sim.bin.count", count, count);
  count_traffic("sim.bin.scan", count, start);
  count_traffic("sim.bin.place", start, cursor, cursor, items);
  return binned;
}

// Dense when the box of the occupied cells (every cell of a wrapping axis)
// has no more cells than the hash table would have slots, or than the dense
// box limit per agent; records the box in `cells`.
void AgentGrid::choose_layout(GridView& cells, Span<const glm::vec2> positions, Span<const std::uint8_t> flags,
                              bool allow_dense) {
  dense_nx_ = dense_ny_ = 0;
  if (allow_dense) {
    const CellBox none{kCellCoordLimit, kCellCoordLimit, -kCellCoordLimit, -kCellCoordLimit};
    CellBox box =
        parallel_reduce("sim.bin.box", positions.size(), none, CellOfAgent{cells, positions, flags}, Enclose{});
    count_traffic("sim.bin.box", positions, flags);
    if (wrap_x_ > 0) box.x0 = 0, box.x1 = wrap_x_ - 1;
    if (wrap_y_ > 0) box.y0 = 0, box.y1 = wrap_y_ - 1;
    const std::int64_t nx = std::int64_t{box.x1} - box.x0 + 1, ny = std::int64_t{box.y1} - box.y0 + 1;
    // (Slots are numbered in 32 bits: slot_of.)
    const Index most = std::min<Index>(std::max<Index>(table_, dense_box_limit_ * positions.size()),
                                       std::numeric_limits<std::int32_t>::max());
    if (box.x0 <= box.x1 && box.y0 <= box.y1 && nx * ny <= most) {
      dense_x0_ = box.x0, dense_y0_ = box.y0;
      dense_nx_ = static_cast<std::int32_t>(nx), dense_ny_ = static_cast<std::int32_t>(ny);
    }
  }
  cells.dense_x0 = dense_x0_, cells.dense_y0 = dense_y0_;
  cells.dense_nx = dense_nx_, cells.dense_ny = dense_ny_;
}

}  // namespace throng::sim
