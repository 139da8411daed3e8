// Distance fields for navigation (sim/navigation_field.h): the walking
// distance to a target from every node of a grid over free space, by the
// fast marching method (Sethian 1996, "A fast marching level set method for
// monotonically advancing fronts", PNAS 93(4)): the first-order upwind
// solution of the eikonal equation |grad T| = F, nodes accepted in order of
// T from a heap, so each node is settled once (O(n log n)).
//
// F is the slowness: 1 in the open, rising to 1 + wall_cost where the
// agent's disc touches a wall, linearly over `wall_band` of clearance. The
// field's shortest ways keep a little off walls and round inner corners in
// an arc, as walkers do, where the way is wide enough. Nodes where the disc
// does not fit (clearance below the radius) are blocked (INFINITY).
//
// Memory and time follow the grid: the cell grows past `cell` so that a
// field never holds more than `max_nodes` nodes.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "path/free_space.h"
#include "sim/navigation_field.h"

namespace throng::path {

struct DistanceFieldOptions {
  float cell = 0.2f;                   // m: node spacing, at least (see max_nodes)
  float wall_band = 0.5f;              // m of clearance beyond the radius over which walls slow
  float wall_cost = 1.0f;              // extra slowness at contact with a wall (0: plain distance)
  std::int64_t max_nodes = 4'000'000;  // per field: the cell grows to stay within this
  void validate() const;               // throws Error naming the field ("field.cell", ...)
};

// The field of `target` over the bounds of `space` for discs of `radius`
// (of the door line target +- target_half where that is not zero: the
// distance to its nearest point). A target without room for the disc
// still seeds the nodes round it (a goal against a wall is reached by
// walking up to the wall).
sim::FieldData build_distance_field(const FreeSpace& space, glm::vec2 target, float radius,
                                    const DistanceFieldOptions& options = {}, glm::vec2 target_half = glm::vec2(0.0f));

// The builder `throng run` uses for `planning: field` and `planning:
// quickest`: the world's free space built once (at the first field), each
// field by fast marching. With a crowd's density every node is slowed by
// sim::congestion_slowness there (the eikonal equation of Hughes 2002, "A
// continuum theory for the flow of pedestrians", Transp. Res. B 36, with
// Weidmann's speed-density relation); the walls' slowness and the seeds of
// such fields are kept for the next time the same field is asked for, and
// such a field asked for again is marched outside the builder's lock (a
// run weighs its fields in parallel). build() may be called from several
// threads at once; give each world its own builder (the free space is kept
// for the last world asked about).
class FastMarchingFieldBuilder final : public sim::FieldBuilder {
 public:
  explicit FastMarchingFieldBuilder(DistanceFieldOptions options = {});
  ~FastMarchingFieldBuilder() override;
  sim::FieldData build(const sim::World& world, glm::vec2 target, float radius,
                       const sim::CrowdDensity* crowd = nullptr,
                       glm::vec2 target_half = glm::vec2(0.0f)) const override;

 private:
  struct Prepared;
  // build() under the lock: the free space made or grown, then the field.
  sim::FieldData build_locked(const sim::World& world, glm::vec2 target, float radius, const sim::CrowdDensity* crowd,
                              glm::vec2 target_half) const;
  std::shared_ptr<const Prepared> find_prepared(glm::vec2 target, float radius, glm::vec2 target_half) const;
  DistanceFieldOptions options_;
  mutable std::mutex mutex_;
  mutable const sim::World* world_ = nullptr;
  mutable std::unique_ptr<FreeSpace> space_;
  mutable sim::Aabb extent_;                                       // targets so far (a world without a walkable region)
  mutable std::vector<std::shared_ptr<const Prepared>> prepared_;  // congestion-weighted fields' walls and seeds
};

}  // namespace throng::path
