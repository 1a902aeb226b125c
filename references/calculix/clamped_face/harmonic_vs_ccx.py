"""The clamped ring's harmonic compliance at n = 0 and n = 1 against a 3-D CalculiX solve.

The superelement's clamped ring is the Fourier-harmonic model
(slewing_model/rings/superelement/harmonic.py) with every displacement of the bolted face
held at zero (supports.py). This script checks that coupling against an independent 3-D
solid model of the same ring:

* the ring's cross-section mesh (the superelement's own quadratic triangles, an input here)
  is swept around the axis into quadratic wedges (C3D15) over half the ring, theta in
  [0, pi], with the symmetry plane y = 0 (u_y = 0) at both ends: the loads below are
  symmetric about it;
* the face to clamp is found from the node coordinates alone (every node with z at the
  ring's lowest or highest z, the bolted face of the bearing file), and all three
  displacement components of its nodes are fixed, the way a 3-D FE user clamps a face;
* the loads are the superelement's four master loads (unit groove-centre forces R_a, z_a,
  R_b, z_b spread as the patch pressure), times cos(n theta), n = 0 and 1 (n = 1 carries
  the tilting moment), turned into consistent nodal forces of the quadratic interpolation
  in theta;
* CalculiX (Debian's calculix-ccx, SPOOLES) solves the 8 linear load cases; the groove-centre
  compliance c_n = L^T u (u: the displacement of the theta = 0 section) is compared with the
  harmonic model's L^T K(n)^-1 L, entry by entry and along the contact normals.

What it tests: the harmonic formulation at n = 0 and 1 and the clamped face (all three
components, both harmonics) against a 3-D solid with its face fixed, on the same section
mesh. What it does not test: the mesh in (r, z) (it is the same in both), the half-space
part, the aliasing to discrete balls, the floor (they act after c_n).

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/calculix/clamped_face/harmonic_vs_ccx.py \
        [--bearing examples/bearings/table1.toml] [--ring outer] [--slabs 18] [--mesh coarse]

Run time: about a minute (table1, outer ring, coarse, 18 slabs: 71 000 DOFs).
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

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, ROOT)

from slewing_model import load_bearing  # noqa: E402
from slewing_model.bearing.geometry import RING_CONTACTS  # noqa: E402
from slewing_model.rings.superelement import condense as cd  # noqa: E402
from slewing_model.rings.superelement import coupling as cp  # noqa: E402
from slewing_model.rings.superelement.harmonic import HarmonicRingModel  # noqa: E402
from slewing_model.rings.superelement.section import MESH_PRESETS, mesh_section, ring_profile  # noqa: E402
from slewing_model.rings.superelement.supports import Support  # noqa: E402


def section_nodes(model):
    """2-D nodes of the P2 mesh: vertices then edge midpoints; their (r, z) and DOF indices (3, nn)."""
    m, b = model.mesh, model.basis
    xy = np.hstack([m.p, m.p[:, m.facets].mean(axis=1)])
    dofs = np.hstack([b.nodal_dofs, b.facet_dofs])
    return xy, dofs


def wedges(model):
    """Per triangle: 3 corner nodes and the 3 edge-midpoint nodes (edges 1-2, 2-3, 3-1), 2-D numbering."""
    m = model.mesh
    nv = m.p.shape[1]
    facet_of = {tuple(sorted(e)): k for k, e in enumerate(m.facets.T)}
    out = []
    for a, b_, c in m.t.T:
        mids = [nv + facet_of[tuple(sorted(e))] for e in ((a, b_), (b_, c), (c, a))]
        out.append([a, b_, c, *mids])
    return np.array(out)


def theta_weights(thetas, n):
    """int N_k(theta) cos(n theta) d theta for the quadratic interpolation on slabs (node layers 0..2S)."""
    w = np.zeros(len(thetas))
    x, g = np.polynomial.legendre.leggauss(10)
    for s in range(0, len(thetas) - 1, 2):
        t0, t2 = thetas[s], thetas[s + 2]
        xi = x                                             # -1..1
        th = 0.5 * (t0 + t2) + 0.5 * (t2 - t0) * xi
        shape = np.stack([0.5 * xi * (xi - 1), 1 - xi**2, 0.5 * xi * (xi + 1)])
        w[s:s + 3] += shape @ (g * np.cos(n * th)) * 0.5 * (t2 - t0)
    return w


def write_deck(path, xy, tri, facets, loads_by_case, slabs, face_z, youngs, poisson, span=math.pi):
    """The CalculiX deck. ``facets`` (2, nf): end vertices of each section edge, whose midpoint is
    2-D node ``n_vertices + f``."""
    nn2 = xy.shape[1]
    n_vertices = nn2 - facets.shape[1]
    layers = 2 * slabs + 1
    thetas = np.linspace(0.0, span, layers)
    node = lambda k, layer: layer * nn2 + k + 1        # noqa: E731
    with open(path, "w") as f:
        f.write("*HEADING\nclamped ring, half model, harmonic loads\n*NODE, NSET=NALL\n")
        for layer, th in enumerate(thetas):
            c, s = math.cos(th), math.sin(th)
            for k in range(nn2 if layer % 2 == 0 else n_vertices):
                r, z = xy[:, k]
                f.write(f"{node(k, layer)}, {r * c:.12e}, {r * s:.12e}, {z:.12e}\n")
        f.write("*ELEMENT, TYPE=C3D15, ELSET=EALL\n")
        eid = 0
        for s in range(slabs):
            l0, l1, l2 = 2 * s, 2 * s + 1, 2 * s + 2
            for a, b_, c, m12, m23, m31 in tri:
                # orient: the wedge's bottom triangle must have its normal towards the top face
                pa, pb, pc = (np.array([xy[0, i], 0.0, xy[1, i]]) for i in (a, b_, c))
                cross = np.cross(pb - pa, pc - pa)          # at theta = 0 the sweep goes along +y
                if cross[1] < 0:
                    b_, c, m12, m31 = c, b_, m31, m12
                eid += 1
                ids = [node(a, l0), node(b_, l0), node(c, l0), node(a, l2), node(b_, l2), node(c, l2),
                       node(m12, l0), node(m23, l0), node(m31, l0), node(m12, l2), node(m23, l2), node(m31, l2),
                       node(a, l1), node(b_, l1), node(c, l1)]
                f.write(f"{eid}, " + ", ".join(map(str, ids[:10])) + ",\n" + ", ".join(map(str, ids[10:])) + "\n")
        clamped = np.flatnonzero(np.abs(xy[1] - face_z) < 1e-9)
        f.write("*NSET, NSET=NFACE\n")
        for layer in range(layers):
            for k in (clamped if layer % 2 == 0 else clamped[clamped < n_vertices]):
                f.write(f"{node(k, layer)},\n")
        f.write("*NSET, NSET=NSYM\n")
        for layer in ((0, layers - 1) if span == math.pi else (0,)):
            for k in range(nn2):
                f.write(f"{node(k, layer)},\n")
        if span != math.pi:                 # a thin sector (n = 0): the far side stays in its plane
            f.write("*NSET, NSET=NFAR\n")
            for k in range(nn2):
                f.write(f"{node(k, layers - 1)},\n")
        f.write("*NSET, NSET=NOUT\n")
        for k in range(nn2):
            f.write(f"{node(k, 0)},\n")
        f.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{youngs:.6e}, {poisson}\n"
                "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n"
                "*BOUNDARY\nNFACE, 1, 3, 0.0\nNSYM, 2, 2, 0.0\n")
        if span != math.pi:                 # cylindrical system: direction 2 is the circumferential one
            f.write("*TRANSFORM, NSET=NFAR, TYPE=C\n0., 0., 0., 0., 0., 1.\n*BOUNDARY\nNFAR, 2, 2, 0.0\n")
        for name, (n, f2d) in loads_by_case.items():
            w = theta_weights(thetas, n)
            forces = np.zeros((layers, nn2, 3))              # Cartesian, the 9-node (Lagrange) face loads
            for layer, th in enumerate(thetas):
                c, s = math.cos(th), math.sin(th)
                fr, ft, fz = f2d * w[layer]
                forces[layer, :, 0], forces[layer, :, 1], forces[layer, :, 2] = fr * c - ft * s, fr * s + ft * c, fz
            # the 15-node wedge's quadrilateral faces are 8-node (serendipity): no node at a face centre
            # (an edge midpoint on a middle layer). Its value there is -1/4 of the corners' plus 1/2 of
            # the midsides', so its load goes to them with these weights (the same virtual work).
            for lm in range(1, layers, 2):
                for fi in range(facets.shape[1]):
                    k = n_vertices + fi
                    load = forces[lm, k].copy()
                    if not load.any():
                        continue
                    a, b_ = facets[:, fi]
                    for kk, ll in ((a, lm - 1), (b_, lm - 1), (a, lm + 1), (b_, lm + 1)):
                        forces[ll, kk] -= 0.25 * load
                    for kk, ll in ((k, lm - 1), (k, lm + 1), (a, lm), (b_, lm)):
                        forces[ll, kk] += 0.5 * load
                    forces[lm, k] = 0.0
            f.write(f"** case {name}\n*STEP\n*STATIC\n*CLOAD, OP=NEW\n")
            for layer in range(layers):
                for k in range(nn2):
                    for dof in range(3):
                        if forces[layer, k, dof] != 0.0:
                            f.write(f"{node(k, layer)}, {dof + 1}, {forces[layer, k, dof]:.12e}\n")
            f.write("*NODE PRINT, NSET=NOUT\nU\n*END STEP\n")


def read_dat(path, cases, nn2):
    """Displacements of the theta = 0 section per step: {case: (nn2, 3)}."""
    out, blocks, cur = {}, [], None
    with open(path) as f:
        for line in f:
            if line.strip().startswith("displacements"):
                cur = np.zeros((nn2, 3))
                blocks.append(cur)
                continue
            parts = line.split()
            if cur is not None and len(parts) == 4:
                try:
                    k = int(parts[0]) - 1
                    cur[k] = [float(v) for v in parts[1:]]
                except ValueError:
                    pass
    for name, block in zip(cases, blocks):
        out[name] = block
    return out


def compare(bearing, ring="outer", mesh="coarse", sector=None, slabs=18, work=None, verbose=False):
    """Clamped-ring compliances of the harmonic model and of CalculiX.

    Returns ``{n: (c_harmonic, c_calculix)}`` (4 x 4, m/N per unit of the theta integral, master
    DOFs R_a, z_a, R_b, z_b) for n = 0 and 1, or n = 0 only on a thin ``sector`` (deg), and the
    patches. ``work``: folder for the deck (default a temporary one)."""
    ccx = shutil.which("ccx")
    if ccx is None:
        raise FileNotFoundError("ccx not found: apt-get install calculix-ccx")
    section = bearing.outer_section if ring == "outer" else bearing.inner_section
    sizes = [cp.patch_size(bearing, c) for c in RING_CONTACTS[ring]]
    sm = mesh_section(ring_profile(bearing, ring), [a for a, _ in sizes], mesh)
    model = HarmonicRingModel(sm.mesh, bearing.youngs_modulus, bearing.poisson_ratio)
    patches = cp.ring_patches(bearing, ring, sizes)
    loads, _ = cp.master_loads(model, sm.patch_facets, patches)
    support = Support("clamped", model, sm.bolted_facets)
    harmonics = (0,) if sector else (0, 1)
    c_harm = cd.harmonic_compliances(model, loads, harmonics, support)

    xy, dofs = section_nodes(model)
    tri = wedges(model)
    face_z = -section.height / 2 if section.bolted_face == "lower" else section.height / 2
    span = math.radians(sector) if sector else math.pi
    slabs = 1 if sector else slabs
    cases = {}
    for n in harmonics:
        for col, name in enumerate(("R_a", "z_a", "R_b", "z_b")):
            cases[f"n{n}_{name}"] = (n, loads[:, col][dofs])      # (3, nn2): f_r, f_theta, f_z per node
    work = work or tempfile.mkdtemp(prefix="clamped_ccx_")
    os.makedirs(work, exist_ok=True)
    deck = os.path.join(work, "ring.inp")
    write_deck(deck, xy, tri, model.mesh.facets, cases, slabs, face_z, bearing.youngs_modulus,
               bearing.poisson_ratio, span)
    nodes3d = xy.shape[1] * (slabs + 1) + (xy.shape[1] - model.mesh.facets.shape[1]) * slabs
    if verbose:
        print(f"{bearing.name}, {ring} ring, clamped {section.bolted_face} face; section {sm.mesh.t.shape[1]} P2 "
              f"triangles; 3-D: {len(tri) * slabs} C3D15 over {math.degrees(span):g} deg, {nodes3d} nodes, "
              f"{3 * nodes3d} DOFs; deck {deck}")
    t0 = time.perf_counter()
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    run = subprocess.run([ccx, "-i", "ring"], cwd=work, env=env, capture_output=True, text=True)
    if run.returncode != 0 or "ERROR" in run.stdout:
        raise RuntimeError(run.stdout[-3000:] + run.stderr[-2000:])
    if verbose:
        print(f"ccx: {time.perf_counter() - t0:.1f} s")
    u3 = read_dat(os.path.join(work, "ring.dat"), list(cases), xy.shape[1])
    out = {}
    for k, n in enumerate(harmonics):
        c3 = np.zeros((4, 4))
        for col, name in enumerate(("R_a", "z_a", "R_b", "z_b")):
            u = u3[f"n{n}_{name}"]                          # theta = 0: (u_x, u_y, u_z) = (U, 0, W)
            field = np.zeros(model.ndofs)
            field[dofs[0]], field[dofs[2]] = u[:, 0], u[:, 2]
            c3[:, col] = loads.T @ field
        out[n] = (c_harm[k], 0.5 * (c3 + c3.T))
    return out, patches


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bearing", default=os.path.join(ROOT, "examples", "bearings", "table1.toml"))
    p.add_argument("--ring", default="outer", choices=("outer", "inner"))
    p.add_argument("--mesh", default="coarse", choices=tuple(MESH_PRESETS))
    p.add_argument("--slabs", type=int, default=18, help="quadratic wedge slabs over half the ring")
    p.add_argument("--sector", type=float, default=None,
                   help="n = 0 only, on a thin sector of this angle (deg, one slab, the far side kept in its "
                        "plane): elements of reasonable shape at the patch")
    p.add_argument("--keep", help="folder to keep the deck and CalculiX's output in")
    args = p.parse_args(argv)
    bearing = load_bearing(args.bearing)
    result, patches = compare(bearing, args.ring, args.mesh, args.sector, args.slabs, args.keep, verbose=True)
    normals = [np.array([math.cos(pt.psi), math.sin(pt.psi)]) for pt in patches]
    worst = 0.0
    for n, (ch, c3) in result.items():
        rel = np.abs(c3 - ch).max() / np.abs(ch).max()
        worst = max(worst, rel)
        print(f"\nn = {n}: groove-centre compliance [um/MN = 1e-12 m/N, per unit of the theta integral], "
              f"harmonic | CalculiX")
        for i, name in enumerate(("R_a", "z_a", "R_b", "z_b")):
            print(f"  {name:4s} " + " ".join(f"{ch[i, j] * 1e12:9.3f}" for j in range(4)) + "  | "
                  + " ".join(f"{c3[i, j] * 1e12:9.3f}" for j in range(4)))
        for k, pt in enumerate(patches):
            nn = np.zeros(4)
            nn[2 * k:2 * k + 2] = normals[k]
            a, b_ = nn @ ch @ nn, nn @ c3 @ nn
            print(f"  contact {pt.contact} along its normal: harmonic {a * 1e12:.3f}, CalculiX {b_ * 1e12:.3f} "
                  f"({b_ / a - 1:+.3%})")
        print(f"  largest entry difference / largest entry: {rel:.2e}")
    print(f"\nlargest difference over the harmonics: {worst:.2e} of the largest entry")
    return worst


if __name__ == "__main__":
    main()
