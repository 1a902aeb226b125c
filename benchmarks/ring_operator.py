"""The flexible solver's fresh reduced operator: its inverse by halves against LAPACK's.

A fresh operator ``W^-1 = (A^-1 + M)_aa^-1`` is what sets the tail of a co-simulation step
(docs/theory/flexible-bime.md). This takes the operators ``W`` the simulator forms while stepping the
benchmark cases (``benchmarks/cases.py``: the pitch and yaw bearings, fine superelement) and
inverts each by :func:`slewing_model.rings.reduced_operator.spd_inverse` (Schur complements,
matrix products) and by ``np.linalg.inv`` (LU, then triangular solves), alternately, on one
BLAS thread as in a step; it prints the median and tail of each, their ratio, and the
residual ``|X W - I|`` of both.

With ``--border``: bordering a kept inverse of 368 rows (the pitch bearing's) by ``r`` new rows,
the compiled loop (:func:`slewing_model.distribution.kernel._bordered_inverse`) against numpy's
products (:func:`slewing_model.rings.reduced_operator.bordered_inverse`), alternately, beside an
inversion of the whole: where the kernel hands bordering to numpy
(:data:`slewing_model.distribution.kernel.BORDER_BLAS_ROWS`) and what a bounded step counts it as.

With ``--stages``: the time of each stage a bounded step counts in floating-point operations
(:data:`slewing_model.distribution.bime.BOUNDED_WORK`): forming ``W`` from the pitch bearing's
operators of 160-600 rows (the loads of the ``realtime`` benchmark's reversal scenario) and each stage of its
inverse (:data:`slewing_model.rings.reduced_operator.STAGES`), against the work counted for it
(:func:`~slewing_model.rings.reduced_operator.forming_work`,
:func:`~slewing_model.rings.reduced_operator.stage_work`): what ``BOUNDED_WORK`` is in time here.

Run: .venv/bin/python -m benchmarks operator [--runs 30] [--border | --stages [--method 0|1|2]]
"""
from __future__ import annotations

import time

import numpy as np

import slewing_model.rings.reduced_operator as reduced_operator
from slewing_model import Loads, load_bearing
from slewing_model.numerics.blas import blas_threads
from slewing_model.rings.superelement import build_superelement
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

from .cases import CASES
from .suite import print_table

RUNS = 30


def formed_operators(case_name: str, steps: int) -> list[np.ndarray]:
    """The matrices ``W`` the simulator inverted while stepping a case, after its first
    (cold) step."""
    case = CASES[case_name](steps)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="fine", bc="free")
    simulator = BearingSimulator(bearing, superelement, SimulatorSettings(
        load_frame="rotating" if case.parameters["load_frame"] == 2 else "fixed"))
    formed, depth, step = [], [0], [0]
    inverse = reduced_operator.spd_inverse

    def keep(w):                                 # the operators, not the halves it recurses on
        if depth[0] == 0 and step[0] > 0:
            formed.append(w.copy())
        depth[0] += 1
        try:
            return inverse(w)
        finally:
            depth[0] -= 1

    reduced_operator.spd_inverse = keep
    try:
        for k in range(steps):
            step[0] = k
            simulator.step(Loads.from_array(case.loads[k]), case.psi[k], case.omega[k])
    finally:
        reduced_operator.spd_inverse = inverse
    return formed


def bordering(runs: int, n: int = 368) -> None:
    """Bordering ``r`` rows onto an inverse of ``n`` rows: compiled loop against numpy's products."""
    from slewing_model.rings.reduced_operator import bordering_work, inverse_work
    from slewing_model.distribution.kernel import compiled_bordered_inverse

    rng = np.random.default_rng(0)
    rows = []
    with blas_threads(1):
        for r in (2, 4, 8, 12, 16, 32, 64, 92):
            a = rng.standard_normal((n + r, n + r))
            w = a @ a.T + (n + r) * np.eye(n + r)
            inverse = np.linalg.inv(w[:n, :n])
            inverse = 0.5 * (inverse + inverse.T)
            jacobian, new_jacobian = rng.standard_normal((n, 5)), rng.standard_normal((r, 5))
            args = (inverse, np.ascontiguousarray(w[:n, n:]), np.ascontiguousarray(w[n:, n:]), jacobian,
                    inverse @ jacobian, new_jacobian, 1e-9)
            methods = {"compiled": compiled_bordered_inverse(), "numpy": reduced_operator.bordered_inverse,
                       "inversion": lambda *_: reduced_operator.spd_inverse(w[:n, :n])}
            times = {m: [] for m in methods}
            for _ in range(runs):
                for m, f in methods.items():
                    start = time.perf_counter()
                    f(*args)
                    times[m].append(time.perf_counter() - start)
            med = {m: float(np.median(t)) * 1e3 for m, t in times.items()}
            rows.append([str(r), f"{med['compiled']:.2f}", f"{med['numpy']:.2f}", f"{med['inversion']:.2f}",
                         f"{med['compiled'] / med['numpy']:.2f}", f"{med['numpy'] / med['inversion']:.2f}",
                         f"{bordering_work(r, n) / inverse_work(n):.2f}"])
    print_table(f"Bordering r rows onto an inverse of {n} rows, one BLAS thread, medians of {runs} runs, "
                "methods alternating [ms]",
                ["r", "compiled", "numpy", f"inversion of {n}", "compiled / numpy", "numpy / inversion",
                 "counted (work / inversion's)"], rows)


def stages(runs: int, method: int = 0) -> None:
    """Forming ``W`` and each stage of its inverse (``method`` 1 and 2: through the Cholesky factor,
    ``FACTOR_STAGES``, in single and in double precision): time against the work a bounded step counts."""
    from dataclasses import replace

    from slewing_model.distribution import bime

    case = CASES["pitch"](2)
    bearing = load_bearing(case.bearing)
    simulator = BearingSimulator(bearing, build_superelement(bearing, mesh="fine", bc="free"),
                                 SimulatorSettings(load_frame="rotating"))
    formed = {}                                  # rows -> (point, active) of a W the solver formed
    original = bime.start_operator

    def keep(point, compliance, stiffness, active, arithmetic=None, until=None):
        formed.setdefault(2 * int(np.count_nonzero(active)), (point, active))
        return original(point, compliance, stiffness, active, arithmetic, until)

    bime.start_operator = keep
    try:
        loads = case.loads[0]
        for k in range(60):                      # the moment reversed every 10 steps, scaled up and down
            factor = (0.6 + 0.1 * (k % 7)) * (-1.0 if (k // 10) % 2 else 1.0)
            simulator.step(Loads(loads[0], loads[1], loads[2], factor * loads[3], factor * loads[4]), 0.0, 0.0)
    finally:
        bime.start_operator = original
    solver = simulator.solver
    arithmetic = solver._arithmetic
    rows = []
    with blas_threads(1):
        for n in sorted(formed)[:: max(1, len(formed) // 5)]:
            point, active = formed[n]
            stages = reduced_operator.FACTOR_STAGES if method else reduced_operator.STAGES
            times = {k: [] for k in ["form", *range(len(stages))]}
            for _ in range(runs):
                start = time.perf_counter()
                pending = reduced_operator.start_operator(point, solver.compliance, solver.assembly.stiffness, active,
                                                          arithmetic, until=0)
                pending = replace(pending, method=method)
                times["form"].append(time.perf_counter() - start)
                for k in range(len(stages)):
                    start = time.perf_counter()
                    pending = reduced_operator.advance_operator(pending, None, None, until=k + 1)
                    times[k].append(time.perf_counter() - start)
            counted = [reduced_operator.forming_work(n)] + [reduced_operator.stage_work(n, k, method)
                                                 for k in range(len(stages))]
            for (label, t), flops in zip(times.items(), counted):
                ms = float(np.median(t)) * 1e3
                rows.append([str(n), "form W" if label == "form" else stages[label].__name__,
                             f"{ms:.3f}", f"{flops / 1e6:.1f}", f"{flops / 1e6 / ms:.1f}" if ms else "–"])
    print_table(f"A new operator's work on one BLAS thread, medians of {runs} runs [ms], against the work a bounded "
                f"step counts (BOUNDED_WORK = {bime.BOUNDED_WORK / 1e6:.0f} M)",
                ["rows", "stage", "time [ms]", "counted work [M]", "counted per ms [M]"], rows)


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=200, help="steps of each case that form the operators")
    parser.add_argument("--border", action="store_true", help="time bordering instead (compiled against numpy)")
    parser.add_argument("--stages", action="store_true", help="time forming W and each stage of its inverse instead")
    parser.add_argument("--method", type=int, default=0, choices=(0, 1, 2),
                        help="with --stages: the stages of a PendingOperator of this method (1 and 2: through the "
                             "Cholesky factor, FACTOR_STAGES, in single and in double precision)")


def main(args) -> None:
    if args.border:
        return bordering(args.runs)
    if args.stages:
        return stages(args.runs, args.method)
    rows = []
    for name in ("pitch", "yaw"):
        operators = formed_operators(name, args.steps)
        warm = operators
        times = {"halves": [], "lapack": []}
        residual = {"halves": 0.0, "lapack": 0.0}
        methods = {"halves": reduced_operator.spd_inverse, "lapack": np.linalg.inv}
        with blas_threads(1):
            for _ in range(args.runs):
                for w in warm:
                    for method, invert in methods.items():
                        start = time.perf_counter()
                        x = invert(w)
                        times[method].append(time.perf_counter() - start)
            for w in warm:
                eye = np.eye(w.shape[0])
                for method, invert in methods.items():
                    residual[method] = max(residual[method], float(np.abs(invert(w) @ w - eye).max()))
        sizes = sorted({w.shape[0] for w in warm})
        for method in methods:
            t = np.array(times[method]) * 1e3
            ratio = np.median(times[method]) / np.median(times["lapack"])
            rows.append([name, f"{len(warm)} ({sizes[0]}-{sizes[-1]} rows)", method, f"{np.median(t):.2f} ms",
                         f"{np.percentile(t, 95):.2f} ms", f"{np.percentile(t, 99):.2f} ms", f"{ratio:.2f}",
                         f"{residual[method]:.1e}"])
    print_table(f"Fresh reduced operator, one BLAS thread, {args.runs} runs of each operator, methods alternating: "
                "spd_inverse (halves) against np.linalg.inv (lapack)",
                ["case", "operators", "method", "median", "95th pct", "99th pct", "ratio to lapack",
                 "max |X W - I|"], rows)

