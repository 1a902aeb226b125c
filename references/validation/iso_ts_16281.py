"""ISO/TS 16281 check values against slewing_model.life, as a figure and a table.

The published case is a radial deep-groove ball bearing: Z = 7 balls of Dw = 11.5 mm on
dm = 43.5 mm, groove radii 0.52 Dw (inner) and 0.53 Dw (outer), contact angle 0, basic
dynamic radial rating C = 23 400 N, inner ring turning, zero clearance. Two load cases:
Fr = 1000 N and Fa = 1000 N. The published values are the ones held by tests/test_life.py.

The ball loads of the radial case come from the rigid zero-clearance equilibrium written out
here (independent of the library): Q_j = Qmax cos^(3/2) psi_j on the loaded half,
Qmax = Fr / sum cos^(5/2) psi_j. Everything after the ball loads is slewing_model.life.

    .venv/bin/python references/validation/iso_ts_16281.py [-o docs/figures/val_iso_ts_16281.png]

Run time: about 2 s (most of it importing matplotlib). Prints the table of the validation page.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import slewing_model.life as life  # noqa: E402
from references.validation.figure import pyplot, save  # noqa: E402

Z, DW, DM = 7, 11.5e-3, 43.5e-3
RI, RE, C = 0.52 * DW, 0.53 * DW, 23400.0

#: (quantity, published value, unit); the published ISO/TS 16281 check values
PUBLISHED = [
    ("radial: Qmax (equilibrium above)", 619.61, "N"),
    ("radial: Qe inner", 347.86, "N"),
    ("radial: Qe outer", 363.99, "N"),
    ("Qc inner (from C)", 8423.2, "N"),
    ("Qc outer (from C)", 18288.7, "N"),
    ("radial: L10r", 13163.0, "10^6 rev"),
    ("axial: L10r", 2222.73, "10^6 rev"),
]


def rigid_radial_ball_loads(radial_load, balls):
    c = np.clip(np.cos(2 * np.pi * np.arange(balls) / balls), 0.0, None)
    return radial_load / np.sum(c ** 2.5) * c ** 1.5


def computed():
    q = rigid_radial_ball_loads(1000.0, Z)
    qci, qce = life.radial_raceway_capacities(C, Z, DW, DM, 0.0, RI, RE)
    radial = life.raceway_life([life.Raceway("inner", RI, 0.0, q, True, qci),
                                life.Raceway("outer", RE, 0.0, q, False, qce)], Z, DW, DM)
    qa = np.full(Z, 631.50)                       # Fa = 1000 N: every ball 631.50 N (published)
    axial = life.raceway_life([life.Raceway("inner", RI, 0.0, qa, True, qci),
                               life.Raceway("outer", RE, 0.0, qa, False, qce)], Z, DW, DM)
    geo = (float(life.raceway_capacity("inner", Z, DW, DM, 0.0, RI)),
           float(life.raceway_capacity("outer", Z, DW, DM, 0.0, RE)))
    return [q.max(), radial.equivalent_load[0], radial.equivalent_load[1], qci, qce, radial.life, axial.life], geo


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", default="results/validation/val_iso_ts_16281.png")
    args = p.parse_args(argv)
    ours, geo = computed()
    print("| quantity | published | slewing_model | difference |")
    print("|---|---|---|---|")
    rel = []
    for (name, ref, unit), val in zip(PUBLISHED, ours):
        rel.append(val / ref - 1)
        print(f"| {name} [{unit}] | {ref:g} | {val:.6g} | {rel[-1]:+.1e} |")
    for ring, ref, val in (("inner", 8423.2, geo[0]), ("outer", 18288.7, geo[1])):
        print(f"| Qc {ring} from the geometry (Lundberg-Palmgren, bm 1.3) [N] | {ref:g} | {val:.5g} | "
              f"{val / ref - 1:+.1%} |")

    plt = pyplot()
    out = Path(args.output)
    fig, ax = plt.subplots(figsize=(8, 4.6))
    names = [n for n, _, _ in PUBLISHED]
    # the published value's last digit: half a unit of it, relative
    half_digit = [0.005 / 619.61, 0.005 / 347.86, 0.005 / 363.99, 0.05 / 8423.2, 0.05 / 18288.7, 0.05 / 13163.0,
                  0.005 / 2222.73]
    y = np.arange(len(names))[::-1]
    ax.barh(y, 2e6 * np.array(half_digit), left=-1e6 * np.array(half_digit), color="0.85",
            label="half a unit of the published last digit")
    ax.plot(np.array(rel) * 1e6, y, "o", color="C0", label="slewing_model / published - 1")
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_yticks(y, names)
    ax.set_xlabel("difference from the published value [1e-6, relative]")
    ax.set_xlim(-25, 25)
    ax.set_title("ISO/TS 16281 check case: radial ball bearing, Z 7, Dw 11.5 mm, C 23.4 kN", fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.4, -0.14), ncol=2, fontsize=8)
    ax.grid(axis="x", alpha=0.3)
    return save(fig, out)


if __name__ == "__main__":
    sys.exit(main())
