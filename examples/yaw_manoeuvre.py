"""Yaw manoeuvre: six electric yaw motors turn the nacelle with the yaw bearing FMU in the loop.

An 8 deg yaw move at the yaw rate limit under tower-top loads (rotor and nacelle weight,
thrust and its tilting moment, aerodynamic yaw moment with turbulence), with and without
the bearing's friction. Writes ``results/yaw_manoeuvre.png`` and ``.csv``.

    .venv/bin/python examples/yaw_manoeuvre.py [--rigid]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from build_fmu import build_fmu  # noqa: E402
from slewing_drives import DriveParameters, LoadSeries  # noqa: E402
from slewing_drives.cosimulation import plot_manoeuvre, run_manoeuvre, summary_table, write_csv  # noqa: E402

YAW_DEG, T_ON, T_END, DT = 8.0, 2.0, 30.0, 0.05


def command(t: float) -> float:
    """Yaw angle command, rad: 8 deg from 2 s (the drive's rate limit sets the speed)."""
    return math.radians(YAW_DEG) if t >= T_ON else 0.0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rigid", action="store_true", help="rigid rings (faster) instead of flexible rings")
    parser.add_argument("--results", default=str(ROOT / "results"))
    args = parser.parse_args(argv)
    results = Path(args.results)
    fmu = build_fmu(ROOT / "examples/bearings/yaw_bearing.toml", ROOT / "build/SlewingBearing_yaw_bearing.fmu",
                    stage=lambda line: print(line, flush=True))     # a line as each stage of the build begins
    drive = DriveParameters.from_toml(ROOT / "examples/drives/yaw_drive.toml")
    loads = LoadSeries.read_csv(ROOT / "examples/loads/tower_top_loads.csv")
    # tower-top loads turn with the nacelle (the inner ring): load_frame = 2 (rotating)
    start = {"load_frame": 2, "ring_model": 1 if args.rigid else 2, "friction_coefficient": 0.1}
    runs = [run_manoeuvre(fmu, drive, loads, command, t_end=T_END, dt=DT, start_values=start, friction=f,
                          progress=True) for f in (True, False)]
    results.mkdir(parents=True, exist_ok=True)
    plot_manoeuvre(runs[0], results / "yaw_manoeuvre.png", without_friction=runs[1],
                   title=f"{YAW_DEG:g} deg yaw move, {drive.name}, yaw bearing FMU in the loop")
    write_csv(runs[0], results / "yaw_manoeuvre.csv", runs[1])
    print(summary_table(*runs))
    print(f"\nplot: {results / 'yaw_manoeuvre.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
