// The Python module `throng` (docs/python.md): scenarios loaded as `throng run`
// loads them (io::load_scenario), simulations built as it builds them
// (io::build_simulation: routes planned, errors located in the file), stepped
// from Python, and the crowd's state returned as NumPy arrays.
//
// The arrays are copies taken when the property is read (the crowd's buffers
// may live in GPU memory, and a view would silently change under the next
// step), so reading them between steps is always safe.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/exec.h"
#include "core/interrupt.h"
#include "io/scenario_yaml.h"
#include "sim/crowd.h"
#include "sim/simulation.h"

namespace py = pybind11;

namespace throng::python {

namespace {

// What errors in scenarios given as a dict name as their file.
constexpr const char* kDictSource = "<dict>";

// A dict becomes scenario text through JSON, which is YAML: the one strict
// reader (unknown keys, types, limits) checks it, and errors name the key
// path ("groups[0].speed") as they do for a file.
io::LoadedScenario scenario_from_dict(const py::dict& d) {
  const std::string text = py::module_::import("json").attr("dumps")(d).cast<std::string>();
  return io::parse_scenario(text, kDictSource);
}

// (n, 2) float32 copy of per-agent 2D vectors.
py::array_t<float> vec2_array(const std::vector<glm::vec2>& v) {
  py::array_t<float> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{2}});
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(glm::vec2));
  return out;
}

py::array_t<float> float_array(const std::vector<float>& v) {
  py::array_t<float> out(static_cast<py::ssize_t>(v.size()));
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(float));
  return out;
}

// (n,) bool: whether each agent's flags have `bit`.
py::array_t<bool> flag_array(const std::vector<std::uint8_t>& flags, std::uint8_t bit) {
  py::array_t<bool> out(static_cast<py::ssize_t>(flags.size()));
  bool* p = out.mutable_data();
  for (std::size_t i = 0; i < flags.size(); ++i) p[i] = (flags[i] & bit) != 0;
  return out;
}

// A simulation with the scenario it was built from (its source maps field
// errors back to file lines).
class PySimulation {
 public:
  PySimulation(io::LoadedScenario scenario, std::optional<std::uint64_t> seed, std::optional<std::int64_t> agents)
      : scenario_(std::move(scenario)) {
    sim::ScenarioSpec& spec = scenario_.spec;
    // Like `throng run --agents N --seed S`; a bad count names "agents".
    if (agents) {
      try {
        sim::scale_agent_counts(spec, *agents);
      } catch (const Error& e) {
        throw Error(e.message(), at_field("agents"));
      }
    }
    if (seed) spec.seed = *seed;
    // Set-up polls the interrupt flag; a previous command's Ctrl-C must not
    // end this one.
    interrupt_flag() = false;
    py::gil_scoped_release release;
    sim_ = io::build_simulation(scenario_);
  }

  // n steps; Ctrl-C in Python ends the call between steps (KeyboardInterrupt).
  void step(std::int64_t n) {
    if (n < 0) throw py::value_error("step(n): n must be >= 0, got " + std::to_string(n));
    for (std::int64_t i = 0; i < n; ++i) {
      {
        py::gil_scoped_release release;
        sim_->step();
      }
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  const sim::Simulation& sim() const { return *sim_; }
  const io::LoadedScenario& scenario() const { return scenario_; }

 private:
  io::LoadedScenario scenario_;
  std::unique_ptr<sim::Simulation> sim_;
};

io::LoadedScenario load(const py::object& source) {
  if (py::isinstance<py::dict>(source)) return scenario_from_dict(source.cast<py::dict>());
  // str or os.PathLike: a built-in name, else a file.
  return io::load_scenario(py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>());
}

}  // namespace

}  // namespace throng::python

// At file scope: the macro defines the module's extern "C" entry point.
using namespace throng;          // NOLINT(google-build-using-namespace)
using namespace throng::python;  // NOLINT(google-build-using-namespace)

PYBIND11_MODULE(throng, m) {
  m.doc() = "throng crowd simulation: load scenarios, step simulations, read the crowd as NumPy arrays";

  // throng::Error's text is "file:line:column: field: message" (core/error.h).
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError);
  py::register_exception<Interrupted>(m, "Interrupted", PyExc_KeyboardInterrupt);

  m.def("builtin_scenarios", &io::builtin_scenario_names, "Names of the built-in scenarios (the files of examples/)");

  m.def(
      "configure",
      [](const std::string& backend, int threads) {
        if (threads < 0) throw Error("thread count must be >= 0 (0 = all cores)", at_field("threads"));
        configure_execution(resolve_backend(parse_backend_choice(backend)), threads);
      },
      py::arg("backend") = "cpu", py::arg("threads") = 0,
      "Where kernels run (\"auto\", \"cpu\" or \"cuda\") and on how many CPU threads (0 = all cores), as throng's "
      "--backend and --threads. Affects simulations created afterwards.");

  py::class_<io::LoadedScenario>(m, "Scenario", "A scenario as read from YAML (docs/scenarios.md)")
      .def_property_readonly("name", [](const io::LoadedScenario& s) { return s.spec.name; })
      .def_property_readonly("description", [](const io::LoadedScenario& s) { return s.spec.description; })
      .def_property_readonly(
          "source", [](const io::LoadedScenario& s) { return s.source.file; },
          "The file read, \"builtin:<name>\" or \"<dict>\"")
      .def_property_readonly("agent_count", [](const io::LoadedScenario& s) { return s.spec.total_agents(); })
      .def_property_readonly("dt", [](const io::LoadedScenario& s) { return s.spec.dt; })
      .def_property_readonly("seed", [](const io::LoadedScenario& s) { return s.spec.seed; })
      .def_property_readonly(
          "duration_steps", [](const io::LoadedScenario& s) { return s.spec.step_count(); },
          "Steps in the scenario's duration (what `throng run` runs)")
      .def_property_readonly(
          "groups",
          [](const io::LoadedScenario& s) {
            std::vector<std::pair<std::string, std::int64_t>> g;
            for (const sim::GroupSpec& group : s.spec.groups) g.emplace_back(group.name, group.count);
            return g;
          },
          "(name, count) of each group")
      .def("__repr__", [](const io::LoadedScenario& s) {
        return "<throng.Scenario " + s.spec.name + " from " + s.source.file + ", " +
               std::to_string(s.spec.total_agents()) + " agents>";
      });

  m.def("load_scenario", &load, py::arg("source"),
        "A scenario from a built-in name (\"circle\"), a YAML file path, or a dict with the YAML file's structure. "
        "Errors raise throng.Error naming the file (or \"<dict>\"), line and key.");

  py::class_<PySimulation>(m, "Simulation", "A crowd simulation built from a scenario as `throng run` builds it")
      .def(py::init([](const py::object& scenario, std::optional<std::uint64_t> seed,
                       std::optional<std::int64_t> agents) {
             io::LoadedScenario loaded =
                 py::isinstance<io::LoadedScenario>(scenario) ? scenario.cast<io::LoadedScenario>() : load(scenario);
             return std::make_unique<PySimulation>(std::move(loaded), seed, agents);
           }),
           py::arg("scenario"), py::arg("seed") = py::none(), py::arg("agents") = py::none(),
           "scenario: a Scenario, or anything load_scenario takes. seed: replaces the scenario's seed. "
           "agents: total agent count, the groups keeping their proportions (as `throng run --agents`).")
      .def("step", &PySimulation::step, py::arg("n") = 1, "Advances n steps of dt")
      .def_property_readonly("scenario", &PySimulation::scenario, py::return_value_policy::copy)
      .def_property_readonly(
          "time", [](const PySimulation& s) { return s.sim().time(); }, "Simulated seconds")
      .def_property_readonly("steps", [](const PySimulation& s) { return s.sim().steps_done(); })
      .def_property_readonly("dt", [](const PySimulation& s) { return s.sim().spec().dt; })
      .def_property_readonly("seed", [](const PySimulation& s) { return s.sim().spec().seed; })
      .def_property_readonly("agent_count", [](const PySimulation& s) { return s.sim().agent_count(); })
      .def_property_readonly("active_count", [](const PySimulation& s) { return s.sim().active_count(); })
      .def_property_readonly("arrived_count", [](const PySimulation& s) { return s.sim().arrived_count(); })
      .def_property_readonly("pending_count", [](const PySimulation& s) { return s.sim().pending_count(); })
      .def_property_readonly("all_arrived", [](const PySimulation& s) { return s.sim().all_arrived(); })
      .def_property_readonly(
          "positions", [](const PySimulation& s) { return vec2_array(s.sim().positions()); },
          "(n, 2) float32 copy, metres")
      .def_property_readonly(
          "velocities", [](const PySimulation& s) { return vec2_array(s.sim().velocities()); },
          "(n, 2) float32 copy, m/s")
      .def_property_readonly(
          "goals", [](const PySimulation& s) { return vec2_array(s.sim().crowd().goal.to_vector()); },
          "(n, 2) float32 copy: the end of each agent's current leg (its current waypoint)")
      .def_property_readonly(
          "headings", [](const PySimulation& s) { return float_array(s.sim().headings()); },
          "(n,) float32 copy, radians from +x")
      .def_property_readonly(
          "radii", [](const PySimulation& s) { return float_array(s.sim().crowd().radius.to_vector()); },
          "(n,) float32 copy, metres")
      .def_property_readonly(
          "arrival_times", [](const PySimulation& s) { return float_array(s.sim().arrival_times()); },
          "(n,) float32 copy, seconds; -1 until the agent arrived")
      .def_property_readonly(
          "active", [](const PySimulation& s) { return flag_array(s.sim().flags(), sim::kAgentActive); },
          "(n,) bool copy: in the scene (entered, when the group arrives over time, and not despawned)")
      .def_property_readonly(
          "arrived", [](const PySimulation& s) { return flag_array(s.sim().flags(), sim::kAgentArrived); },
          "(n,) bool copy: reached its goal at least once")
      .def("__repr__", [](const PySimulation& s) {
        return "<throng.Simulation " + s.sim().spec().name + ", " + std::to_string(s.sim().agent_count()) +
               " agents, step " + std::to_string(s.sim().steps_done()) + ">";
      });
}
