"""The NREL 5MW in turbulent wind with ROSCO and three electric pitch drives on their pitch bearings.

60 s of IEC class B turbulence (Kaimal, 13 m/s mean at the hub), once with the bearings' friction and once
without; prints the summary table (pitch tracking, motor torque and duty, rotor speed, friction, x/2b;
the first 20 s, the start-up, left out: TurbineConfig.settle) and saves the time series as a figure.

    nice -n 10 .venv/bin/python examples/turbine_loop.py [--t-end 60] [--rigid] [--results results]

Each step (10 ms): wind -> each blade's BEM at its own pitch and azimuth in the sheared wind, plus gravity
and centrifugal loads -> each blade's pitch bearing (flexible rings by default; ``--rigid``: rigid rings,
about twice as fast) -> its friction torque and the blade's pitching moment to the blade's pitch drive
-> rotor speed -> ROSCO -> the pitch demands for the next step (slewing_turbine.loop).
Writes ``<results>/turbine_loop.png`` and ``<results>/turbine_loop.md`` (the table).
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from slewing_turbine.loop import RATED_ROTOR_SPEED, TurbineConfig, run_turbine, summary_table  # noqa: E402
from slewing_turbine.wind import kaimal  # noqa: E402

MEAN_WIND, SEED, DT = 13.0, 1, 0.01


def plot(runs: dict, path: Path, title: str) -> None:
    """Six panels against time: wind; rotor speed; blade 1's pitch demand and pitch; blade 1's motor
    torque; the three bearings' friction torque; blade 1's root bending moments (the bearing's tilting load)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    on, off = runs["friction on"], runs["friction off"]
    t = on.time
    fig, ax = plt.subplots(6, 1, figsize=(10, 15), sharex=True)
    ax[0].plot(t, on.wind, "k", lw=0.8)
    ax[0].set_ylabel("hub wind [m/s]")
    ax[1].plot(t, on.rotor_speed * 30 / math.pi, label="friction on")
    ax[1].plot(t, off.rotor_speed * 30 / math.pi, ":", label="friction off")
    ax[1].axhline(RATED_ROTOR_SPEED * 30 / math.pi, color="r", lw=0.8, label="rated 12.1 rpm")
    ax[1].set_ylabel("rotor speed [rpm]")
    ax[1].legend(loc="lower right", fontsize=8)
    ax[2].plot(t, np.degrees(on.pitch_demand[:, 0]), "k--", lw=0.8, label="demand (friction on)")
    ax[2].plot(t, np.degrees(on.pitch[:, 0]), label="pitch, friction on")
    ax[2].plot(t, np.degrees(off.pitch[:, 0]), ":", label="pitch, friction off")
    ax[2].set_ylabel("blade 1 pitch [deg]")
    ax[2].legend(loc="upper left", fontsize=8)
    p = on.drive_params
    ax[3].plot(t, on.motor_torque[:, 0], label="friction on")
    ax[3].plot(t, off.motor_torque[:, 0], ":", label="friction off")
    for sign in (1, -1):
        ax[3].axhline(sign * p.torque_limit, color="r", lw=0.8, label="torque limit" if sign > 0 else None)
    ax[3].axhline(on.continuous_torque_share * p.torque_limit, color="orange", lw=0.8, ls="--",
                  label="continuous torque (assumed)")
    ax[3].set_ylabel("blade 1 motor torque [N m]")
    ax[3].legend(loc="upper right", fontsize=8, ncol=2)
    for k in range(3):
        ax[4].plot(t, on.friction_torque[:, k] / 1e3, lw=0.8, label=f"blade {k + 1}")
    ax[4].set_ylim(0, None)
    ax[4].set_ylabel("bearing friction [kN m]")
    ax[4].legend(loc="lower right", fontsize=8, ncol=3)
    loads = on.root_loads
    ax[5].plot(t, loads[:, 0, 4] / 1e6, label="flap My (blade frame)")
    ax[5].plot(t, loads[:, 0, 3] / 1e6, label="edge Mx")
    ax[5].plot(t, loads[:, 0, 5] / 1e6 * 10, label="pitching Mz x 10")
    ax[5].set_ylabel("blade 1 root [MN m]")
    ax[5].legend(loc="upper right", fontsize=8, ncol=3)
    ax[5].set_xlabel("time [s]")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=60.0, help="simulated seconds (default 60)")
    parser.add_argument("--rigid", action="store_true", help="rigid bearing rings (faster) instead of flexible")
    parser.add_argument("--results", default=str(ROOT / "results"))
    args = parser.parse_args(argv)
    ring = "rigid" if args.rigid else "flexible"
    wind = kaimal(MEAN_WIND, args.t_end, DT, seed=SEED)
    config = TurbineConfig()
    runs = {}
    for name, friction in (("friction on", True), ("friction off", False)):
        print(f"{name}: {args.t_end:g} s at {DT * 1e3:g} ms, {ring} pitch bearings ...", flush=True)
        runs[name] = run_turbine(config, wind, t_end=args.t_end, dt=DT, drives="electric", bearings=ring,
                                 friction=friction, aero="bem", progress=True)
    table = summary_table(runs)
    print(table)
    results = Path(args.results)
    results.mkdir(parents=True, exist_ok=True)
    (results / "turbine_loop.md").write_text(table + "\n")
    figure = results / "turbine_loop.png"
    plot(runs, figure, f"NREL 5MW, Kaimal {MEAN_WIND:g} m/s class B, ROSCO, electric pitch drives on "
                       f"{ring} pitch bearings")
    print(f"\nfigure: {figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
