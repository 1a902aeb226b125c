"""NREL DG03's catalogue life of an oscillating slewing bearing (Harris, Rumbarger and
Butterfield, Wind turbine design guideline DG03: yaw and pitch rolling bearing life,
NREL/TP-500-42362, 2009), from the same run, so that every result shows it beside ours.

* Equivalent load of a moment bearing: ``Pea = 0.75 Fr + Fa + 2 M / dm``.
* Over a spectrum of bins (here: the rainflow cycles, count ``c_i``, full swing ``θ_i``):
  ``Pea_osc = [Σ Pea_i^3 c_i θ_i / Σ c_i θ_i]^(1/3)``, ``θe = Σ c_i θ_i / Σ c_i``.
* Balls: ``Ca_osc = Ca (180°/θe)^(3/10) Z^0.033``, whatever θe: above the critical angle the
  factor is applied as the formula stands, and :attr:`DG03Life.above_critical` says so.
* ``L10 = (Ca_osc / Pea_osc)^3`` 10^6 cycles.

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .oscillation import dg03_rating_factor


def equivalent_axial_load(loads, pitch_diameter):
    """DG03's equivalent axial load of a moment bearing, ``Pea = 0.75 Fr + Fa + 2 M / dm``.

    Parameters
    ----------
    loads : array_like, shape (n, >= 5) or (>= 5,)
        Loads ``(Fx, Fy, Fz, Mx, My)``, N and N m, one row a sample.
    pitch_diameter : float
        Pitch diameter ``dm``, m.

    Returns
    -------
    ndarray, shape (n,)
        ``Pea``, N.
    """
    f = np.atleast_2d(np.asarray(loads, dtype=float))
    fr = np.hypot(f[:, 0], f[:, 1])
    m = np.hypot(f[:, 3], f[:, 4])
    return 0.75 * fr + np.abs(f[:, 2]) + 2.0 * m / pitch_diameter


@dataclass(frozen=True)
class DG03Life:
    """DG03's life of a run.

    Attributes
    ----------
    pea_osc : float
        Equivalent axial load of the oscillation ``Pea_osc``, N.
    theta_e : float
        Equivalent full swing ``θe``, rad.
    rating : float
        Axial rating ``Ca``, N.
    rating_osc : float
        Oscillating rating ``Ca_osc``, N.
    life_cycles : float
        L10, cycles.
    hours : float
        L10 in hours of the run's duty.
    above_critical : bool
        θe at or above the critical angle: DG03's factor is used beyond the range it was
        stated for (it does not return ``Ca`` at 180°).
    """

    pea_osc: float
    theta_e: float
    rating: float
    rating_osc: float
    life_cycles: float
    hours: float
    above_critical: bool = False


def dg03_life(pea_cycle, swing, count, rating, ball_count, critical, duration) -> DG03Life:
    """DG03's L10 of a run from its rainflow cycles.

    Parameters
    ----------
    pea_cycle : array_like, shape (n,)
        Equivalent axial load ``Pea`` of each cycle, N.
    swing : array_like, shape (n,)
        Full swing of each cycle, rad.
    count : array_like, shape (n,)
        Count of each cycle (1 or 0.5).
    rating : float
        Axial rating ``Ca``, N.
    ball_count : int
        Number of balls ``Z``.
    critical : float
        Critical angle, rad; only to flag :attr:`DG03Life.above_critical`.
    duration : float
        Duration of the run, s.

    Returns
    -------
    DG03Life
        Infinite life where the run has no cycles.
    """
    pea, th, c = (np.asarray(a, dtype=float) for a in (pea_cycle, swing, count))
    ct = float(np.sum(c * th))
    if c.size == 0 or ct <= 0:
        return DG03Life(0.0, 0.0, rating, math.inf, math.inf, math.inf)
    pea_osc = (float(np.sum(pea ** 3 * c * th)) / ct) ** (1 / 3)
    theta_e = ct / float(c.sum())
    ca_osc = rating * float(dg03_rating_factor(theta_e, ball_count))
    cycles = (ca_osc / pea_osc) ** 3 * 1e6 if pea_osc > 0 else math.inf
    per_hour = float(c.sum()) / duration * 3600.0
    return DG03Life(pea_osc, theta_e, rating, ca_osc, cycles, cycles / per_hour, bool(theta_e >= critical))
