#include <algorithm>
#include <limits>

#include <cmath>
#include <fmt/format.h>

#include "core/error.h"
#include "sim/agent_grid.h"
#include "sim/grid.h"

namespace throng::sim {

Index grid_capacity_for(Index n) {
  Index c = 16;
  while (c < 2 * n) c *= 2;
  return c;
}

StaticGrid::StaticGrid(float cell_size, std::vector<std::pair<std::uint64_t, std::int32_t>> pairs, Memory memory,
                       bool allow_dense)
    : cell_size_(cell_size) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  Index cells = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) cells += (i == 0 || pairs[i].first != pairs[i - 1].first);
  occupied_ = cells;
  const Index cap = grid_capacity_for(cells);
  mask_ = static_cast<std::uint64_t>(cap - 1);
  if (allow_dense) choose_dense_box(pairs, 2 * cap);
  const bool dense = dense_nx_ > 0;
  // A dense grid's items run slot by slot (row by row), as AgentGrid's.
  const GridView box = geometry();
  const auto slot_of = [&](std::uint64_t key) {
    return static_cast<std::uint64_t>(box.dense_slot(key_cx(key), key_cy(key)));
  };
  if (dense)
    std::stable_sort(pairs.begin(), pairs.end(),
                     [&](const auto& a, const auto& b) { return slot_of(a.first) < slot_of(b.first); });
  const auto slots = static_cast<std::size_t>(dense ? Index{dense_nx_} * dense_ny_ : cap);
  host_keys_.assign(slots, kEmptyCell);
  host_start_.assign(slots, 0);
  host_count_.assign(slots, 0);
  host_items_.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size();) {
    std::size_t j = i;
    while (j < pairs.size() && pairs[j].first == pairs[i].first) {
      host_items_[j] = pairs[j].second;
      ++j;
    }
    std::uint64_t s = dense ? slot_of(pairs[i].first) : home_slot(pairs[i].first, mask_);
    while (!dense && host_keys_[s] != kEmptyCell) s = (s + 1) & mask_;
    host_keys_[s] = pairs[i].first;
    host_start_[s] = static_cast<std::int32_t>(i);
    host_count_[s] = static_cast<std::int32_t>(j - i);
    i = j;
  }
  // Every dense slot's start set, an empty one's where its items would be (GridView).
  for (std::size_t s = 1; dense && s < slots; ++s)
    if (host_count_[s] == 0) host_start_[s] = host_start_[s - 1] + host_count_[s - 1];
  keys_ = Buffer<std::uint64_t>(std::span<const std::uint64_t>(host_keys_), memory);
  start_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_start_), memory);
  count_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_count_), memory);
  items_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_items_), memory);
}

// Dense when the box of the occupied cells has at most `most` cells.
void StaticGrid::choose_dense_box(const std::vector<std::pair<std::uint64_t, std::int32_t>>& pairs, Index most) {
  if (pairs.empty()) return;
  std::int32_t x0 = kCellCoordLimit, y0 = kCellCoordLimit, x1 = -kCellCoordLimit, y1 = -kCellCoordLimit;
  for (const auto& [key, item] : pairs) {
    x0 = std::min(x0, key_cx(key)), x1 = std::max(x1, key_cx(key));
    y0 = std::min(y0, key_cy(key)), y1 = std::max(y1, key_cy(key));
  }
  const std::int64_t nx = std::int64_t{x1} - x0 + 1, ny = std::int64_t{y1} - y0 + 1;
  // (Slots are numbered in 32 bits, as AgentGrid's.)
  if (nx * ny > std::min<std::int64_t>(most, std::numeric_limits<std::int32_t>::max())) return;
  dense_x0_ = x0, dense_y0_ = y0;
  dense_nx_ = static_cast<std::int32_t>(nx), dense_ny_ = static_cast<std::int32_t>(ny);
}

GridView StaticGrid::geometry() const {
  GridView v;
  v.cell_size = v.cell_size_y = cell_size_;
  v.mask = mask_;
  v.dense_x0 = dense_x0_, v.dense_y0 = dense_y0_;
  v.dense_nx = dense_nx_, v.dense_ny = dense_ny_;
  return v;
}

GridView StaticGrid::view() const {
  GridView v = geometry();
  v.keys = keys_.span();
  v.start = start_.span();
  v.count = count_.span();
  v.items = items_.span();
  return v;
}

GridView StaticGrid::host_view() const {
  GridView v = geometry();
  v.keys = Span<const std::uint64_t>(host_keys_.data(), static_cast<Index>(host_keys_.size()));
  v.start = Span<const std::int32_t>(host_start_.data(), static_cast<Index>(host_start_.size()));
  v.count = Span<const std::int32_t>(host_count_.data(), static_cast<Index>(host_count_.size()));
  v.items = Span<const std::int32_t>(host_items_.data(), static_cast<Index>(host_items_.size()));
  return v;
}

namespace {
// Cells along one wrapping axis: an even number, at least four, each at
// least `side` wide.
std::int32_t cells_per_period(float period, float side, const char* axis) {
  const double fit = std::floor(static_cast<double>(period) / static_cast<double>(side));
  if (!(fit >= 4.0))
    throw Error(fmt::format("the period along {} ({:.3g} m) must be at least four neighbour cells long ({:.3g} m): "
                            "lengthen the walkable area or lower model.max_speed",
                            axis, period, 4.0 * side),
                at_field("world.periodic"));
  const auto n = static_cast<std::int32_t>(std::min(fit, 1.0e6));
  return n - (n & 1);
}
}  // namespace

AgentGrid::AgentGrid(float cell_size, const Periodic& periodic)
    : asked_(cell_size), cell_size_(cell_size), cell_size_y_(cell_size), periodic_(periodic) {
  if (periodic.period.x > 0.0f) {
    wrap_x_ = cells_per_period(periodic.period.x, cell_size, "x");
    cell_size_ = periodic.period.x / static_cast<float>(wrap_x_);
  }
  if (periodic.period.y > 0.0f) {
    wrap_y_ = cells_per_period(periodic.period.y, cell_size, "y");
    cell_size_y_ = periodic.period.y / static_cast<float>(wrap_y_);
  }
}

GridView AgentGrid::view() const {
  GridView v;
  v.cell_size = cell_size_;
  v.cell_size_y = cell_size_y_;
  if (periodic_.wraps()) v.origin = periodic_.origin;
  v.wrap_x = wrap_x_;
  v.wrap_y = wrap_y_;
  v.mask = mask_;
  v.dense_x0 = dense_x0_, v.dense_y0 = dense_y0_;
  v.dense_nx = dense_nx_, v.dense_ny = dense_ny_;
  v.keys = keys_.span().subspan(0, slots());
  v.start = start_.span().subspan(0, slots());
  v.count = count_.span().subspan(0, slots());
  // Only the first binned_ items are agents (inactive ones are not binned).
  v.items = items_.span().subspan(0, binned_);
  return v;
}

Index AgentGrid::occupied_cells() const {
  Index n = 0;
  const std::vector<std::uint64_t> keys = keys_.to_vector();
  for (Index s = 0; s < slots(); ++s) n += keys[static_cast<std::size_t>(s)] != kEmptyCell;
  return n;
}

std::size_t AgentGrid::bytes() const {
  return static_cast<std::size_t>(keys_.size()) * sizeof(std::uint64_t) +
         static_cast<std::size_t>(start_.size() + count_.size() + cursor_.size() + items_.size() +
                                  slot_of_agent_.size()) *
             sizeof(std::int32_t);
}

}  // namespace throng::sim
