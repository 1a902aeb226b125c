"""The closed turbine loop against a real-time clock: ROSCO, the rotor, each blade's BEM and three pitch
drives on flexible pitch bearings, at 10 ms steps.

The NREL 5MW in IEC class B turbulence (Kaimal, 13 m/s mean at the hub, seeded: the first ``--duration`` s,
default 30, of a 10-minute realisation, as :func:`slewing_turbine.wind.kaimal` gives a short run) through
:func:`slewing_turbine.loop.run_turbine` with ``drives="electric"``,
``bearings="flexible"`` (``examples/bearings/pitch_bearing.toml``, ``--mesh`` superelement, friction on),
``aero="bem"``, its bearings solving every step to their tolerance (``step_work`` "complete"), and the
same with bounded steps (``step_work`` "bounded": a step's work capped, as a real-time host runs the FMU), and
the same with the three pitch bearings as FMUs (``loop, bearings as FMUs``: the bearing FMU, FMI 2.0 as
``build_fmu.py`` builds it by default with the ``--mesh`` superelement and no win64 half, built once before the
rounds, three instances stepped through fmpy by :func:`slewing_turbine.fmu_bearing.fmu_bearings`, set as the
library's simulators; in this Python host the FMUs run this process's ``slewing_model`` and its loops, so the
row measures what the FMI layers add; the FMU's first step also builds its simulator, in
``exitInitializationMode``). Two baselines measured in the same run, alternating with them (``--runs``
rounds, each of the six once):

* ``ideal drives``: the same loop with ideal pitch drives and no bearing (ROSCO, rotor, BEM, blade loads):
  what the loop costs without its pitch axes;
* ``bearings alone``: the three bearing simulators stepped through the loads, angles and speeds the full
  loop gave them in that round (fresh simulators, the same inputs): what the pitch bearings cost on their
  own; and ``bearings alone, as FMUs``: the same through three fresh instances of the FMU.

Each row: seconds of wall time per simulated second (its inverse is the real-time factor; the goal is at
least 1.5, i.e. at most 0.67 s per s; the step times summed, the set-up outside), the process's CPU
seconds per simulated second over the whole run (what a shared machine's other load does not inflate as
much as the wall time: the two differ when the process waited for a core), the median and tail of the
step times over the rounds' steps (a step of the loop: all of it; of the bearings alone: the three
bearings' steps), and the full loop's median against each baseline's. Simulators are built (and their
loops compiled or loaded from cache) before a round's clock starts; each round's first 0.5 s of simulated
time is left out of the step statistics (the first steps solve from a cold start), and a 1 s run before
the rounds warms the caches (and one through the FMUs). A note gives the largest difference between the pitch
of the loop through the FMUs and through the library (they compute the same numbers: 0).

Run: .venv/bin/python -m benchmarks turbine [--runs 3] [--duration 30] [--mesh fine|coarse]
"""
from __future__ import annotations

import math
import os
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from .suite import build_fmu_module, note, print_table, record, spread

#: rounds of the six variants (``--runs``)
RUNS = 3
DT = 0.01
MEAN_WIND = 13.0
SEED = 63
#: simulated time left out of the step statistics at the start of each run, s
SETTLE = 0.5
#: the real-time goal: simulated seconds per wall second
GOAL = 1.5


def add_arguments(parser) -> None:
    parser.add_argument("--duration", type=float, default=30.0, help="simulated seconds per run (default 30)")
    parser.add_argument("--mesh", choices=("fine", "coarse"), default="fine",
                        help="superelement mesh of the flexible bearings (default fine, the FMU's)")


def _bearings_alone(config, result, sims=None):
    """Step three fresh flexible bearings (``sims``, default the library's simulators) through ``result``'s
    bearing inputs; the step times (s) of the three together, per loop step."""
    from slewing_model import Loads
    from slewing_turbine.loop import make_bearings

    sims = make_bearings(config, "flexible", friction=True) if sims is None else sims
    n = result.time.size
    seconds = np.zeros(n)
    for i in range(1, n):
        start = time.perf_counter()
        for k, sim in enumerate(sims):
            sim.step(Loads(*map(float, result.root_loads[i, k, :5])), psi=-float(result.pitch[i - 1, k]),
                     omega=-float(result.pitch_rate[i - 1, k]))
        seconds[i] = time.perf_counter() - start
    return seconds


def main(args) -> None:
    with tempfile.TemporaryDirectory(prefix="bench_turbine_") as tmp:
        _main(args, Path(tmp))


def _main(args, tmp: Path) -> None:
    from slewing_turbine.fmu_bearing import fmu_bearings
    from slewing_turbine.loop import PITCH_BEARING, TurbineConfig, make_bearings, run_turbine
    from slewing_turbine.wind import kaimal

    config = TurbineConfig(mesh=args.mesh)
    wind = kaimal(MEAN_WIND, args.duration + 1.0, DT, seed=SEED)
    note(f"NREL 5MW, Kaimal class B {MEAN_WIND:g} m/s (seed {SEED}, the first {args.duration:g} s of a 600 s "
         f"realisation), {args.duration:g} s at {DT * 1e3:g} ms, "
         f"pitch bearing with flexible rings ({args.mesh} superelement), friction on; {args.runs} rounds")
    note(f"machine load at the start (1, 5, 15 min): {', '.join(f'{x:.2f}' for x in os.getloadavg())} "
         f"on {os.cpu_count()} cores")
    started = time.perf_counter()
    make_bearings(config, "flexible", friction=True, count=1)        # builds or loads the superelement
    note(f"superelement and first simulator: {time.perf_counter() - started:.1f} s")
    started = time.perf_counter()
    fmu = build_fmu_module().build_fmu(PITCH_BEARING, tmp / "SlewingBearing_pitch_bearing.fmu", mesh=args.mesh,
                                       bc="free", win64=False)
    note(f"the bearing FMU (FMI 2.0, standalone, {args.mesh} mesh, no win64 half): built in "
         f"{time.perf_counter() - started:.1f} s")
    run_turbine(config, wind, t_end=1.0, dt=DT, drives="electric", bearings="flexible", aero="bem")   # warm-up
    with fmu_bearings(config, fmu, "flexible", friction=True, dt=DT) as sims:
        run_turbine(config, wind, t_end=1.0, dt=DT, drives="electric", bearings="flexible", aero="bem",
                    bearing_simulators=sims)

    skip = int(round(SETTLE / DT)) + 1
    steps = {"loop": [], "loop, bounded steps": [], "loop, bearings as FMUs": [], "ideal drives": [],
             "bearings alone": [], "bearings alone, as FMUs": []}
    pitch_difference = 0.0
    wall = {k: [] for k in steps}
    cpu = {k: [] for k in steps}

    def timed(name, func):
        start = time.process_time()
        out = func()
        cpu[name].append((time.process_time() - start) / args.duration)
        return out

    for _ in range(args.runs):
        sims = make_bearings(config, "flexible", friction=True)
        full = timed("loop", lambda: run_turbine(config, wind, t_end=args.duration, dt=DT, drives="electric",
                                                 bearings="flexible", aero="bem", bearing_simulators=sims))
        bounded_config = replace(config, step_work="bounded")
        sims = make_bearings(bounded_config, "flexible", friction=True)
        bounded = timed("loop, bounded steps", lambda: run_turbine(
            bounded_config, wind, t_end=args.duration, dt=DT, drives="electric", bearings="flexible", aero="bem",
            bearing_simulators=sims))
        with fmu_bearings(config, fmu, "flexible", friction=True, dt=DT) as sims:
            via_fmus = timed("loop, bearings as FMUs", lambda: run_turbine(
                config, wind, t_end=args.duration, dt=DT, drives="electric", bearings="flexible", aero="bem",
                bearing_simulators=sims))
        pitch_difference = max(pitch_difference, float(np.max(np.abs(via_fmus.pitch - full.pitch))))
        ideal = timed("ideal drives", lambda: run_turbine(config, wind, t_end=args.duration, dt=DT, drives="ideal",
                                                          aero="bem"))
        alone = timed("bearings alone", lambda: _bearings_alone(config, full))
        with fmu_bearings(config, fmu, "flexible", friction=True, dt=DT) as sims:
            alone_fmus = timed("bearings alone, as FMUs", lambda: _bearings_alone(config, full, sims))
        for name, seconds in (("loop", full.step_seconds), ("loop, bounded steps", bounded.step_seconds),
                              ("loop, bearings as FMUs", via_fmus.step_seconds), ("ideal drives", ideal.step_seconds),
                              ("bearings alone", alone), ("bearings alone, as FMUs", alone_fmus)):
            steps[name].append(seconds[skip:])
            wall[name].append(float(seconds[1:].sum()) / args.duration)
    rows, medians = [], {}
    for name in steps:
        s = spread(np.concatenate(steps[name]))
        medians[name] = s["median"]
        per_second = float(np.median(wall[name]))
        rows.append([name, f"{per_second:.3f}", f"{1.0 / per_second:.2f}x", f"{max(wall[name]):.3f}",
                     f"{float(np.median(cpu[name])):.3f}", f"{s['median'] * 1e3:.2f} ms", f"{s['p95'] * 1e3:.2f} ms",
                     f"{s['p99'] * 1e3:.2f} ms", f"{s['max'] * 1e3:.1f} ms"])
        record(name, {"seconds_per_simulated_second": wall[name], "cpu_seconds_per_simulated_second": cpu[name],
                      "steps": s})
    print_table(f"the turbine loop, {args.duration:g} s at {DT * 1e3:g} ms, {args.runs} rounds (goal: at least "
                f"{GOAL:g}x real time)",
                ["variant", "s per simulated s (median)", "real-time factor", "s per s (worst round)",
                 "CPU s per simulated s", "median step", "p95", "p99", "slowest"], rows)
    loop_median = medians["loop"]
    print_table("the full loop's median step against the baselines'",
                ["baseline", "baseline median", "loop / baseline", "loop - baseline"],
                [[name, f"{medians[name] * 1e3:.2f} ms", f"{loop_median / medians[name]:.2f}",
                  f"{(loop_median - medians[name]) * 1e3:.2f} ms"] for name in ("ideal drives", "bearings alone")])
    note(f"the loop through the FMUs against the library's: pitch within {pitch_difference:.3g} rad")
    record("pitch_difference_fmu_library", pitch_difference)
    factors = {}
    for name in ("loop", "loop, bounded steps", "loop, bearings as FMUs"):
        factors[name] = factor = 1.0 / float(np.median(wall[name]))
        note(f"real-time factor, {name}: {factor:.2f}x ({'meets' if factor >= GOAL else 'misses'} the {GOAL:g}x goal)")
    note(f"machine load at the end (1, 5, 15 min): {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    factor = factors["loop"]
    record("real_time_factor", factors)
    record("goal", GOAL)
    if not math.isfinite(factor):      # pragma: no cover
        raise SystemExit("no steps timed")
