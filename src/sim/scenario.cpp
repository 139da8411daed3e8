#include "sim/scenario.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "core/error.h"
#include "core/ground.h"

namespace throng::sim {

namespace {
void check_range(float v, float lo, float hi, bool lo_inclusive, const char* field, const char* what) {
  const bool above = lo_inclusive ? v >= lo : v > lo;
  if (!std::isfinite(v) || !above || v > hi)
    throw Error(fmt::format("{} must be {} {} and at most {} (got {})", what, lo_inclusive ? ">=" : ">", lo, hi, v),
                at_field(field));
}
}  // namespace

void ModelParams::validate() const {
  check_range(pred_time, 0.0f, 100.0f, false, "model.pred_time", "prediction time (s)");
  check_range(max_speed, 0.0f, 100.0f, false, "model.max_speed", "maximum speed (m/s)");
  check_range(max_force, 0.0f, 1000.0f, false, "model.max_force", "maximum steering acceleration (m/s^2)");
  check_range(personal_space, 0.0f, 100.0f, true, "model.personal_space", "personal space (m)");
  check_range(lane_half_width, 0.0f, 1000.0f, false, "model.lane_half_width", "lane half-width (m)");
  check_range(relaxation_time, 0.0f, 100.0f, false, "model.relaxation_time", "relaxation time (s)");
  check_range(probe_margin, 0.0f, 100.0f, true, "model.probe_margin", "probe margin (m)");
  if (contact_iterations < 0 || contact_iterations > 64)
    throw Error(fmt::format("contact iterations must be in [0, 64] (got {})", contact_iterations),
                at_field("model.contact_iterations"));
  if (contact_extra_iterations < 0 || contact_extra_iterations > 64)
    throw Error(fmt::format("extra contact iterations must be in [0, 64] (got {})", contact_extra_iterations),
                at_field("model.contact_extra_iterations"));
  check_range(contact_tolerance, 0.0f, 1.0f, true, "model.contact_tolerance", "contact tolerance (m)");
  check_range(body_radius_limit, 0.0f, 10.0f, true, "model.max_radius",
              "largest agent radius (m; 0 = the model's default)");
  check_range(cfs.time_gap, 0.0f, 100.0f, false, "model.time_gap", "time gap (s)");
  check_range(cfs.neighbour_strength, 0.0f, 1000.0f, true, "model.neighbour_strength", "neighbour repulsion strength");
  check_range(cfs.neighbour_range, 0.001f, 10.0f, true, "model.neighbour_range", "neighbour repulsion range (m)");
  check_range(cfs.wall_strength, 0.0f, 1000.0f, true, "model.wall_strength", "wall repulsion strength");
  check_range(cfs.wall_range, 0.001f, 10.0f, true, "model.wall_range", "wall repulsion range (m)");
  check_range(cfs.avoid_strength, 0.0f, 100.0f, true, "model.avoid_strength", "anticipation strength");
  check_range(cfs.avoid_time, 0.0f, 100.0f, false, "model.avoid_time", "anticipation time (s)");
  check_range(cfs.side_margin, 0.0f, 10.0f, true, "model.side_margin", "anticipation side margin (m)");
  check_range(cfs.turn_time, 0.0f, 10.0f, true, "model.turn_time", "turn time (s)");
  check_range(cfs.anticipation_time, 0.0f, 10.0f, true, "model.anticipation_time", "anticipation time (s)");
  check_range(cfs.lane_width, 0.5f, 1.0f, true, "model.lane_width", "lane width (of the summed radii)");
  check_range(ttc.strength, 0.0f, 100.0f, true, "model.ttc_strength", "interaction strength k (m^2)");
  check_range(ttc.time_horizon, 0.1f, 100.0f, true, "model.ttc_time_horizon", "interaction time horizon tau0 (s)");
  check_range(ttc.relaxation_time, 0.01f, 100.0f, true, "model.ttc_relaxation_time", "goal relaxation time (s)");
  check_range(ttc.sensing_radius, 1.0f, 20.0f, true, "model.ttc_sensing_radius", "sensing radius (m)");
  check_range(ttc.max_acceleration, 0.0f, 1000.0f, false, "model.ttc_max_acceleration", "largest acceleration (m/s^2)");
  check_range(ttc.side_bias, 0.0f, 10.0f, true, "model.ttc_side_bias", "keep-right bias");
  check_range(sf.mass, 1.0f, 1000.0f, true, "model.sf_mass", "mass (kg)");
  check_range(sf.relaxation_time, 0.01f, 100.0f, true, "model.sf_relaxation_time", "goal relaxation time (s)");
  check_range(sf.strength, 0.0f, 1.0e5f, true, "model.sf_strength", "social repulsion strength A (N)");
  check_range(sf.range, 0.01f, 10.0f, true, "model.sf_range", "social repulsion range B (m)");
  check_range(sf.body_stiffness, 0.0f, 1.0e7f, true, "model.sf_body_stiffness", "body stiffness k (kg/s^2)");
  check_range(sf.friction, 0.0f, 1.0e7f, true, "model.sf_friction", "sliding friction kappa (kg/(m s))");
  check_range(sf.anisotropy, 0.0f, 1.0f, true, "model.sf_anisotropy", "anisotropy lambda");
  check_range(sf.sensing_radius, 1.0f, 20.0f, true, "model.sf_sensing_radius", "sensing radius (m)");
  check_range(sf.max_substep, 0.0005f, 0.05f, true, "model.sf_max_substep", "largest substep (s)");
  check_range(sf.side_bias, 0.0f, 10.0f, true, "model.sf_side_bias", "keep-right bias");
}

const char* to_string(ModelKind k) {
  if (k == ModelKind::Priority) return "priority";
  if (k == ModelKind::SocialForce) return "social_force";
  return k == ModelKind::Ttc ? "ttc" : "collision_free_speed";
}

ModelKind parse_model_kind(const std::string& text, const std::string& field) {
  if (text == "collision_free_speed") return ModelKind::CollisionFreeSpeed;
  if (text == "priority") return ModelKind::Priority;
  if (text == "ttc") return ModelKind::Ttc;
  if (text == "social_force") return ModelKind::SocialForce;
  throw Error("unknown model type '" + text + "' (collision_free_speed, priority, ttc or social_force)",
              at_field(field));
}

const char* to_string(ArrivalBehaviour a) {
  switch (a) {
    case ArrivalBehaviour::Stop: return "stop";
    case ArrivalBehaviour::Despawn: return "despawn";
    case ArrivalBehaviour::Loop: return "loop";
  }
  return "?";
}

const char* to_string(SchedulerKind s) { return s == SchedulerKind::FourColour ? "four_colour" : "double_buffer"; }
const char* to_string(PlanningKind p) {
  switch (p) {
    case PlanningKind::None: return "none";
    case PlanningKind::Field: return "field";
    case PlanningKind::Quickest: return "quickest";
    case PlanningKind::Roadmap: break;
  }
  return "roadmap";
}

SchedulerKind parse_scheduler(const std::string& text, const std::string& field) {
  if (text == "double_buffer") return SchedulerKind::DoubleBuffer;
  if (text == "four_colour" || text == "four_color") return SchedulerKind::FourColour;
  throw Error("unknown scheduler '" + text + "' (double_buffer or four_colour)", at_field(field));
}

std::int64_t ScenarioSpec::total_agents() const {
  std::int64_t n = 0;
  for (const GroupSpec& g : groups) n += g.count;
  return n;
}

std::int64_t ScenarioSpec::step_count() const {
  if (steps > 0) return steps;
  return static_cast<std::int64_t>(std::ceil(static_cast<double>(duration) / static_cast<double>(dt) - 1e-9));
}

Camera overview_camera(const Aabb& extent) {
  const glm::vec2 centre = extent.empty() ? glm::vec2(0.0f) : 0.5f * (extent.min + extent.max);
  const float reach = std::max(0.5f * glm::length(extent.size()), 5.0f);  // radius of a sphere around the scene
  Camera c;
  c.fov_y = 0.9272952f;
  const float distance = reach / std::sin(0.5f * c.fov_y);  // the sphere fits the vertical field of view
  const float elevation = 0.6981317f;                       // 40 degrees
  const glm::vec2 from_south_west(-0.70710678f, -0.70710678f);
  const glm::vec2 ground = centre + from_south_west * (distance * std::cos(elevation));
  c.position = world_from_ground(ground, distance * std::sin(elevation));
  c.target = world_from_ground(centre);
  c.near_plane = std::max(0.1f, 0.01f * distance);
  c.far_plane = distance + 2.0f * reach;
  return c;
}

void scale_agent_counts(ScenarioSpec& spec, std::int64_t total) {
  const auto groups = static_cast<std::int64_t>(spec.groups.size());
  if (groups == 0) throw Error("the scenario has no groups to resize", at_field("--agents"));
  if (total < groups)
    throw Error(fmt::format("need at least one agent per group ({} groups)", groups), at_field("--agents"));
  for (std::size_t g = 0; g < spec.groups.size(); ++g) {
    if (spec.groups[g].spawn.kind == Region::Kind::points)
      throw Error(fmt::format("groups[{}] spawns at {} fixed points and cannot be resized", g,
                              spec.groups[g].spawn.points.size()),
                  at_field("--agents"));
    if (!spec.groups[g].inflow.times.empty())
      throw Error(fmt::format("groups[{}] enters at {} listed times and cannot be resized", g,
                              spec.groups[g].inflow.times.size()),
                  at_field("--agents"));
  }
  const std::int64_t old_total = spec.total_agents();
  std::vector<std::int64_t> counts(spec.groups.size(), 1);
  std::vector<std::pair<double, std::size_t>> remainders;
  std::int64_t assigned = 0;
  for (std::size_t g = 0; g < spec.groups.size(); ++g) {
    // Equal shares when the scenario has no agents to take proportions from.
    const double share = old_total > 0 ? static_cast<double>(spec.groups[g].count) / static_cast<double>(old_total)
                                       : 1.0 / static_cast<double>(groups);
    const double exact = share * static_cast<double>(total - groups);
    counts[g] += static_cast<std::int64_t>(std::floor(exact));
    assigned += counts[g];
    remainders.push_back({exact - std::floor(exact), g});
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; assigned < total; k = (k + 1) % remainders.size(), ++assigned) ++counts[remainders[k].second];
  for (std::size_t g = 0; g < spec.groups.size(); ++g) spec.groups[g].count = counts[g];
}

}  // namespace throng::sim
