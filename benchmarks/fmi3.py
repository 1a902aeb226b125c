"""The FMI 3.0 bearing FMU (per-ball arrays) against the FMI 2.0 one: time per doStep, and per step with
the per-ball results read, in the same run.

Case: the 150-ball pitch bearing (fine superelement, flexible rings by default) under the shipped
blade-root series, pitching +-5 deg at 0.5 rad/s, friction on. Both FMUs are instantiated in one
process and stepped alternately with the same inputs, so that both see the same machine load. A
step is: set the 7 inputs, ``doStep`` (10 ms). "doStep" times the call alone; "step + per-ball"
adds reading every per-ball result (FMI 2.0: 8 B = 1200 scalars by value reference; FMI 3.0: the
three arrays). The ratio column is FMI 3.0 / FMI 2.0; the goal is a doStep ratio of at most 1.10.

Run: .venv/bin/python -m benchmarks fmi3 [--steps 1000] [--rigid] [--bearing pitch_bearing] [--mesh fine]
"""
from __future__ import annotations

import math
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .suite import ROOT, build_fmu_module, note, print_table, record, spread

INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
DT = 0.01


def _instances(fmu2: Path, fmu3: Path, ring_model: int):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    md2, md3 = read_model_description(str(fmu2)), read_model_description(str(fmu3))
    dirs = [extract(str(fmu2)), extract(str(fmu3))]
    f2 = FMU2Slave(guid=md2.guid, unzipDirectory=dirs[0], modelIdentifier=md2.coSimulation.modelIdentifier,
                   instanceName="fmi2")
    f3 = FMU3Slave(guid=md3.guid, unzipDirectory=dirs[1], modelIdentifier=md3.coSimulation.modelIdentifier,
                   instanceName="fmi3")
    refs2 = {v.name: v.valueReference for v in md2.modelVariables}
    refs3 = {v.name: v.valueReference for v in md3.modelVariables}
    f2.instantiate()
    f2.setupExperiment(startTime=0.0)
    f2.setInteger([refs2["ring_model"], refs2["load_frame"]], [ring_model, 2])
    f2.enterInitializationMode()
    f2.exitInitializationMode()
    f3.instantiate()
    f3.setInt32([refs3["ring_model"], refs3["load_frame"]], [ring_model, 2])
    f3.enterInitializationMode(startTime=0.0)
    f3.exitInitializationMode()
    return f2, f3, refs2, refs3, dirs


def step_both(fmu2: Path, fmu3: Path, steps: int, ring_model: int) -> dict:
    """Times (s) of doStep and of a step with the per-ball results read, per FMU; and the largest
    relative difference of the friction torque between them (a check that both did the same work)."""
    if str(ROOT / "fmu_src") not in sys.path:
        sys.path.insert(0, str(ROOT / "fmu_src"))
    from bearing_variables import BALL_ARRAYS
    from slewing_drives import LoadSeries

    loads = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    f2, f3, refs2, refs3, dirs = _instances(fmu2, fmu3, ring_model)
    balls = sum(name.endswith(".Q1") for name in refs2)
    in2, in3 = [refs2[n] for n in INPUTS], [refs3[n] for n in INPUTS]
    per_ball2 = [refs2[f"ball[{i}].{c}"] for i in range(1, balls + 1) for _, _, cols, _, _ in BALL_ARRAYS for c in cols]
    arrays3 = [(refs3[name], balls * len(cols)) for name, _, cols, _, _ in BALL_ARRAYS]
    friction2, friction3 = refs2["friction_torque"], refs3["friction_torque"]
    times = {key: np.empty(steps) for key in ("do2", "do3", "all2", "all3")}
    worst = 0.0
    try:
        for k in range(steps):
            t = k * DT
            amplitude, speed = math.radians(5.0), 0.5
            psi = amplitude * math.sin(speed * t / amplitude)
            omega = speed * math.cos(speed * t / amplitude)
            values = [*map(float, loads.at(t)[:5]), psi, omega]
            for f, refs_in, key, read in ((f2, in2, "2", lambda: f2.getReal(per_ball2)),
                                          (f3, in3, "3", lambda: [f3.getFloat64([r], nValues=n) for r, n in arrays3])):
                start = time.perf_counter()
                (f.setReal if key == "2" else f.setFloat64)(refs_in, values)
                begin = time.perf_counter()
                f.doStep(t, DT)
                done = time.perf_counter()
                read()
                end = time.perf_counter()
                times[f"do{key}"][k] = done - begin
                times[f"all{key}"][k] = end - start
            a, b = f2.getReal([friction2])[0], f3.getFloat64([friction3])[0]
            worst = max(worst, abs(a - b) / max(abs(a), 1e-300))
    finally:
        for f in (f2, f3):
            f.terminate()
            f.freeInstance()
        for d in dirs:
            shutil.rmtree(d, ignore_errors=True)
    times["friction_difference"] = worst
    return times


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--rigid", action="store_true", help="rigid rings instead of flexible rings")
    parser.add_argument("--bearing", default="pitch_bearing", help="a definition of examples/bearings")
    parser.add_argument("--mesh", choices=("coarse", "fine"), default="fine")


def main(args) -> None:
    build_fmu = build_fmu_module().build_fmu

    with tempfile.TemporaryDirectory(prefix="bench_fmi3_") as tmp:
        tmp = Path(tmp)
        definition = ROOT / "examples" / "bearings" / f"{args.bearing}.toml"
        fmu2 = build_fmu(definition, tmp / "fmi2.fmu", mesh=args.mesh)
        fmu3 = build_fmu(definition, tmp / "fmi3.fmu", mesh=args.mesh, fmi_version=3)
        times = step_both(fmu2, fmu3, args.steps, ring_model=1 if args.rigid else 2)
    rows = []
    for label, key in (("doStep", "do"), ("step + per-ball results", "all")):
        a, b = times[f"{key}2"] * 1e3, times[f"{key}3"] * 1e3
        for name, stat in (("median", np.median), ("95th", lambda x: np.percentile(x, 95)),
                           ("99th", lambda x: np.percentile(x, 99))):
            rows.append([label, name, f"{stat(a):.3f}", f"{stat(b):.3f}", f"{stat(b) / stat(a):.3f}"])
    rings = "rigid" if args.rigid else "flexible"
    print_table(f"{args.bearing}, {rings} rings, {args.mesh} superelement, {args.steps} steps of 10 ms, "
                f"FMI 2.0 and FMI 3.0 alternating (ms)",
                ["what", "statistic", "FMI 2.0", "FMI 3.0", "ratio 3.0/2.0"], rows)
    for key in ("do2", "do3", "all2", "all3"):
        record(f"{key} [ms]", spread(times[key] * 1e3))
    note(f"\nlargest relative difference of friction_torque between the two: {times['friction_difference']:.1e}")
    ratio = np.median(times["do3"]) / np.median(times["do2"])
    note(f"goal: median doStep ratio <= 1.10: {'met' if ratio <= 1.10 else 'NOT met'} ({ratio:.3f})")

