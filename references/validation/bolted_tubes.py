"""Both rings bolted to tubes: the 3-D CalculiX reference against the model, ball by ball.

The reference is references/calculix/connected/bearing_3d.py (table1 with 40 balls, both rings
and their 300 mm tubes as 3-D solids assembled by CalculiX, the balls as nonlinear Hertz springs,
steel tubes E 210 GPa and soft ones E 20 GPa, Fz 200 kN and My 150 kN m). Its ball loads are
read from the CSV that bearing_3d.py --csv writes (default references/validation/data/bolted_tubes.csv); the model (coarse superelements with the
same tubes as parametric adapters) is computed here, live.

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/calculix/connected/bearing_3d.py --csv references/validation/data/bolted_tubes.csv   # CalculiX, 6-15 min, 2 GB
    .venv/bin/python references/validation/bolted_tubes.py -o docs/figures/val_calculix_bolted.png   # redraw, 30 s

Prints the page's table.
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from slewing_model import load_bearing  # noqa: E402
from references.validation.figure import pyplot, save  # noqa: E402

DATA = Path(__file__).resolve().parent / "data" / "bolted_tubes.csv"
DIAGONALS = ((1, 3), (4, 2))


def bearing_3d():
    spec = importlib.util.spec_from_file_location(
        "bearing_3d", ROOT / "references" / "calculix" / "connected" / "bearing_3d.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def stored(path=DATA):
    out = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            key = (float(r["tube_modulus_gpa"]), r["case"], r["halfspace"])
            out.setdefault(key, {})[int(r["diagonal"]), int(r["ball"])] = (float(r["load_3d_n"]),
                                                                            float(r["load_model_n"]))
    res = {}
    for key, d in out.items():
        nb = max(b for _, b in d) + 1
        q3 = np.array([[d[k + 1, b][0] for b in range(nb)] for k in range(2)])
        qm = np.array([[d[k + 1, b][1] for b in range(nb)] for k in range(2)])
        res[key] = (q3, qm)
    return res


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", default="results/validation/val_calculix_bolted.png")
    p.add_argument("--data", default=str(DATA), help="the CSV that bearing_3d.py --csv wrote")
    args = p.parse_args(argv)
    b3 = bearing_3d()
    bearing = load_bearing(b3.BEARING)
    B = bearing.ball_count
    ref = stored(args.data)
    tubes = sorted({k[0] for k in ref}, reverse=True)
    cases = list(b3.LOAD_CASES)
    live = {}
    for e in tubes:
        model, _ = b3.model_solution(bearing, e * 1e9, b3.LOAD_CASES)
        for name in cases:
            qm = model[name]
            live[e, name] = np.array([qm[:B // 2 + 1, o - 1] for o, _ in DIAGONALS])
    print("| tubes | load | peak 3-D [kN] (without the patch correction) | peak model [kN] | model / 3-D - 1 | "
          "largest per-contact difference / peak | loaded balls 3-D | loaded balls model |")
    print("|---|---|---|---|---|---|---|---|")
    for e in tubes:
        for name in cases:
            q3, qm_stored = ref[e, name, "corrected"]
            q3u = ref[e, name, "uncorrected"][0]
            qm = live[e, name]
            drift = np.abs(qm - qm_stored).max() / qm.max()
            pk3, pku, pkm = q3.max(), q3u.max(), qm.max()
            zone3 = [int(np.sum(q3[d] > 0.01 * pk3)) for d in range(2)]
            zonem = [int(np.sum(qm[d] > 0.01 * pkm)) for d in range(2)]
            print(f"| E {e:g} GPa | {name} | {pk3 / 1e3:.3f} ({pku / 1e3:.3f}) | {pkm / 1e3:.3f} | "
                  f"{pkm / pk3 - 1:+.2%} ({pkm / pku - 1:+.2%}) | {np.abs(q3 - qm).max() / pk3:.2%} | "
                  f"{zone3[0]} / {zone3[1]} | {zonem[0]} / {zonem[1]} |")
            if drift > 1e-6:
                print(f"  note: the live model differs from the model stored with the reference by {drift:.1e} of its peak")

    plt = pyplot()
    out = Path(args.output)
    fig, axes = plt.subplots(len(tubes), len(cases), figsize=(11, 3.6 * len(tubes)), squeeze=False)
    ang = 360.0 * np.arange(B // 2 + 1) / B
    for i, e in enumerate(tubes):
        for j, name in enumerate(cases):
            ax = axes[i, j]
            q3 = ref[e, name, "corrected"][0]
            qm = live[e, name]
            for d, color in ((0, "C0"), (1, "C1")):
                if q3[d].max() <= 0.01 * q3.max() and qm[d].max() <= 0.01 * qm.max():
                    continue
                ax.plot(ang, q3[d] / 1e3, "o", color=color, mfc="none", ms=6, label=f"3-D CalculiX, diagonal {d + 1}")
                ax.plot(ang, qm[d] / 1e3, "-", color=color, lw=1.2, label=f"model, diagonal {d + 1}")
            ax.set_title(f"E {e:g} GPa, {name}: peak {q3.max() / 1e3:.2f} kN (3-D), "
                         f"{qm.max() / 1e3:.2f} kN (model)", fontsize=8)
            if q3[1].max() <= 0.01 * q3.max():            # one diagonal, every ball alike: +-2 % of the peak
                ax.set_ylim(0.98 * q3.max() / 1e3, 1.02 * q3.max() / 1e3)
            ax.set_xlabel("ball angle [deg]")
            ax.set_ylabel("contact load [kN]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
    fig.suptitle(f"{bearing.name}: both rings bolted to 300 mm tubes, balls 0..{B // 2} (the other half mirrors them)",
                 fontsize=10)
    return save(fig, out)


if __name__ == "__main__":
    sys.exit(main())
