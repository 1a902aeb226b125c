"""Fourier-harmonic finite element model of an axisymmetric ring.

The ring is a solid of revolution about z. A displacement field of harmonic
``n`` of the *symmetric family* is

    u_r = U(r, z) cos(n theta),   u_theta = V(r, z) sin(n theta),   u_z = W(r, z) cos(n theta)

and its strains (cylindrical coordinates; Zienkiewicz & Taylor, *The Finite
Element Method*, vol. 1, "axisymmetric solids under non-symmetric load") are,
with the theta factor taken out,

    eps_r   = dU/dr                       eps_z   = dW/dz
    eps_t   = (U + n V) / r               gam_rz  = dU/dz + dW/dr
    gam_rt  = (-n U + r dV/dr - V) / r    gam_tz  = dV/dz - n W / r

i.e. ``eps = B0 u + n B1 u``. The strain energy of the whole ring is
``c_n / 2 * int eps^T D eps r dr dz`` with ``c_n = pi`` (n >= 1) or ``2 pi``
(n = 0). The *antisymmetric* family (sin, cos, sin) has the same stiffness
for n >= 1, so one family per harmonic is enough. The model works with the
stiffness without the ``c_n`` factor,

    K(n) = K0 + n K1 + n^2 K2,     K0 = int B0^T D B0 r,   K1 = int (B0^T D B1 + B1^T D B0) r,
                                   K2 = int B1^T D B1 r,

assembled once; a load ``t(r, z) cos(n theta)`` then has the load vector
``f = int t . N (r dA or r ds)`` without the ``c_n`` factor either, which cancels.

Quadratic triangles (scikit-fem ``ElementTriP2``), three fields U, V, W.
For n = 0 the V field (torsion about z) decouples from U, W and is dropped:
the groove-centre masters have no circumferential degree of freedom.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementTriP2, ElementVector, FacetBasis, LinearForm, MeshTri, asm


def lame(youngs_modulus: float, poisson_ratio: float) -> tuple[float, float]:
    """Lame constants (lambda, mu), Pa."""
    e, nu = youngs_modulus, poisson_ratio
    return e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))


def _strains(w, r):
    """(B0 w, B1 w): the n-independent part and the coefficient of n of the six strains
    [eps_r, eps_t, eps_z, gam_rz, gam_rt, gam_tz] of field ``w`` (U, V, W)."""
    (U, V, W), (dU, dV, dW) = w, w.grad
    zero = 0.0 * U
    b0 = (dU[0], U / r, dW[1], dU[1] + dW[0], dV[0] - V / r, dV[1])
    b1 = (zero, V / r, zero, zero, -U / r, -W / r)
    return b0, b1


def _energy(lam, mu, a, b):
    """eps_a^T D eps_b for isotropic D (engineering shear strains)."""
    tr_a, tr_b = a[0] + a[1] + a[2], b[0] + b[1] + b[2]
    return (lam * tr_a * tr_b + 2 * mu * (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
            + mu * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]))


class HarmonicRingModel:
    """K(n) = K0 + n K1 + n^2 K2 of a ring cross-section, and harmonic solves.

    Parameters
    ----------
    mesh : skfem.MeshTri
        Cross-section in (r, z), m; all r > 0.
    youngs_modulus : float, Pa
    poisson_ratio : float
    intorder : int
        Quadrature order of the element integrals.
    """

    def __init__(self, mesh: MeshTri, youngs_modulus: float, poisson_ratio: float, intorder: int = 4):
        self.mesh = mesh
        self.youngs_modulus = youngs_modulus
        self.poisson_ratio = poisson_ratio
        self.element = ElementVector(ElementTriP2(), 3)
        self.basis = Basis(mesh, self.element, intorder=intorder)
        lam, mu = lame(youngs_modulus, poisson_ratio)

        @BilinearForm
        def k0(u, v, w):
            r = w.x[0]
            return _energy(lam, mu, _strains(u, r)[0], _strains(v, r)[0]) * r

        @BilinearForm
        def k1(u, v, w):
            r = w.x[0]
            (u0, u1), (v0, v1) = _strains(u, r), _strains(v, r)
            return (_energy(lam, mu, u0, v1) + _energy(lam, mu, u1, v0)) * r

        @BilinearForm
        def k2(u, v, w):
            r = w.x[0]
            return _energy(lam, mu, _strains(u, r)[1], _strains(v, r)[1]) * r

        self.K0 = asm(k0, self.basis).tocsr()
        self.K1 = asm(k1, self.basis).tocsr()
        self.K2 = asm(k2, self.basis).tocsr()
        b = self.basis
        n = b.N
        self.component = np.empty(n, dtype=int)       # 0 = U, 1 = V, 2 = W
        for c in range(3):
            self.component[b.nodal_dofs[c]] = c
            self.component[b.facet_dofs[c]] = c
        self.doflocs = b.doflocs

    @property
    def ndofs(self) -> int:
        return self.basis.N

    def stiffness(self, n: int) -> sp.csr_matrix:
        """K(n) (without the pi or 2 pi factor), N/m per unit of the theta integral."""
        return (self.K0 + n * self.K1 + (n * n) * self.K2).tocsr()

    # ---- degrees of freedom -----------------------------------------------------------
    def facet_dofs(self, facets, components=(0, 1, 2)) -> np.ndarray:
        """DOF indices of ``components`` on the nodes of ``facets``."""
        b = self.basis
        verts = np.unique(self.mesh.facets[:, facets])
        idx = [b.nodal_dofs[c, verts] for c in components] + [b.facet_dofs[c, facets] for c in components]
        return np.unique(np.concatenate(idx))

    def field(self, u=None, v=None, w=None) -> np.ndarray:
        """DOF vector interpolating the fields u(r, z), v(r, z), w(r, z) (callables or None)."""
        x = np.zeros(self.ndofs)
        r, z = self.doflocs
        for c, f in enumerate((u, v, w)):
            if f is not None:
                sel = self.component == c
                x[sel] = np.broadcast_to(f(r[sel], z[sel]), r[sel].shape)
        return x

    def rigid_modes(self, n: int) -> np.ndarray:
        """Rigid-body displacement fields of harmonic ``n`` (symmetric family), shape (ndofs, m).

        n = 0: translation along z (W = 1). n = 1: translation along x (U = 1, V = -1) and
        rotation about y (U = z, V = -z, W = -r). Rotation about z (n = 0, V = r) is not in
        the model (V is dropped at n = 0). Other n: none."""
        if n == 0:
            return self.field(w=lambda r, z: 1.0)[:, None]
        if n == 1:
            t = self.field(u=lambda r, z: 1.0, v=lambda r, z: -1.0)
            rot = self.field(u=lambda r, z: z, v=lambda r, z: -z, w=lambda r, z: -r)
            return np.stack([t, rot], axis=1)
        return np.zeros((self.ndofs, 0))

    # ---- loads ------------------------------------------------------------------------
    def facet_load(self, facets, traction, intorder: int = 8) -> np.ndarray:
        """Load vector of a traction ``traction(r, z) -> (t_r, t_theta, t_z)`` per unit area
        of the facets times cos/sin(n theta), i.e. ``int t . N r ds``."""
        fb = FacetBasis(self.mesh, self.element, facets=facets, intorder=intorder)

        @LinearForm
        def form(v, w):
            r, z = w.x
            t = traction(r, z)
            return (t[0] * v[0] + t[1] * v[1] + t[2] * v[2]) * r

        return asm(form, fb)

    def body_load(self, force) -> np.ndarray:
        """Load vector of a body force ``force(r, z) -> (f_r, f_theta, f_z)`` per unit volume,
        ``int f . N r dA``."""
        @LinearForm
        def form(v, w):
            r, z = w.x
            f = force(r, z)
            return (f[0] * v[0] + f[1] * v[1] + f[2] * v[2]) * r

        return asm(form, self.basis)

    # ---- solution ---------------------------------------------------------------------
    def solver(self, n: int, fixed=(), constraints=None):
        """A factorised solver of K(n) u = f.

        Parameters
        ----------
        n : int
        fixed : int array
            DOFs held at zero (supports).
        constraints : (ndofs, m) array or None
            Linear constraints ``C^T u = 0`` enforced with Lagrange multipliers (removal of
            rigid modes). For a load with no component along the constrained rigid modes the
            multipliers vanish and the solution is a solution of the unconstrained problem.

        Returns
        -------
        callable f -> u (arrays (ndofs,) or (ndofs, k)).
        """
        return _Solver(self, n, fixed, constraints)


class _Solver:
    def __init__(self, model: HarmonicRingModel, n: int, fixed, constraints):
        k = model.stiffness(n)
        keep = np.ones(model.ndofs, dtype=bool)
        keep[np.asarray(fixed, dtype=int)] = False
        if n == 0:
            keep &= model.component != 1
        self.free = np.flatnonzero(keep)
        kf = k[self.free][:, self.free]
        self.m = 0
        if constraints is not None and constraints.shape[1]:
            c = sp.csr_matrix(constraints[self.free])
            self.m = c.shape[1]
            kf = sp.bmat([[kf, c], [c.T, None]])
        self.lu = spla.splu(kf.tocsc(), permc_spec="COLAMD")
        self.n_all = model.ndofs

    def __call__(self, f):
        f = np.asarray(f, dtype=float)
        vec = f.ndim == 1
        f2 = f[:, None] if vec else f
        rhs = np.zeros((len(self.free) + self.m, f2.shape[1]))
        rhs[: len(self.free)] = f2[self.free]
        sol = self.lu.solve(rhs)
        u = np.zeros((self.n_all, f2.shape[1]))
        u[self.free] = sol[: len(self.free)]
        return u[:, 0] if vec else u
