#include "sim/simulation.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "core/exec.h"
#include "core/parallel.h"
#include "core/timing.h"

namespace throng::sim {

AgentArrays arrays_of(CrowdState& c) {
  return {c.position.span(),       c.velocity.span(),        c.heading.span(),       c.radius.span(),
          c.pref_speed.span(),     c.path_start.span(),      c.goal.span(),          c.waypoint_begin.span(),
          c.waypoint_count.span(), c.waypoint_cursor.span(), c.waypoint_goal.span(), c.group.span(),
          c.flags.span(),          c.arrival_time.span(),    c.waypoints.span(),     c.waypoint_stage.span(),
          c.stages.span(),         c.groups.span(),          c.start_time.span()};
}

Simulation::Simulation(const ScenarioSpec& spec, const SimulationOptions& options)
    : spec_(spec),
      scheduler_(spec.scheduler),
      neighbours_(options.neighbours),
      dense_bins_(options.dense_bins),
      skip_idle_contact_passes_(options.skip_idle_contact_passes),
      skip_far_cells_walking_along_(options.skip_far_cells_walking_along) {
  spec_.model.validate();
  world_ = World::build(spec_.world, spec_.model.query_radius(), options.limits, current_memory());
  const CrowdHost host = spawn_crowd(spec_, world_, options.limits, options.planner);
  for (std::size_t i = 0; i < host.flags.size(); ++i)
    if ((host.flags[i] & kAgentPending) != 0)
      pending_.push_back({host.start_time[i], static_cast<Index>(i), host.position[i], host.radius[i]});
  std::sort(pending_.begin(), pending_.end(), [](const PendingEntry& a, const PendingEntry& b) {
    return a.time < b.time || (a.time == b.time && a.agent < b.agent);
  });
  crowd_ = upload_crowd(host, current_memory());
  exits_ = ExitChooser(spec_, host);
  replan_ = Replanner(spec_, host, options.replanner);
  if (options.fields != nullptr) build_fields(*options.fields);
  if (options.fields != nullptr && spec_.planning == PlanningKind::Quickest && fields_.count() > 0)
    quickest_builder_ = options.fields;
  exits_.use_fields(fields_.host_view());
  bins_ = AgentGrid(spec_.model.query_radius(), world_.periodic());
  for (const GroupSpec& g : spec_.groups) max_radius_ = std::max(max_radius_, g.radius);
  contact_bins_ = AgentGrid(std::min(4.0f * max_radius_, spec_.model.query_radius()), world_.periodic());
  bins_.set_counting(options.bin_counting);
  contact_bins_.set_counting(options.bin_counting);
  bins_.set_dense_box_limit(kDenseCellsPerItem);
  contact_bins_.set_dense_box_limit(kDenseCellsPerItem);
  const Memory m = current_memory();
  anchor_ = Buffer<glm::vec2>(crowd_.count, m);
  candidate_ = Buffer<glm::vec2>(crowd_.count, m);
  scratch_ = Buffer<glm::vec2>(crowd_.count, m);
  sensed_ = Buffer<glm::vec2>::zeros(crowd_.count, m);      // inactive agents are never sensed
  move_cells_ = Buffer<MoveCells>::zeros(crowd_.count, m);  // nor given move cells
  contact_depth_ = Buffer<float>::zeros(crowd_.count, m);
  moved_before_ = Buffer<std::int32_t>(crowd_.count + 1, m);
  binned_position_ = Buffer<glm::vec2>(crowd_.count, m);
  binned_velocity_ = Buffer<glm::vec2>(crowd_.count, m);
  binned_radius_ = Buffer<float>(crowd_.count, m);
  binned_flags_ = Buffer<std::uint8_t>(crowd_.count, m);
  if (spec_.model.kind != ModelKind::Priority) {
    aim_ = Buffer<AgentAim>::zeros(crowd_.count, m);
    binned_aim_ = Buffer<AgentAim>::zeros(crowd_.count, m);
  }
  // (the steering bins' slots: at most their hash table's capacity)
  if (summarises_far_cells()) cell_headings_ = Buffer<CellHeadings>(grid_capacity_for(crowd_.count), m);
}

StepContext Simulation::context() const {
  StepContext ctx;
  ctx.world = world_.view();
  ctx.bins = bins_.view();
  ctx.contact_bins = contact_bins_.view();
  ctx.model = spec_.model;
  ctx.dt = spec_.dt;
  ctx.time_after = static_cast<float>(static_cast<double>(steps_done_ + 1) * spec_.dt);
  // The move stage accepts at most 0.95 radius per step (simulation_kernels.cpp).
  ctx.bin_slack = scheduler_ == SchedulerKind::FourColour ? max_radius_ : 0.0f;
  ctx.fields = fields_.view();
  ctx.periodic = world_.periodic();
  return ctx;
}

namespace {

// The walkable area of each density cell: the cell's area times the share
// of a 5 x 5 lattice of points in it that lie in free space.
std::vector<float> free_area_of(const World& world, const CrowdDensity& cells) {
  constexpr int kSamples = 5;
  std::vector<float> area(cells.density.size(), 0.0f);
  host_parallel_for("sim.quickest_fields.free_area", cells.ny, [&](Index j) {
    for (std::int32_t i = 0; i < cells.nx; ++i) {
      int free = 0;
      for (int v = 0; v < kSamples; ++v)
        for (int u = 0; u < kSamples; ++u) {
          const glm::vec2 q(static_cast<float>(i) + (static_cast<float>(u) + 0.5f) / kSamples,
                            static_cast<float>(j) + (static_cast<float>(v) + 0.5f) / kSamples);
          free += world.in_free_space(cells.origin + q * cells.cell) ? 1 : 0;
        }
      area[static_cast<std::size_t>(j) * static_cast<std::size_t>(cells.nx) + static_cast<std::size_t>(i)] =
          cells.cell * cells.cell * static_cast<float>(free) / (kSamples * kSamples);
    }
  });
  return area;
}

}  // namespace

// One field per target of the groups that walk to one point or choose among
// exits (their own waypoints, or goals that differ per agent, keep the
// straight legs), for the largest radius heading there, in group order.
void Simulation::build_fields(const FieldBuilder& builder) {
  std::vector<FieldTarget> targets;
  // (A door line's field is seeded along it; fields are found by their
  // middle, so the first target at a point decides its extent.)
  auto add = [&](glm::vec2 t, glm::vec2 half, float radius) {
    for (FieldTarget& known : targets)
      if (known.point == t) {
        known.radius = std::max(known.radius, radius);
        return;
      }
    targets.push_back({t, half, radius});
  };
  for (const GroupSpec& g : spec_.groups) {
    if (!g.waypoints.empty() || g.count == 0) continue;
    if (g.goal.kind == GoalSpec::Kind::Point) add(g.goal.value, glm::vec2(0.0f), g.radius);
    if (g.goal.kind == GoalSpec::Kind::Exits)
      for (const ExitSpec& e : g.goal.exits) add(e.point, e.half, g.radius);
  }
  // Weighed fields are built again on their first grid: where the free
  // space grows with the targets (a world without a walkable region), the
  // first pass grows it to hold them all and the second lays every field
  // over it, at the density of nobody (the plain distances).
  const bool weighed = spec_.planning == PlanningKind::Quickest;
  const CrowdDensity nobody;
  for (int pass = weighed && !world_.has_walkable() ? 0 : 1; pass < 2; ++pass) {
    for (const FieldTarget& t : targets) {
      FieldData f = builder.build(world_, t.point, t.radius, weighed ? &nobody : nullptr, t.half);
      if (f.grid.nx == 0 || pass == 0) continue;  // none: nothing in the way
      fields_.add(std::move(f));
      field_targets_.push_back(t);
    }
  }
  fields_.upload();
}

// The density map: over every field's grid, in cells of 1 m (coarser past a
// million cells), each cell's walkable area measured once.
void Simulation::reweigh_fields() {
  if (density_cells_.nx == 0) {
    Aabb extent;
    for (std::int32_t k = 0; k < fields_.count(); ++k) {
      const FieldGrid& g = fields_.grid(k);
      extent.add(g.origin);
      extent.add(g.origin + glm::vec2(static_cast<float>(g.nx - 1), static_cast<float>(g.ny - 1)) * g.cell);
    }
    const float cell = std::max(1.0f, std::sqrt(extent.size().x * extent.size().y / 1e6f));
    density_cells_ = density_cells(extent, cell);
    density_free_area_ = free_area_of(world_, density_cells_);
  }
  CrowdDensity density = density_cells_;
  count_crowd(density, positions(), flags(), density_free_area_);
  // Each field is marched on its own (fast marching is serial): in
  // parallel over the fields, the same fields on any thread count.
  std::vector<FieldData> weighed(field_targets_.size());
  host_parallel_for("sim.quickest_fields.march", static_cast<Index>(weighed.size()), [&](Index k) {
    const auto i = static_cast<std::size_t>(k);
    const FieldTarget& t = field_targets_[i];
    weighed[i] = quickest_builder_->build(world_, t.point, t.radius, &density, t.half);
  });
  for (std::size_t k = 0; k < weighed.size(); ++k) fields_.replace(static_cast<std::int32_t>(k), weighed[k]);
  fields_.upload();
  fields_weighed_at_ = steps_done_;
}

void Simulation::step() {
  ScopedTimer timer("sim.step");
  if (quickest_builder_) {
    const auto every = std::max<std::int64_t>(1, std::llround(kQuickestRefreshS / spec_.dt));
    if (fields_weighed_at_ < 0 || steps_done_ - fields_weighed_at_ >= every) {
      ScopedTimer weigh("sim.quickest_fields");
      reweigh_fields();
    }
  }
  if (!exits_.empty()) {
    ScopedTimer choose("sim.exit_choice");
    exits_.update(time(), crowd_);
  }
  if (!replan_.empty()) {
    ScopedTimer replan("sim.replan");
    replan_.update(time(), world_, crowd_);
  }
  bin();
  if (!pending_.empty() && admit_entries()) bin();
  const StepContext ctx = context();
  copy_positions(crowd_.position.span(), anchor_.span());
  sense_and_steer(ctx);
  move(ctx);
  ++steps_done_;
  finish_device_work();  // on CUDA, sim.step then times the step's kernels, not only their launches
}

void Simulation::bin() {
  bins_.rebuild(crowd_.position.span(), crowd_.flags.span(), dense_bins_);
  contact_bins_.rebuild(crowd_.position.span(), crowd_.flags.span(), dense_bins_);
}

// The arriving agents due by now, in order of entry time, each entering
// where its disc overlaps no agent in the scene and no agent admitted before
// it in this step (the rest wait at their points). True when any entered.
bool Simulation::admit_entries() {
  std::size_t due = 0;
  // (1% of a step absorbs the float rounding of the entry times.)
  const double now = time() + 0.01 * static_cast<double>(spec_.dt);
  while (due < pending_.size() && static_cast<double>(pending_[due].time) <= now) ++due;
  if (due == 0) return false;
  std::vector<glm::vec2> spots(due);
  std::vector<float> radii(due);
  for (std::size_t k = 0; k < due; ++k) {
    spots[k] = pending_[k].spot;
    radii[k] = pending_[k].radius;
  }
  const Memory m = current_memory();
  const Buffer<glm::vec2> spot_buffer(std::span<const glm::vec2>(spots), m);
  const Buffer<float> radius_buffer(std::span<const float>(radii), m);
  Buffer<float> clearance = Buffer<float>::zeros(static_cast<Index>(due), m);
  entry_clearance(contact_bins_.view(), world_.periodic(), crowd_.position.span(), crowd_.radius.span(),
                  crowd_.flags.span(), spot_buffer.span(), radius_buffer.span(), clearance.span());
  const std::vector<float> gap = clearance.to_vector();
  std::vector<PendingEntry> waiting, entered;
  for (std::size_t k = 0; k < due; ++k) {
    bool free = gap[k] >= 0.0f;
    for (const PendingEntry& e : entered)
      free = free && length2(e.spot - spots[k]) >= (e.radius + radii[k]) * (e.radius + radii[k]);
    (free ? entered : waiting).push_back(pending_[k]);
  }
  const std::uint8_t active = kAgentActive;
  for (const PendingEntry& e : entered) crowd_.flags.write(e.agent, std::span<const std::uint8_t>(&active, 1));
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(due));
  pending_.insert(pending_.begin(), waiting.begin(), waiting.end());
  return !entered.empty();
}

// The far look's summary of the steering bins' cells (collision-free speed
// model only; its buffer grows with the bins' slots); none otherwise.
Span<const CellHeadings> Simulation::far_headings(const GridView& bins, const BinnedState& state) {
  if (!summarises_far_cells()) return {};
  if (cell_headings_.size() < bins.capacity()) cell_headings_ = Buffer<CellHeadings>(bins.capacity(), current_memory());
  const Span<CellHeadings> out = cell_headings_.span().subspan(0, bins.capacity());
  summarise_cell_headings(bins, state, out);
  far_cells_summarised_ = bins.capacity();
  return out;
}
// (Without anticipation the far look never runs.)
bool Simulation::summarises_far_cells() const {
  return spec_.model.kind == ModelKind::CollisionFreeSpeed && spec_.model.cfs.avoid_strength > 0.0f &&
         skip_far_cells_walking_along_;
}

void Simulation::sense_and_steer(const StepContext& ctx) {
  const AgentArrays a = arrays_of(crowd_);
  if (neighbours_ == NeighbourSearch::AllPairs) {
    if (scheduler_ != SchedulerKind::DoubleBuffer)
      throw Error("the all-pairs reference runs with the double buffer only", at_field("scheduler"));
    sense_all_pairs(ctx, a, sensed_.span());
    steer_double_buffer(ctx, a, sensed_.span(), candidate_.span());
  } else if (scheduler_ == SchedulerKind::DoubleBuffer) {
    // Neighbours read from the bins' copy in cell order (the crowd stays
    // as binned until the move stage).
    const Index items = ctx.bins.items.size();
    StepContext gathered = ctx;
    gathered.binned = {binned_position_.span().subspan(0, items), binned_velocity_.span().subspan(0, items),
                       binned_radius_.span().subspan(0, items), binned_flags_.span().subspan(0, items),
                       binned_aim_.span().subspan(0, binned_aim_.size() > 0 ? items : 0)};
    gather_binned_state(ctx, a, aim_.span(), gathered.binned);
    gathered.far_headings = far_headings(ctx.bins, gathered.binned);
    sense_double_buffer(gathered, a, sensed_.span());
    steer_double_buffer(ctx, a, sensed_.span(), candidate_.span());
  } else {
    StepContext coloured = ctx;
    if (spec_.model.kind == ModelKind::CollisionFreeSpeed) {
      const Index items = ctx.bins.items.size();
      coloured.far_state = {binned_position_.span().subspan(0, items),
                            binned_velocity_.span().subspan(0, items),
                            binned_radius_.span().subspan(0, items),
                            binned_flags_.span().subspan(0, items),
                            {}};
      gather_binned_state(ctx, a, {}, coloured.far_state);
      coloured.far_headings = far_headings(ctx.bins, coloured.far_state);
    }
    sense_steer_four_colour(coloured, a);
  }
}

void Simulation::move(const StepContext& ctx) {
  const AgentArrays a = arrays_of(crowd_);
  const Span<const glm::vec2> anchor = anchor_.span();
  const Span<const MoveCells> cells = move_cells_.span();
  move_cells(ctx, anchor, move_cells_.span());
  const Span<float> depth = contact_depth_.span();
  const ModelParams& m = spec_.model;
  // The fixed passes, then extra ones while the last pass found a pair
  // deeper than the tolerance (the depth it saw before pushing). A pass that
  // moved nobody ends them: the passes left, fixed or extra, would each give
  // the same positions again (bit for bit), so a sparse crowd pays for one
  // pass. `pass(want_depth)` runs one and says what it did.
  const std::int32_t most = m.contact_iterations > 0 ? m.contact_iterations + m.contact_extra_iterations : 0;
  auto run_passes = [&](auto&& pass) {
    for (contact_passes_ = 0; contact_passes_ < most;) {
      const ContactPass done = pass(contact_passes_ + 1 >= m.contact_iterations);
      ++contact_passes_;
      if (!done.moved || (contact_passes_ >= m.contact_iterations && done.deepest <= m.contact_tolerance)) break;
    }
  };
  if (scheduler_ == SchedulerKind::DoubleBuffer) {  // (the all-pairs reference included)
    // Past the first pass, agents whose move cells the pass before left
    // still are passed over (contacts_double_buffer).
    Span<glm::vec2> in = candidate_.span(), out = scratch_.span();
    Span<const std::int32_t> moved_before;
    run_passes([&](bool want_depth) {
      contacts_double_buffer(ctx, a, anchor, cells, in, out, depth, moved_before);
      std::swap(in, out);
      const float deepest = want_depth ? deepest_contact(depth, a.flags) : 0.0f;
      if (!skip_idle_contact_passes_) return ContactPass{deepest, true};
      const Index moved = mark_moved_items(ctx.contact_bins, out, in, moved_before_.span());
      moved_before = moved_before_.span();
      return ContactPass{deepest, moved > 0};
    });
    finalize_step(ctx, a, anchor, cells, in);
  } else {  // in place: whether a pass moved anybody is not kept
    run_passes([&](bool want_depth) {
      contacts_four_colour(ctx, a, anchor, cells, depth);
      return ContactPass{want_depth ? deepest_contact(depth, a.flags) : 0.0f, true};
    });
    finalize_step(ctx, a, anchor, cells, a.position);
  }
}

void Simulation::run(std::int64_t steps) {
  for (std::int64_t s = 0; s < steps; ++s) step();
}

Index Simulation::active_count() const { return count_flag(crowd_.flags.span(), kAgentActive); }
Index Simulation::arrived_count() const { return count_flag(crowd_.flags.span(), kAgentArrived); }

}  // namespace throng::sim
