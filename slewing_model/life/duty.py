"""Life and wear of a run: the step-by-step accumulator (FMU, studies) and the run's analysis.

:class:`LifeModel` holds what does not change during a run (the tracks' ``Qc``, critical
angles, which ring turns relative to the load). :class:`LifeAccumulator` takes each step's
load distribution: it adds the raceway map's passes (:mod:`.raceway_map`), detects completed
half-cycles of the ring angle online (a reversal of ``ψ`` by more than a tolerance) and gives
their ``x/2b``; with ``record=True`` it also keeps a few numbers per step and track for
:func:`analyse_run`, which counts the run's cycles by rainflow and returns the ISO/TS 16281
life with the oscillation rule, the raceway map's life, DG03's life, and the wear indicators.

Which ring turns relative to the load (ISO/TS 16281's choice of the ``Qe`` exponent): loads
given in the fixed ring's frame stand relative to the fixed ring, so the moving ring turns
relative to them; loads in the moving ring's frame (blade-root loads of a pitch bearing)
turn with it, so the fixed ring turns relative to them.

Run-time module: numpy and the standard library (``rainflow`` in :func:`analyse_run`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..numerics.compiled import use_compiled
from .dg03 import DG03Life, dg03_life, equivalent_axial_load
from .kernel import compiled_widest_contacts
from .oscillation import critical_angle, equivalent_revolutions, rainflow_cycles, span_mean
from .rating import TRACK_RINGS, LifeInputError, axial_rating, combined_damage, equivalent_load, \
    four_point_capacities
from .raceway_map import DEFAULT_SLICES, RacewayMap, default_slices, passes_per_revolution, track_damage
from .wear import rolling_travel, relubrication_gap

#: default reversal tolerance of the online half-cycle detector and smallest rainflow swing, rad:
#: above the 16-bit quantisation of recorded pitch angles (about 5e-6 rad over 18°)
DEFAULT_REVERSAL_TOLERANCE = 1e-5
#: a rainflow cycle is a micro-cycle, left out of the x/2b and critical-angle shares counted by cycles,
#: when its swing is below this many steps of the series' angle resolution (:func:`angle_resolution`,
#: the recording's quantisation step): each of a cycle's two reversals is
#: rounded by up to half a step, so a swing of 10 steps is known to ±10 %, and shorter ones are mostly
#: rounding (the FAST v8 pitch series: steps of 2.1e-6 rad, its smallest cycles 7 steps)
MICRO_CYCLE_STEPS = 10
#: changes of ψ between samples below this are rounding of the number format, not of the recording, rad
_ANGLE_NOISE = 1e-12
#: largest plausible speed of a pitch or yaw bearing's ring, rad/s (28.6 deg/s): pitch systems feather at
#: up to about 10 deg/s, yaw drives turn at about 0.5 deg/s; a series in degrees read as radians shows
#: 57.3 times its speed, so a blade pitching at 0.5 deg/s already exceeds it
PLAUSIBLE_SPEED = 0.5
#: largest plausible range of ψ of a run, rad: a pitch bearing turns through at most about 95 deg; a pitch
#: series of more than 6.3 deg in degrees read as radians exceeds one revolution
PLAUSIBLE_RANGE = 2 * math.pi


@dataclass(frozen=True)
class LifeSettings:
    """What a user sets for a life calculation (SI units).

    Attributes
    ----------
    rating : float or None
        Basic dynamic axial rating ``Ca`` of the bearing, N (ISO 281, from the maker's catalogue);
        None (default): from the raceway geometry (:func:`slewing_model.life.rating.axial_rating`).
    slices : int or None
        Slices of each track in the raceway map (>= 4); None (default):
        :func:`~slewing_model.life.raceway_map.default_slices` of the bearing's ball count
        (at least 1440, with no common divisor with Z: no aliasing).
    reversal_tolerance : float
        Smallest movement against the current direction that counts as a reversal of ``ψ``
        (online half-cycles), and smallest rainflow swing kept, rad. Default 1e-5, above the
        16-bit quantisation of recorded pitch angles.
    relubrication_swing : float or None
        Movement that relubricates the raceway, rad; None (default): the largest critical
        angle of the tracks (a swing over which neighbouring balls' tracks overlap, so the
        balls spread the grease over the whole raceway).
    rating_factor : callable or None
        ``f(theta, Z)`` (``theta`` in rad) raising the rating below the critical angle;
        None (default): DG03's ``(180°/θ)^(3/10) Z^0.033``.

    Raises
    ------
    LifeInputError
        If a value is out of its range.
    """

    rating: float | None = None
    slices: int | None = None
    reversal_tolerance: float = DEFAULT_REVERSAL_TOLERANCE
    relubrication_swing: float | None = None
    rating_factor: object = None

    def __post_init__(self):
        if self.slices is not None and (isinstance(self.slices, bool) or not isinstance(self.slices, (int, np.integer))
                                        or self.slices < 4):
            raise LifeInputError(f"slices = {self.slices!r}: must be a whole number >= 4, or None (the default)")
        if self.rating is not None and not (math.isfinite(self.rating) and self.rating > 0):
            raise LifeInputError(f"rating = {self.rating!r}: must be finite and > 0 (N), or None")
        if not (math.isfinite(self.reversal_tolerance) and self.reversal_tolerance > 0):
            raise LifeInputError(f"reversal_tolerance = {self.reversal_tolerance!r}: must be finite and > 0 (rad)")
        if self.relubrication_swing is not None and not (math.isfinite(self.relubrication_swing)
                                                         and self.relubrication_swing > 0):
            raise LifeInputError(f"relubrication_swing = {self.relubrication_swing!r}: must be finite and > 0 (rad)")


class LifeModel:
    """The run-independent part of a four-point bearing's life calculation.

    The tracks' capacities, critical angles and which ring turns relative to the load:
    loads given in the fixed ring's frame stand relative to the fixed ring, so the moving
    ring turns relative to them; loads in the moving ring's frame (blade-root loads of a
    pitch bearing) turn with it, so the fixed ring turns relative to them.

    Parameters
    ----------
    bearing : Bearing
        The bearing definition.
    moving_ring : {"inner", "outer"}, optional
        The ring that turns by ``psi``; default the bearing's.
    load_frame : {"fixed", "rotating"}, optional
        Frame of the loads. Default "fixed".
    settings : LifeSettings, optional
        Default ``LifeSettings()``.

    Attributes
    ----------
    capacity : ndarray, shape (4,)
        ``Qc`` of contacts 1..4, N.
    rating : float
        Axial rating ``Ca``, N.
    critical : ndarray, shape (4,)
        Critical angle of each track, rad.
    rotating : ndarray of bool, shape (4,)
        Tracks whose ring turns relative to the load.
    relubrication_swing : float
        Swing that relubricates, rad.
    slices : int
        Slices of each track in the raceway map.

    Raises
    ------
    LifeInputError
        If ``load_frame`` is unknown.
    """

    def __init__(self, bearing, moving_ring: str | None = None, load_frame: str = "fixed",
                 settings: LifeSettings | None = None):
        if load_frame not in ("fixed", "rotating"):
            raise LifeInputError(f"load_frame = {load_frame!r}: must be 'fixed' or 'rotating'")
        self.bearing = bearing
        self.settings = settings or LifeSettings()
        self.moving_ring = moving_ring or bearing.moving_ring
        self.capacity = four_point_capacities(bearing, self.settings.rating)          # Qc, (4,)
        self.rating = axial_rating(bearing, self.capacity)                            # Ca
        self.passes = passes_per_revolution(bearing.ball_count, bearing.ball_diameter, bearing.pitch_diameter,
                                            bearing.contact_angle)
        self.critical = np.array([float(critical_angle(bearing.ball_count, bearing.ball_diameter,
                                                       bearing.pitch_diameter, bearing.contact_angle, r))
                                  for r in TRACK_RINGS])
        moving = np.array([r == self.moving_ring for r in TRACK_RINGS])
        self.rotating = moving if load_frame == "fixed" else ~moving                 # turns relative to the load
        self.relubrication_swing = self.settings.relubrication_swing or float(self.critical.max())
        self.slices = self.settings.slices or default_slices(bearing.ball_count)

    def track_standing_loads(self, contact_load) -> np.ndarray:
        """``Qe`` of the four tracks at one step with the exponent 10/3 of a ring standing relative to the load.

        What a swing below a track's critical angle makes of every track (each point of the
        raceway meets only the balls next to it, see :func:`analyse_run`).

        Parameters
        ----------
        contact_load : array_like, shape (B, 4)
            Contact loads of contacts 1..4, N.

        Returns
        -------
        ndarray, shape (4,)
            ``Qe``, N.
        """
        q = np.asarray(contact_load, dtype=float)
        return np.array([float(equivalent_load(q[:, k], False)) for k in range(4)])

    def track_equivalent_loads(self, contact_load) -> np.ndarray:
        """ISO/TS 16281 ``Qe`` of the four tracks at one step.

        Parameters
        ----------
        contact_load : array_like, shape (B, 4)
            Contact loads of contacts 1..4, N.

        Returns
        -------
        ndarray, shape (4,)
            ``Qe``, N, each with the exponent of its ring (turning or standing relative to the load).
        """
        q = np.asarray(contact_load, dtype=float)
        return np.array([float(equivalent_load(q[:, k], bool(self.rotating[k]))) for k in range(4)])


#: the per-step numbers :class:`LifeAccumulator` records (``record=True``), per track where (4,)
RECORD_FIELDS = ("time", "psi", "qe", "qe_standing", "b_max", "angle_at_b_max", "p_max", "pea")


@dataclass
class HalfCycles:
    """State of the online half-cycle detector of ``ψ``."""

    direction: float = 0.0          # +1, -1, 0 before the first movement
    turn: float = math.nan          # ψ at the last reversal
    extreme: float = math.nan       # furthest ψ since then
    b_max: np.ndarray = field(default_factory=lambda: np.zeros(4))      # largest b per track since, m
    angle: np.ndarray = field(default_factory=lambda: np.zeros(4))      # contact angle at it, rad
    last_ratio: float = math.nan    # x/2b of the last completed half-cycle
    last_swing: float = 0.0         # its swing, rad
    completed: int = 0


class LifeAccumulator:
    """Step-by-step life and wear of one bearing (what the FMU carries; plain numpy state).

    It adds the raceway map's passes (:class:`RacewayMap`), detects completed half-cycles
    of the ring angle online (a reversal of ``ψ`` by more than a tolerance) and gives their
    ``x/2b``; with ``record=True`` it also keeps a few numbers per step and track for
    :func:`analyse_run`.

    Parameters
    ----------
    model : LifeModel
        The bearing's capacities and settings.
    record : bool, optional
        Keep the per-step numbers :func:`analyse_run` needs (time, ``psi``, ``Qe`` per track,
        widest patch, largest pressure, DG03's ``Pea``). Default False.
    kernel : {"numpy", "auto", "compiled"}, optional
        How the raceway map adds a step's passes (``kernel`` of :class:`RacewayMap`).
        Default "numpy".

    Attributes
    ----------
    map : RacewayMap
        The raceway damage map.

    Examples
    --------
    A rigid-ring run of 10 s, the ring swinging ±0.05 rad at 0.5 Hz under a constant load:

    >>> import numpy as np
    >>> from slewing_model import load_bearing, Loads
    >>> from slewing_model.simulation import BearingSimulator, SimulatorSettings
    >>> from slewing_model.life import LifeAccumulator, LifeModel, analyse_run
    >>> bearing = load_bearing("examples/bearings/table3.toml")
    >>> sim = BearingSimulator(bearing, settings=SimulatorSettings(ring_model="rigid",
    ...                                                            friction_coefficient=0.0))
    >>> acc = LifeAccumulator(LifeModel(bearing), record=True)
    >>> loads = Loads(Fz=5e4, My=2e4)
    >>> for t in np.arange(0.0, 10.0, 0.05):
    ...     psi = 0.05 * np.sin(np.pi * t)
    ...     acc.step(t, psi, sim.step(loads, psi, 0.0).distribution, loads.as_array())
    >>> result = analyse_run(acc)
    >>> result.worst_track, f"{result.life_hours:.3g} h"
    (3, '1.08e+06 h')
    """

    def __init__(self, model: LifeModel, record: bool = False, kernel: str = "numpy"):
        self.model = model
        self.map = RacewayMap(model.capacity, model.passes, model.moving_ring, model.slices, kernel=kernel)
        self._compiled = use_compiled(kernel, "kernel")
        self.half = HalfCycles()
        self.record = record
        self.rows: list = []
        #: the flagged steps not yet counted (:meth:`step`): ``[time, psi, ball_angle, loads]`` each
        self._pending: list = []
        self._waiting = 0               # flagged steps behind them (a monotone stretch is kept as its ends)

    # ---- one step ------------------------------------------------------------------------
    def step(self, time: float, psi: float, distribution, loads=None) -> None:
        """Add a step.

        A step whose load distribution is not an equilibrium (``distribution.converged`` False: a
        bounded step's iterate, ``step_work="bounded"``) adds no damage from its loads: its ring angle
        and ball places are kept, and the next converged step counts the rolling of the flagged steps
        with its own load distribution (:meth:`_count`), before its own.

        Why the next equilibrium and not the last one: the flagged steps follow a sudden change of the
        loads (a moment reversed, a load switched), and the bearing carries the new loads in them, the
        solver only lags behind. The next converged step is the equilibrium of those new loads (of the
        same loads where they hold, as after a reversal: then the damage is the complete steps'); the
        last equilibrium is that of the loads before the change: after a reversal it loads the
        opposite diagonal, so it would put the flagged steps' damage on the wrong tracks. The balls
        roll over the raceway in the flagged steps either way: their rolled angle is counted, not
        dropped. An iterate is no load to count: after a moment reversal its largest ball load is up
        to several times the equilibrium's, and its damage goes with the cube of that.

        Parameters
        ----------
        time : float
            Time of the step, s (used only when recording).
        psi : float
            Rotation of the moving ring, rad.
        distribution : LoadDistribution
            The step's load distribution.
        loads : array_like, shape (>= 5,), optional
            Loads ``(Fx, Fy, Fz, Mx, My)``, N and N m, for DG03's equivalent load
            (``record`` only).
        """
        d = distribution
        if not getattr(d, "converged", True):
            self._defer(time, psi, d.ball_angle, loads)
            return
        widest, widest_angle = self._widest_contacts(d.semi_axis_b, d.contact_angle)
        if self._pending:
            for when, angle, balls, given in self._pending:
                self._count(when, angle, balls, d, widest, widest_angle, given)
            self._pending, self._waiting = [], 0
        self._count(time, psi, d.ball_angle, d, widest, widest_angle, loads)

    def _count(self, time, psi, ball_angle, d, widest, widest_angle, loads) -> None:
        """Add the passes up to the ring angle ``psi`` and ball places ``ball_angle`` with the loads of the
        equilibrium ``d`` (its widest patches ``widest``, ``widest_angle``), and the half-cycles of ``psi``."""
        self.map.update(ball_angle, psi, d.contact_load)
        self._half_cycle(psi, widest, widest_angle)
        if self.record:
            pea = float(equivalent_axial_load(np.asarray(loads, float)[:5], self.model.bearing.pitch_diameter)[0]) \
                if loads is not None else math.nan
            self.rows.append((time, psi, self.model.track_equivalent_loads(d.contact_load),
                              self.model.track_standing_loads(d.contact_load), widest,
                              widest_angle, d.contact_pressure.max(axis=0), pea))

    def _defer(self, time, psi, ball_angle, loads) -> None:
        """Keep a flagged step's ring angle and ball places for the next converged step (:meth:`step`).

        Where ``psi`` goes on the same way as over the last two kept steps (and every ball's place on
        both rings with it), the last kept step is replaced, not added to: under one load the passes
        and half-cycles of a monotone stretch are those of its ends, so a long flagged stretch keeps
        only its reversals. The first kept step stays: the pass to it carries the mean of the last
        equilibrium's ``Q^3`` and the next one's, as in the complete steps. Not while recording (a row
        a step)."""
        angle = np.array(ball_angle, dtype=float)
        point = [time, float(psi), angle, None if loads is None else np.array(loads, dtype=float)]
        self._waiting += 1
        pending = self._pending
        if not self.record and len(pending) >= 2:
            (_, psi0, angle0, _), (_, psi1, angle1, _) = pending[-2], pending[-1]
            if ((psi1 - psi0) * (psi - psi1) >= 0.0 and np.all((angle1 - angle0) * (angle - angle1) >= 0.0)
                    and np.all((angle1 - psi1 - angle0 + psi0) * (angle - psi - angle1 + psi1) >= 0.0)):
                pending[-1] = point
                return
        pending.append(point)

    @property
    def pending_steps(self) -> int:
        """Flagged steps whose rolling waits for the next converged step (:meth:`step`); 0 after it."""
        return self._waiting

    def _widest_contacts(self, semi_b, contact_angle):
        """The widest patch of each track this step (4,) and its contact angle (4,)."""
        if self._compiled:
            return compiled_widest_contacts()(np.ascontiguousarray(semi_b, dtype=float),
                                              np.ascontiguousarray(contact_angle, dtype=float))
        j, cols = np.argmax(semi_b, axis=0), np.arange(semi_b.shape[1])
        return semi_b[j, cols], contact_angle[j, cols]

    def _half_cycle(self, psi, b, angle) -> None:
        h, tol = self.half, self.model.settings.reversal_tolerance
        if h.direction == 0.0:
            if math.isnan(h.turn):
                h.turn = h.extreme = psi
                h.b_max, h.angle = b.copy(), angle.copy()
                return
            if abs(psi - h.turn) > tol:
                h.direction = math.copysign(1.0, psi - h.turn)
                h.extreme = psi
            self._widest(b, angle)
            return
        if (psi - h.extreme) * h.direction >= 0.0:                  # still going the same way
            h.extreme = psi
            self._widest(b, angle)
            return
        if (h.extreme - psi) * h.direction <= tol:                  # a small step back: not yet a reversal
            self._widest(b, angle)
            return
        swing = abs(h.extreme - h.turn)                             # a half-cycle completed at the extreme
        loaded = h.b_max > 0.0
        if np.any(loaded):
            x = rolling_travel(swing, self.model.bearing.pitch_diameter, self.model.bearing.ball_diameter,
                               h.angle[loaded])
            h.last_ratio = float(np.min(x / (2.0 * h.b_max[loaded])))
        h.last_swing, h.completed = swing, h.completed + 1
        h.turn, h.extreme, h.direction = h.extreme, psi, -h.direction
        h.b_max, h.angle = b.copy(), angle.copy()

    def _widest(self, b, angle) -> None:
        h = self.half
        wider = b > h.b_max
        h.b_max = np.where(wider, b, h.b_max)
        h.angle = np.where(wider, angle, h.angle)

    # ---- outputs -------------------------------------------------------------------------
    @property
    def track_damage(self) -> np.ndarray:
        """Raceway-map damage of contacts 1..4 so far (weakest link over the slices), shape (4,)."""
        return self.map.track_damage()

    @property
    def worst_damage(self) -> float:
        """Damage of the worst track so far (1: its L10 is used up)."""
        return self.map.worst_track_damage()

    @property
    def last_ratio(self) -> float:
        """``x/2b`` of the last completed half-cycle (NaN before the first)."""
        return self.half.last_ratio

    # ---- state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """The accumulator's state: the raceway map's, the half-cycle detector's, the number of recorded rows and
        the flagged steps not yet counted (:meth:`step`)."""
        h = self.half
        return {"map": self.map.get_state(),
                "half": {"direction": h.direction, "turn": h.turn, "extreme": h.extreme, "b_max": h.b_max,
                         "angle": h.angle, "last_ratio": h.last_ratio, "last_swing": h.last_swing,
                         "completed": h.completed},
                "rows": len(self.rows), "pending": [list(p) for p in self._pending], "waiting": self._waiting}

    def set_state(self, state: dict) -> None:
        """Restore a state of :meth:`get_state`; recorded rows after it are dropped."""
        self.map.set_state(state["map"])
        s = state["half"]
        self.half = HalfCycles(float(s["direction"]), float(s["turn"]), float(s["extreme"]),
                               np.array(s["b_max"], dtype=float), np.array(s["angle"], dtype=float),
                               float(s["last_ratio"]), float(s["last_swing"]), int(s["completed"]))
        del self.rows[int(state.get("rows", len(self.rows))):]
        self._pending = [[None if t is None else float(t), float(p), np.array(a, dtype=float),
                          None if f is None else np.array(f, dtype=float)] for t, p, a, f in state.get("pending") or []]
        self._waiting = int(state.get("waiting", len(self._pending)))

    def records(self) -> dict:
        """The recorded steps as arrays.

        Returns
        -------
        dict of ndarray
            ``time`` (s), ``psi`` (rad), ``qe`` and ``qe_standing`` (N, per track),
            ``b_max`` (m) and ``angle_at_b_max`` (rad) of the widest patch, ``p_max`` (Pa)
            and ``pea`` (N), one row a step.

        Raises
        ------
        LifeInputError
            If no step was recorded.
        """
        if not self.rows:
            raise LifeInputError("records: no steps were recorded (record=True and at least one step)")
        cols = list(zip(*self.rows))
        return {name: np.array(c, dtype=float) for name, c in zip(RECORD_FIELDS, cols)}


@dataclass(frozen=True)
class LifeResult:
    """Life and wear of one run (SI units; hours of the run's duty repeated).

    Attributes
    ----------
    duration : float, s
        Duration of the run.
    track_damage : ndarray (4,)
        ISO/TS 16281 loads with the oscillation rule: damage of contacts 1..4 over the run.
    damage : float
        The bearing's (tracks combined by the weakest link).
    life_hours : float, h
        ``duration / damage`` (inf: no damage).
    worst_track : int or None
        Contact 1..4 with the largest damage; None when nothing was damaged (the ring never moved).
    map_track_damage : ndarray (4,)
        Damage of contacts 1..4 from the raceway map.
    map_damage : float
        The bearing's damage from the raceway map.
    map_life_hours : float, h
        Life from the raceway map.
    damage_map : ndarray (4, slices)
        Damage of every slice of the four tracks.
    dg03 : DG03Life
        NREL DG03's catalogue life of the same run.
    swing, count : ndarray
        Rainflow cycles (rad; 1 or 0.5).
    below_critical : float
        Share of the cycles (by count, micro-cycles left out) whose swing is below the inner
        raceway's critical angle; NaN without such cycles.
    travel_ratio : ndarray
        ``x/2b`` of each cycle (the smallest over the loaded tracks).
    share_below_one : float
        Share of the cycles (by count, micro-cycles left out) with ``x/2b < 1``; NaN without such cycles.
    track_travel_ratio : ndarray (cycles, 4)
        ``x/2b`` of each cycle and contact 1..4 (the contact's widest patch in the cycle; inf: unloaded).
    cycle_peak_pressure : ndarray (cycles, 4), Pa
        Largest Hertz pressure of each contact in each cycle.
    peak_pressure : ndarray (4,), Pa
        Largest Hertz pressure of each track over the run.
    relubrication_gap : float, s
        Longest time without a movement of ``relubrication_swing``.
    relubrication_swing : float, rad
        The movement that counts as relubricating.
    cycle_damage : ndarray (cycles, 4)
        Damage of each cycle on contacts 1..4 (the terms of ``track_damage``).
    micro_swing : float, rad
        Swing below which a cycle is a micro-cycle (10 steps, ``MICRO_CYCLE_STEPS``, of the series'
        angle resolution, at least the reversal tolerance).
    micro_cycles : float
        Number of micro-cycles (by count).
    damage_share_below_one, damage_share_below_critical : float
        The two shares weighted by each cycle's damage on the worst track instead of counted (every
        cycle, micro-cycles too: they weigh what they damage); NaN without damage.
    warnings : tuple of str
        Plausibility warnings on the series (:func:`motion_warnings`).
    """

    duration: float
    track_damage: np.ndarray
    damage: float
    life_hours: float
    worst_track: int | None
    map_track_damage: np.ndarray
    map_damage: float
    map_life_hours: float
    damage_map: np.ndarray
    dg03: DG03Life
    swing: np.ndarray
    count: np.ndarray
    below_critical: float
    travel_ratio: np.ndarray
    share_below_one: float
    track_travel_ratio: np.ndarray
    cycle_peak_pressure: np.ndarray
    peak_pressure: np.ndarray
    relubrication_gap: float
    relubrication_swing: float
    cycle_damage: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    micro_swing: float = 0.0
    micro_cycles: float = 0.0
    damage_share_below_one: float = math.nan
    damage_share_below_critical: float = math.nan
    warnings: tuple = ()

    @property
    def dg03_ratio(self) -> float:
        """DG03's life over ours (NaN when neither has damage: no cycles)."""
        if math.isinf(self.life_hours) and math.isinf(self.dg03.hours):
            return math.nan
        return self.dg03.hours / self.life_hours if self.life_hours > 0 else math.nan

    def summary(self) -> dict:
        """The numbers of a study's summary row.

        Returns
        -------
        dict
            ``life_L10_h``, ``life_map_L10_h``, ``life_dg03_L10_h`` (h), ``life_damage_per_h``
            (1/h), the worst track, the DG03 ratio, the cycle count, shares and the
            relubrication gap (s). None where a value does not exist (no worst track without
            damage, no ratio or share without cycles); inf: no damage, an infinite life.
        """
        def value(x):
            return None if x is None or (isinstance(x, float) and math.isnan(x)) else x

        return {
            "life_L10_h": self.life_hours, "life_worst_track": self.worst_track,
            "life_damage_per_h": value(self.damage / self.duration * 3600.0 if self.duration > 0 else math.nan),
            "life_map_L10_h": self.map_life_hours, "life_dg03_L10_h": self.dg03.hours,
            "life_dg03_ratio": value(self.dg03_ratio),
            "life_cycles": float(self.count.sum()), "life_share_x2b_below_1": value(self.share_below_one),
            "life_share_below_critical": value(self.below_critical), "life_relubrication_gap_s": self.relubrication_gap,
            "life_micro_cycles": self.micro_cycles,
            "life_damage_share_x2b_below_1": value(self.damage_share_below_one),
            "life_damage_share_below_critical": value(self.damage_share_below_critical),
        }


def _hours(duration, damage):
    return duration / damage / 3600.0 if damage > 0 else math.inf


def angle_resolution(psi) -> float:
    """The recording's angle resolution (quantisation step) of ``psi``, rad; 0 when the series shows none.

    The smallest change of ``psi`` between samples above rounding of the number format, ``q``, is taken
    as the recording's step when the series shows that it is one: the changes are whole multiples of
    ``q`` (95 % of the changes up to 20 q within 5 % of a whole multiple; ``q`` is the mean of the
    changes within 10 % of the smallest, as the written digits round it) and not all of one size
    (some are 2 q or more). A smoothly sampled angle (changes that are
    not multiples of its smallest one) or an evenly stepped one (every change the same: the sampling's
    grid, not a recording's) has none."""
    step = np.abs(np.diff(np.asarray(psi, dtype=float)))
    step = step[step > _ANGLE_NOISE]
    if step.size == 0:
        return 0.0
    q = float(step[step < 1.1 * step.min()].mean())     # one step, averaged over the written digits' rounding
    k = step[step < 20.5 * q] / q                       # the small changes, where a quantisation shows
    whole = np.abs(k - np.round(k)) < 0.05
    return q if whole.mean() >= 0.95 and np.any(k >= 1.95) else 0.0


def motion_warnings(time, psi) -> list[str]:
    """Plausibility of a pitch or yaw bearing's ring angle ``psi`` (rad) over ``time`` (s): a speed
    above :data:`PLAUSIBLE_SPEED` or a range above :data:`PLAUSIBLE_RANGE` most likely means an
    angle given in degrees (the lives then come out far too short). Messages name the value and the rule."""
    t, p = np.asarray(time, dtype=float), np.asarray(psi, dtype=float)
    out = []
    if p.size > 1:
        speed = np.abs(np.diff(p) / np.diff(t))
        k = int(np.argmax(speed))
        if speed[k] > PLAUSIBLE_SPEED:
            out.append(f"psi changes at {speed[k]:.3g} rad/s ({math.degrees(speed[k]):.3g} deg/s) at t = {t[k]:.6g} s, "
                       f"more than the {PLAUSIBLE_SPEED:g} rad/s a pitch or yaw bearing turns: is psi in degrees? "
                       f"It must be in rad")
        span = float(p.max() - p.min())
        if span > PLAUSIBLE_RANGE:
            out.append(f"psi spans {span:.4g} rad ({math.degrees(span):.4g} deg), more than one revolution "
                       f"({PLAUSIBLE_RANGE:.4g} rad): is psi in degrees? It must be in rad (a yaw bearing that "
                       f"really turned that far may ignore this)")
    return out


def analyse_run(accumulator: LifeAccumulator) -> LifeResult:
    """Life and wear of a recorded run (``LifeAccumulator(record=True)`` stepped through it).

    The equivalent load of a track in a cycle: ISO/TS 16281's ``Qe`` of its ring, except under a
    swing below the track's critical angle, where a ring that turns relative to the load is
    treated as standing (exponent 10/3): a point of its raceway is then rolled over only by the
    ball next to it, meeting the load at its own place again and again, never the others --
    exactly ISO's situation of a standing ring. ISO's exponent 3 would understate its damage by
    ``(Qe,10/3 / Qe,3)^3`` (1.139 for the rigid-ring moment distribution ``Q ∝ cos^1.5 φ``;
    see the user guide's life and wear page).

    Needs the ``rainflow`` package.

    Parameters
    ----------
    accumulator : LifeAccumulator
        Stepped through the run with ``record=True``.

    Returns
    -------
    LifeResult
        ISO/TS 16281 life with the oscillation rule, the raceway map's life, DG03's life and
        the wear indicators; hours of the run's duty repeated.

    Raises
    ------
    LifeInputError
        If no step was recorded.
    """
    m, r = accumulator.model, accumulator.records()
    t, psi = r["time"], r["psi"]
    duration = float(t[-1] - t[0])
    tol = m.settings.reversal_tolerance
    cyc = rainflow_cycles(psi, min_swing=tol)
    w = np.abs(np.diff(psi, prepend=psi[0]))                       # the ring's rotation at each sample
    below_track = cyc.swing[:, None] < m.critical[None, :]         # (cycles, 4): the swing below the track's
    qe = np.where(below_track, span_mean(r["qe_standing"], w, cyc.start, cyc.end),
                  span_mean(r["qe"], w, cyc.start, cyc.end))      # (cycles, 4), N
    rev = equivalent_revolutions(cyc.swing[:, None], m.critical[None, :], m.bearing.ball_count,
                                 m.settings.rating_factor)        # (cycles, 4)
    cycle_damage = cyc.count[:, None] * rev * (qe / m.capacity) ** 3 / 1e6
    track = np.sum(cycle_damage, axis=0)
    damage = float(combined_damage(track))
    map_track = accumulator.track_damage
    map_damage = float(combined_damage(map_track))

    b, ang, pmax = r["b_max"], r["angle_at_b_max"], r["p_max"]
    track_ratio = np.full((cyc.swing.size, 4), np.inf)            # x/2b per cycle and track (inf: unloaded)
    cycle_pressure = np.zeros((cyc.swing.size, 4))
    cols = np.arange(4)
    for i, (s, e) in enumerate(zip(cyc.start, cyc.end)):
        bb = b[s:e + 1]
        k = np.argmax(bb, axis=0)                                  # the widest patch of each track in the cycle
        bmax, a = bb[k, cols], ang[s:e + 1][k, cols]
        loaded = bmax > 0
        x = rolling_travel(cyc.swing[i], m.bearing.pitch_diameter, m.bearing.ball_diameter, a[loaded])
        track_ratio[i, loaded] = x / (2 * bmax[loaded])
        cycle_pressure[i] = pmax[s:e + 1].max(axis=0)
    ratio = track_ratio.min(axis=1) if cyc.swing.size else np.zeros(0)
    micro_swing = max(tol, MICRO_CYCLE_STEPS * angle_resolution(psi))
    counted = cyc.swing >= micro_swing
    total = float(cyc.count[counted].sum())
    share = float(cyc.count[counted & (ratio < 1.0)].sum() / total) if total else math.nan
    below = float(cyc.count[counted & (cyc.swing < m.critical.min())].sum() / total) if total else math.nan
    worst = int(np.argmax(track)) if damage > 0 else None
    weight = cycle_damage[:, worst] if worst is not None else np.zeros(cyc.swing.size)
    weight_sum = float(weight.sum())
    d_share = float(weight[ratio < 1.0].sum() / weight_sum) if weight_sum > 0 else math.nan
    d_below = float(weight[cyc.swing < m.critical.min()].sum() / weight_sum) if weight_sum > 0 else math.nan

    pea = span_mean(r["pea"], w, cyc.start, cyc.end) if np.all(np.isfinite(r["pea"])) else np.full(cyc.swing.size,
                                                                                                      math.nan)
    dg = dg03_life(pea, cyc.swing, cyc.count, m.rating, m.bearing.ball_count, float(m.critical.max()), duration)
    return LifeResult(
        duration=duration, track_damage=track, damage=damage, life_hours=_hours(duration, damage),
        worst_track=None if worst is None else worst + 1, map_track_damage=map_track, map_damage=map_damage,
        map_life_hours=_hours(duration, map_damage), damage_map=accumulator.map.damage_map.copy(), dg03=dg,
        swing=cyc.swing, count=cyc.count, below_critical=below, travel_ratio=ratio, share_below_one=share,
        track_travel_ratio=track_ratio, cycle_peak_pressure=cycle_pressure,
        peak_pressure=r["p_max"].max(axis=0),
        relubrication_gap=relubrication_gap(t, psi, m.relubrication_swing),
        relubrication_swing=m.relubrication_swing, cycle_damage=cycle_damage, micro_swing=micro_swing,
        micro_cycles=float(cyc.count[~counted].sum()), damage_share_below_one=d_share,
        damage_share_below_critical=d_below, warnings=tuple(motion_warnings(t, psi)))


def life_files(res, model) -> dict:
    """What :func:`slewing_model.study.engine.write_life` writes of a run (maps, cycles, summary): plain
    arrays and numbers of ``res`` (:class:`LifeResult`) and ``model`` (:class:`LifeModel`)."""
    return {"damage_map": res.damage_map, "swing": res.swing, "count": res.count,
            "travel_ratio": res.travel_ratio, "track_travel_ratio": res.track_travel_ratio,
            "cycle_peak_pressure": res.cycle_peak_pressure, "critical_angle": model.critical,
            "cycle_damage": res.cycle_damage,
            "summary": {"track_damage": res.track_damage, "map_track_damage": res.map_track_damage,
                        "duration_s": res.duration, "life_L10_h": res.life_hours,
                        "life_map_L10_h": res.map_life_hours, "life_dg03_L10_h": res.dg03.hours,
                        "life_dg03_ratio": res.dg03_ratio, "life_worst_track": res.worst_track,
                        "micro_swing_rad": res.micro_swing, "warnings": list(res.warnings)}}
