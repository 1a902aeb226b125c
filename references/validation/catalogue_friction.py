"""The makers' start-up friction formula against the analytical friction torque, table1.

The catalogue formula of four-point contact slewing bearings,
``M = mu/2 (4.4 M_k + F_a D + 2.2 F_r D 1.73)`` with mu = 0.006 (scatter +-25 %), is
slewing_model.friction.catalogue_torque. The analytical torque is friction_torque on the
rigid-ring load distribution of examples/bearings/table1.toml (100 balls, dm 1.5 m), contact
mu = 0.1, no seals. Left: the load cases of the validation page's table (no preload and
20 um); right: a sweep of the tilting moment and of the axial load, no preload.

    .venv/bin/python references/validation/catalogue_friction.py [-o docs/figures/val_catalogue_friction.png]

Run time: about 10 s. Prints the table of the validation page.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from slewing_model import Loads, load_bearing, solve  # noqa: E402
from slewing_model.friction import catalogue_torque, friction_torque  # noqa: E402
from references.validation.figure import pyplot, save  # noqa: E402

CASES = [("axial Fa 1000 kN", Loads(Fz=1000e3)),
         ("moment Mk 1000 kN m", Loads(My=1000e3)),
         ("Fr 200 kN + Fa 200 kN", Loads(Fx=200e3, Fz=200e3)),
         ("Fa 500 kN, Fr 100 kN, Mk 800 kN m", Loads.from_paper(500e3, 100e3, 800e3))]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", default="results/validation/val_catalogue_friction.png")
    args = p.parse_args(argv)
    t1 = load_bearing(ROOT / "examples/bearings/table1.toml")
    rows = []
    print("| load case | preload [um] | catalogue [kN m] (range +-25 %) | analytical, mu 0.1 [kN m] | ratio |")
    print("|---|---|---|---|---|")
    for preload in (0.0, 20e-6):
        b = t1.with_preload(preload)
        for name, loads in CASES:
            m_cat = catalogue_torque(b, loads)
            m = friction_torque(b, solve(b, loads)).magnitude
            rows.append((name, preload, m_cat, m))
            print(f"| {name} | {preload * 1e6:.0f} | {m_cat / 1e3:.2f} ({0.75 * m_cat / 1e3:.2f}-{1.25 * m_cat / 1e3:.2f})"
                  f" | {m / 1e3:.2f} | {m / m_cat:.2f} |")
        m_idle = friction_torque(b, solve(b, None)).magnitude
        print(f"| idling | {preload * 1e6:.0f} | 0 | {m_idle / 1e3:.2f} | - |")

    moments = np.linspace(0.1e6, 3e6, 12)
    axial = np.linspace(0.1e6, 3e6, 12)
    sweep = {}
    for label, series, make in (("moment", moments, lambda v: Loads(My=v)), ("axial", axial, lambda v: Loads(Fz=v))):
        sweep[label] = (series, np.array([catalogue_torque(t1, make(v)) for v in series]),
                        np.array([friction_torque(t1, solve(t1, make(v))).magnitude for v in series]))
        s, cat, ana = sweep[label]
        print(f"{label} sweep: analytical / catalogue from {ana[0] / cat[0]:.2f} at {s[0] / 1e6:g} to "
              f"{ana[-1] / cat[-1]:.2f} at {s[-1] / 1e6:g} (MN m or MN)")

    plt = pyplot()
    out = Path(args.output)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.6), gridspec_kw={"width_ratios": [1.3, 1]})
    x = np.arange(len(CASES))
    for k, preload in enumerate((0.0, 20e-6)):
        sel = [r for r in rows if r[1] == preload]
        cat = np.array([r[2] for r in sel]) / 1e3
        ana = np.array([r[3] for r in sel]) / 1e3
        if k == 0:
            a1.bar(x - 0.3, cat, 0.2, yerr=0.25 * cat, capsize=3, color="0.75", label="catalogue, mu 0.006 (+-25 %)")
        a1.bar(x - 0.1 + 0.2 * k, ana, 0.2, color=("C0", "C1")[k],
               label=f"analytical, contact mu 0.1, preload {preload * 1e6:.0f} um")
    a1.set_xticks(x, [name.replace(", ", ",\n").replace(" + ", " +\n") for name, _ in CASES], fontsize=8)
    a1.set_ylabel("friction torque [kN m]")
    a1.set_title(f"{t1.name}, rigid rings: load cases", fontsize=10)
    a1.set_ylim(0, 21)
    a1.legend(fontsize=8, loc="upper left")
    a1.grid(axis="y", alpha=0.3)
    for label, color in (("moment", "C0"), ("axial", "C2")):
        s, cat, ana = sweep[label]
        a2.fill_between(s / 1e6, 0.75 * cat / 1e3, 1.25 * cat / 1e3, color=color, alpha=0.2)
        a2.plot(s / 1e6, cat / 1e3, "--", color=color, label=f"catalogue, {label} load")
        a2.plot(s / 1e6, ana / 1e3, "o-", color=color, ms=4, label=f"analytical, {label} load")
    a2.set_xlabel("My [MN m] or Fz [MN]")
    a2.set_ylabel("friction torque [kN m]")
    a2.set_title("sweep, no preload (band: catalogue +-25 %)", fontsize=10)
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3)
    return save(fig, out)


if __name__ == "__main__":
    sys.exit(main())
