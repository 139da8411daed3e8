#include "path/distance_field.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

#include "core/error.h"
#include "core/interrupt.h"
#include "path/host_parallel.h"
#include "path/route_planner.h"

namespace throng::path {

void DistanceFieldOptions::validate() const {
  if (!(std::isfinite(cell) && cell >= 0.01f && cell <= 100.0f))
    throw Error("cell must be in [0.01, 100] m", at_field("field.cell"));
  if (!(std::isfinite(wall_band) && wall_band > 0)) throw Error("wall band must be > 0 m", at_field("field.wall_band"));
  if (!(std::isfinite(wall_cost) && wall_cost >= 0)) throw Error("wall cost must be >= 0", at_field("field.wall_cost"));
  if (max_nodes < 16) throw Error("max nodes must be >= 16", at_field("field.max_nodes"));
}

namespace {

// Index of node (x, y) in the field's distances, and where it lies.
std::size_t node(const sim::FieldGrid& g, std::int32_t x, std::int32_t y) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(g.nx) + static_cast<std::size_t>(x);
}
glm::vec2 node_point(const sim::FieldGrid& g, std::int32_t x, std::int32_t y) {
  return g.origin + glm::vec2(static_cast<float>(x), static_cast<float>(y)) * g.cell;
}

// The grid over `bounds` with a cell round it: `cell` or coarser, so that
// it holds at most max_nodes nodes (the cell grows until it does: the grid
// always covers the bounds).
sim::FieldGrid grid_over(const sim::Aabb& bounds, glm::vec2 target, glm::vec2 target_half,
                         const DistanceFieldOptions& o) {
  const glm::vec2 size = bounds.size();
  sim::FieldGrid g;
  g.target = target;
  g.target_half = target_half;
  double cell = o.cell;
  for (;;) {
    const double nx = std::ceil(static_cast<double>(size.x) / cell + 2.0) + 1.0;
    const double ny = std::ceil(static_cast<double>(size.y) / cell + 2.0) + 1.0;
    if (nx * ny <= static_cast<double>(o.max_nodes)) {
      g.nx = static_cast<std::int32_t>(nx);
      g.ny = static_cast<std::int32_t>(ny);
      break;
    }
    // Step to the cell the budget allows were the grid exactly size / cell,
    // then on by 1 % while the margin's nodes still overflow it.
    cell = std::max(cell * 1.01, std::sqrt(static_cast<double>(size.x) * size.y / static_cast<double>(o.max_nodes)));
  }
  g.cell = static_cast<float>(cell);
  g.origin = bounds.min - glm::vec2(g.cell);
  return g;
}

// Slowness of every node (INFINITY where the disc does not fit), in
// parallel: each node reads the free space and writes only itself.
std::vector<float> node_slowness(const FreeSpace& space, const sim::FieldGrid& g, float radius,
                                 const DistanceFieldOptions& o) {
  std::vector<float> slow(static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny));
  host_parallel_for(
      "path.field_clearance", g.ny,
      [&](Index j) {
        for (std::int32_t i = 0; i < g.nx; ++i) {
          const glm::vec2 p = node_point(g, i, j);
          const float c = space.clearance(p);
          const float near_wall = std::clamp(1.0f - (c - radius) / o.wall_band, 0.0f, 1.0f);
          slow[node(g, i, j)] = c < radius ? INFINITY : 1.0f + o.wall_cost * near_wall;
        }
      },
      1);
  return slow;
}

// The first-order upwind value of node (i, j) from its settled neighbours
// (hf: the cell times the node's slowness): along each axis the nearer
// settled neighbour; both axes where the front passes between them, else
// the nearer alone. First order lengthens ways that run diagonally to the
// grid by up to about 5 % (tests/path/distance_field_test.cpp); the agents
// use the field's direction, which is far better. (A second-order stencil
// undershot by as much near the seeds.)
float upwind(const std::vector<float>& t, const std::vector<std::uint8_t>& settled, const sim::FieldGrid& g,
             std::int32_t i, std::int32_t j, float hf) {
  auto at = [&](std::int32_t x, std::int32_t y) {
    if (x < 0 || y < 0 || x >= g.nx || y >= g.ny) return INFINITY;
    const std::size_t k = node(g, x, y);
    return settled[k] != 0 ? t[k] : INFINITY;
  };
  const float a = std::min(at(i - 1, j), at(i + 1, j)), b = std::min(at(i, j - 1), at(i, j + 1));
  const float lo = std::min(a, b), hi = std::max(a, b);
  if (!(hi < INFINITY) || hi - lo >= hf) return lo + hf;
  return 0.5f * (a + b + std::sqrt(2.0f * hf * hf - (a - b) * (a - b)));
}

// The nodes the march starts from, with their values: the four round the
// target (whether the disc fits there or not: a goal against a wall is
// reached by walking up to it), and every free node within kSeedCells of
// it (of a door line: of its nearest point) that sees it (no wall in
// between), at the straight distance times its slowness: the front is a
// circle there, which the upwind differences resolve badly at a handful of
// cells.
std::vector<std::pair<float, std::int64_t>> seeds(const FreeSpace& space, const std::vector<float>& slow,
                                                  const sim::FieldGrid& g) {
  constexpr std::int32_t kSeedCells = 3;
  auto cell_x = [&](float x) {
    return std::clamp(static_cast<std::int32_t>(std::floor((x - g.origin.x) / g.cell)), 0, g.nx - 2);
  };
  auto cell_y = [&](float y) {
    return std::clamp(static_cast<std::int32_t>(std::floor((y - g.origin.y) / g.cell)), 0, g.ny - 2);
  };
  const std::int32_t ti = cell_x(g.target.x), tj = cell_y(g.target.y);
  const glm::vec2 a = g.target - g.target_half, b = g.target + g.target_half;
  const std::int32_t x0 = std::min(cell_x(a.x), cell_x(b.x)), x1 = std::max(cell_x(a.x), cell_x(b.x));
  const std::int32_t y0 = std::min(cell_y(a.y), cell_y(b.y)), y1 = std::max(cell_y(a.y), cell_y(b.y));
  std::vector<std::pair<float, std::int64_t>> out;
  for (std::int32_t y = std::max(0, y0 - kSeedCells); y <= std::min(g.ny - 1, y1 + 1 + kSeedCells); ++y)
    for (std::int32_t x = std::max(0, x0 - kSeedCells); x <= std::min(g.nx - 1, x1 + 1 + kSeedCells); ++x) {
      const std::size_t k = node(g, x, y);
      const bool corner = (x == ti || x == ti + 1) && (y == tj || y == tj + 1);
      const glm::vec2 p = node_point(g, x, y);
      const glm::vec2 near = sim::field_target_near(g, p);
      const float d = sim::length_of(p - near);
      const bool free = slow[k] < INFINITY;
      if (!corner &&
          !(free && d <= static_cast<float>(kSeedCells) * g.cell && space.segment_clear(p, near, 0.0f, true)))
        continue;
      out.emplace_back(d * (free ? slow[k] : 1.0f), static_cast<std::int64_t>(k));
    }
  return out;
}

// Fast marching from the seeds.
void march(std::vector<float>& t, const std::vector<float>& slow, const sim::FieldGrid& g,
           const std::vector<std::pair<float, std::int64_t>>& start) {
  const auto n = t.size();
  std::vector<std::uint8_t> settled(n, 0);
  using Entry = std::pair<float, std::int64_t>;  // (T, node): ties by node index, so the order is fixed
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  for (const auto& [value, k] : start) {
    t[static_cast<std::size_t>(k)] = value;
    open.push({value, k});
  }
  std::int64_t pops = 0;
  while (!open.empty()) {
    const auto [tk, k] = open.top();
    open.pop();
    if (settled[static_cast<std::size_t>(k)] != 0 || tk > t[static_cast<std::size_t>(k)]) continue;
    settled[static_cast<std::size_t>(k)] = 1;
    if ((++pops & 0xffff) == 0) check_interrupt("building navigation fields");
    const auto i = static_cast<std::int32_t>(k % g.nx), j = static_cast<std::int32_t>(k / g.nx);
    const std::int32_t di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
    for (int m = 0; m < 4; ++m) {
      const std::int32_t x = i + di[m], y = j + dj[m];
      if (x < 0 || y < 0 || x >= g.nx || y >= g.ny) continue;
      const std::size_t q = node(g, x, y);
      if (settled[q] != 0 || !(slow[q] < INFINITY)) continue;
      const float tq = upwind(t, settled, g, x, y, g.cell * slow[q]);
      if (tq < t[q]) {
        t[q] = tq;
        open.push({tq, static_cast<std::int64_t>(q)});
      }
    }
  }
}

// What a field's march starts from: its grid, the slowness of every node
// (walls only) and the seeds round the target.
struct PreparedField {
  sim::FieldGrid grid;
  std::vector<float> slowness;
  std::vector<std::pair<float, std::int64_t>> seeds;
};

PreparedField prepare_field(const FreeSpace& space, glm::vec2 target, glm::vec2 target_half, float radius,
                            const DistanceFieldOptions& o) {
  o.validate();
  if (!(std::isfinite(target.x) && std::isfinite(target.y) && std::isfinite(target_half.x) &&
        std::isfinite(target_half.y)))
    throw Error("the field's target is not finite");
  sim::Aabb bounds = space.bounds();
  bounds.add(target - target_half);
  bounds.add(target + target_half);
  PreparedField p;
  p.grid = grid_over(bounds, target, target_half, o);
  p.slowness = node_slowness(space, p.grid, radius, o);
  p.seeds = seeds(space, p.slowness, p.grid);
  return p;
}

// The march from the prepared seeds; with `crowd`, every node's slowness
// (and each seed's value) times the congestion at the node.
sim::FieldData march_field(const PreparedField& p, const sim::CrowdDensity* crowd) {
  sim::FieldData field;
  field.grid = p.grid;
  field.distance.assign(p.slowness.size(), INFINITY);
  if (crowd == nullptr) {
    march(field.distance, p.slowness, field.grid, p.seeds);
    return field;
  }
  std::vector<float> slow = p.slowness;
  for (std::int32_t j = 0; j < p.grid.ny; ++j)
    for (std::int32_t i = 0; i < p.grid.nx; ++i)
      slow[node(p.grid, i, j)] *= sim::congestion_slowness(crowd->at(node_point(p.grid, i, j)));
  std::vector<std::pair<float, std::int64_t>> start = p.seeds;
  for (auto& [value, k] : start) {
    const auto i = static_cast<std::int32_t>(k % p.grid.nx), j = static_cast<std::int32_t>(k / p.grid.nx);
    value *= sim::congestion_slowness(crowd->at(node_point(p.grid, i, j)));
  }
  march(field.distance, slow, field.grid, start);
  return field;
}

}  // namespace

sim::FieldData build_distance_field(const FreeSpace& space, glm::vec2 target, float radius,
                                    const DistanceFieldOptions& options, glm::vec2 target_half) {
  return march_field(prepare_field(space, target, target_half, radius, options), nullptr);
}

struct FastMarchingFieldBuilder::Prepared {
  glm::vec2 target{0.0f}, target_half{0.0f};
  float radius = 0.0f;
  PreparedField field;
};

FastMarchingFieldBuilder::FastMarchingFieldBuilder(DistanceFieldOptions options) : options_(options) {
  options_.validate();
}

FastMarchingFieldBuilder::~FastMarchingFieldBuilder() = default;

sim::FieldData FastMarchingFieldBuilder::build_locked(const sim::World& world, glm::vec2 target, float radius,
                                                      const sim::CrowdDensity* crowd, glm::vec2 target_half) const {
  // Without a walkable region the free space is the obstacles' box grown by
  // a margin: grown again to hold every target asked for.
  const bool outside =
      space_ && !world.has_walkable() &&
      !(space_->bounds().contains(target - target_half) && space_->bounds().contains(target + target_half));
  if (world_ != &world || !space_ || outside) {
    FreeSpaceOptions o;
    if (!world.has_walkable()) {
      o.extent = space_ && world_ == &world ? extent_ : sim::Aabb{};
      o.extent.add(target - target_half);
      o.extent.add(target + target_half);
      extent_ = o.extent;
    }
    space_ = std::make_unique<FreeSpace>(FreeSpace::build(world, o));
    world_ = &world;
    prepared_.clear();
  }
  if (crowd == nullptr) return build_distance_field(*space_, target, radius, options_, target_half);
  std::shared_ptr<const Prepared> p = find_prepared(target, radius, target_half);
  if (!p) {
    p = std::make_shared<const Prepared>(
        Prepared{target, target_half, radius, prepare_field(*space_, target, target_half, radius, options_)});
    prepared_.push_back(p);
  }
  return march_field(p->field, crowd);
}

sim::FieldData FastMarchingFieldBuilder::build(const sim::World& world, glm::vec2 target, float radius,
                                               const sim::CrowdDensity* crowd, glm::vec2 target_half) const {
  if (!world_has_obstacles(world)) return {};  // straight lines are the shortest ways
  std::shared_ptr<const Prepared> p;
  {
    std::lock_guard lock(mutex_);
    if (crowd == nullptr || !space_ || world_ != &world) return build_locked(world, target, radius, crowd, target_half);
    p = find_prepared(target, radius, target_half);
    if (!p) return build_locked(world, target, radius, crowd, target_half);
  }
  // A weighed field asked for again: marched outside the lock (on a copy of
  // the pointer, which keeps it alive whatever else the builder is asked),
  // so that a run's fields are weighed in parallel.
  return march_field(p->field, crowd);
}

// Congestion-weighted fields are asked for again and again: their walls and
// seeds are kept.
std::shared_ptr<const FastMarchingFieldBuilder::Prepared> FastMarchingFieldBuilder::find_prepared(
    glm::vec2 target, float radius, glm::vec2 target_half) const {
  for (const std::shared_ptr<const Prepared>& p : prepared_)
    if (p->target == target && p->radius == radius && p->target_half == target_half) return p;
  return nullptr;
}

}  // namespace throng::path
