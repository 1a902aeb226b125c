"""Wear and false-brinelling indicators: the rolling travel of a contact against its Hertz patch.

* Rolling travel (kinematics of rolling without slip): for a full swing ``Δψ`` of one ring
  relative to the other, the contact point moves over either raceway by
  ``x = Δψ (dm/4)(1 - γ_j^2)``, ``γ_j = Dw cos α_j / dm`` of the contact's own angle. The
  same on both rings and whichever ring moves (``DESIGN.md``; Houpert and Menck 2022).
  Derivation: the raceway radii at the contact are ``(dm/2)(1 ∓ γ)``; the cage turns
  ``(1 - γ)/2 Δψ`` when the inner ring turns ``Δψ`` against a standing outer ring, so the
  contact moves ``(dm/2)(1 - γ)(1 + γ)/2 Δψ`` on the inner raceway (relative angle
  ``(1 + γ)/2 Δψ``) and ``(dm/2)(1 + γ)(1 - γ)/2 Δψ`` on the outer one.
* ``2b``: the contact ellipse's width in the rolling direction (short axis in a conforming
  groove). ``x/2b < 1``: part of the patch is never uncovered (false brinelling, standstill
  marks); above 1, wear from grease starvation is the risk. Tests on full-size pitch
  bearings find wear under steady small oscillations, prevented by occasional larger
  movements (Behnke and Schleich 2023; Bartschat et al. 2023): hence the longest time
  without a relubricating movement.

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import math

import numpy as np

from .rating import gamma

#: default swing that counts as relubricating: the ring turns far enough that every contact
#: rolls off its own patch several times, x/2b >= 1 -- expressed as a ring angle, see
#: :func:`relubrication_gap`
RELUBRICATION_TRAVEL_RATIO = 1.0


def rolling_travel(swing, pitch_diameter, ball_diameter, contact_angle):
    """Travel ``x = Δψ (dm/4)(1 - γ²)`` of a contact over its raceway for a full swing of the ring.

    The same on both rings and whichever ring moves. Arrays broadcast.

    Parameters
    ----------
    swing : float or array_like
        Full swing ``Δψ`` of one ring relative to the other, rad.
    pitch_diameter, ball_diameter : float
        Pitch diameter ``dm`` and ball diameter ``Dw``, m.
    contact_angle : float or array_like
        Contact angle ``α_j`` of the contact, rad.

    Returns
    -------
    float or ndarray
        Rolling travel ``x``, m.

    Examples
    --------
    >>> round(float(rolling_travel(math.radians(1.0), 1.0, 0.05, 0.0)) * 1e3, 4)   # dm 1000 mm, γ = 0.05
    4.3524
    """
    g = gamma(ball_diameter, pitch_diameter, contact_angle)
    return np.abs(swing) * pitch_diameter / 4.0 * (1.0 - g * g)


def travel_by_ring_kinematics(swing, pitch_diameter, ball_diameter, contact_angle, moving_ring):
    """The same travel from the raceway radii and the cage's turn, whichever ring ``moving_ring``
    turns ``swing`` (rad) against the other: ``(inner, outer)`` travel, m (they are equal; see the
    module docstring). Used by the tests to check :func:`rolling_travel` from first principles."""
    g = gamma(ball_diameter, pitch_diameter, contact_angle)
    r_in, r_out = pitch_diameter / 2 * (1 - g), pitch_diameter / 2 * (1 + g)
    if moving_ring == "inner":
        cage = (1 - g) / 2 * swing                # Harris: cage speed of an inner ring turning
        inner_rel, outer_rel = swing - cage, cage - 0.0
    else:
        cage = (1 + g) / 2 * swing
        inner_rel, outer_rel = 0.0 - cage, swing - cage
    # the contact point travels the raceway radius times the ball's angle relative to the ring
    return abs(r_in * inner_rel), abs(r_out * outer_rel)


def relubrication_gap(time, psi, threshold):
    """Longest time during which the ring angle stays within a band narrower than ``threshold``.

    The longest stretch of samples ``i..j`` with ``max(psi) - min(psi) < threshold``, its
    length ``t_j - t_i``.

    No movement of ``threshold`` happens inside such a stretch (two angles ``threshold`` apart
    would make the band that wide), and slow drift counts as soon as it adds up to ``threshold``.
    The answer does not depend on where the record starts: a steady swing of full range
    ``2A >= threshold`` gives, in every period ``T``, the stretch around a peak where the angle
    stays within ``threshold`` of it, ``T (π + 2 asin(threshold/A - 1)) / (2π)`` for a sine
    (tested at several starting phases). A ring that never moves by ``threshold`` gives the run.
    Sliding window with monotone queues of the band's maximum and minimum: O(n).

    Parameters
    ----------
    time : array_like, shape (n,)
        Sample times, s.
    psi : array_like, shape (n,)
        Ring angle at each sample, rad.
    threshold : float
        Width of band that counts as a relubricating movement, rad.

    Returns
    -------
    float
        The longest gap, s (0 for an empty series).
    """
    from collections import deque

    t = np.asarray(time, dtype=float)
    p = np.asarray(psi, dtype=float)
    if t.size == 0:
        return 0.0
    high, low = deque(), deque()        # sample indices of the window's decreasing maxima, increasing minima
    start, gap = 0, 0.0
    for j in range(p.size):             # a plain loop: post-processing only
        while high and p[high[-1]] <= p[j]:
            high.pop()
        high.append(j)
        while low and p[low[-1]] >= p[j]:
            low.pop()
        low.append(j)
        while p[high[0]] - p[low[0]] >= threshold:     # sample j moved the band to threshold: shrink it
            start += 1
            if high[0] < start:
                high.popleft()
            if low[0] < start:
                low.popleft()
        gap = max(gap, t[j] - t[start])
    return float(gap)


def relubrication_swing(pitch_diameter, ball_diameter, contact_angle, semi_axis_b,
                        ratio: float = RELUBRICATION_TRAVEL_RATIO):
    """Ring swing (rad) that rolls a contact of semi-axis ``semi_axis_b`` (m) ``ratio`` times its
    patch width, ``ratio 2b / ((dm/4)(1 - γ²))``: the default relubrication threshold."""
    g = gamma(ball_diameter, pitch_diameter, contact_angle)
    return ratio * 2.0 * semi_axis_b / (pitch_diameter / 4.0 * (1.0 - g * g))
