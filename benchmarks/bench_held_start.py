"""The held-rings start of a warm solve after a load jump (issue 31), on and off in one run.

A warm start far from its equilibrium tries the moving ring's equilibrium under the new loads with
the rings held as they are deformed (``BimeSolver._held_rings_start``; off: ``HELD_START`` infinite).
This steps the pitch bearing's real-time scenarios (``bench_realtime.py``) through two library
simulators side by side, one with it and one without, alternating which goes first each step (the
library, not the FMU: the switch is a module constant; flexible rings, compiled kernels, friction and
life on), complete and bounded, and prints per scenario the median, 99th percentile and slowest step
of each, the steps flagged (bounded) and the Newton iterations of the slowest solve.

Run: .venv/bin/python benchmarks/bench_held_start.py [--scenarios reversal jump ...]  (about 2 minutes)
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_realtime import SCENARIOS, step_variants  # noqa: E402
from timing import print_table  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", nargs="*", default=["reversal", "jump", "nrel"], choices=SCENARIOS)
    args = parser.parse_args()
    rows = []
    for name in args.scenarios:
        for step_work in ("complete", "bounded"):
            found = dict(zip(("on", "off"), step_variants(name, step_work, [{}, {"HELD_START": math.inf}])))
            for version in ("on", "off"):
                times = np.array(found[version]["times"][1:])
                slowest = int(np.argmax(times)) + 1
                rows.append([name, step_work, version, f"{np.median(times):.2f}", f"{np.percentile(times, 99):.2f}",
                             f"{times.max():.1f}", str(found[version]["iterations"][slowest]),
                             f"{times.sum() / 1e3:.2f}", str(found[version]["flagged"]),
                             f"{times.max() / np.array(found['off']['times'][1:]).max():.2f}"])
    print_table("Held-rings start on and off (pitch bearing, library, alternating each step); times in ms",
                ["scenario", "step work", "held start", "median", "p99", "slowest", "its iterations", "total [s]",
                 "flagged steps", "slowest / off's"], rows)


if __name__ == "__main__":
    main()
