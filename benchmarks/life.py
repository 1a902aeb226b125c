"""Speed cost of the FMU's life outputs on the pitch case of the ``fmu`` benchmark.

One FMU (the pitch bearing, the build's defaults), two instances in worker processes of their
own: the integer parameter ``life`` = 1 (the raceway map and the half-cycle detector update at
every step, outputs ``life_damage`` and ``life_travel_ratio`` read) and ``life`` = 0 (the same FMU
without them). Their timed runs alternate, so both see the same machine load. A step is
``setReal`` of the 7 inputs + ``doStep`` (10 ms) + ``getReal`` of 5 outputs (and of the 2 life
outputs with life on).

Run: .venv/bin/python -m benchmarks life [--steps 1000] [--runs 3] [--case pitch]
"""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from .cases import CASES, DT
from .fmu import OUTPUTS, Worker     # one FMU instance in a worker process of its own
from .suite import build_fmu_module, note, print_table, spread

RUNS = 3
LIFE_OUTPUTS = ("life_damage", "life_travel_ratio")
WARM = 20


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--case", default="pitch", choices=list(CASES))


def main(args) -> None:
    build_fmu = build_fmu_module().build_fmu

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
    s = {k: spread(np.array(v) * 1e3) for k, v in times.items()}
    med = {k: s[k]["median"] for k in s}
    rows = [[args.case, "off (life = 0)", f"{med[0]:.3f} ms", f"{s[0]['p95']:.3f} ms", f"{s[0]['p99']:.3f} ms", ""],
            [args.case, "on (life = 1)", f"{med[1]:.3f} ms", f"{s[1]['p95']:.3f} ms", f"{s[1]['p99']:.3f} ms",
             f"{med[1] - med[0]:+.3f} ms ({(med[1] / med[0] - 1) * 100:+.1f} %)"]]
    print_table(f"Bearing FMU through fmpy, {case.description}; one step = setReal + doStep ({DT * 1e3:.0f} ms) + "
                f"getReal; {args.runs} runs of {args.steps} steps per instance, interleaved",
                ["case", "life outputs", "median", "95th pct", "99th pct", "cost of life (median)"], rows)
    note(f"after {total} steps with life on: life_damage = {last[1][-2]:.4g}, life_travel_ratio = {last[1][-1]:.4g}")

