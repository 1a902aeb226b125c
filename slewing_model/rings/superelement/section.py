"""Ring cross-sections with the gothic-arch groove, and their structured mesh.

A ring section is the rectangle of :class:`~slewing_model.bearing.geometry.RingSection`
(ring width, height and bore from the bearing definition, or the documented
defaults of :func:`~slewing_model.bearing.geometry.default_sections`) with the groove
cut out of the side that faces the other ring. The groove is the
*intersection* of the two groove disks of the ring: centres at the ring's two
groove centres ``O_a``, ``O_b`` (:attr:`Bearing.groove_centres`), radii the
groove radii ``Rc_a``, ``Rc_b``. Its boundary is therefore two circular arcs
(a gothic arch) meeting at the crest, each running from the crest to the
land (the cylindrical face towards the other ring). No gear teeth, no bolt
holes (paper section 2.2).

The mesh is a structured, graded transfinite-interpolation (TFI) mesh of
quadratic triangles: one logical block whose four sides are the groove side
(land, arc, arc, land), the back face, the lower face and the upper face.
Nodes are placed so that the ends and the centre of each contact patch
(:mod:`.coupling`) are mesh nodes, with element sizes graded from the patch
outwards. scikit-fem has no general mesher and the section is a simple shape,
so no mesher dependency is needed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from skfem import MeshTri

from ...bearing.geometry import RING_CONTACTS, Bearing, RingSection

def contact_direction(contact: int, alpha: float) -> float:
    """Angle (rad) in the (r, z) plane of the unit vector from the ball centre to contact point
    ``contact`` for the contact angle ``alpha``: 1 upper-outer, 2 upper-inner, 3 lower-inner,
    4 lower-outer (``Bearing.contact_normals``)."""
    return {1: alpha, 2: math.pi - alpha, 3: math.pi + alpha, 4: -alpha}[contact]


@dataclass(frozen=True)
class GrooveArc:
    """One raceway arc of a ring: the circle of a groove centre between crest and land.

    A point of the arc is ``centre + radius * (cos psi, sin psi)``.

    Attributes
    ----------
    contact : int
        1..4.
    centre : tuple (R, z), m
        Nominal groove centre ``O``.
    radius : float, m
        Groove radius ``Rc``.
    psi_contact : float, rad
        Angle of the nominal contact point seen from the centre (the contact angle
        direction of :func:`contact_direction`).
    psi_crest, psi_edge : float, rad
        Angles at which the arc meets the other arc (crest) and the land (edge).
    """

    contact: int
    centre: tuple
    radius: float
    psi_contact: float
    psi_crest: float
    psi_edge: float

    def point(self, psi):
        """(r, z) of the arc at angle ``psi`` (array broadcast), m."""
        psi = np.asarray(psi, dtype=float)
        return np.stack([self.centre[0] + self.radius * np.cos(psi),
                         self.centre[1] + self.radius * np.sin(psi)])

    @property
    def contact_point(self) -> np.ndarray:
        return self.point(self.psi_contact)


@dataclass(frozen=True)
class RingProfile:
    """Cross-section of one ring: rectangle minus the gothic-arch groove.

    Attributes
    ----------
    ring : str
        ``"outer"`` or ``"inner"``.
    section : RingSection
        The rectangle and the bolted face.
    arcs : tuple of two GrooveArc
        Arc of contact ``a`` then ``b``: (1, 4) for the outer ring, (2, 3) for the inner one.
    land_radius : float, m
        Radius of the face towards the other ring (where the groove is cut).
    crest : ndarray (2,), m
        Deepest point of the groove, where the two arcs meet.
    """

    ring: str
    section: RingSection
    arcs: tuple
    land_radius: float
    crest: np.ndarray

    @property
    def back_radius(self) -> float:
        s = self.section
        return s.outer_radius if self.ring == "outer" else s.inner_radius

    @property
    def lower_arc(self) -> GrooveArc:
        return min(self.arcs, key=lambda a: a.contact_point[1])

    @property
    def upper_arc(self) -> GrooveArc:
        return max(self.arcs, key=lambda a: a.contact_point[1])


def _circle_intersections(c1, r1, c2, r2):
    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    d = np.linalg.norm(c2 - c1)
    a = (r1**2 - r2**2 + d**2) / (2 * d)
    h = math.sqrt(max(r1**2 - a**2, 0.0))
    m = c1 + a * (c2 - c1) / d
    perp = np.array([-(c2 - c1)[1], (c2 - c1)[0]]) / d
    return m + h * perp, m - h * perp


def ring_profile(bearing: Bearing, ring: str) -> RingProfile:
    """Cross-section of ``ring`` ("outer" or "inner") of ``bearing`` with its groove."""
    if ring not in RING_CONTACTS:
        raise ValueError(f"ring = {ring!r}: must be 'outer' or 'inner'")
    section = bearing.outer_section if ring == "outer" else bearing.inner_section
    land = section.inner_radius if ring == "outer" else section.outer_radius
    ca, cb = RING_CONTACTS[ring]
    centres = bearing.groove_centres
    rc = bearing.groove_radius
    p, q = _circle_intersections(centres[ca - 1], rc[ca - 1], centres[cb - 1], rc[cb - 1])
    # the crest lies inside the ring: the larger r for the outer ring, smaller for the inner one
    crest = max(p, q, key=lambda x: x[0]) if ring == "outer" else min(p, q, key=lambda x: x[0])
    arcs = []
    for c in (ca, cb):
        o = centres[c - 1]
        psi_p = contact_direction(c, bearing.contact_angle)
        psi_crest = math.atan2(crest[1] - o[1], crest[0] - o[0])
        dz = math.sqrt(max(rc[c - 1] ** 2 - (land - o[0]) ** 2, 0.0))
        z_edge = o[1] + (dz if math.sin(psi_p) > 0 else -dz)
        psi_edge = math.atan2(z_edge - o[1], land - o[0])
        # unwrap both ends to the branch of psi_contact
        psi_crest = psi_p + math.remainder(psi_crest - psi_p, 2 * math.pi)
        psi_edge = psi_p + math.remainder(psi_edge - psi_p, 2 * math.pi)
        arcs.append(GrooveArc(c, (float(o[0]), float(o[1])), float(rc[c - 1]), psi_p, psi_crest, psi_edge))
    return RingProfile(ring, section, tuple(arcs), float(land), np.asarray(crest))


# ---- structured mesh ------------------------------------------------------------------

@dataclass(frozen=True)
class MeshSize:
    """Element sizes of the section mesh.

    Attributes
    ----------
    patch_elements : int
        Elements across each contact patch (along the groove arc).
    growth : float
        Size growth per unit distance from the patch (dimensionless gradient, 0.3 = 30 %).
    max_size : float
        Largest element size as a fraction of the section's smaller side.
    """

    patch_elements: int
    growth: float
    max_size: float
    smoothing: int = 20


#: the named mesh settings of the command line (what each is worth: docs/theory/superelement.md, Accuracy)
MESH_PRESETS = {
    "coarse": MeshSize(patch_elements=4, growth=0.45, max_size=0.25),
    "fine": MeshSize(patch_elements=8, growth=0.25, max_size=0.12),
    "finer": MeshSize(patch_elements=16, growth=0.15, max_size=0.06),
}


def _graded(length: float, size, n_min: int = 1) -> np.ndarray:
    """Positions in [0, length] whose spacing follows ``size(t)`` (callable, m)."""
    t = np.linspace(0.0, length, 2001)
    dens = 1.0 / size(t)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (dens[1:] + dens[:-1]) * np.diff(t))])
    n = max(n_min, int(math.ceil(cum[-1] - 1e-9)))
    return np.interp(np.linspace(0.0, cum[-1], n + 1), cum, t)


@dataclass
class SectionMesh:
    """Mesh of a ring section and the named boundary parts used by the model.

    Attributes
    ----------
    profile : RingProfile
    mesh : skfem.MeshTri
    patch_facets : tuple of two int arrays
        Boundary facets of the contact patch of contact ``a`` and ``b``.
    patch_half_angles : tuple of two floats, rad
        Half-angle ``gamma`` of each patch seen from its groove centre.
    bolted_facets : int array
        Facets of the bolted face.
    """

    profile: RingProfile
    mesh: MeshTri
    patch_facets: tuple
    patch_half_angles: tuple
    bolted_facets: np.ndarray
    info: dict = field(default_factory=dict)


def mesh_section(profile: RingProfile, patch_half_widths, size: MeshSize | str = "coarse") -> SectionMesh:
    """Structured TFI mesh of ``profile`` with nodes at the ends and centre of each patch.

    Parameters
    ----------
    profile : RingProfile
    patch_half_widths : (2,) floats, m
        Half-width ``a`` (along the groove arc) of the patch of contact ``a`` and ``b``.
    size : MeshSize or str
        A :data:`MESH_PRESETS` name or explicit sizes.
    """
    if isinstance(size, str):
        size = MESH_PRESETS[size]
    s = profile.section
    h_sec = min(s.height, s.outer_radius - s.inner_radius)
    gammas = [w / arc.radius for w, arc in zip(patch_half_widths, profile.arcs)]
    h_patch = min(2 * w / size.patch_elements for w in patch_half_widths)
    h_max = max(size.max_size * h_sec, h_patch)

    # groove-side curve: land (lower) | lower arc | upper arc | land (upper), from z = -h/2 up
    lower, upper = profile.lower_arc, profile.upper_arc
    g_low = gammas[profile.arcs.index(lower)]
    g_up = gammas[profile.arcs.index(upper)]
    for arc, g in ((lower, g_low), (upper, g_up)):
        lo, hi = sorted((arc.psi_crest, arc.psi_edge))
        if not (lo < arc.psi_contact - g and arc.psi_contact + g < hi):
            raise ValueError(f"contact {arc.contact}: the load patch (half-angle {math.degrees(g):.1f} deg around "
                             f"the contact point) does not fit on the raceway arc "
                             f"({math.degrees(lo):.1f}..{math.degrees(hi):.1f} deg): lower the reference "
                             f"pressure or the patch scale")

    # curve pieces: each a callable t -> (r, z) on [0, L] and the patch intervals (in t) it holds
    land = profile.land_radius
    z_lo_edge = lower.point(lower.psi_edge)[1]
    z_up_edge = upper.point(upper.psi_edge)[1]
    pieces = []

    def line(p0, p1):
        p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
        length = float(np.linalg.norm(p1 - p0))
        return (lambda t: p0[:, None] + (p1 - p0)[:, None] * (np.asarray(t) / length)), length

    def arc_piece(arc, psi0, psi1):
        length = abs(psi1 - psi0) * arc.radius
        sgn = 1.0 if psi1 > psi0 else -1.0
        return (lambda t: arc.point(psi0 + sgn * np.asarray(t) / arc.radius)), length, psi0, sgn

    f, L = line((land, -s.height / 2), (land, z_lo_edge))
    pieces.append((f, L, []))
    for arc, g, psi0, psi1 in ((lower, g_low, lower.psi_edge, lower.psi_crest),
                              (upper, g_up, upper.psi_crest, upper.psi_edge)):
        f, L, p0, sgn = arc_piece(arc, psi0, psi1)
        tc = (arc.psi_contact - p0) * sgn * arc.radius
        w = g * arc.radius
        pieces.append((f, L, [(tc - w, tc + w)]))
    f, L = line((land, z_up_edge), (land, s.height / 2))
    pieces.append((f, L, []))

    # global distance to the nearest patch along the curve, for the size function
    offsets = np.cumsum([0.0] + [p[1] for p in pieces])
    patches = [(offsets[i] + a, offsets[i] + b) for i, p in enumerate(pieces) for a, b in p[2]]

    def size_at(tg):
        d = np.full_like(tg, np.inf)
        for a, b in patches:
            d = np.minimum(d, np.where(tg < a, a - tg, np.where(tg > b, tg - b, 0.0)))
        return np.minimum(h_patch + size.growth * d, h_max)

    groove_pts, patch_t, t_all = [], [], []
    for i, (f, L, pats) in enumerate(pieces):
        breaks = [0.0] + [x for a, b in pats for x in (a, 0.5 * (a + b), b)] + [L]
        ts = [np.zeros(1)]
        for t0, t1 in zip(breaks[:-1], breaks[1:]):
            ts.append(t0 + _graded(t1 - t0, lambda t, t0=t0, off=offsets[i]: size_at(off + t0 + t))[1:])
        ts = np.concatenate(ts)
        groove_pts.append(f(ts) if not groove_pts else f(ts)[:, 1:])
        t_all.append(offsets[i] + (ts if i == 0 else ts[1:]))
        patch_t += [(offsets[i] + a, offsets[i] + b) for a, b in pats]
    G = np.concatenate(groove_pts, axis=1)          # (2, n_eta + 1)
    t_glob = np.concatenate(t_all)
    patch_nodes = [(int(np.argmin(abs(t_glob - a))), int(np.argmin(abs(t_glob - b)))) for a, b in patch_t]
    # back face: the same number of points, spaced like the arc length along the groove side
    # (copying the groove points' z would squeeze rows where the arc is nearly horizontal)
    seg = np.linalg.norm(np.diff(G, axis=1), axis=0)
    frac = np.concatenate([[0.0], np.cumsum(seg)]) / seg.sum()
    z = -s.height / 2 + s.height * frac
    back = profile.back_radius
    K = np.stack([np.full_like(z, back), z])
    # logical xi direction (groove side -> back face), graded from the groove
    width = abs(back - profile.crest[0])
    xi = _graded(width, lambda t: np.minimum(h_patch + size.growth * t, h_max)) / width
    # TFI between the groove side G(eta) and the back face K(eta); the lower and upper faces are
    # straight and G, K end on them, so the linear blend reproduces them exactly
    Xi = xi[None, :]
    P = (1 - Xi)[None] * G[:, :, None] + Xi[None] * K[:, :, None]  # (2, n_eta+1, n_xi+1)
    n_eta, n_xi = G.shape[1] - 1, len(xi) - 1
    P = _smooth(P, size.smoothing)
    idx = np.arange((n_eta + 1) * (n_xi + 1)).reshape(n_eta + 1, n_xi + 1)
    p = P.reshape(2, -1)
    tris = []
    for j in range(n_eta):
        for i in range(n_xi):
            a, b, c, d = idx[j, i], idx[j, i + 1], idx[j + 1, i + 1], idx[j + 1, i]
            if np.linalg.norm(p[:, a] - p[:, c]) <= np.linalg.norm(p[:, b] - p[:, d]):
                tris += [(a, b, c), (a, c, d)]
            else:
                tris += [(a, b, d), (b, c, d)]
    t = np.array(tris).T
    area = 0.5 * ((p[0, t[1]] - p[0, t[0]]) * (p[1, t[2]] - p[1, t[0]])
                  - (p[0, t[2]] - p[0, t[0]]) * (p[1, t[1]] - p[1, t[0]]))
    if np.any(area * np.sign(area.mean()) <= 0):
        raise RuntimeError("section mesh folded: the mapping is not valid for this section")
    if area.mean() < 0:
        t = t[[0, 2, 1]]
    # C order, as scikit-fem keeps them: given a transposed (Fortran-order) array of over 1000
    # elements it copies it and logs "Transforming over 1000 elements to C_CONTIGUOUS."
    mesh = MeshTri(np.ascontiguousarray(p), np.ascontiguousarray(t))

    # named boundary parts from the structured node numbering
    facet_of = {tuple(sorted(e)): k for k, e in enumerate(mesh.facets.T)}

    def facets_between(nodes):
        return np.array([facet_of[tuple(sorted((u, v)))] for u, v in zip(nodes[:-1], nodes[1:])])

    groove_col = idx[:, 0]
    patch_sets = []
    for arc in profile.arcs:
        k = [lower, upper].index(arc)
        ia, ib = patch_nodes[k]
        patch_sets.append(facets_between(groove_col[ia:ib + 1]))
    row = idx[0] if s.bolted_face == "lower" else idx[-1]
    bolted = facets_between(row)
    info = {"elements": int(t.shape[1]), "vertices": int(p.shape[1]),
            "min_size_m": float(h_patch), "max_size_m": float(h_max)}
    return SectionMesh(profile, mesh, tuple(patch_sets), tuple(gammas), bolted, info)


def _smooth(P: np.ndarray, iterations: int) -> np.ndarray:
    """Laplace smoothing of the interior nodes of a structured grid (boundary fixed), with
    the nodes of the back face free to slide along it (they keep their r)."""
    P = P.copy()
    for _ in range(iterations):
        avg = 0.25 * (P[:, :-2, 1:-1] + P[:, 2:, 1:-1] + P[:, 1:-1, :-2] + P[:, 1:-1, 2:])
        P[:, 1:-1, 1:-1] = 0.5 * P[:, 1:-1, 1:-1] + 0.5 * avg
        P[1, 1:-1, -1] = 0.5 * P[1, 1:-1, -1] + 0.25 * (P[1, :-2, -1] + P[1, 2:, -1])
    return P


def rectangle_mesh(inner_radius: float, outer_radius: float, height: float, n_r: int, n_z: int) -> MeshTri:
    """Uniform triangle mesh of a rectangular section (the closed-form test rings)."""
    return MeshTri.init_tensor(np.linspace(inner_radius, outer_radius, n_r + 1),
                               np.linspace(-height / 2, height / 2, n_z + 1))
