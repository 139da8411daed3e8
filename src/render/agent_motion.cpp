// Host-side checks of render/agent_motion.h (kernel in agent_motion_kernels.cpp).
#include <fmt/format.h>

#include <cmath>

#include "core/error.h"
#include "render/agent_motion.h"

namespace throng::render {

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
}

}  // namespace throng::render
