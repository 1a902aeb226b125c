"""Hertz contact: Houpert's formula (paper eqs 9-11) and the exact Hertz ellipse."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from slewing_model.bearing.contact import (contact_load, diagonal_stiffness, elliptic_integrals, hertz_ellipse,
                                   houpert_stiffness)


def test_houpert_stiffness_matches_paper_formula_in_n_mm():
    # paper eq 10 written out in N and mm, converted by hand: 1 N/mm^1.5 = 1e3^1.5 N/m^1.5
    dw_mm, rc_mm = 35.0, 18.56
    s = dw_mm / (2 * rc_mm)
    k_nmm = 88220 * dw_mm**0.5 / (1 - s) ** 0.3621
    assert houpert_stiffness(dw_mm * 1e-3, s) == pytest.approx(k_nmm * 1e3**1.5, rel=1e-12)


def test_houpert_deflection_is_eq9():
    # eq 9: delta = 5.046e-4 (1-s)^0.2414 Q^(2/3) / Dw^(1/3), mm; eq 10 is its inverse to 4 digits
    dw_mm, s, q = 25.0, 25.0 / 26.5, 5000.0
    delta_eq9_mm = 5.046e-4 * (1 - s) ** 0.2414 * q ** (2 / 3) / dw_mm ** (1 / 3)
    k = houpert_stiffness(dw_mm * 1e-3, s)
    assert (q / k) ** (2 / 3) == pytest.approx(delta_eq9_mm * 1e-3, rel=2e-3)


def test_series_stiffness_adds_deflections():
    # eq 11: under one load Q the two deflections add up
    ka, kb, q = 3.0e10, 5.0e10, 8000.0
    ktot = diagonal_stiffness(ka, kb)
    assert (q / ktot) ** (2 / 3) == pytest.approx((q / ka) ** (2 / 3) + (q / kb) ** (2 / 3), rel=1e-12)


def test_contact_is_traction_only():
    assert np.all(contact_load([-1e-6, 0.0], 1e10) == 0.0)
    assert contact_load(1e-6, 1e10) == pytest.approx(1e10 * 1e-9)


def test_elliptic_integrals_match_scipy():
    m = np.linspace(0.0, 0.9999, 50)
    k, e = elliptic_integrals(m)
    assert np.allclose(k, ellipk(m), rtol=1e-13) and np.allclose(e, ellipe(m), rtol=1e-13)


def _hertz_reference(q, dw, rc, alpha, dm, ring, youngs=2e11, nu=0.3):
    """Exact Hertz, solved independently with scipy (Harris & Kotzalas eqs 6.25-6.41)."""
    gamma = dw * math.cos(alpha) / dm
    rolling = 2 / dw * gamma / (1 - gamma) if ring == "inner" else -2 / dw * gamma / (1 + gamma)
    rho = [2 / dw, 2 / dw, rolling, -1 / rc]
    sum_rho = sum(rho)
    f_rho = ((rho[0] - rho[1]) + (rho[2] - rho[3])) / sum_rho

    def f_of_kappa(kappa):
        m = 1 - 1 / kappa**2
        return ((kappa**2 + 1) * ellipe(m) - 2 * ellipk(m)) / ((kappa**2 - 1) * ellipe(m)) - f_rho

    kappa = brentq(f_of_kappa, 1.0 + 1e-9, 500.0, xtol=1e-14)
    m = 1 - 1 / kappa**2
    cap_e, cap_k = ellipe(m), ellipk(m)
    x = 3 * q / (2 * sum_rho) * 2 * (1 - nu**2) / youngs
    a = (2 * kappa**2 * cap_e / math.pi) ** (1 / 3) * x ** (1 / 3)
    b = (2 * cap_e / (math.pi * kappa)) ** (1 / 3) * x ** (1 / 3)
    delta = 2 * cap_k / math.pi * (math.pi / (2 * kappa**2 * cap_e)) ** (1 / 3) * x ** (2 / 3) * sum_rho / 2
    return a, b, 3 * q / (2 * math.pi * a * b), delta


@pytest.mark.parametrize("ring", ["inner", "outer"])
@pytest.mark.parametrize("rc_ratio", [0.505, 0.52, 0.53, 0.56])
def test_ellipse_matches_exact_hertz(ring, rc_ratio):
    dw, dm, alpha, q = 0.035, 1.5, math.radians(45), 12e3
    ref = _hertz_reference(q, dw, rc_ratio * dw, alpha, dm, ring)
    ell = hertz_ellipse(q, dw, rc_ratio * dw, alpha, dm, ring)
    got = (ell.a, ell.b, ell.max_pressure, ell.deflection)
    assert np.allclose(got, ref, rtol=2e-5)


def test_sphere_on_flat_is_circular_closed_form():
    # a groove of infinite radius and no rolling curvature: ball on a flat, a = (3 Q R / (4 E*))^(1/3)
    dw, q, youngs, nu = 0.02, 1000.0, 2e11, 0.3
    ell = hertz_ellipse(q, dw, 1e12, math.pi / 2, 1e3, "outer", youngs, nu)
    e_star = youngs / (2 * (1 - nu**2))
    a = (3 * q * dw / 2 / (4 * e_star)) ** (1 / 3)
    assert ell.a == pytest.approx(a, rel=1e-6) and ell.b == pytest.approx(a, rel=1e-6)
    assert ell.max_pressure == pytest.approx(3 * q / (2 * math.pi * a**2), rel=1e-5)


@pytest.mark.parametrize("s", [0.89, 0.92, 0.95, 0.97])
def test_houpert_agrees_with_exact_hertz_deflection(s):
    # Houpert fitted exact Hertz for osculations 0.89..0.99 (paper ref. [22]); with the small
    # rolling curvature of a large slewing bearing (dm/Dw ~ 40) the two agree within 3 %
    dw, dm, q = 0.035, 1.5, 10e3
    exact = hertz_ellipse(q, dw, dw / (2 * s), math.radians(45), dm, "outer").deflection
    houpert = (q / houpert_stiffness(dw, s)) ** (2 / 3)
    assert houpert == pytest.approx(exact, rel=0.03)
