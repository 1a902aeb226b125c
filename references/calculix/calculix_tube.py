#!/usr/bin/env python3
"""The harmonic tube adapter against a 3-D CalculiX tube: run outside `make test`,
needs `ccx` (Debian calculix-ccx); about a minute.

    .venv/bin/python references/calculix/calculix_tube.py [--keep DIR]

An orthotropic tube (r 760-805 mm, 300 mm long; axial 40 GPa, hoop 15 GPa, shear 5 GPa,
Poisson 0.3, radial = hoop: the blade-root kind of material) is clamped at its far end, and its
near face is given a displacement pattern of Fourier harmonic n:

* ``radial n``: u_r = d cos(n theta) (u_theta = u_z = 0), the face's ovalisation-like waves;
* ``axial n``: u_z = d cos(n theta), the face's waviness out of plane.

CalculiX: C3D20 bricks, 2 through the wall x 96 around x 12 along, the material as
``*ELASTIC, TYPE=ENGINEERING CONSTANTS`` in a cylindrical ``*ORIENTATION``; the energy is
``1/2 sum u . RF`` over the face nodes. slewing_model: the tube as a harmonic adapter on the
outer ring face of table1 (``fine`` mesh), ``pi / 2 q^T F(n) q`` (c_n = pi). Both are the energy
of the same face motion with all face nodes following it, so they must agree to the
discretisation error of the two meshes.
"""
from __future__ import annotations

import argparse
import math
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from references.calculix.tube_mesh import c3d20_tube, nset  # noqa: E402

RI, RO, LENGTH = 0.760, 0.805, 0.300          # m
EZ, ET, ER, G, NU = 40e9, 15e9, 15e9, 5e9, 0.3   # Pa
N_R, N_T, N_Z = 2, 96, 12
D = 1e-3                                       # mm, the face's amplitude in the deck


def deck(z_face: float, n: int, kind: str) -> str:
    """The CalculiX input (mm, N, MPa) of one pattern; the tube runs from z_face downwards."""
    lines, ids, _ = c3d20_tube(RI, RO, LENGTH, z_face, N_R, N_T, N_Z, number_format=".9f")
    face = sorted({v for (i, j, k), v in ids.items() if k == 0})
    far = sorted({v for (i, j, k), v in ids.items() if k == 2 * N_Z})
    out = lines + nset("FACE", face) + nset("FAR", far)
    nu12, nu13, nu23 = NU * ER / ET, NU * ER / EZ, NU * ET / EZ   # S_12 = -NU/ET, S_13 = S_23 = -NU/EZ
    out += ["*ORIENTATION,NAME=CYL,SYSTEM=CYLINDRICAL", "0.,0.,0.,0.,0.,1.",
            "*MATERIAL,NAME=LAMINATE", "*ELASTIC,TYPE=ENGINEERING CONSTANTS",
            f"{ER / 1e6:.6g},{ET / 1e6:.6g},{EZ / 1e6:.6g},{nu12:.6g},{nu13:.6g},{nu23:.6g},{G / 1e6:.6g},{G / 1e6:.6g}",
            f"{G / 1e6:.6g},0.",
            "*SOLID SECTION,ELSET=TUBE,MATERIAL=LAMINATE,ORIENTATION=CYL",
            "*STEP", "*STATIC", "*BOUNDARY", "FAR,1,3"]
    coords = {v: key for key, v in ids.items()}
    for v in face:
        i, j, _ = coords[v]
        t = 2 * math.pi * j / (2 * N_T)
        ur, uz = (D * math.cos(n * t), 0.0) if kind == "radial" else (0.0, D * math.cos(n * t))
        for dof, value in ((1, ur * math.cos(t)), (2, ur * math.sin(t)), (3, uz)):
            out.append(f"{v},{dof},{dof},{value:.12e}")
    out += ["*NODE PRINT,NSET=FACE", "U,RF", "*END STEP"]
    return "\n".join(out) + "\n"


def calculix_energy(text: str, workdir: Path) -> float:
    """1/2 sum u . RF over the face nodes, J."""
    (workdir / "tube.inp").write_text(text)
    subprocess.run(["ccx", "-i", "tube"], cwd=workdir, capture_output=True, check=True)
    u, rf, block = {}, {}, None
    for line in (workdir / "tube.dat").read_text().splitlines():
        if "displacements" in line:
            block = u
        elif "forces" in line:
            block = rf
        p = line.split()
        if block is not None and len(p) == 4 and p[0].isdigit():
            block[int(p[0])] = np.array([float(x) for x in p[1:]])
    return 0.5 * sum(u[k] @ rf[k] for k in rf) * 1e-3            # N mm -> J


def harmonic_energy(n: int, kind: str) -> float:
    from slewing_model import load_bearing
    from slewing_model.bearing.connection import Adapter
    from slewing_model.rings.superelement.adapters import ring_face_stiffness

    bearing = load_bearing(ROOT / "examples/bearings/table1.toml")
    tube = Adapter("outer", "tube", RI, RO, LENGTH, "far_end", EZ, ET, ER, G, NU)
    fs = ring_face_stiffness(bearing, "outer", tube, mesh="fine")
    q = np.zeros(fs.face.size)
    q[(0 if kind == "radial" else 2)::3] = D * 1e-3                # m
    c_n = 2 * math.pi if n == 0 else math.pi
    return 0.5 * c_n * q @ fs.matrix(n) @ q, fs.face.z


def main() -> int:
    global N_R, N_T, N_Z
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--keep", help="folder to keep the decks and results in")
    p.add_argument("--elements", type=int, nargs=3, default=[N_R, N_T, N_Z], metavar=("WALL", "AROUND", "ALONG"),
                   help="CalculiX bricks through the wall, around, along")
    p.add_argument("--patterns", nargs="*", default=["radial2", "radial8", "axial2", "axial8"])
    args = p.parse_args()
    N_R, N_T, N_Z = args.elements
    if shutil.which("ccx") is None:
        print("ccx not found (Debian: apt-get install calculix-ccx)")
        return 1
    print(f"{'pattern':10} {'CalculiX [J]':>14} {'harmonic [J]':>14} {'harmonic / CalculiX - 1':>24}")
    for pattern in args.patterns:
        kind, n = pattern.rstrip("0123456789"), int(pattern[len(pattern.rstrip("0123456789")):])
        e_h, z_face = harmonic_energy(n, kind)
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(args.keep) / f"{kind}{n}" if args.keep else Path(tmp)
            work.mkdir(parents=True, exist_ok=True)
            e_c = calculix_energy(deck(z_face, n, kind), work)
        print(f"{kind + ' ' + str(n):10} {e_c:14.6g} {e_h:14.6g} {100 * (e_h / e_c - 1):+23.2f} %", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
