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
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cases import CASES, DT  # noqa: E402
from timing import print_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
OUTPUTS = ("z", "rx", "ry", "friction_torque", "max_ball_load")
WARM = 20


def worker(fmu_path: str, case_name: str, steps: int, life: int) -> None:
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    case = CASES[case_name](steps)
    md = read_model_description(fmu_path)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(fmu_path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    for name, value in {**case.parameters, "life": life}.items():
        fmu.setInteger([refs[name]], [value])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    names = OUTPUTS + (("life_damage", "life_travel_ratio") if life else ())
    inputs, outputs = [refs[n] for n in INPUTS], [refs[n] for n in names]
    print(json.dumps({"ready": True}), flush=True)
    last = None
    for line in sys.stdin:
        first, count = map(int, line.split())
        times = []
        for k in range(first, first + count):
            values = [*map(float, case.loads[k]), float(case.psi[k]), float(case.omega[k])]
            t0 = time.perf_counter()
            fmu.setReal(inputs, values)
            fmu.doStep(k * DT, DT)
            last = fmu.getReal(outputs)
            times.append(time.perf_counter() - t0)
        print(json.dumps({"times": times, "last": last}), flush=True)
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


class Worker:
    def __init__(self, fmu_path, case_name, steps, life):
        self.process = subprocess.Popen([sys.executable, __file__, "--worker", str(fmu_path), case_name, str(steps),
                                         str(life)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.answer()

    def answer(self):
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"benchmark worker ended (exit {self.process.wait()})")
        return json.loads(line)

    def run(self, first, count):
        self.process.stdin.write(f"{first} {count}\n")
        self.process.stdin.flush()
        return self.answer()

    def close(self):
        self.process.stdin.close()
        self.process.wait()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--case", default="pitch")
    parser.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker[0], args.worker[1], int(args.worker[2]), int(args.worker[3]))
        return
    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu

    case = CASES[args.case](1)
    with tempfile.TemporaryDirectory(prefix="bench_life_") as tmp:
        fmu = build_fmu(case.bearing, Path(tmp) / "bearing.fmu")
        total = WARM + args.steps * args.runs
        workers = {life: Worker(fmu, args.case, total, life) for life in (0, 1)}
        for w in workers.values():
            w.run(0, WARM)
        times, last = {0: [], 1: []}, {}
        for r in range(args.runs):
            for life, w in workers.items():
                answer = w.run(WARM + r * args.steps, args.steps)
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
