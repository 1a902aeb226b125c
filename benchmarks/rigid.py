"""Rigid-BIME speed: our Newton solver against scipy.optimize.minimize (BFGS, numeric
gradient) on the same energy, table1.toml (100 balls), a combined load, cold start.

``--runs``: the Newton solves timed (default 15); BFGS, a third of them (at least 2).

Run: .venv/bin/python -m benchmarks rigid [--runs 15]
"""
from __future__ import annotations

import numpy as np

from .suite import ROOT, median_time, print_table, record

RUNS = 15


def main(args) -> None:
    from scipy.optimize import minimize

    from slewing_model import BimeSolver, Loads, load_bearing

    bearing = load_bearing(ROOT / "examples/bearings/table1.toml")
    loads = Loads(Fx=150e3, Fy=-50e3, Fz=800e3, Mx=400e3, My=-1.2e6)

    def newton():
        return BimeSolver(bearing).solve(loads)  # cold: includes assembling the bearing

    solver = BimeSolver(bearing)
    scale = np.array([1.0, 1.0, 1.0, solver.length, solver.length])  # rotations as arc lengths

    def energy(x_scaled):
        return solver.potential_energy(x_scaled / scale, loads)

    def bfgs():
        # gtol: 1e-6 of the largest load component (scaled), looser than our 1e-10
        f_scaled = loads.as_array() / scale
        return minimize(energy, np.zeros(5), method="BFGS", options={"gtol": 1e-6 * np.abs(f_scaled).max()})

    ours = newton()
    ref = bfgs()
    t_newton = median_time(newton, repeat=args.runs)
    t_bfgs = median_time(bfgs, repeat=max(2, args.runs // 3))
    disp_ref = ref.x / scale
    agreement = np.abs(disp_ref - ours.displacement).max() / np.abs(ours.displacement).max()
    record("seconds", {"newton": t_newton, "bfgs": t_bfgs})
    print_table(
        f"Rigid-BIME cold solve, {bearing.name} ({bearing.ball_count} balls), loads {loads}",
        ["method", "median time", "ratio to Newton", "iterations / energy evaluations", "max rel. diff. of displacement"],
        [
            ["Newton, analytic gradient + Hessian (ours)", f"{t_newton * 1e3:.2f} ms", "1.0",
             f"{ours.iterations}", "reference"],
            ["scipy BFGS, numeric gradient", f"{t_bfgs * 1e3:.1f} ms", f"{t_bfgs / t_newton:.0f}",
             f"{ref.nfev}", f"{agreement:.1e}"],
        ],
    )
