#!/usr/bin/env python3
"""Draws docs/fundamental_diagram.png: the collision-free speed model's speed
and specific flow against density, beside Weidmann's curve.

The measurements come from the FundamentalDiagram test, which writes them
when THRONG_FD_CSV names a file:

  THRONG_FD_CSV=/tmp/fd.csv build/release/src/sim_tests --gtest_filter='FundamentalDiagram.*'
  python3 scripts/plot_fundamental_diagram.py /tmp/fd.csv docs/fundamental_diagram.png

Needs matplotlib (Debian: python3-matplotlib); only for redrawing the docs.
"""
import csv
import math
import sys


def weidmann(rho):
    return 1.34 * (1.0 - math.exp(-1.913 * (1.0 / rho - 1.0 / 5.4)))


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_fundamental_diagram.py MEASURED.csv OUT.png")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("matplotlib is missing: apt-get install python3-matplotlib")
    with open(sys.argv[1], newline="") as f:
        rows = [(float(r["density"]), float(r["speed"])) for r in csv.DictReader(f)]
    if not rows:
        sys.exit(f"{sys.argv[1]}: no measurements")
    curve = [0.3 + 0.01 * k for k in range(0, 511)]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    # Speed, then specific flow = density x speed, each against Weidmann.
    panels = [(lambda d, v: v, "speed along the corridor (m/s)"), (lambda d, v: d * v, "specific flow (1/(m s))")]
    for ax, (of, label) in zip(axes, panels):
        ax.plot(curve, [of(r, weidmann(r)) for r in curve], "k-", label="Weidmann 1993")
        ax.plot([d for d, _ in rows], [of(d, v) for d, v in rows], "o", color="tab:blue", label="throng, collision_free_speed")
        ax.set_xlabel("density (1/m²)")
        ax.set_ylabel(label)
        ax.set_xlim(0, 5.6)
        ax.set_ylim(0, 1.5)
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle("RiMEA test 4 set-up: 10 m corridor, measured 10-70 s")
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=90)


if __name__ == "__main__":
    main()
