"""The bearing FMU through fmpy: instantiation time, doStep time, memory over many steps.

table3 with synthetic errors, flexible rings (fine superelement, the build default), friction on; a slowly
varying load and a turning ring (Fz ramp with a moment, psi at 0.5 rad/s). The rigid
model is measured in the same run as the baseline.

Run: .venv/bin/python benchmarks/bench_fmu.py [--steps 100000]
"""
from __future__ import annotations

import argparse
import math
import shutil
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import print_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def rss_mb() -> float:
    """Resident memory of this process now, MB (Linux)."""
    with open("/proc/self/statm") as fh:
        pages = int(fh.read().split()[1])
    import resource

    return pages * resource.getpagesize() / 1e6


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--steps", type=int, default=100_000, help="steps of the memory run")
    args = parser.parse_args()
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from build_fmu import build_fmu

    fmu_path = build_fmu(ROOT / "examples/bearings/table3_errors.toml", ROOT / "build/SlewingBearing_table3_errors.fmu")
    md = read_model_description(str(fmu_path))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(fmu_path))
    inputs = [refs[n] for n in ("Fz", "Mx", "psi", "omega")]
    outputs = [refs[n] for n in ("z", "friction_torque", "max_ball_load", "ball[1].Q1")]

    def instantiate(ring_model):
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="bench")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.setInteger([refs["ring_model"]], [ring_model])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        return fmu

    def step(fmu, k, dt=0.01):
        t = k * dt
        fmu.setReal(inputs, [2e4 + 1e4 * math.sin(0.2 * t), 2e3 * math.cos(0.3 * t), 0.5 * t, 0.5])
        fmu.doStep(t, dt)
        return fmu.getReal(outputs)

    rows = []
    for ring_model, label in ((1, "rigid rings (baseline)"), (2, "flexible rings")):
        starts = []
        for _ in range(5):
            t0 = time.perf_counter()
            fmu = instantiate(ring_model)
            starts.append(time.perf_counter() - t0)
            fmu.terminate()
            fmu.freeInstance()
        fmu = instantiate(ring_model)
        times = []
        for k in range(2000):
            t0 = time.perf_counter()
            step(fmu, k)
            times.append(time.perf_counter() - t0)
        fmu.terminate()
        fmu.freeInstance()
        rows.append([label, f"{statistics.median(starts) * 1e3:.0f} ms", f"{statistics.median(times) * 1e3:.2f} ms",
                     f"{sorted(times)[int(0.95 * len(times))] * 1e3:.2f} ms"])
    base = float(rows[0][2].split()[0])
    for r in rows:
        r.append(f"{float(r[2].split()[0]) / base:.2f}")
    print_table("Bearing FMU through fmpy: table3 with errors (67 balls), friction on, slowly varying load, turning ring",
                ["model", "instantiate + initialise (median of 5)", "doStep median (2000 steps)",
                 "doStep 95th percentile", "ratio to rigid"], rows)

    fmu = instantiate(2)
    memory = []
    for k in range(args.steps):
        step(fmu, k)
        if k + 1 in (1_000, args.steps) or (k + 1) % 20_000 == 0:
            memory.append((k + 1, rss_mb()))
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)
    print_table("Resident memory of the host process (flexible rings)", ["steps", "RSS [MB]"],
                [[f"{k:,}", f"{m:.1f}"] for k, m in memory])


if __name__ == "__main__":
    main()
