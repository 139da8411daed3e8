#!/usr/bin/env python3
"""The circle of twenty round the ring, as scenario files through `throng run`.

Twenty agents on a circle of radius 8 m (r = 0.2 m, 1.3 m/s, max_speed 1.5)
each walk to their antipode, as tests/sim/encounters.h lays them out; the
whole ring is turned by `turns` angles spread evenly over its period of 18
degrees, computed in float as the tests do (40 turns give their layouts).
For each layout it reads stats.json's last arrival and prints it over the
unhindered time (16 - 0.3) / 1.3 s, then the median, the worst and how many
lie beyond 1.5x.
docs/simulation.md ("The circle round the ring") quotes its figures.

    python3 scripts/circle_of_twenty.py --model collision_free_speed --turns 200
"""
import argparse
import concurrent.futures
import ctypes
import ctypes.util
import json
import math
import os
import struct
import subprocess
import sys
import tempfile


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


# The C library's float cosine and sine, which the tests' std::cos(float)
# calls: the double ones rounded to float differ in the last bit at times,
# and the crowd's outcome hangs on such bits.
_libm = ctypes.CDLL(ctypes.util.find_library("m"))
for _name in ("cosf", "sinf"):
    getattr(_libm, _name).restype = ctypes.c_float
    getattr(_libm, _name).argtypes = [ctypes.c_float]
cosf, sinf = _libm.cosf, _libm.sinf


def scenario(model, turn_degrees):
    turn = f32(f32(turn_degrees * f32(math.pi)) / 180.0)  # degrees * kPiF / 180.0f
    lines = ["name: circle_of_twenty", "planning: none", "duration: 120",
             "model:", f"  type: {model}", "  max_speed: 1.5", "groups:"]
    for k in range(20):
        a = f32(turn + f32(f32(k * f32(6.2831853)) / 20.0))  # k * 6.2831853f / 20.0f, left to right
        x, y = 8.0 * cosf(a), 8.0 * sinf(a)
        lines.append(f"  - {{name: g{k}, count: 1, radius: 0.2, speed: 1.3, spawn: {{points: [[{x!r}, {y!r}]]}}, "
                     f"goal: {{point: [{-x!r}, {-y!r}]}}, on_arrival: despawn, arrival_radius: 0.3}}")
    return "\n".join(lines) + "\n"


def slowest(throng, model, turn_degrees):
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "circle.yaml")
        with open(path, "w") as fh:
            fh.write(scenario(model, turn_degrees))
        run = subprocess.run([throng, "run", path, "--no-animate", "--out", d, "--threads", "1"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if run.returncode != 0:
            sys.exit(f"throng run failed on the layout turned {turn_degrees} degrees:\n{run.stderr}")
        with open(os.path.join(d, "stats.json")) as fh:
            crowd = json.load(fh)["crowd"]
    if crowd.get("arrived", 20) < 20:
        return math.inf
    return crowd["arrival_time_s"]["max"] / ((16.0 - 0.3) / 1.3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="collision_free_speed")
    ap.add_argument("--turns", type=int, default=40, help="layouts over the ring's 18 degrees")
    ap.add_argument("--throng", default="build/release/throng")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    if args.turns < 1:
        sys.exit("--turns must be at least 1")
    if not os.access(args.throng, os.X_OK):
        sys.exit(f"no throng executable at {args.throng} (build it first, or pass --throng)")
    step = f32(18.0 / args.turns)
    angles = [f32(step * k) for k in range(args.turns)]  # float, as the tests
    with concurrent.futures.ThreadPoolExecutor(args.workers) as pool:
        ratios = list(pool.map(lambda a: slowest(args.throng, args.model, a), angles))
    for a, r in zip(angles, ratios):
        print(f"{a:7.3f} deg  {r:.3f}x")
    s = sorted(ratios)
    print(f"{args.model}: {args.turns} layouts, median {s[len(s) // 2]:.2f}x, worst {s[-1]:.2f}x, "
          f"{sum(r > 1.5 for r in ratios)} beyond 1.5x")


if __name__ == "__main__":
    main()
