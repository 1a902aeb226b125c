"""The slewing bearing makers' start-up friction torque formula (catalogue formula).

Run-time module: the standard library.
"""
from __future__ import annotations

import math

from .contact import check_number
from ..bearing.geometry import Bearing

#: Catalogue start-up friction coefficient of four-point contact slewing bearings
CATALOGUE_MU = 0.006


def catalogue_torque(bearing: Bearing, loads, mu: float = CATALOGUE_MU) -> float:
    """Start-up friction torque of slewing bearing catalogues, N m.

    ``M = mu / 2 (4.4 M_k + F_a D + 2.2 F_r D 1.73)``. The makers write it with
    ``M`` and ``M_k`` in kN m, forces in kN and ``D`` (raceway, i.e. pitch,
    diameter) in m; every term is a force times a length, so the same
    expression holds in N, N m and m (both sides scale by 1000) and no
    numerical conversion factor is needed.

    Parameters
    ----------
    bearing : Bearing
        The bearing; only its pitch diameter ``D`` (m) enters.
    loads : Loads or None
        External load, N and N m: ``F_a = |Fz|``, ``F_r = hypot(Fx, Fy)``,
        ``M_k = hypot(Mx, My)``; None: no load (torque 0).
    mu : float, optional
        Friction coefficient of the formula, about 0.006 for four-point contact
        bearings (scatter about +-25 %). Default 0.006.

    Returns
    -------
    float
        Start-up friction torque, N m (no seal part).

    Raises
    ------
    ValueError
        If ``mu`` is not a finite number >= 0.

    Examples
    --------
    >>> from slewing_model import load_bearing, Loads
    >>> b = load_bearing("examples/bearings/table1.toml")
    >>> round(catalogue_torque(b, Loads(Fz=1e6)))   # 0.003 * 1e6 N * 1.5 m
    4500
    """
    mu = check_number("mu", mu, 0.0)
    if loads is None:
        return 0.0
    d = bearing.pitch_diameter
    f_a = abs(loads.Fz)
    f_r = math.hypot(loads.Fx, loads.Fy)
    m_k = math.hypot(loads.Mx, loads.My)
    return 0.5 * mu * (4.4 * m_k + f_a * d + 2.2 * f_r * d * 1.73)
