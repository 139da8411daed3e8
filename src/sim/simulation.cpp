#include "sim/simulation.h"

#include <algorithm>
#include <utility>

#include "core/timing.h"

namespace throng::sim {

AgentArrays arrays_of(CrowdState& c) {
  return {c.position.span(),       c.velocity.span(),       c.heading.span(),         c.radius.span(),
          c.pref_speed.span(),     c.path_start.span(),     c.goal.span(),            c.waypoint_begin.span(),
          c.waypoint_count.span(), c.waypoint_cursor.span(), c.group.span(),          c.flags.span(),
          c.arrival_time.span(),   c.waypoints.span(),      c.groups.span()};
}

Simulation::Simulation(const ScenarioSpec& spec, const ScenarioLimits& limits) : spec_(spec), scheduler_(spec.scheduler) {
  spec_.model.validate();
  world_ = World::build(spec_.world, spec_.model.query_radius(), limits, current_memory());
  crowd_ = upload_crowd(spawn_crowd(spec_, world_, limits), current_memory());
  bins_ = AgentGrid(spec_.model.query_radius());
  float max_radius = 0.0f;
  for (const GroupSpec& g : spec_.groups) max_radius = std::max(max_radius, g.radius);
  contact_bins_ = AgentGrid(std::min(4.0f * max_radius, spec_.model.query_radius()));
  const Memory m = current_memory();
  anchor_ = Buffer<glm::vec2>(crowd_.count, m);
  candidate_ = Buffer<glm::vec2>(crowd_.count, m);
  scratch_ = Buffer<glm::vec2>(crowd_.count, m);
}

void Simulation::step() {
  ScopedTimer timer("sim.step");
  const AgentArrays a = arrays_of(crowd_);
  bins_.rebuild(crowd_.position.span(), crowd_.flags.span());
  contact_bins_.rebuild(crowd_.position.span(), crowd_.flags.span());
  StepContext ctx;
  ctx.world = world_.view();
  ctx.bins = bins_.view();
  ctx.contact_bins = contact_bins_.view();
  ctx.model = spec_.model;
  ctx.dt = spec_.dt;
  ctx.time_after = static_cast<float>(static_cast<double>(steps_done_ + 1) * spec_.dt);
  copy_positions(crowd_.position.span(), anchor_.span());
  const Span<const glm::vec2> anchor = anchor_.span();
  if (scheduler_ == SchedulerKind::DoubleBuffer) {
    steer_double_buffer(ctx, a, candidate_.span());
    Span<glm::vec2> in = candidate_.span(), out = scratch_.span();
    for (std::int32_t k = 0; k < spec_.model.contact_iterations; ++k) {
      contacts_double_buffer(ctx, a, anchor, in, out);
      std::swap(in, out);
    }
    finalize_step(ctx, a, anchor, in);
  } else {
    steer_four_colour(ctx, a);
    for (std::int32_t k = 0; k < spec_.model.contact_iterations; ++k) contacts_four_colour(ctx, a, anchor);
    finalize_step(ctx, a, anchor, a.position);
  }
  ++steps_done_;
}

void Simulation::run(std::int64_t steps) {
  for (std::int64_t s = 0; s < steps; ++s) step();
}

Index Simulation::active_count() const {
  Index n = 0;
  for (std::uint8_t f : flags()) n += (f & kAgentActive) != 0;
  return n;
}

Index Simulation::arrived_count() const {
  Index n = 0;
  for (float t : arrival_times()) n += t >= 0.0f;
  return n;
}

}  // namespace throng::sim
