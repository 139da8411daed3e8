#!/usr/bin/env python3
"""Run the built-in circle scenario from Python and look at the crowd.

From a build tree (see docs/python.md):

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/run_circle.py

Each block below is one step of a notebook: load, build, step, read arrays.
"""
import numpy as np

import throng

# %% Load a scenario: a built-in name, a YAML path or a dict work alike.
scenario = throng.load_scenario("circle")
print(scenario)  # <throng.Scenario circle from builtin:circle, 1000 agents>

# %% Build the simulation as `throng run circle --agents 200 --seed 42` would
# (routes planned, agents spawned). The scenario object itself is unchanged.
sim = throng.Simulation(scenario, seed=42, agents=200)
goals = sim.goals                  # (200, 2) float32: where each agent is heading
start = sim.positions              # (200, 2) float32, metres

# %% Step in chunks and watch the crowd close in on its goals. Every array is
# a copy taken when read: `start` above keeps the starting positions.
while not sim.all_arrived and sim.time < 120.0:
    sim.step(100)                  # 100 steps of dt = 0.1 s
    remaining = np.linalg.norm(goals - sim.positions, axis=1)
    speed = np.linalg.norm(sim.velocities, axis=1)
    print(f"t={sim.time:5.1f} s  arrived {sim.arrived_count:3d}/{sim.agent_count}  "
          f"mean distance to goal {remaining.mean():5.2f} m  mean speed {speed.mean():.2f} m/s")

# %% Per-agent results: arrival times (-1 for agents still walking).
times = sim.arrival_times
done = times >= 0
print(f"{done.sum()} arrived; first at {times[done].min():.1f} s, last at {times[done].max():.1f} s")
print(f"net displacement: {np.linalg.norm(sim.positions - start, axis=1).mean():.1f} m on average")
