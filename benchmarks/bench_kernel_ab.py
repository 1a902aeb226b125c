"""One compiled call of a step, replayed hot: the library's loop against the same loop compiled with other
fast-math flags, or from the kernel's source at another revision, alternating call by call in one process
(issue 31).

A change inside one compiled call that saves a few percent of a step is below what a step-level A/B
resolves on a noisy machine (runs of the same pair of revisions gave ratios 0.78-1.02 here: docs/speed.md,
"Issue 31, twenty-second turn"). So the pitch bearing is stepped as the FMU steps it (flexible rings, loads
in the blade-root frame, friction and life on, complete steps) through a scenario of ``bench_realtime.py``,
and the arguments of one compiled call are recorded every tenth step from the 50th on:

- ``--kernel distribution``: the usual solve's one call (``kernel._warm_solve``: the start, the operator's
  turn, the kept iterations and the contacts' results);
- ``--kernel friction``: the friction's one call (``kernel._friction_step``: the balls' equilibrium and the
  torque).

The kernel module is then loaded again from a copy of its source (in a temporary folder: its own numba
cache), this checkout's or that of git revision ``--revision``, with ``FASTMATH`` set to ``--flags`` where
given (none: ``--flags`` alone), and its loop compiled; the call's signature must be the same. Each round
calls every recorded call once with the library's loop and once with the variant's, in alternating order,
each on fresh copies of its arguments; a round's time is the sum over the recorded calls. The table gives
the rounds' median and tail percentiles of each loop, and the ratio variant / library of each round (its
median and percentiles). The largest difference of the two loops' answers (relative to each answer's
largest entry) and whether their iterations agree are printed under it: a change of flags moves
round-off, and where the distribution's stop rule then flips an iteration the answers differ by up to
its tolerance.

Run: .venv/bin/python benchmarks/bench_kernel_ab.py --kernel distribution --flags [--flags contract reassoc]
     [--revision HEAD~1] [--scenario nrel] [--steps 550] [--rounds 30]
"""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from contextlib import ExitStack
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_realtime import scenario  # noqa: E402
from bench_step_parts import patched, recorder  # noqa: E402
from timing import print_table  # noqa: E402

from slewing_model import Loads, load_bearing  # noqa: E402
from slewing_model.distribution import bime  # noqa: E402
from slewing_model.friction import ball_kinematics  # noqa: E402
from slewing_model.numerics.compiled import aot_kernels  # noqa: E402
from slewing_model.rings.superelement import build_superelement  # noqa: E402
from slewing_model.simulation import simulator  # noqa: E402

#: per kernel: the module whose factory a step calls, the factory's name, the kernel module, its loop and signature
KERNELS = {"distribution": (bime, "compiled_warm_solve", "slewing_model.distribution.kernel", "_warm_solve",
                            "_WARM_SIGNATURE"),
           "friction": (ball_kinematics, "compiled_friction_step", "slewing_model.friction.kernel", "_friction_step",
                        "_FRICTION_STEP_SIGNATURE")}
#: per kernel: the answers compared (name, index in what the loop returns) and the integers that must agree
ANSWERS = {"distribution": ((("ring displacements", 5), ("ring motions y", 6), ("contact loads", 10)), (0, 1, 3, 4)),
           "friction": ((("contact powers", 4), ("contact torques", 5)), (0, 1, 3))}
FLAGS = ("contract", "reassoc", "arcp", "afn", "nsz")
ROOT = Path(__file__).resolve().parents[1]


def record(kernel: str, name: str, steps: int) -> list:
    """The arguments of ``kernel``'s one call in every tenth step from the 50th of scenario ``name``."""
    owner, factory, *_ = KERNELS[kernel]
    case = scenario(name)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="fine", progress=False)
    sim = simulator.BearingSimulator(bearing, superelement, simulator.SimulatorSettings(
        ring_model="flexible", load_frame="rotating", life=True, step_work="complete", contact_kernel="auto"))
    calls, recorded = {}, []
    with ExitStack() as stack:
        stack.enter_context(patched(owner, factory, recorder(kernel, calls)))
        for k in range(min(steps, case.steps)):
            calls["list"] = [] if k >= 50 and k % 10 == 5 else None
            sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
            recorded += [args for _, _, args in calls["list"] or ()]
    return recorded


def variant(kernel: str, flags: frozenset | None, revision: str | None, folder: Path):
    """``kernel``'s loop compiled from a copy of its module's source (this checkout's, or ``revision``'s)
    with ``FASTMATH = flags`` (None: the source's own)."""
    *_, module_name, function, signature = KERNELS[kernel]
    source = Path(importlib.util.find_spec(module_name).origin)
    text = source.read_text()
    if revision is not None:
        path = source.relative_to(ROOT).as_posix()
        text = subprocess.run(["git", "show", f"{revision}:{path}"], cwd=ROOT, check=True, capture_output=True,
                              text=True).stdout
    copy = folder / source.name
    copy.write_text(text)
    spec = importlib.util.spec_from_file_location(module_name.rsplit(".", 1)[0] + "._flags_variant", copy)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    if flags is not None:
        module.FASTMATH = flags
    return module._compile(getattr(module, function), getattr(module, signature)), sorted(module.FASTMATH)


def fresh(args: list) -> list:
    return [a.copy() if isinstance(a, np.ndarray) else a for a in args]


def difference(kernel: str, a, b) -> tuple[dict, bool]:
    """The largest difference of two answers' :data:`ANSWERS` relative to the answer's largest entry, and
    whether their integers (status, iterations, operator turned) agree."""
    compared, integers = ANSWERS[kernel]
    moved = {name: float(np.abs(a[i] - b[i]).max() / max(np.abs(b[i]).max(), 1e-300)) if b[i].size else 0.0
             for name, i in compared}
    return moved, all(a[i] == b[i] for i in integers)


def replay(calls: list, loops: dict, rounds: int) -> dict:
    """Each round: every call once with each loop, the order alternating; the rounds' sums, us."""
    totals = {label: [] for label in loops}
    labels = list(loops)
    for r in range(rounds):
        spent = dict.fromkeys(labels, 0.0)
        for j, args in enumerate(calls):
            for label in (labels if (r + j) % 2 == 0 else labels[::-1]):
                operands = fresh(args)
                start = time.perf_counter()
                loops[label](*operands)
                spent[label] += time.perf_counter() - start
        for label in labels:
            totals[label].append(1e6 * spent[label])
    return {label: np.asarray(v) for label, v in totals.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kernel", choices=sorted(KERNELS), default="distribution")
    parser.add_argument("--flags", nargs="*", choices=FLAGS, help="the variant's FASTMATH (none: --flags alone)")
    parser.add_argument("--revision", help="the variant's kernel source from this git revision")
    parser.add_argument("--scenario", default="nrel")
    parser.add_argument("--steps", type=int, default=550)
    parser.add_argument("--rounds", type=int, default=30)
    args = parser.parse_args()
    if aot_kernels() is not None:
        raise SystemExit("the loops compiled ahead of time are installed here: this compares numba's loops")
    if args.flags is None and args.revision is None:
        raise SystemExit("give the variant's --flags, its --revision or both")
    owner, factory, module_name, *_ = KERNELS[args.kernel]
    library = getattr(owner, factory)()
    calls = record(args.kernel, args.scenario, args.steps)
    own = sorted(importlib.import_module(module_name).FASTMATH)
    with tempfile.TemporaryDirectory() as folder:
        loop, flags = variant(args.kernel, None if args.flags is None else frozenset(args.flags), args.revision,
                              Path(folder))
        loops = {f"library {own}": library, f"variant {args.revision or 'this source'} {flags}": loop}
        worst, same = {}, 0
        for call in calls:
            one, other = (loop(*fresh(call)) for loop in loops.values())
            moved, agree = difference(args.kernel, other, one)
            worst = {name: max(value, worst.get(name, 0.0)) for name, value in moved.items()}
            same += agree
        for loop in loops.values():              # warm both before timing
            for call in calls[:5]:
                loop(*fresh(call))
        totals = replay(calls, loops, args.rounds)
    rows = []
    for label, t in totals.items():
        rows.append([label, f"{np.median(t):.0f}", f"{np.percentile(t, 10):.0f}", f"{np.percentile(t, 90):.0f}",
                     f"{np.median(t) / len(calls):.1f}"])
    lib, var = totals.values()
    ratio = var / lib
    rows.append(["variant / library, round by round", f"{np.median(ratio):.3f}", f"{np.percentile(ratio, 10):.3f}",
                 f"{np.percentile(ratio, 90):.3f}", ""])
    print_table(f"{args.kernel}'s one call, {len(calls)} calls of the {args.scenario} scenario replayed hot, "
                f"{args.rounds} rounds, us a round", ["loop", "median", "p10", "p90", "median a call"], rows)
    print("answers, largest difference of the variant's from the library's, relative to its largest entry: "
          + ", ".join(f"{name} {value:.1e}" for name, value in worst.items())
          + f"; status and iterations the same in {same} of {len(calls)} calls")


if __name__ == "__main__":
    main()
