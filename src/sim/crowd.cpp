#include "sim/crowd.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <span>
#include <unordered_map>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/math.h"
#include "core/random.h"

namespace throng::sim {

namespace {

Aabb region_bounds(const Region& r) {
  Aabb b;
  switch (r.kind) {
    case Region::Kind::rect:
      b.add(r.min);
      b.add(r.max);
      break;
    case Region::Kind::disc:
    case Region::Kind::ring:
      b.add(r.center - glm::vec2(r.radius));
      b.add(r.center + glm::vec2(r.radius));
      break;
    case Region::Kind::polygon: b = bounds(r.polygon); break;
    case Region::Kind::points:
      for (glm::vec2 p : r.points) b.add(p);
      break;
  }
  return b;
}

bool region_contains(const Region& r, glm::vec2 p) {
  switch (r.kind) {
    case Region::Kind::rect: return p.x >= r.min.x && p.x <= r.max.x && p.y >= r.min.y && p.y <= r.max.y;
    case Region::Kind::disc: return length2(p - r.center) <= r.radius * r.radius;
    case Region::Kind::ring: return false;
    case Region::Kind::polygon: return point_in_polygon(p, r.polygon);
    case Region::Kind::points: return false;
  }
  return false;
}

void check_region(const Region& r, const std::string& field, float max_extent) {
  auto finite = [&](glm::vec2 p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::fabs(p.x) <= max_extent && std::fabs(p.y) <= max_extent;
  };
  switch (r.kind) {
    case Region::Kind::rect:
      if (!finite(r.min) || !finite(r.max))
        throw Error("rect corners must be finite numbers within the extent limit", at_field(field + ".rect"));
      if (!(r.max.x > r.min.x && r.max.y > r.min.y))
        throw Error("rect needs max > min in x and y", at_field(field + ".rect"));
      break;
    case Region::Kind::disc:
    case Region::Kind::ring:
      if (!finite(r.center)) throw Error("center must be finite numbers within the extent limit", at_field(field));
      if (!std::isfinite(r.radius) || r.radius < 0 || r.radius > max_extent)
        throw Error("radius must be >= 0", at_field(field + ".radius"));
      if (r.kind == Region::Kind::disc && !(r.radius > 0))
        throw Error("disc radius must be > 0", at_field(field + ".radius"));
      if (!std::isfinite(r.spacing) || r.spacing < 0 || r.spacing > max_extent)
        throw Error("spacing must be >= 0", at_field(field + ".spacing"));
      break;
    case Region::Kind::polygon:
      if (r.polygon.outer.size() < 3) throw Error("polygon needs at least 3 vertices", at_field(field + ".polygon"));
      for (glm::vec2 p : r.polygon.outer)
        if (!finite(p))
          throw Error("polygon vertices must be finite numbers within the extent limit", at_field(field + ".polygon"));
      if (find_self_intersection(r.polygon.outer))
        throw Error("spawn polygon is self-intersecting", at_field(field + ".polygon"));
      break;
    case Region::Kind::points:
      for (std::size_t i = 0; i < r.points.size(); ++i)
        if (!finite(r.points[i]))
          throw Error("a point must be finite numbers within the extent limit",
                      at_field(fmt::format("{}.points[{}]", field, i)));
      break;
  }
}

// Agents already placed, for overlap tests across groups. The cell must be
// at least the largest r + rq + gap asked about. Over a periodic area the
// agents across the seam count too (at their copies one period away).
class Occupancy {
 public:
  explicit Occupancy(float cell, const Periodic& periodic = {}) : cell_(cell), periodic_(periodic) {}
  // The id of an agent closer than r + rq + gap to p, or -1.
  std::int64_t find(glm::vec2 p, float r, float gap) const {
    std::int64_t id = -1;
    periodic_.for_each_shift([&](glm::vec2 shift) {
      if (id < 0) id = find_near(p + shift, r, gap);
    });
    return id;
  }
  bool overlaps(glm::vec2 p, float r, float gap) const { return find(p, r, gap) >= 0; }
  void add(glm::vec2 p, float r, std::int64_t id) {
    cells_[cell_key(cell_coord(p.x, cell_), cell_coord(p.y, cell_))].push_back({p, r, id});
  }

 private:
  std::int64_t find_near(glm::vec2 p, float r, float gap) const {
    const std::int32_t cx = cell_coord(p.x, cell_), cy = cell_coord(p.y, cell_);
    for (std::int32_t dy = -1; dy <= 1; ++dy)
      for (std::int32_t dx = -1; dx <= 1; ++dx) {
        auto it = cells_.find(cell_key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (const Entry& e : it->second)
          if (length2(e.p - p) < (r + e.r + gap) * (r + e.r + gap)) return e.id;
      }
    return -1;
  }
  struct Entry {
    glm::vec2 p;
    float r;
    std::int64_t id;
  };
  float cell_;
  Periodic periodic_;
  std::unordered_map<std::uint64_t, std::vector<Entry>> cells_;
};

// Hexagonal lattice sites of spacing a over the box b (rows a * sqrt(3) / 2
// apart, odd rows shifted by a / 2, the whole centred in the box), in row
// order, each moved uniformly within a disc of radius `jitter`; `keep` is
// called with every site. Returns the number of sites.
template <class Keep>
std::int64_t hex_sites(const Aabb& b, double a, double jitter, Rng& rng, const Keep& keep) {
  const double w = b.size().x, h = b.size().y, row = a * 0.5 * std::sqrt(3.0);
  const auto nx = static_cast<std::int64_t>(std::floor(w / a)) + 1,
             ny = static_cast<std::int64_t>(std::floor(h / row)) + 1;
  const double x0 = b.min.x + (w - static_cast<double>(nx - 1) * a) * 0.5,
               y0 = b.min.y + (h - static_cast<double>(ny - 1) * row) * 0.5;
  std::int64_t sites = 0;
  for (std::int64_t j = 0; j < ny; ++j) {
    const bool odd = (j & 1) != 0;
    for (std::int64_t i = 0; i < nx - (odd ? 1 : 0); ++i, ++sites) {
      double x = x0 + (static_cast<double>(i) + (odd ? 0.5 : 0.0)) * a, y = y0 + static_cast<double>(j) * row;
      if (jitter > 0) {
        const double rho = jitter * std::sqrt(rng.uniform()), phi = 2.0 * kPi * rng.uniform();
        x += rho * std::cos(phi);
        y += rho * std::sin(phi);
      }
      keep(glm::vec2(static_cast<float>(x), static_cast<float>(y)));
    }
  }
  return sites;
}

// How many sites hex_sites makes for spacing a (nx per even row, nx - 1 per odd row).
double hex_site_count(const Aabb& b, double a) {
  const double nx = std::floor(b.size().x / a) + 1, ny = std::floor(b.size().y / (a * 0.5 * std::sqrt(3.0))) + 1;
  return nx * ny - std::floor(ny / 2);
}

// The hexagonal lattice spacing with `density` sites per m^2.
double hex_spacing(double density) { return std::sqrt(2.0 / (std::sqrt(3.0) * density)); }

double region_area(const Region& r) {
  switch (r.kind) {
    case Region::Kind::rect: return static_cast<double>(r.max.x - r.min.x) * static_cast<double>(r.max.y - r.min.y);
    case Region::Kind::disc: return kPi * static_cast<double>(r.radius) * r.radius;
    case Region::Kind::polygon: return area(r.polygon);
    case Region::Kind::ring:
    case Region::Kind::points: return 0.0;
  }
  return 0.0;
}

std::string point_text(glm::vec2 p) { return fmt::format("({:.3g}, {:.3g})", p.x, p.y); }

// The goal or waypoint `goal` (field gf) within the scenario's limits.
void check_goal(const GoalSpec& goal, const std::string& gf, const ScenarioLimits& limits) {
  if (!std::isfinite(goal.value.x) || !std::isfinite(goal.value.y) || std::fabs(goal.value.x) > limits.max_extent ||
      std::fabs(goal.value.y) > limits.max_extent)
    throw Error("goal coordinates must be finite numbers within the extent limit", at_field(gf));
  if (goal.kind == GoalSpec::Kind::Exits) {
    if (goal.exits.empty()) throw Error("give at least one exit", at_field(gf + ".exits"));
    for (std::size_t e = 0; e < goal.exits.size(); ++e) {
      const ExitSpec& x = goal.exits[e];
      const std::string ef = fmt::format("{}.exits[{}]", gf, e);
      if (!std::isfinite(x.point.x) || !std::isfinite(x.point.y) || std::fabs(x.point.x) > limits.max_extent ||
          std::fabs(x.point.y) > limits.max_extent)
        throw Error("exit coordinates must be finite numbers within the extent limit", at_field(ef + ".point"));
      if (!std::isfinite(x.width) || !(x.width > 0))
        throw Error(fmt::format("width must be > 0 m (got {})", x.width), at_field(ef + ".width"));
    }
    if (!std::isfinite(goal.reconsider_s) || !(goal.reconsider_s > 0))
      throw Error(fmt::format("reconsider must be > 0 s (got {})", goal.reconsider_s), at_field(gf + ".reconsider"));
  }
  if (goal.kind == GoalSpec::Kind::Gate) {
    const glm::vec2 to = goal.gate_to;
    if (!std::isfinite(to.x) || !std::isfinite(to.y) || std::fabs(to.x) > limits.max_extent ||
        std::fabs(to.y) > limits.max_extent)
      throw Error("gate coordinates must be finite numbers within the extent limit", at_field(gf + ".gate"));
    if (length_of(to - goal.value) < kMinGateLength)
      throw Error(fmt::format("a gate needs two ends at least {} m apart (got {:.3g} m)", kMinGateLength,
                              length_of(to - goal.value)),
                  at_field(gf + ".gate"));
  }
  if (goal.kind == GoalSpec::Kind::Direction && std::fabs(length_of(goal.value) - 1.0f) > 1e-3f)
    throw Error("a direction must be a unit vector", at_field(gf + ".direction"));
  if (!std::isfinite(goal.wait_s) || goal.wait_s < 0)
    throw Error(fmt::format("wait must be a finite number of seconds >= 0 (got {})", goal.wait_s),
                at_field(gf + ".wait"));
  if (goal.kind == GoalSpec::Kind::Random) {
    check_region(goal.region, gf + ".random", limits.max_extent);
    if (goal.region.kind == Region::Kind::ring)
      throw Error("a ring is not an area to draw goals from", at_field(gf + ".random"));
    if (goal.region.kind == Region::Kind::points)
      throw Error("a list of points is not an area to draw goals from", at_field(gf + ".random"));
  }
}

// Pre-movement times (s) within [0, last_start], the start of the run's
// last step (a later start would never walk): finite bounds in order, a
// positive mean and a non-negative spread where the distribution has them.
void check_premovement(const PremovementSpec& P, const std::string& field, float last_start) {
  if (P.kind == PremovementSpec::Kind::none) return;
  auto finite = [&](float x, const char* key) {
    if (!std::isfinite(x))
      throw Error(fmt::format("{} must be a finite number of seconds", key), at_field(field + "." + key));
  };
  finite(P.min, "min");
  finite(P.max, "max");
  if (P.min < 0) throw Error(fmt::format("min must be >= 0 s (got {})", P.min), at_field(field + ".min"));
  if (P.max < P.min)
    throw Error(fmt::format("max ({} s) must be >= min ({} s)", P.max, P.min), at_field(field + ".max"));
  if (P.max > last_start)
    throw Error(
        fmt::format("max ({} s{}) is past the start of the run's last step ({:.4g} s): those agents would never "
                    "walk",
                    P.max, P.kind == PremovementSpec::Kind::uniform ? "" : "; by default mean + 4 stddev", last_start),
        at_field(field + ".max"));
  if (P.kind == PremovementSpec::Kind::uniform) return;
  finite(P.mean, "mean");
  finite(P.stddev, "stddev");
  if (!(P.mean > 0)) throw Error(fmt::format("mean must be > 0 s (got {})", P.mean), at_field(field + ".mean"));
  if (P.stddev < 0) throw Error(fmt::format("stddev must be >= 0 s (got {})", P.stddev), at_field(field + ".stddev"));
}

// An inflow (field) of a group of `count` agents spawning in `spawn`: an
// area to enter, entry times finite, ascending and up to last_start (the
// start of the run's last step).
void check_inflow(const InflowSpec& I, const Region& spawn, std::int64_t count, const std::string& field,
                  float last_start) {
  if (!I.enabled) return;
  if (spawn.kind == Region::Kind::points || spawn.kind == Region::Kind::ring)
    throw Error("agents arriving over time need an area to enter: a rect, disc or polygon spawn",
                at_field(field + ".spawn"));
  const std::string in = field + ".inflow";
  if (!I.times.empty()) {
    if (static_cast<std::int64_t>(I.times.size()) != count)
      throw Error(fmt::format("{} entry times for a count of {}: give one time per agent", I.times.size(), count),
                  at_field(in + ".times"));
    for (std::size_t k = 0; k < I.times.size(); ++k) {
      const float t = I.times[k];
      if (!std::isfinite(t) || t < 0 || t > last_start || (k > 0 && t < I.times[k - 1]))
        throw Error(
            fmt::format("entry times must be ascending, in [0, {:.4g} s] (up to the start of the run's last step); "
                        "got {} after {}",
                        last_start, t, k > 0 ? I.times[k - 1] : 0.0f),
            at_field(fmt::format("{}.times[{}]", in, k)));
    }
    return;
  }
  if (!std::isfinite(I.rate) || !(I.rate > 0))
    throw Error(fmt::format("rate must be > 0 persons per second (got {})", I.rate), at_field(in + ".rate"));
  if (!std::isfinite(I.from) || I.from < 0)
    throw Error(fmt::format("from must be >= 0 s (got {})", I.from), at_field(in + ".from"));
  if (std::isnan(I.until) || !(I.until > I.from))
    throw Error(fmt::format("until ({} s) must come after from ({} s)", I.until, I.from), at_field(in + ".until"));
  const float last = count > 0 ? I.entry_time(count - 1) : I.from;
  if (last > I.until || last > last_start)
    throw Error(fmt::format("{} agents at {} P/s from {} s enter until {:.4g} s, after {} {:.4g} s", count, I.rate,
                            I.from, last, last > I.until ? "until" : "the start of the run's last step",
                            last > I.until ? I.until : last_start),
                at_field(in + ".rate"));
}

// Group G (field groups[g]) against the model: radius and speeds (m, m/s)
// within what its time step and bins of side `cell` (m) allow.
void check_group_body(const ScenarioSpec& spec, const GroupSpec& G, const std::string& field, float cell) {
  if (G.count < 0) throw Error(fmt::format("count must be >= 0 (got {})", G.count), at_field(field + ".count"));
  if (!std::isfinite(G.radius) || !(G.radius > 0))
    throw Error(fmt::format("radius must be a positive number (got {})", G.radius), at_field(field + ".radius"));
  const float step = spec.model.max_speed * spec.dt;
  if (step > 0.9f * G.radius)
    throw Error(
        fmt::format("dt * model.max_speed = {:.3g} m must stay below 0.9 * radius = {:.3g} m, else agents could step "
                    "through walls: lower dt or max_speed",
                    step, 0.9f * G.radius),
        at_field(field + ".radius"));
  if (2.0f * G.radius + 2.0f * step > cell || G.radius > spec.model.max_radius())
    throw Error(fmt::format("radius {} m is too large for the {} model (at most {:.3g} m, model.max_radius, and 2 "
                            "* radius + 2 * dt * max_speed within its bins of side {:.3g} m)",
                            G.radius, to_string(spec.model.kind), spec.model.max_radius(), cell),
                at_field(field + ".radius"));
  const SpeedSpec& S = G.speed;
  if (!std::isfinite(S.mean) || !(S.mean > 0))
    throw Error(fmt::format("mean speed must be > 0 (got {})", S.mean), at_field(field + ".speed.mean"));
  if (!std::isfinite(S.stddev) || S.stddev < 0)
    throw Error(fmt::format("stddev must be >= 0 (got {})", S.stddev), at_field(field + ".speed.stddev"));
  if (!std::isfinite(S.min) || !(S.min > 0))
    throw Error(fmt::format("min speed must be > 0 (got {})", S.min), at_field(field + ".speed.min"));
  if (!std::isfinite(S.max) || S.max < S.min)
    throw Error("max speed must be >= min speed", at_field(field + ".speed.max"));
  if (S.max > spec.model.max_speed)
    throw Error(fmt::format("speed.max {} exceeds model.max_speed {}", S.max, spec.model.max_speed),
                at_field(field + ".speed.max"));
  if (!std::isfinite(G.arrival_radius) || !(G.arrival_radius > 0))
    throw Error(fmt::format("arrival radius must be > 0 (got {})", G.arrival_radius),
                at_field(field + ".arrival_radius"));
  const float last_start = static_cast<float>(spec.step_count() - 1) * spec.dt;
  check_premovement(G.premovement, field + ".premovement", last_start);
  check_inflow(G.inflow, G.spawn, G.count, field, last_start);
  if (G.inflow.enabled && G.premovement.kind != PremovementSpec::Kind::none)
    throw Error("agents arriving over time walk as they enter: pre-movement is for those present at the start",
                at_field(field + ".premovement"));
}

// Group G (field groups[g]): its body, spawn region and route points.
void check_group(const ScenarioSpec& spec, const GroupSpec& G, const std::string& field, float cell,
                 const ScenarioLimits& limits) {
  check_group_body(spec, G, field, cell);
  if (static_cast<std::int64_t>(G.waypoints.size()) > limits.max_waypoints)
    throw Error(fmt::format("more than {} waypoints", limits.max_waypoints), at_field(field + ".waypoints"));
  check_region(G.spawn, field + ".spawn", limits.max_extent);
  if (G.spawn.kind == Region::Kind::points && static_cast<std::int64_t>(G.spawn.points.size()) != G.count)
    throw Error(fmt::format("{} points for a count of {}: give one point per agent", G.spawn.points.size(), G.count),
                at_field(field + ".spawn.points"));
  for (std::size_t w = 0; w < G.waypoints.size(); ++w) {
    const std::string wf = fmt::format("{}.waypoints[{}]", field, w);
    if (G.waypoints[w].kind == GoalSpec::Kind::Exits) throw Error("exits can only be a group's goal", at_field(wf));
    check_goal(G.waypoints[w], wf, limits);
  }
  if (G.goal.kind == GoalSpec::Kind::Gate)
    throw Error("a gate is a waypoint: the goal is a point, a region or exits", at_field(field + ".goal"));
  const bool periodic = spec.world.periodic_x || spec.world.periodic_y;
  if (G.goal.kind == GoalSpec::Kind::Direction && !periodic)
    throw Error("a direction goal needs a periodic world (world.periodic): elsewhere give a point to walk to",
                at_field(field + ".goal.direction"));
  if (periodic && G.goal.kind != GoalSpec::Kind::Direction)
    throw Error("in a periodic world agents walk in a direction: give goal: {direction: [x, y]}",
                at_field(field + ".goal"));
  const glm::vec2 d = G.goal.value;
  if (periodic &&
      (spec.world.periodic_x ? std::fabs(d.x) : 0.0f) + (spec.world.periodic_y ? std::fabs(d.y) : 0.0f) < 1e-3f)
    throw Error("the direction runs along no periodic axis: the agents would walk into the wall",
                at_field(field + ".goal.direction"));
  if (periodic && !G.waypoints.empty())
    throw Error("in a periodic world agents walk in a direction, without waypoints", at_field(field + ".waypoints"));
  if (G.goal.wait_s > 0)
    throw Error("the goal takes no wait (on_arrival: stop keeps agents there)", at_field(field + ".goal.wait"));
  check_goal(G.goal, field + ".goal", limits);
  if (G.goal.kind == GoalSpec::Kind::Exits && G.arrival == ArrivalBehaviour::Loop)
    throw Error("agents leave by an exit: on_arrival stop or despawn, not loop", at_field(field + ".on_arrival"));
}

// Validates the whole spec against the world and limits (errors name the
// field); returns the largest agent radius, m.
float check_scenario(const ScenarioSpec& spec, const World& world, const ScenarioLimits& limits) {
  spec.model.validate();
  if (!(spec.dt > 0) || !(spec.dt <= 10.0f))
    throw Error(fmt::format("time step must be in (0, 10] s (got {})", spec.dt), at_field("dt"));
  const std::int64_t total = spec.total_agents();
  if (total > limits.max_agents)
    throw Error(fmt::format("{} agents exceed the limit of {}", total, limits.max_agents), at_field("groups"));
  if (spec.groups.empty()) throw Error("a scenario needs at least one group", at_field("groups"));
  float max_radius = 0.0f;
  for (std::size_t g = 0; g < spec.groups.size(); ++g) {
    check_group(spec, spec.groups[g], fmt::format("groups[{}]", g), world.cell_size(), limits);
    max_radius = std::max(max_radius, spec.groups[g].radius);
  }
  std::int64_t total_waypoints = 0;
  for (const GroupSpec& G : spec.groups)
    total_waypoints +=
        G.count * static_cast<std::int64_t>(G.arrival == ArrivalBehaviour::Loop ? 2 * G.waypoints.size() + 2
                                                                                : G.waypoints.size() + 1);
  if (total_waypoints > 4 * limits.max_agents)
    throw Error(fmt::format("{} waypoints in all (agents x route points) exceed the limit of {}", total_waypoints,
                            4 * limits.max_agents),
                at_field("groups"));
  return max_radius;
}

// Grows `extent` by everything group G could need: its spawn region and
// every place its goals and waypoints can lie.
void add_group_extent(const GroupSpec& G, Aabb& extent) {
  const Aabb sb = region_bounds(G.spawn);
  extent.add(sb);
  std::vector<const GoalSpec*> goals;
  for (const GoalSpec& w : G.waypoints) goals.push_back(&w);
  goals.push_back(&G.goal);
  for (const GoalSpec* goal_ptr : goals) {
    const GoalSpec& goal = *goal_ptr;
    switch (goal.kind) {
      case GoalSpec::Kind::Point: extent.add(goal.value); break;
      case GoalSpec::Kind::Offset:
        extent.add(sb.min + goal.value);
        extent.add(sb.max + goal.value);
        break;
      case GoalSpec::Kind::Mirror:
        extent.add(2.0f * goal.value - sb.min);
        extent.add(2.0f * goal.value - sb.max);
        break;
      case GoalSpec::Kind::Random: extent.add(region_bounds(goal.region)); break;
      case GoalSpec::Kind::Gate:
        extent.add(goal.value);
        extent.add(goal.gate_to);
        break;
      case GoalSpec::Kind::Exits:
        for (const ExitSpec& x : goal.exits) extent.add(x.point);
        break;
      case GoalSpec::Kind::Direction: break;  // no place: the agent walks on
    }
  }
}

// The reachability raster over everything the agents could need, or null
// in an open world (no walkable area, no obstacle).
std::unique_ptr<Reachability> make_reachability(const ScenarioSpec& spec, const World& world,
                                                const ScenarioLimits& limits) {
  if (!world.has_walkable() && world.polygons().empty() && world.circles().empty()) return nullptr;
  Aabb extent = world.bounds();
  if (!world.has_walkable()) {
    for (const GroupSpec& G : spec.groups) add_group_extent(G, extent);
    const glm::vec2 margin = extent.size() * 0.05f + glm::vec2(5.0f);
    extent.min -= margin;
    extent.max += margin;
  }
  return std::make_unique<Reachability>(world, extent, limits.raster_resolution);
}

// Where one group is placed: its agents of radius r (m) keep `gap` (m) from
// each other and wall_clearance (m) from walls; `placed` holds the agents
// of earlier groups, `out` their spawn data.
struct Placement {
  const World& world;
  const Occupancy& placed;
  const CrowdHost& out;
  const GroupSpec& G;
  std::string field;
  float r, gap, wall_clearance;
};

// G.count agents evenly on a ring (spawn: ring), in order round it.
std::vector<glm::vec2> place_on_ring(const Placement& at) {
  const GroupSpec& G = at.G;
  const float r = at.r;
  const double R = G.spawn.radius > 0 ? G.spawn.radius : static_cast<double>(G.count) * G.spawn.spacing / (2.0 * kPi);
  if (!(R > 0)) throw Error("a ring needs radius > 0 or spacing > 0", at_field(at.field + ".spawn.ring"));
  const double chord = G.count > 1 ? 2.0 * R * std::sin(kPi / static_cast<double>(G.count)) : 2.0 * R + 2.0 * r;
  if (chord < 2.0 * r + at.gap)
    throw Error(
        fmt::format("{} agents of radius {} do not fit on a ring of radius {:.3g} m (neighbours {:.3g} m apart)",
                    G.count, r, R, chord),
        at_field(at.field + ".spawn"));
  std::vector<glm::vec2> chosen;
  for (std::int64_t k = 0; k < G.count; ++k) {
    const double a = 2.0 * kPi * static_cast<double>(k) / static_cast<double>(G.count);
    const glm::vec2 p =
        G.spawn.center + glm::vec2(static_cast<float>(R * std::cos(a)), static_cast<float>(R * std::sin(a)));
    if (!at.world.disc_fits(p, at.wall_clearance)) {
      const std::string blocked = at.world.what_blocks(p);
      throw Error(fmt::format("agent {} at {} does not fit: {}", k, point_text(p),
                              blocked.empty() ? "too close to a wall" : blocked),
                  at_field(at.field + ".spawn"));
    }
    if (at.placed.overlaps(p, r, at.gap))
      throw Error(fmt::format("agent {} at {} overlaps an agent of an earlier group", k, point_text(p)),
                  at_field(at.field + ".spawn"));
    chosen.push_back(p);
  }
  return chosen;
}

// The exact positions of spawn: points. Each must be free and apart from
// every agent so far (discs may touch); the group's own points are checked
// among themselves.
std::vector<glm::vec2> place_at_points(const Placement& at) {
  const GroupSpec& G = at.G;
  const float r = at.r;
  Occupancy own(std::max(2.0f * r * 1.2f, 0.1f), at.world.periodic());
  std::vector<glm::vec2> chosen;
  for (std::size_t k = 0; k < G.spawn.points.size(); ++k) {
    const glm::vec2 p = G.spawn.points[k];
    const std::string pf = fmt::format("{}.spawn.points[{}]", at.field, k);
    if (!at.world.disc_fits(p, at.wall_clearance)) {
      const std::string blocked = at.world.what_blocks(p);
      throw Error(fmt::format("an agent of radius {} m at {} does not fit: {}", r, point_text(p),
                              blocked.empty() ? fmt::format("closer than {:.3g} m to a wall", at.wall_clearance)
                                              : "it lies " + blocked),
                  at_field(pf));
    }
    if (const std::int64_t other = own.find(p, r, 0.0f); other >= 0)
      throw Error(fmt::format("an agent at {} overlaps the one at points[{}] {}: centres {:.3g} m apart, less than 2 * "
                              "radius = {:.3g} m",
                              point_text(p), other, point_text(G.spawn.points[static_cast<std::size_t>(other)]),
                              length_of(p - G.spawn.points[static_cast<std::size_t>(other)]), 2.0f * r),
                  at_field(pf));
    if (const std::int64_t other = at.placed.find(p, r, 0.0f); other >= 0)
      throw Error(fmt::format("an agent at {} overlaps agent {} of groups[{}] at {}", point_text(p), other,
                              at.out.group[static_cast<std::size_t>(other)],
                              point_text(at.out.position[static_cast<std::size_t>(other)])),
                  at_field(pf));
    own.add(p, r, static_cast<std::int64_t>(k));
    chosen.push_back(p);
  }
  return chosen;
}

// Free sites of jittered hexagonal lattices over the spawn region of group
// g, made denser until they hold at least G.count (see place_on_lattice).
std::vector<glm::vec2> lattice_candidates(const Placement& at, std::uint64_t seed, std::size_t g) {
  const GroupSpec& G = at.G;
  const Aabb b = region_bounds(G.spawn);
  const double d = 2.0 * at.r + at.gap;
  const double max_sites = 8.0 * static_cast<double>(G.count) + 4.0e6;
  if (hex_site_count(b, d) < static_cast<double>(G.count))
    throw Error(fmt::format("{} agents of radius {} m cannot fit in the spawn region ({:.3g} x {:.3g} m)", G.count,
                            at.r, b.size().x, b.size().y),
                at_field(at.field + ".spawn"));
  const double wanted = 3.0 * static_cast<double>(G.count);
  const double area = region_area(G.spawn);
  double a = area > 0 ? std::max(d, hex_spacing(wanted / area)) : d;
  if (hex_site_count(b, a) > max_sites)
    throw Error(fmt::format("the spawn region ({:.3g} x {:.3g} m) is too elongated for agents of radius {} m",
                            b.size().x, b.size().y, at.r),
                at_field(at.field + ".spawn"));
  std::vector<glm::vec2> candidates;
  for (int pass = 0;; ++pass) {
    Rng rng(seed, 0x59a3000000ull + g + (static_cast<std::uint64_t>(pass) << 32));
    candidates.clear();
    // Against earlier groups with 0.99 * gap: a group of the same radius
    // on the same lattice has its sites exactly d from ours, which
    // rounding must not reject.
    std::int64_t visited = 0;
    // Sites of the lattice are d apart but for those across a periodic
    // seam: of two too close there, the first is kept.
    const bool periodic = at.world.periodic().wraps();
    Occupancy across(static_cast<float>(d) * 1.01f, at.world.periodic());
    const std::int64_t sites = hex_sites(b, a, (a - d) * 0.5, rng, [&](glm::vec2 p) {
      if ((++visited & 4095) == 0) setup_checkpoint("placing agents");
      if (region_contains(G.spawn, p) && at.world.disc_fits(p, at.wall_clearance) &&
          !at.placed.overlaps(p, at.r, 0.99f * at.gap) && !(periodic && across.overlaps(p, at.r, 0.99f * at.gap))) {
        candidates.push_back(p);
        if (periodic) across.add(p, at.r, 0);
      }
    });
    if (static_cast<std::int64_t>(candidates.size()) >= G.count || a <= d) break;
    // Free area as seen by this lattice; at least a 20 % denser lattice next.
    const double free_area = static_cast<double>(b.size().x) * b.size().y * static_cast<double>(candidates.size()) /
                             static_cast<double>(sites);
    double next = free_area > 0 ? hex_spacing(wanted / free_area) : d;
    next = std::max(d, std::min(next, 0.8 * a));
    if (hex_site_count(b, next) > max_sites) break;
    a = next;
  }
  return candidates;
}

// Sites of a hexagonal lattice (the densest packing of equal discs), of
// which count are chosen at random. Sites of spacing a >= d = 2r + gap stay
// d apart when each moves less than (a - d) / 2, so jitter within that disc
// never makes an overlap. a is chosen so that the free part of the region
// holds about 3 * count sites: the random choice of a third of them and the
// jitter make sparse spawns look random; a dense spawn gets a = d, up to
// 2 / (sqrt(3) d^2) agents per m^2 (6.5 at r = 0.2 m; random sequential
// placement would jam near 4.3). The free area is not known in advance
// (obstacles, walls, other groups): when a lattice holds fewer than count
// free sites, the next one is made denser from the free fraction it found,
// down to a = d.
std::vector<glm::vec2> place_on_lattice(const Placement& at, std::uint64_t seed, std::size_t g) {
  const GroupSpec& G = at.G;
  const std::vector<glm::vec2> candidates = lattice_candidates(at, seed, g);
  if (static_cast<std::int64_t>(candidates.size()) < G.count) {
    const Aabb b = region_bounds(G.spawn);
    const glm::vec2 centre = (b.min + b.max) * 0.5f;
    const std::string blocked = at.world.what_blocks(centre);
    if (candidates.empty() && !blocked.empty())
      throw Error(fmt::format("the spawn region lies {}: no free place for an agent", blocked),
                  at_field(at.field + ".spawn"));
    throw Error(
        fmt::format(
            "room for only {} of {} agents of radius {} m in the spawn region (obstacles, walls and other groups "
            "take the rest)",
            candidates.size(), G.count, at.r),
        at_field(at.field + ".spawn"));
  }
  Rng rng(seed, 0x5e1ec7000000ull + g);
  // Choose count of them at random, then keep lattice order (neighbours
  // in space get neighbouring indices: better memory locality).
  std::vector<std::uint32_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0u);
  for (std::size_t k = 0; k < static_cast<std::size_t>(G.count); ++k) {
    const std::size_t pick = k + static_cast<std::size_t>(rng.below(order.size() - k));
    std::swap(order[k], order[pick]);
  }
  order.resize(static_cast<std::size_t>(G.count));
  std::sort(order.begin(), order.end());
  std::vector<glm::vec2> chosen;
  for (std::uint32_t k : order) chosen.push_back(candidates[k]);
  return chosen;
}

// Where each agent of an arriving group g enters: a point of its spawn area
// where its disc fits (clear of walls by the placement's clearance), drawn
// per agent from the seed. Agents entering at different times may share a
// point: the simulation admits each when its point is free.
std::vector<glm::vec2> place_entries(const Placement& at, std::uint64_t seed, std::size_t g) {
  const Aabb b = region_bounds(at.G.spawn);
  std::vector<glm::vec2> out;
  out.reserve(static_cast<std::size_t>(at.G.count));
  for (std::int64_t k = 0; k < at.G.count; ++k) {
    Rng rng(seed, (std::uint64_t{3} << 61) + (static_cast<std::uint64_t>(g) << 40) + static_cast<std::uint64_t>(k));
    bool found = false;
    glm::vec2 q(0.0f);
    for (int attempt = 0; attempt < 200 && !found; ++attempt) {
      q = glm::vec2(static_cast<float>(rng.uniform(b.min.x, b.max.x)),
                    static_cast<float>(rng.uniform(b.min.y, b.max.y)));
      found = region_contains(at.G.spawn, q) && at.world.disc_fits(q, at.wall_clearance);
    }
    if (!found)
      throw Error(fmt::format("found no free place for an agent of radius {} m to enter", at.r),
                  at_field(at.field + ".spawn"));
    out.push_back(q);
  }
  return out;
}

// The spawn positions of group g, by its spawn region's kind.
std::vector<glm::vec2> place_group(const Placement& at, std::uint64_t seed, std::size_t g) {
  if (at.G.count == 0) return {};
  if (at.G.inflow.enabled) return place_entries(at, seed, g);
  if (at.G.spawn.kind == Region::Kind::ring) return place_on_ring(at);
  if (at.G.spawn.kind == Region::Kind::points) return place_at_points(at);
  return place_on_lattice(at, seed, g);
}

// What resolving one agent's route points needs.
struct RouteContext {
  const World& world;
  const Reachability* reach;
  const ScenarioLimits& limits;
  float r;
};

// Errors unless route point q (field gf) of `agent` lies in the world, free
// and reachable from `from`. Planned routes go around obstacles; only a
// missing path is an error.
void check_route_point(const RouteContext& ctx, glm::vec2 q, glm::vec2 from, std::int64_t agent,
                       const std::string& gf) {
  const float max_extent = ctx.limits.max_extent;
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || std::fabs(q.x) > max_extent || std::fabs(q.y) > max_extent)
    throw Error(fmt::format("goal {} of agent {} is beyond the extent limit", point_text(q), agent), at_field(gf));
  if (const std::string blocked = ctx.world.what_blocks(q); !blocked.empty())
    throw Error(fmt::format("goal {} of agent {} lies {}", point_text(q), agent, blocked), at_field(gf));
  if (ctx.reach && !ctx.reach->connected(from, q))
    throw Error(
        fmt::format(
            "goal {} of agent {} is unreachable from {}: no free path joins them (checked on a {:.3g} m raster)",
            point_text(q), agent, point_text(from), ctx.reach->cell_size()),
        at_field(gf));
}

// Space kept between the bodies of agents waiting in one waiting area: at
// r = 0.25 m the spots are at least 0.75 m apart, about 2 persons per m^2
// where they are packed, so that those standing leave ways to the others.
constexpr float kWaitingSpotGap = 0.25f;  // m

// Route point `goal` (field gf) of an agent that spawned at p and comes
// from `from`: a point, or one drawn from a region with arng (free for a
// disc of radius r and reachable from `from`).
glm::vec2 resolve_goal(const RouteContext& ctx, const GoalSpec& goal, const std::string& gf, glm::vec2 p,
                       glm::vec2 from, std::int64_t agent, Rng& arng, Occupancy* spots) {
  glm::vec2 q(0.0f);
  switch (goal.kind) {
    case GoalSpec::Kind::Point: q = goal.value; break;
    case GoalSpec::Kind::Offset: q = p + goal.value; break;
    case GoalSpec::Kind::Mirror: q = 2.0f * goal.value - p; break;
    case GoalSpec::Kind::Gate: q = 0.5f * (goal.value + goal.gate_to); break;  // its middle
    case GoalSpec::Kind::Direction: q = p + goal.value * kDirectionReach; break;
    case GoalSpec::Kind::Exits: {
      // Every exit must be reachable (a quickest choice may switch to any);
      // the agent starts towards the nearest in a straight line.
      float best = INFINITY;
      for (std::size_t e = 0; e < goal.exits.size(); ++e) {
        const glm::vec2 x = goal.exits[e].point;
        check_route_point(ctx, x, from, agent, fmt::format("{}.exits[{}]", gf, e));
        if (length_of(x - from) < best) {
          best = length_of(x - from);
          q = x;
        }
      }
      break;
    }
    case GoalSpec::Kind::Random: {
      const Aabb rb = region_bounds(goal.region);
      bool found = false, taken = false;  // taken: a free, reachable place was another's spot
      for (int attempt = 0; attempt < 200 && !found; ++attempt) {
        q = glm::vec2(static_cast<float>(arng.uniform(rb.min.x, rb.max.x)),
                      static_cast<float>(arng.uniform(rb.min.y, rb.max.y)));
        found = region_contains(goal.region, q) && ctx.world.disc_fits(q, ctx.r) &&
                (!ctx.reach || ctx.reach->connected(from, q));
        if (found && spots != nullptr && spots->overlaps(q, ctx.r, kWaitingSpotGap)) {
          found = false;
          taken = true;
        }
      }
      if (!found && taken)
        throw Error(fmt::format("found no free spot for agent {} in the waiting area: each agent waiting there "
                                "stands on a spot of its own; make the area larger",
                                agent),
                    at_field(gf + ".random"));
      if (!found)
        throw Error(fmt::format("found no free place reachable from {} for agent {} in the goal region",
                                point_text(from), agent),
                    at_field(gf + ".random"));
      if (spots != nullptr) spots->add(q, ctx.r, agent);
      break;
    }
  }
  return q;
}

// One agent's pre-movement time (s) from its own generator (a stream apart
// from the one that draws its speed and goals, so adding pre-movement to a
// group changes nothing else): see PremovementSpec.
double draw_premovement(const PremovementSpec& P, Rng& rng) {
  if (P.kind == PremovementSpec::Kind::none) return 0.0;
  const double lo = P.min, hi = P.max;
  if (P.kind == PremovementSpec::Kind::uniform) return rng.uniform(lo, hi);
  const double mean = P.mean, sd = P.stddev;
  // Log-normal: mu and sigma of the logarithm from the mean and spread of the times.
  const double s2 = std::log1p((sd / mean) * (sd / mean));
  const double mu = std::log(mean) - 0.5 * s2, sigma = std::sqrt(s2);
  double t = mean;
  for (int k = 0; k < 64; ++k) {
    const double z = rng.normal();
    t = P.kind == PremovementSpec::Kind::normal ? mean + sd * z : std::exp(mu + sigma * z);
    if (t >= lo && t <= hi) return t;
  }
  return std::clamp(t, lo, hi);
}

// Appends group g's agents at `chosen` to `out` (position, radius, speed
// drawn per agent, group) and to `placed`; returns every agent's waypoints
// and goal resolved, stride waypoints + 1.
std::vector<glm::vec2> add_agents(const RouteContext& ctx, const ScenarioSpec& spec, std::size_t g,
                                  const std::vector<glm::vec2>& chosen, Occupancy& placed, CrowdHost& out) {
  const GroupSpec& G = spec.groups[g];
  const std::string field = fmt::format("groups[{}]", g);
  const auto first_agent = static_cast<std::int64_t>(out.position.size());
  const std::size_t W = G.waypoints.size();
  std::vector<glm::vec2> resolved(chosen.size() * (W + 1));
  // A waiting area gives each agent a spot of its own (not one another's).
  std::vector<Occupancy> spots(W, Occupancy(2.0f * ctx.r + kWaitingSpotGap));  // (a cell reaches every conflict)
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const glm::vec2 p = chosen[k];
    const std::int64_t agent = first_agent + static_cast<std::int64_t>(k);
    if ((k & 4095) == 4095)
      setup_checkpoint("choosing goals", static_cast<double>(k) / static_cast<double>(chosen.size()));
    if (!G.inflow.enabled) placed.add(p, ctx.r, agent);  // arriving agents take their point only when they enter
    Rng arng(spec.seed, (static_cast<std::uint64_t>(g) << 40) + static_cast<std::uint64_t>(k));
    const double speed =
        std::clamp(static_cast<double>(G.speed.mean) + static_cast<double>(G.speed.stddev) * arng.normal(),
                   static_cast<double>(G.speed.min), static_cast<double>(G.speed.max));
    out.position.push_back(p);
    out.radius.push_back(ctx.r);
    out.pref_speed.push_back(static_cast<float>(speed));
    Rng prng(spec.seed,
             (std::uint64_t{1} << 62) + (static_cast<std::uint64_t>(g) << 40) + static_cast<std::uint64_t>(k));
    const float start = G.inflow.enabled ? G.inflow.entry_time(static_cast<std::int64_t>(k))
                                         : static_cast<float>(draw_premovement(G.premovement, prng));
    out.start_time.push_back(start);
    out.flags.push_back(G.inflow.enabled ? kAgentPending
                                         : (start > 0.0f ? kAgentActive | kAgentWaiting : kAgentActive));
    out.group.push_back(static_cast<std::int32_t>(g));
    glm::vec2 from = p;
    for (std::size_t w = 0; w <= W; ++w) {
      const GoalSpec& goal = w < W ? G.waypoints[w] : G.goal;
      const std::string gf = w < W ? fmt::format("{}.waypoints[{}]", field, w) : field + ".goal";
      const bool waiting_area = w < W && goal.kind == GoalSpec::Kind::Random && goal.wait_s > 0.0f;
      const glm::vec2 q = resolve_goal(ctx, goal, gf, p, from, agent, arng, waiting_area ? &spots[w] : nullptr);
      if (goal.kind != GoalSpec::Kind::Direction) check_route_point(ctx, q, from, agent, gf);
      resolved[k * (W + 1) + w] = q;
      from = q;
    }
  }
  return resolved;
}

// Appends to out.stages what group G's waypoints ask beyond being reached
// (a gate's extent, a wait) and its exits given as door lines (gates), and
// to out.exit_stages the group's exits' stages; returns each waypoint's
// index there, -1 for a plain point.
std::vector<std::int32_t> add_stages(const GroupSpec& G, CrowdHost& out) {
  auto add = [&](glm::vec2 half, float wait_s) {
    out.stages.push_back({half, wait_s});
    return static_cast<std::int32_t>(out.stages.size()) - 1;
  };
  std::vector<std::int32_t> ids(G.waypoints.size(), -1);
  for (std::size_t w = 0; w < G.waypoints.size(); ++w) {
    const GoalSpec& goal = G.waypoints[w];
    if (goal.kind == GoalSpec::Kind::Gate)
      ids[w] = add(0.5f * (goal.gate_to - goal.value), goal.wait_s);
    else if (goal.wait_s > 0.0f)
      ids[w] = add(glm::vec2(0.0f), goal.wait_s);
  }
  std::vector<std::int32_t>& exits = out.exit_stages.emplace_back();
  if (G.goal.kind == GoalSpec::Kind::Exits)
    for (const ExitSpec& x : G.goal.exits) exits.push_back(length2(x.half) > 0.0f ? add(x.half, 0.0f) : -1);
  return ids;
}

// Appends the routes of the agents at `chosen` (group G, field) to `out`:
// their waypoints (or, for a goal without waypoints, the planner's points
// in between, when there is a planner), the goal, the way back for a loop,
// and the heading towards the first point.
void add_routes(const GroupSpec& G, const std::string& field, const std::vector<glm::vec2>& chosen,
                const std::vector<glm::vec2>& resolved, const std::vector<std::int32_t>& stage_ids,
                const std::vector<std::int32_t>& exit_stages, const World& world, const RoutePlanner* planner,
                const ScenarioLimits& limits, float r, CrowdHost& out) {
  const std::size_t W = G.waypoints.size();
  std::vector<std::vector<glm::vec2>> planned;
  // (Agents choosing among exits walk straight: a planned route would hold
  // them to the exit they started towards.)
  if (planner != nullptr && W == 0 && !chosen.empty() && G.goal.kind != GoalSpec::Kind::Exits &&
      G.goal.kind != GoalSpec::Kind::Direction) {
    planned = planner->plan(world, chosen, resolved, r);
    if (planned.size() != chosen.size())
      throw Error(fmt::format("the route planner returned {} routes for {} agents", planned.size(), chosen.size()),
                  at_field(field + ".goal"));
  }
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const glm::vec2 p = chosen[k];
    const auto begin = static_cast<std::int32_t>(out.waypoints.size());
    out.waypoint_begin.push_back(begin);
    std::span<const glm::vec2> via(resolved.data() + k * (W + 1), W);
    if (!planned.empty()) via = planned[k];
    if (static_cast<std::int64_t>(via.size()) > limits.max_waypoints)
      throw Error(fmt::format("a planned route has {} points, more than {}", via.size(), limits.max_waypoints),
                  at_field(field + ".goal"));
    // (Planned points are plain; the group's own waypoints carry their stages.)
    auto stage = [&](std::size_t v) { return planned.empty() ? stage_ids[v] : -1; };
    out.waypoints.insert(out.waypoints.end(), via.begin(), via.end());
    for (std::size_t v = 0; v < via.size(); ++v) out.waypoint_stage.push_back(stage(v));
    // (An exit goal: the stage of the exit spawning chose, a door line's gate.)
    const glm::vec2 goal = resolved[k * (W + 1) + W];
    const std::int32_t chosen_exit = exit_stages.empty() ? -1 : G.goal.exit_at(goal);
    const std::int32_t goal_stage = chosen_exit < 0 ? -1 : exit_stages[static_cast<std::size_t>(chosen_exit)];
    out.waypoints.push_back(goal);
    out.waypoint_stage.push_back(goal_stage);
    out.waypoint_goal.push_back(static_cast<std::int32_t>(out.waypoints.size()) - 1 - begin);
    // A loop walks back along the route to where the agent started.
    if (G.arrival == ArrivalBehaviour::Loop) {
      for (std::size_t v = via.size(); v-- > 0;) {
        out.waypoints.push_back(via[v]);
        out.waypoint_stage.push_back(stage(v));
      }
      out.waypoints.push_back(p);
      out.waypoint_stage.push_back(-1);
    }
    out.waypoint_count.push_back(static_cast<std::int32_t>(out.waypoints.size()) - begin);
    const glm::vec2 to = out.waypoints[static_cast<std::size_t>(begin)] - p;
    out.heading.push_back(length2(to) > 0 ? std::atan2(to.y, to.x) : 0.0f);
  }
}

}  // namespace

CrowdHost spawn_crowd(const ScenarioSpec& spec, const World& world, const ScenarioLimits& limits,
                      const RoutePlanner* planner) {
  const float max_radius = check_scenario(spec, world, limits);
  const std::unique_ptr<Reachability> reach = make_reachability(spec, world, limits);
  CrowdHost out;
  out.position.reserve(static_cast<std::size_t>(spec.total_agents()));
  Occupancy placed(std::max(2.0f * max_radius * 1.2f, 0.1f), world.periodic());
  for (std::size_t g = 0; g < spec.groups.size(); ++g) {
    check_interrupt("placing agents");
    const GroupSpec& G = spec.groups[g];
    const std::string field = fmt::format("groups[{}]", g);
    const float r = G.radius;
    const Placement at{world, placed, out, G, field, r, 0.1f * r, 1.05f * r};
    const std::vector<glm::vec2> chosen = place_group(at, spec.seed, g);
    GroupRuntime rt;
    rt.arrival = G.arrival;
    rt.arrival_radius = G.arrival_radius;
    out.groups.push_back(rt);
    const RouteContext ctx{world, reach.get(), limits, r};
    const std::vector<glm::vec2> resolved = add_agents(ctx, spec, g, chosen, placed, out);
    const std::vector<std::int32_t> stage_ids = add_stages(G, out);
    add_routes(G, field, chosen, resolved, stage_ids, out.exit_stages.back(), world, planner, limits, r, out);
  }
  return out;
}

CrowdState upload_crowd(const CrowdHost& h, Memory m) {
  CrowdState c;
  const auto n = static_cast<Index>(h.position.size());
  c.count = n;
  auto up = [m](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    return Buffer<T>(std::span<const T>(v), m);
  };
  c.position = up(h.position);
  c.velocity = Buffer<glm::vec2>::zeros(n, m);
  c.heading = up(h.heading);
  c.radius = up(h.radius);
  c.pref_speed = up(h.pref_speed);
  c.path_start = up(h.position);
  std::vector<glm::vec2> goals(h.position.size());
  for (std::size_t i = 0; i < goals.size(); ++i) goals[i] = h.waypoints[static_cast<std::size_t>(h.waypoint_begin[i])];
  c.goal = up(goals);
  c.waypoint_begin = up(h.waypoint_begin);
  c.waypoint_count = up(h.waypoint_count);
  c.waypoint_goal = up(h.waypoint_goal);
  c.waypoint_cursor = Buffer<std::int32_t>::zeros(n, m);
  c.group = up(h.group);
  // (Hand-made crowds may leave start times and flags out: all walk at once.)
  c.flags = up(h.flags.empty() ? std::vector<std::uint8_t>(h.position.size(), kAgentActive) : h.flags);
  c.start_time = up(h.start_time.empty() ? std::vector<float>(h.position.size(), 0.0f) : h.start_time);
  c.arrival_time = up(std::vector<float>(h.position.size(), -1.0f));
  c.waypoints = up(h.waypoints);
  c.waypoint_stage =
      up(h.waypoint_stage.empty() ? std::vector<std::int32_t>(h.waypoints.size(), -1) : h.waypoint_stage);
  // (One entry at least: a device span of a null buffer is no table.)
  c.stages = up(h.stages.empty() ? std::vector<StageRuntime>(1) : h.stages);
  c.groups = up(h.groups);
  return c;
}

}  // namespace throng::sim
