// The neighbours a sense stage reads: their state (NeighbourArrays), the
// candidates of an agent (from the bins' cells, or every agent for the
// O(N^2) reference) and the sift of those within a range
// (for_each_neighbour). Host+device.
#pragma once

#include "core/periodic.h"
#include "core/span.h"
#include "sim/crowd.h"
#include "sim/geometry.h"
#include "sim/grid.h"

namespace throng::sim {

// Read-only view of the neighbours' state, element j of each array being
// agent j, or, with `ids` given, the steering bins' item j (a copy gathered
// in item order, element k holding agent ids[k]: the double buffer's sense
// stage), so that the candidates of a 3 x 3 are a few contiguous runs of
// every array rather than reads all over the crowd's. Models index
// neighbours by element and ask id(j) for the agent itself. Models read a
// neighbour's position through at(j, p): over a periodic area, the image
// nearest p.
struct NeighbourArrays {
  Span<const glm::vec2> position;
  Span<const glm::vec2> velocity;
  Span<const float> radius;
  Span<const std::uint8_t> flags;
  Periodic periodic;
  Span<const std::int32_t> ids = {};  // the agent of each element (the bins' items); empty: element j is agent j
  THRONG_HOST_DEVICE THRONG_INLINE glm::vec2 at(Index j, glm::vec2 p) const { return periodic.near(position[j], p); }
  THRONG_HOST_DEVICE THRONG_INLINE Index id(Index j) const { return ids.size() > 0 ? Index{ids[j]} : j; }
};

// The candidate neighbours of a sense stage: for_each_candidate(c) calls
// c(j, at) for every active agent that may be a neighbour, in a fixed
// order, j its element of the neighbour arrays and `at` its position as
// stored. Below: the bins' items (in their order; every binned agent is
// active), of one run of `count` from `start` or of every run of `cells`;
// and every agent (the O(N^2) reference).
template <class Fn>
THRONG_HOST_DEVICE inline void for_each_binned_candidate(const GridView& bins, std::int32_t start, std::int32_t count,
                                                         const NeighbourArrays& n, const Fn& fn) {
  const bool in_items = n.ids.size() > 0;
  for (std::int32_t k = start; k < start + count; ++k) {
    const Index j = in_items ? Index{k} : Index{bins.items[k]};
    fn(j, n.position[j]);
  }
}
template <int kCells, class Fn>
THRONG_HOST_DEVICE inline void for_each_binned_candidate(const GridView& bins, const CellRuns<kCells>& cells,
                                                         const NeighbourArrays& n, const Fn& fn) {
  for (int r = 0; r < cells.runs; ++r) for_each_binned_candidate(bins, cells.start[r], cells.count[r], n, fn);
}
template <class Fn>
THRONG_HOST_DEVICE inline void for_each_active_candidate(const NeighbourArrays& n, const Fn& fn) {
  for (Index j = 0; j < n.position.size(); ++j)
    if ((n.flags[j] & kAgentActive) != 0) fn(j, n.position[j]);
}

// Calls fn(j, q) for every candidate j whose position q (its image
// nearest p) keep(j, q) accepts, in the order for_each_candidate visits
// them. The candidates are first sifted without a branch into a batch
// (keep is evaluated for every one, so it should be a few comparisons
// without branches of its own), then the batch is visited: most
// candidates fail the test, and a branch on each mispredicts often enough
// to cost more than the test itself.
inline constexpr int kNeighbourBatch = 32;
template <class ForEachCandidate, class Keep, class Fn>
THRONG_HOST_DEVICE inline void for_each_sifted(const ForEachCandidate& for_each_candidate, const NeighbourArrays& n,
                                               glm::vec2 p, const Keep& keep, const Fn& fn) {
  std::int32_t batch[kNeighbourBatch];
  glm::vec2 image[kNeighbourBatch];
  int found = 0;
  auto visit = [&]() {
    for (int k = 0; k < found; ++k) fn(static_cast<Index>(batch[k]), image[k]);
    found = 0;
  };
  for_each_candidate([&](Index j, glm::vec2 at) {
    const glm::vec2 q = n.periodic.near(at, p);
    batch[found] = static_cast<std::int32_t>(j);
    image[found] = q;
    found += keep(j, q) ? 1 : 0;
    if (found == kNeighbourBatch) visit();
  });
  visit();
}

// Calls fn(j, q) for every candidate j other than `self` (the agent's own
// element of the neighbour arrays) whose position q (its image nearest p)
// lies closer to p than sqrt(range2), in the order for_each_candidate
// visits them (sifted: for_each_sifted).
template <class ForEachCandidate, class Fn>
THRONG_HOST_DEVICE inline void for_each_neighbour(const ForEachCandidate& for_each_candidate, Index self,
                                                  const NeighbourArrays& n, glm::vec2 p, float range2, const Fn& fn) {
  for_each_sifted(
      for_each_candidate, n, p, [&](Index j, glm::vec2 q) { return (j != self) & (length2(q - p) < range2); }, fn);
}

}  // namespace throng::sim
