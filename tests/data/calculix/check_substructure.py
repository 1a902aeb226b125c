#!/usr/bin/env python3
"""What CalculiX's substructure export holds: run outside `make test`, needs `ccx`
(Debian calculix-ccx).

    .venv/bin/python tests/data/calculix/check_substructure.py

The model (block_substructure.inp): a 30 x 30 x 20 mm steel block of 3 x 3 x 2 C3D8 elements,
its lower face fixed, the 16 nodes of its upper face retained (x, y, z). The script

1. runs `*SUBSTRUCTURE GENERATE` (the deck as it is) and reads the .mtx with
   slewing_model's reader;
2. assembles, in numpy, the C3D8 element stiffness (full 2x2x2 integration) into the whole block
   and condenses it onto the retained DOFs (the interior layer eliminated), and also forms the
   retained block K_tt without condensation;
3. runs a *STATIC step with a unit displacement of node 33 in x (all other retained DOFs held at 0)
   and reads CalculiX's own reaction forces.

Found with CalculiX 2.20 (Debian 2.20-1): the .mtx equals K_tt (to 1e-14), not the condensed
matrix; the static reactions equal the numpy condensation to 7 digits (K[33x,33x] = 446.1 N per
um against 493.6 in the .mtx). So that version's export is the stiffness of the retained DOFs
with the interior held fixed, too stiff; a single-layer model makes it abort (realloc). An
imported CalculiX 2.20 substructure is only right when no interior node couples retained ones.
"""
from __future__ import annotations

import itertools
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2]))
NX, NY, NZ, A, E, NU = 3, 3, 2, 10.0, 210000.0, 0.3


def nid(i, j, k):
    return 1 + i + (NX + 1) * (j + (NY + 1) * k)


def hex8_stiffness(a=A, e=E, nu=NU) -> np.ndarray:
    """C3D8 (full integration) stiffness of a cube of side a, node order of CalculiX, N/mm."""
    lam, mu = e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[range(3), range(3)] += 2 * mu
    d[3, 3] = d[4, 4] = d[5, 5] = mu
    xi = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],
                  float)
    g = 1 / np.sqrt(3)
    k = np.zeros((24, 24))
    for p in itertools.product([-g, g], repeat=3):
        dn = np.array([[xi[i][j] * np.prod([1 + xi[i][m] * p[m] for m in range(3) if m != j]) / 8 for j in range(3)]
                       for i in range(8)]) / (a / 2)
        b = np.zeros((6, 24))
        for i in range(8):
            b[0, 3 * i], b[1, 3 * i + 1], b[2, 3 * i + 2] = dn[i]
            b[3, 3 * i], b[3, 3 * i + 1] = dn[i, 1], dn[i, 0]
            b[4, 3 * i + 1], b[4, 3 * i + 2] = dn[i, 2], dn[i, 1]
            b[5, 3 * i], b[5, 3 * i + 2] = dn[i, 2], dn[i, 0]
        k += b.T @ d @ b * (a / 2) ** 3
    return k


def block_matrices():
    """(top node ids, K_tt, K condensed) of the block, N/mm."""
    ke = hex8_stiffness()
    nn = (NX + 1) * (NY + 1) * (NZ + 1)
    kf = np.zeros((3 * nn, 3 * nn))
    for k, j, i in itertools.product(range(NZ), range(NY), range(NX)):
        n = [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
             nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1), nid(i, j + 1, k + 1)]
        idx = np.array([3 * (m - 1) + c for m in n for c in range(3)])
        kf[np.ix_(idx, idx)] += ke
    top = [nid(i, j, NZ) for j in range(NY + 1) for i in range(NX + 1)]
    inner = [nid(i, j, k) for k in range(1, NZ) for j in range(NY + 1) for i in range(NX + 1)]
    t = np.array([3 * (m - 1) + c for m in top for c in range(3)])
    m = np.array([3 * (q - 1) + c for q in inner for c in range(3)])
    k_tt = kf[np.ix_(t, t)]
    k_c = k_tt - kf[np.ix_(t, m)] @ np.linalg.solve(kf[np.ix_(m, m)], kf[np.ix_(m, t)])
    return np.array(top), k_tt, k_c


def main() -> int:
    from slewing_model.rings.superelement.imported import read_calculix

    if shutil.which("ccx") is None:
        print("ccx not found (Debian: apt-get install calculix-ccx)")
        return 1
    top, k_tt, k_c = block_matrices()
    deck = (HERE / "block_substructure.inp").read_text()
    model = deck.split("*STEP")[0]
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "block.inp").write_text(deck)
        subprocess.run(["ccx", "-i", "block"], cwd=tmp, capture_output=True, check=True)
        k = read_calculix(os.path.join(tmp, "blocksub.mtx"), top)
        static = [model, "*STEP", "*STATIC", "*BOUNDARY"]
        static += [f"{n},{d + 1},{d + 1},{(1e-3 if (n == top[0] and d == 0) else 0.0):.10e}" for n in top
                   for d in range(3)]
        static += ["*NODE PRINT,NSET=TOP", "RF", "*END STEP"]
        (Path(tmp) / "static.inp").write_text("\n".join(static) + "\n")
        subprocess.run(["ccx", "-i", "static"], cwd=tmp, capture_output=True, check=True)
        rf = {}
        for line in (Path(tmp) / "static.dat").read_text().splitlines():
            p = line.split()
            if len(p) == 4 and p[0].isdigit():
                rf[int(p[0])] = [float(x) for x in p[1:]]
    column = np.concatenate([rf[n] for n in top]) / 1e-3
    scale = np.abs(k_c).max()
    print(f"CalculiX .mtx vs K_tt (no condensation):      {np.abs(k - k_tt).max() / scale:.2e}")
    print(f"CalculiX .mtx vs condensed K:                 {np.abs(k - k_c).max() / scale:.2e}")
    print(f"CalculiX static reactions vs condensed K[:,0]: {np.abs(column - k_c[:, 0]).max() / scale:.2e}")
    print(f"K[33x,33x]: .mtx {k[0, 0]:.1f}, condensed {k_c[0, 0]:.1f}, static {column[0]:.1f} N/mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
