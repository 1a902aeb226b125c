"""Connected structures condensed onto a ring's bolted face, per harmonic.

A ring's bolted face can be bolted to a **tube** (a blade root, a tower top) or a **plate** (a hub
or bedplate flange), both bodies of revolution (:class:`~slewing_model.bearing.connection.Adapter`),
or to a stiffness imported from another FE tool (:mod:`.imported`). Either way the structure
enters the ring's harmonic model as a **face stiffness** ``F(n)`` on the ring's bolted-face DOFs
(all P2 nodes of the face, components U, V, W), added to the ring's ``K(n)``:

    K_connected(n) = K_ring(n) + A^T F(n) A

The ring is then solved and condensed to its groove centres exactly as before
(:mod:`.condense`), with no other support: the connected structure's own support (its clamped
end) holds it, so the condensed matrix is positive definite like a clamped ring's.

**Parametric adapter.** The adapter's (r, z) section, a rectangle ``[inner_radius,
outer_radius] x [face, face -+ length]`` on the far side of the bolted face, is meshed with
quadratic triangles in the ring's own Fourier-harmonic model (:class:`OrthotropicHarmonicModel`,
the strains of :mod:`.harmonic` with an orthotropic D), its clamped end held (tube: the far
end cross-section; plate: its inner or outer cylindrical edge). The radial grid of the adapter's
joined face holds every vertex of the ring's face inside the bolted annulus (the overlap of
the two), so each adapter face edge lies inside one ring face edge. The adapter's face nodes in
the annulus are **tied** to the ring face: their displacement is the ring face's quadratic
field there (``T``, exact where the meshes match). Per harmonic the adapter is condensed onto
those tied nodes (Schur complement ``S(n) = K_tt - K_ti K_ii^-1 K_it``) and
``F(n) = T^T S(n) T``. The adapter's face outside the annulus is free. (The build does not form
``F(n)``: it solves the ring and the adapter's interior DOFs as one sparse system, the tied DOFs
eliminated through ``T`` -- the same condensation, cheaper; ``F(n)`` serves exports.)

Build time only (scipy, scikit-fem).
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementTriP2, ElementVector, MeshTri, asm

from .harmonic import HarmonicRingModel, _Solver, _strains

CONNECTED = "connected"


# ---- the adapter's harmonic model --------------------------------------------------------------

def _energy_general(d, a, b):
    """eps_a^T D eps_b for a general 6x6 D (numbers), strains as lists of 6 arrays."""
    out = 0.0
    for i in range(6):
        for j in range(6):
            if d[i, j] != 0.0:
                out = out + d[i, j] * a[i] * b[j]
    return out


class OrthotropicHarmonicModel(HarmonicRingModel):
    """:class:`HarmonicRingModel` with a constant 6x6 elasticity ``D`` in the strain order
    ``[eps_r, eps_t, eps_z, gam_rz, gam_rt, gam_tz]`` (cylindrical orthotropy)."""

    def __init__(self, mesh: MeshTri, elasticity: np.ndarray, intorder: int = 4):
        d = np.asarray(elasticity, dtype=float)
        self.mesh = mesh
        self.elasticity = d
        self.youngs_modulus = float("nan")
        self.poisson_ratio = float("nan")
        self.element = ElementVector(ElementTriP2(), 3)
        self.basis = Basis(mesh, self.element, intorder=intorder)

        @BilinearForm
        def k0(u, v, w):
            r = w.x[0]
            return _energy_general(d, _strains(u, r)[0], _strains(v, r)[0]) * r

        @BilinearForm
        def k1(u, v, w):
            r = w.x[0]
            (u0, u1), (v0, v1) = _strains(u, r), _strains(v, r)
            return (_energy_general(d, u0, v1) + _energy_general(d, u1, v0)) * r

        @BilinearForm
        def k2(u, v, w):
            r = w.x[0]
            return _energy_general(d, _strains(u, r)[1], _strains(v, r)[1]) * r

        self.K0 = asm(k0, self.basis).tocsr()
        self.K1 = asm(k1, self.basis).tocsr()
        self.K2 = asm(k2, self.basis).tocsr()
        b = self.basis
        self.component = np.empty(b.N, dtype=int)
        for c in range(3):
            self.component[b.nodal_dofs[c]] = c
            self.component[b.facet_dofs[c]] = c
        self.doflocs = b.doflocs


# ---- the ring's bolted face --------------------------------------------------------------------

class RingFace:
    """The P2 nodes of a ring's bolted face, sorted by r, and their DOFs.

    Attributes
    ----------
    z : float, m
        Axial position of the face.
    side : int
        +1 if the connected structure lies above the face (upper face), -1 below.
    r : (m,) array, m
        Radii of the face's P2 nodes (vertices and edge midpoints), ascending.
    dofs : (3 m,) int array
        Ring DOF of node k, component c (U, V, W) at ``3 k + c``.
    edges : (e, 3) int array
        Per face edge: local indices (first vertex, midpoint, second vertex), ascending r.
    """

    def __init__(self, model: HarmonicRingModel, facets: np.ndarray, section):
        b, mesh = model.basis, model.mesh
        nodes = []          # (r, kind, index)
        for f in facets:
            v0, v1 = mesh.facets[:, f]
            nodes += [(mesh.p[0, v0], 0, v0), (mesh.p[0, v1], 0, v1),
                      (0.5 * (mesh.p[0, v0] + mesh.p[0, v1]), 1, f)]
        uniq = {}
        for r, kind, idx in nodes:
            uniq[(kind, int(idx))] = r
        keys = sorted(uniq, key=lambda k: uniq[k])
        self.r = np.array([uniq[k] for k in keys])
        local = {k: i for i, k in enumerate(keys)}
        dofs = np.empty((len(keys), 3), dtype=int)
        for i, (kind, idx) in enumerate(keys):
            for c in range(3):
                dofs[i, c] = b.nodal_dofs[c, idx] if kind == 0 else b.facet_dofs[c, idx]
        self.dofs = dofs.ravel()
        edges = []
        for f in facets:
            v0, v1 = mesh.facets[:, f]
            a, m_, c = local[(0, int(v0))], local[(1, int(f))], local[(0, int(v1))]
            edges.append((a, m_, c) if self.r[a] < self.r[c] else (c, m_, a))
        self.edges = np.array(sorted(edges, key=lambda e: self.r[e[0]]))
        self.z = float(mesh.p[1, mesh.facets[0, facets[0]]])
        self.side = 1 if section.bolted_face == "upper" else -1
        self.inner_radius = float(self.r[0])
        self.outer_radius = float(self.r[-1])
        self.vertex_r = self.r[np.unique(self.edges[:, [0, 2]])]

    @property
    def size(self) -> int:
        return 3 * len(self.r)

    def interpolation(self, r) -> np.ndarray:
        """(len(r), m) weights of the face's quadratic field at radii ``r`` (clipped to the face)."""
        r = np.clip(np.asarray(r, dtype=float), self.r[0], self.r[-1])
        w = np.zeros((len(r), len(self.r)))
        r0, r1 = self.r[self.edges[:, 0]], self.r[self.edges[:, 2]]
        for k, x in enumerate(r):
            e = int(np.clip(np.searchsorted(r1, x - 1e-12 * max(1.0, abs(x))), 0, len(r1) - 1))
            t = (x - r0[e]) / (r1[e] - r0[e])
            a, m_, c = self.edges[e]
            w[k, a] += (1 - t) * (1 - 2 * t)
            w[k, m_] += 4 * t * (1 - t)
            w[k, c] += t * (2 * t - 1)
        return w


# ---- face stiffness of a parametric adapter ----------------------------------------------------

def _graded_from(start: float, stop: float, h0: float, growth: float, h_cap: float) -> np.ndarray:
    """Points from ``start`` to ``stop`` (either order), sizes growing from h0 by (1 + growth) up to h_cap."""
    length = abs(stop - start)
    if length <= 0:
        return np.array([start])
    pts, x, h = [0.0], 0.0, h0
    while x + h < length * (1 - 1e-9):
        x += h
        pts.append(x)
        h = min(h * (1 + growth), h_cap)
    if length - pts[-1] < 0.3 * h and len(pts) > 1:
        pts.pop()
    pts.append(length)
    s = np.array(pts) / length
    return start + (stop - start) * s


class AdapterFaceStiffness:
    """Face stiffness ``F(n)`` of a parametric :class:`~slewing_model.bearing.connection.Adapter`
    on the ring face ``face`` (see module docstring)."""

    def __init__(self, adapter, face: RingFace, size, h_section: float):
        t0 = time.perf_counter()
        self.adapter = adapter
        self.face = face
        ri, ro = adapter.inner_radius, adapter.outer_radius
        lo, hi = max(ri, face.inner_radius), min(ro, face.outer_radius)
        if hi <= lo:
            raise ValueError(f"the {adapter.kind} on the {adapter.ring} ring (r {ri * 1e3:g}..{ro * 1e3:g} mm) does "
                             f"not overlap its bolted face (r {face.inner_radius * 1e3:g}..{face.outer_radius * 1e3:g} mm)")
        self.annulus = (lo, hi)
        inside = face.vertex_r[(face.vertex_r > lo) & (face.vertex_r < hi)]
        # a ring face vertex very near the annulus' edge would leave a sliver: drop it (the tie then
        # holds the adapter's node there to the ring's field, a node-to-surface tie)
        v = face.vertex_r
        for end in (lo, hi):
            k = int(np.clip(np.searchsorted(v, end), 1, len(v) - 1))
            length = v[k] - v[k - 1]                       # the ring face edge holding this end
            if min(abs(v - end)) > 1e-9 * max(end, 1.0):   # the end is the adapter's, inside a face edge
                inside = inside[np.abs(inside - end) > 0.3 * length]
        spacing = np.diff(np.concatenate([[lo], inside, [hi]]))
        h0 = float(spacing.min())
        h_cap = max(size.max_size * h_section, h0)
        # radial grid: the ring face's vertices in the annulus; outside it, graded from the annulus
        grid = [inside, [lo, hi]]
        if ri < lo:
            grid.append(_graded_from(lo, ri, h0, size.growth, h_cap))
        if ro > hi:
            grid.append(_graded_from(hi, ro, h0, size.growth, h_cap))
        r_grid = np.unique(np.concatenate(grid))
        r_grid = r_grid[np.concatenate([[True], np.diff(r_grid) > 1e-9 * ro])]
        # axial grid: from the face, away from the ring; sizes grow from the face's element size
        z0 = face.z
        z1 = z0 + face.side * adapter.length
        z_grid = np.sort(_graded_from(z0, z1, h0, size.growth, max(h_cap, 0.5 * (ro - ri))))
        mesh = MeshTri.init_tensor(r_grid, z_grid)
        self.model = OrthotropicHarmonicModel(mesh, adapter.elasticity())
        r, z = self.model.doflocs
        tol = 1e-9 * max(ro, 1.0)
        on_face = np.abs(z - z0) < tol
        self.tied = np.flatnonzero(on_face & (r >= lo - tol) & (r <= hi + tol))
        if adapter.clamped_edge == "far_end":
            clamped = np.abs(z - z1) < tol
        elif adapter.clamped_edge == "inner":
            clamped = np.abs(r - ri) < tol
        else:
            clamped = np.abs(r - ro) < tol
        clamped &= ~np.isin(np.arange(self.model.ndofs), self.tied)
        self.clamped = np.flatnonzero(clamped)
        rest = np.ones(self.model.ndofs, dtype=bool)
        rest[self.tied] = False
        rest[self.clamped] = False
        self.interior = np.flatnonzero(rest)
        # tie: adapter DOF (tied node, component) = ring face field interpolated at its radius
        w = face.interpolation(r[self.tied])                      # (t, m)
        comp = self.model.component[self.tied]
        T = np.zeros((len(self.tied), face.size))
        for c in range(3):
            sel = comp == c
            T[np.ix_(sel, np.arange(c, face.size, 3))] = w[sel]
        self.T = T
        self._cache = {}
        self.info = {"kind": adapter.kind, "clamped": adapter.clamped_edge,
                     "bolted_annulus_m": [lo, hi], "elements": int(mesh.t.shape[1]),
                     "dofs": int(self.model.ndofs), "tied_dofs": int(len(self.tied)),
                     "setup_seconds": time.perf_counter() - t0}

    @property
    def dofs(self) -> np.ndarray:
        return self.face.dofs

    @property
    def extra_component(self) -> np.ndarray:
        """Component (0 U, 1 V, 2 W) of each adapter DOF the connected model carries (the interior ones)."""
        return self.model.component[self.interior]

    def blocks(self, n: int, ring_ndofs: int):
        """The adapter in the connected model's sparse system, harmonic n: ``(A, C, D)`` with
        ``A = Tr^T K_tt Tr`` (ring x ring), ``C = Tr^T K_ti`` (ring x interior), ``D = K_ii``;
        ``Tr`` the tie from all ring DOFs to the adapter's tied DOFs. Solving the ring and the
        adapter's interior together is the condensation of :meth:`condensed` without forming it."""
        k = self.model.stiffness(n)
        tr = self._tie(ring_ndofs)
        t, i = self.tied, self.interior
        k_t = k[t]
        a = (tr.T @ k_t[:, t] @ tr).tocsr()
        c = (tr.T @ k_t[:, i]).tocsr()
        return a, c, k[i][:, i].tocsr()

    def _tie(self, ring_ndofs: int) -> sp.csr_matrix:
        if getattr(self, "_tr", None) is None or self._tr.shape[1] != ring_ndofs:
            rows, cols = np.nonzero(self.T)
            self._tr = sp.csr_matrix((self.T[rows, cols], (rows, self.face.dofs[cols])),
                                     shape=(len(self.tied), ring_ndofs))
        return self._tr

    def condensed(self, n: int) -> np.ndarray:
        """The adapter condensed onto its tied DOFs, harmonic n: ``S(n)`` (t, t), N/m per unit
        of the theta integral."""
        k = self.model.stiffness(n)
        t, i = self.tied, self.interior
        k_ii = k[i][:, i].tocsc()
        k_it = k[i][:, t].toarray()
        lu = spla.splu(k_ii, permc_spec="COLAMD")
        s = k[t][:, t].toarray() - k_it.T @ lu.solve(k_it)
        return 0.5 * (s + s.T)

    def matrix(self, n: int) -> np.ndarray:
        """``F(n) = T^T S(n) T`` on the ring face DOFs (:attr:`RingFace.dofs`): the adapter's face
        stiffness (for exports; the build solves ring and adapter together, :meth:`blocks`)."""
        if n not in self._cache:
            self._cache[n] = self.T.T @ self.condensed(n) @ self.T
        return self._cache[n]


# ---- the ring with its face stiffness ----------------------------------------------------------

class ConnectedModel:
    """A ring model joined to a connected structure; everything not below is the ring model's.

    A parametric adapter brings its interior DOFs into the system (appended after the ring's:
    ``ndofs`` and ``component`` cover both; the ring's load vectors are padded with zeros by
    :meth:`pad`) and its tied DOFs are eliminated through the tie, so the ring and the adapter are
    one sparse system per harmonic. An imported stiffness (dense, on the face DOFs) is added to
    ``K(n)`` as it is."""

    def __init__(self, model: HarmonicRingModel, face_stiffness):
        self._model = model
        self.face_stiffness = face_stiffness
        self.ring_ndofs = model.ndofs
        self.sparse = hasattr(face_stiffness, "blocks")
        extra = face_stiffness.extra_component if self.sparse else np.zeros(0, dtype=int)
        self.component = np.concatenate([model.component, extra])

    def __getattr__(self, name):
        return getattr(self._model, name)

    @property
    def ndofs(self) -> int:
        return len(self.component)

    def pad(self, vectors: np.ndarray) -> np.ndarray:
        """Ring DOF vectors (ring_ndofs, ...) extended with zeros on the adapter's DOFs."""
        extra = self.ndofs - self.ring_ndofs
        return np.concatenate([vectors, np.zeros((extra,) + vectors.shape[1:])], axis=0)

    def stiffness(self, n: int) -> sp.csr_matrix:
        k = self._model.stiffness(n)
        if self.sparse:
            a, c, d = self.face_stiffness.blocks(n, self.ring_ndofs)
            return sp.bmat([[k + a, c], [c.T, d]], format="csr")
        d = self.face_stiffness.dofs
        f = self.face_stiffness.matrix(n)
        add = sp.coo_matrix((f.ravel(), (np.repeat(d, len(d)), np.tile(d, len(d)))), shape=k.shape)
        return (k + add).tocsr()

    def solver(self, n: int, fixed=(), constraints=None):
        return _Solver(self, n, fixed, constraints)


class ConnectedSupport:
    """The support of a connected ring: none of its own (the connected structure's clamped end
    holds it), no rigid-mode constraints."""

    kind = CONNECTED
    free = False

    def fixed(self, n: int) -> np.ndarray:
        return np.zeros(0, dtype=int)

    def constraints(self, n: int):
        return None


def face_stiffness(connection, model, section_mesh, size):
    """The face stiffness of ``connection`` (Adapter or ImportedStiffness) on the bolted face of
    ``section_mesh``."""
    section = section_mesh.profile.section
    face = RingFace(model, section_mesh.bolted_facets, section)
    if getattr(connection, "kind", None) in ("tube", "plate"):
        h_section = min(section.height, section.outer_radius - section.inner_radius)
        return AdapterFaceStiffness(connection, face, size, h_section)
    from .imported import ImportedFaceStiffness

    return ImportedFaceStiffness(connection, face)


def connect(model, section_mesh, connection, size):
    """(ConnectedModel, ConnectedSupport, info) of a ring bolted to ``connection``."""
    fs = face_stiffness(connection, model, section_mesh, size)
    info = dict(fs.info)
    info["support"] = (f"the bolted face is joined to a {info['kind']} ({_what(connection)}); no rigid-body "
                       f"mode is left: the connected structure's clamped end holds the ring")
    return ConnectedModel(model, fs), ConnectedSupport(), info


def _what(connection) -> str:
    if getattr(connection, "kind", None) == "tube":
        return (f"r {connection.inner_radius * 1e3:g}..{connection.outer_radius * 1e3:g} mm, length "
                f"{connection.length * 1e3:g} mm, clamped at its far end")
    if getattr(connection, "kind", None) == "plate":
        return (f"r {connection.inner_radius * 1e3:g}..{connection.outer_radius * 1e3:g} mm, thickness "
                f"{connection.length * 1e3:g} mm, clamped along its {connection.clamped_edge} edge")
    return f"{connection.format} file {connection.file}, held as its FE model held it"


def ring_face_stiffness(bearing, ring: str, connection, mesh="coarse", patch_scale: float = 1.0,
                        reference_pressure: float | None = None):
    """The face stiffness of ``connection`` on ``ring``'s bolted face meshed as
    :func:`~.build.build_superelement` meshes it (for exports and studies)."""
    from ...bearing.conventions import RING_CONTACTS
    from . import coupling as cp
    from .section import MESH_PRESETS, mesh_section, ring_profile

    size = MESH_PRESETS[mesh] if isinstance(mesh, str) else mesh
    pressure = cp.REFERENCE_PRESSURE if reference_pressure is None else reference_pressure
    sizes = [cp.patch_size(bearing, c, pressure) for c in RING_CONTACTS[ring]]
    sm = mesh_section(ring_profile(bearing, ring), [a * patch_scale for a, _ in sizes], size)
    model = HarmonicRingModel(sm.mesh, bearing.youngs_modulus, bearing.poisson_ratio)
    return face_stiffness(connection, model, sm, size)
