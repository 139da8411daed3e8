// Lane order of counterflows (metrics.h): a host-side O(N^2) count, meant
// for tests and validation runs of a few thousand agents.
#include <cmath>

#include "sim/crowd.h"
#include "sim/metrics.h"

namespace throng::sim {

LaneOrder lane_order(const std::vector<glm::vec2>& positions, const std::vector<glm::vec2>& goals,
                     const std::vector<std::uint8_t>& flags, glm::vec2 axis, float band, float reach,
                     const Periodic& periodic) {
  const glm::vec2 across = perp_left(axis);
  auto heading_sign = [&](std::size_t i) { return dot2(goals[i] - positions[i], axis) >= 0.0f ? 1 : -1; };
  LaneOrder out;
  double sum = 0;
  for (std::size_t j = 0; j < positions.size(); ++j) {
    if ((flags[j] & kAgentActive) == 0) continue;
    const int mine = heading_sign(j);
    double same = 0, other = 0;
    for (std::size_t k = 0; k < positions.size(); ++k) {
      if (k == j || (flags[k] & kAgentActive) == 0) continue;
      const glm::vec2 d = periodic.near(positions[k], positions[j]) - positions[j];
      if (std::fabs(dot2(d, across)) >= band || std::fabs(dot2(d, axis)) >= reach) continue;
      (heading_sign(k) == mine ? same : other) += 1.0;
    }
    if (same + other == 0.0) continue;
    const double phi = (same - other) / (same + other);
    sum += phi * phi;
    ++out.counted;
  }
  out.order = out.counted > 0 ? sum / static_cast<double>(out.counted) : 0.0;
  return out;
}

}  // namespace throng::sim
