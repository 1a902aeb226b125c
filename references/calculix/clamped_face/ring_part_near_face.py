"""How much compliance the superelement gives each contact beyond Hertz, next to a clamped face.

For each ring of a bearing (clamped, and free for comparison) and each
contact, along its contact normal, per ball harmonic j (j = 0: every ball pushed alike; long
waves carry the tilting moment at j = 1):

* ``FE - S``: the ring's compliance (a free ring's: off its rigid modes) at the groove centre from the harmonic FE model (half-space
  beyond its last harmonic), less one half-space self-compliance S (what Houpert's Hertz
  spring holds on the ring side). Negative: the ring is locally *stiffer* than the half-space
  Hertz assumes.
* ``kept``: what the condensation keeps (algorithm version 3: the long waves whose half-space
  excess is given back are projected onto positive semi-definite matrices per ball harmonic,
  after the give-back; the other harmonics per harmonic) and ``old``: what it kept before
  (version 2: every continuous harmonic projected before the give-back). The floor (5 % of S)
  comes on top of both, in series.

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/calculix/clamped_face/ring_part_near_face.py \
        [--bearing examples/bearings/table1.toml] [--mesh fine]

Units: um/kN (1e-9 m/N). About 40 s with --mesh fine.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, ROOT)

from slewing_model import load_bearing  # noqa: E402
from slewing_model.rings.superelement import build as bd  # noqa: E402
from slewing_model.rings.superelement import condense as cd  # noqa: E402
from slewing_model.rings.superelement.section import MESH_PRESETS  # noqa: E402


def old_ring_part(c_fe, c_hs, patches, free):
    """Version 2: each continuous harmonic projected onto the positive semi-definite matrices."""
    return cd.ring_part(c_fe, c_hs, patches, free)[0]


def projected(g, patches, free):
    """The positive semi-definite part of each ball-harmonic block (free ring: off its rigid modes)."""
    out = np.zeros_like(g)
    for j in range(g.shape[0]):
        jj = min(j, g.shape[0] - j)
        r = cd.rigid_master_modes(patches, jj) if free else np.zeros((4, 0))
        q = np.linalg.qr(r, mode="complete")[0][:, r.shape[1]:] if r.shape[1] else np.eye(4)
        w, v = np.linalg.eigh(q.T @ g[j] @ q)
        u = q @ v
        out[j] = (u * np.maximum(w, 0.0)) @ u.T
    return out


def off_rigid(g, patches, j, balls, free):
    """A free ring's block restricted to the complement of its rigid modes (not projected)."""
    jj = min(j, balls - j)
    r = cd.rigid_master_modes(patches, jj) if free else np.zeros((4, 0))
    q = np.linalg.qr(r, mode="complete")[0][:, r.shape[1]:] if r.shape[1] else np.eye(4)
    p = q @ q.T
    return p @ g @ p


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bearing", default=os.path.join(ROOT, "examples", "bearings", "table1.toml"))
    p.add_argument("--mesh", default="fine", choices=tuple(MESH_PRESETS))
    p.add_argument("--harmonics", default="0,1,2,5,10,25", help="ball harmonics j to print")
    args = p.parse_args(argv)
    b = load_bearing(args.bearing)
    B = b.ball_count
    js = [int(x) for x in args.harmonics.split(",")]
    print(f"{b.name}, {B} balls, mesh {args.mesh}; along each contact normal, um/kN")
    for ring in ("outer", "inner"):
        face = (b.outer_section if ring == "outer" else b.inner_section).bolted_face
        for bc in ("clamped", "free"):
            h = bd.ring_harmonics(b, ring, MESH_PRESETS[args.mesh], bc, bd.auto_harmonics(b, ring, 12.0),
                                  bd.DEFAULT_OPTIONS)
            free = bc == "free"
            back = cd.halfspace_addback(h.patches, h.lams, B, h.youngs_modulus, h.poisson_ratio)
            raw = cd.ball_blocks(h.c_fe - h.c_hs, h.patches, B) + back
            given = cd.given_back_harmonics(back, h.c_fe.shape[0] - 1)
            kept = projected(cd.ball_blocks(cd.ring_part(h.c_fe, h.c_hs, h.patches, free, given)[0], h.patches, B)
                             + back, h.patches, free)
            raw = np.array([off_rigid(g, h.patches, j, B, free) for j, g in enumerate(raw)])
            old = projected(cd.ball_blocks(old_ring_part(h.c_fe, h.c_hs, h.patches, free), h.patches, B) + back,
                            h.patches, free)
            s = cd.halfspace_self_block(h.patches, h.lams, h.youngs_modulus, h.poisson_ratio)
            for k, patch in enumerate(h.patches):
                nrm = np.zeros(4)
                nrm[2 * k:2 * k + 2] = math.cos(patch.psi), math.sin(patch.psi)
                where = ("upper" if math.sin(patch.psi) > 0 else "lower") + " contact point"
                tag = f"{ring} ring ({bc}, bolted {face} face), contact {patch.contact} ({where})"
                print(f"\n{tag}: S = {nrm @ s @ nrm * 1e9:.3f}, floor = {nrm @ h.floor @ nrm * 1e9:.3f}")
                print("   j   " + " ".join(f"{j:>8d}" for j in js))
                for name, g in (("FE - S", raw), ("kept", kept), ("old", old)):
                    print(f"  {name:6s}" + " ".join(f"{nrm @ g[j] @ nrm * 1e9:8.3f}" for j in js))


if __name__ == "__main__":
    main()
