#include <algorithm>

#include "core/error.h"
#include "sim/grid.h"

namespace throng::sim {

Index grid_capacity_for(Index n) {
  Index c = 16;
  while (c < 2 * n) c *= 2;
  return c;
}

StaticGrid::StaticGrid(float cell_size, std::vector<std::pair<std::uint64_t, std::int32_t>> pairs, Memory memory)
    : cell_size_(cell_size) {
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  Index cells = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) cells += (i == 0 || pairs[i].first != pairs[i - 1].first);
  occupied_ = cells;
  const Index cap = grid_capacity_for(cells);
  mask_ = static_cast<std::uint64_t>(cap - 1);
  host_keys_.assign(static_cast<std::size_t>(cap), kEmptyCell);
  host_start_.assign(static_cast<std::size_t>(cap), 0);
  host_count_.assign(static_cast<std::size_t>(cap), 0);
  host_items_.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size();) {
    std::size_t j = i;
    while (j < pairs.size() && pairs[j].first == pairs[i].first) {
      host_items_[j] = pairs[j].second;
      ++j;
    }
    std::uint64_t s = home_slot(pairs[i].first, mask_);
    while (host_keys_[s] != kEmptyCell) s = (s + 1) & mask_;
    host_keys_[s] = pairs[i].first;
    host_start_[s] = static_cast<std::int32_t>(i);
    host_count_[s] = static_cast<std::int32_t>(j - i);
    i = j;
  }
  keys_ = Buffer<std::uint64_t>(std::span<const std::uint64_t>(host_keys_), memory);
  start_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_start_), memory);
  count_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_count_), memory);
  items_ = Buffer<std::int32_t>(std::span<const std::int32_t>(host_items_), memory);
}

GridView StaticGrid::view() const {
  return {cell_size_, mask_, keys_.span(), start_.span(), count_.span(), items_.span()};
}

GridView StaticGrid::host_view() const {
  return {cell_size_,
          mask_,
          Span<const std::uint64_t>(host_keys_.data(), static_cast<Index>(host_keys_.size())),
          Span<const std::int32_t>(host_start_.data(), static_cast<Index>(host_start_.size())),
          Span<const std::int32_t>(host_count_.data(), static_cast<Index>(host_count_.size())),
          Span<const std::int32_t>(host_items_.data(), static_cast<Index>(host_items_.size()))};
}

GridView AgentGrid::view() const {
  // Only the first binned_ items are agents (inactive ones are not binned).
  return {cell_size_, mask_, keys_.span(), start_.span(), count_.span(), items_.span().subspan(0, binned_)};
}

Index AgentGrid::occupied_cells() const {
  Index n = 0;
  for (std::uint64_t k : keys_.to_vector()) n += k != kEmptyCell;
  return n;
}

std::size_t AgentGrid::bytes() const {
  return static_cast<std::size_t>(keys_.size()) * sizeof(std::uint64_t) +
         static_cast<std::size_t>(start_.size() + count_.size() + cursor_.size() + items_.size() +
                                  slot_of_agent_.size()) *
             sizeof(std::int32_t);
}

}  // namespace throng::sim
