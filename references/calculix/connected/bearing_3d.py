#!/usr/bin/env python3
"""A 3-D CalculiX reference of both rings bolted to tubes, the balls as nonlinear Hertz springs,
against slewing_model's superelement with the same adapters.
Outside `make test`; needs `ccx` (Debian calculix-ccx 2.20).

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/calculix/connected/bearing_3d.py \
        [--tube-modulus-gpa 210 20] [--keep DIR]

The model (README.md next to this file says how far to trust it):

* Bearing: table1's section, contact geometry and material with 40 balls
  (``table1_40balls.toml``: fewer balls keep the 3-D mesh in minutes).
* Bodies: each ring's cross-section (the superelement's section mesher with a coarser setting,
  ``SECTION_SIZE``) and its tube (over the whole bolted face, 300 mm long, the given modulus,
  Poisson 0.3: the outer ring's tube below its lower face, the inner ring's above its upper face;
  the tube's grid shares the face's vertices, i.e. bonded) swept about z into 15-node quadratic
  wedges (C3D15); half the bearing (theta 0..180 deg, u_y = 0 on the plane y = 0: the loads are
  symmetric about it), 4 slabs per ball pitch, the thin ones (the patch width) at the balls.
  Each tube's far end clamped. CalculiX writes each body's stiffness (``*FREQUENCY,
  SOLVER=MATRIXSTORAGE``); the static solves are done here with it (scipy sparse LU).
* Balls: at each ball and each diagonal (contacts 1-3 and 2-4) one nonlinear spring between the
  two groove centres, its force along their current line, ``Q = f(|c_i' - c_o'| - A0)`` with
  Hertz ``delta = (Q / K)^(2/3)`` (Houpert's K of both contacts in series, as the model), zero
  in tension (no preload). Each groove centre follows its raceway through a distributing
  coupling: the force spread as the consistent nodal loads of a uniform pressure over the patch
  (+-a along the groove arc, a the Hertz semi-axis at 2.5 GPa; +-``PATCH_CIRC`` along the
  circumference), the centre's displacement the same weighted (work-conjugate) mean of the
  patch's displacements. The patch is far larger along the circumference than a Hertz ellipse,
  and its local (half-space) compliance is in the FE as well as in Hertz: it is subtracted,
  ``delta_spring = delta_Hertz(Q) - (c_o + c_i) Q`` with c the half-space compliance of the
  uniform rectangular patch (``--no-halfspace-correction`` keeps it, for the sensitivity).
* Load: the inner ring's tube far end moves as a rigid body (reference point the bearing
  centre in the ball plane): its motion plus the body's response with that end clamped. The
  equations (springs + the rigid body's equilibrium) are solved by scipy's hybrid Newton
  (``root``), started from the model's ball loads (the converged answer does not depend on it).

Compared: the peak ball (contact) load and the loaded balls (contact load > 1 % of the peak) with
``slewing_model`` (``build_superelement(mesh="coarse")`` with the same tubes, ``solve(...,
model="flexible")``) under an axial load and a tilting moment.
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy import integrate, optimize

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))
HERE = Path(__file__).resolve().parent

from slewing_model import load_bearing  # noqa: E402
from slewing_model.bearing.connection import Adapter  # noqa: E402
from slewing_model.bearing.contact import diagonal_stiffness, houpert_stiffness  # noqa: E402
from slewing_model.bearing.geometry import RING_CONTACTS  # noqa: E402
from slewing_model.rings.superelement import coupling as cp  # noqa: E402
from slewing_model.rings.superelement.section import MeshSize, mesh_section, ring_profile  # noqa: E402
from skfem import MeshTri  # noqa: E402

BEARING = HERE / "table1_40balls.toml"
SECTION_SIZE = MeshSize(patch_elements=2, growth=0.8, max_size=0.5)
TUBE_LENGTH = 0.300                                   # m
TUBE_ROWS = np.array([0.0, 0.01, 0.025, 0.05, 0.1, 0.18, 0.3]) / 0.3   # fractions of the length, graded
PATCH_CIRC = 0.005                                    # m, half-width of the coupling patch along the circumference
MIDDLE_SLABS = 2                                      # slabs between the patches of neighbouring balls
DIAGONALS = ((1, 3), (4, 2))                          # (outer contact, inner contact)
LOAD_CASES = {"axial Fz 200 kN": (0.0, 200e3, 0.0), "moment My 150 kN m": (0.0, 0.0, 150e3)}   # Fx, Fz, My


# ---- the 3-D mesh of one body (ring + tube) ------------------------------------------------------

def body_section(bearing, ring):
    """2-D P2 mesh of the ring section and its tube: skfem MeshTri, triangle material flags
    (0 ring, 1 tube), the far-end vertex row's z, the section mesh (patches)."""
    sizes = [cp.patch_size(bearing, c) for c in RING_CONTACTS[ring]]
    sm = mesh_section(ring_profile(bearing, ring), [a for a, _ in sizes], SECTION_SIZE)
    p, t = sm.mesh.p, sm.mesh.t
    s = bearing.outer_section if ring == "outer" else bearing.inner_section
    side = -1.0 if s.bolted_face == "lower" else 1.0
    z_face = side * s.height / 2
    on_face = np.flatnonzero(np.abs(p[1] - z_face) < 1e-9)
    on_face = on_face[np.argsort(p[0, on_face])]
    rows = [on_face]
    pts = [p]
    nv = p.shape[1]
    for frac in TUBE_ROWS[1:]:
        z = z_face + side * TUBE_LENGTH * frac
        new = np.stack([p[0, on_face], np.full(len(on_face), z)])
        rows.append(np.arange(nv, nv + len(on_face)))
        pts.append(new)
        nv += len(on_face)
    tris = [t]
    for a, b in zip(rows[:-1], rows[1:]):
        for k in range(len(a) - 1):
            tris.append(np.array([[a[k], a[k + 1], b[k + 1]], [a[k], b[k + 1], b[k]]]).T)
    t_all = np.hstack(tris)
    mesh = MeshTri(np.hstack(pts), t_all)
    flags = np.r_[np.zeros(t.shape[1], int), np.ones(t_all.shape[1] - t.shape[1], int)]
    return mesh, flags, z_face + side * TUBE_LENGTH, sm, sizes


def theta_layers(bearing):
    """Node layers over theta 0..pi (quadratic slabs: layers 2s, 2s+1, 2s+2) and the ball angles
    in it. Per pitch: slabs [0, f], [f, 1/2], [1/2, 1 - f], [1 - f, 1] (f the patch width)."""
    B = bearing.ball_count
    pitch = 2 * math.pi / B
    f = PATCH_CIRC / (bearing.pitch_diameter / 2) / pitch
    bounds = []
    for k in range(B // 2):
        bounds += [k + x for x in [0.0] + list(f + (1 - 2 * f) * np.arange(MIDDLE_SLABS) / MIDDLE_SLABS) + [1 - f]]
    bounds = np.array(bounds + [B // 2]) * pitch
    layers = np.empty(2 * len(bounds) - 1)
    layers[0::2] = bounds
    layers[1::2] = 0.5 * (bounds[1:] + bounds[:-1])
    return layers


def sweep(mesh, flags, layers, far_z):
    """3-D nodes (N, 3) with (2-D node, layer), C3D15 connectivity per material, far-end and plane node sets."""
    p, t, facets = mesh.p, mesh.t, mesh.facets
    nv = p.shape[1]
    facet_of = {tuple(sorted(e)): k for k, e in enumerate(facets.T)}
    xy = np.hstack([p, p[:, facets].mean(axis=1)])
    nn2 = xy.shape[1]
    ids = {}
    coords = []
    for layer, th in enumerate(layers):
        for k in range(nn2 if layer % 2 == 0 else nv):
            ids[(k, layer)] = len(coords) + 1
            coords.append((xy[0, k] * math.cos(th), xy[0, k] * math.sin(th), xy[1, k]))
    elems = {0: [], 1: []}
    for s in range(len(layers) // 2):
        l0, l1, l2 = 2 * s, 2 * s + 1, 2 * s + 2
        for e, (a, b, c) in enumerate(t.T):
            m12, m23, m31 = (nv + facet_of[tuple(sorted(x))] for x in ((a, b), (b, c), (c, a)))
            pa, pb, pc = (np.array([xy[0, i], 0.0, xy[1, i]]) for i in (a, b, c))
            if np.cross(pb - pa, pc - pa)[1] < 0:
                b, c, m12, m31 = c, b, m31, m12
            elems[flags[e]].append([ids[(a, l0)], ids[(b, l0)], ids[(c, l0)], ids[(a, l2)], ids[(b, l2)], ids[(c, l2)],
                                    ids[(m12, l0)], ids[(m23, l0)], ids[(m31, l0)], ids[(m12, l2)], ids[(m23, l2)],
                                    ids[(m31, l2)], ids[(a, l1)], ids[(b, l1)], ids[(c, l1)]])
    far = [v for (k, layer), v in ids.items() if abs(xy[1, k] - far_z) < 1e-9]
    plane = [v for (k, layer), v in ids.items() if layer in (0, len(layers) - 1)]
    return np.array(coords), ids, xy, elems, far, plane


def write_deck(path, coords, elems, far, plane, e_ring, e_tube, nu):
    with open(path, "w") as f:
        f.write("*NODE\n")
        for i, (x, y, z) in enumerate(coords, start=1):
            f.write(f"{i},{x * 1e3:.12g},{y * 1e3:.12g},{z * 1e3:.12g}\n")
        eid = 0
        for mat, name in ((0, "RING"), (1, "TUBE")):
            f.write(f"*ELEMENT,TYPE=C3D15,ELSET={name}\n")
            for conn in elems[mat]:
                eid += 1
                f.write(f"{eid}," + ",".join(map(str, conn[:10])) + ",\n" + ",".join(map(str, conn[10:])) + "\n")
        for name, nodes in (("FAR", far), ("PLANE", plane)):
            f.write(f"*NSET,NSET={name}\n")
            for s in range(0, len(nodes), 12):
                f.write(",".join(map(str, nodes[s:s + 12])) + "\n")
        for name, e in (("RING", e_ring), ("TUBE", e_tube)):
            f.write(f"*MATERIAL,NAME=M{name}\n*ELASTIC\n{e / 1e6:.6g},{nu}\n*DENSITY\n7.85e-9\n"
                    f"*SOLID SECTION,ELSET={name},MATERIAL=M{name}\n")
        f.write("*BOUNDARY\nFAR,1,3\nPLANE,2,2\n*STEP\n*FREQUENCY,SOLVER=MATRIXSTORAGE\n1\n*END STEP\n")


def read_stiffness(workdir: Path, job: str):
    dofs = [tuple(int(x) for x in line.split(".")) for line in (workdir / f"{job}.dof").read_text().split()]
    data = np.fromstring((workdir / f"{job}.sti").read_text(), sep=" ").reshape(-1, 3)
    i, j, v = data[:, 0].astype(int) - 1, data[:, 1].astype(int) - 1, data[:, 2]
    off = i != j
    k = sp.coo_matrix((np.concatenate([v, v[off]]), (np.concatenate([i, j[off]]), np.concatenate([j, i[off]]))),
                      shape=(len(dofs), len(dofs))).tocsc()
    return k * 1e3, {d: n for n, d in enumerate(dofs)}           # N/mm -> N/m


# ---- couplings -----------------------------------------------------------------------------------

def patch_weights(xy, ids, layers, patch, a_arc, theta_ball):
    """{node id: weight}: consistent loads of a unit uniform pressure resultant over the patch
    (serendipity 8-node faces: corners -1/12, midsides 1/3 of each face's share), on the faces
    inside the half model (sum 1, or 1/2 on the plane y = 0)."""
    o = patch.centre
    rc = patch.groove_radius
    d = xy - o[:, None]
    on_arc = np.abs(np.hypot(d[0], d[1]) - rc) < 1e-7
    ang = np.arctan2(d[1], d[0])
    s = rc * (np.remainder(ang - patch.psi + np.pi, 2 * np.pi) - np.pi)
    node_at = {}
    for target in (-a_arc, 0.0, a_arc):                     # vertices on the arc
        hit = np.flatnonzero(on_arc & (np.abs(s - target) < 1e-6 * a_arc + 1e-9))
        if len(hit) != 1:
            raise RuntimeError(f"contact {patch.contact}: {len(hit)} section nodes at {target * 1e3:.3f} mm along the groove")
        node_at[round(target / a_arc * 2)] = int(hit[0])     # -2, 0, 2
    for side in (-1, 1):                                     # the (straight) edges' midpoints between them
        mid = 0.5 * (xy[:, node_at[0]] + xy[:, node_at[2 * side]])
        hit = np.flatnonzero(np.hypot(xy[0] - mid[0], xy[1] - mid[1]) < 1e-9)
        if len(hit) != 1:
            raise RuntimeError(f"contact {patch.contact}: no edge between the patch's vertices")
        node_at[side] = int(hit[0])
    lb = int(np.argmin(np.abs(layers - theta_ball)))
    assert abs(layers[lb] - theta_ball) < 1e-9 and lb % 2 == 0
    w = {}
    for ds in (-1, 1):                  # groove side
        for dt in (-1, 1):              # circumferential side
            if not (0 <= lb + 2 * dt < len(layers)):
                continue
            s_c, s_m = (0, 2 * ds), ds   # corners at s index 0 and 2 ds, midside at ds
            face = [((s_c[0], lb), -1 / 12), ((s_c[1], lb), -1 / 12), ((s_c[0], lb + 2 * dt), -1 / 12),
                    ((s_c[1], lb + 2 * dt), -1 / 12), ((s_m, lb), 1 / 3), ((s_m, lb + 2 * dt), 1 / 3),
                    ((s_c[0], lb + dt), 1 / 3), ((s_c[1], lb + dt), 1 / 3)]
            for (si, layer), wt in face:
                nid = ids[(node_at[si], layer)]
                w[nid] = w.get(nid, 0.0) + wt / 4
    return w


def halfspace_rectangle(a, b, youngs, nu):
    """Mean normal displacement per unit resultant of a uniform pressure on a 2a x 2b rectangle, m/N."""
    L, W = 2 * a, 2 * b
    val, _ = integrate.dblquad(lambda y, x: (L - x) * (W - y) / math.hypot(x, y), 0, L, 0, W, epsabs=0, epsrel=1e-7)
    return (1 - nu**2) / (math.pi * youngs) * 4 * val / (L * W) ** 2


# ---- the reference -------------------------------------------------------------------------------

class Body:
    """One ring with its tube: compliance of its groove-centre couplings (half model)."""

    def __init__(self, bearing, ring, e_tube, work: Path, log):
        self.ring = ring
        mesh, flags, far_z, sm, sizes = body_section(bearing, ring)
        layers = theta_layers(bearing)
        coords, ids, xy, elems, far, plane = sweep(mesh, flags, layers, far_z)
        t0 = time.perf_counter()
        job = f"{ring}"
        write_deck(work / f"{job}.inp", coords, elems, far, plane, bearing.youngs_modulus, e_tube, bearing.poisson_ratio)
        run = subprocess.run(["ccx", "-i", job], cwd=work, capture_output=True, text=True,
                             env={**os.environ, "OMP_NUM_THREADS": "1"})
        if run.returncode != 0 or not (work / f"{job}.sti").exists():
            raise RuntimeError(run.stdout[-3000:] + run.stderr[-2000:])
        k, pos = read_stiffness(work, job)
        t1 = time.perf_counter()
        patches = {pt.contact: pt for pt in cp.ring_patches(bearing, ring, sizes)}
        a_arc = {c: a for c, (a, _) in zip(RING_CONTACTS[ring], sizes)}
        B = bearing.ball_count
        self.balls = np.arange(B // 2 + 1)
        self.theta = 2 * math.pi * self.balls / B
        cols, self.factor, self.share = [], [], []
        for outer_c, inner_c in DIAGONALS:
            c = outer_c if ring == "outer" else inner_c
            for th in self.theta:
                w = patch_weights(xy, ids, layers, patches[c], a_arc[c], th)
                total = sum(w.values())
                for e in (np.array([math.cos(th), math.sin(th), 0.0]), np.array([0.0, 0.0, 1.0])):
                    col = np.zeros(k.shape[0])
                    for nid, wt in w.items():
                        for comp in range(3):
                            if (nid, comp + 1) in pos:
                                col[pos[(nid, comp + 1)]] += wt * e[comp]
                    cols.append(col)
                self.factor.append(1.0 / total)          # 1, or 2 on the plane
                self.share.append(total)                 # the half model's share of the ball's force
        wmat = np.array(cols).T
        lu = spla.splu(k, permc_spec="MMD_AT_PLUS_A")
        x = lu.solve(wmat)
        c = wmat.T @ x
        f = np.repeat(self.factor, 2)
        self.c = f[:, None] * c                          # (2 nref, 2 nref): (r, z) of each coupling, m/N
        self.share = np.array(self.share)
        self.patch_a = {c_: a_arc[c_] for c_ in a_arc}
        self.size = (len(coords), 3 * len(coords), sum(len(v) for v in elems.values()))
        log(f"  {ring} body: {self.size[2]} C3D15, {self.size[0]} nodes, {k.shape[0]} free DOFs; "
            f"ccx + reading {t1 - t0:.1f} s, LU + {wmat.shape[1]} solves {time.perf_counter() - t1:.1f} s")


def reference(bearing, bodies, loads, q_guess, halfspace: bool, x0=None):
    """Spring loads Q (2, nb) and the inner body's rigid motion (t_x, t_z, omega_y)."""
    outer, inner = bodies["outer"], bodies["inner"]
    nb = len(outer.theta)
    E, nu = bearing.youngs_modulus, bearing.poisson_ratio
    ks, cent, c_hs = [], [], []
    for outer_c, inner_c in DIAGONALS:
        ka = houpert_stiffness(bearing.ball_diameter, bearing.osculation[outer_c - 1], E, nu)
        kb = houpert_stiffness(bearing.ball_diameter, bearing.osculation[inner_c - 1], E, nu)
        ks.append(float(diagonal_stiffness(ka, kb)))
        cent.append((bearing.groove_centres[outer_c - 1], bearing.groove_centres[inner_c - 1]))
        c_hs.append(sum(halfspace_rectangle(body.patch_a[c], PATCH_CIRC, E, nu)
                        for body, c in ((outer, outer_c), (inner, inner_c))) if halfspace else 0.0)
    a0 = np.linalg.norm(cent[0][1] - cent[0][0])
    th = outer.theta
    share = outer.share.reshape(2, nb)
    fx, fz, my = loads

    def spring(g, d):
        """Q >= 0 with delta_H(Q) - c Q = g (0 for g <= 0)."""
        k, c = ks[d], c_hs[d]
        q = np.where(g > 0, k * np.maximum(g, 0) ** 1.5, 0.0)
        for _ in range(40):
            pos = q > 0
            dl = (q[pos] / k) ** (2 / 3)
            r = dl - c * q[pos] - g[pos]
            q[pos] = np.maximum(q[pos] - r / ((2 / 3) * dl / q[pos] - c), 1e-12 * k)
        return q

    def state(x):
        q = x[:2 * nb].reshape(2, nb) * 1e3
        t_x, t_z, om = x[2 * nb:] * 1e-6
        f_o, f_i, u = [], [], []
        for d in range(2):
            g_vec = cent[d][1] - cent[d][0]
            u.append(g_vec / np.linalg.norm(g_vec))
        return q, (t_x, t_z, om), u

    def residual(x):
        q, (t_x, t_z, om), _ = state(x)
        # forces on the bodies at the couplings, (r, z), with the current directions from the last displacements
        res = []
        disp_o = outer.c @ forces(q, dirs_cache[0], +1)
        disp_i = inner.c @ forces(q, dirs_cache[0], -1)
        dirs = []
        g_all = []
        for d in range(2):
            vo = disp_o.reshape(2, nb, 2)[d]
            vi = disp_i.reshape(2, nb, 2)[d]
            r_p = np.array([cent[d][1][0] + 0 * th, cent[d][1][1] + 0 * th]).T
            # rigid motion of the inner body at the coupling (contact point on the force line: any point of it)
            ux = t_x * np.cos(th) + om * r_p[:, 1] * np.cos(th)
            uz = t_z - om * r_p[:, 0] * np.cos(th)
            vi = vi + np.stack([ux, uz], axis=1)
            co, ci = cent[d][0][None, :] + vo, cent[d][1][None, :] + vi
            gv = ci - co
            length = np.linalg.norm(gv, axis=1)
            dirs.append(gv / length[:, None])
            g_all.append(length - a0)
            res.append(q[d] - spring(length - a0, d))
        dirs_cache[1] = dirs
        # equilibrium of the inner body (half model): external half load + forces on the inner ring
        ffx = ffz = mmy = 0.0
        for d in range(2):
            e = dirs[d]
            fr, fzz = -q[d] * e[:, 0] * share[d], -q[d] * e[:, 1] * share[d]
            px = cent[d][1][0] * np.cos(th)            # a point of the force line (the inner groove centre)
            pz = cent[d][1][1]
            ffx += np.sum(fr * np.cos(th))
            ffz += np.sum(fzz)
            mmy += np.sum(pz * fr * np.cos(th) - px * fzz)
        eq = np.array([(ffx + fx / 2) / scale_f, (ffz + fz / 2) / scale_f, (mmy + my / 2) / scale_m])
        return np.concatenate([np.concatenate(res) / 1e3, eq])

    def forces(q, dirs, sign):
        f = np.zeros((2, nb, 2))
        for d in range(2):
            f[d] = sign * q[d][:, None] * dirs[d]
        return f.reshape(-1)

    scale_f = max(abs(fz), abs(fx), 1.0) / 10
    scale_m = max(abs(my), 1.0) / 10
    u0 = [np.tile((cent[d][1] - cent[d][0]) / a0, (nb, 1)) for d in range(2)]
    dirs_cache = [u0, u0]
    x = np.concatenate([q_guess.reshape(-1) / 1e3, np.zeros(3)]) if x0 is None else x0.copy()
    for _ in range(30):                 # update the force directions until they settle
        sol = optimize.root(residual, x, method="hybr", options={"xtol": 1e-12, "maxfev": 20000})
        x = sol.x
        residual(x)
        change = max(np.abs(a - b).max() for a, b in zip(dirs_cache[0], dirs_cache[1]))
        dirs_cache[0] = dirs_cache[1]
        if change < 1e-10:
            break
    r = residual(x)
    q, rigid, _ = state(x)
    if np.abs(r).max() > 1e-6:             # polish: Levenberg-Marquardt from where hybr stopped
        sol = optimize.root(residual, x, method="lm", options={"xtol": 1e-14, "ftol": 1e-14, "maxiter": 20000})
        x = sol.x
        r = residual(x)
    q, rigid, _ = state(x)
    return q, rigid, float(np.abs(r).max()), x, (ks, c_hs)


def model_solution(bearing, e_tube, loads):
    from slewing_model.distribution.bime import Loads, solve
    from slewing_model.rings.superelement import build_superelement

    so, si = bearing.outer_section, bearing.inner_section
    g = e_tube / (2 * 1.3)
    conn = {"outer": Adapter("outer", "tube", so.inner_radius, so.outer_radius, TUBE_LENGTH, "far_end",
                             e_tube, e_tube, e_tube, g, 0.3),
            "inner": Adapter("inner", "tube", si.inner_radius, si.outer_radius, TUBE_LENGTH, "far_end",
                             e_tube, e_tube, e_tube, g, 0.3)}
    connected = bearing.with_connection(conn)
    t0 = time.perf_counter()
    se = build_superelement(connected, mesh="coarse", cache=False)
    t_build = time.perf_counter() - t0
    out = {}
    for name, (fx, fz, my) in loads.items():
        out[name] = solve(bearing, Loads(fx, 0.0, fz, 0.0, my), model="flexible", superelement=se).contact_load
    return out, t_build


def main() -> int:
    global SECTION_SIZE, MIDDLE_SLABS, PATCH_CIRC
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tube-modulus-gpa", type=float, nargs="+", default=[210.0, 20.0])
    p.add_argument("--cases", nargs="+", default=list(LOAD_CASES), choices=list(LOAD_CASES))
    p.add_argument("--keep", help="folder for the decks and CalculiX's files")
    p.add_argument("--no-halfspace-correction", action="store_true")
    p.add_argument("--section", type=float, nargs=3, metavar=("PATCH_ELEMENTS", "GROWTH", "MAX_SIZE"),
                   help=f"section mesh of the 3-D bodies (default {SECTION_SIZE.patch_elements} "
                        f"{SECTION_SIZE.growth} {SECTION_SIZE.max_size}; the couplings need 2 patch elements)")
    p.add_argument("--middle-slabs", type=int, default=MIDDLE_SLABS, help="slabs between neighbouring patches")
    p.add_argument("--patch-mm", type=float, default=PATCH_CIRC * 1e3,
                   help="half-width of the coupling patch along the circumference, mm")
    p.add_argument("--csv", help="write every ball's contact load, 3-D and model, to this CSV file "
                                 "(references/validation/bolted_tubes.py draws it)")
    args = p.parse_args()
    if args.section:
        SECTION_SIZE = MeshSize(int(args.section[0]), args.section[1], args.section[2])
    MIDDLE_SLABS, PATCH_CIRC = args.middle_slabs, args.patch_mm * 1e-3
    if shutil.which("ccx") is None:
        print("ccx not found (Debian: apt-get install calculix-ccx)")
        return 1
    bearing = load_bearing(BEARING)
    B = bearing.ball_count
    assert B % 2 == 0 and bearing.first_ball_angle == 0.0
    tmp = tempfile.TemporaryDirectory()
    t_start = time.perf_counter()
    csv_rows = []
    for e_gpa in args.tube_modulus_gpa:
        e_tube = e_gpa * 1e9
        work = Path(args.keep) / f"tube_{e_gpa:g}gpa" if args.keep else Path(tmp.name) / f"tube_{e_gpa:g}"
        work.mkdir(parents=True, exist_ok=True)
        print(f"\ntubes E = {e_gpa:g} GPa (nu 0.3, 300 mm, over each bolted face); {B} balls", flush=True)
        t0 = time.perf_counter()
        bodies = {ring: Body(bearing, ring, e_tube, work, lambda s: print(s, flush=True)) for ring in ("outer", "inner")}
        model, t_build = model_solution(bearing, e_tube, LOAD_CASES)
        print(f"  3-D bodies {time.perf_counter() - t0 - t_build:.0f} s; superelement (coarse) {t_build:.1f} s", flush=True)
        for name in args.cases:
            qm = model[name]                                      # (B, 4)
            guess = np.array([np.maximum(qm[:B // 2 + 1, o - 1], 1.0) for o, _ in DIAGONALS])
            x_prev = None
            for hs in ((False,) if args.no_halfspace_correction else (False, True)):
                q, rigid, res, x_prev, (ks, c_hs) = reference(bearing, bodies, LOAD_CASES[name], guess, hs, x_prev)
                peak_ref, peak_mod = q.max(), qm.max()
                zone_ref = [int(np.sum(q[d] > 0.01 * peak_ref)) for d in range(2)]
                # the model's balls 0..B/2 (the half the reference holds; the other half mirrors it)
                qm_half = np.array([qm[:B // 2 + 1, o - 1] for o, _ in DIAGONALS])
                zone_mod = [int(np.sum(qm_half[d] > 0.01 * peak_mod)) for d in range(2)]
                diff = np.abs(q - qm_half).max() / peak_ref
                tag = "corrected" if hs else "uncorrected"
                for d in range(2):
                    for b in range(B // 2 + 1):
                        csv_rows.append(f"{e_gpa:g},{name},{tag},{d + 1},{b},{360.0 * b / B:g},"
                                        f"{q[d, b]:.6e},{qm_half[d, b]:.6e}")
                print(f"  {name:20} ({tag:11}): peak 3-D {peak_ref / 1e3:8.3f} kN, model {peak_mod / 1e3:8.3f} kN "
                      f"({100 * (peak_mod / peak_ref - 1):+.2f} %); balls 0..{B // 2} loaded (> 1 % of the peak) on "
                      f"diagonals 1, 2: 3-D {zone_ref}, model {zone_mod}; largest per-contact difference "
                      f"{100 * diff:.2f} % of the peak; residual {res:.1e}", flush=True)
                if hs:
                    print(f"    half-space of the two patches {c_hs[0] * 1e9:.3f} m/N x 1e-9", flush=True)
                    for d in range(2):
                        print(f"    ball loads 0..{B // 2} [kN], diagonal {d + 1}: 3-D   {np.round(q[d] / 1e3, 2).tolist()}\n"
                              f"                                 model {np.round(qm_half[d] / 1e3, 2).tolist()}", flush=True)
    if args.csv:
        Path(args.csv).parent.mkdir(parents=True, exist_ok=True)
        Path(args.csv).write_text("tube_modulus_gpa,case,halfspace,diagonal,ball,angle_deg,load_3d_n,load_model_n\n"
                                  + "\n".join(csv_rows) + "\n")
        print(f"wrote {args.csv}")
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
