// throng route SCENARIO: the routes a sample of agents will walk, as `throng
// run` plans them (waypoints as given, or filled in by the route planner),
// printed and written as GeoJSON or CSV.
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/scenario_choice.h"
#include "core/error.h"
#include "io/routes_output.h"
#include "io/run_outputs.h"
#include "io/scenario_yaml.h"

namespace throng::app {

namespace {

struct RouteOptions {
  ScenarioChoice choice;
  Index sample = 10;
  std::string out;
  std::string format = "geojson";
};

void print_route(const io::AgentRoute& r) {
  std::printf("agent %lld (%s): %zu waypoints, %.1f m (straight %.1f m):", static_cast<long long>(r.agent),
              r.group.c_str(), r.points.size() - 2, r.length_m, r.straight_m);
  for (std::size_t k = 0; k < r.points.size(); ++k)
    std::printf("%s(%.2f, %.2f)", k == 0 ? " " : " -> ", static_cast<double>(r.points[k].x),
                static_cast<double>(r.points[k].y));
  std::printf("\n");
}

void route(const RouteOptions& o) {
  const io::LoadedScenario loaded = o.choice.load();
  const sim::ScenarioSpec& spec = loaded.spec;
  std::fprintf(stderr, "throng route: %s: %lld agents, planning %s\n", spec.name.c_str(),
               static_cast<long long>(spec.total_agents()), to_string(spec.planning));
  const std::unique_ptr<sim::Simulation> sim = io::build_simulation(loaded);
  const std::vector<io::AgentRoute> routes = io::sample_routes(*sim, o.sample);
  for (const io::AgentRoute& r : routes) print_route(r);
  const std::string dir = !o.out.empty() ? o.out : "out/" + spec.name;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create the output folder: " + ec.message(), at_field("--out", dir));
  const std::string path = dir + (o.format == "csv" ? "/routes.csv" : "/routes.geojson");
  if (o.format == "csv")
    io::write_text_file(path, io::routes_csv(routes));
  else
    io::write_json_file(path, io::routes_geojson(routes));
  std::fprintf(stderr, "throng route: wrote %s (%zu routes of %lld agents)\n", path.c_str(), routes.size(),
               static_cast<long long>(sim->agent_count()));
}

}  // namespace

void add_route_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand(
      "route", "Print and write the routes a sample of agents will walk (as `throng run` plans them): GeoJSON or CSV");
  static RouteOptions o;
  o.choice.add_options(*cmd);
  cmd->add_option("--sample", o.sample, "How many agents, spread evenly over the crowd")
      ->check(at_least(1))
      ->capture_default_str();
  cmd->add_option("--out", o.out, "Output folder (default: out/<scenario>)");
  cmd->add_option("--format", o.format, "geojson (DIR/routes.geojson) or csv (DIR/routes.csv)")
      ->check(CLI::IsMember({"geojson", "csv"}))
      ->capture_default_str();
  cmd->callback([&g] {
    apply_global_options(g);
    route(o);
  });
}

}  // namespace throng::app
