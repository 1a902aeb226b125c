"""Raceway rating life from the load on every ball (ISO/TS 16281, Lundberg–Palmgren).

Written for the raceways of any ball bearing: a raceway is given by its ring, the loads
and contact angles of the balls on it, its groove radius and the bearing's Dw, dm and Z.
For the four-point contact bearing every contact is one raceway track: contacts 1 and 4
on the outer ring, 2 and 3 on the inner ring (``DESIGN.md`` conventions).

Sources
    ISO/TS 16281:2008, clauses on the basic dynamic load rating of a raceway ``Qc`` and the
    dynamic equivalent rolling element load ``Qe`` (balls), with the combination of the
    raceways' lives ``L10r = [sum (Qc/Qe)^(-10/3)]^(-9/10)`` (Weibull slope 10/9 of ball
    bearings). ISO 281:2007, the dynamic load rating and the factor ``bm = 1.3``.
    Lundberg and Palmgren, Dynamic capacity of rolling bearings, Acta Polytechnica
    Mech. Eng. Ser. 1(3), 1947: the raceway capacity from the geometry (as given in
    Harris and Kotzalas, Rolling Bearing Analysis, 5th ed., 2007, ch. 8).

Units: SI (m, N, rad) at the interface; the N–mm formulas are evaluated by
:func:`_capacity_nmm`, the one conversion point of this module.

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Weibull slope of ball bearings (Lundberg–Palmgren); the raceways' lives combine with it
WEIBULL_SLOPE = 10.0 / 9.0
#: load-life exponent of a ball contact
LIFE_EXPONENT = 3.0
#: ISO 281:2007 rating factor bm of ball bearings (radial and angular contact, thrust)
BM_BALL = 1.3
#: Lundberg–Palmgren constant of the raceway capacity of balls, N and mm (Harris and Kotzalas)
LP_CONSTANT = 98.1
RINGS = ("inner", "outer")


class LifeInputError(ValueError):
    """A life input breaks a rule; the message names the field, the value and the rule.

    A :class:`ValueError`.
    """


def _check_positive(name, value):
    v = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise LifeInputError(f"{name} = {value!r}: must be finite and > 0")
    return v


def _check_ring(name, ring):
    if ring not in RINGS:
        raise LifeInputError(f"{name} = {ring!r}: must be 'inner' or 'outer'")
    return ring


def gamma(ball_diameter, pitch_diameter, contact_angle):
    """``γ = Dw cos α / dm`` (ISO 281), dimensionless; arrays broadcast."""
    return ball_diameter * np.cos(contact_angle) / pitch_diameter


def conformity_ratio(ball_diameter, pitch_diameter, contact_angle, inner_groove_radius, outer_groove_radius):
    """ISO/TS 16281 ``r`` of a radial ball bearing, the ratio of the inner to the outer raceway
    capacity: ``r = 1.044 ((1-γ)/(1+γ))^1.72 ((ri/re)(2re-Dw)/(2ri-Dw))^0.41``."""
    g = gamma(ball_diameter, pitch_diameter, contact_angle)
    ri, re, dw = inner_groove_radius, outer_groove_radius, ball_diameter
    return 1.044 * ((1 - g) / (1 + g)) ** 1.72 * ((ri / re) * (2 * re - dw) / (2 * ri - dw)) ** 0.41


def radial_raceway_capacities(rating, ball_count, ball_diameter, pitch_diameter, contact_angle,
                              inner_groove_radius, outer_groove_radius, rows=1):
    """Raceway capacities ``(Qci, Qce)`` of a radial ball bearing from its rating ``C`` (ISO/TS 16281).

    ``Qci = C / (0.407 Z (i cos α)^0.7) (1 + r^(10/3))^0.3`` and
    ``Qce = C / (0.389 Z (i cos α)^0.7) (1 + r^(-10/3))^0.3``.

    Parameters
    ----------
    rating : float
        Basic dynamic radial load rating ``C``, N.
    ball_count : int
        Number of balls ``Z`` (per row).
    ball_diameter, pitch_diameter : float
        Ball diameter ``Dw`` and pitch diameter ``dm``, m.
    contact_angle : float
        Nominal contact angle ``α``, rad.
    inner_groove_radius, outer_groove_radius : float
        Groove radii of the inner and outer raceway, m.
    rows : int, optional
        Number of rows ``i``. Default 1.

    Returns
    -------
    Qci, Qce : float
        Basic dynamic load ratings of the inner and the outer raceway, N.

    Raises
    ------
    LifeInputError
        If ``rating`` or ``ball_count`` is not finite and positive.
    """
    _check_positive("rating", rating)
    _check_positive("ball_count", ball_count)
    r = conformity_ratio(ball_diameter, pitch_diameter, contact_angle, inner_groove_radius, outer_groove_radius)
    k = ball_count * (rows * math.cos(contact_angle)) ** 0.7
    return (rating / (0.407 * k) * (1 + r ** (10 / 3)) ** 0.3,
            rating / (0.389 * k) * (1 + r ** (-10 / 3)) ** 0.3)


def _capacity_nmm(dw_mm, f, g, cos_a, z, inner):
    """Lundberg–Palmgren raceway capacity in N for Dw in mm (the one N–mm formula):
    ``Qc = bm 98.1 (2f/(2f-1))^0.41 (1∓γ)^1.39/(1±γ)^(1/3) (γ/cos α)^0.3 Dw^1.8 Z^(-1/3)``,
    upper signs for an inner raceway; ``Dw^1.8`` becomes ``3.647 Dw^1.4`` above 25.4 mm as in
    ISO 281's ratings."""
    s = np.where(inner, 1.0, -1.0)
    # ISO 281: balls above 25.4 mm (1 in) carry less than Dw^1.8 says: 3.647 Dw^1.4 (equal at 25.4 mm)
    size = dw_mm ** 1.8 if dw_mm <= 25.4 else 3.647 * dw_mm ** 1.4
    return (BM_BALL * LP_CONSTANT * (2 * f / (2 * f - 1)) ** 0.41 * (1 - s * g) ** 1.39 / (1 + s * g) ** (1 / 3)
            * (g / cos_a) ** 0.3 * size * z ** (-1 / 3))


def raceway_capacity(ring, ball_count, ball_diameter, pitch_diameter, contact_angle, groove_radius):
    """Basic dynamic load rating ``Qc`` of one raceway from its geometry, N.

    Lundberg–Palmgren's capacity (Harris and Kotzalas, ch. 8) times ISO 281's ``bm = 1.3``,
    so that it is on the same footing as the ISO ratings. Arrays broadcast.

    Parameters
    ----------
    ring : {"inner", "outer"}
        The ring of the raceway.
    ball_count : int
        Number of balls ``Z``.
    ball_diameter, pitch_diameter : float
        Ball diameter ``Dw`` and pitch diameter ``dm``, m.
    contact_angle : float or ndarray
        Nominal contact angle ``α``, rad (``0 <= α < pi/2``).
    groove_radius : float or ndarray
        Groove radius of the raceway, m (above ``Dw/2``).

    Returns
    -------
    float or ndarray
        ``Qc``, N.

    Raises
    ------
    LifeInputError
        If an input is out of its range.

    Examples
    --------
    >>> from slewing_model.life import raceway_capacity
    >>> round(float(raceway_capacity("inner", 100, 0.05, 1.5, 0.785, 0.02625)))   # N
    28882
    """
    _check_ring("ring", ring)
    _check_positive("ball_count", ball_count)
    dw = float(_check_positive("ball_diameter", ball_diameter))
    _check_positive("pitch_diameter", pitch_diameter)
    f = np.asarray(groove_radius, dtype=float) / dw
    if np.any(f <= 0.5):
        raise LifeInputError(f"groove_radius = {groove_radius!r}: must exceed half the ball diameter ({dw / 2!r} m)")
    a = np.asarray(contact_angle, dtype=float)
    if np.any(~np.isfinite(a)) or np.any(a < 0) or np.any(a >= math.pi / 2):
        raise LifeInputError(f"contact_angle = {contact_angle!r}: must lie in [0, pi/2) rad")
    g = gamma(dw, pitch_diameter, a)
    return _capacity_nmm(dw * 1e3, f, g, np.cos(a), ball_count, ring == "inner")


def equivalent_load(loads, rotating: bool, ball_count: int | None = None):
    """Dynamic equivalent ball load ``Qe`` of a raceway (ISO/TS 16281), N.

    ``(Σ Q^3 / Z)^(1/3)`` on a ring that turns relative to the load (every point of it
    meets every ball's load), ``(Σ Q^(10/3) / Z)^(3/10)`` on a ring that stands relative
    to it (each point meets one load: Weibull weakest link, ``3 · 10/9 = 10/3``). Unloaded
    balls count 0.

    Parameters
    ----------
    loads : array_like, shape (..., Z)
        Ball loads on the raceway, N (last axis: the balls; negative values count 0).
    rotating : bool
        True: the ring turns relative to the load (exponent 3); False: it stands
        relative to the load (exponent 10/3).
    ball_count : int, optional
        ``Z``; default the length of the last axis.

    Returns
    -------
    float or ndarray, shape (...)
        ``Qe``, N.
    """
    q = np.maximum(np.asarray(loads, dtype=float), 0.0)
    z = q.shape[-1] if ball_count is None else ball_count
    p = LIFE_EXPONENT if rotating else LIFE_EXPONENT * WEIBULL_SLOPE
    return (np.sum(q ** p, axis=-1) / z) ** (1.0 / p)


def combined_life(capacities, equivalent_loads):
    """Combined L10 life of several raceways (ISO/TS 16281).

    ``L10r = [Σ_k (Qc_k/Qe_k)^(-10/3)]^(-9/10)``. A raceway with ``Qe = 0`` adds
    nothing; all unloaded gives ``inf``.

    Parameters
    ----------
    capacities : array_like, shape (..., K)
        Basic dynamic load ratings ``Qc`` of the K raceways, N.
    equivalent_loads : array_like, shape (..., K)
        Equivalent ball loads ``Qe`` of the raceways, N.

    Returns
    -------
    float or ndarray, shape (...)
        ``L10r``, 10^6 revolutions.
    """
    qc = np.asarray(capacities, dtype=float)
    qe = np.asarray(equivalent_loads, dtype=float)
    terms = (qe / qc) ** (LIFE_EXPONENT * WEIBULL_SLOPE)
    s = np.sum(terms, axis=-1)
    with np.errstate(divide="ignore"):
        return s ** (-1.0 / WEIBULL_SLOPE)


def combined_damage(track_damage):
    """The bearing's damage from its tracks' damages ``D = [Σ D_k^(10/9)]^(9/10)``: the same
    weakest-link sum as :func:`combined_life` (``D_k = 1/L_k`` for one unit of duty)."""
    d = np.asarray(track_damage, dtype=float)
    return np.sum(d ** WEIBULL_SLOPE, axis=-1) ** (1.0 / WEIBULL_SLOPE)


@dataclass(frozen=True)
class Raceway:
    """One raceway (track) of a ball bearing, SI units.

    Attributes
    ----------
    ring : {"inner", "outer"}
        The ring of the raceway.
    groove_radius : float
        Groove radius, m.
    contact_angle : float
        Nominal contact angle, rad, for the capacity.
    loads : ndarray, shape (Z,)
        Ball loads on the raceway, N.
    rotating : bool
        The ring turns relative to the load.
    capacity : float or None
        ``Qc``, N, when known (e.g. from ISO/TS 16281 and ``C``); None (default): from the geometry.
    """

    ring: str
    groove_radius: float
    contact_angle: float
    loads: np.ndarray
    rotating: bool
    capacity: float | None = None


@dataclass(frozen=True)
class RacewayLife:
    """What :func:`raceway_life` returns.

    Attributes
    ----------
    capacity : ndarray, shape (K,)
        Basic dynamic load rating ``Qc`` of each raceway, N.
    equivalent_load : ndarray, shape (K,)
        Equivalent ball load ``Qe`` of each raceway, N.
    life : float
        Combined L10 life, 10^6 revolutions.
    """

    capacity: np.ndarray
    equivalent_load: np.ndarray
    life: float


def raceway_life(raceways, ball_count: int, ball_diameter: float, pitch_diameter: float) -> RacewayLife:
    """Each raceway's ``Qc`` and ``Qe`` and the combined L10 (ISO/TS 16281).

    Parameters
    ----------
    raceways : sequence of Raceway
        The raceways, each with its ``ball_count`` ball loads.
    ball_count : int
        Number of balls ``Z``.
    ball_diameter, pitch_diameter : float
        Ball diameter ``Dw`` and pitch diameter ``dm``, m (for capacities from the geometry).

    Returns
    -------
    RacewayLife
        ``Qc`` and ``Qe`` per raceway (N) and the combined L10 (10^6 revolutions).

    Raises
    ------
    LifeInputError
        If a raceway's ring or loads are not valid.

    Examples
    --------
    One raceway, equal loads: ``L10 = (Qc/Q)^3``.

    >>> import numpy as np
    >>> r = Raceway("inner", 0.006, 0.0, np.full(7, 500.0), True, capacity=5000.0)
    >>> round(raceway_life([r], 7, 0.0115, 0.0435).life, 6)
    1000.0
    """
    qc, qe = [], []
    for k, r in enumerate(raceways):
        _check_ring(f"raceways[{k}].ring", r.ring)
        loads = np.asarray(r.loads, dtype=float)
        if loads.shape != (ball_count,) or not np.all(np.isfinite(loads)):
            raise LifeInputError(f"raceways[{k}].loads: must be {ball_count} finite ball loads (N), got shape "
                                 f"{loads.shape}")
        qc.append(float(r.capacity) if r.capacity is not None else
                  float(raceway_capacity(r.ring, ball_count, ball_diameter, pitch_diameter, r.contact_angle,
                                         r.groove_radius)))
        qe.append(float(equivalent_load(loads, r.rotating)))
    qc, qe = np.array(qc), np.array(qe)
    return RacewayLife(qc, qe, float(combined_life(qc, qe)))


def radial_bearing_life(ball_loads, ball_count, ball_diameter, pitch_diameter, contact_angle,
                        inner_groove_radius, outer_groove_radius, rotating_ring="inner", rating=None,
                        outer_ball_loads=None, rows=1) -> RacewayLife:
    """ISO/TS 16281 life of a (single-row) radial or angular contact ball bearing under a load of fixed
    direction: its inner and outer raceway, in that order.

    Parameters
    ----------
    ball_loads : array_like, shape (Z,)
        Ball loads on the inner raceway, N (and on the outer one unless ``outer_ball_loads``).
    ball_count : int
        Number of balls ``Z``.
    ball_diameter, pitch_diameter : float
        Ball diameter ``Dw`` and pitch diameter ``dm``, m.
    contact_angle : float
        Nominal contact angle, rad.
    inner_groove_radius, outer_groove_radius : float
        Groove radii of the inner and outer raceway, m.
    rotating_ring : {"inner", "outer"}, optional
        The ring that turns (default "inner"); under a load of fixed direction it turns
        relative to the load (exponent 3), the other stands (exponent 10/3).
    rating : float or None, optional
        Basic dynamic radial rating ``C``, N: capacities by :func:`radial_raceway_capacities`;
        None (default): from the geometry (:func:`raceway_capacity`).
    outer_ball_loads : array_like, shape (Z,), optional
        Ball loads on the outer raceway, N, where they differ from ``ball_loads``.
    rows : int, optional
        Number of rows ``i`` (for ``rating``). Default 1.

    Returns
    -------
    RacewayLife
        Inner and outer raceway, in that order, and the combined L10 (10^6 revolutions).
    """
    _check_ring("rotating_ring", rotating_ring)
    q_in = np.asarray(ball_loads, dtype=float)
    q_out = q_in if outer_ball_loads is None else np.asarray(outer_ball_loads, dtype=float)
    if rating is None:
        qci = qce = None
    else:
        qci, qce = radial_raceway_capacities(rating, ball_count, ball_diameter, pitch_diameter, contact_angle,
                                             inner_groove_radius, outer_groove_radius, rows)
    return raceway_life([Raceway("inner", inner_groove_radius, contact_angle, q_in, rotating_ring == "inner", qci),
                         Raceway("outer", outer_groove_radius, contact_angle, q_out, rotating_ring == "outer", qce)],
                        ball_count, ball_diameter, pitch_diameter)


# ---- the four-point contact bearing ------------------------------------------------------
#: column of each contact 1..4 in the (B, 4) arrays, and its ring
TRACK_RINGS = ("outer", "inner", "inner", "outer")


def four_point_capacities(bearing, rating: float | None = None) -> np.ndarray:
    """``Qc`` of the four tracks (contacts 1..4) of a four-point bearing, N.

    From the geometry (:func:`raceway_capacity` at the nominal contact angle), or scaled so
    that the bearing's axial rating (:func:`axial_rating`) equals a given ``rating``, the
    tracks keeping the ratios of their geometric capacities.

    Parameters
    ----------
    bearing : Bearing
        The bearing definition.
    rating : float, optional
        Basic dynamic axial rating ``Ca`` of the bearing, N (e.g. a catalogue's); None
        (default): capacities from the geometry.

    Returns
    -------
    ndarray, shape (4,)
        ``Qc`` of contacts 1..4, N.
    """
    qc = np.array([float(raceway_capacity(TRACK_RINGS[j], bearing.ball_count, bearing.ball_diameter,
                                          bearing.pitch_diameter, bearing.contact_angle,
                                          bearing.groove_radius[j])) for j in range(4)])
    if rating is None:
        return qc
    _check_positive("rating", rating)
    return qc * rating / axial_rating(bearing, qc)


def axial_rating(bearing, capacities=None) -> float:
    """Basic dynamic axial rating ``Ca`` of the four-point bearing carried as a thrust bearing on one
    diagonal, N.

    The axial load whose equal ball loads ``Q = Ca / (Z sin α)`` give ``L10 = 10^6`` revolutions
    on the diagonal's two tracks: ``Ca = Z sin α [Qc_o^(-10/3) + Qc_i^(-10/3)]^(-3/10)``, the
    weaker diagonal taken. ISO 281's rating of thrust ball bearings with α ≠ 90°,
    ``Ca = bm fc (cos α)^0.7 tan α Z^(2/3) Dw^1.8`` (``Dw ≤ 25.4 mm``; ``3.647 ... Dw^1.4`` above),
    has the structure of ``Z sin α Qc``, without the empirical reductions of the standard's ``fc``
    table (so it can differ from an ISO 281 or catalogue value); :func:`iso281_axial_rating`
    evaluates the standard's formula for a tabulated ``fc``.

    Parameters
    ----------
    bearing : Bearing
        The bearing definition.
    capacities : array_like, shape (4,), optional
        ``Qc`` of contacts 1..4, N; default :func:`four_point_capacities` from the geometry.

    Returns
    -------
    float
        ``Ca``, N.

    Examples
    --------
    >>> from slewing_model import load_bearing
    >>> from slewing_model.life import axial_rating
    >>> round(axial_rating(load_bearing("examples/bearings/table1.toml")))   # N
    873455
    """
    qc = four_point_capacities(bearing) if capacities is None else np.asarray(capacities, dtype=float)
    e = LIFE_EXPONENT * WEIBULL_SLOPE
    diag = [(qc[0] ** -e + qc[2] ** -e) ** (-1 / e), (qc[3] ** -e + qc[1] ** -e) ** (-1 / e)]
    return float(bearing.ball_count * math.sin(bearing.contact_angle) * min(diag))


def iso281_axial_rating(fc: float, ball_count: int, ball_diameter: float, contact_angle: float,
                        bm: float = BM_BALL) -> float:
    """ISO 281:2007 basic dynamic axial rating of a thrust ball bearing with ``α ≠ 90°``, N.

    ``Ca = bm fc (cos α)^0.7 tan α Z^(2/3) Dw^1.8`` for ``Dw ≤ 25.4 mm`` and
    ``3.647 bm fc (cos α)^0.7 tan α Z^(2/3) Dw^1.4`` above (N, mm); ``fc`` from the
    standard's table for ``Dw cos α / dm`` (the user reads it there).

    Parameters
    ----------
    fc : float
        ISO 281's factor ``fc`` for this bearing (from the standard's table).
    ball_count : int
        Number of balls ``Z``.
    ball_diameter : float
        Ball diameter ``Dw``, m (converted to mm inside).
    contact_angle : float
        Nominal contact angle ``α``, rad, in (0, pi/2).
    bm : float, optional
        Rating factor; default 1.3 (ball bearings).

    Returns
    -------
    float
        ``Ca``, N.

    Raises
    ------
    LifeInputError
        If ``fc`` or ``ball_diameter`` is not positive or ``contact_angle`` is out of range.
    """
    _check_positive("fc", fc)
    dw = float(_check_positive("ball_diameter", ball_diameter)) * 1e3
    if not 0 < contact_angle < math.pi / 2:
        raise LifeInputError(f"contact_angle = {contact_angle!r}: must lie in (0, pi/2) rad for a thrust rating")
    k = bm * fc * math.cos(contact_angle) ** 0.7 * math.tan(contact_angle) * ball_count ** (2 / 3)
    return k * dw ** 1.8 if dw <= 25.4 else 3.647 * k * dw ** 1.4
