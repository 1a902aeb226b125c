"""A bounded step's work cap (``BOUNDED_WORK``, issue 31): the slowest steps against the steps flagged,
for several values of the cap in one run.

A bounded solve (``step_work="bounded"``) spends at most ``BOUNDED_WORK`` of work, the ring operator's
(and always one piece of it: forming ``W``, a stage of its inverse or a bordering) and its Newton
iterations', and flags what it carries over. A smaller cap makes the slowest steps faster and flags
more steps. This steps the pitch
bearing's real-time scenarios (``bench_realtime.py``) through one library simulator per value of the
cap, alternating which goes first each step (the library, not the FMU: the cap is a module constant;
flexible rings, compiled kernels, friction and life on), each started at zero loads as an FMU leaving
initialization with its start values, and prints per scenario and cap the first step, the median, 99th
percentile and slowest of the others, how many of them were slower than 4 NREL medians (the issue's
goal; the NREL median of the first cap, measured in the same run) and the steps flagged.

Run: .venv/bin/python benchmarks/bench_bound.py [--work 1e8 1.1e8 1.2e8] [--scenarios nrel reversal ...]
     (about 3 minutes for three caps)
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_realtime import SCENARIOS, step_variants  # noqa: E402
from timing import print_table  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--work", nargs="*", type=float, default=[1e8, 1.1e8, 1.2e8])
    parser.add_argument("--scenarios", nargs="*", default=list(SCENARIOS), choices=SCENARIOS)
    args = parser.parse_args()
    scenarios = ["nrel"] + [s for s in args.scenarios if s != "nrel"]     # NREL first: its median is the unit
    results = {name: step_variants(name, "bounded", [{"BOUNDED_WORK": cap} for cap in args.work], start_values=True)
               for name in scenarios}
    nrel_median = float(np.median(results["nrel"][0]["times"][1:]))
    rows = []
    for name in scenarios:
        if name not in args.scenarios:
            continue
        for cap, found in zip(args.work, results[name]):
            times = np.array(found["times"])
            rest = times[1:]
            rows.append([name, f"{cap:.3g}", f"{times[0]:.1f}", f"{np.median(rest):.2f}",
                         f"{np.percentile(rest, 99):.2f}", f"{rest.max():.1f}", f"{rest.max() / nrel_median:.1f}",
                         str(int(np.sum(rest > 4 * nrel_median))), f"{times[0] / np.median(rest):.0f}",
                         str(found["flagged"])])
    print_table(f"Bounded steps by BOUNDED_WORK (pitch bearing, library, alternating each step; NREL median of "
                f"the first cap {nrel_median:.2f} ms); times in ms",
                ["scenario", "BOUNDED_WORK", "first step", "median", "p99", "slowest", "slowest / NREL median",
                 "steps over 4 NREL medians", "first / median", "flagged steps"], rows)


if __name__ == "__main__":
    main()
