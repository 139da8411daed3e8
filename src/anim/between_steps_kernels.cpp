#include <glm/common.hpp>

#include "anim/between_steps.h"
#include "core/parallel.h"

namespace throng::anim {

void InterpolateAgentsJob::run() const {
  validate();
  const float a = alpha;
  const Span<const glm::vec2> p0 = previous_positions, p1 = positions;
  const Span<const float> h0 = previous_headings, h1 = headings;
  const Span<glm::vec2> out_p = out_positions;
  const Span<float> out_h = out_headings;
  const Span<glm::vec2> out_v = out_velocities;
  const float per_second = out_v.empty() ? 0.0f : 1.0f / step_seconds;
  parallel_for("anim.interpolate_agents", agent_count(), THRONG_LAMBDA(Index i) {
    constexpr float kPi = 3.14159265358979f, kTwoPi = 6.28318530717959f;
    out_p[i] = p0[i] + a * (p1[i] - p0[i]);
    if (!out_v.empty()) out_v[i] = per_second * (p1[i] - p0[i]);
    float turn = h1[i] - h0[i];
    turn -= kTwoPi * glm::floor((turn + kPi) / kTwoPi);  // into [-pi, pi)
    float h = h0[i] + a * turn;
    h -= kTwoPi * glm::floor((h + kPi) / kTwoPi);
    out_h[i] = h;
  });
}

}  // namespace throng::anim
