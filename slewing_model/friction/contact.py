"""Coulomb friction over one Hertz contact ellipse.

The traction ``mu p`` opposes the local sliding velocity of the raceway against the ball
(rolling, spin and differential sliding together). Across the groove the contact surface
is bent with the radius :func:`conformity_radius`, which gives the differential sliding.
:func:`ellipse_friction` integrates force, moment and dissipated power for one contact and
any rigid relative motion: the building block that :mod:`slewing_model.friction.ball_kinematics`
evaluates for all contacts at once, and a check against closed forms (pivoting moment
``3 pi / 16 mu Q a``).

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .ellipse_quadrature import DEFAULT_QUADRATURE, as_quadrature

#: Default Coulomb coefficient of the ball-raceway contacts. Slewing bearings
#: turn so slowly (entrainment speeds of mm/s) that no lubricant film separates
#: the surfaces: grease-lubricated steel on steel is in boundary lubrication,
#: where friction coefficients of about 0.08-0.12 are usual. 0.1 is the middle
#: of that range; calibrate it against a measured running torque where one exists.
DEFAULT_MU = 0.1
#: Sliding-velocity regularisation ``eps``, as a fraction of ``|omega| a`` (the
#: sliding speed at the ellipse edge of a spin as fast as the ring); the
#: spin of a two-contact ball is about ``0.35 |omega|``, so eps is ~0.3 % of it
DEFAULT_SLIDING_REGULARISATION = 1e-3


def check_number(name: str, value, minimum: float | None = None, strict: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} = {value!r}: must be a number")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} = {value!r}: must be finite (not NaN or infinite)")
    if minimum is not None and (value < minimum or (strict and value == minimum)):
        raise ValueError(f"{name} = {value!r}: must be {'>' if strict else '>='} {minimum:g}")
    return value


def conformity_radius(ball_radius, groove_radius):
    """Radius ``R_d`` of the deformed contact surface across the groove, m.

    Harmonic mean of the ball and groove radii, ``2 r_b R_c / (r_b + R_c)``
    (Harris & Kotzalas, *Rolling Bearing Analysis*: the pressure surface of a
    ball in a conforming groove lies between the two)."""
    rb = np.asarray(ball_radius, dtype=float)
    rc = np.asarray(groove_radius, dtype=float)
    return 2.0 * rb * rc / (rb + rc)


@dataclass(frozen=True)
class EllipseFriction:
    """Friction integrated over one contact ellipse, in the contact's frame
    (t: rolling direction, g: across the groove, n: normal out of the ball).

    Attributes
    ----------
    force : ndarray (..., 3), N
        Friction force on the ball, components along (t, g, n).
    moment : ndarray (..., 3), N m
        Its moment about the centre of the ellipse.
    power : ndarray (...), W
        Dissipated power ``integral tau . v_s dA`` (>= 0).
    """

    force: np.ndarray
    moment: np.ndarray
    power: np.ndarray


def ellipse_friction(load, a, b, mu, *, sliding_velocity=(0.0, 0.0), relative_rotation=(0.0, 0.0, 0.0),
                     conformity_radius=np.inf, quadrature=None, regularisation=0.0) -> EllipseFriction:
    """Coulomb friction on one Hertz contact ellipse for a rigid relative motion.

    The raceway moves relative to the ball with the velocity ``v0 + w x (x - x0)``
    (``x0`` the centre of the ellipse). The friction traction on the ball is
    ``mu p v_s / |v_s|``, ``v_s`` the tangential part of that velocity on the
    contact surface: it drags the ball along with the raceway. This is the
    integration used by :func:`friction_torque`, for one contact.

    Parameters
    ----------
    load : float or array, N
        Contact load ``Q``.
    a, b : float or array, m
        Semi-axes across the groove (``g``) and along the rolling direction (``t``).
    mu : float
        Coulomb coefficient.
    sliding_velocity : (..., 2) array_like, m/s
        ``v0`` along (t, g).
    relative_rotation : (..., 3) array_like, rad/s
        ``w`` along (t, g, n); ``(0, 0, w_n)`` is a pure spin (pivoting).
    conformity_radius : float or array, m
        ``R_d`` of the contact surface across the groove; ``inf``: a flat ellipse.
    quadrature : int, (int, int), EllipseQuadrature or None
        None: ``DEFAULT_QUADRATURE[0]`` points across and as many along as
        keep the spacing (``>= n_across * b / a``, at least
        ``DEFAULT_QUADRATURE[1]``): the bearing default suits its slender
        ellipses (``a/b`` about 5-10), not a circle.
    regularisation : float or array, m/s
        ``|v_s|`` becomes ``sqrt(|v_s|^2 + regularisation^2)``.

    Returns
    -------
    EllipseFriction

    Examples
    --------
    Pivoting moment of a circular contact, ``3 pi / 16 mu Q a``:

    >>> f = ellipse_friction(1000.0, 1e-3, 1e-3, 0.1, relative_rotation=(0, 0, 1.0), quadrature=40)
    >>> round(float(f.moment[2] / (3 * math.pi / 16 * 0.1 * 1000.0 * 1e-3)), 3)
    1.0
    """
    if quadrature is None:
        n_across = DEFAULT_QUADRATURE[0]
        ratio = float(np.max(np.asarray(b, dtype=float) / np.asarray(a, dtype=float)))
        quadrature = (n_across, max(DEFAULT_QUADRATURE[1], math.ceil(n_across * ratio)))
    quad = as_quadrature(quadrature)
    q = np.asarray(load, dtype=float)
    a = np.asarray(a, dtype=float)[..., None]
    b = np.asarray(b, dtype=float)[..., None]
    radius = np.asarray(conformity_radius, dtype=float)[..., None]
    eta, xi = a * quad.across, b * quad.along
    flat = np.isinf(radius)
    finite = np.where(flat, 1.0, radius)
    theta = np.where(flat, 0.0, eta / finite)
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    rg = np.where(flat, eta, finite * sin_t)                  # bent surface, centre of curvature on -n
    rn = np.where(flat, 0.0, finite * (cos_t - 1.0))
    rt = xi
    v0 = np.asarray(sliding_velocity, dtype=float)
    w = np.asarray(relative_rotation, dtype=float)
    vt = v0[..., 0, None] + w[..., 1, None] * rn - w[..., 2, None] * rg     # v = v0 + w x r
    vg = v0[..., 1, None] + w[..., 2, None] * rt - w[..., 0, None] * rn
    vn = w[..., 0, None] * rg - w[..., 1, None] * rt
    s1, s2 = vt, cos_t * vg - sin_t * vn                      # along t and along the bent g
    speed = np.sqrt(s1**2 + s2**2 + np.asarray(regularisation, dtype=float)[..., None] ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(speed > 0.0, (mu * q)[..., None] * quad.weight / speed, 0.0)
    ft, fb = scale * s1, scale * s2
    fg, fn = fb * cos_t, -fb * sin_t
    force = np.stack([ft.sum(-1), fg.sum(-1), fn.sum(-1)], axis=-1)
    moment = np.stack([(rg * fn - rn * fg).sum(-1), (rn * ft - rt * fn).sum(-1), (rt * fg - rg * ft).sum(-1)],
                      axis=-1)
    power = (scale * (s1**2 + s2**2)).sum(-1)
    return EllipseFriction(force, moment, power)
