"""The C3D20 tube mesh of the CalculiX tube references: one mesher for
``references/calculix/connected/imported_tube.py`` and ``references/calculix/calculix_tube.py``.

Both import it as ``references.calculix.tube_mesh`` with the repository root on ``sys.path``.
"""
from __future__ import annotations

import math


def c3d20_tube(ri: float, ro: float, length: float, z_face: float, n_r: int, n_t: int, n_z: int,
               number_format: str = ".12g") -> tuple[list[str], dict, dict]:
    """A tube of 20-node bricks (C3D20), ``n_r`` through the wall x ``n_t`` around x ``n_z`` along,
    from its face at ``z_face`` downwards (``ri``, ``ro``, ``length``, ``z_face`` in m; the deck in mm).

    Returns the deck's lines from ``*NODE`` to the last element (ELSET ``TUBE``; coordinates
    written with ``number_format``), the node ids by half-step index ``{(i, j, k): id}`` (i 0..2 n_r
    from the bore out, j 0..2 n_t - 1 around, periodic, k 0..2 n_z from the face down: k = 0 is the
    face, k = 2 n_z the far end) and ``{id: (r mm, theta rad, z mm, k)}``.
    """
    ids, where = {}, {}
    lines = ["*NODE"]

    def node(i, j, k):
        key = (i, j % (2 * n_t), k)
        if key not in ids:
            ids[key] = len(ids) + 1
            r = (ri + (ro - ri) * i / (2 * n_r)) * 1e3
            t = 2 * math.pi * key[1] / (2 * n_t)
            z = (z_face - length * k / (2 * n_z)) * 1e3
            where[ids[key]] = (r, t, z, k)
            lines.append(f"{ids[key]},{r * math.cos(t):{number_format}},{r * math.sin(t):{number_format}},"
                         f"{z:{number_format}}")
        return ids[key]

    elements = []
    for i in range(n_r):
        for j in range(n_t):
            for k in range(n_z):
                a, b, c = 2 * i, 2 * j, 2 * k
                # local axes (r, theta, -z) would be left-handed: the bottom face is the far (lower) one
                lo, hi = c + 2, c
                corners = [(a, b, lo), (a + 2, b, lo), (a + 2, b + 2, lo), (a, b + 2, lo),
                           (a, b, hi), (a + 2, b, hi), (a + 2, b + 2, hi), (a, b + 2, hi)]
                mids = [(a + 1, b, lo), (a + 2, b + 1, lo), (a + 1, b + 2, lo), (a, b + 1, lo),
                        (a + 1, b, hi), (a + 2, b + 1, hi), (a + 1, b + 2, hi), (a, b + 1, hi),
                        (a, b, c + 1), (a + 2, b, c + 1), (a + 2, b + 2, c + 1), (a, b + 2, c + 1)]
                elements.append([node(*p) for p in corners + mids])
    lines.append("*ELEMENT,TYPE=C3D20,ELSET=TUBE")
    for e, conn in enumerate(elements, start=1):
        lines.append(f"{e}," + ",".join(map(str, conn[:15])) + ",")
        lines.append(",".join(map(str, conn[15:])))
    return lines, ids, where


def nset(name: str, nodes) -> list[str]:
    """An ``*NSET`` block, 12 node ids a line."""
    nodes = list(nodes)
    return [f"*NSET,NSET={name}"] + [",".join(map(str, nodes[s:s + 12])) for s in range(0, len(nodes), 12)]
