"""Coupling of a groove centre to its raceway, and the half-space part it must not count.

The master of contact ``i`` is the groove centre ``O_i`` with
a radial and an axial degree of freedom. Its force is passed to the raceway
as a **normal pressure over a patch** around the nominal contact point, the
way the ball passes it (frictionless contact: every pressure line goes
through ``O_i``):

    p(x, s) = [lambda_0 + lambda_1 x / a] w(x / a) H(s),     w(t) = sqrt(1 - t^2)

* ``x`` is the arc length along the groove from the contact point, ``|x| <= a``;
  ``s`` the arc length along the circumference, ``H(s) = 2/(pi b) sqrt(1 - s^2/b^2)``
  (unit integral). ``a`` and ``b`` are the semi-axes of the Hertz contact
  ellipse at a reference load (:func:`patch_size`): the patch Daidie's
  mechanism ties to the groove centre (paper section 2.2, ref. [11]).
* ``(lambda_0, lambda_1)`` are fixed by the master force ``(F_R, F_z)``: the
  resultant of the pressure equals it, and its moment about ``O_i`` is zero by
  construction. A force along the nominal contact normal is a symmetric
  (Hertz-like) pressure; a component across it is the linear part
  ``lambda_1``, which moves the centre of pressure along the groove -- what a
  change of contact angle does.
* The master displacement is the work-conjugate of this load (distributing,
  RBE3-like coupling: it spreads the force, adds no stiffness). For any rigid
  motion of the raceway it equals the rigid motion of ``O_i`` exactly.

**No double counting of the Hertz deformation.** The Hertz springs contain
the approach of the ball and the "distant" ring material: the deformation of a
flat elastic half-space under the contact pressure. A ring model loaded by a
pressure patch contains that local deformation as well (it grows like
``1/a`` when the patch shrinks, and the harmonic sum only converges beyond
``n ~ R/b`` harmonics). So the compliance the superelement keeps is

    G_ring = G_FE - G_halfspace,self

where ``G_halfspace,self`` is the compliance of the same patch load on a flat
half-space with the ring's E and nu (Boussinesq, Fourier form
``u_hat = 2 (1 - nu^2) / (E |k|) p_hat``; Johnson, *Contact Mechanics*, ch. 3),
computed here in closed form up to a 1-D or 2-D quadrature. Per circumferential
harmonic the FE compliance tends to the half-space one (:func:`halfspace_harmonic`),
so harmonics above the FE cut-off are summed with the half-space value; what is
left converges fast in both the number of harmonics and the mesh, and depends
little on the patch size (less than 0.5 % over a fourfold range: docs/theory/superelement.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from ...bearing.contact import hertz_ellipse
from ...bearing.geometry import RING_CONTACTS, Bearing

#: default reference pressure of the patch: the Hertz ellipse at this maximum pressure, Pa
REFERENCE_PRESSURE = 2500e6


def patch_size(bearing: Bearing, contact: int, pressure: float = REFERENCE_PRESSURE) -> tuple[float, float]:
    """Semi-axes (a across the groove, b along the circumference), m, of the Hertz
    contact ellipse of ``contact`` whose maximum pressure is ``pressure`` (Pa)."""
    ring = "outer" if contact in RING_CONTACTS["outer"] else "inner"
    args = (bearing.ball_diameter, bearing.groove_radius[contact - 1], bearing.contact_angle,
            bearing.pitch_diameter, ring, bearing.youngs_modulus, bearing.poisson_ratio)
    q1 = 1000.0
    p1 = float(hertz_ellipse(q1, *args).max_pressure)
    e = hertz_ellipse(q1 * (pressure / p1) ** 3, *args)
    return float(e.a), float(e.b)


@dataclass(frozen=True)
class Patch:
    """Load patch of one groove centre.

    Attributes
    ----------
    contact : int
    centre : (2,) array, m
        Groove centre ``O``.
    groove_radius : float, m
    psi : float, rad
        Direction of the nominal contact point seen from ``O``.
    a, b : float, m
        Half-width along the groove arc and along the circumference.
    radius : float, m
        Radius r of the contact point (circumferential arc length s = r theta).
    """

    contact: int
    centre: np.ndarray
    groove_radius: float
    psi: float
    a: float
    b: float
    radius: float

    def pressure_basis(self, r, z):
        """Normal direction (2, ...) and the two basis pressures w(x/a), (x/a) w(x/a) at (r, z)."""
        dr, dz = r - self.centre[0], z - self.centre[1]
        rho = np.hypot(dr, dz)
        psi = self.psi + np.remainder(np.arctan2(dz, dr) - self.psi + np.pi, 2 * np.pi) - np.pi
        t = np.clip(self.groove_radius * (psi - self.psi) / self.a, -1.0, 1.0)
        w = np.sqrt(1.0 - t * t)
        return np.stack([dr / rho, dz / rho]), w, t * w

    def resultant_matrix(self) -> np.ndarray:
        """Resultant (F_R, F_z) of the two basis pressures on the exact arc, columns (2, 2), m:
        ``a pi J1(c)/c n`` and ``a pi J2(c)/c t`` with ``c = a / Rc``, n and t the contact normal
        and the groove tangent at the contact point. Its inverse maps a master force to
        (lambda_0, lambda_1); :func:`master_loads` computes the same on the mesh."""
        c = self.a / self.groove_radius
        n = np.array([math.cos(self.psi), math.sin(self.psi)])
        t = np.array([-math.sin(self.psi), math.cos(self.psi)])
        return np.stack([self.a * math.pi * special.j1(c) / c * n, self.a * math.pi * special.jv(2, c) / c * t],
                        axis=1)

    def circumferential_factor(self, n):
        """``h_n``: Fourier coefficient of the unit circumferential profile H, ``2 J1(k b)/(k b)``
        with ``k = n / radius``."""
        x = np.asarray(n, dtype=float) * self.b / self.radius
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(x == 0.0, 1.0, 2.0 * special.j1(x) / np.where(x == 0, 1, x))


def ring_patches(bearing: Bearing, ring: str, sizes) -> tuple[Patch, Patch]:
    """The two patches of ``ring`` in DOF order (contacts (1, 4) or (2, 3)).

    ``sizes``: ((a, b), (a, b)) for the two contacts, m."""
    from .section import contact_direction

    out = []
    for c, (a, b) in zip(RING_CONTACTS[ring], sizes):
        o = bearing.groove_centres[c - 1]
        psi = contact_direction(c, bearing.contact_angle)
        rc = float(bearing.groove_radius[c - 1])
        r_p = float(o[0] + rc * math.cos(psi))
        out.append(Patch(c, np.asarray(o, float), rc, psi, float(a), float(b), r_p))
    return tuple(out)


def basis_loads(model, facets, patch: Patch) -> np.ndarray:
    """Load vectors (ndofs, 2) of the patch's two basis pressures ``w0, w1`` acting along the
    raceway normal over ``facets`` (traction ``P / r``: see :func:`master_loads`)."""
    loads = []
    for k in (1, 2):
        def traction(r, z, k=k):
            nrm, w0, w1 = patch.pressure_basis(r, z)
            p = (w0, w1)[k - 1] / r
            return (p * nrm[0], 0.0 * r, p * nrm[1])
        loads.append(model.facet_load(facets, traction, intorder=12))
    return np.stack(loads, axis=1)


def master_loads(model, mesh_facets, patches) -> tuple[np.ndarray, list]:
    """Load vectors of unit master forces, shape (ndofs, 4), columns [R_a, z_a, R_b, z_b].

    Returns also, per patch, the 2x2 map ``Lam`` from the master force (F_R, F_z) to the
    basis coefficients (lambda_0, lambda_1), used for the half-space part.

    The load vector of a basis pressure P is ``int P n . N dx`` over the patch facets
    (per unit of the theta integral, without the r of the measure: the traction is
    ``P h(theta) / r`` so that the force of an element is ``P h dtheta dx``)."""
    e_u = model.field(u=lambda r, z: 1.0)
    e_w = model.field(w=lambda r, z: 1.0)
    cols, lams = [], []
    for facets, patch in zip(mesh_facets, patches):
        g = basis_loads(model, facets, patch)        # (ndofs, 2) basis pressures
        resultant = np.stack([e_u @ g, e_w @ g])     # rows F_R, F_z; columns lambda_0, lambda_1
        lam = np.linalg.inv(resultant)
        cols.append(g @ lam)
        lams.append(lam)
    return np.concatenate(cols, axis=1), lams


# ---- flat half-space (Boussinesq) -----------------------------------------------------------

def _basis_spectra(u):
    """|P_hat|^2 / (pi a)^2 of the two basis pressures at u = xi a: (J1(u)/u)^2, (J2(u)/u)^2."""
    u = np.asarray(u, dtype=float)
    safe = np.where(u == 0, 1.0, u)
    s0 = np.where(u == 0, 0.25, (special.j1(safe) / safe) ** 2)
    s1 = np.where(u == 0, 0.0, (special.jv(2, safe) / safe) ** 2)
    return s0, s1


_U_NODES, _U_WEIGHTS = None, None


def _u_quadrature():
    """Quadrature of int_0^inf f(u) du for the Bessel spectra (smooth, decaying like u^-3)."""
    global _U_NODES, _U_WEIGHTS
    if _U_NODES is None:
        x, w = np.polynomial.legendre.leggauss(64)
        edges = np.concatenate([np.linspace(0, 40, 41), np.geomspace(40, 4e4, 60)[1:]])
        nodes = [0.5 * (b - a) * x + 0.5 * (b + a) for a, b in zip(edges[:-1], edges[1:])]
        weights = [0.5 * (b - a) * w for a, b in zip(edges[:-1], edges[1:])]
        _U_NODES, _U_WEIGHTS = np.concatenate(nodes), np.concatenate(weights)
    return _U_NODES, _U_WEIGHTS


def halfspace_harmonic(patch: Patch, n, youngs_modulus: float, poisson_ratio: float) -> np.ndarray:
    """Half-space compliance of harmonic(s) ``n`` in the basis (lambda_0, lambda_1), shape (len(n), 2).

    The flat-half-space analogue of ``g_i^T K(n)^-1 g_i``: the basis pressure
    ``P_i(x) cos(k s)``, ``k = n / r``, on a half-space, work-conjugate normal
    displacement, per unit of the theta integral:

        c_n,i = (1 / r) int dxi / (2 pi) |P_i_hat(xi)|^2 2 (1 - nu^2) / (E sqrt(xi^2 + k^2))

    The two basis pressures (even and odd in x) do not couple on a flat half-space."""
    n = np.atleast_1d(np.asarray(n, dtype=float))
    u, wq = _u_quadrature()
    s0, s1 = _basis_spectra(u)
    a, r = patch.a, patch.radius
    factor = 2 * (1 - poisson_ratio**2) / youngs_modulus
    ka = (n * a / r)[:, None]
    kern = 1.0 / np.sqrt(u[None, :] ** 2 + ka**2)
    # xi = u / a: int dxi/(2 pi) (pi a)^2 s(u) / sqrt(xi^2 + k^2) = pi a^2 int_0^inf s(u) / sqrt(u^2 + (k a)^2) du
    c = np.stack([(kern * s).dot(wq) for s in (s0, s1)], axis=1)
    return c * np.pi * a**2 * factor / r


def halfspace_self(patch: Patch, youngs_modulus: float, poisson_ratio: float) -> np.ndarray:
    """Half-space compliance of the patch load on itself, basis (lambda_0, lambda_1): diag (2,), m/N.

        C_i = int dxi deta / (4 pi^2) |P_i_hat(xi)|^2 |H_hat(eta)|^2 2 (1 - nu^2) / (E sqrt(xi^2 + eta^2))

    evaluated in polar coordinates of (xi a, eta b) so that the 1/kappa singularity is absorbed.
    It depends on a, b, E, nu only and is remembered (both patches of a ring usually agree)."""
    key = (patch.a, patch.b, youngs_modulus, poisson_ratio)
    if key not in _SELF_CACHE:
        _SELF_CACHE[key] = _halfspace_self(patch.a, patch.b, youngs_modulus, poisson_ratio)
    return _SELF_CACHE[key].copy()


_SELF_CACHE: dict = {}


def _halfspace_self(a, b, youngs_modulus, poisson_ratio):
    factor = 2 * (1 - poisson_ratio**2) / youngs_modulus
    u, wu = _u_quadrature()                      # radial variable rho in the scaled plane
    xt, wt = np.polynomial.legendre.leggauss(96)
    th = 0.25 * np.pi * (xt + 1.0)               # first quadrant, (0, pi/2)
    wt = 0.25 * np.pi * wt
    # scaled coordinates: xi a = rho cos(th), eta b = rho sin(th); d xi d eta = rho drho dth / (a b)
    ux = u[:, None] * np.cos(th)[None, :]
    uy = u[:, None] * np.sin(th)[None, :]
    kappa = np.sqrt((ux / a) ** 2 + (uy / b) ** 2)
    hy = np.where(uy == 0, 1.0, 2 * special.j1(uy) / np.where(uy == 0, 1, uy)) ** 2
    out = []
    for s in _basis_spectra(ux):
        integrand = s * (np.pi * a) ** 2 * hy / kappa * u[:, None] / (a * b)
        out.append(4.0 * wu.dot(integrand).dot(wt) / (4 * np.pi**2))   # 4 quadrants
    return np.array(out) * factor
