"""Friction torque speed: one evaluation for table3.toml (67 balls) from a given load distribution.

For three load distributions (all balls on one diagonal; all in four-point
contact; a mix) it times, as medians of repeated runs in this process:

* cold: ``friction_torque(bearing, distribution)`` with no previous result;
* warm: the next co-simulation step, i.e. ``initial=`` the previous result:
  for a load 0.5 % away or, last row, one degree of rotation further on a
  bearing with synthetic errors (what the FMU does every step);
* baseline 1, per-ball loop: the same computation called ball by ball (one
  ball loaded at a time), the naive way to write it;
* baseline 2, fine rule: the ball equilibrium solved and integrated on a
  48 x 8 rule (the accuracy reference of the relative difference column).

``--runs``: the cold and warm evaluations timed (default 21); the per-ball loop and the fine rule,
a seventh of them (at least 2).

Run: .venv/bin/python -m benchmarks friction [--runs 21]
"""
from __future__ import annotations

import dataclasses
import platform

import numpy as np

from .suite import ROOT, median_time, print_table

RUNS = 21


def per_ball_loop(bearing, distribution):
    """Baseline: one call per loaded ball, the other balls unloaded."""
    from slewing_model.friction import friction_torque

    total = 0.0
    for b in np.flatnonzero(distribution.contact_load.max(axis=1) > 0):
        q = np.zeros_like(distribution.contact_load)
        q[b] = distribution.contact_load[b]
        single = dataclasses.replace(distribution, contact_load=q)
        total += friction_torque(bearing, single).contact_part
    return total


def main(args) -> None:
    from slewing_model import Loads, load_bearing, solve, synthetic_errors
    from slewing_model.friction import friction_torque

    few = max(2, args.runs // 7)
    table3 = load_bearing(ROOT / "examples/bearings/table3.toml")
    with_errors = table3.with_preload(10e-6).with_errors(synthetic_errors(table3.ball_count, seed=1))
    cases = [
        ("axial 300 kN, no preload", table3, Loads(Fz=300e3), Loads(Fz=301.5e3), 0.0),
        ("idling, preload 20 um", table3.with_preload(20e-6), None, Loads(Fz=0.5e3), 0.0),
        ("Fz 100 kN + Mx 50 kNm", table3, Loads(Fz=100e3, Mx=50e3), Loads(Fz=100.5e3, Mx=50.25e3), 0.0),
        ("errors, preload 10 um, Fz 50 kN; psi + 1 deg", with_errors, Loads(Fz=50e3), Loads(Fz=50e3),
         np.radians(1.0)),
    ]
    rows = []
    for name, bearing, loads, next_loads, dpsi in cases:
        dist = solve(bearing, loads, rtol=1e-8)
        dist_next = solve(bearing, next_loads, psi=dpsi, rtol=1e-8)
        result = friction_torque(bearing, dist)
        step = friction_torque(bearing, dist_next, initial=result)
        t_cold = median_time(lambda: friction_torque(bearing, dist), repeat=args.runs)
        t_warm = median_time(lambda: friction_torque(bearing, dist_next, initial=result), repeat=args.runs)
        t_loop = median_time(lambda: per_ball_loop(bearing, dist), repeat=few)
        fine = friction_torque(bearing, dist, quadrature=(48, 8), solve_quadrature=None)
        t_fine = median_time(lambda: friction_torque(bearing, dist, quadrature=(48, 8), solve_quadrature=None),
                             repeat=few)
        loop_value = per_ball_loop(bearing, dist)
        assert abs(loop_value / result.contact_part - 1) < 1e-3, "per-ball loop must give the same torque"
        rows.append([
            name, f"{np.bincount(result.contact_count, minlength=5)[[2, 4]].tolist()}",
            f"{result.magnitude:.2f}", f"{t_cold * 1e3:.2f} ms ({result.iterations} it)",
            f"{t_warm * 1e3:.2f} ms ({step.iterations} it)",
            f"{t_loop * 1e3:.0f} ms (x{t_loop / t_cold:.0f})", f"{t_fine * 1e3:.1f} ms (x{t_fine / t_cold:.1f})",
            f"{result.magnitude / fine.magnitude - 1:+.1e}",
        ])
    print_table(
        f"Friction torque of {table3.name} ({table3.ball_count} balls), rigid-BIME distributions, mu = 0.1; "
        f"median of runs (Python {platform.python_version()}, numpy {np.__version__}, {platform.machine()})",
        ["load case", "balls [2, 4 contacts]", "torque N m", "cold", "warm (next step)",
         "per-ball loop (ratio to cold)", "fine 48x8 rule (ratio)", "rel. diff. to fine"],
        rows,
    )

