"""Studies on Dask (`slewing batch`): cases per minute with 1 and 2 workers, and what 1,000 cases of 600 s take.

Cases: the 150-ball pitch bearing (examples/bearings/pitch_bearing.toml), flexible rings
(coarse superelement, free rings), friction on, stepped through seeded synthetic blade-root
load series (slewing_drives.load_series.synthetic_blade_root_loads) while the blade pitches
(a 2 deg sine of 0.1 Hz plus a ramp), sampled at 20 Hz (dt = 0.05 s). ``--cases`` cases of
``--duration`` s each.

The study runs with an embedded LocalCluster of 1 worker process and of 2, alternately,
``--runs`` times each, into fresh output directories, so that both see the same machine load;
the cluster start is timed apart. Cases per minute count from the first submission to the
last result written. The ratio is 2 workers over 1, per pair of runs.

The projection takes the measured cost per step of every case (its wall time on its worker
over its steps) and the measured overhead per case (wall time of the 1-worker runs minus the
cases' own times), and simulates 1,000 cases of 600 s (12,000 steps at 20 Hz) assigned to
the first free worker, each case's cost drawn from the measured ones (500 draws): median and
95th percentile of the wall time on 1, 16 and 128 workers. It assumes each worker has a core
as fast as this machine's, the load files on the workers, and a scheduler that keeps up
(Dask's is good for thousands of tasks per second; a case takes tens of seconds).

Run: .venv/bin/python -m benchmarks batch [--cases 20] [--duration 20] [--runs 2]
"""
from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from .suite import ROOT, note, print_table

#: pairs of (1 worker, 2 workers) runs
RUNS = 2
DT = 0.05


def write_inputs(folder: Path, cases: int, duration: float) -> Path:
    """Load series CSVs with the pitch motion, and the study file."""
    from slewing_drives.load_series import synthetic_blade_root_loads
    from slewing_model.study.series import MotionSeries, write_csv

    entries = []
    for seed in range(cases):
        s = synthetic_blade_root_loads(duration, dt=DT, seed=seed)
        t = s.time
        pitch = np.radians(2.0 * np.sin(2 * np.pi * 0.1 * t + seed) + 0.2 * t)
        rate = np.radians(2.0 * 2 * np.pi * 0.1 * np.cos(2 * np.pi * 0.1 * t + seed) + 0.2)
        path = folder / f"loads_{seed:03d}.csv"
        write_csv(str(path), MotionSeries(t, s.loads, pitch, rate, "rotating", str(path)))
        entries.append(f'[[loads]]\nname = "seed {seed}"\ncsv = "{path.as_posix()}"\nload_frame = "rotating"\n')
    study = folder / "bench.toml"
    study.write_text('[study]\nname = "bench"\n\n' + "\n".join(entries)
                     + f'\n[bearings]\nfiles = ["{(ROOT / "examples/bearings/pitch_bearing.toml").as_posix()}"]\n'
                     'ring_model = ["flexible"]\n\n[simulation]\nmesh = "coarse"\nbc = "free"\n')
    return study


def run_study_on(study: Path, out: Path, workers: int) -> dict:
    from distributed import Client, LocalCluster

    from slewing_model.study import run_study

    import dask

    start = time.perf_counter()
    # as slewing batch's embedded cluster does (slewing_model/study/engine.py): without Dask's
    # MALLOC_TRIM_THRESHOLD_, whose page faults make every step 1.6 times slower
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}), \
            LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                         scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, silence_logs=40) as cluster, Client(cluster) as client:
        started = time.perf_counter() - start
        report = run_study(study, out, client=client, progress=False, figures=False)
    assert not report.failed, report.failed
    elapsed = [float(r["elapsed_s"]) for r in report.rows]
    steps = [int(r["steps"]) for r in report.rows]
    return {"workers": workers, "wall": report.wall_time, "start": started, "elapsed": elapsed, "steps": steps,
            "per_minute": len(report.rows) / report.wall_time * 60.0}


def project(costs: np.ndarray, overhead: float, workers: int, cases: int = 1000, draws: int = 500,
            seed: int = 0) -> tuple[float, float]:
    """Wall time (median, 95th percentile over draws) of ``cases`` cases whose costs are drawn from
    ``costs`` (s), each given to the first free of ``workers`` workers."""
    rng = np.random.default_rng(seed)
    walls = []
    for _ in range(draws):
        c = rng.choice(costs, size=cases) + overhead
        free = np.zeros(workers)
        for x in c:
            i = np.argmin(free)
            free[i] += x
        walls.append(free.max())
    return float(np.median(walls)), float(np.percentile(walls, 95))


def hms(seconds: float) -> str:
    if seconds >= 3600:
        return f"{seconds / 3600:.2f} h"
    if seconds >= 60:
        return f"{seconds / 60:.1f} min"
    return f"{seconds:.1f} s"


def add_arguments(parser) -> None:
    parser.add_argument("--cases", type=int, default=20)
    parser.add_argument("--duration", type=float, default=20.0, help="s of simulated time per case")


def main(args) -> None:

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        os.environ.setdefault("SLEWING_CACHE_DIR", str(tmp / "cache"))
        study = write_inputs(tmp, args.cases, args.duration)
        from slewing_model.study import load_study
        from slewing_model.study.engine import _Prepared

        t0 = time.perf_counter()
        _Prepared(load_study(study).simulation).superelement(str(ROOT / "examples/bearings/pitch_bearing.toml"))
        build = time.perf_counter() - t0
        results = []
        for k in range(args.runs):
            for workers in (1, 2):
                results.append(run_study_on(study, tmp / f"out_{k}_{workers}", workers))
                r = results[-1]
                print(f"run {k + 1}, {workers} worker(s): {r['wall']:.1f} s, {r['per_minute']:.1f} cases/min "
                      f"(cluster start {r['start']:.1f} s)", flush=True)

    one = [r for r in results if r["workers"] == 1]
    two = [r for r in results if r["workers"] == 2]
    ratios = [b["per_minute"] / a["per_minute"] for a, b in zip(one, two)]
    steps = results[0]["steps"][0]
    note(f"\n{args.cases} cases of {args.duration:g} s ({steps} steps at {DT} s), pitch bearing 150 balls, flexible "
          f"rings (coarse superelement, built once in {build:.1f} s), friction on; {args.runs} runs each, alternating; "
          f"the machine's 2 cores are shared with other users")
    rows = []
    for label, group in (("1 worker", one), ("2 workers", two)):
        costs = np.concatenate([r["elapsed"] for r in group])
        rows.append([label, f"{statistics.median(r['per_minute'] for r in group):.1f}",
                     " / ".join(f"{r['per_minute']:.1f}" for r in group),
                     f"{np.median(costs):.2f} s", f"{np.percentile(costs, 95):.2f} s", f"{costs.max():.2f} s",
                     f"{np.median(costs) / steps * 1e3:.2f} ms"])
    rows[0].append("1.00")
    rows[1].append(f"{statistics.median(ratios):.2f} ({' / '.join(f'{x:.2f}' for x in ratios)})")
    print_table("Cases per minute (from first submission to last result written)",
                ["cluster", "cases/min (median)", "each run", "case median", "case p95", "case max",
                 "per step", "ratio to 1 worker"], rows)

    per_step = np.concatenate([np.array(r["elapsed"]) / np.array(r["steps"]) for r in results])
    overhead = statistics.median(max(0.0, (r["wall"] - sum(r["elapsed"])) / len(r["elapsed"])) for r in one)
    steps600 = int(round(600.0 / DT))
    costs600 = per_step * steps600
    rows = []
    for workers in (1, 16, 128):
        med, p95 = project(costs600, overhead, workers)
        rows.append([str(workers), f"{int(np.ceil(1000 / workers))}", hms(med), hms(p95)])
    print_table(f"Projected wall time of 1,000 cases of 600 s ({steps600} steps at {DT} s; measured cost per case "
                f"median {hms(float(np.median(costs600)))}, p95 {hms(float(np.percentile(costs600, 95)))}, overhead "
                f"{overhead * 1e3:.0f} ms per case; one core per worker as fast as this one)",
                ["workers", "cases per worker", "wall time (median)", "wall time (p95)"], rows)

