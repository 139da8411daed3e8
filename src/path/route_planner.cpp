#include "path/route_planner.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/interrupt.h"
#include "path/host_parallel.h"

namespace throng::path {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void RoutePlannerOptions::validate() const {
  if (!(std::isfinite(wall_margin) && wall_margin >= 0))
    throw Error("wall margin must be >= 0", at_field("planning.wall_margin"));
  if (!(std::isfinite(clearance_weight) && clearance_weight >= 0))
    throw Error("clearance weight must be >= 0", at_field("planning.clearance_weight"));
}

PlanOptions RoutePlannerOptions::plan_options(float radius) const {
  PlanOptions o;
  o.radius = radius;
  o.clearance_weight = clearance_weight;
  o.shortcut_clearance = radius + wall_margin;
  o.corner_radius = 0.0f;
  return o;
}

bool world_has_obstacles(const sim::World& world) {
  return world.has_walkable() || !world.polygons().empty() || !world.circles().empty();
}

RoadmapRoutePlanner::RoadmapRoutePlanner(RoutePlannerOptions options) : options_(options) { options_.validate(); }

RoutePlannerStats RoadmapRoutePlanner::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

const FreeSpace& RoadmapRoutePlanner::space_for(const sim::World& world, std::span<const glm::vec2> starts,
                                                std::span<const glm::vec2> goals) const {
  // Without a walkable region the free space is a box around the obstacles
  // and the points it must hold: rebuilt (rarely) when a group's points fall
  // outside it.
  sim::Aabb points;
  for (glm::vec2 p : starts) points.add(p);
  for (glm::vec2 p : goals) points.add(p);
  const FreeSpace* current = space_ ? space_.get() : planners_.empty() ? nullptr : &planners_.begin()->second.space();
  const bool outside = current != nullptr && !world.has_walkable() && !points.empty() &&
                       !(current->bounds().contains(points.min) && current->bounds().contains(points.max));
  if (world_ != &world || current == nullptr || outside) {
    const auto t0 = std::chrono::steady_clock::now();
    FreeSpaceOptions fo;
    if (!world.has_walkable()) {
      fo.extent = points;
      if (current != nullptr && world_ == &world) fo.extent.add(space_options_.extent);
    }
    planners_.clear();
    space_.reset();
    world_ = &world;
    space_options_ = fo;
    space_ = std::make_unique<FreeSpace>(build_space());
    current = space_.get();
    stats_.build_seconds += seconds_since(t0);
  }
  return *current;
}

FreeSpace RoadmapRoutePlanner::build_space() const {
  try {
    return FreeSpace::build(*world_, space_options_);
  } catch (const Error& e) {
    throw Error(std::string("route planning: ") + e.what(), at_field("planning"));
  }
}

const Planner& RoadmapRoutePlanner::planner_for(float radius) const {
  auto it = planners_.find(radius);
  if (it == planners_.end()) {
    const auto t0 = std::chrono::steady_clock::now();
    // The first roadmap takes over the free space built for the straight
    // lines (it stays reachable as planner.space()); later radii rebuild it.
    FreeSpace space = space_ ? std::move(*space_) : build_space();
    space_.reset();
    it = planners_.emplace(radius, Planner::build(std::move(space), options_.plan_options(radius))).first;
    ++stats_.roadmaps;
    stats_.build_seconds += seconds_since(t0);
    spdlog::debug("route planner: roadmap for radius {} m: {} nodes, {} edges", radius,
                  it->second.roadmap().node_count(), it->second.roadmap().edge_count());
  }
  return it->second;
}

std::vector<std::vector<glm::vec2>> RoadmapRoutePlanner::plan(const sim::World& world,
                                                              std::span<const glm::vec2> starts,
                                                              std::span<const glm::vec2> goals,
                                                              float agent_radius) const {
  if (starts.size() != goals.size())
    throw Error(fmt::format("{} starts but {} goals", starts.size(), goals.size()), at_field("planning"));
  std::vector<std::vector<glm::vec2>> routes(starts.size());
  if (starts.empty() || !world_has_obstacles(world)) return routes;
  std::lock_guard lock(mutex_);
  const FreeSpace& space = space_for(world, starts, goals);

  // The straight line first: where it keeps the radius, no roadmap is needed
  // (nor built, when that holds for every agent).
  const auto t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<Index>(starts.size());
  std::vector<std::uint8_t> straight(starts.size(), 0);
  host_parallel_for(
      "path.route_straight", n,
      [&](Index i) {
        const auto k = static_cast<std::size_t>(i);
        if (interrupt_flag().load(std::memory_order_relaxed)) return;  // (checked after the loop)
        straight[k] = space.segment_clear(starts[k], goals[k], agent_radius) ? 1 : 0;
      },
      64);
  check_interrupt("planning routes");
  std::int64_t straight_count = 0;
  for (std::uint8_t s : straight) straight_count += s;
  stats_.plan_seconds += seconds_since(t0);
  std::int64_t fallback = 0, planned = 0;
  if (straight_count < n) {
    const Planner& planner = planner_for(agent_radius);
    if (n - straight_count >= 10000)  // seconds of work: say so before it starts
      spdlog::info("route planner: routing {} agents over the roadmap", n - straight_count);
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<PlanStatus> status(starts.size(), PlanStatus::Found);
    host_parallel_for(
        "path.route", n,
        [&](Index i) {
          const auto k = static_cast<std::size_t>(i);
          if (straight[k] != 0 || interrupt_flag().load(std::memory_order_relaxed)) return;
          const PlannedPath p = planner.plan({starts[k], goals[k], true});
          status[k] = p.status;
          if (p.found() && p.points.size() > 2) routes[k].assign(p.points.begin() + 1, p.points.end() - 1);
        },
        4);
    check_interrupt("planning routes");
    for (std::size_t k = 0; k < starts.size(); ++k) {
      if (status[k] != PlanStatus::Found)
        ++fallback;
      else if (straight[k] == 0)
        ++planned;
    }
    stats_.plan_seconds += seconds_since(t1);
  }
  stats_.queries += n;
  stats_.straight += straight_count;
  stats_.planned += planned;
  stats_.fallback += fallback;
  if (fallback > 0)
    spdlog::warn(
        "route planner: {} of {} agents (radius {} m) found no roadmap route (goal too close to a wall, or a gap "
        "narrower "
        "than the agent); they walk straight to their goal",
        fallback, n, agent_radius);
  return routes;
}

}  // namespace throng::path
