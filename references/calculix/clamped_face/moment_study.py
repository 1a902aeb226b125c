"""Pure tilting moment on a bearing with both rings clamped: what the projection of the ring part does.

The outer ring is clamped on its lower face, the inner (moving) ring on its
upper face (the moment comes in through a rigid plate bolted there). Under a pure moment a
rigid bearing loads both diagonals alike and does not lift; clamped faces make the diagonal
whose contacts sit next to them (contacts 4 and 2) stiffer, so it carries more and the moving
ring rises. Three condensations of the same harmonic FE solves:

* ``v2``: the ring part ``c_n - c_n^HS`` projected onto positive semi-definite matrices per
  continuous harmonic, before the long-wave give-back (algorithm version 2);
* ``v3``: the long waves whose excess is given back projected per ball harmonic, after the
  give-back, the other harmonics per harmonic (algorithm version 3, the code's);
* ``none``: not projected at all: negative ring parts kept, i.e. the contacts next to a clamped face
  made *stiffer* than Hertz's half-space, as a solid FE model has them. The superelement cannot
  keep this (its matrix would not be positive definite); shown to size what it leaves out.

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/calculix/clamped_face/moment_study.py [fine|coarse]

About 1 min with fine (two rings' harmonic solves, 15 flexible solves).
"""
import os
import sys

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, ROOT)

from slewing_model import Loads, load_bearing, solve  # noqa: E402
from slewing_model.rings.stiffness import Superelement  # noqa: E402
from slewing_model.rings.superelement import build as bd  # noqa: E402
from slewing_model.rings.superelement import condense as cd  # noqa: E402
from slewing_model.rings.superelement.section import MESH_PRESETS  # noqa: E402



def no_projection(g_hat, patches, free, floor):
    """``stiffness_blocks`` without the projection (a clamped ring: no rigid modes)."""
    k_hat = np.zeros_like(g_hat)
    for j in range(g_hat.shape[0]):
        k = np.linalg.inv(g_hat[j] + floor)
        k_hat[j] = 0.5 * (k + k.T)
    return k_hat, {}


def superelements(bearing, mesh):
    harmonics = {ring: bd.ring_harmonics(bearing, ring, MESH_PRESETS[mesh], "clamped",
                                         bd.auto_harmonics(bearing, ring, 12.0), bd.DEFAULT_OPTIONS)
                 for ring in ("outer", "inner")}
    out = {}
    given_back, stiffness_blocks = cd.given_back_harmonics, cd.stiffness_blocks
    for variant in ("v2", "v3", "none"):
        try:
            if variant == "v2":                          # nothing spared from the per-harmonic projection
                cd.given_back_harmonics = lambda back, n_max: np.zeros(n_max + 1, dtype=bool)
            if variant == "none":                        # nothing projected anywhere
                cd.given_back_harmonics = lambda back, n_max: np.ones(n_max + 1, dtype=bool)
                cd.stiffness_blocks = no_projection
            rings = {ring: bd.condense_ring(h, bearing.ball_count)[0] for ring, h in harmonics.items()}
        finally:
            cd.given_back_harmonics, cd.stiffness_blocks = given_back, stiffness_blocks
        out[variant] = Superelement(rings["outer"], rings["inner"], {})
    return out


def main():
    mesh = sys.argv[1] if len(sys.argv) > 1 else "fine"
    bearing = load_bearing(os.path.join(ROOT, "examples", "bearings", "table1.toml"))
    ses = superelements(bearing, mesh)
    print(f"{bearing.name}, both rings clamped (outer: lower face, inner: upper face), mesh {mesh}")
    print("| M [MN m] | condensation | Q1 max / rigid - 1 | Q4 max / rigid - 1 | Z [um] | ry [urad] (rigid) |")
    print("|---|---|---|---|---|---|")
    for moment in (0.5e6, 1e6, 1.5e6, 2e6, 3e6):
        rigid = solve(bearing, Loads(My=moment))
        q = rigid.contact_load
        for variant, se in ses.items():
            f = solve(bearing, Loads(My=moment), model="flexible", superelement=se)
            qf = f.contact_load
            print(f"| {moment / 1e6:.1f} | {variant} | {qf[:, 0].max() / q[:, 0].max() - 1:+.2%} | "
                  f"{qf[:, 3].max() / q[:, 3].max() - 1:+.2%} | {f.displacement[2] * 1e6:.2f} | "
                  f"{f.displacement[4] * 1e6:.1f} ({rigid.displacement[4] * 1e6:.1f}) |")


if __name__ == "__main__":
    main()
