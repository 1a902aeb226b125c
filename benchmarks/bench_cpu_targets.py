"""The numba FMU's loops on another machine: the building CPU's loops against those it carries for an
x86-64-v3 CPU and for any x86-64 CPU (``slewing_model/numerics/targets.py``), on this machine.

An FMU takes the building CPU's loops only on a CPU of the same name and features; elsewhere it takes the
first portable set that CPU can run (``fmu_src/bearing_variables.kernels_of``). Each set is run here in a
worker process of its own (``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES`` as the FMU sets them; none for the
building CPU's), the processes of the three sets alternating round after round so that all see the same
machine load: the library's simulator steps the pitch bearing as the FMU runs it (flexible rings, loads in
the blade-root frame, friction and life on, complete steps) through a scenario of ``bench_realtime.py``.
The first 50 steps of each process are left out. A set not yet in numba's cache is compiled by its first
process (about 95 s), which the table reports as its first load.

Run: .venv/bin/python benchmarks/bench_cpu_targets.py [--scenario nrel] [--steps 1500] [--rounds 5]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import print_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
WARM = 50
WORKER = r'''
import json, sys, time
sys.path.insert(0, sys.argv[3])
from bench_realtime import scenario
from slewing_model import Loads, load_bearing
from slewing_model.friction.kernel import compile_all
from slewing_model.rings.superelement import build_superelement
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

start = time.perf_counter()
compile_all()
loaded = time.perf_counter() - start
case = scenario(sys.argv[1])
bearing = load_bearing(case.bearing)
sim = BearingSimulator(bearing, build_superelement(bearing, mesh="fine", progress=False), SimulatorSettings(
    ring_model="flexible", load_frame="rotating", life=True, step_work="complete", contact_kernel="auto"))
times = []
for k in range(min(int(sys.argv[2]), case.steps)):
    start = time.perf_counter()
    out = sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
    times.append(time.perf_counter() - start)
print(json.dumps({"loaded": loaded, "times": times, "torque": out.friction_torque}))
'''


def targets() -> dict:
    """Each set of loops by label, with the environment that selects it."""
    from slewing_model.numerics.targets import PORTABLE_TARGETS, target_environment

    return {"building CPU": {}, **{name: target_environment(name) for name, _ in PORTABLE_TARGETS}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="nrel", help="a scenario of bench_realtime.py")
    parser.add_argument("--steps", type=int, default=1500, help="steps of each process")
    parser.add_argument("--rounds", type=int, default=5, help="processes per set of loops")
    args = parser.parse_args()
    sets = targets()
    found = {label: {"times": [], "loaded": [], "torque": None} for label in sets}
    for _ in range(args.rounds):
        for label, environment in sets.items():
            env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU_")}
            run = subprocess.run([sys.executable, "-c", WORKER, args.scenario, str(args.steps),
                                  str(Path(__file__).resolve().parent)], env={**env, **environment}, cwd=ROOT,
                                 capture_output=True, text=True)
            if run.returncode != 0:
                raise RuntimeError(f"the worker for {label} failed:\n{run.stderr[-3000:]}")
            out = json.loads(run.stdout.strip().splitlines()[-1])
            found[label]["times"].append(1e3 * np.array(out["times"][WARM:]))
            found[label]["loaded"].append(out["loaded"])
            found[label]["torque"] = out["torque"]
    medians = {label: [float(np.median(t)) for t in f["times"]] for label, f in found.items()}
    reference = "building CPU"
    rows = []
    for label, f in found.items():
        t = np.concatenate(f["times"])
        ratios = np.array(medians[label]) / np.array(medians[reference])      # round by round
        rows.append([label, sets[label].get("NUMBA_CPU_NAME", "(this CPU's)"),
                     f"{f['loaded'][0]:.1f} s / {np.median(f['loaded'][1:] or f['loaded']):.1f} s",
                     f"{np.median(t):.3f} ms", f"{np.percentile(t, 95):.3f} ms", f"{np.percentile(t, 99):.3f} ms",
                     f"{np.median(ratios):.3f} ({ratios.min():.2f}-{ratios.max():.2f})",
                     f"{abs(f['torque'] / found[reference]['torque'] - 1.0):.1e}"])
    print_table(f"The library's step ({args.scenario}, pitch bearing, flexible rings, friction and life on), "
                f"{args.rounds} alternating processes of {args.steps} steps per set of loops, the first {WARM} left out",
                ["loops", "NUMBA_CPU_NAME", "first load / later loads", "median", "95th pct", "99th pct",
                 "median / building CPU's, round by round (range)", "last torque, relative to the building CPU's"],
                rows)


if __name__ == "__main__":
    main()
