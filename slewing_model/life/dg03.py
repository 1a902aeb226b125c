"""NREL DG03's catalogue life of an oscillating slewing bearing (Harris, Rumbarger and
Butterfield, Wind turbine design guideline DG03: yaw and pitch rolling bearing life,
NREL/TP-500-42362, 2009), from the same run, so that every result shows it beside ours.

* Equivalent load of a moment bearing: ``Pea = 0.75 Fr + Fa + 2 M / dm``.
* Over a spectrum of bins (here: the rainflow cycles, count ``c_i``, full swing ``θ_i``):
  ``Pea_osc = [Σ Pea_i^3 c_i θ_i / Σ c_i θ_i]^(1/3)``, ``θe = Σ c_i θ_i / Σ c_i``.
* Balls: ``Ca_osc = Ca (180°/θe)^(3/10) Z^0.033``, whatever θe. An earlier version switched to
  ``(180°/θe)^(1/3)`` at or above the critical angle; that switch could not be found in DG03's text
  (not reachable here) nor in the one public DG03 implementation found, so it was removed (issue 28):
  above the critical angle the factor is applied as the formula stands, and :attr:`DG03Life.above_critical`
  says so.
* ``L10 = (Ca_osc / Pea_osc)^3`` 10^6 cycles.

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .oscillation import dg03_rating_factor


def equivalent_axial_load(loads, pitch_diameter):
    """``Pea = 0.75 Fr + Fa + 2 M / dm``, N, of loads (n, >= 5) ``(Fx, Fy, Fz, Mx, My)`` (N, N m)."""
    f = np.atleast_2d(np.asarray(loads, dtype=float))
    fr = np.hypot(f[:, 0], f[:, 1])
    m = np.hypot(f[:, 3], f[:, 4])
    return 0.75 * fr + np.abs(f[:, 2]) + 2.0 * m / pitch_diameter


@dataclass(frozen=True)
class DG03Life:
    """DG03's life of a run.

    Attributes
    ----------
    pea_osc : float, N
    theta_e : float, rad
        Equivalent full swing.
    rating : float, N
        ``Ca``.
    rating_osc : float, N
        ``Ca_osc``.
    life_cycles : float
        L10, cycles.
    hours : float
        L10 in hours of the run's duty.
    above_critical : bool
        θe at or above the critical angle: DG03's factor is used beyond the range it was stated for
        (``DESIGN.md``: it does not return Ca at 180°).
    """

    pea_osc: float
    theta_e: float
    rating: float
    rating_osc: float
    life_cycles: float
    hours: float
    above_critical: bool = False


def dg03_life(pea_cycle, swing, count, rating, ball_count, critical, duration) -> DG03Life:
    """DG03's L10 of a run from its cycles' equivalent loads ``pea_cycle`` (N), full swings ``swing``
    (rad) and counts, the axial rating ``rating`` (N), ``Z``, the critical angle (rad; only to flag
    :attr:`DG03Life.above_critical`) and the run's duration (s)."""
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
