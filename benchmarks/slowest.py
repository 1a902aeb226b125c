"""What the slowest steps spend their time on: each part of the slowest steps of a scenario.

The pitch bearing as the FMU runs it (flexible rings, loads in the blade-root frame, friction and life on,
compiled kernels), started at zero loads as an FMU leaving initialization with its start values, stepped
through the library's simulator under a scenario of the ``realtime`` benchmark; bounded steps by default
(``step_work="bounded"``, whose slowest step the goal wants under 4 NREL medians). Each part is timed
where it is called (the function wrapped for the run, its calls within it not counted twice):

- ``form``: a new operator's ``W`` gathered (``start_operator``);
- ``stages``: the stages of its inverse (``_run_stages``, by halves or through the Cholesky factor);
- ``check``: the inverse's probe check (``passes_check``);
- ``coupling``: its coupling to the ring's motions (``reduced_operator``);
- ``bordering``: contacts that closed bordered in (``update_operator``);
- ``solve calls``: the usual solve's one compiled call and the kept iterations' loop;
- ``evaluations``: the start's and the line searches' trial points, one by one from Python;
- ``result``: the load distribution worded (the contacts' results where the one call did not give them);
- ``friction``, ``life``; ``rest``: the step less these (the Python between them, the line search's
  evaluations, the results).

``work`` is what the step charged to ``BOUNDED_WORK`` (the bounded solve's count: forming, stages,
bordering, iterations; :mod:`slewing_model.distribution.bime`), shown as the time it stands for at 55
million a millisecond. A part whose time is far above its share of that count is work the bound does
not see.

Run: .venv/bin/python -m benchmarks slowest [--scenarios nrel reversal ...] [--top 5]
     [--step-work bounded|complete]   (about 20 s for the five scenarios)
"""
from __future__ import annotations

import time
from contextlib import ExitStack

import numpy as np

from slewing_model import Loads, load_bearing
from slewing_model.distribution import bime
from slewing_model.life.duty import LifeAccumulator
from slewing_model.rings import reduced_operator
from slewing_model.rings.superelement import build_superelement
from slewing_model.simulation import simulator

from .realtime import SCENARIOS, scenario
from .step_parts import patched, timer
from .suite import print_table

#: the parts timed: (label, owner, attribute)
PARTS = (
    ("form", bime, "start_operator"),
    ("stages", reduced_operator, "_run_stages"),
    ("check", reduced_operator, "passes_check"),
    ("coupling", reduced_operator, "reduced_operator"),
    ("bordering", bime, "update_operator"),
    ("solve calls", bime.BimeSolver, "_warm_solve"),
    ("solve calls", bime.BimeSolver, "_kept_iterations"),
    ("evaluations", bime.BimeSolver, "_evaluate"),
    ("result", bime.BimeSolver, "_result"),
    ("friction", simulator, "warm_torque"),             # the usual step's one compiled call, prepared
    ("friction", simulator, "friction_torque"),         # ... or, where it declines, the general path
    ("life", LifeAccumulator, "step"),
)
#: work a millisecond, as BOUNDED_WORK counts it (its comment)
WORK_RATE = 55e6


def step_scenario(name: str, step_work: str) -> list[dict]:
    """Every step of the scenario ``name``: its time, flag, work charged and parts (ms)."""
    case = scenario(name)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="fine", progress=False)
    sim = simulator.BearingSimulator(bearing, superelement, simulator.SimulatorSettings(
        ring_model="flexible", load_frame="rotating", life=True, step_work=step_work, contact_kernel="auto"))
    sim.step(Loads(), 0.0, 0.0)                     # the start values, solved leaving initialization
    steps, spent = [], {}
    with ExitStack() as stack:
        for label, owner, attribute in PARTS:
            stack.enter_context(patched(owner, attribute, timer(label, spent)))
        for k in range(case.steps):
            spent.clear()
            start = time.perf_counter()
            out = sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
            total = time.perf_counter() - start
            work = bime.BOUNDED_WORK - sim.solver._work_left if step_work == "bounded" else float("nan")
            steps.append({"step": k, "time": 1e3 * total, "flagged": not out.distribution.converged,
                          "work": work, **{label: 1e3 * t for label, t in spent.items()}})
    return steps


def add_arguments(parser) -> None:
    parser.add_argument("--scenarios", nargs="*", default=list(SCENARIOS), choices=SCENARIOS)
    parser.add_argument("--top", type=int, default=5, help="the slowest steps shown per scenario")
    parser.add_argument("--step-work", default="bounded", choices=bime.STEP_WORK)


def main(args) -> None:
    scenarios = ["nrel"] + [s for s in args.scenarios if s != "nrel"]     # NREL first: its median is the unit
    labels = list(dict.fromkeys(label for label, _, _ in PARTS))
    nrel_median = None
    for name in scenarios:
        steps = step_scenario(name, args.step_work)
        times = np.array([s["time"] for s in steps])
        nrel_median = nrel_median or float(np.median(times))
        if name not in args.scenarios:
            continue
        rows = []
        for s in sorted(steps, key=lambda s: -s["time"])[:args.top]:
            rest = s["time"] - sum(s.get(label, 0.0) for label in labels)
            rows.append([str(s["step"]), f"{s['time']:.2f}", f"{s['time'] / nrel_median:.1f}",
                         "yes" if s["flagged"] else "", f"{s['work'] / WORK_RATE:.2f}"]
                        + [f"{s.get(label, 0.0):.2f}" for label in labels] + [f"{rest:.2f}"])
        print_table(f"{name}, {args.step_work} steps: the {args.top} slowest of {len(steps)} (median "
                    f"{np.median(times):.2f} ms, NREL median {nrel_median:.2f} ms); times in ms",
                    ["step", "time", "NREL medians", "flagged", "work charged [ms]"] + labels + ["rest"],
                    rows)

