"""How slow this machine makes a step whose work never changes: the floor under the slowest-step goal.

The goal is that a bounded step never takes more than 4 times the NREL median, measured as the slowest of
the scenario's steps (``realtime``: 6000 NREL steps, 2000 of the others). A step's time is its
work plus whatever the machine does to it meanwhile: another process on the core, an interrupt, the
shared host's caches. This times a compiled loop whose work is the same every call (square roots of
the same numbers), sized to about one NREL median of the pitch bearing FMU (``--us``), called as often
as the scenario has steps, several runs: the spread it shows is the machine's alone. Where its slowest
call passes 4 medians, the slowest-step goal cannot be told from the machine's noise here, whatever the
step does.

Run: .venv/bin/python -m benchmarks machine_noise [--us 600] [--steps 6000] [--runs 5]
"""
from __future__ import annotations

import time

import numba
import numpy as np

from .suite import print_table

RUNS = 5

#: the goal's factor: the slowest step against the NREL median
GOAL = 4.0


@numba.njit(cache=False, nogil=True)
def constant_work(values: np.ndarray, passes: int) -> float:
    """The same arithmetic every call: ``passes`` sums of the square roots of ``values`` plus the pass."""
    total = 0.0
    for k in range(passes):
        for v in values:
            total += np.sqrt(v + k)
    return total


def passes_for(values: np.ndarray, us: float) -> int:
    """The passes that take about ``us`` microseconds here (the fastest of a few calls of one pass each)."""
    constant_work(values, 1)
    one = min(_timed(values, 20) for _ in range(5)) / 20
    return max(1, round(us * 1e-6 / one))


def _timed(values: np.ndarray, passes: int) -> float:
    start = time.perf_counter()
    constant_work(values, passes)
    return time.perf_counter() - start


def add_arguments(parser) -> None:
    parser.add_argument("--us", type=float, default=600.0, help="the work of a call, microseconds (an NREL median)")
    parser.add_argument("--steps", type=int, default=6000, help="calls a run (the NREL scenario's steps)")


def main(args) -> None:
    values = np.random.default_rng(0).random(2000)
    passes = passes_for(values, args.us)
    rows = []
    for run in range(args.runs):
        times = np.array([_timed(values, passes) for _ in range(args.steps)]) * 1e3
        median = float(np.median(times))
        rows.append([str(run + 1), f"{median:.3f}", f"{np.percentile(times, 99) / median:.2f}",
                     f"{np.percentile(times, 99.9) / median:.2f}", f"{times.max() / median:.1f}",
                     str(int(np.count_nonzero(times > GOAL * median))),
                     "yes" if times.max() <= GOAL * median else "no"])
    print_table(f"the same work every call ({passes} passes, about {args.us:.0f} us), {args.steps} calls a run",
                ["run", "median [ms]", "p99 / median", "p99.9 / median", "slowest / median",
                 f"calls over {GOAL:g} medians", f"slowest within {GOAL:g} medians"], rows)

