"""BIME: load distribution by minimum total potential energy (paper eqs 1, 16, 20, 23).

Unknowns
    ``q = (X, Y, Z, rx, ry)``: the moving ring's rigid-body displacement
    (paper eq 23, small rotations), and for flexible rings the groove-centre
    displacements ``D_out``, ``D_in`` of both rings (eqs 3, 14).

Energy (eq 20)
    ``U = sum_b sum_diag 2/5 K_tot delta_tot^(5/2)  +  1/2 D^T K_ring D  -  F . q``
    with ``delta_tot = |e| - l_N`` the elongation of the spring between the two
    groove centres of a diagonal (eqs 6-7), traction only, and
    ``e = O_in - O_out`` the vector between them.

Solver
    Newton's method with the analytic gradient and Hessian and a backtracking
    line search on ``U`` (it is convex: a convex increasing function of the
    lengths ``|e|``, which are convex in the unknowns, plus a quadratic).

    For flexible rings the rings are linear, so their displacements are
    eliminated exactly in every Newton step: with ``G`` the compliance of each
    ring at its groove centres (the pseudo-inverse of the superelement matrix,
    block-circulant) and ``M = P_in G_in P_in^T + P_out G_out P_out^T`` the
    combined compliance seen by the contacts, the Newton system reduces to the
    *active* contacts only:

    ``[(A^-1 + M)_aa  -S J_a] [y_a]   [A_a^-1 f_a + (M y)_a]``
    ``[-S J_a^T          0  ] [dq ] = [-F                  ]``

    where ``A`` are the 2x2 contact stiffness blocks, ``f`` the contact forces
    and ``y`` the contact forces after the step (``D_in = -G_in P_in^T y``,
    ``D_out = G_out P_out^T y``). Its size is twice the number of loaded
    diagonals instead of ``5 + 8B``; rigid rings are the case ``M = 0``, where
    it collapses to the 5x5 system ``(sum J^T A J) dq = -grad``.

Stopping rule
    Force and moment residuals on the moving ring below ``rtol`` times the load
    scale ``max(|F|, |M|/(dm/2), max contact load)``, and, for flexible
    rings, the contact forces felt by the rings equal the Hertz forces to the
    same tolerance.

Where the pieces live
    :mod:`slewing_model.distribution` (the loads and the result),
    :mod:`slewing_model.rings.compliance` (``G`` and ``M`` from the superelements),
    :mod:`slewing_model.rings.reduced_operator` (the reduced Newton operator, kept between
    iterations and steps and updated when contacts open or close); this module holds the
    energy, its derivatives and the Newton iteration.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .assembly import Assembly, INNER_SLOT, OUTER_SLOT, assemble
from ..bearing.contact import ISO76_PRESSURE_LIMIT, contact_deflection, hertz_ellipse
from .kernel import (
    COMPILED_ARITHMETIC, WARM_CONVERGED, WARM_FAR, WARM_STOPPED, compiled_contact_results, compiled_jacobian,
    compiled_kept_iterations, compiled_rigid_solve, compiled_ring_times, compiled_trial_point, compiled_warm_solve,
    contact_tables, product_inverses,
)
from .results import (  # noqa: F401  (Loads, LoadDistribution and the errors belong to this interface)
    DISPLACEMENT_FIELDS, LOAD_FIELDS, LoadCapacityError, LoadDistribution, Loads, NoEquilibriumError,
)
from ..numerics.blas import blas_threads
from ..numerics.compiled import use_compiled
from ..bearing.geometry import RING_CONTACTS, Bearing
from ..rings.reduced_operator import (
    APPROXIMATE_TURN, NUMPY_ARITHMETIC, SPREAD_STAGES, STAGES, PendingOperator, ReducedOperator, advance_operator,
    bordering_work, borders, forming_work, off_rows, stage_work, start_operator, step_end,
    turned_operator, update_operator,
)
from ..rings.compliance import contact_compliance, product_operands, ring_compliances, ring_selector  # noqa: F401

#: the flexible solver refreshes its reduced Newton operator when an iteration reduced the
#: residual by less than this factor (with a new operator spread over two steps, 0.4 measures better
#: than 0.25: pitch mean -3 %, yaw 95th percentile -35 %)
REFRESH = 0.4
#: ... unless, at the rate of that iteration, the residual reaches the tolerance within this many
#: more iterations, which cost less than a new operator (pitch bearing: 3 of 0.1 ms against
#: one operator of 2.5 ms)
FINISH_ITERATIONS = 3
#: in a warm solve a new operator is inverted over this solve and the next (a bounded one: as its work
#: allows, BOUNDED_WORK), while the solver goes on
#: with the one it has (:class:`slewing_model.rings.reduced_operator.PendingOperator`); all at once when an
#: iteration past this many in one solve is still slow
SPREAD_ITERATIONS = 8
#: what a bounded warm solve (``step_work="bounded"``) may spend of work: the ring operator's, and at
#: least one piece of it (forming ``W``, a stage of its inverse on its way, a bordering), whatever else
#: it spent; and its Newton iterations' (:data:`ITERATION_WEIGHT`): once
#: it has done operator work it starts an iteration only where the work left covers it. Floating-point
#: operations weighted so that they track time, some 55 million a millisecond on one core here (the
#: stages of a spread inverse of ``W = (A^-1 + M)_aa``:
#: :func:`~slewing_model.rings.reduced_operator.stage_work`; forming ``W``:
#: :func:`~slewing_model.rings.reduced_operator.forming_work`;
#: bordering: :func:`~slewing_model.rings.reduced_operator.bordering_work`). Work, not time, so that a
#: step's answer does not depend on the machine. 1e8, about 1.8 ms, chosen by the pitch bearing's
#: scenarios of the ``realtime`` benchmark (``python -m benchmarks realtime``; the library's solves, caps
#: side by side in one run): against 1.1e8, two runs, the slowest steps of the reversal, the jump, the
#: feather and the turbulence 3.3-3.6 NREL medians instead of 3.6-4.7, none of them over 4 instead of 0-7
#: a scenario; NREL's flagged steps 61 of 6000 instead of 36, the reversal's 51 of 2000 instead of 44
#: (9e7: 198 and 65)
BOUNDED_WORK = 1e8
#: a bounded solve's one piece of operator work (:meth:`BimeSolver._take`), where it is a bordering, borders
#: the contacts that closed whose work is at most this, or the work left if more (that a run of bounded solves
#: gets on; :meth:`BimeSolver._bordering_that_fits`): what a step has after a held-rings start (HELD_WORK)
BORDER_PIECE = 5e7
#: ... and Newton iterations (each a product with ``W^-1`` and a line search: 0.05-0.2 ms on the
#: pitch bearing); what is left is carried over to the next solve
BOUNDED_ITERATIONS = 12
#: a warm start whose relative residual is above this (the loads jumped) tries the moving ring's
#: equilibrium with the rings held (BimeSolver._held_rings_start); steps of slowly varying loads
#: start at 1e-3-1e-2, a reversal at 2, NREL's first step from zero loads at 1, a load 1.5 times
#: the last at 0.33
HELD_START = 0.5
#: a Newton step's longest move of the moving ring, in ball diameters (a step across a clearance is
#: limited, then checked by the energy)
TRUST_LENGTH = 0.02
#: the Newton steps' damping ``mu``, relative to the springs' reference stiffness (``mu I`` keeps the
#: moving ring's equations regular where no contact holds a direction)
DAMPING = 1e-12
#: the relative tolerance of the rigid solves that start a flexible one (the cold start's, the held-rings start's)
RIGID_START_TOLERANCE = 1e-6
#: ... and kept where more than this share of the diagonals it loads were open at the start
HELD_NEW_CONTACTS = 0.25
#: the held-rings start's rigid solve counts as this much of a bounded solve's BOUNDED_WORK (about 0.9 ms,
#: half a step's operator work, on the pitch bearing). Compiled (kernel._rigid_solve) it takes 0.15 ms, but
#: a step that tries it is a step after a jump, whose Newton iterations and friction's cold balls cost more
#: too: charged by its time alone (1e7), the reversal's bounded run flags 41 steps instead of 54, but 8-17 of
#: its steps take more than 4.2 ms instead of 2-5, the slowest 5.1-5.2 ms against 4.5-4.7, and its first step
#: from the start values 5.4-5.5 ms against 4.1-4.6 (three runs)
HELD_WORK = 5e7
#: a bounded solve's Newton iterations count against BOUNDED_WORK too, each (BimeSolver._iteration_work)
#: its product with the operator's inverse, ``2 n^2`` for ``n`` rows, times the first, and its trial point and
#: ring products, the second times the balls: 2.9e6 for the pitch bearing's kept operator (368 rows, 150
#: balls), whose iterations take 44.8 us each in a step with the kept inverse in single precision (55 us
#: in double; ``python -m benchmarks step_parts``). A product factor of 2.9 instead of 5.0 makes no clear
#: difference side by side, so it stays
ITERATION_WEIGHT = (5.0, 1.1e4)
STEP_WORK = ("complete", "bounded")
#: a warm solve with a kept operator and no stage of a new one due (a co-simulation's usual step) runs its
#: compiled loops in one call (BimeSolver._warm_solve): the same loops in the same order, the same numbers;
#: False runs them one by one from Python, as a solve that hands back does (a test compares the two)
WARM_CALL = True
#: what :meth:`BimeSolver.set_rotation` sets: a solver at the same rotation may take them (BimeSolver._rigid_solver)
ROTATION_ARRAYS = ("assembly", "_moving_centre", "_separation", "reference_stiffness", "jacobian", "_jacobian_rows")
#: the ring of contacts 1..4
CONTACT_RING = np.array(["outer" if c in RING_CONTACTS["outer"] else "inner" for c in (1, 2, 3, 4)])
INNER_CONTACT = CONTACT_RING == "inner"


class BimeSolver:
    """Rigid- or Flexible-BIME solver for one bearing at one rotation ``psi``.

    Keep one solver for a sequence of solves (warm starts, FMU steps); use
    :func:`solve` for a single case.

    Parameters
    ----------
    bearing : Bearing
        The bearing definition (with its errors and preload).
    superelement : Superelement, optional
        Both rings' condensed stiffness (:mod:`slewing_model.rings.stiffness`);
        None (default) for rigid rings.
    psi : float, optional
        Rotation of the moving ring, rad. Default 0.
    cage_angle : float, optional
        Rotation of the ball set, rad; default (None): rolling without slip from ``psi``.
    rtol : float, optional
        Relative tolerance of the stopping rule (force residual relative to the load
        scale). Default 1e-10.
    max_iterations : int, optional
        Most Newton iterations of a complete solve. Default 200.
    pressure_limit : float, optional
        Loads whose largest Hertz pressure exceeds this, Pa, are refused
        (:class:`LoadCapacityError`). Default ``2 x 4200 MPa``: twice the ISO 76
        permanent-deformation limit (static safety factor 0.125), gross plastic
        deformation where the elastic Hertz model no longer holds.
    kernel : {"numpy", "auto", "compiled"}, optional
        How the solver's per-contact work is done: numpy array operations, or compiled
        loops (:mod:`slewing_model.distribution.kernel`, needs numba), which also run the
        flexible solver's iterations in one loop, with the ring compliance's product by a
        real DFT; "auto" takes the compiled loops where numba is installed. The same
        iterations, and results to round-off. Default "numpy": a few solves do not repay
        numba's import (0.5 s); the co-simulation's simulator takes "auto"
        (``SimulatorSettings.contact_kernel``).
    step_work : {"complete", "bounded"}, optional
        How much a warm solve may do. "complete" (default): Newton to ``rtol``, however
        many iterations and ring operator inversions that takes. "bounded" (real time): at
        most 12 Newton iterations and 1e8 of work (``BOUNDED_ITERATIONS``, ``BOUNDED_WORK``:
        floating-point operations weighted to track time, about 1.8 ms on one core), the
        operator's and the iterations' (a new operator's inverse spread over as many solves
        as that takes);
        a solve that would need more returns its last iterate with ``converged=False`` and
        its ``residual``, keeps its operator (and one being inverted), and the next warm
        solve goes on from there. A cold solve (no ``initial``) is always complete.
    blas_threads : int or None, optional
        Threads of numpy's BLAS while the solver iterates
        (:func:`slewing_model.numerics.blas.blas_threads`, restored after; the ring
        operator's inversions are its BLAS work); None (default) leaves them as the
        process has them.

    Raises
    ------
    ValueError
        If ``step_work`` is unknown or the superelement was built for another ball count.

    Examples
    --------
    >>> from slewing_model import BimeSolver, Loads, load_bearing
    >>> solver = BimeSolver(load_bearing("examples/bearings/table1.toml"))
    >>> first = solver.solve(Loads(Fz=500e3))
    >>> solver.set_rotation(0.01)
    >>> second = solver.solve(Loads(Fz=510e3), initial=first)
    >>> second.contact_load.shape
    (100, 4)
    """

    def __init__(self, bearing: Bearing, superelement=None, *, psi: float = 0.0, cage_angle: float | None = None,
                 rtol: float = 1e-10, max_iterations: int = 200, pressure_limit: float = 2.0 * ISO76_PRESSURE_LIMIT,
                 kernel: str = "numpy", step_work: str = "complete", blas_threads: int | None = None):
        if step_work not in STEP_WORK:
            raise ValueError(f"step_work = {step_work!r}: must be one of {', '.join(map(repr, STEP_WORK))}")
        if superelement is not None and superelement.outer.ball_count != bearing.ball_count:
            raise ValueError(f"superelement has {superelement.outer.ball_count} balls, "
                             f"the bearing ball_count = {bearing.ball_count}")
        self.bearing = bearing
        self.superelement = superelement
        self.model = "rigid" if superelement is None else "flexible"
        self.rtol = rtol
        self.max_iterations = max_iterations
        self.pressure_limit = pressure_limit
        self.kernel = kernel
        self.step_work = step_work
        self.blas_threads = blas_threads
        self._work_left = math.inf   # per solve: the work still allowed (BOUNDED_WORK: the operator's, the iterations')
        self._operator_work_done = False   # per solve: a piece of operator work done (_advance, _spend)
        self._compiled = use_compiled(kernel, "kernel")    # the per-contact work as compiled loops
        self._arithmetic = COMPILED_ARITHMETIC if self._compiled else NUMPY_ARITHMETIC     # the operator's too
        self.length = bearing.pitch_diameter / 2.0  # scale of rotations in the unknowns
        self.ring_compliance = None if superelement is None else ring_compliances(superelement)
        self.compliance = None if superelement is None else contact_compliance(self.ring_compliance)
        # M's product in the compiled iterations (contact_kernel._kept_iterations)
        self._product_operands = None
        if self._compiled and superelement is not None:
            self._product_operands = product_operands(self.compliance)
        # groove edge angles of contacts 1..4 (truncation check)
        self.edge_angle = np.array([bearing.groove_edge_angle(c) for c in (1, 2, 3, 4)])
        self._loaded_from = 1e-15 * bearing.ball_diameter     # a spring stretched more than this is loaded
        self._reduced = None  # reduced Newton operator kept between iterations and solves (flexible)
        self._reduced_jacobian = None  # the Jacobian (its array) the kept operator's coupling was formed for
        #: a new ring operator being inverted over several warm solves (flexible rings), or None;
        #: part of a co-simulation's state
        self.pending_operator: PendingOperator | None = None
        # a turn of the ring only turns the Jacobian's columns where the moving ring's grooves have no
        # errors; with errors, nearly (reduced_operator.APPROXIMATE_TURN)
        rigid_turn = bearing.errors is None or getattr(bearing.errors, bearing.moving_ring) is None
        self._turn_tolerance = 0.0 if rigid_turn else APPROXIMATE_TURN
        self._stage_due = self._spread = False  # per solve: a stage of the pending operator is due; it may be spread
        self.assembly: Assembly | None = None
        self._rigid: BimeSolver | None = None   # the rigid-ring solver of the starting guesses (_rigid_solver)
        self.set_rotation(psi, cage_angle)

    @property
    def operator(self):
        """The reduced Newton operator kept between solves (flexible rings; None before the first
        solve, :mod:`slewing_model.rings.reduced_operator`): part of a co-simulation's state.
        Settable (to restore a state)."""
        return self._reduced

    @operator.setter
    def operator(self, op) -> None:
        self._reduced, self._reduced_jacobian = op, None     # its coupling is checked against the Jacobian

    # ---- set-up -------------------------------------------------------------------
    def set_rotation(self, psi: float, cage_angle: float | None = None) -> None:
        """Re-assemble at another rotation of the moving ring.

        The manufacturing errors move with the rings; the ring matrices do not change
        (the rings are axisymmetric).

        Parameters
        ----------
        psi : float
            Rotation of the moving ring, rad.
        cage_angle : float, optional
            Rotation of the ball set, rad; default (None): rolling without slip from ``psi``.
        """
        previous = self.assembly
        self.assembly = a = assemble(self.bearing, psi, cage_angle, previous=previous, compiled=self._compiled)
        if previous is None or a.groove_centre is not previous.groove_centre:   # other grooves under the balls
            self._moving_centre = a.moving_centre
            self._separation = a.separation                    # e before loading, (B, 2, 2)
        if previous is None or a.stiffness is not previous.stiffness:           # other springs
            k_mean = float(a.stiffness.mean())
            self.reference_stiffness = a.stiffness.size * k_mean * math.sqrt(1e-4 * self.bearing.ball_diameter)
        if self._compiled:                     # the same formulas, one compiled loop (contact_kernel)
            self.jacobian = compiled_jacobian()(a.ball_angle, self._moving_centre, self.length, a.moving_sign)
        else:
            phi = a.ball_angle[:, None]
            r, z = self._moving_centre[..., 0], self._moving_centre[..., 1]
            c, s = np.cos(phi), np.sin(phi)
            L = self.length
            # d(R, z of the moving groove centre)/d(X, Y, Z, L rx, L ry), eq 23: (B, 2 diag, 2 comp, 5)
            jac = np.zeros(r.shape + (2, 5))
            jac[:, :, 0, 0], jac[:, :, 0, 1] = c, s                              # R
            jac[:, :, 0, 3], jac[:, :, 0, 4] = -z * s / L, z * c / L
            jac[:, :, 1, 2] = 1.0                                                # z
            jac[:, :, 1, 3], jac[:, :, 1, 4] = r * s / L, -r * c / L
            self.jacobian = a.moving_sign * jac
        self._jacobian_rows = self.jacobian.reshape(-1, 5)     # (4B, 5): one matrix-vector product

    def scaled_load(self, loads: Loads) -> np.ndarray:
        """The loads as the solver's unknowns take them.

        Parameters
        ----------
        loads : Loads
            External load on the moving ring.

        Returns
        -------
        ndarray, shape (5,)
            ``(Fx, Fy, Fz, Mx / L, My / L)``, N, with ``L`` the solver's length scale
            (:attr:`length`, the pitch radius, m); a new array.
        """
        f = loads.as_array()
        f[3:] /= self.length
        return f

    # ---- energy -------------------------------------------------------------------
    def _contacts(self, e: np.ndarray, hessian: bool = True):
        """Spring terms for relative vectors ``e`` (B, 2, 2): elongation, force
        vectors dPhi/de, contact energy and (if asked) the 2x2 Hessian blocks."""
        a = self.assembly
        length = np.sqrt(e[..., 0] ** 2 + e[..., 1] ** 2)
        n = e / length[..., None]
        delta = length - a.natural_length                                   # eq 7
        dpos = np.maximum(delta, 0.0)
        q = a.stiffness * (dpos * np.sqrt(dpos))                            # eq 8
        energy = 0.4 * float(np.vdot(q, dpos))                              # eq 1: 2/5 K delta^(5/2)
        force = q[..., None] * n
        if not hessian:
            return delta, q, force, energy, None, n, length
        k_normal = 1.5 * a.stiffness * np.sqrt(dpos)
        nn = n[..., :, None] * n[..., None, :]
        eye = np.eye(2)
        hess = k_normal[..., None, None] * nn + (q / length)[..., None, None] * (eye - nn)
        return delta, q, force, energy, hess, n, length

    def energy_terms(self, x: np.ndarray, loads: Loads | None = None):
        """Total potential energy (eq 20), its gradient and Hessian in the
        paper's unknowns, SI units.

        Parameters
        ----------
        x : ndarray (5,) for rigid rings, (5 + 8B,) for flexible rings
            ``(X, Y, Z, rx, ry)``, then ``D_out`` and ``D_in`` (4B each, ordered
            as paper eq 14: per ball ``R, z`` of the ring's two groove centres); m and rad.
        loads : Loads, optional
            External load on the moving ring; None: no load.

        Returns
        -------
        energy : float
            Total potential energy, J.
        gradient : ndarray like ``x``
            Its derivative by ``x``: N for lengths, N m for angles.
        hessian : ndarray (len(x), len(x))
            Its second derivative by ``x`` (N/m, N, N m by pairs of unknowns).
        """
        loads = Loads() if loads is None else loads
        n = self.bearing.ball_count
        f_ext = loads.as_array()
        scale = np.array([1.0, 1.0, 1.0, self.length, self.length])
        jac = self.jacobian * scale  # d e / d(X, Y, Z, rx, ry), physical units
        q = np.asarray(x[:5], float)
        e = self.assembly.separation + jac @ q
        flexible = self.superelement is not None
        if flexible:
            d_out, d_in = np.asarray(x[5:5 + 4 * n]), np.asarray(x[5 + 4 * n:])
            # relative vector of diagonal k: + inner groove centre - outer groove centre
            p_out = ring_selector(n, OUTER_SLOT)
            p_in = ring_selector(n, INNER_SLOT)
            e = e + (p_in @ d_in - p_out @ d_out).reshape(e.shape)
            jac_full = np.concatenate([jac.reshape(-1, 5), -p_out, p_in], axis=1)
        else:
            jac_full = jac.reshape(-1, 5)
        _, _, force, energy, hess, _, _ = self._contacts(e)
        grad = jac_full.T @ force.ravel()
        blocks = np.zeros((force.size, force.size))
        for i in range(force.size // 2):
            blocks[2 * i:2 * i + 2, 2 * i:2 * i + 2] = hess.reshape(-1, 2, 2)[i]
        hessian = jac_full.T @ blocks @ jac_full
        grad[:5] -= f_ext
        energy -= float(f_ext @ q)
        if flexible:
            k_out, k_in = self.superelement.outer.dense(), self.superelement.inner.dense()
            energy += 0.5 * float(d_out @ k_out @ d_out + d_in @ k_in @ d_in)   # eq 15
            grad[5:5 + 4 * n] += k_out @ d_out
            grad[5 + 4 * n:] += k_in @ d_in
            hessian[5:5 + 4 * n, 5:5 + 4 * n] += k_out
            hessian[5 + 4 * n:, 5 + 4 * n:] += k_in
        return energy, grad, hessian

    def potential_energy(self, x: np.ndarray, loads: Loads | None = None) -> float:
        """Total potential energy (eq 20) of the rigid model, energy only.

        For comparisons with derivative-free minimisers.

        Parameters
        ----------
        x : ndarray, shape (5,)
            ``(X, Y, Z, rx, ry)`` of the moving ring, m and rad.
        loads : Loads, optional
            External load on the moving ring; None: no load.

        Returns
        -------
        float
            The energy, J.
        """
        loads = Loads() if loads is None else loads
        x = np.asarray(x, dtype=float)
        e = self.assembly.separation + self.jacobian @ (x * [1.0, 1.0, 1.0, self.length, self.length])
        return self._contacts(e, hessian=False)[3] - float(loads.as_array() @ x)

    # ---- solve --------------------------------------------------------------------
    def solve(self, loads: Loads | None = None, initial: "LoadDistribution | np.ndarray | None" = None
              ) -> LoadDistribution:
        """Equilibrium under ``loads``.

        Parameters
        ----------
        loads : Loads, optional
            None: idling (preload and errors only).
        initial : LoadDistribution or ndarray, optional
            Warm start: a previous result of this solver (or its ``state``).

        Returns
        -------
        LoadDistribution
            Ball loads, contact angles, ring displacement and solver figures.

        Raises
        ------
        NoEquilibriumError
            The load has no equilibrium within the bearing (a direction no
            contact resists, or no convergence).
        LoadCapacityError
            A contact point would leave the raceway (contact angle past the
            groove edge): the load is beyond what the bearing can carry.
        """
        loads = Loads() if loads is None else loads
        f_scaled = self.scaled_load(loads)
        flexible = self.compliance is not None
        n_balls = self.bearing.ball_count
        dw = self.bearing.ball_diameter

        qs = np.zeros(5)
        y = np.zeros(4 * n_balls) if flexible else np.zeros(0)
        if initial is not None:
            state = initial.state if isinstance(initial, LoadDistribution) else np.asarray(initial, float)
            qs = state[:5].copy()
            if flexible and state.size == 5 + 4 * n_balls:
                y = state[5:].copy()
        elif flexible:
            # start from the rigid solution: the rings feel its contact forces
            rigid = self._rigid_solver()
            qs = rigid.solve(loads).state[:5].copy()
            y = rigid._evaluate(qs, y, f_scaled).force.ravel()

        trust = TRUST_LENGTH * dw
        mu = DAMPING * self.reference_stiffness
        iterations = 0
        bounded = self.step_work == "bounded" and initial is not None
        self._work_left = BOUNDED_WORK if bounded else math.inf
        self._operator_work_done = False
        limit = min(self.max_iterations, BOUNDED_ITERATIONS) if bounded else self.max_iterations
        last_residual = None if initial is None else math.inf  # a warm start may reuse the last operator
        self._stage_due = self._spread = initial is not None    # a new operator's inverse may be spread over steps
        if initial is None:
            self.pending_operator = None                  # a cold solve depends on nothing before it
        load_scale = max(map(abs, f_scaled.tolist()))
        if not flexible and self._compiled:
            # the rigid model's iterations in one compiled loop; where it stops short, the loop below runs them
            # again from the start and answers, or raises, as it always did
            still = np.zeros(4 * n_balls)
            found = self._compiled_rigid_solve(qs, still, still, f_scaled, load_scale, self.rtol, limit)
            if found is not None:
                qs, done, e, delta, q, (total, peak_force, peak_residual) = found
                end = _Point(qs, y, e, delta, q, None, None, None, None, total, None, None, None, peak_force,
                             peak_residual, None, None)               # what _result reads of it
                return self._result(loads, end, done, peak_residual / max(load_scale, peak_force, 1e-300))
        handed_back = False                               # the compiled loop stopped before this iteration
        point, held = None, flexible and initial is not None
        if (WARM_CALL and held and self._reduced is not None and self._product_operands is not None
                and self.pending_operator is None):
            # the usual step (a kept operator, no stage due): its loops in one compiled call, as far as they go
            point, iterations, last_residual, handed_back, held, contacts = self._warm_solve(
                qs, y, f_scaled, load_scale, mu, trust, limit, bounded)
            if contacts is not None:                      # at the equilibrium
                residual = point.peak_residual / max(load_scale, point.peak_force, 1e-300)
                return self._result(loads, point, iterations, residual, contacts=contacts)
        # the iterations beyond the usual step's compiled call: the operator's work runs numpy's BLAS on
        # blas_threads threads (the usual step uses none: its context's three calls to OpenBLAS cost
        # about 20 us of it)
        with blas_threads(self.blas_threads):
            if point is None:
                point = self._evaluate(qs, y, f_scaled)
            if held and point.any_loaded:
                point = self._held_rings_start(point, loads, f_scaled, load_scale)
            while True:
                grad_q, mismatch = point.gradient, point.mismatch
                scale = max(load_scale, point.peak_force, 1e-300)
                residual = point.peak_residual / scale
                if not math.isfinite(residual):
                    raise NoEquilibriumError(f"no equilibrium for loads {loads}: a non-finite force residual "
                                             f"({residual}) after {iterations} Newton iterations")
                if residual <= self.rtol or scale == 1e-300:  # converged, or no load and no contact at all
                    break
                cost = self._iteration_work(point) if bounded and flexible else 0.0     # an iteration's of the bound
                if iterations >= limit or self._affordable_iterations(cost) < 1:
                    if bounded:                               # the rest is the next solve's
                        return self._result(loads, point, iterations, residual, converged=False)
                    raise NoEquilibriumError(
                        f"no convergence after {iterations} Newton iterations (relative residual {residual:.2e}) "
                        f"for loads {loads}")
                if (self._product_operands is not None and not handed_back
                        and not _refresh_due(residual, last_residual, self.rtol)):
                    if self._reduced is not None:
                        self._reduced, self._reduced_jacobian = self._turned(self._reduced, mu), self._jacobian_rows
                    if self._kept_operator_serves():
                        # the iterations that keep the operator, in one compiled loop, as far as they go; the
                        # one it stopped before is this loop's (handed_back)
                        done, point, last_residual = self._kept_iterations(
                            point, f_scaled, load_scale, trust, last_residual, iterations,
                            int(min(limit, iterations + self._affordable_iterations(cost))))
                        self._work_left -= done * cost
                        handed_back = True
                        if done:
                            iterations += done
                            continue
                handed_back = False
                iterations += 1
                self._work_left -= cost

                if flexible:
                    fresh = _refresh_due(residual, last_residual, self.rtol)
                    last_residual = residual
                    try:
                        dq, dy = self._flexible_direction(point, f_scaled, mu, fresh, iterations)
                    except _WorkSpent:                        # a bounded solve: the rest is the next solve's
                        return self._result(loads, point, iterations - 1, residual, converged=False)
                    m_dy = self._ring_times(dy)       # M is symmetric: (M (f - y)) . dy = (f - y) . M dy
                    slope = float(grad_q @ dq) - float(mismatch @ m_dy)
                else:
                    dq, dy = self._rigid_direction(point, grad_q, mu), point.y
                    slope = float(grad_q @ dq)
                norm = math.sqrt(float(dq @ dq))
                if norm > trust:  # a step across a clearance is limited, then checked by the energy
                    dq, dy = dq * (trust / norm), dy * (trust / norm)
                    slope *= trust / norm
                    if flexible:
                        m_dy = m_dy * (trust / norm)

                # backtracking line search on the total energy (convex)
                t = 1.0
                for _ in range(60):
                    trial = self._evaluate(point.qs, point.y, f_scaled, point.ring_motion,
                                           (dq, dy, m_dy) if flexible else (dq, None, None), t)
                    roundoff = 1e-12 * max(point.energy_scale, trial.energy_scale)
                    if trial.total <= point.total + 1e-4 * t * min(slope, 0.0) + roundoff:
                        break
                    t *= 0.5
                else:
                    raise NoEquilibriumError(f"line search failed (relative residual {residual:.2e}) for loads {loads}")
                point = trial
                if float(point.qs @ point.qs) > dw * dw:
                    raise NoEquilibriumError(
                        f"no equilibrium for loads {loads}: the moving ring would move "
                        f"{np.linalg.norm(point.qs) * 1e3:.3g} mm, beyond the ball diameter ({dw * 1e3:g} mm); "
                        f"no contact resists this load")

            return self._result(loads, point, iterations, residual)

    def _rigid_solver(self, ring_motion: np.ndarray | None = None) -> "BimeSolver":
        """A rigid-ring solver at this rotation for a starting guess (no capacity checks), its
        grooves moved by ``ring_motion`` (``M y``, 4B) where given: the rings held as they are deformed.
        The cold start's, and the held-rings start's with numpy's loops (with the compiled ones that
        start runs the rigid model's loop itself, :meth:`_compiled_rigid_solve`, without the result a
        solve makes). Made once and kept (it holds nothing from one solve to the next); it takes this
        solver's assembly at its rotation (:meth:`set_rotation`'s arrays) instead of assembling it
        again (0.3 of the numpy held start's 1 ms when this was measured)."""
        rigid = self._rigid
        if rigid is None:
            rigid = self._rigid = BimeSolver(self.bearing, None, psi=self.assembly.psi,
                                             cage_angle=self.assembly.cage_angle, rtol=RIGID_START_TOLERANCE,
                                             max_iterations=self.max_iterations, kernel=self.kernel,
                                             blas_threads=self.blas_threads)
            rigid.edge_angle = np.full(4, np.pi)
            rigid.pressure_limit = math.inf
        for name in ROTATION_ARRAYS:
            setattr(rigid, name, getattr(self, name))
        if ring_motion is not None:
            rigid._separation = self._separation - ring_motion.reshape(self._separation.shape)
        return rigid

    def _held_rings_start(self, p: "_Point", loads: Loads, f_scaled: np.ndarray, load_scale: float) -> "_Point":
        """The start of a warm solve: ``p``, or where ``p`` is far from its equilibrium (relative
        residual above :data:`HELD_START`: the loads jumped) and it loads other contacts, the moving
        ring's equilibrium under the new loads with the rings held as they are deformed.

        After a moment reversal the old equilibrium's operator knows only the contacts that carried
        the old load: its Newton steps overshoot, and finding the new contact set takes many
        iterations and operators. Re-solving the moving ring's displacement ``(X, Y, Z, rx, ry)``
        with the ring forces held (a rigid-ring solve on the deformed grooves) is a step of block
        descent on the total energy (eq 20) that finds most of the new contact set at the cost of
        a rigid solve (0.15 ms compiled, :func:`~slewing_model.distribution.kernel._rigid_solve`;
        0.7 ms with numpy's rigid solver). It is taken where it lowers the energy and loads contacts that
        were open: more than :data:`HELD_NEW_CONTACTS` of its loaded diagonals (the pitch bearing's
        reversal: 56 of 109; 14 Newton iterations become 9). Where the loads grow in their
        direction (a jump, the first step from zero loads) it loads no new contacts, and its steps
        would take more iterations than the old equilibrium's; unless the solver has no operator at
        all (the first step under load after a cold solve that needed none, the yaw bearing's at
        zero loads): the first Newton step forms one, and at the held point it is formed on the
        contacts the loads close, where at ``p`` it would be the preload's alone on every diagonal
        (720 rows, condition 4e13, singular in single precision; bounded: 15 flagged steps, one of
        11 ms, against 8 and 6 ms; complete: 53 against 20 ms)."""
        if p.peak_residual <= HELD_START * max(load_scale, p.peak_force):
            return p
        self._work_left -= HELD_WORK          # a bounded solve counts the held start as operator work
        if self._compiled:                    # the rigid solve's iterations in one compiled loop
            found = self._compiled_rigid_solve(p.qs, p.y, p.ring_motion, f_scaled, load_scale, RIGID_START_TOLERANCE,
                                               self.max_iterations)
            if found is None:
                return p
            qs = found[0]
        else:
            try:
                qs = self._rigid_solver(p.ring_motion).solve(loads, initial=p.qs).state[:5].copy()
            except NoEquilibriumError:
                return p
        held = self._evaluate(qs, p.y, f_scaled, p.ring_motion)
        newly_loaded = int(np.count_nonzero(held.loaded & ~p.loaded))
        no_operator = self._reduced is None and self.pending_operator is None
        opened = newly_loaded > HELD_NEW_CONTACTS * int(np.count_nonzero(held.loaded))
        if held.total < p.total and (opened or no_operator):
            return held
        return p

    def _compiled_rigid_solve(self, qs, y, ring_motion, f_scaled, load_scale, rtol, limit):
        """The rigid model's iterations of :meth:`solve` from ``qs`` on the grooves moved by the held ring
        motion ``ring_motion`` (``M y``), in one compiled loop (:func:`~slewing_model.distribution.kernel._rigid_solve`):
        the moving ring's displacement reached, the iterations and the springs there (``e``, ``delta``,
        ``q``, ``(total energy, largest force, largest residual)``), or None where the loop of
        :meth:`solve` would not converge within ``limit`` iterations or would raise."""
        dw = self.bearing.ball_diameter
        rules = np.array([rtol, load_scale, TRUST_LENGTH * dw, dw * dw, DAMPING * self.reference_stiffness, limit])
        qs, iterations, converged, e, delta, q, terms = compiled_rigid_solve()(
            self._separation, self._jacobian_rows, qs, y, ring_motion, self.assembly.natural_length,
            self.assembly.stiffness, f_scaled, self._loaded_from, rules)
        return (qs, iterations, e, delta, q, terms) if converged else None

    def _ring_times(self, v: np.ndarray) -> np.ndarray:
        """``M v``: the ring compliance's product (numpy's, :class:`~slewing_model.rings.compliance.BlockCirculant`;
        or, with the compiled loops, their DFT)."""
        if self._product_operands is None:
            return self.compliance @ v
        return compiled_ring_times()(*self._product_operands, np.ascontiguousarray(v, dtype=float))

    def _turned(self, op: ReducedOperator, mu: float) -> ReducedOperator:
        """The kept operator ``op`` with its coupling to (X, Y, Z, rx, ry) following the ring's turn
        since it was formed (:meth:`set_rotation`; ``W^-1`` holds): :func:`turned_operator`, where
        the Jacobian is another array than the one the operator's coupling is for."""
        if self._reduced_jacobian is self._jacobian_rows:
            return op
        return turned_operator(op, self.jacobian, mu, self._turn_tolerance, self._arithmetic)

    def _kept_operator_serves(self) -> bool:
        """Whether the next iteration may keep the reduced operator as it is, all else equal: its
        coupling is that of this Jacobian and no stage of a pending one is due (``_flexible_direction``)."""
        return (self._reduced is not None and self._reduced_jacobian is self._jacobian_rows
                and not (self.pending_operator is not None and self._stage_due))

    def _kept_iterations(self, p: "_Point", f_scaled: np.ndarray, load_scale: float, trust: float,
                         last_residual: float, iterations: int, limit: int):
        """The iterations with the kept operator from ``p`` in one compiled loop
        (:func:`slewing_model.distribution.kernel._kept_iterations`: the steps of :meth:`solve`, up
        to the first that needs more than the operator's product): the iterations done, the point
        reached and the last residual."""
        dw = self.bearing.ball_diameter
        rules = np.array([self.rtol, load_scale, trust, dw * dw, REFRESH, FINISH_ITERATIONS, last_residual])
        terms = np.array([p.total, p.energy_scale, p.peak_force, p.peak_residual, float(p.any_loaded)])
        done, last_residual, *reached = compiled_kept_iterations()(
            *self._kept_operands(f_scaled), p.qs, p.y, p.ring_motion, p.e, p.delta, p.q, p.force, p.n, p.length,
            p.gradient, p.mismatch, p.loaded, terms, rules, iterations, limit)
        if not done:
            return 0, p, last_residual
        return done, _compiled_point(*reached), last_residual

    def _warm_solve(self, qs: np.ndarray, y: np.ndarray, f_scaled: np.ndarray, load_scale: float, mu: float,
                    trust: float, limit: int, bounded: bool):
        """The start of a warm solve with a kept operator (:meth:`solve`) in one compiled call
        (:func:`~slewing_model.distribution.kernel._warm_solve`): the start evaluated, the held-rings
        start's test, the operator turned with the ring, its iterations and, at an equilibrium, the
        contacts' results. Returns the point reached, the iterations done, the last residual, whether
        the kept loop stopped before the next iteration, whether the held-rings start is still to be
        tried (a start far off), and the contacts' results
        (:func:`~slewing_model.distribution.kernel._contact_results`) where the point is the
        equilibrium, else None: there :meth:`solve` goes on."""
        op, dw = self._reduced, self.bearing.ball_diameter
        rules = np.array([self.rtol, load_scale, trust, dw * dw, REFRESH, FINISH_ITERATIONS, HELD_START, mu,
                          self._turn_tolerance])
        status, done, last_residual, turned, changed, *found = compiled_warm_solve()(
            *self._kept_operands(f_scaled), qs, y, rules, limit, self._reduced_jacobian is not self._jacobian_rows,
            *self._contact_arguments())
        reached, (coupling, schur_inverse, jacobian), contacts = found[:13], found[13:16], found[16:]
        if turned:
            if changed:
                self._reduced = ReducedOperator(op.rows, op.active, op.contact_compliance, op.inverse, jacobian,
                                                coupling, schur_inverse)
            self._reduced_jacobian = self._jacobian_rows
        point = _compiled_point(*reached)
        if bounded:
            self._work_left -= done * self._iteration_work(point)
        return (point, done, last_residual, status == WARM_STOPPED, status == WARM_FAR,
                contacts if status == WARM_CONVERGED else None)

    def _kept_operands(self, f_scaled: np.ndarray) -> tuple:
        """What the compiled loops of the kept operator's iterations take first (``kernel._KEPT_OPERAND_TYPES``):
        the springs, the loads, the loaded threshold, the kept operator and the ring product's tables."""
        a, op = self.assembly, self._reduced
        return (self._separation, self._jacobian_rows, a.natural_length, a.stiffness, f_scaled, self._loaded_from,
                *product_inverses(op.inverse), op.contact_compliance, op.rows, op.jacobian, op.coupling,
                op.schur_inverse, op.active, *self._product_operands)

    def _contact_arguments(self) -> tuple:
        """What the compiled contacts' results take of the bearing beside the springs
        (:func:`~slewing_model.distribution.kernel._contact_results`)."""
        a, b = self.assembly, self.bearing
        return (a.contact_stiffness, a.ball_diameter, a.groove_radius, b.pitch_diameter, INNER_CONTACT,
                *contact_tables(b.youngs_modulus, b.poisson_ratio), self.edge_angle)

    def _evaluate(self, qs: np.ndarray, y: np.ndarray, f_scaled: np.ndarray, my: np.ndarray | None = None,
                  direction: tuple | None = None, t: float = 0.0) -> "_Point":
        """Contact terms, total energy and residuals at the unknowns ``(qs, y)``, or at the trial
        point ``(qs + t dq, y + t dy)`` of a line search along ``direction = (dq, dy, M dy)``;
        ``my``: ``M y`` if known (along a search line it is linear in the step)."""
        ring = 0.0
        flexible = self.compliance is not None
        if flexible and my is None:
            my = self._ring_times(y)
        if flexible and self._compiled:      # the same formulas, one compiled loop
            a = self.assembly
            dq, dy, m_dy = (np.zeros(5), np.zeros(y.size), np.zeros(y.size)) if direction is None else direction
            (qs, y, my, e, delta, q, force, n, length, gradient, mismatch, loaded, terms) = compiled_trial_point()(
                self._separation, self._jacobian_rows, qs, dq, y, dy, my, m_dy, t, a.natural_length, a.stiffness,
                f_scaled, self._loaded_from)
            energy, ring, work, peak_force, peak_residual, n_loaded = terms
            return _Point(qs, y, e, delta, q, force, None, n, length, energy + ring - work, energy + ring + abs(work),
                          gradient, mismatch, peak_force, peak_residual, loaded, n_loaded > 0, my)
        if direction is not None:
            dq, dy, m_dy = direction
            qs = qs + t * dq
            if flexible:
                y, my = y + t * dy, my + t * m_dy
        e = self._separation + (self._jacobian_rows @ qs).reshape(self.jacobian.shape[:-1])
        if flexible:
            e = e - my.reshape(e.shape)   # e_D = -M y: groove centres moved by ring deformation
            ring = 0.5 * float(y @ my)    # eq 15
        # the flexible step takes the springs' compliance from n, delta, q (reduced_operator)
        delta, q, force, energy, hess, n, length = self._contacts(e, hessian=not flexible)
        f = force.ravel()
        gradient = self._jacobian_rows.T @ f - f_scaled
        peak_force, peak_residual = float(q.max()), float(np.abs(gradient).max())
        mismatch = None
        if flexible:
            mismatch = f - y            # the Hertz forces less those the rings feel
            peak_force = max(peak_force, float(np.abs(y).max()))
            peak_residual = max(peak_residual, float(np.abs(mismatch).max()))
        work = float(f_scaled @ qs)
        loaded = (delta > self._loaded_from).ravel()
        # the total is a difference of larger terms: its roundoff scales with them
        return _Point(qs, y, e, delta, q, force, hess, n, length, energy + ring - work, energy + ring + abs(work),
                      gradient, mismatch, peak_force, peak_residual, loaded, bool(loaded.any()), my)

    def _rigid_direction(self, p: "_Point", grad_q: np.ndarray, mu: float) -> np.ndarray:
        """Newton step of the rigid model: ``(sum J^T A J) dq = -grad``."""
        jac = self.jacobian
        h = jac.reshape(-1, 5).T @ (p.hess.reshape(-1, 2, 2) @ jac.reshape(-1, 2, 5)).reshape(-1, 5)
        return np.linalg.solve(h + mu * np.eye(5), -grad_q)

    def _flexible_direction(self, p: "_Point", f_scaled: np.ndarray, mu: float, fresh: bool, iterations: int):
        """Newton step of the flexible model, reduced to the active contacts
        (:mod:`slewing_model.rings.reduced_operator`): returns the increments of ``qs`` and ``y``.

        The reduced operator ``(A^-1 + M)_aa^-1`` is kept and reused (a modified
        Newton step with the contact stiffness ``A`` of an earlier iterate, which
        is still a descent direction) while ``fresh`` is False, bordered by contacts
        that close (contacts that open keep their rows, :func:`update_operator`); the
        solve loop asks for a fresh one when convergence slows. Between warm-started
        solves of slowly changing loads (the FMU's steps) an iteration then costs
        matrix-vector products only.

        In a warm solve a fresh operator is formed at once but inverted over this solve and
        the next (:class:`PendingOperator`), while the kept one goes on: at most one step's stages
        (:data:`~slewing_model.rings.reduced_operator.SPREAD_STAGES`) a solve, and all at once when an
        iteration past :data:`SPREAD_ITERATIONS` of one solve is still slow or the kept operator
        cannot follow the contacts that closed. A bounded solve (``step_work``) runs of these the
        stages its work allows (:meth:`_advance`) and goes on in the next solves.
        """
        if not p.any_loaded:
            self._reduced = self.pending_operator = None
            return np.linalg.solve(mu * np.eye(5), f_scaled), -p.y
        try:
            op = self._step_operator(p, mu, fresh, iterations)
        except _WorkSpent:
            # a bounded solve ends here; that the next goes further, a new operator at this iterate
            # has the stages now that are left, if none is on its way
            if self.pending_operator is None:
                try:
                    self.pending_operator = self._start_operator(p, mu, SPREAD_STAGES[0], required=False)
                except _WorkSpent:
                    pass
                self._stage_due = False
            raise
        y_off = off_rows(op, p.y)             # forces a fresh operator's rows leave out: their ring motion
        dq, y_new = self._arithmetic.step(op, p, f_scaled, None if y_off is None else self._ring_times(y_off))
        return dq, y_new - p.y

    def _step_operator(self, p: "_Point", mu: float, fresh: bool, iterations: int) -> ReducedOperator:
        """The reduced operator of this iteration (:meth:`_flexible_direction`), kept as the solver's."""
        active = p.loaded
        op, pending = self._reduced, self.pending_operator
        if pending is not None:
            if op is None or (fresh and iterations > SPREAD_ITERATIONS):     # the kept one no longer serves
                pending = self._advance(pending, mu, len(STAGES), required=True)
            elif self._stage_due:                                              # one step's stages a solve
                pending = self._advance(pending, mu, step_end(pending), required=False)
            self._stage_due = False
            if isinstance(pending, ReducedOperator):     # inverted: its coupling is that of the Jacobian now
                op, pending, fresh = pending, None, False
                self._reduced, self._reduced_jacobian = op, self._jacobian_rows
            else:
                fresh = False
        elif fresh and op is not None and self._spread and self._stage_due and iterations <= SPREAD_ITERATIONS:
            pending = self._start_operator(p, mu, SPREAD_STAGES[0], required=False)
            fresh = self._stage_due = False
        self.pending_operator = pending

        def bordered(op):                      # contacts closed: bordered in (those that opened stay)
            closed = active & ~op.active
            if not closed.any():
                return op
            entering = active
            if borders(op, 2 * int(np.count_nonzero(closed))):        # else update_operator declines: no work
                entering = self._bordering_that_fits(op, p, closed)
                self._spend(bordering_work(2 * int(np.count_nonzero(entering)), op.rows.size))
                entering = entering | op.active
            return update_operator(op, p, self.compliance, self.assembly.stiffness, self.jacobian, entering, mu,
                                   self._arithmetic)

        if not fresh and op is not None:
            op = bordered(self._turned(op, mu))
            if op is None and self.pending_operator is not None:     # too many closed: the pending one, at once
                op = self._advance(self.pending_operator, mu, len(STAGES), required=True)
                self._reduced, self._reduced_jacobian, self.pending_operator = op, self._jacobian_rows, None
                op = bordered(op)
        if fresh or op is None:                # formed and inverted now (a bounded solve: as its work allows)
            op = self._start_operator(p, mu, len(STAGES), required=True)
            self.pending_operator = None
        self._reduced, self._reduced_jacobian = op, self._jacobian_rows
        return op

    def _start_operator(self, p: "_Point", mu: float, until: int, required: bool):
        """A new operator formed at ``p`` and its stages up to ``until``, as :meth:`_advance` allows."""
        self._spend(forming_work(2 * int(np.count_nonzero(p.loaded))))
        pending = start_operator(p, self.compliance, self.assembly.stiffness, p.loaded, self._arithmetic, until=0)
        return self._advance(pending, mu, until, required)

    def _advance(self, pending: PendingOperator, mu: float, until: int, required: bool):
        """The pending operator's stages up to ``until`` (:data:`~slewing_model.rings.reduced_operator.STAGES`),
        those the solve's work allows (``step_work``: at least one where the solve did no operator
        work yet, whatever else it spent, so that a run of bounded solves always gets on); the
        operator where they are all done and asked for (``until`` the last), else the pending one,
        kept as the solver's and :class:`_WorkSpent` raised where ``required``."""
        n, stage = pending.matrix.shape[0], pending.stage
        while stage < until and self._take(stage_work(n, stage, pending.method)):
            stage += 1
        if stage > pending.stage:
            # an inverse that misses the check: made again, spread where the solve can wait or its work is bounded
            pending = advance_operator(pending, None, None, self._arithmetic, until=stage,
                                       again=not required or math.isfinite(self._work_left))
        if pending.stage >= len(STAGES) and until >= len(STAGES):
            return advance_operator(pending, self.jacobian, mu, self._arithmetic)
        if required:
            self.pending_operator = pending
            raise _WorkSpent
        return pending

    def _bordering_that_fits(self, op: ReducedOperator, p: "_Point", closed: np.ndarray) -> np.ndarray:
        """The diagonals that ``closed`` since ``op`` was formed and are bordered in now: all of them
        where the solve's work allows it (a complete solve: always), else the most stretched (largest
        ``delta``) whose bordering the work left allows
        (:func:`~slewing_model.rings.reduced_operator.bordering_work`); where the solve did no operator
        work yet (its one piece, :meth:`_take`), what :data:`BORDER_PIECE` allows if more. The others
        carry no force in this solve's Newton steps (as a fresh operator's rows left out,
        :func:`~slewing_model.rings.reduced_operator.off_rows`) and enter in the next solves. All at once,
        the pitch bearing's NREL step 3 from its start values would border 74 rows onto 402: 1.8 ms of work
        by its count where the held-rings start left 0.9 ms (3.4 ms measured), the scenario's slowest
        step."""
        n, count = op.rows.size, int(np.count_nonzero(closed))
        allowed = self._work_left if self._operator_work_done else max(self._work_left, BORDER_PIECE)
        if bordering_work(2 * count, n) <= allowed:
            return closed
        fit = 0
        while fit < count and bordering_work(2 * (fit + 1), n) <= allowed:
            fit += 1
        if fit == 0:                        # not even one: _spend refuses it (or it is the one piece)
            fit = 1
        candidates = np.flatnonzero(closed)
        entering = np.zeros_like(closed)
        entering[candidates[np.argsort(-p.delta.ravel()[candidates], kind="stable")[:fit]]] = True
        return entering

    def _iteration_work(self, p: "_Point") -> float:
        """The work of a Newton iteration from ``p`` (:data:`BOUNDED_WORK`, as the operator's work is
        counted: about time): its product with the reduced operator's inverse, ``2 n^2`` for ``n`` rows
        (the kept operator's, or two a loaded diagonal), and its line search's trial point and ring
        products, which go with the balls (:data:`ITERATION_WEIGHT`)."""
        rows = self._reduced.rows.size if self._reduced is not None else 2 * int(np.count_nonzero(p.loaded))
        return ITERATION_WEIGHT[0] * 2.0 * rows * rows + ITERATION_WEIGHT[1] * self.bearing.ball_count

    def _affordable_iterations(self, cost: float) -> float:
        """How many more Newton iterations of work ``cost`` each (:meth:`_iteration_work`; 0 in a
        complete solve) the solve may start: those the work left covers, once it has done operator
        work; before, any (an iteration may do its one piece, that a run of bounded solves always
        gets on; :meth:`_take`)."""
        if cost <= 0.0 or not self._operator_work_done:
            return math.inf
        return max(self._work_left // cost, 0.0)

    def _spend(self, work: float) -> None:
        """Take ``work`` (:data:`BOUNDED_WORK`) from what the solve may still do (``step_work``);
        :class:`_WorkSpent` where it is not left (nothing is done then), except for the solve's first
        piece of operator work (as :meth:`_advance`)."""
        if not self._take(work):
            raise _WorkSpent

    def _take(self, work: float) -> bool:
        """Whether the solve may do ``work`` more of operator work (:data:`BOUNDED_WORK`): where it is
        left, or it is the solve's first piece; taken from what is left if so."""
        if work > self._work_left and self._operator_work_done:
            return False
        self._work_left -= work
        self._operator_work_done = True
        return True

    def _result(self, loads: Loads, p: "_Point", iterations: int, residual: float,
                converged: bool = True, contacts: tuple | None = None) -> LoadDistribution:
        """The load distribution at ``p`` (its contacts' results ``contacts`` where the compiled loop
        gave them, :meth:`_warm_solve`)."""
        a = self.assembly
        qs, y, e, delta, q = p.qs, p.y, p.e, p.delta, p.q
        b = self.bearing
        if self._compiled:                    # the same formulas, one compiled loop (contact_kernel)
            if contacts is None:
                contacts = compiled_contact_results()(q, e, *self._contact_arguments())
            (contact_load, contact_angle, deflection, semi_a, semi_b, pressure, truncated, first_off) = contacts
            off = None if first_off < 0 else divmod(first_off, 4)
        else:
            # per contact 1..4 from the diagonals: contacts (1,3) <- diagonal 1, (2,4) <- diagonal 2
            per_contact = np.array([0, 1, 0, 1])
            contact_load = q[:, per_contact]
            alpha_diag = np.stack([np.arctan2(e[:, 0, 1], e[:, 0, 0]), np.arctan2(-e[:, 1, 1], e[:, 1, 0])], axis=1)
            contact_angle = alpha_diag[:, per_contact]
            deflection = contact_deflection(contact_load, a.contact_stiffness)
            ell = hertz_ellipse(contact_load, a.ball_diameter[:, None], a.groove_radius, contact_angle,
                                b.pitch_diameter, CONTACT_RING, b.youngs_modulus, b.poisson_ratio)
            semi_a, semi_b, pressure = ell.a, ell.b, ell.max_pressure
            loaded = contact_load > 0.0
            # the contact point must stay on the raceway: beyond the groove edge the ball rides the
            # edge and the model (and the bearing) no longer carries the load
            beyond = np.argwhere(loaded & (contact_angle >= self.edge_angle[None, :]))
            off = tuple(map(int, beyond[0])) if beyond.size else None
            # edge loading: the ellipse runs over the groove edge (reported, see LoadDistribution.truncated)
            truncated = loaded & (contact_angle + semi_a / a.groove_radius >= self.edge_angle[None, :])
        if off is not None and converged:        # an iterate on its way is not checked (step_work)
            ball, contact = off
            raise LoadCapacityError(
                f"loads {loads} are beyond what the bearing can carry: at ball {ball + 1} the contact angle of "
                f"contact {contact + 1} would be {math.degrees(contact_angle[ball, contact]):.1f} deg, past the "
                f"groove edge at {math.degrees(self.edge_angle[contact]):.1f} deg (load {contact_load[ball, contact]:.4g} N)")
        if pressure.max() > self.pressure_limit and converged:
            ball, contact = np.unravel_index(int(np.argmax(pressure)), pressure.shape)
            raise LoadCapacityError(
                f"loads {loads} are beyond what the bearing can carry: the contact pressure of ball {ball + 1}, "
                f"contact {contact + 1} would be {pressure.max() / 1e6:.0f} MPa, above the limit of "
                f"{self.pressure_limit / 1e6:.0f} MPa (static safety factor "
                f"{(ISO76_PRESSURE_LIMIT / pressure.max()) ** 3:.3f})")
        displacement = qs.copy()
        displacement[3:] /= self.length
        return LoadDistribution(
            model=self.model, loads=loads, displacement=displacement, ball_angle=a.ball_angle.copy(),
            contact_load=contact_load, contact_angle=contact_angle, interference=delta.copy(),
            contact_deflection=deflection, semi_axis_a=semi_a, semi_axis_b=semi_b,
            contact_pressure=pressure, truncated=truncated, energy=p.total, iterations=iterations, residual=residual,
            state=np.concatenate([qs, y]), rings=self.ring_compliance, converged=converged,
        )


class _WorkSpent(Exception):
    """A bounded solve has not the work left for what its next iteration needs (``step_work``)."""


def _refresh_due(residual: float, last_residual: float | None, rtol: float) -> bool:
    """Whether the flexible solver's next iteration forms a fresh reduced operator: on the first
    iteration of a cold solve (no last residual) and whenever the residual fell by less than a
    factor ``1 / REFRESH`` in the last iteration, unless at that rate the iterations still needed
    are few (:data:`FINISH_ITERATIONS`): they cost less than a new operator."""
    if last_residual is None:
        return True
    fresh = residual > REFRESH * last_residual
    if fresh and residual < last_residual:
        fresh = math.log(rtol / residual) < FINISH_ITERATIONS * math.log(residual / last_residual)
    return fresh


def _compiled_point(qs, y, my, e, delta, q, force, n, length, gradient, mismatch, loaded, terms) -> "_Point":
    """The :class:`_Point` a compiled loop reached, as it returns it (``terms``: the total energy, the
    energy scale, the largest force, the largest residual, the loaded diagonals;
    :func:`~slewing_model.distribution.kernel._kept_iterations`)."""
    total, energy_scale, peak_force, peak_residual, n_loaded = terms
    return _Point(qs, y, e, delta, q, force, None, n, length, total, energy_scale, gradient, mismatch, peak_force,
                  peak_residual, loaded, n_loaded > 0, my)


@dataclass
class _Point:
    """Unknowns and the contact terms evaluated there (one Newton iterate)."""

    qs: np.ndarray
    y: np.ndarray
    e: np.ndarray
    delta: np.ndarray
    q: np.ndarray
    force: np.ndarray
    hess: np.ndarray
    n: np.ndarray
    length: np.ndarray
    total: float
    energy_scale: float
    gradient: np.ndarray                    # of the energy in qs (scaled): J^T f - F
    mismatch: np.ndarray | None             # the Hertz forces less those the rings feel, f - y (flexible)
    peak_force: float                       # the largest of q and |y|: the stop rule's scale
    peak_residual: float                    # the largest of |gradient| and |mismatch|
    loaded: np.ndarray                      # (2B,) the diagonals whose springs are stretched (delta > 1e-15 Dw)
    any_loaded: bool
    ring_motion: np.ndarray | None = None   # M y: the groove centres' relative motion from ring deformation (flexible)


def solve(bearing: Bearing, loads: Loads | None = None, *, model: str = "rigid", superelement=None,
          bc: str = "free", mesh: str = "coarse", psi: float = 0.0, cage_angle: float | None = None,
          initial=None, rtol: float = 1e-10) -> LoadDistribution:
    """Load distribution of ``bearing`` under ``loads``: the one obvious entry point.

    Parameters
    ----------
    bearing : Bearing
        The bearing definition (with its errors and preload).
    loads : Loads, optional
        External load on the moving ring (fixed frame), N and N m; None (default) for idling.
    model : {"rigid", "flexible"}, optional
        Rigid rings (Rigid-BIME, default) or flexible rings (Flexible-BIME).
    superelement : Superelement, optional
        For ``model="flexible"``; built (or read from the cache) with ``bc``
        and ``mesh`` when not given.
    bc : {"free", "clamped", "frictionless"}, optional
        Ring support for a superelement built here. Default "free".
    mesh : {"coarse", "fine"}, optional
        Finite element mesh of a superelement built here. Default "coarse".
    psi : float, optional
        Rotation of the moving ring, rad. Default 0.
    cage_angle : float, optional
        Rotation of the ball set, rad; default (None): rolling without slip from ``psi``.
    initial : LoadDistribution, optional
        Warm start.
    rtol : float, optional
        Relative tolerance of the force residuals. Default 1e-10.

    Returns
    -------
    LoadDistribution
        Ball loads ``Q`` (N), contact angles (rad), ring displacement, Hertz
        ellipses and pressures.

    Raises
    ------
    NoEquilibriumError
        The load has no equilibrium within the bearing.
    LoadCapacityError
        The load is beyond what the raceways can carry.

    Examples
    --------
    >>> from slewing_model import load_bearing, solve, Loads
    >>> b = load_bearing("examples/bearings/table1.toml")
    >>> r = solve(b, Loads(Fz=500e3))            # pure axial load: the 100 balls share it equally
    >>> round(r.max_ball_load)                   # N
    6898
    >>> r = solve(b, Loads(Fz=500e3, My=1e6))
    >>> round(r.max_ball_load), round(r.static_safety_factor, 2)
    (40289, 2.33)
    """
    if model not in ("rigid", "flexible"):
        raise ValueError(f"model = {model!r}: must be 'rigid' or 'flexible'")
    if model == "flexible" and superelement is None:
        from ..rings.superelement import build_superelement

        superelement = build_superelement(bearing, mesh=mesh, bc=bc)
    solver = BimeSolver(bearing, superelement if model == "flexible" else None, psi=psi, cage_angle=cage_angle,
                        rtol=rtol)
    return solver.solve(loads, initial=initial)


def solve_dense_newton(solver: BimeSolver, loads: Loads | None = None, *, rtol: float = 1e-10,
                       max_iterations: int = 100) -> tuple[np.ndarray, int]:
    """Reference solver: plain Newton on all ``5 + 8B`` unknowns of eq 20 with a
    dense factorisation of the full Hessian (:meth:`BimeSolver.energy_terms`).

    The baseline the structured solver is measured against, and an independent
    check of it. A free ring's deformation is kept orthogonal to its rigid-body
    modes (the null space of its superelement) by an exact projection: the
    ring's rigid motion is the moving ring's ``q``, on which the load works;
    letting the deformation carry rigid motion too would make the energy
    unbounded under load.

    Returns
    -------
    x : ndarray (5 + 8B,)
        ``(X, Y, Z, rx, ry, D_out, D_in)``.
    iterations : int
    """
    loads = Loads() if loads is None else loads
    n = solver.bearing.ball_count
    se = solver.superelement
    x = np.zeros(5 + 8 * n)
    start = BimeSolver(solver.bearing, None, psi=solver.assembly.psi, cage_angle=solver.assembly.cage_angle)
    start.edge_angle, start.pressure_limit = np.full(4, np.pi), math.inf
    x[:5] = start.solve(loads).displacement
    null = np.zeros((5 + 8 * n, 0))
    for k, ring in enumerate((se.outer, se.inner)):
        w, v = np.linalg.eigh(ring.dense())
        modes = v[:, np.abs(w) <= 1e-9 * np.abs(w).max()]
        block = np.zeros((5 + 8 * n, modes.shape[1]))
        block[5 + 4 * n * k:5 + 4 * n * (k + 1)] = modes
        null = np.hstack([null, block])
    project = np.eye(5 + 8 * n) - null @ null.T
    units = np.ones(5 + 8 * n)
    units[3:5] = 1.0 / solver.length  # moments as forces at the pitch radius
    force_scale = max(float(np.abs(loads.as_array() * units[:5]).max()), 1.0)
    for iteration in range(max_iterations + 1):
        u, g, h = solver.energy_terms(x, loads)
        g = project @ g
        if iteration and np.abs(g * units).max() <= rtol * force_scale:
            return x, iteration
        reduced = project @ h @ project
        step = np.linalg.solve(reduced + np.abs(np.diag(reduced)).max() * (null @ null.T), -g)
        t = 1.0
        while solver.energy_terms(x + t * step, loads)[0] > u + 1e-4 * t * (g @ step) + 1e-13 * abs(u) and t > 1e-12:
            t *= 0.5
        x = x + t * step
    raise NoEquilibriumError(f"dense Newton: no convergence after {max_iterations} iterations")
