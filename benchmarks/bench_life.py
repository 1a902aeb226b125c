"""Speed cost of the FMU's life outputs (issue 24) on the pitch case of ``bench_fmu.py``.

One FMU (the pitch bearing, the build's defaults), two instances in worker processes of their
own: the integer parameter ``life`` = 1 (the raceway map and the half-cycle detector update at
every step, outputs ``life_damage`` and ``life_travel_ratio`` read) and ``life`` = 0 (the same FMU
without them). Their timed runs alternate, so both see the same machine load. A step is
``setReal`` of the 7 inputs + ``doStep`` (10 ms) + ``getReal`` of 5 outputs (and of the 2 life
outputs with life on).

Run: .venv/bin/python benchmarks/bench_life.py [--steps 1000] [--runs 3] [--case pitch]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_fmu import OUTPUTS, Worker  # noqa: E402  (one FMU instance in a worker process of its own)
from cases import CASES, DT  # noqa: E402
from timing import print_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
LIFE_OUTPUTS = ("life_damage", "life_travel_ratio")
WARM = 20


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--case", default="pitch")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu

    case = CASES[args.case](1)
    with tempfile.TemporaryDirectory(prefix="bench_life_") as tmp:
        fmu = build_fmu(case.bearing, Path(tmp) / "bearing.fmu")
        total = WARM + args.steps * args.runs
        workers = {life: Worker(fmu, args.case, total, integers={"life": life},
                                outputs=OUTPUTS + (LIFE_OUTPUTS if life else ())) for life in (0, 1)}
        for w in workers.values():
            w.run(0, WARM)
        times, last = {0: [], 1: []}, {}
        for r in range(args.runs):
            for life, w in workers.items():
                answer = w.run(WARM + r * args.steps, args.steps, rewarm=True)   # Worker.run
                times[life] += answer["times"]
                last[life] = answer["last"]
        for w in workers.values():
            w.close()
    med = {k: float(np.median(np.array(v) * 1e3)) for k, v in times.items()}
    rows = [[args.case, "off (life = 0)", f"{med[0]:.3f} ms", f"{np.percentile(np.array(times[0]) * 1e3, 95):.3f} ms",
             ""],
            [args.case, "on (life = 1)", f"{med[1]:.3f} ms", f"{np.percentile(np.array(times[1]) * 1e3, 95):.3f} ms",
             f"{med[1] - med[0]:+.3f} ms ({(med[1] / med[0] - 1) * 100:+.1f} %)"]]
    print_table(f"Bearing FMU through fmpy, {case.description}; one step = setReal + doStep ({DT * 1e3:.0f} ms) + "
                f"getReal; {args.runs} runs of {args.steps} steps per instance, interleaved",
                ["case", "life outputs", "median", "95th pct", "cost of life (median)"], rows)
    print(f"after {total} steps with life on: life_damage = {last[1][-2]:.4g}, life_travel_ratio = {last[1][-1]:.4g}")


if __name__ == "__main__":
    main()
