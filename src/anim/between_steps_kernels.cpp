#include <glm/common.hpp>

#include "anim/between_steps.h"
#include "core/math.h"
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
  const Periodic wrap = periodic;
  parallel_for(
      "anim.interpolate_agents", agent_count(), THRONG_LAMBDA(Index i) {
        const glm::vec2 from = wrap.near(p0[i], p1[i]);
        out_p[i] = wrap.wrap(from + a * (p1[i] - from));
        if (!out_v.empty()) out_v[i] = per_second * (p1[i] - from);
        const float turn = wrap_angle(h1[i] - h0[i]);
        out_h[i] = wrap_angle(h0[i] + a * turn);
      });
}

}  // namespace throng::anim
