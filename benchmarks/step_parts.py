"""Where a co-simulation step's time goes, and what of it one compiled call could save: the floor.

The pitch bearing as the FMU runs it (flexible rings, loads in the blade-root frame, friction and
life on, complete steps), stepped through the library's simulator under a scenario of
the ``realtime`` benchmark (``nrel``, ``turbulence``, ...). Each part of a step is timed where it is
called (the method wrapped for the run):

- ``set_rotation``: the solver's assembly at the ring's angle;
- ``solve``, and within it the usual warm solve's one compiled call (``one call``: the start, the
  operator's turn, the kept iterations and, at the equilibrium, the contacts' results) and where it
  stops short or is not taken, the compiled Newton iterations with the kept operator (``kept
  iterations``), the start and line-search evaluations (``evaluate``), the operator's turn
  (``turned``), the results (``result``, which at an equilibrium of the one call only words it), and
  the rest (the Python between them);
- ``friction``, and within it the one compiled call of the balls' equilibrium and torque;
- ``life``: the raceway map and damage;
- ``simulator``: the step's own bookkeeping (the warm starts, the state), what is left of the step.

Steps that form, border or invert an operator (their time is that work's: the ``operator`` benchmark)
are counted apart; the table is of the other steps, the usual ones. The compiled calls (the two big
ones, the solve's and the friction's, and the other loops a step calls from Python: the start's
trial point, the ring product, the operator's turn, the contacts' results, the life map) are then
called again with the arguments they had in those steps, each several times in a row ("hot": its
data and code in the cache, no Python around it): the sum of the hot calls is what a step made of one
compiled call would still cost, the floor of "one compiled call", against the median of the step as it
runs now. The gap between a call in
the step and the same call hot is what the step's cold caches cost it (the other parts' data and
code ran in between).

``--scenarios`` takes the ``realtime`` benchmark's scenarios and ``yaw`` (the ``fmu`` benchmark's yaw case: the
180-ball yaw bearing under the tower-top series, yawing in bursts). With a pitch scenario and ``yaw``
the last lines weigh them as the whole turbine does (3 pitch + 1 yaw bearing at a 10 ms step):
the four usual steps' medians and the four steps' compiled calls hot, each as a real-time factor. The
hot calls are a floor no formulation of the step around these loops goes below; the real-time factor of
the whole turbine's mean steps, with the ring operators' work, is the ``fmu`` benchmark's.

Run: .venv/bin/python -m benchmarks step_parts [--scenarios nrel turbulence yaw] [--steps 3000]
"""
from __future__ import annotations

import time
from contextlib import ExitStack, contextmanager

import numpy as np

from slewing_model import Loads, load_bearing
from slewing_model.distribution import bime
from slewing_model.distribution import kernel as distribution_kernel
from slewing_model.friction import ball_kinematics
from slewing_model.life import raceway_map
from slewing_model.life.duty import LifeAccumulator
from slewing_model.rings.superelement import build_superelement
from slewing_model.simulation import simulator

from .cases import DT, yaw
from .realtime import SCENARIOS, scenario
from .suite import note, print_table, record

#: the parts timed, (label, owner, attribute); a label with a leading space is a part of the one above
PARTS = (
    ("set_rotation", bime.BimeSolver, "set_rotation"),
    ("solve", bime.BimeSolver, "solve"),
    (" one call", bime.BimeSolver, "_warm_solve"),
    (" kept iterations", bime.BimeSolver, "_kept_iterations"),
    (" evaluate", bime.BimeSolver, "_evaluate"),
    (" turned", bime.BimeSolver, "_turned"),
    (" result", bime.BimeSolver, "_result"),
    ("friction", simulator, "warm_torque"),
    (" compiled call", ball_kinematics.WarmFrictionStep, "__call__"),
    ("life", LifeAccumulator, "step"),
)
#: the label of the other compiled loops a step calls from Python (the start's trial point, the ring product,
#: the operator's turn, the contacts' results, the life map), replayed hot together
OTHER = "the other compiled loops"
#: what marks a step with operator work
OPERATOR_WORK = ((bime.BimeSolver, "_start_operator"), (bime.BimeSolver, "_advance"), (bime, "update_operator"))
#: the compiled calls replayed hot: (label, module, factory name)
COMPILED = ((" one call", bime, "compiled_warm_solve"), (" kept iterations", bime, "compiled_kept_iterations"),
            (" compiled call", ball_kinematics, "compiled_friction_step"),
            (OTHER, bime, "compiled_trial_point"), (OTHER, bime, "compiled_ring_times"),
            (OTHER, distribution_kernel, "compiled_column_turn"), (OTHER, distribution_kernel, "compiled_contact_results"),
            (OTHER, raceway_map, "compiled_map_update"))
REPLAYS = 5


@contextmanager
def patched(owner, name, wrapper):
    original = getattr(owner, name)
    setattr(owner, name, wrapper(original))
    try:
        yield
    finally:
        setattr(owner, name, original)


def timer(label, spent, depth=None):
    """A wrapper adding the time of the outermost calls of a part to ``spent[label]`` (a call within a call of
    the same label, ``_run_stages``' recursion, is not counted twice; ``depth``: the calls open per label)."""
    depth = {} if depth is None else depth

    def wrap(original):
        def timed(*args, **kwargs):
            depth[label] = depth.get(label, 0) + 1
            start = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                depth[label] -= 1
                if depth[label] == 0:
                    spent[label] = spent.get(label, 0.0) + time.perf_counter() - start
        return timed
    return wrap


def counter(seen):
    def wrap(original):
        def counted(*args, **kwargs):
            seen.append(1)
            return original(*args, **kwargs)
        return counted
    return wrap


def recorder(label, calls):
    """The factory of a compiled loop, whose loop records its arguments (copied) for the replay where
    ``calls`` is a list (the steps sampled for it; their own times are not used)."""
    def wrap(factory):
        def recording_factory():
            loop = factory()
            if calls.get("list") is None:
                return loop

            def recording(*args):
                calls["list"].append((label, loop, [a.copy() if isinstance(a, np.ndarray) else a for a in args]))
                return loop(*args)
            return recording
        return recording_factory
    return wrap


def step_scenario(name: str, steps: int) -> dict:
    case = yaw(steps) if name == "yaw" else scenario(name)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="fine", progress=False)
    sim = simulator.BearingSimulator(bearing, superelement, simulator.SimulatorSettings(
        ring_model="flexible", load_frame="rotating", life=True, step_work="complete", contact_kernel="auto"))
    spent, seen, calls = {}, [], {}
    usual = {"step": []}
    replay = []
    with ExitStack() as stack:
        for label, owner, attribute in PARTS:
            stack.enter_context(patched(owner, attribute, timer(label, spent)))
        for owner, attribute in OPERATOR_WORK:
            stack.enter_context(patched(owner, attribute, counter(seen)))
        for label, module, factory in COMPILED:
            stack.enter_context(patched(module, factory, recorder(label, calls)))
        for k in range(min(steps, case.steps)):
            spent.clear()
            seen.clear()
            sampled = k >= 50 and k % 10 == 5      # its compiled calls recorded for the replay, not timed
            calls["list"] = [] if sampled else None
            start = time.perf_counter()
            sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
            total = time.perf_counter() - start
            if k < 50 or seen:                 # the first steps, and those with operator work, apart
                continue
            if sampled:
                replay.append(calls["list"])
                continue
            usual["step"].append(total)
            for label, _, _ in PARTS:
                usual.setdefault(label, []).append(spent.get(label, 0.0))
    hot = {label: [] for label, _, _ in COMPILED}
    for step_calls in replay:
        per_label = {label: 0.0 for label in hot}
        for label, loop, args in step_calls:
            times = []
            for _ in range(REPLAYS):
                fresh = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
                start = time.perf_counter()
                loop(*fresh)
                times.append(time.perf_counter() - start)
            per_label[label] += min(times[1:])         # the first call of a row warms the cache
        for label, value in per_label.items():
            hot[label].append(value)
    return {"usual": {k: 1e6 * np.asarray(v) for k, v in usual.items()},
            "hot": {k: 1e6 * np.asarray(v) for k, v in hot.items()}, "steps": len(usual["step"])}


def add_arguments(parser) -> None:
    parser.add_argument("--scenarios", nargs="+", default=["nrel", "turbulence"], choices=(*SCENARIOS, "yaw"))
    parser.add_argument("--steps", type=int, default=3000, help="steps of the yaw case (the others: the scenario's)")


def main(args) -> None:
    medians, floors = {}, {}
    for name in args.scenarios:
        found = step_scenario(name, args.steps)
        usual, hot = found["usual"], found["hot"]
        step = float(np.median(usual["step"]))
        parts = {label: float(np.mean(usual[label])) for label, _, _ in PARTS}
        rows = [["step", f"{step:.0f}", f"{np.mean(usual['step']):.0f}", "", ""]]
        for label, _, _ in PARTS:
            hot_cell = f"{np.median(hot[label]):.0f}" if label in hot else ""
            rows.append([label, "", f"{parts[label]:.0f}", f"{parts[label] / np.mean(usual['step']):.2f}", hot_cell])
        rows.append([OTHER, "", "", "", f"{np.median(hot[OTHER]):.0f}"])
        top = sum(v for label, v in parts.items() if not label.startswith(" "))
        inside = {"solve": (" one call", " kept iterations", " evaluate", " turned", " result"),
                  "friction": (" compiled call",)}
        for whole, pieces in inside.items():
            rows.append([f" {whole}: the rest", "", f"{parts[whole] - sum(parts[p] for p in pieces):.0f}", "", ""])
        rows.append(["simulator (the step less its parts)", "", f"{np.mean(usual['step']) - top:.0f}", "", ""])
        print_table(f"{name}: {found['steps']} steps without operator work, us", ["part", "median", "mean",
                                                                                   "share of the mean", "hot"], rows)
        floor = float(np.median(np.sum([hot[label] for label in hot], axis=0)))
        note(f"the compiled calls hot: {floor:.0f} us, {floor / step:.2f} of the median step ({step:.0f} us)")
        record(f"{name} [us]", {"median step": step, "compiled calls hot": floor})
        medians[name], floors[name] = step, floor
    pitch = next((name for name in args.scenarios if name != "yaw"), None)
    if pitch is not None and "yaw" in args.scenarios:
        for what, values in (("usual steps' medians", medians), ("compiled calls hot", floors)):
            turbine = 3.0 * values[pitch] + values["yaw"]
            note(f"whole turbine (3 x {pitch} + yaw), {what}: {turbine:.0f} us a 10 ms step, "
                  f"{1e6 * DT / turbine:.1f} times real time")

