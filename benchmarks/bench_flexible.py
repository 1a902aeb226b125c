"""Flexible-BIME speed: our structured Newton (reduced to the active contacts, reused
operator) against the dense Newton on all 5 + 8B unknowns, measured side by side.

Run: .venv/bin/python benchmarks/bench_flexible.py
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import median_time, print_table  # noqa: E402

from slewing_model import BimeSolver, Loads, load_bearing  # noqa: E402
from slewing_model.distribution.bime import solve_dense_newton  # noqa: E402
from slewing_model.rings.superelement import build_superelement  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
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

        t_cold = median_time(cold, repeat=7)
        t_warm = median_time(warm, repeat=15)
        t_dense = median_time(dense, repeat=3)
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


if __name__ == "__main__":
    main()
