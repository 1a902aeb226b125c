"""Load distribution with rigid and flexible rings, like the paper's Figs 6 and 8-11.

* table3 with synthetic errors, idling with the nominal ball and with +20 um preload:
  interference per ball, rigid against flexible rings (Figs 8, 9), with the mean and
  max-min band the paper discusses in section 4.1;
* the same bearing, ball loads idling and under a radial load (Figs 10, 11);
* table1, axial load against axial displacement for rigid rings and for flexible rings
  clamped, on a frictionless support and free (Fig. 6).

Writes PNG files to ``results/load_distribution/`` and prints the figures' numbers.

    .venv/bin/python examples/load_distribution_study.py
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from slewing_model import Loads, load_bearing, solve
from slewing_model.plots import plot_axial_stiffness, plot_distribution
from slewing_model.rings.superelement import build_superelement

ROOT = Path(__file__).resolve().parents[1]


def idling(out: Path) -> list[str]:
    bearing = load_bearing(ROOT / "examples/bearings/table3_errors.toml")
    se = build_superelement(bearing, mesh="fine", bc="free")
    lines = ["| preload | rings | mean interference [um] | max - min [um] |", "|---|---|---|---|"]
    for preload in (0.0, 20e-6):
        b = bearing.with_preload(preload)
        rigid, flexible = solve(b), solve(b, model="flexible", superelement=se)
        for name, r in (("rigid", rigid), ("flexible (free)", flexible)):
            lines.append(f"| +{preload * 1e6:g} um | {name} | {r.interference.mean() * 1e6:.1f} | "
                         f"{np.ptp(r.interference) * 1e6:.1f} |")
        plot_distribution({"rigid rings (Rigid-BIME)": rigid, "flexible rings (Flexible-BIME)": flexible},
                          out / f"interference_preload_{preload * 1e6:g}um.png",
                          title=f"{b.name}: idling, ball preload +{preload * 1e6:g} um (paper Figs 8, 9)")
    idle = solve(bearing, model="flexible", superelement=se)
    radial = solve(bearing, Loads(Fx=150e3), model="flexible", superelement=se)
    plot_distribution({"idling": idle, "radial load 150 kN": radial}, out / "ball_loads_idle_radial.png",
                      quantity="load", title=f"{bearing.name}: flexible rings (paper Figs 10, 11)")
    return lines


#: why free rings come out stiffer than rings on a frictionless support (the figure's caption)
FREE_VS_FRICTIONLESS = (
    "free: rigid-body modes removed, so an even axial load of the balls moves a ring without deforming it;\n"
    "only the radial (hoop) and rolling parts of the ball forces deform it. frictionless: the bolted face carries\n"
    "the axial load, so the cross-section also deforms and rolls between the raceway and that face: softer.")


def axial_stiffness(out: Path) -> list[str]:
    bearing = load_bearing(ROOT / "examples/bearings/table1.toml")
    forces = np.linspace(0.25e6, 6e6, 12)
    curves = {"rigid rings": [solve(bearing, Loads(Fz=f)).displacement[2] for f in forces]}
    for bc in ("clamped", "frictionless", "free"):
        se = build_superelement(bearing, mesh="fine", bc=bc)
        curves[f"flexible, {bc}"] = [solve(bearing, Loads(Fz=f), model="flexible", superelement=se).displacement[2]
                                     for f in forces]
    plot_axial_stiffness({k: (v, forces) for k, v in curves.items()}, out / "axial_stiffness_table1.png",
                         title=f"{bearing.name}: axial stiffness (paper Fig. 6)", note=FREE_VS_FRICTIONLESS)
    lines = ["| axial load [kN] | " + " | ".join(f"{k} [um]" for k in curves) + " |",
             "|---" * (len(curves) + 1) + "|"]
    for i in (1, 3, 7, 11):
        lines.append(f"| {forces[i] / 1e3:.0f} | " + " | ".join(f"{v[i] * 1e6:.0f}" for v in curves.values()) + " |")
    return lines


def main() -> int:
    out = ROOT / "results" / "load_distribution"
    out.mkdir(parents=True, exist_ok=True)
    print("\n".join(idling(out)))
    print()
    print("\n".join(axial_stiffness(out)))
    print(f"\nfigures in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
