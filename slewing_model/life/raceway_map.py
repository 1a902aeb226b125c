"""Raceway damage map: each track cut into slices around its ring, each slice damaged by the
balls that roll over it, with their loads.

Derivation (the weakest-link combination used)
    Lundberg–Palmgren give the survival of a stressed volume as
    ``ln(1/S) ∝ N^e V`` (Weibull slope ``e = 10/9`` of ball bearings) and, at one point of a
    raceway under loads that change from pass to pass, Miner's rule with the load-life
    exponent 3: a pass under load ``Q`` uses ``(Q/Qc)^3`` of what the raceway's rating
    promises. So slice ``j`` of a track (a share ``1/N`` of its circumference) carries the
    damage

        ``d_j = Σ_passes (Q_p / Qc)^3 / (m 10^6)``,

    where ``m = Z (1 ± γ)/2`` is the number of passes a point of the raceway receives per
    revolution of the rings relative to each other (upper sign inner ring): ``Qc`` is defined
    per revolution (ISO/TS 16281), so ``d_j = 1`` is one rating life of a point that is passed
    as in rotation. The slices are independent Weibull volumes,
    ``ln(1/S) = ln(1/0.9) Σ_j (1/N) d_j^e``, so the track's damage (``S = 0.9`` at ``D_k = 1``) is

        ``D_k = [ (1/N) Σ_j d_j^(10/9) ]^(9/10)``

    and the bearing's, with the tracks again independent volumes, ``D = [Σ_k D_k^(10/9)]^(9/10)``
    (ISO/TS 16281's combination of raceways). Checks: in full rotation under equal loads every
    slice has ``d = n (Q/Qc)^3 / 10^6`` after ``n`` revolutions, so ``D_k = n / (Qc/Q)^3`` (the ISO
    life); under a load pattern fixed to the other ring, a slice of the ring that turns meets all
    the loads (``(Σ Q^3/Z)`` — ISO's rotating ``Qe``) and a slice of the ring that stands meets the
    load at its place again and again, and the weakest-link sum gives ``(Σ Q^(10/3)/Z)^(3/10)`` —
    ISO's standing ``Qe``. In small oscillations slices that no ball crosses get no rolling damage
    (Menck, Stammler and Schleich, Wind Energ. Sci. 5, 2020, map the damage around the raceway in
    the same spirit; Houpert and Menck 2022).

    A ball passes a slice when its contact crosses the slice's centre; between two steps the
    ball moves from its old to its new place on each ring (fixed ring: the ball angle ``φ_b``;
    moving ring: ``φ_b - ψ``), and the pass carries the mean of ``Q^3`` of the two steps.

Run-time module: numpy only (a step costs a few array operations over the balls), or its one
compiled loop (:mod:`slewing_model.life.kernel`).
"""
from __future__ import annotations

import math

import numpy as np

from .kernel import compiled_map_update
from .rating import TRACK_RINGS, WEIBULL_SLOPE, LifeInputError, gamma
from ..numerics.compiled import use_compiled

#: fewest slices of a track around its circumference by default (0.25 deg each); the default is the
#: first count from here with no common divisor with the ball count (:func:`default_slices`)
DEFAULT_SLICES = 1440


def default_slices(ball_count: int, minimum: int = DEFAULT_SLICES) -> int:
    """Slices of a track by default: the smallest ``N >= minimum`` with ``gcd(N, Z) = 1`` (1441 for
    Z = 150).

    Why coprime: the balls sit ``360°/Z`` apart, so against a grid of ``N`` slices their tracks
    start at only ``Z / gcd(N, Z)`` different offsets (5 for 720 slices and 150 balls): each ball's
    short track then covers either k or k + 1 slice centres together with the others, and a swing
    whose track is about a slice long is counted ±20 % wrong. With
    ``gcd(N, Z) = 1`` the Z balls fall at Z offsets ``1/Z`` of a slice apart: over the balls the
    track is sampled at ``1/Z`` of a slice, and the map's damage of a steady swing of 0.7-3° is
    within 2 % of its converged value (0.5°: 2.6 %, 0.3°: 4 %; 150 balls, 1441 slices; tested
    against the closed form of the user guide's life and wear page).

    Parameters
    ----------
    ball_count : int
        Number of balls ``Z``.
    minimum : int, optional
        Fewest slices. Default 1440 (0.25° each).

    Returns
    -------
    int
        The number of slices ``N``.
    """
    n = int(minimum)
    while math.gcd(n, int(ball_count)) != 1:
        n += 1
    return n


def passes_per_revolution(ball_count, ball_diameter, pitch_diameter, contact_angle):
    """``m = Z (1 ± γ)/2`` of the four tracks (contacts 1..4; + for the inner ring's 2 and 3), (4,)."""
    g = gamma(ball_diameter, pitch_diameter, contact_angle)
    sign = np.array([1.0 if r == "inner" else -1.0 for r in TRACK_RINGS])
    return ball_count * (1.0 + sign * g) / 2.0


def crossed_slices(start, end, slices):
    """Slice indices (mod ``slices``) whose centres lie between ``start`` and ``end`` (angles, rad,
    (B,), unwrapped) -- half-open, so back and forth over a centre counts twice -- and for each the
    ball it belongs to. Returns ``(ball, slice)`` int arrays."""
    u0 = np.asarray(start) * (slices / (2 * math.pi)) - 0.5
    u1 = np.asarray(end) * (slices / (2 * math.pi)) - 0.5
    a = np.floor(np.minimum(u0, u1)).astype(np.int64)
    n = np.floor(np.maximum(u0, u1)).astype(np.int64) - a
    total = int(n.sum())
    if total == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    ball = np.repeat(np.arange(n.size), n)
    offset = np.arange(total) - np.repeat(np.cumsum(n) - n, n)
    return ball, (a[ball] + 1 + offset) % slices


class RacewayMap:
    """Damage map of the four tracks, accumulated step by step.

    Each track is cut into slices around its ring; a slice is damaged by the balls
    that roll over it, with their loads (Miner's rule with exponent 3, slices combined
    as weakest-link Weibull volumes). A damage of 1 is one L10 rating life.

    Parameters
    ----------
    capacities : ndarray, shape (4,)
        ``Qc`` of contacts 1..4, N (:func:`slewing_model.life.rating.four_point_capacities`).
    passes : ndarray, shape (4,)
        Ball passes ``m = Z (1 ± γ)/2`` a point of each track receives per revolution.
    moving_ring : {"inner", "outer"}
        The ring that turns by ``psi``.
    slices : int, optional
        Slices of each track around its circumference (>= 4). Default 1440.
    kernel : {"numpy", "auto", "compiled"}, optional
        How a step's passes are added: numpy array operations (default), or one compiled
        loop (:mod:`slewing_model.life.kernel`, needs numba; "auto" where it is installed).
        The same map to round-off.

    Attributes
    ----------
    damage_map : ndarray, shape (4, slices)
        Damage ``d_j`` of every slice of contacts 1..4.
    rolled : float
        Rotation of the rings relative to each other counted into the map, ``Σ |Δψ|`` over the
        updates, rad.

    Raises
    ------
    LifeInputError
        If ``slices`` or ``moving_ring`` is not valid.
    """

    def __init__(self, capacities, passes, moving_ring: str, slices: int = DEFAULT_SLICES, kernel: str = "numpy"):
        if isinstance(slices, bool) or not isinstance(slices, (int, np.integer)) or slices < 4:
            raise LifeInputError(f"slices = {slices!r}: must be a whole number >= 4")
        if moving_ring not in ("inner", "outer"):
            raise LifeInputError(f"moving_ring = {moving_ring!r}: must be 'inner' or 'outer'")
        self.scale = 1.0 / (np.asarray(capacities, float) ** 3 * np.asarray(passes, float) * 1e6)
        self.slices = int(slices)
        self.moving = np.array([r == moving_ring for r in TRACK_RINGS])
        self._compiled = use_compiled(kernel, "kernel")
        #: the tracks of the fixed ring and of the moving ring
        self._tracks = {ring_moving: np.flatnonzero(self.moving == ring_moving) for ring_moving in (False, True)}
        self.reset()

    def reset(self) -> None:
        """Clear the map: no damage, no step recorded."""
        self.damage_map = np.zeros((4, self.slices))    # d_j of every slice of contacts 1..4
        self._power = np.zeros(4)                       # Σ_j d_j^(10/9) of each track, kept as slices change
        self._shared = False                            # damage_map handed out by get_state: copy before a change
        self._angle = None                              # ball angles of the last step (B,), rad
        self._psi = 0.0
        self._q3 = None                                 # Q^3 of the last step (B, 4)
        self.rolled = 0.0                               # Σ |Δψ| of the steps counted, rad

    def update(self, ball_angle, psi: float, contact_load) -> None:
        """Add the passes from the last step to this one (the first call only records).

        Only the slices a ball crossed change, and each track's ``Σ d_j^(10/9)`` follows them.
        A pass carries the mean of ``Q^3`` of the two steps.

        Parameters
        ----------
        ball_angle : ndarray, shape (B,)
            Angular position ``φ_b`` of every ball in the fixed frame, rad.
        psi : float
            Rotation of the moving ring, rad.
        contact_load : ndarray, shape (B, 4)
            Contact loads ``Q`` of contacts 1..4, N.
        """
        if self._angle is not None:
            self.rolled += abs(float(psi) - self._psi)
        if self._angle is not None and self._compiled:     # Q^3 and the passes in one compiled loop
            self._own_map()
            q3 = compiled_map_update()(self.damage_map, self._power, self.scale, self.moving, self._angle,
                                       np.ascontiguousarray(ball_angle, dtype=float), self._psi, float(psi),
                                       self._q3, np.ascontiguousarray(contact_load, dtype=float), WEIBULL_SLOPE)
        else:
            q3 = np.maximum(contact_load, 0.0) ** 3
            if self._angle is not None:
                mean = 0.5 * (q3 + self._q3) * self.scale
                for ring_moving, tracks in self._tracks.items():
                    shift_old, shift_new = (self._psi, psi) if ring_moving else (0.0, 0.0)
                    ball, where = crossed_slices(self._angle - shift_old, ball_angle - shift_new, self.slices)
                    if ball.size and tracks.size:
                        self._add(tracks, ball, where, mean)
        self._angle = np.array(ball_angle, dtype=float)
        self._psi = float(psi)
        self._q3 = q3

    def _add(self, tracks, ball, where, mean) -> None:
        """Add ``mean[ball, k]`` to slice ``where`` of each track ``k`` of ``tracks``."""
        self._own_map()
        crossed, inverse = np.unique(where, return_inverse=True)
        for k in tracks:
            old = self.damage_map[k, crossed]
            new = old + np.bincount(inverse, mean[ball, k], minlength=crossed.size)
            self._power[k] += float(np.sum(new ** WEIBULL_SLOPE - old ** WEIBULL_SLOPE))
            self.damage_map[k, crossed] = new

    def _own_map(self) -> None:
        """Before a change: a map a state holds (:meth:`get_state`) stays as it was, this one is a copy."""
        if self._shared:
            self.damage_map = self.damage_map.copy()
            self._shared = False

    def track_damage(self) -> np.ndarray:
        """Damage of each track, ``D_k = [(1/N) Σ_j d_j^(10/9)]^(9/10)``.

        From the sums kept step by step (:func:`track_damage` sums the whole map again; they
        agree to round-off).

        Returns
        -------
        ndarray, shape (4,)
            ``D_k`` of contacts 1..4 (1: one L10 life used).
        """
        return self._damage(self._power)

    def worst_track_damage(self) -> float:
        """The largest of :meth:`track_damage`, without the arrays.

        Returns
        -------
        float
            The worst track's damage (the FMU's ``life_damage`` output, every step).
        """
        return float(self._damage(max(self._power.tolist())))

    def _damage(self, power):
        """``D = [(1/N) max(power, 0)]^(9/10)`` of a track's kept sum, or of each of an array of them."""
        return (np.maximum(power, 0.0) / self.slices) ** (1.0 / WEIBULL_SLOPE)

    def get_state(self) -> dict:
        """The map's state, for a checkpoint.

        Returns
        -------
        dict
            The map, its sums, the last ball angles (rad), ring angle (rad), ``Q^3`` (N^3) and
            rolled angle (rad).
            The map is not copied: the next update copies it before a change; the others are
            replaced, not changed, by an update.
        """
        self._shared = True
        return {"map": self.damage_map, "power": self._power.copy(), "angle": self._angle, "psi": self._psi,
                "q3": self._q3, "rolled": self.rolled}

    def set_state(self, state: dict) -> None:
        """Restore a state of :meth:`get_state` (or its JSON form decoded)."""
        self.damage_map = np.array(state["map"], dtype=float).reshape(4, self.slices)
        self._shared = False
        power = state.get("power")
        self._power = (np.sum(self.damage_map ** WEIBULL_SLOPE, axis=1) if power is None
                       else np.array(power, dtype=float))
        self._angle = None if state["angle"] is None else np.array(state["angle"], dtype=float)
        self._psi = float(state["psi"])
        self._q3 = None if state["q3"] is None else np.array(state["q3"], dtype=float)
        self.rolled = float(state.get("rolled", 0.0))


def track_damage(damage_map) -> np.ndarray:
    """Weakest-link damage of each track from its slices' damages.

    ``D_k = [(1/N) Σ_j d_j^(10/9)]^(9/10)``: the slices are independent Weibull volumes.

    Parameters
    ----------
    damage_map : array_like, shape (..., N)
        Damage ``d_j`` of every slice (last axis: the N slices of a track).

    Returns
    -------
    ndarray, shape (...)
        Damage of each track.
    """
    d = np.asarray(damage_map, dtype=float)
    return np.mean(d ** WEIBULL_SLOPE, axis=-1) ** (1.0 / WEIBULL_SLOPE)
