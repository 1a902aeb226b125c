"""Figures of a turbine study: bearing friction off against on, IPC off against on.

    .venv/bin/slewing turbine examples/studies/turbine_nrel5mw.toml -o results/turbine_nrel5mw --workers 2
    .venv/bin/python examples/turbine_study_figures.py results/turbine_nrel5mw

Reads ``DIR/summary.csv`` and writes into ``DIR/figures/``:

* ``turbine_study.png`` -- each figure against the mean wind speed, one line per IPC and friction setting,
  the mean over the seeds with their range as a band (:func:`slewing_turbine.study.study_figure`);
* ``turbine_pairs.png`` -- each case with friction on against the same case with friction off (top row), and
  with IPC on against IPC off (bottom row), coloured by the wind speed: a point above the diagonal is a
  figure the switch raises.

Prints the study's table and, per switch, the mean ratio on / off of each figure over the paired cases.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from slewing_turbine.study import _axes, markdown_table, read_summary, study_figure  # noqa: E402

PAIR_COLUMNS = (("motor_torque_rms_Nm", "motor torque RMS [N m]"),
                ("drive_energy_kJ", "drive energy [kJ]"),
                ("pitch_tracking_error_rms_deg", "pitch tracking error RMS [deg]"),
                ("time_above_continuous_torque_pct", "time above continuous torque [%]"),
                ("rotor_speed_std_rpm", "rotor speed std [rpm]"))
SWITCHES = (("friction", "bearing friction"), ("ipc", "IPC"))


def pairs(rows: list, switch: str, column: str, axes: list):
    """(off, on, wind speed) of the cases that differ in ``switch`` alone."""
    others = [a for a in axes if a != switch]
    off = {tuple(r[a] for a in others): r for r in rows if r[switch] == "false"}
    out = []
    for r in rows:
        if r[switch] == "true":
            mate = off.get(tuple(r[a] for a in others))
            if mate is not None and r[column] and mate[column]:
                out.append((float(mate[column]), float(r[column]), float(r.get("speed_m_s") or "nan")))
    return np.array(out).reshape(-1, 3)


def pair_figure(rows: list, axes: list, png: str) -> list:
    """The paired figure (module docstring); returns the lines of ratios it printed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    switches = [(s, label) for s, label in SWITCHES if s in axes]
    columns = [(c, label) for c, label in PAIR_COLUMNS if c in rows[0]]
    fig, ax = plt.subplots(len(switches), len(columns), figsize=(3.1 * len(columns), 3.1 * len(switches)),
                           squeeze=False)
    lines = []
    for i, (switch, switch_label) in enumerate(switches):
        for j, (column, label) in enumerate(columns):
            p = pairs(rows, switch, column, axes)
            a = ax[i, j]
            if p.size:
                points = a.scatter(p[:, 0], p[:, 1], c=p[:, 2], cmap="viridis", s=18)
                lo, hi = float(np.min(p[:, :2])), float(np.max(p[:, :2]))
                a.plot([lo, hi], [lo, hi], "k:", lw=0.8)
                some = p[:, 0] != 0.0                    # a ratio needs the figure without the switch
                if some.any():
                    ratio = np.mean(p[some, 1] / p[some, 0])
                    lines.append(f"{switch_label} on / off, {label}: {ratio:.3g} (mean of {some.sum()} pairs)")
                else:
                    lines.append(f"{switch_label} on / off, {label}: 0 in every case without it, "
                                 f"{np.max(p[:, 1]):.3g} at most with it")
                if j == len(columns) - 1:
                    fig.colorbar(points, ax=a, label="mean wind [m/s]")
            a.set_xlabel(f"{switch_label} off", fontsize=8)
            a.set_ylabel(f"{switch_label} on", fontsize=8)
            a.set_title(label, fontsize=8)
            a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", help="the study's output directory (summary.csv)")
    args = parser.parse_args(argv)
    summary = os.path.join(args.results, "summary.csv")
    rows = [r for r in read_summary(summary) if r["status"] == "ok"]
    if not rows:
        print(f"{summary}: no finished case", file=sys.stderr)
        return 1
    figures = os.path.join(args.results, "figures")
    os.makedirs(figures, exist_ok=True)
    written = [study_figure(summary, os.path.join(figures, "turbine_study.png"))]
    ratios = pair_figure(rows, _axes(list(rows[0])), os.path.join(figures, "turbine_pairs.png"))
    written.append(os.path.join(figures, "turbine_pairs.png"))
    print(markdown_table(summary))
    print()
    print("\n".join(ratios))
    print("wrote " + ", ".join(w for w in written if w))
    return 0


if __name__ == "__main__":
    sys.exit(main())
