// Host-side checks of anim/between_steps.h (kernel in between_steps_kernels.cpp).
#include "anim/between_steps.h"

#include <fmt/format.h>

#include <cmath>

#include "core/error.h"

namespace throng::anim {

void InterpolateAgentsJob::validate() const {
  if (!(alpha >= 0.0f && alpha <= 1.0f)) throw Error("must be within 0..1", at_field("interpolate.alpha"));
  const Index n = agent_count();
  const auto check = [n](Index size, const char* field) {
    if (size != n) throw Error(fmt::format("size {} for {} agents", size, n), at_field(field));
  };
  check(previous_positions.size(), "interpolate.previous_positions");
  check(previous_headings.size(), "interpolate.previous_headings");
  check(headings.size(), "interpolate.headings");
  check(out_positions.size(), "interpolate.out_positions");
  check(out_headings.size(), "interpolate.out_headings");
  if (!out_velocities.empty()) {
    check(out_velocities.size(), "interpolate.out_velocities");
    if (!(step_seconds > 0.0f) || !std::isfinite(step_seconds))
      throw Error("must be positive seconds", at_field("interpolate.step_seconds"));
  }
}

}  // namespace throng::anim
