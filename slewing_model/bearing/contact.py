"""Hertz contact of a ball in a raceway groove (paper eqs 8-11).

* :func:`houpert_stiffness` -- Houpert's load-deflection constant (eqs 9-10).
  The paper gives it in N and mm; this function is the **one place** where
  that formula is converted to SI (N / m^1.5).
* :func:`diagonal_stiffness` -- two contacts of a diagonal in series (eq 11).
* :func:`contact_load` -- traction-only ``Q = K delta^1.5`` (eq 8, 10).
* :func:`hertz_ellipse` -- exact Hertz point contact: semi-axes of the contact
  ellipse, maximum pressure and deflection, from the curvatures of ball and
  raceway (Harris & Kotzalas, *Rolling Bearing Analysis*, ch. 6). The complete
  elliptic integrals are evaluated with the arithmetic-geometric mean, so this
  module needs numpy only (it runs inside the FMU).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Houpert's formula holds for E = 2e5 MPa and nu = 0.3 (paper, after eq 8)
_HOUPERT_EFFECTIVE_MODULUS = 2.0e11 / (1.0 - 0.3**2)
#: ISO 76 contact pressure limit for ball bearings, Pa (static load rating)
ISO76_PRESSURE_LIMIT = 4200e6


def effective_modulus(youngs_modulus: float, poisson_ratio: float) -> float:
    """``E' = E / (1 - nu^2)`` for two bodies of the same material (Pa).

    Hertz: ``1/E* = 2 (1 - nu^2)/E``, so ``E* = E'/2``."""
    return youngs_modulus / (1.0 - poisson_ratio**2)


def houpert_stiffness(ball_diameter, osculation, youngs_modulus=2.0e11, poisson_ratio=0.3):
    """Hertz load-deflection constant K of one ball-raceway contact (paper eq 10).

    ``Q = K delta^1.5`` with ``K = 88220 Dw^0.5 / (1 - s)^0.3621`` in N/mm^1.5
    (Houpert, valid for osculations 0.89..0.99), scaled by ``E'`` for other
    materials (Hertz: K is proportional to ``E/(1-nu^2)``).

    Parameters
    ----------
    ball_diameter : float or array, m
    osculation : float or array
        ``s = Dw / (2 Rc)``, in (0, 1).
    youngs_modulus : float, Pa
    poisson_ratio : float

    Returns
    -------
    K : float or array, N/m^1.5

    Examples
    --------
    >>> round(houpert_stiffness(0.035, 35 / 37.12) / 1e9, 3)   # N/m^1.5 -> 1e9
    46.536
    """
    dw_mm = np.asarray(ball_diameter) * 1e3
    k_n_per_mm15 = 88220.0 * np.sqrt(dw_mm) / (1.0 - np.asarray(osculation)) ** 0.3621
    scale = effective_modulus(youngs_modulus, poisson_ratio) / _HOUPERT_EFFECTIVE_MODULUS
    return k_n_per_mm15 * 1e3**1.5 * scale  # N/mm^1.5 -> N/m^1.5


def diagonal_stiffness(k_a, k_b):
    """Total stiffness of two contacts in series (paper eq 11):
    ``1/Ktot^(2/3) = 1/Ka^(2/3) + 1/Kb^(2/3)``."""
    return (np.asarray(k_a) ** (-2.0 / 3.0) + np.asarray(k_b) ** (-2.0 / 3.0)) ** -1.5


def contact_load(interference, stiffness):
    """Traction-only Hertz load ``Q = K delta^1.5`` for ``delta > 0``, else 0 (eqs 8, 10)."""
    delta = np.maximum(np.asarray(interference, dtype=float), 0.0)
    return stiffness * delta**1.5


def contact_deflection(load, stiffness):
    """Inverse of :func:`contact_load`: ``delta = (Q/K)^(2/3)``."""
    return (np.maximum(np.asarray(load, dtype=float), 0.0) / stiffness) ** (2.0 / 3.0)


# ---- exact Hertz ellipse ------------------------------------------------------------

def elliptic_integrals(m):
    """Complete elliptic integrals K(m) and E(m) of parameter ``m = e^2`` in [0, 1).

    Arithmetic-geometric mean (Abramowitz & Stegun 17.6): converges to machine
    precision in a handful of steps."""
    m = np.asarray(m, dtype=float)
    a = np.ones_like(m)
    b = np.sqrt(1.0 - m)
    c = np.sqrt(m)
    total = 0.5 * c**2
    power = 0.5
    for _ in range(30):
        if np.all(np.abs(c) < 1e-16):
            break
        a, b, c = 0.5 * (a + b), np.sqrt(a * b), 0.5 * (a - b)
        power *= 2.0
        total = total + power * c**2
    k = np.pi / (2.0 * a)
    return k, k * (1.0 - total)


def _curvature_difference(kappa):
    """Hertz's ``F(rho)`` as a function of the ellipticity ``kappa = a/b >= 1``."""
    k, e = elliptic_integrals(1.0 - 1.0 / kappa**2)
    return ((kappa**2 + 1.0) * e - 2.0 * k) / ((kappa**2 - 1.0) * e)


# Table of F(rho), K and E against log(kappa), built once: inverting it by
# interpolation costs microseconds per call instead of an iteration per contact
# (checked against an independent exact solution in tests/test_contact.py).
_LOG_KAPPA = np.linspace(1e-6, math.log(200.0), 6001)
_K_TABLE, _E_TABLE = elliptic_integrals(1.0 - np.exp(-2.0 * _LOG_KAPPA))
_F_TABLE = _curvature_difference(np.exp(_LOG_KAPPA))


@dataclass(frozen=True)
class ContactEllipse:
    """Hertz contact ellipse of a ball-raceway contact (arrays broadcast like the load).

    Attributes
    ----------
    a : semi-axis across the groove (the major one in a conformal groove), m
    b : semi-axis along the rolling direction, m
    max_pressure : Pa
    deflection : approach of ball and raceway, m
    kappa : ellipticity a/b
    """

    a: np.ndarray
    b: np.ndarray
    max_pressure: np.ndarray
    deflection: np.ndarray
    kappa: np.ndarray


def raceway_curvatures(ball_diameter, groove_radius, contact_angle, pitch_diameter, ring):
    """Principal curvature sums of a ball on a raceway (Harris & Kotzalas, eqs 2.29-2.32).

    Returns ``(sum_rho, f_rho)``: the curvature sum (1/m) and the curvature
    difference ``F(rho)``. ``ring`` is ``"inner"`` or ``"outer"``.
    """
    dw = np.asarray(ball_diameter, dtype=float)
    gamma = dw * np.cos(contact_angle) / pitch_diameter
    inner = np.asarray(ring) == "inner"
    rolling = np.where(inner, 2.0 / dw * gamma / (1.0 - gamma), -2.0 / dw * gamma / (1.0 + gamma))
    transverse = -1.0 / np.asarray(groove_radius, dtype=float)
    rho_ball = 2.0 / dw
    sum_rho = 2.0 * rho_ball + rolling + transverse
    f_rho = (rolling - transverse) / sum_rho
    return sum_rho, f_rho


def hertz_ellipse(load, ball_diameter, groove_radius, contact_angle, pitch_diameter, ring,
                  youngs_modulus=2.0e11, poisson_ratio=0.3) -> ContactEllipse:
    """Exact Hertz contact of a ball in a groove.

    Parameters
    ----------
    load : float or array, N
        Contact load Q (>= 0; zero gives a zero ellipse).
    ball_diameter, groove_radius : float or array, m
    contact_angle : float or array, rad
    pitch_diameter : float, m
    ring : str or array of str
        ``"inner"`` or ``"outer"`` (sign of the rolling-direction curvature),
        per contact if an array.
    youngs_modulus : float, Pa
    poisson_ratio : float

    Returns
    -------
    ContactEllipse
        ``a = (6 kappa^2 E Q / (pi sum_rho E'))^(1/3)``,
        ``b = (6 E Q / (pi kappa sum_rho E'))^(1/3)``,
        ``p_max = 3 Q / (2 pi a b)``,
        ``delta = (2 K / pi) (pi / (2 kappa^2 E))^(1/3) (3 Q/(sum_rho E'))^(2/3) sum_rho / 2``,
        with K, E the complete elliptic integrals of modulus ``1 - 1/kappa^2``.
    """
    q = np.maximum(np.asarray(load, dtype=float), 0.0)
    sum_rho, f_rho = raceway_curvatures(ball_diameter, groove_radius, contact_angle, pitch_diameter, ring)
    log_kappa = np.interp(f_rho, _F_TABLE, _LOG_KAPPA, left=0.0)
    kappa = np.exp(log_kappa)
    k_int = np.interp(log_kappa, _LOG_KAPPA, _K_TABLE)
    e_int = np.interp(log_kappa, _LOG_KAPPA, _E_TABLE)
    e_eff = effective_modulus(youngs_modulus, poisson_ratio)
    base = 3.0 * q / (sum_rho * e_eff)
    a = (2.0 * kappa**2 * e_int / np.pi * base) ** (1.0 / 3.0)
    b = (2.0 * e_int / (np.pi * kappa) * base) ** (1.0 / 3.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        p_max = np.where(q > 0.0, 1.5 * q / (np.pi * a * b), 0.0)
    delta = (2.0 * k_int / np.pi) * (np.pi / (2.0 * kappa**2 * e_int)) ** (1.0 / 3.0) * base ** (2.0 / 3.0) * sum_rho / 2.0
    return ContactEllipse(a=a, b=b, max_pressure=p_max, deflection=delta, kappa=kappa)
