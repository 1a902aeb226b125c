"""The C3D20 tube mesher of the CalculiX tube references (references/calculix/tube_mesh.py, used by
references/calculix/calculix_tube.py and references/calculix/connected/imported_tube.py): its counts and
geometry, no CalculiX run."""
import importlib.util
import math
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _mesher():
    spec = importlib.util.spec_from_file_location("tube_mesh", ROOT / "references" / "calculix" / "tube_mesh.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_tube_mesh_counts_match_the_documented_imported_tube():
    # references/calculix/connected/README.md: 2 x 139 x 12 bricks, 55 044 free DOFs (far end
    # clamped), 1112 face nodes (5 radii at the 139 corner angles, 3 at the 139 midside angles)
    m = _mesher()
    lines, ids, where = m.c3d20_tube(0.760, 0.805, 0.300, -0.0375, 2, 139, 12)
    assert lines[0] == "*NODE" and "*ELEMENT,TYPE=C3D20,ELSET=TUBE" in lines
    start = lines.index("*ELEMENT,TYPE=C3D20,ELSET=TUBE")
    assert start - 1 == len(ids) == len(where)
    assert len(lines) - start - 1 == 2 * 2 * 139 * 12          # two lines an element
    face = [v for (i, j, k), v in ids.items() if k == 0]
    far = [v for (i, j, k), v in ids.items() if k == 2 * 12]
    assert len(face) == len(far) == 5 * 139 + 3 * 139
    assert 3 * (len(ids) - len(far)) == 55_044
    # no node of a 20-node brick has two odd half-step indices (no face or body centres)
    assert all(sum(x % 2 for x in key) <= 1 for key in ids)


def test_tube_mesh_geometry_and_elements():
    m = _mesher()
    ri, ro, length, z_face = 0.5, 0.56, 0.2, 0.1
    lines, ids, where = m.c3d20_tube(ri, ro, length, z_face, 1, 7, 3, number_format=".9f")
    xyz = np.array([[float(x) for x in line.split(",")[1:]] for line in lines[1:1 + len(ids)]])
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    assert abs(r.min() - ri * 1e3) < 1e-6 and abs(r.max() - ro * 1e3) < 1e-6
    assert abs(xyz[:, 2].max() - z_face * 1e3) < 1e-9 and abs(xyz[:, 2].min() - (z_face - length) * 1e3) < 1e-9
    for v, (rr, t, z, k) in where.items():                    # where agrees with the written coordinates
        assert np.allclose(xyz[v - 1], [rr * math.cos(t), rr * math.sin(t), z], atol=1e-6)
    start = lines.index("*ELEMENT,TYPE=C3D20,ELSET=TUBE")
    conn = [[int(x) for x in (lines[start + 1 + 2 * e] + lines[start + 2 + 2 * e]).split(",") if x][1:]
            for e in range(7 * 3)]
    assert all(len(c) == 20 and len(set(c)) == 20 for c in conn)
    for c in conn:                                             # a positive volume: corners 1-4 below 5-8
        p = xyz[np.array(c[:8]) - 1]
        assert p[:4, 2].mean() < p[4:, 2].mean()
        a, b, d = p[1] - p[0], p[3] - p[0], p[4] - p[0]
        assert np.dot(np.cross(a, b), d) > 0
    assert m.nset("FAR", range(1, 14)) == ["*NSET,NSET=FAR", "1,2,3,4,5,6,7,8,9,10,11,12", "13"]
