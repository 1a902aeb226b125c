"""Oscillation: cycles of the ring angle, critical angle, equivalent revolutions, Miner's rule.

* Cycles: rainflow counting (ASTM E1049-85) of the ring angle ``ψ(t)`` by the ``rainflow``
  package (imported when counting: a post-processing step, not an FMU step). A cycle's full
  swing ``θ`` is its peak-to-valley range; a full cycle turns the ring ``2θ``.
* Critical angle (Rumbarger and Jones, Dynamic capacity of oscillating rolling element
  bearings, J. Lubr. Technol. 90(1), 1968): the full swing below which neighbouring balls'
  tracks on a raceway do not overlap, ``θcrit = 720° / (Z (1 ± γ))``, upper sign for the
  inner raceway (the ball moves over it by ``(1 + γ)/2`` of the ring's swing).
* Above it a cycle counts as ``θ/180°`` revolutions (the raceway is overrolled as in
  rotation, ``2θ/360°`` revolutions per cycle; Rumbarger and Jones; Houpert and Menck 2022).
* Below it the rating is raised by NREL DG03's factor for balls (Harris, Rumbarger and
  Butterfield, Wind turbine design guideline DG03: yaw and pitch rolling bearing life,
  NREL/TP-500-42362, 2009): ``Ca_osc = Ca (180°/θ)^(3/10) Z^0.033``, so a cycle counts as
  ``f^-3 = (θ/180°)^(9/10) Z^(-0.099)`` revolutions; or by a factor the user supplies.
  The two rules do not meet at ``θcrit``: DG03's holds below it only (``DESIGN.md``).
* Damage adds up by Miner's rule: ``D = Σ n_i / L_i``.

Run-time module: numpy and the standard library (``rainflow`` for :func:`rainflow_cycles`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .rating import LifeInputError, gamma


def critical_angle(ball_count, ball_diameter, pitch_diameter, contact_angle, ring):
    """Critical full swing of a raceway, rad: ``720° / (Z (1 + γ))`` on the inner ring and
    ``720° / (Z (1 - γ))`` on the outer ring.

    A ball moves over the inner raceway by ``(1 + γ)/2`` of the swing and over the outer one by
    ``(1 - γ)/2`` of it (whichever ring turns): the tracks of neighbouring balls, ``360°/Z`` apart,
    begin to overlap when that reaches the ball pitch.

    Parameters
    ----------
    ball_count : int
        Number of balls ``Z``.
    ball_diameter, pitch_diameter : float
        Ball diameter ``Dw`` and pitch diameter ``dm``, m.
    contact_angle : float or ndarray
        Contact angle ``α``, rad (``γ = Dw cos α / dm``).
    ring : {"inner", "outer"} or array_like of them
        The raceway's ring.

    Returns
    -------
    float or ndarray
        ``θcrit``, rad (full swing, peak to valley).

    Examples
    --------
    >>> round(math.degrees(critical_angle(150, 0.0762, 4.5, math.radians(45), "inner")), 4)
    4.7432
    """
    g = gamma(ball_diameter, pitch_diameter, contact_angle)
    s = np.where(np.asarray(ring) == "inner", 1.0, -1.0)
    return 4.0 * math.pi / (ball_count * (1.0 + s * g))


def dg03_rating_factor(theta, ball_count):
    """DG03's oscillation factor of balls on the rating, ``(180°/θ)^(3/10) Z^0.033``.

    Parameters
    ----------
    theta : float or array_like
        Full swing ``θ``, rad.
    ball_count : int
        Number of balls ``Z``.

    Returns
    -------
    float or ndarray
        The factor ``Ca_osc / Ca``, dimensionless.
    """
    return (math.pi / np.asarray(theta, dtype=float)) ** 0.3 * ball_count ** 0.033


def equivalent_revolutions(theta, critical, ball_count, rating_factor=None):
    """Revolutions a full cycle of swing ``theta`` counts for.

    ``θ/π`` at or above the raceway's critical angle, ``f(θ)^-3`` below it, with ``f``
    DG03's :func:`dg03_rating_factor` or the user's ``rating_factor``. Arrays broadcast.

    Parameters
    ----------
    theta : float or array_like
        Full swing of the cycle, rad (>= 0).
    critical : float or array_like
        Critical angle of the raceway, rad (:func:`critical_angle`).
    ball_count : int
        Number of balls ``Z``.
    rating_factor : callable, optional
        ``rating_factor(theta, ball_count)``, the factor on the rating below the critical
        angle; default :func:`dg03_rating_factor`.

    Returns
    -------
    float or ndarray
        Equivalent revolutions per full cycle.

    Raises
    ------
    LifeInputError
        If a swing is negative or not finite.
    """
    theta = np.asarray(theta, dtype=float)
    if np.any(theta < 0) or not np.all(np.isfinite(theta)):
        raise LifeInputError(f"theta = {theta!r}: swings must be finite and >= 0")
    f = (rating_factor or dg03_rating_factor)(np.maximum(theta, 1e-300), ball_count)
    below = np.where(theta > 0, np.asarray(f, dtype=float) ** -3.0, 0.0)
    return np.where(theta >= critical, theta / math.pi, below)


@dataclass(frozen=True)
class Cycles:
    """Rainflow cycles of a series (arrays of the same length).

    Attributes
    ----------
    swing : ndarray, rad
        Full swing θ (peak to valley).
    count : ndarray
        1 (a full cycle) or 0.5 (a half cycle, residue).
    start, end : ndarray of int
        Sample indices of the cycle's first and last reversal.
    """

    swing: np.ndarray
    count: np.ndarray
    start: np.ndarray
    end: np.ndarray


def rainflow_cycles(psi, min_swing: float = 0.0) -> Cycles:
    """Rainflow cycles (ASTM E1049-85, ``rainflow.extract_cycles``) of the ring angle.

    Needs the ``rainflow`` package (post-processing, not an FMU step).

    Parameters
    ----------
    psi : array_like, shape (n,)
        Ring angle series, rad.
    min_swing : float, optional
        Cycles of full swing not above this, rad, are left out. Default 0.

    Returns
    -------
    Cycles
        Arrays ``swing`` (full swing, rad), ``count`` (1 or 0.5) and ``start``, ``end``
        (sample indices of the cycle's first and last reversal).

    Raises
    ------
    LifeInputError
        If ``psi`` is not a finite 1-D series.
    """
    import rainflow   # post-processing only

    psi = np.asarray(psi, dtype=float)
    if psi.ndim != 1 or not np.all(np.isfinite(psi)):
        raise LifeInputError("psi: must be a finite 1-D series of ring angles (rad)")
    rows = [c for c in rainflow.extract_cycles(psi) if c[0] > min_swing] if psi.size > 1 else []
    if not rows:
        return Cycles(np.zeros(0), np.zeros(0), np.zeros(0, int), np.zeros(0, int))
    a = np.array(rows, dtype=float)
    return Cycles(a[:, 0], a[:, 2], a[:, 3].astype(int), a[:, 4].astype(int))


def span_mean(values, weights, start, end, exponent=3.0):
    """Per cycle, the ``exponent``-mean of ``values`` (n, ...) over samples ``start..end``
    weighted by ``weights`` (n,) (the ring's rotation at each sample); by samples where the
    cycle's weights sum to 0. Cumulative sums: O(n + cycles)."""
    v = np.asarray(values, dtype=float) ** exponent
    w = np.asarray(weights, dtype=float)
    wv = w.reshape(w.shape + (1,) * (v.ndim - 1)) * v
    cw = np.concatenate([[0.0], np.cumsum(w)])
    cwv = np.concatenate([np.zeros((1,) + v.shape[1:]), np.cumsum(wv, axis=0)])
    cv = np.concatenate([np.zeros((1,) + v.shape[1:]), np.cumsum(v, axis=0)])
    s, e = np.asarray(start), np.asarray(end) + 1
    sw = (cw[e] - cw[s]).reshape((-1,) + (1,) * (v.ndim - 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(sw > 0, (cwv[e] - cwv[s]) / np.where(sw > 0, sw, 1.0),
                        (cv[e] - cv[s]) / (e - s).reshape(sw.shape))
    return np.maximum(mean, 0.0) ** (1.0 / exponent)
