"""Could an inner iteration stand in for a new ring operator? (issue 31: the mean step and the whole turbine)

A third of NREL's steps do operator work, because the contact springs change as the loads do and
the kept ``W^-1`` (of ``W = (A^-1 + M)_aa`` at an earlier iterate) then converges too slowly
(docs/speed.md, "Issue 31, sixteenth turn"). This measures, at each new operator a complete NREL run
starts, how well the kept inverse would precondition the current ``W_p = (A_p^-1 + M)_aa`` on the
kept rows (the diagonals loaded now take their springs at the iterate, those that opened keep theirs,
as in the solver): the contraction of the modified Newton step, ``rho(I - W^-1 W_p)``, and the
conjugate-gradient iterations on ``W_p x = b`` (``b`` a fixed random vector) to relative residuals
1e-6 and 1e-9, preconditioned by ``W^-1`` alone and by ``W^-1`` corrected exactly (Woodbury) for the
diagonals whose compliance block changed by more than ``--outlier`` of its size. Each iteration
is a product with ``W^-1`` and one with ``W_p`` (about 20 + 30 us on the pitch bearing).

A measurement for the next design, not a model: nothing in ``slewing_model`` uses it.

Run: .venv/bin/python benchmarks/bench_inner_solve.py [--steps 400] [--outlier 0.3]   (about 1 min)
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.linalg import block_diag
from scipy.sparse.linalg import cg

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_realtime import scenario  # noqa: E402
from timing import print_table  # noqa: E402

from slewing_model import Loads, load_bearing  # noqa: E402
from slewing_model.distribution import bime  # noqa: E402
from slewing_model.rings.reduced_operator import contact_compliance_blocks  # noqa: E402
from slewing_model.rings.superelement import build_superelement  # noqa: E402
from slewing_model.simulation import simulator  # noqa: E402


def block_diagonal(blocks: np.ndarray) -> np.ndarray:
    """The (2k, 2k) matrix of k (2, 2) blocks."""
    return block_diag(*blocks)


def conjugate_gradients(matrix: np.ndarray, preconditioner: np.ndarray, b: np.ndarray, tol: float,
                        limit: int = 200) -> int:
    """Iterations of scipy's preconditioned conjugate gradients on ``matrix x = b`` to ``|r| <= tol |b|``
    (``limit + 1`` where they do not get there)."""
    count = [0]

    def counted(_):
        count[0] += 1

    _, info = cg(matrix, b, rtol=tol, atol=0.0, maxiter=limit, M=preconditioner, callback=counted)
    return count[0] if info == 0 else limit + 1


def current_blocks(op, point, stiffness) -> np.ndarray:
    """``A^-1`` of the operator's diagonals at ``point``: the loaded ones' springs now, the others as kept."""
    diagonals = op.rows[::2] // 2
    blocks = op.contact_compliance.copy()
    loaded = point.loaded[diagonals]
    if loaded.any():
        mask = np.zeros(point.loaded.size, dtype=bool)
        mask[diagonals[loaded]] = True
        by_diagonal = contact_compliance_blocks(point, stiffness, mask)       # in the diagonals' order
        placed = np.empty_like(by_diagonal)
        placed[np.argsort(diagonals[loaded])] = by_diagonal
        blocks[loaded] = placed
    return blocks


def measure(op, point, solver, outlier: float) -> dict:
    """The figures of one renewal (see the module's docstring)."""
    blocks = current_blocks(op, point, solver.assembly.stiffness)
    ring = solver.compliance.entries(op.rows, op.rows)
    w_now = block_diagonal(blocks) + ring
    kept = op.inverse.astype(float)
    size = op.rows.size
    change = (np.abs(blocks - op.contact_compliance).max(axis=(1, 2))
              / np.abs(op.contact_compliance).max(axis=(1, 2)))
    b = np.random.default_rng(0).standard_normal(size)
    changed = np.flatnonzero(change > outlier)
    corrected = kept
    if changed.size:                    # Woodbury: (W + E D E^T)^-1 = W^-1 - W^-1 E (D^-1 + E^T W^-1 E)^-1 E^T W^-1
        index = np.concatenate([2 * changed, 2 * changed + 1])
        difference = (block_diagonal(blocks) - block_diagonal(op.contact_compliance))[np.ix_(index, index)]
        columns = kept[:, index]
        corrected = kept - columns @ np.linalg.solve(np.linalg.inv(difference) + kept[np.ix_(index, index)],
                                                     columns.T)
    return {"rows": size, "check": float(np.abs(kept @ (block_diagonal(op.contact_compliance) + ring)
                                             - np.eye(size)).max()),
            "rho": float(np.abs(np.linalg.eigvals(np.eye(size) - kept @ w_now)).max()),
            "cg6": conjugate_gradients(w_now, kept, b, 1e-6), "cg9": conjugate_gradients(w_now, kept, b, 1e-9),
            "changed": int(changed.size), "wcg6": conjugate_gradients(w_now, corrected, b, 1e-6),
            "wcg9": conjugate_gradients(w_now, corrected, b, 1e-9), "median_change": float(np.median(change))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=400, help="NREL steps (complete, after the start values)")
    parser.add_argument("--outlier", type=float, default=0.3,
                        help="a diagonal whose compliance changed by more than this share is corrected exactly")
    args = parser.parse_args()
    case = scenario("nrel")
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="fine", progress=False)
    sim = simulator.BearingSimulator(bearing, superelement, simulator.SimulatorSettings(
        ring_model="flexible", load_frame="rotating", life=True, step_work="complete", contact_kernel="auto"))
    sim.step(Loads(), 0.0, 0.0)                     # the start values
    found, step = [], [0]
    original = bime.BimeSolver._start_operator

    def spied(solver, point, *rest, **options):
        if solver._reduced is not None and step[0] > 5:          # after the first steps' load ramp
            found.append(measure(solver._reduced, point, solver, args.outlier))
        return original(solver, point, *rest, **options)

    bime.BimeSolver._start_operator = spied
    try:
        for k in range(args.steps):
            step[0] = k
            sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
    finally:
        bime.BimeSolver._start_operator = original

    def spread(key, fmt="{:.0f}"):
        values = np.array([f[key] for f in found], dtype=float)
        return [fmt.format(np.median(values)), fmt.format(np.percentile(values, 90)), fmt.format(values.max())]

    rows = [["rows of the kept operator"] + spread("rows"),
            ["|W^-1 W - I| of the kept inverse (single precision)"] + spread("check", "{:.1e}"),
            ["median relative change of a compliance block"] + spread("median_change", "{:.3f}"),
            ["rho(I - W^-1 W_p): the modified Newton step's contraction"] + spread("rho", "{:.2f}"),
            ["CG preconditioned by W^-1: iterations to 1e-6"] + spread("cg6"),
            ["... to 1e-9"] + spread("cg9"),
            [f"diagonals changed by more than {args.outlier:g}"] + spread("changed"),
            ["CG by W^-1 corrected for those (Woodbury): to 1e-6"] + spread("wcg6"),
            ["... to 1e-9"] + spread("wcg9")]
    print_table(f"NREL, complete, {args.steps} steps: {len(found)} new operators after step 5",
                ["at each new operator", "median", "p90", "largest"], rows)


if __name__ == "__main__":
    main()
