"""The Python module `throng` (src/python/module.cpp, docs/python.md).

Run by ctest as python.pytest with PYTHONPATH set to the build's python/
folder; small crowds keep the whole file to a few seconds.
"""
import numpy as np
import pytest

import throng

AGENTS = 100  # circle scaled down from 1000: a ring of 100 agents 1 m apart


def circle(**kwargs):
    kwargs.setdefault("agents", AGENTS)
    return throng.Simulation("circle", **kwargs)


def test_builtin_scenarios_include_circle():
    assert "circle" in throng.builtin_scenarios()


def test_load_builtin_scenario():
    s = throng.load_scenario("circle")
    assert s.name == "circle"
    assert s.source == "builtin:circle"
    assert s.agent_count == 1000
    assert s.dt == pytest.approx(0.1)
    assert s.groups == [("ring", 1000)]


def test_step_and_arrays():
    sim = circle()
    assert sim.agent_count == AGENTS
    assert sim.steps == 0 and sim.time == 0.0
    sim.step(100)
    assert sim.steps == 100
    assert sim.time == pytest.approx(100 * 0.1)
    for name in ("positions", "velocities", "goals"):
        a = getattr(sim, name)
        assert isinstance(a, np.ndarray)
        assert a.shape == (AGENTS, 2) and a.dtype == np.float32, name
    for name in ("headings", "radii", "arrival_times"):
        a = getattr(sim, name)
        assert a.shape == (AGENTS,) and a.dtype == np.float32, name
    for name in ("active", "arrived"):
        a = getattr(sim, name)
        assert a.shape == (AGENTS,) and a.dtype == np.bool_, name
    assert sim.active.all()
    assert sim.active_count == AGENTS


def test_agents_move_towards_their_goals():
    sim = circle()
    start = sim.positions
    goals = sim.goals
    sim.step(100)
    before = np.linalg.norm(goals - start, axis=1)
    after = np.linalg.norm(goals - sim.positions, axis=1)
    # Ten seconds at about 1.3 m/s on a ring of radius ~16 m: every agent is
    # closer to its antipode, most by several metres.
    assert (after < before).all()
    assert np.median(before - after) > 5.0


def test_arrays_are_copies():
    sim = circle()
    positions = sim.positions
    sim.step(10)
    assert not np.array_equal(positions, sim.positions)


def test_same_seed_same_arrays():
    a, b = circle(seed=7), circle(seed=7)
    a.step(50)
    b.step(50)
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.velocities, b.velocities)
    assert np.array_equal(a.headings, b.headings)
    assert a.seed == 7


def test_seed_changes_the_run():
    a, b = circle(seed=1), circle(seed=2)
    a.step(20)
    b.step(20)
    assert not np.array_equal(a.velocities, b.velocities)


def test_agents_override_keeps_the_scenario_unchanged():
    scenario = throng.load_scenario("circle")
    sim = throng.Simulation(scenario, agents=40)
    assert sim.agent_count == 40
    assert scenario.agent_count == 1000


def test_bad_agent_count_names_the_argument():
    with pytest.raises(throng.Error, match="agents"):
        throng.Simulation("circle", agents=0)


def test_missing_file_names_it(tmp_path):
    path = tmp_path / "nowhere.yaml"
    with pytest.raises(throng.Error, match="nowhere.yaml"):
        throng.load_scenario(str(path))


def test_bad_scenario_error_names_file_line_and_key(tmp_path):
    path = tmp_path / "bad.yaml"
    text = throng_yaml_text().replace("radius: 0.25", "radius: quarter")
    path.write_text(text)
    with pytest.raises(throng.Error) as e:
        throng.Simulation(path)  # os.PathLike works as well as str
    message = str(e.value)
    line = text.splitlines().index("    radius: quarter") + 1
    assert f"bad.yaml:{line}:" in message
    assert "groups[0].radius" in message
    assert isinstance(e.value, RuntimeError)


def test_scenario_from_dict():
    spec = {
        "name": "two",
        "dt": 0.1,
        "duration": 60,
        "groups": [
            {
                "name": "pair",
                "count": 2,
                "radius": 0.25,
                "speed": {"mean": 1.2},
                "spawn": {"points": [[-5, 0], [5, 0.5]]},
                "goal": {"mirror": [0, 0]},
            }
        ],
    }
    scenario = throng.load_scenario(spec)
    assert scenario.source == "<dict>"
    sim = throng.Simulation(spec, seed=3)
    assert sim.agent_count == 2
    # Head-on, 0.5 m apart sideways: they sidestep each other on the way.
    sim.step(400)
    assert sim.arrived.all()


def test_dict_errors_name_the_key():
    with pytest.raises(throng.Error, match=r"<dict>.*groups\[0\]\.count"):
        throng.load_scenario({"name": "x", "groups": [{"name": "g", "count": "many", "spawn": {"points": [[0, 0]]}, "goal": {"point": [1, 0]}}]})


def test_step_rejects_negative_counts():
    sim = circle(agents=10)
    with pytest.raises(ValueError):
        sim.step(-1)


def throng_yaml_text():
    # The circle scenario's text, from the source tree beside this file.
    import pathlib

    return (pathlib.Path(__file__).resolve().parents[2] / "examples" / "circle.yaml").read_text()


def test_agents_arriving_over_time_are_pending_then_active():
    spec = {
        "name": "inflow",
        "dt": 0.1,
        "duration": 60,
        "planning": "none",
        "groups": [
            {
                "count": 4,
                "radius": 0.25,
                "spawn": {"rect": {"min": [0, 0], "max": [20, 20]}},
                "inflow": {"times": [0, 1, 2, 30]},
                "goal": {"offset": [5, 0]},
            }
        ],
    }
    sim = throng.Simulation(spec)
    assert sim.pending_count == 4 and sim.active_count == 0
    sim.step(25)  # 2.5 s: the first three are in
    assert sim.pending_count == 1
    assert list(sim.active) == [True, True, True, False]
