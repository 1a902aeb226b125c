"""Time stepping of one bearing: what a co-simulation step asks of the library.

:class:`BearingSimulator` holds a bearing, its (optional) superelement and the
solver's warm start, and answers each step with the load distribution and the
friction torque for the loads, the rotation ``psi`` and the speed ``omega`` of
the moving ring. It knows nothing of FMI: the FMU in ``fmu_src/`` maps its
variables onto this class, and scripts can use it directly.

Its whole state is :meth:`BearingSimulator.get_state` (plain data, JSON by :func:`encode_state`
but for the last held answer, kept in memory only), so a step can be rolled back and repeated exactly.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..distribution.bime import STEP_WORK, BimeSolver, LoadDistribution, Loads
from ..friction.torque import friction_torque, prepare_warm_torque, regularised_torque, seal_torque_of, warm_torque
from ..friction.kernel import compile_all, use_compiled
from ..bearing.geometry import Bearing
from ..numerics.blas import blas_threads
from ..rings.reduced_operator import PendingOperator, ReducedOperator

RING_MODELS = ("rigid", "flexible")
LOAD_FRAMES = ("fixed", "rotating")
#: the ball equilibrium's iterations behind the friction torque of a step whose load distribution is
#: an iterate on its way (``step_work="bounded"``): its torque is one too, and the next step goes on
#: from it (after a moment reversal a complete one takes 13-14, about 2 ms on the pitch bearing)
BOUNDED_FRICTION_ITERATIONS = 4
#: loads whose change in a step is below this share of their size held in it (:func:`extrapolated_start`)
HELD_LOADS = 1e-9
#: the column of a ball's orbital speed in the friction torque's state (``FrictionTorque.state``: ``w_r``,
#: ``w_t``, ``w_z``, ``w_c`` per unit of speed), zero for a ball that carries no load
ORBITAL = 3


@dataclass(frozen=True)
class SimulatorSettings:
    """Options of a :class:`BearingSimulator` (SI units).

    Frozen; :meth:`BearingSimulator.tune` changes the tunable ones between steps.

    Attributes
    ----------
    ring_model : {"flexible", "rigid"}
        Flexible rings (Flexible-BIME, needs a superelement; default) or rigid rings.
    moving_ring : {"inner", "outer"}
        The ring the loads act on and that turns by ``psi`` (overrides the bearing
        definition's). Default "inner".
    load_frame : {"fixed", "rotating"}
        Frame the loads are given in: the fixed ring's (default), or the moving ring's
        (turned by ``psi``; e.g. blade root loads of a pitch bearing).
    preload : float or None
        Ball preload, m, overriding the bearing definition; None (default) keeps the definition's.
    friction_coefficient : float
        Coulomb coefficient ``mu`` of the raceway contacts; 0 switches the
        contact friction off. Default 0.1. Tunable.
    seal_torque : float
        Load-independent friction torque (seals, grease), N m. Default 0. Tunable.
    tolerance : float
        Relative tolerance of the load distribution solver, in (0, 0.01): the force and
        moment residuals on the moving ring (and the contact forces the rings feel) below
        ``tolerance`` times the load scale. The default 1e-7 is tied to what the outputs
        need: ten times below the 1e-6 balance of forces the co-simulation promises, and it
        leaves ``z``, ``rx``, ``ry`` and the ball loads within 2e-5 of a solve at the
        round-off floor in the benchmark cases; each decade tighter costs about one Newton
        iteration per step.
    omega_regularisation : float
        Speed over which the signed friction torque goes from 0 to its
        full-sliding level, rad/s (:func:`slewing_model.friction.regularised_torque`);
        choose at least ``magnitude * step / inertia`` for an explicit coupling
        (:func:`slewing_model.friction.omega_regularisation_for_step`). Default 1e-4. Tunable.
    friction_tolerance : float
        Relative accuracy of the ball equilibrium behind each step's friction
        torque, in (0, 0.01) (``tol`` of :func:`slewing_model.friction.friction_torque`; the
        torque error it leaves is below it). Default 1e-5: with 1e-4 the yaw bearing's
        torque is off by up to 1.8e-4 at some steps, where a four-contact ball stops on a
        flat stretch of its power.
    blas_threads : int or None
        Threads of numpy's BLAS while a step does its BLAS work: the load distribution's and
        the ring operator's (``blas_threads`` of
        :class:`~slewing_model.distribution.bime.BimeSolver`), and the friction torque's
        numpy path (:func:`slewing_model.numerics.blas.blas_threads`, restored after; the
        usual step's compiled calls use no BLAS); None leaves them as the process has
        them. Default 1: the step's matrices have a few hundred rows, and a second thread
        that spins while other processes share the cores makes steps several times slower.
    friction_kernel : {"auto", "numpy", "compiled"}
        How the friction model runs its loops over points and balls (``kernel`` of
        :func:`slewing_model.friction.friction_torque`): "auto" (default) takes the compiled
        loops where numba is installed, numpy otherwise; the results are the same to round-off.
    contact_kernel : {"auto", "numpy", "compiled"}
        The same for the load distribution's loops (its per-contact work and the reduced ring
        operator's: ``kernel`` of :class:`slewing_model.distribution.bime.BimeSolver`) and the
        life map's (``kernel`` of :class:`slewing_model.life.RacewayMap`). Default "auto".
    step_work : {"complete", "bounded"}
        How much a step may do (``step_work`` of :class:`slewing_model.distribution.bime.BimeSolver`):
        "complete" (default) solves every step to ``tolerance``, however long a sudden change
        of the loads makes it (a moment reversed in one step: tens of ms); "bounded" (real
        time) caps a step's work, its Newton iterations and ring operator work together, at
        about 1.8 ms (a new operator's inverse spread over steps), and a step that would need
        more answers with its last iterate, ``distribution.converged`` False and its
        ``distribution.residual``, and carries the rest over to the next steps; the friction
        torque of such a step is an iterate too (at most 4 iterations of the ball
        equilibrium), and the life accumulator counts no damage from it: the rolling of such
        steps is counted with the next converged step's load distribution. The first step is complete.
    life : bool
        Accumulate the raceway life and wear step by step (:class:`slewing_model.life.LifeAccumulator`
        as ``BearingSimulator.life``, default :class:`slewing_model.life.LifeSettings`): the
        raceway damage map and the half-cycles of ``psi``; part of the simulator's state.
        Default False.

    Raises
    ------
    ValueError
        If a choice is unknown or a number is out of its range.
    """

    ring_model: str = "flexible"
    moving_ring: str = "inner"
    load_frame: str = "fixed"
    preload: float | None = None
    friction_coefficient: float = 0.1
    seal_torque: float = 0.0
    tolerance: float = 1e-7
    omega_regularisation: float = 1e-4
    friction_tolerance: float = 1e-5
    blas_threads: int | None = 1
    friction_kernel: str = "auto"
    contact_kernel: str = "auto"
    step_work: str = "complete"
    life: bool = False

    def __post_init__(self):
        _choice("ring_model", self.ring_model, RING_MODELS)
        _choice("moving_ring", self.moving_ring, ("inner", "outer"))
        _choice("load_frame", self.load_frame, LOAD_FRAMES)
        _choice("step_work", self.step_work, STEP_WORK)
        use_compiled(self.friction_kernel, "friction_kernel")
        use_compiled(self.contact_kernel, "contact_kernel")
        for name in ("friction_coefficient", "seal_torque", "tolerance", "omega_regularisation", "friction_tolerance"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise ValueError(f"{name} = {value!r}: must be a finite number >= 0")
        for name in ("tolerance", "friction_tolerance"):
            if not 0 < getattr(self, name) < 1e-2:
                raise ValueError(f"{name} = {getattr(self, name)!r}: must lie in (0, 0.01)")
        if self.blas_threads is not None and (isinstance(self.blas_threads, bool) or not isinstance(
                self.blas_threads, int) or self.blas_threads < 1):
            raise ValueError(f"blas_threads = {self.blas_threads!r}: must be a whole number >= 1, or None")
        if self.preload is not None and not math.isfinite(self.preload):
            raise ValueError(f"preload = {self.preload!r}: must be finite")


def _choice(name, value, allowed):
    if value not in allowed:
        raise ValueError(f"{name} = {value!r}: must be one of {', '.join(map(repr, allowed))}")


@dataclass(frozen=True)
class StepResult:
    """What one step answers (SI units).

    Attributes
    ----------
    distribution : LoadDistribution
        Ball loads, contact angles and ring displacement of the step.
    friction_torque : float
        Friction torque of the bearing on the moving ring about +z, N m. Signed:
        opposes ``omega`` (regularised near rest by ``omega_regularisation``).
    friction_torque_magnitude : float
        Friction torque at full sliding, N m (>= 0), whatever ``omega``.
    """

    distribution: LoadDistribution
    friction_torque: float
    friction_torque_magnitude: float


@dataclass
class BearingSimulator:
    """Load distribution and friction torque, step after step, warm-started.

    Holds a bearing, its (optional) superelement and the solver's warm start, and
    answers each :meth:`step` with the load distribution and the friction torque for
    the loads, the rotation ``psi`` and the speed ``omega`` of the moving ring. Its
    whole state is :meth:`get_state`, so a step can be rolled back and repeated exactly.
    The FMU wraps this class.

    Parameters
    ----------
    bearing : Bearing
        The bearing definition; ``settings.moving_ring`` and ``settings.preload`` override its own.
    superelement : Superelement, optional
        Both rings' condensed stiffness; needed for ``settings.ring_model == "flexible"``.
    settings : SimulatorSettings, optional
        Options; default ``SimulatorSettings()`` (flexible rings).

    Attributes
    ----------
    solver : BimeSolver
        The load distribution solver, kept step to step.
    last : StepResult or None
        The last step's answer.
    life : LifeAccumulator or None
        The life and wear accumulator when ``settings.life`` is True.

    Raises
    ------
    ValueError
        If ``ring_model`` is "flexible" and no superelement is given.

    Examples
    --------
    >>> from slewing_model import load_bearing, Loads
    >>> from slewing_model.simulation import BearingSimulator, SimulatorSettings
    >>> sim = BearingSimulator(load_bearing("examples/bearings/table3.toml"),
    ...                        settings=SimulatorSettings(ring_model="rigid", friction_coefficient=0.0))
    >>> r = sim.step(Loads(Fz=5e4), psi=0.0, omega=0.1)     # N; rad, rad/s
    >>> bool(r.distribution.displacement[2] > 0)            # the inner ring moves towards +z
    True
    """

    bearing: Bearing
    superelement: object = None
    settings: SimulatorSettings = field(default_factory=SimulatorSettings)

    def __post_init__(self):
        s = self.settings
        if s.ring_model == "flexible" and self.superelement is None:
            raise ValueError("ring_model = 'flexible' needs a superelement")
        bearing = replace(self.bearing, moving_ring=s.moving_ring)
        if s.preload is not None:
            bearing = bearing.with_preload(s.preload)
        self.bearing = bearing
        self.solver = BimeSolver(bearing, self.superelement if s.ring_model == "flexible" else None,
                                 rtol=s.tolerance, kernel=s.contact_kernel, step_work=s.step_work,
                                 blas_threads=s.blas_threads)
        friction, contact = use_compiled(s.friction_kernel, "friction_kernel"), use_compiled(s.contact_kernel,
                                                                                             "contact_kernel")
        if friction or contact:
            compile_all(friction, contact)     # compiled (or loaded from numba's cache) now, not in a step
        self._warm: np.ndarray | None = None
        self._previous: np.ndarray | None = None      # the state one step before _warm
        self._loads: tuple = (None, None)              # the scaled loads of _warm and of _previous
        self._warm_converged = True                    # _warm an equilibrium (not a bounded step's iterate)
        self._friction_warm: np.ndarray | None = None  # ball kinematics of the last step
        self._friction_previous: np.ndarray | None = None   # ... and of the step before (both equilibria)
        self._friction_converged = True                # _friction_warm an equilibrium (not capped)
        self._psi = 0.0
        #: (loads, psi, StepResult) of the last step where it ended at an equilibrium: a step with the same
        #: inputs answers it again (:meth:`step`); None where there is none
        self._held: tuple | None = None
        self._warm_friction = None
        self._prepare_friction()
        self.last: StepResult | None = None
        self.life = None
        if s.life:
            from ..life import LifeAccumulator, LifeModel

            self.life = LifeAccumulator(LifeModel(bearing, s.moving_ring, s.load_frame), kernel=s.contact_kernel)

    def tune(self, **changes) -> None:
        """Change the tunable settings between steps; the others need a new simulator.

        Parameters
        ----------
        **changes
            New values of ``friction_coefficient`` (-), ``seal_torque`` (N m) or
            ``omega_regularisation`` (rad/s).

        Raises
        ------
        ValueError
            If a setting is not tunable.
        """
        for name in changes:
            if name not in ("friction_coefficient", "seal_torque", "omega_regularisation"):
                raise ValueError(f"{name} is not tunable: build a new simulator")
        self.settings = replace(self.settings, **changes)
        self._prepare_friction()
        self._held = None                 # the last torque was of the settings before

    def _prepare_friction(self) -> None:
        """The friction torque's one compiled call prepared for the settings (:func:`prepare_warm_torque`),
        where the friction's loops are compiled and its coefficient is not zero; else None."""
        s = self.settings
        self._warm_friction, self._seal_torque = None, seal_torque_of(self.bearing, s.seal_torque)
        if s.friction_coefficient > 0.0 and use_compiled(s.friction_kernel, "friction_kernel"):
            self._warm_friction = prepare_warm_torque(self.bearing, mu=s.friction_coefficient, omega=1.0,
                                                      tol=s.friction_tolerance)

    def step(self, loads: Loads, psi: float, omega: float) -> StepResult:
        """Solve the step: load distribution at rotation ``psi`` (warm-started
        from the previous step), then the friction torque at speed ``omega``.

        Parameters
        ----------
        loads : Loads
            External load on the moving ring, N and N m, in the frame ``settings.load_frame``.
        psi : float
            Rotation of the moving ring, rad.
        omega : float
            Speed of the moving ring relative to the fixed ring about +z, rad/s.

        Returns
        -------
        StepResult
            The load distribution and the signed and full-sliding friction torques.

        Raises
        ------
        ValueError
            A non-finite input, naming it.
        NoEquilibriumError, LoadCapacityError
            The load cannot be carried. The simulator is then as it was before the
            step (the solver's rotation and kept operator restored): the next step
            goes on as if this one had not been asked for.

        Notes
        -----
        A step whose loads and ``psi`` equal the last step's, where that one ended at an equilibrium
        (its load distribution and friction torque converged), answers that equilibrium again at once:
        the same load distribution (its arrays, ``iterations`` 0) and friction torque magnitude, and the
        signed torque at this ``omega`` (the magnitude is that of a unit speed, whatever ``omega``).
        Solving it again would start at that equilibrium, take no Newton iteration and give the same
        numbers to round-off (the friction's balls take their last small Newton step again: within
        ``friction_tolerance``); the life accumulator adds nothing in such a step (no ball crosses a
        slice, ``psi`` does not move), so it is not called. Held inputs are what a parked or idling
        drive, a master's repeated step and the held stretches of step-wise load cases send.
        """
        for name, value in (("psi", psi), ("omega", omega)):
            if not math.isfinite(value):
                raise ValueError(f"input {name} = {value!r}: must be finite (not NaN or infinite)")
        held = self._held
        if held is not None and held[1] == psi and held[0] == loads:
            return self._repeat(held, omega)
        given = loads
        if self.settings.load_frame == "rotating":
            loads = loads.rotated(psi)
        before = self._checkpoint()
        try:
            result = self._step(loads, psi, omega)
        except Exception:
            self._restore(before)
            raise
        self._held = (given, psi, result) if self._warm_converged and self._friction_converged else None
        return result

    def _repeat(self, held: tuple, omega: float) -> StepResult:
        """A step with the inputs of the last one, which ended at an equilibrium (``held``, :meth:`step`): its
        answer, with no Newton iteration (``iterations`` 0, as a solve started there reports), the signed torque
        at ``omega``; the warm starts kept as :meth:`_step` keeps those of a step that found the same state (the
        loads held in it: the next step's start goes on from this state along ``psi``)."""
        last = held[2]
        if last.distribution.iterations:           # made once for a run of held steps
            last = replace(last, distribution=replace(last.distribution, iterations=0))
            self._held = (held[0], held[1], last)
        self._previous, self._loads = self._warm, (self._loads[0], self._loads[0])
        if self.settings.friction_coefficient > 0.0:
            self._friction_previous = self._friction_warm
        magnitude = last.friction_torque_magnitude
        signed = regularised_torque(magnitude, omega, self.settings.omega_regularisation)
        self.last = StepResult(last.distribution, signed, magnitude)
        return self.last

    def _step(self, loads: Loads, psi: float, omega: float) -> StepResult:
        if psi != self._psi or self._warm is None:
            self.solver.set_rotation(psi)
        load = self.solver.scaled_load(loads)
        share = load_share(load, *self._loads)
        distribution = self.solver.solve(loads, initial=extrapolated_start(self._warm, self._previous, share))
        magnitude = self._seal_torque
        if self.settings.friction_coefficient > 0.0:
            initial = extrapolated_motion(self._friction_warm, self._friction_previous, share)
            capped = {} if distribution.converged else {"max_iterations": BOUNDED_FRICTION_ITERATIONS}
            friction = None
            if self._warm_friction is not None:          # the usual step: one compiled call, prepared
                friction = warm_torque(self._warm_friction, distribution, initial, self._seal_torque, **capped)
            if friction is None:    # the general path: with numpy's loops, BLAS products over every point
                with blas_threads(self.settings.blas_threads):
                    friction = friction_torque(self.bearing, distribution, mu=self.settings.friction_coefficient,
                                               omega=1.0, seal_torque=self.settings.seal_torque, initial=initial,
                                               tol=self.settings.friction_tolerance,
                                               kernel=self.settings.friction_kernel, **capped)
            magnitude = friction.magnitude
            converged = friction.converged and distribution.converged
            # a capped torque's motions (a flagged step's) are no point to extrapolate from or to
            self._friction_previous = self._friction_warm if converged and self._friction_converged else None
            self._friction_warm, self._friction_converged = friction.state, converged
        signed = regularised_torque(magnitude, omega, self.settings.omega_regularisation)
        if self.life is not None:       # the last that can fail: a step that raises leaves life as it was
            # a flagged step (an iterate) adds no damage: the accumulator keeps its ring angle and ball places
            # and counts their rolling with the next converged step's loads (LifeAccumulator.step says why)
            self.life.step(None, psi, distribution)
        # an iterate on its way (a bounded step) is no point of the trajectory to extrapolate from or to
        keep = distribution.converged and self._warm_converged
        self._previous = self._warm if keep else None
        self._warm = distribution.state
        self._loads = (load, self._loads[0] if keep else None)
        self._warm_converged = distribution.converged
        self._psi = psi
        self.last = StepResult(distribution, signed, magnitude)
        return self.last

    # ---- state -------------------------------------------------------------------
    def _checkpoint(self) -> tuple:
        """What a failed :meth:`step` restores (:meth:`_restore`): :meth:`get_state`'s entries as they are
        (none is changed in place), with no dictionary built (:meth:`get_state` took 17-22 us of the pitch
        bearing's NREL steps). Not the life accumulator's: its
        step is the step's last that can fail (:meth:`_step`), so a step that raises has not touched it
        (a checkpoint of it would make the raceway map copy itself at every step's update). Nor the held
        answer: :meth:`step` sets it only after the step succeeded."""
        return (self._warm, self._previous, self._loads, self._warm_converged, self._psi, self.solver.operator,
                self.solver.pending_operator, self._friction_warm, self._friction_previous, self._friction_converged)

    def _restore(self, checkpoint: tuple) -> None:
        """Back to a :meth:`_checkpoint`, as :meth:`set_state` restores a state."""
        (self._warm, self._previous, self._loads, self._warm_converged, self._psi, operator, pending,
         self._friction_warm, self._friction_previous, self._friction_converged) = checkpoint
        self.solver.set_rotation(self._psi)
        self.solver.operator, self.solver.pending_operator = operator, pending

    def get_state(self) -> dict:
        """Everything that affects the next step.

        Returns
        -------
        dict
            The warm start, the rotation ``psi`` (rad), the solver's reused Newton operator,
            the friction's ball motions and the life accumulator's state (numpy arrays, not
            copied: they are never changed in place). :func:`encode_state` makes it JSON data.

        Notes
        -----
        ``held`` is the last step's inputs and result where it ended at an equilibrium (:meth:`step`):
        objects, kept only as long as the state is in memory (an FMU's ``fmi2GetFMUstate``), so that a
        step repeated from the state repeats exactly; :func:`encode_state` leaves it out, and a state
        through JSON solves its first held step again (the same equilibrium, to round-off)."""
        operator, pending = self.solver.operator, self.solver.pending_operator
        return {"warm": self._warm, "previous": self._previous, "loads": list(self._loads),
                "warm_converged": self._warm_converged, "psi": self._psi,
                "operator": None if operator is None else operator.as_tuple(),
                "pending": None if pending is None else pending.as_tuple(), "friction": self._friction_warm,
                "friction_previous": self._friction_previous, "friction_converged": self._friction_converged,
                "life": None if self.life is None else self.life.get_state(), "held": self._held}

    def set_state(self, state: dict) -> None:
        """Restore a state.

        Parameters
        ----------
        state : dict
            What :meth:`get_state` returned (or :func:`decode_state` of its JSON form).
        """
        self._warm = None if state["warm"] is None else np.asarray(state["warm"], dtype=float)
        self._previous = None if state.get("previous") is None else np.asarray(state["previous"], dtype=float)
        self._loads = tuple(None if f is None else np.asarray(f, dtype=float)
                            for f in state.get("loads") or (None, None))
        self._warm_converged = bool(state.get("warm_converged", True))
        self._psi = float(state["psi"])
        self.solver.set_rotation(self._psi)
        self.solver.operator = None if state["operator"] is None else ReducedOperator.from_tuple(state["operator"])
        pending = state.get("pending")
        self.solver.pending_operator = None if pending is None else PendingOperator.from_tuple(pending)
        self._friction_warm = None if state["friction"] is None else np.asarray(state["friction"], dtype=float)
        previous = state.get("friction_previous")
        self._friction_previous = None if previous is None else np.asarray(previous, dtype=float)
        self._friction_converged = bool(state.get("friction_converged", True))
        if self.life is not None and state.get("life") is not None:
            self.life.set_state(state["life"])
        self._held = state.get("held")


def load_share(load, last_load, load_before) -> float:
    """The share of the last step's change that this step's loads repeat: their change projected on
    their last one, ``s = (f - f1) . (f1 - f0) / |f1 - f0|^2`` in [0, 1] (``f`` this step's scaled
    loads (:meth:`~slewing_model.distribution.bime.BimeSolver.scaled_load`), ``f1`` those of the last
    state, ``f0`` of the one before; :func:`extrapolated_start`). Loads that held in the last step
    (their change below :data:`HELD_LOADS` of their size) take the whole last change: the state then
    follows ``psi``; so do states kept before their loads were (``f1`` or ``f0`` None)."""
    if last_load is None or load_before is None:
        return 1.0
    change = last_load - load_before
    size = float(change @ change)
    if size <= (HELD_LOADS * float(np.max(np.abs(last_load)))) ** 2:
        return 1.0
    return min(max(float((load - last_load) @ change) / size, 0.0), 1.0)


def extrapolated_start(warm, previous, share=1.0):
    """The start of a step's solve: the last state ``warm`` carried on along its last change
    ``warm - previous`` as far as the loads go on along theirs, ``warm + share (warm - previous)``
    (``share``: :func:`load_share`; or an array that broadcasts against the states, a share per row).

    The states of slowly varying inputs lie on a smooth curve: started from ``2 warm - previous``
    the start error is of second order in the step (measured, it halves the Newton iterations).
    But a state is the equilibrium of its loads: where the loads jumped in the last step and
    hold in this one (a moment reversed, a load switched, the first step after a start at other
    loads), that extrapolation repeats the jump, a start as far off as the jump itself (after a
    moment reversal: 21 Newton iterations and 28 ms instead of none). So the last change is taken
    by the share of it that the loads repeat, the least-squares extrapolation of the inputs carried
    to the state. Without ``previous``: ``warm``."""
    if previous is None or warm is None or previous.shape != warm.shape:
        return warm
    return warm + share * (warm - previous)


def extrapolated_motion(warm, previous, share: float = 1.0):
    """The warm start of a step's friction torque (its balls' motions per unit of speed, (B, 4):
    ``FrictionTorque.state``): :func:`extrapolated_start` of the last two steps' motions, ball by ball
    where the ball rolled in both (a ball newly loaded, or unloaded, has no motion to carry on; it
    keeps the last one, which the friction torque starts cold where it is none).

    The balls' motions follow the loads as the load distribution does: carried on, the warm start of
    the pitch bearing's NREL series is within the friction's tolerance for most balls at once (one
    Newton iteration where two were usual: the balls' minimisation 241 -> 183 us a step, 243 -> 164
    us for turbulent loads). Where the friction of either
    step stopped short (a flagged step's, capped) there is no ``previous``: ``warm``."""
    if previous is None or warm is None or previous.shape != warm.shape:
        return warm
    rolled = (warm[:, ORBITAL] != 0.0) & (previous[:, ORBITAL] != 0.0)      # a loaded ball orbits
    return extrapolated_start(warm, previous, (share * rolled)[:, None])


#: the entries of :meth:`BearingSimulator.get_state` kept in memory only: :func:`encode_state` leaves them out
MEMORY_ONLY = ("held",)


def encode_state(value):
    """JSON-ready copy of a state: numpy arrays become ``{"__array__": dtype, "shape", "data": hex}``
    (exact, unlike decimal text); the entries :data:`MEMORY_ONLY` are left out."""
    if isinstance(value, np.ndarray):
        return {"__array__": value.dtype.str, "shape": list(value.shape), "data": value.tobytes().hex()}
    if isinstance(value, dict):
        return {k: encode_state(v) for k, v in value.items() if k not in MEMORY_ONLY}
    if isinstance(value, (list, tuple)):
        return [encode_state(v) for v in value]
    return value


def decode_state(value):
    """Inverse of :func:`encode_state`."""
    if isinstance(value, dict):
        if "__array__" in value:
            return np.frombuffer(bytes.fromhex(value["data"]), dtype=value["__array__"]).reshape(value["shape"]).copy()
        return {k: decode_state(v) for k, v in value.items()}
    if isinstance(value, list):
        return [decode_state(v) for v in value]
    return value
