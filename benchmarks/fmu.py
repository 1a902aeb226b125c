"""The bearing FMU through fmpy, on the cases users run: time per step, its tail, instantiation, memory.

Cases (`benchmarks/cases.py`): the 150-ball pitch bearing under the shipped blade-root series,
pitching +-5 deg at 0.5 rad/s (flexible and rigid rings); the 180-ball yaw bearing under the
shipped tower-top series, yawing 0.5 deg/s in bursts; table3 with errors under a heavy combined
load, turning; and the earlier light table3 case. Friction on, fine superelement, free rings
(the build's defaults).

A step is what a host does each communication step: set the 7 inputs, ``doStep`` (10 ms),
get 5 outputs. The FMU of a released version (``--baseline VERSION``, default
:data:`benchmarks.suite.DEFAULT_BASELINE`; ``none``: no baseline) is built from a temporary git
worktree by that version's own ``build_fmu.py`` and stepped in the same run, its runs alternating
with the current one's, so that both see the same machine load; the ratio column is current /
baseline.

Each FMU runs in a worker process of its own: an FMU's Python code runs in its host's
interpreter, and two FMUs in one process would share the first ``slewing_model`` imported.

The current FMU runs its friction loops compiled where numba is installed in the
host's Python (as in this venv); ``--without-numba`` makes numba unimportable in the
workers, so that the FMU runs its numpy fallback, as on a host without numba.

Run: .venv/bin/python -m benchmarks fmu [--steps 1000] [--runs 3] [--baseline VERSION|none]
     [--memory-steps 100000] [--without-numba] [--cases pitch yaw ...]
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

from .cases import CASES, DT, load_case
from .suite import DEFAULT_BASELINE, ROOT, build_baseline, build_fmu_module, print_table, record, spread, \
    worker_command

RUNS = 3
BASELINE = DEFAULT_BASELINE
INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
OUTPUTS = ("z", "rx", "ry", "friction_torque", "max_ball_load")
BEARINGS = ("pitch_bearing", "yaw_bearing", "table3_errors")
WARM = 20  # the first steps (cold start of the solvers) are timed apart: "first step"


# ---- worker: one FMU instance in a process of its own -----------------------------------------

class _NoNumba:
    """An import hook that refuses numba, as on a host where it is not installed."""

    def find_spec(self, name, path=None, target=None):
        if name == "numba" or name.startswith("numba."):
            raise ImportError("numba made unimportable by --without-numba")


def rss_mb() -> float:
    """Resident memory of this process now, MB (Linux)."""
    import resource

    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * resource.getpagesize() / 1e6


def worker(fmu_path: str, case_name: str, steps: int, integers: dict | None = None, outputs=OUTPUTS,
           trace: str | None = None, start_inputs: bool = False) -> None:
    """Instantiate the FMU (the case's integer parameters, then ``integers``), then answer lines
    ``first count`` on stdin with the step times and the last ``outputs`` (JSON); with ``trace``, the
    value of that output after every step too. ``start_inputs``: the case's first inputs are set in
    initialization mode, as fmpy's ``simulate_fmu`` sets a master's inputs at the start time (the FMU
    then solves them when it leaves initialization); else the FMU starts from its start values."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    case = load_case(case_name, steps)
    md = read_model_description(fmu_path)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(fmu_path)
    start = time.perf_counter()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    for name, value in {**case.parameters, **(integers or {})}.items():
        fmu.setInteger([refs[name]], [value])
    inputs, outputs = [refs[n] for n in INPUTS], [refs[n] for n in outputs]
    fmu.enterInitializationMode()
    if start_inputs:
        fmu.setReal(inputs, [*map(float, case.loads[0]), float(case.psi[0]), float(case.omega[0])])
    fmu.exitInitializationMode()
    instantiate = time.perf_counter() - start
    compiled = "numba" in sys.modules
    print(json.dumps({"instantiate": instantiate, "compiled": compiled}), flush=True)
    traced = refs[trace] if trace else None

    def values_at(k):
        return [*map(float, case.loads[k]), float(case.psi[k]), float(case.omega[k])]

    for line in sys.stdin:
        first, count, rewarm = (*map(int, line.split()), 0)[:3]
        if rewarm:
            # on a shared machine a step whose memory was not touched for a second or more can take 8-40 ms
            # of CPU time instead of 1 (no page fault: out of the shared host's caches; docs/performance.md): the
            # block's first step, made once and rolled back, warms it first
            state = fmu.getFMUstate()
            fmu.setReal(inputs, values_at(first))
            fmu.doStep(first * DT, DT)
            fmu.setFMUstate(state)
            fmu.freeFMUstate(state)
        times, values_traced = [], []
        for k in range(first, first + count):
            values = values_at(k)
            t0 = time.perf_counter()
            fmu.setReal(inputs, values)
            fmu.doStep(k * DT, DT)                      # fmpy raises on a status other than OK
            last = fmu.getReal(outputs)
            times.append(time.perf_counter() - t0)
            if traced is not None:
                values_traced.append(fmu.getReal([traced])[0])
        print(json.dumps({"times": times, "rss_mb": rss_mb(), "last": last, "trace": values_traced}), flush=True)
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


class Worker:
    """The parent's handle on a worker process."""

    def __init__(self, fmu_path: Path, case_name: str, steps: int, without_numba: bool = False,
                 integers: dict | None = None, outputs=OUTPUTS, trace: str | None = None, start_inputs: bool = False):
        command = worker_command("fmu", str(fmu_path), case_name, str(steps),
                                 "--worker-options", json.dumps({"integers": integers or {}, "outputs": list(outputs),
                                                                 "trace": trace, "start_inputs": start_inputs}))
        if without_numba:
            command.append("--without-numba")
        self.process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.started = self._answer()

    def _answer(self) -> dict:
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"benchmark worker ended (exit {self.process.wait()})")
        return json.loads(line)

    def run(self, first: int, count: int, rewarm: bool = False) -> dict:
        """Steps ``first .. first + count - 1``, timed; ``rewarm``: the first of them made once and rolled
        back before (:func:`worker`), for a worker that waited while others ran."""
        self.process.stdin.write(f"{first} {count} {int(rewarm)}\n")
        self.process.stdin.flush()
        return self._answer()

    def close(self):
        self.process.stdin.close()
        self.process.wait()


# ---- the parent: builds, alternates, tabulates -------------------------------------------------

def worker_main(argv: list[str]) -> None:
    """A worker process (:class:`Worker`): ``FMU CASE STEPS [--worker-options JSON] [--without-numba]``."""
    parser = argparse.ArgumentParser()
    parser.add_argument("worker", nargs=3, metavar=("FMU", "CASE", "STEPS"))
    parser.add_argument("--worker-options", default="{}")
    parser.add_argument("--without-numba", action="store_true")
    args = parser.parse_args(argv)
    if args.without_numba:
        sys.meta_path.insert(0, _NoNumba())
    worker(args.worker[0], args.worker[1], int(args.worker[2]), **json.loads(args.worker_options))


def build_current(out: Path, bearings=BEARINGS) -> dict[str, Path]:
    build_fmu = build_fmu_module().build_fmu
    return {name: Path(build_fmu(ROOT / f"examples/bearings/{name}.toml", out / f"current_{name}.fmu"))
            for name in bearings}


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=1000, help="steps of each timed run")
    parser.add_argument("--memory-steps", type=int, default=100_000, help="steps of the memory run (0: none)")
    parser.add_argument("--cases", nargs="*", default=list(CASES), choices=list(CASES))
    parser.add_argument("--without-numba", action="store_true",
                        help="make numba unimportable in the workers: the current FMU runs its numpy fallback")


def main(args) -> None:
    with tempfile.TemporaryDirectory(prefix="bench_fmu_") as tmp:
        tmp = Path(tmp)
        bearings = {Path(CASES[name](1).bearing).stem for name in args.cases}      # the FMUs the cases step
        if args.memory_steps:
            bearings.add("table3_errors")
        bearings = [b for b in BEARINGS if b in bearings]
        fmus = {"current": build_current(tmp, bearings)}
        if args.baseline_commit:
            fmus["baseline"] = build_baseline(args.baseline_commit, tmp, bearings)
        versions = list(fmus)
        rows, medians, means, kernel = [], {}, {}, ""
        total = WARM + args.steps * args.runs
        for name in args.cases:
            case = CASES[name](1)
            bearing = Path(case.bearing).stem
            workers, first = {}, {}
            for v in versions:     # the first step straight after instantiation, as a host makes it
                workers[v] = Worker(fmus[v][bearing], name, total, args.without_numba)
                first[v] = workers[v].run(0, WARM)["times"][0]
            times = {v: [] for v in versions}
            for r in range(args.runs):
                for v in versions:  # rewarm: a worker that waited for the others (Worker.run)
                    times[v] += workers[v].run(WARM + r * args.steps, args.steps, rewarm=True)["times"]
            for v in versions:
                workers[v].close()
                t = times[v] = np.array(times[v]) * 1e3
                medians[name, v], means[name, v] = float(np.median(t)), float(np.mean(t))
                record(f"{name} {v} [ms]", {**spread(t), "mean": means[name, v], "first": first[v] * 1e3,
                                            "instantiate": workers[v].started["instantiate"] * 1e3})
            kernel = "compiled friction loop (numba)" if workers["current"].started["compiled"] else \
                "numpy friction (no numba)"
            for v in versions:
                s = spread(times[v])
                ratio = "" if v == "baseline" or "baseline" not in versions else \
                    f"{medians[name, v] / medians[name, 'baseline']:.2f}"
                rows.append([name, v, f"{workers[v].started['instantiate'] * 1e3:.0f} ms", f"{first[v] * 1e3:.1f} ms",
                             f"{s['median']:.2f} ms", f"{s['p95']:.2f} ms", f"{s['p99']:.2f} ms", f"{s['max']:.1f} ms",
                             ratio])
            print(f"  {name}: {case.description}", flush=True)
        print_table(f"Bearing FMU through fmpy, one step = setReal + doStep ({DT * 1e3:.0f} ms) + getReal; "
                    f"{args.runs} runs of {args.steps} steps per case and version, interleaved; current: {kernel}"
                    + (f"; baseline: {args.baseline} ({args.baseline_commit[:9]})" if args.baseline_commit else ""),
                    ["case", "version", "instantiate", "first step", "median", "95th pct", "99th pct", "max",
                     "median ratio to baseline"], rows)
        if {"pitch", "yaw"} <= set(args.cases):
            lines = []
            for v in versions:
                turbine = 3 * means["pitch", v] + means["yaw", v]
                lines.append([v, f"{turbine:.2f} ms", f"{DT * 1e3 / turbine:.2f}"])
            print_table("A whole turbine's bearings (3 pitch + 1 yaw, flexible rings) at a 10 ms step: mean cost of "
                        "one step of all four, and the real-time factor (simulated time / wall time; > 1 is faster "
                        "than real time)", ["version", "4 bearings per step", "real-time factor"], lines)

        if args.memory_steps:
            memory_worker = Worker(fmus["current"]["table3_errors"], "table3_light", args.memory_steps,
                                   args.without_numba)
            memory, done = [], 0
            for mark in sorted({1_000, *range(20_000, args.memory_steps + 1, 20_000), args.memory_steps}):
                memory.append([f"{mark:,}", f"{memory_worker.run(done, mark - done)['rss_mb']:.1f}"])
                done = mark
            memory_worker.close()
            print_table("Resident memory of the host process (current FMU, table3_light, flexible rings)",
                        ["steps", "RSS [MB]"], memory)

