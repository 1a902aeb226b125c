"""What a bounded step that was flagged answers, against the complete step at the same time.

A bounded step (``step_work`` = "bounded") that cannot reach the equilibrium within its work answers
with its last iterate, flagged by ``distribution.converged`` False (the FMU: ``equilibrium_residual``
above ``tolerance``). This runs the pitch bearing's five real-time scenarios (``realtime``)
through the library's simulator twice, bounded and complete, step by step side by side (flexible
rings, friction and life on), and compares the flagged steps' friction torque, largest ball load and
ring displacements (axial ``z``, tilt ``(rx, ry)``) with the complete steps': as answered (the iterate) and, for comparison, as the last equilibrium of
the bounded run would give them (held) and as a rigid-ring simulator stepped alongside gives them (the
cheap approximate answer such a step could give instead). Accuracy, not time: the figures do not depend
on the machine.

Run: .venv/bin/python -m benchmarks flagged [--scenarios reversal nrel ...]
"""
from __future__ import annotations

import numpy as np

from .realtime import SCENARIOS, scenario
from .suite import print_table


def flagged_errors(name: str) -> tuple[np.ndarray, dict]:
    """Per flagged step: (residual, friction torque error of the iterate, of the held equilibrium,
    largest ball load error of the iterate, of the held equilibrium, friction torque error of the rigid
    rings, largest ball load error of the rigid rings, axial displacement error of the iterate, its tilt
    error), relative to the complete step (the tilt's: the norm of the difference of ``(rx, ry)`` over
    the complete step's); and the flexible runs' life damage at the end."""
    from slewing_model import Loads, load_bearing
    from slewing_model.rings.superelement import build_superelement
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    case = scenario(name)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="fine", progress=False)
    sims = {work: BearingSimulator(bearing, superelement, SimulatorSettings(
        ring_model="flexible", load_frame="rotating", life=True, step_work=work)) for work in ("complete", "bounded")}
    sims["rigid"] = BearingSimulator(bearing, None, SimulatorSettings(ring_model="rigid", load_frame="rotating",
                                                                      life=False))
    held, rows = None, []
    for k in range(case.steps):
        out = {work: sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
               for work, sim in sims.items()}
        bounded, complete = out["bounded"], out["complete"]
        if bounded.distribution.converged:
            held = bounded
            continue
        torque = complete.friction_torque_magnitude
        peak = complete.distribution.contact_load.max()

        def errors(answer):          # of the friction torque and of the largest ball load
            if answer is None:
                return np.nan, np.nan
            return answer.friction_torque_magnitude / torque - 1.0, answer.distribution.contact_load.max() / peak - 1.0

        (torque_iterate, peak_iterate), (torque_held, peak_held), (torque_rigid, peak_rigid) = map(
            errors, (bounded, held, out["rigid"]))
        moved, reached = bounded.distribution.displacement, complete.distribution.displacement
        axial = moved[2] / reached[2] - 1.0
        tilt = float(np.linalg.norm(moved[3:5] - reached[3:5]) / np.linalg.norm(reached[3:5]))
        rows.append((bounded.distribution.residual, torque_iterate, torque_held, peak_iterate, peak_held,
                     torque_rigid, peak_rigid, axial, tilt))
    damage = {work: sims[work].life.worst_damage for work in ("complete", "bounded")}
    return np.array(rows).reshape(-1, 9), damage


def _spread(errors: np.ndarray) -> str:
    errors = np.abs(errors[np.isfinite(errors)])
    if not errors.size:
        return "–"
    return f"{np.median(errors):.3g} / {np.percentile(errors, 90):.3g} / {errors.max():.3g}"


def add_arguments(parser) -> None:
    parser.add_argument("--scenarios", nargs="*", default=list(SCENARIOS), choices=SCENARIOS)


def main(args) -> None:
    rows = []
    for name in args.scenarios:
        errors, damage = flagged_errors(name)
        residual = f"{np.median(errors[:, 0]):.1e} / {errors[:, 0].max():.1e}" if errors.size else "–"
        rows.append([name, str(len(errors)), residual, _spread(errors[:, 1]), _spread(errors[:, 2]),
                     _spread(errors[:, 3]), _spread(errors[:, 4]), _spread(errors[:, 5]), _spread(errors[:, 6]),
                     _spread(errors[:, 7]), _spread(errors[:, 8]),
                     f"{damage['bounded'] / damage['complete']:.4f}" if damage["complete"] > 0 else "–"])
    print_table("Flagged bounded steps against the complete steps (pitch bearing, library); errors relative, "
                "median / 90th percentile / largest",
                ["scenario", "flagged steps", "residual (median / largest)", "friction torque: iterate",
                 "friction torque: last equilibrium", "largest ball load: iterate", "largest ball load: last equilibrium",
                 "friction torque: rigid rings", "largest ball load: rigid rings", "axial displacement: iterate",
                 "tilt: iterate",
                 "life damage, bounded / complete"], rows)

