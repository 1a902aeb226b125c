#!/usr/bin/env python3
"""An imported CalculiX stiffness of a 3-D tube against the parametric tube adapter: the
imported matrix of the same adapter must give the parametric result within 1 %. Outside
`make test`; needs `ccx` (Debian calculix-ccx 2.20).

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/calculix/connected/imported_tube.py [--keep DIR]

1. CalculiX: a steel tube (r 760-805 mm, 300 mm long, E 210 GPa, nu 0.3) under the outer ring's
   lower bolted face of table1, its far end clamped; C3D20 bricks (``--elements`` through the
   wall, around, along). A ``*FREQUENCY, SOLVER=MATRIXSTORAGE`` step writes the full stiffness
   (``tube.sti``: the upper triangle, ``row col value`` over the free DOFs, N/mm) and its DOF list
   (``tube.dof``: ``node.dof``). CalculiX 2.20's ``*SUBSTRUCTURE MATRIX OUTPUT`` does not condense
   (tests/data/calculix/check_substructure.py), so the condensation is done here.
2. Python: the Schur complement onto every node of the face (z = face), ``S = K_tt - K_ti K_ii^-1
   K_it`` (scipy sparse LU), written as Matrix Market (N/mm) with the nodes' CSV (mm).
3. slewing_model: table1 with ``[connection.outer] type = "matrix"`` reading those files, against
   table1 with the parametric tube of the same dimensions and material (``type = "tube"``), the
   inner ring clamped, coarse mesh, ``--harmonics`` N for both. Compared: the outer ring's
   condensed compliance in every ball harmonic (relative Frobenius), the peak ball load and the
   number of loaded balls under an axial load and under an axial load with a tilting moment.

The face nodes sit at 2 x (bricks around) equally spaced angles: the importer resolves harmonics
below that / 2, so ``--elements W A L`` needs A >= N + 1. Defaults: 2 x 139 x 12 bricks, N = 138
(the outer ring's own default): 6 min, 3 GB (the condensation onto 4170 face DOFs); a quick
variant ``--elements 2 49 12 --harmonics 48`` takes 40 s.
"""
from __future__ import annotations

import argparse
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))

from references.calculix.tube_mesh import c3d20_tube, nset  # noqa: E402

RI, RO, LENGTH = 0.760, 0.805, 0.300          # m
E, NU = 210e9, 0.3                             # Pa


def tube_deck(z_face: float, n_r: int, n_t: int, n_z: int) -> tuple[str, dict]:
    """CalculiX input (mm, N, MPa): the tube from z_face downwards, C3D20, far end clamped, one
    matrix-storage frequency step. Returns the deck and {node id: (r mm, theta rad, z mm, k)} (k = 0: the face)."""
    lines, ids, where = c3d20_tube(RI, RO, LENGTH, z_face, n_r, n_t, n_z)
    out = lines + nset("FAR", sorted(v for (i, j, k), v in ids.items() if k == 2 * n_z))
    out += ["*MATERIAL,NAME=STEEL", "*ELASTIC", f"{E / 1e6:.6g},{NU}", "*DENSITY", "7.85e-9",
            "*SOLID SECTION,ELSET=TUBE,MATERIAL=STEEL",
            "*BOUNDARY", "FAR,1,3",
            "*STEP", "*FREQUENCY,SOLVER=MATRIXSTORAGE", "1", "*END STEP"]
    return "\n".join(out) + "\n", where


def read_stiffness(workdir: Path, job: str):
    """The stored stiffness (sparse, symmetric, N/mm) and its DOFs [(node, dof)]."""
    dofs = [tuple(int(x) for x in line.split(".")) for line in (workdir / f"{job}.dof").read_text().split()]
    data = np.loadtxt(workdir / f"{job}.sti")
    i, j, v = data[:, 0].astype(int) - 1, data[:, 1].astype(int) - 1, data[:, 2]
    off = i != j
    k = sp.coo_matrix((np.concatenate([v, v[off]]), (np.concatenate([i, j[off]]), np.concatenate([j, i[off]]))),
                      shape=(len(dofs), len(dofs))).tocsc()
    return k, dofs


def condense(k, dofs, retained_nodes: list[int]) -> np.ndarray:
    """Schur complement on the retained nodes' x, y, z (in that node order), N/mm."""
    pos = {d: n for n, d in enumerate(dofs)}
    t = np.array([pos[(v, c)] for v in retained_nodes for c in (1, 2, 3)])
    mask = np.ones(len(dofs), dtype=bool)
    mask[t] = False
    i = np.flatnonzero(mask)
    k_tt = k[t][:, t].toarray()
    k_it = k[i][:, t].tocsc()
    lu = spla.splu(k[i][:, i].tocsc())
    s = k_tt.copy()
    for c0 in range(0, len(t), 300):
        x = lu.solve(k_it[:, c0:c0 + 300].toarray())
        s[:, c0:c0 + 300] -= k_it.T @ x
    return 0.5 * (s + s.T)


def bearing_with(table: str, folder: Path):
    from slewing_model import load_bearing

    path = folder / "table1_connected.toml"
    path.write_text((ROOT / "examples/bearings/table1.toml").read_text() + table)
    return load_bearing(path)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--keep", help="folder for the deck, the matrix files and the bearing file")
    p.add_argument("--elements", type=int, nargs=3, default=[2, 139, 12], metavar=("WALL", "AROUND", "ALONG"))
    p.add_argument("--harmonics", type=int, default=138,
                   help="FE harmonics N of both superelements (138: the outer ring's default, 12 r / w)")
    args = p.parse_args()
    if shutil.which("ccx") is None:
        print("ccx not found (Debian: apt-get install calculix-ccx)")
        return 1
    from slewing_model import load_bearing
    from slewing_model.bearing.connection import Adapter
    from slewing_model.distribution.bime import Loads, solve
    from slewing_model.rings.superelement import build_superelement
    from slewing_model.rings.superelement.imported import write_matrix_market, write_nodes

    n_r, n_t, n_z = args.elements
    table1 = load_bearing(ROOT / "examples/bearings/table1.toml")
    z_face = -table1.outer_section.height / 2
    tmp = tempfile.TemporaryDirectory()
    work = Path(args.keep) if args.keep else Path(tmp.name)
    work.mkdir(parents=True, exist_ok=True)

    t0 = time.perf_counter()
    text, where = tube_deck(z_face, n_r, n_t, n_z)
    (work / "tube.inp").write_text(text)
    run = subprocess.run(["ccx", "-i", "tube"], cwd=work, capture_output=True, text=True)
    if run.returncode != 0 or not (work / "tube.sti").exists():
        print(run.stdout[-2000:], run.stderr[-2000:])
        return 1
    t_ccx = time.perf_counter() - t0
    k, dofs = read_stiffness(work, "tube")
    face = sorted(v for v, w in where.items() if w[3] == 0)
    s = condense(k, dofs, face)                                  # N/mm
    t_cond = time.perf_counter() - t0 - t_ccx
    xyz = np.array([[w[0] * math.cos(w[1]), w[0] * math.sin(w[1]), w[2]] for w in (where[v] for v in face)]) * 1e-3
    write_nodes(work / "tube_face_nodes.csv", np.array(face), xyz)
    write_matrix_market(work / "tube_face.mtx", s)
    print(f"CalculiX tube: {n_r} x {n_t} x {n_z} C3D20, {len(where)} nodes, {len(dofs)} free DOFs; "
          f"{len(face)} face nodes ({2 * n_t} angles, largest gap {360 / (2 * n_t):.3g} deg); "
          f"ccx {t_ccx:.1f} s, condensation {t_cond:.1f} s", flush=True)

    imported = bearing_with('\n[connection.outer]\ntype = "matrix"\nformat = "matrix_market"\n'
                            'file = "tube_face.mtx"\nnodes_csv = "tube_face_nodes.csv"\nstiffness_unit = "N/mm"\n', work)
    tube = Adapter("outer", "tube", RI, RO, LENGTH, "far_end", E, E, E, E / (2 * (1 + NU)), NU)
    parametric = table1.with_connection({"outer": tube})
    se = {}
    for name, b in (("parametric", parametric), ("imported", imported)):
        t1 = time.perf_counter()
        se[name] = build_superelement(b, mesh="coarse", bc="clamped", cache=False, harmonics=args.harmonics)
        print(f"superelement {name}: {time.perf_counter() - t1:.1f} s", flush=True)
    a = se["parametric"].outer.harmonic_blocks().real
    b = se["imported"].outer.harmonic_blocks().real
    rel = [np.linalg.norm(np.linalg.inv(x) - np.linalg.inv(y)) / np.linalg.norm(np.linalg.inv(x)) for x, y in zip(a, b)]
    j = int(np.argmax(rel))
    print(f"outer ring compliance per ball harmonic, imported vs parametric (relative Frobenius): "
          f"worst {100 * rel[j]:.3f} % (ball harmonic {j}), harmonic 0: {100 * rel[0]:.3f} %, "
          f"1: {100 * rel[1]:.3f} %, 2: {100 * rel[2]:.3f} %")
    plain = table1.with_connection(None)
    print(f"{'load':34} {'peak parametric [kN]':>21} {'peak imported [kN]':>19} {'difference':>11} {'loaded balls':>13}")
    for label, loads in (("Fz 300 kN", Loads(0.0, 0.0, 300e3, 0.0, 0.0)),
                         ("Fz 300 kN + My 400 kN m", Loads(0.0, 0.0, 300e3, 0.0, 400e3))):
        res = {n: solve(plain, loads, model="flexible", superelement=se[n]) for n in se}
        qp, qi = res["parametric"].max_ball_load, res["imported"].max_ball_load
        zp, zi = (int(np.sum(r.contact_load.max(axis=1) > 0)) for r in (res["parametric"], res["imported"]))
        print(f"{label:34} {qp / 1e3:21.4f} {qi / 1e3:19.4f} {100 * (qi / qp - 1):+10.3f} % {zp:>6} / {zi}")
    # the bounds: the outer ring unconnected, clamped or free (the inner ring clamped), for the size of the tube's effect
    for bc in ("clamped", "free"):
        se_bc = build_superelement(plain, mesh="coarse", bc={"outer": bc, "inner": "clamped"}, cache=False,
                                   harmonics=args.harmonics)
        q = [solve(plain, loads, model="flexible", superelement=se_bc).max_ball_load / 1e3
             for loads in (Loads(0.0, 0.0, 300e3, 0.0, 0.0), Loads(0.0, 0.0, 300e3, 0.0, 400e3))]
        print(f"for scale, outer ring {bc:7} (no tube): peak {q[0]:.4f} kN (Fz), {q[1]:.4f} kN (Fz + My)")
    print(f"total {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
