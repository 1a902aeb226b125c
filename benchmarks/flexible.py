"""Flexible-BIME speed: our structured Newton (reduced to the active contacts, reused
operator) against the dense Newton on all 5 + 8B unknowns, measured side by side.

``--runs``: the warm solves timed (default 15); the cold ones, half of them, the dense ones a fifth
(at least 2).

Run: .venv/bin/python -m benchmarks flexible [--runs 15]
"""
from __future__ import annotations

import os

import numpy as np

from .suite import ROOT, median_time, print_table

RUNS = 15


def main(args) -> None:
    from slewing_model import BimeSolver, Loads, load_bearing
    from slewing_model.distribution.bime import solve_dense_newton
    from slewing_model.rings.superelement import build_superelement

    rows = []
    cases = [("table3_errors.toml", Loads(Fx=1e4, Fz=5e4, Mx=3e3, My=-2e3)),
             ("table1.toml", Loads(Fx=8e4, Fz=8e5, Mx=3e5, My=6e5))]
    for name, loads in cases:
        bearing = load_bearing(ROOT / "examples" / "bearings" / name).with_preload(10e-6)
        se = build_superelement(bearing, mesh="coarse", bc="free")
        n = bearing.ball_count

        def cold():
            return BimeSolver(bearing, se).solve(loads)

        solver = BimeSolver(bearing, se)
        base = solver.solve(loads)
        changed = Loads(*(1.01 * loads.as_array()))

        def warm():
            return solver.solve(changed, initial=base)

        def dense():
            return solve_dense_newton(BimeSolver(bearing, se), loads)

        t_cold = median_time(cold, repeat=max(2, args.runs // 2))
        t_warm = median_time(warm, repeat=args.runs)
        t_dense = median_time(dense, repeat=max(2, args.runs // 5))
        x, dense_iterations = dense()
        diff = np.abs(x[:5] - base.displacement).max() / np.abs(base.displacement).max()
        rows += [
            [bearing.name, f"{5 + 8 * n}", "structured Newton, cold", f"{t_cold * 1e3:.1f} ms", "1.0",
             f"{cold().iterations}"],
            [bearing.name, f"{5 + 8 * n}", "structured Newton, warm (+1 % load)", f"{t_warm * 1e3:.2f} ms",
             f"{t_warm / t_cold:.3f}", f"{warm().iterations}"],
            [bearing.name, f"{5 + 8 * n}", f"dense Newton (baseline), cold; max rel. diff. {diff:.0e}",
             f"{t_dense * 1e3:.0f} ms", f"{t_dense / t_cold:.0f}", f"{dense_iterations}"],
        ]
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "default")
    print_table(f"Flexible-BIME solve, free rings, coarse superelement (OPENBLAS_NUM_THREADS={threads})",
                ["bearing", "unknowns", "method", "median time", "ratio to cold", "iterations"], rows)

