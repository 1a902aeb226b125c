"""The bearing as assembled, at a rotation ``psi`` of the moving ring.

Paper section 2.1 (eqs 3, 5, 10, 11) with the manufacturing errors of each
ring read at the ball positions. As the moving ring turns by ``psi``, the
balls (cage) orbit by ``cage_ratio * psi`` and each ring's errors stay with
that ring, so the errors under each ball change with ``psi``:

* ball ``b`` sits at ``phi_b = phi_0 + 2 pi b / B + cage_ratio * psi`` in the
  fixed frame and keeps its own diameter;
* the fixed ring's errors are read at ``theta = phi_b``, the moving ring's at
  ``theta = phi_b - psi``.

Everything returned is per ball and per diagonal, ready for the energy of
:mod:`slewing_model.distribution.bime`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..bearing.contact import diagonal_stiffness, houpert_stiffness
from .kernel import add_groove_errors
from ..numerics.compiled import use_compiled
from ..bearing.conventions import INNER_SLOT, OUTER_SLOT  # noqa: F401  (part of this interface)
from ..bearing.geometry import DIAGONALS, RING_CONTACTS, Bearing

#: for each diagonal (1, 2) the column of its outer and inner contact in (B, 4) arrays
OUTER_OF_DIAGONAL = np.array([c - 1 for c, _ in DIAGONALS])   # contacts 1, 4
INNER_OF_DIAGONAL = np.array([c - 1 for _, c in DIAGONALS])   # contacts 3, 2
#: the columns (contacts 1..4, 0-based) of each ring's two contacts
_RING_COLUMNS = {ring: [c - 1 for c in contacts] for ring, contacts in RING_CONTACTS.items()}


def cage_ratio(bearing: Bearing) -> float:
    """Cage (ball set) rotation per rotation of the moving ring, rolling without slip.

    ``(1 - gamma)/2`` when the inner ring turns, ``(1 + gamma)/2`` when the outer
    ring turns, ``gamma = Dw cos(alpha) / dm`` (Harris & Kotzalas, ch. 8)."""
    gamma = bearing.ball_diameter * np.cos(bearing.contact_angle) / bearing.pitch_diameter
    return 0.5 * (1.0 - gamma) if bearing.moving_ring == "inner" else 0.5 * (1.0 + gamma)


@dataclass(frozen=True)
class Assembly:
    """Per-ball geometry of the assembled bearing (SI units).

    Attributes
    ----------
    psi : float, rad
        Rotation of the moving ring.
    cage_angle : float, rad
        Rotation of the ball set.
    ball_angle : ndarray (B,), rad
        ``phi_b`` in the fixed frame.
    groove_centre : ndarray (B, 4, 2), m
        (R, z) of the groove centres of contacts 1..4 before loading (eq 3).
    groove_radius : ndarray (B, 4), m
    ball_diameter : ndarray (B,), m
        Including preload and the ball's own deviation (eq 5).
    contact_stiffness : ndarray (B, 4), N/m^1.5
        Houpert's K of each contact (eq 10).
    stiffness : ndarray (B, 2), N/m^1.5
        ``K_tot`` of diagonals 1 and 2 (eq 11).
    natural_length : ndarray (B, 2), m
        ``l_N = Rc_i + Rc_{i+2} - Dw`` of diagonals 1 and 2 (eq 5).
    moving_sign : float
        +1 when the inner ring moves, -1 when the outer ring moves.
    """

    psi: float
    cage_angle: float
    ball_angle: np.ndarray
    groove_centre: np.ndarray
    groove_radius: np.ndarray
    ball_diameter: np.ndarray
    contact_stiffness: np.ndarray
    stiffness: np.ndarray
    natural_length: np.ndarray
    moving_sign: float

    @property
    def separation(self) -> np.ndarray:
        """Vector from the outer to the inner groove centre of each diagonal,
        (B, 2, 2) as (ball, diagonal, (r, z)), before loading."""
        return np.take(self.groove_centre, INNER_OF_DIAGONAL, axis=1) - np.take(self.groove_centre, OUTER_OF_DIAGONAL,
                                                                               axis=1)

    @property
    def moving_centre(self) -> np.ndarray:
        """(R, z) of the moving ring's groove centre of each diagonal, (B, 2, 2)."""
        cols = INNER_OF_DIAGONAL if self.moving_sign > 0 else OUTER_OF_DIAGONAL
        return np.take(self.groove_centre, cols, axis=1)


def assemble(bearing: Bearing, psi: float = 0.0, cage_angle: float | None = None,
             previous: Assembly | None = None, compiled: bool = False) -> Assembly:
    """Groove centres, groove radii, ball diameters and spring constants at ``psi``.

    Parameters
    ----------
    bearing : Bearing
    psi : float, rad
        Rotation of the moving ring from the reference position.
    cage_angle : float, rad, optional
        Rotation of the ball set (cage); default ``cage_ratio(bearing) * psi``
        (rolling without slip).
    previous : Assembly, optional
        This bearing assembled at another rotation. Where neither ring has
        errors, every ball sees the same grooves at any ``psi`` (each ball keeps
        its own diameter), so only the angles change: the rest is taken from it;
        where no ring has measured groove radii, so are the radii and stiffnesses.
    compiled : bool
        Interpolate the rings' error tables and add them to the groove centres by a
        compiled loop (:func:`slewing_model.distribution.kernel.add_groove_errors`, needs
        numba): numpy's arithmetic, the same values.

    Returns
    -------
    Assembly
    """
    n = bearing.ball_count
    cage = cage_ratio(bearing) * psi if cage_angle is None else cage_angle
    phi = bearing.ball_angles + cage
    sign = 1.0 if bearing.moving_ring == "inner" else -1.0
    if previous is not None:
        if previous.ball_diameter.shape != (n,) or previous.moving_sign != sign:
            raise ValueError(f"previous: an assembly of {previous.ball_diameter.shape[0]} balls, moving sign "
                             f"{previous.moving_sign:+g}: not of this bearing ({n} balls, "
                             f"{bearing.moving_ring} ring moving)")
        if not rings_have_errors(bearing):
            return replace(previous, psi=float(psi), cage_angle=float(cage), ball_angle=phi)
    centre = np.empty((n, 4, 2))
    centre[:] = bearing.groove_centres
    measured = []                                         # (contacts, groove radii) a ring measured

    errors = bearing.errors
    if errors is not None:
        for ring in ("outer", "inner"):
            error_map = getattr(errors, ring)
            if error_map is None:
                continue
            theta = phi - psi if ring == bearing.moving_ring else phi
            cols = _RING_COLUMNS[ring]
            if compiled:                              # the same additions, one compiled loop
                rc = _compiled_groove_errors(centre, theta, error_map, cols)
            else:
                d_radial, d_axial, rc = error_map.at(theta)
                centre[:, cols, 0] += d_radial
                centre[:, cols, 1] += d_axial
            if rc is not None:
                measured.append((cols, rc))

    if previous is not None and not measured:             # the same grooves' radii under every ball
        return replace(previous, psi=float(psi), cage_angle=float(cage), ball_angle=phi, groove_centre=centre)
    radius = np.broadcast_to(bearing.groove_radius, (n, 4)).copy()
    for cols, rc in measured:
        radius[:, cols] = rc
    dw = ball_diameters(bearing)
    k = houpert_stiffness(dw[:, None], dw[:, None] / (2.0 * radius), bearing.youngs_modulus, bearing.poisson_ratio)
    k_tot = diagonal_stiffness(k[:, OUTER_OF_DIAGONAL], k[:, INNER_OF_DIAGONAL])
    natural = radius[:, OUTER_OF_DIAGONAL] + radius[:, INNER_OF_DIAGONAL] - dw[:, None]
    return Assembly(
        psi=float(psi), cage_angle=float(cage), ball_angle=phi, groove_centre=centre, groove_radius=radius, ball_diameter=dw,
        contact_stiffness=k, stiffness=k_tot, natural_length=natural,
        moving_sign=sign,
    )


def ball_diameters(bearing: Bearing) -> np.ndarray:
    """Diameter of every ball (B,), m: the nominal one with the preload and each ball's deviation."""
    dw = np.full(bearing.ball_count, bearing.ball_diameter + bearing.preload)
    if bearing.errors is not None and bearing.errors.ball_diameter_deviation is not None:
        dw = dw + bearing.errors.ball_diameter_deviation
    return dw


def _compiled_groove_errors(centre: np.ndarray, theta: np.ndarray, error_map, cols: list) -> np.ndarray | None:
    """A ring's errors at its angles ``theta`` added to the groove centres of its contacts ``cols``
    by a compiled loop (:func:`slewing_model.distribution.kernel.add_groove_errors`); its measured
    groove radii, or None."""
    use_compiled("compiled", "compiled")               # a clear ValueError where numba is not installed
    return add_groove_errors(centre, theta, error_map, cols)


def rings_have_errors(bearing: Bearing) -> bool:
    """Whether a ring's errors put other grooves under the balls as the moving ring turns."""
    errors = bearing.errors
    return errors is not None and (errors.outer is not None or errors.inner is not None)
