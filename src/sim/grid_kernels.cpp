// Per-step agent binning: the counting sort of the perception layer.
#include "core/parallel.h"
#include "core/reduce.h"
#include "sim/atomics.h"
#include "sim/grid.h"

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
}  // namespace

void AgentGrid::rebuild(Span<const glm::vec2> positions, Span<const std::uint8_t> flags) {
  const Index n = positions.size();
  const Index cap = grid_capacity_for(n);
  const Memory m = current_memory();
  if (keys_.size() != cap || keys_.memory() != m) {
    keys_ = Buffer<std::uint64_t>(cap, m);
    start_ = Buffer<std::int32_t>(cap, m);
    count_ = Buffer<std::int32_t>(cap, m);
    cursor_ = Buffer<std::int32_t>(cap, m);
  }
  if (items_.size() != n || items_.memory() != m) {
    items_ = Buffer<std::int32_t>(n, m);
    slot_of_agent_ = Buffer<std::int32_t>(n, m);
  }
  mask_ = static_cast<std::uint64_t>(cap - 1);
  const std::uint64_t mask = mask_;
  GridView cells;  // the cell geometry only (its tables are being built)
  cells.cell_size = cell_size_;
  cells.cell_size_y = cell_size_y_;
  if (periodic_.wraps()) cells.origin = periodic_.origin;
  cells.wrap_x = wrap_x_;
  cells.wrap_y = wrap_y_;
  auto keys = keys_.span();
  auto start = start_.span();
  auto count = count_.span();
  auto cursor = cursor_.span();
  auto items = items_.span();
  auto slot_of = slot_of_agent_.span();

  parallel_for(
      "sim.bin.clear", cap, THRONG_LAMBDA(Index s) {
        keys[s] = kEmptyCell;
        count[s] = 0;
        cursor[s] = 0;
      });
  // Histogram: find or claim the agent's cell slot, count it.
  parallel_for(
      "sim.bin.count", n, THRONG_LAMBDA(Index i) {
        if ((flags[i] & 1u) == 0) {
          slot_of[i] = -1;
          return;
        }
        const std::uint64_t key = cells.key_of(cells.cell_x(positions[i].x), cells.cell_y(positions[i].y));
        std::uint64_t s = home_slot(key, mask);
        for (;;) {
          std::uint64_t found = atomic_load(&keys[static_cast<Index>(s)]);
          if (found == kEmptyCell) found = atomic_compare_swap(&keys[static_cast<Index>(s)], kEmptyCell, key);
          if (found == kEmptyCell || found == key) break;
          s = (s + 1) & mask;
        }
        slot_of[i] = static_cast<std::int32_t>(s);
        atomic_fetch_add(&count[static_cast<Index>(s)], 1);
      });
  binned_ = exclusive_scan("sim.bin.scan", Span<const std::int32_t>(count), start);
  // Scatter in arbitrary order, then sort each run by agent index.
  parallel_for(
      "sim.bin.scatter", n, THRONG_LAMBDA(Index i) {
        const std::int32_t s = slot_of[i];
        if (s < 0) return;
        const std::int32_t k = atomic_fetch_add(&cursor[s], 1);
        items[start[s] + k] = static_cast<std::int32_t>(i);
      });
  parallel_for(
      "sim.bin.sort", cap, THRONG_LAMBDA(Index s) {
        const std::int32_t c = count[s];
        if (c > 1) sort_run(items.data() + start[s], c);
      });
}

}  // namespace throng::sim
