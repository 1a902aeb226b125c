"""Pitch manoeuvre of an electric pitch drive with the bearing FMU in the loop.

A 5 deg pitch step held for 5 s and back, under blade-root loads (turbulent
thrust moment, rotor-periodic gravity), once with the bearing's friction and
once with it switched off. Writes ``results/pitch_manoeuvre.png`` and
``results/pitch_manoeuvre.csv`` and prints a summary table.

    .venv/bin/python examples/pitch_manoeuvre.py [--fast]
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

STEP_DEG, T_ON, T_OFF, T_END, DT = 5.0, 1.0, 6.0, 12.0, 0.01


def command(t: float) -> float:
    """Pitch angle command, rad: 5 deg between 1 s and 6 s."""
    return math.radians(STEP_DEG) if T_ON <= t < T_OFF else 0.0


def stage(line: str) -> None:
    """One line as a stage begins (the FMU's build is silent for minutes on a fresh machine)."""
    print(line, flush=True)


def run(results: Path, *, ring_model: int = 2, progress: bool = True):
    """Both manoeuvres (with and without bearing friction); returns the two results. With
    ``progress``, a line as each stage begins and a progress bar for each co-simulation."""
    say = stage if progress else None
    fmu = build_fmu(ROOT / "examples/bearings/pitch_bearing.toml", ROOT / "build/SlewingBearing_pitch_bearing.fmu",
                    stage=say)
    drive = DriveParameters.from_toml(ROOT / "examples/drives/pitch_drive.toml")
    loads = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    # blade-root loads turn with the blade: load_frame = 2 (rotating)
    start = {"load_frame": 2, "ring_model": ring_model, "friction_coefficient": 0.1}
    steps = round(T_END / DT)
    if say:
        say(f"co-simulating the pitch manoeuvre with the bearing's friction ({steps} steps of {DT * 1e3:g} ms) ...")
    with_friction = run_manoeuvre(fmu, drive, loads, command, t_end=T_END, dt=DT, start_values=start,
                                  progress=progress)
    if say:
        say(f"co-simulating it again with the friction off ({steps} steps) ...")
    without = run_manoeuvre(fmu, drive, loads, command, t_end=T_END, dt=DT, start_values=start, friction=False,
                            progress=progress)
    results.mkdir(parents=True, exist_ok=True)
    plot_manoeuvre(with_friction, results / "pitch_manoeuvre.png", without_friction=without,
                   title=f"{STEP_DEG:g} deg pitch step and back, {drive.name}, bearing FMU in the loop")
    write_csv(with_friction, results / "pitch_manoeuvre.csv", without)
    return with_friction, without


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rigid", action="store_true", help="rigid rings (faster) instead of flexible rings")
    parser.add_argument("--results", default=str(ROOT / "results"))
    args = parser.parse_args(argv)
    with_friction, without = run(Path(args.results), ring_model=1 if args.rigid else 2)
    print(summary_table(with_friction, without))
    print(f"\nplot: {Path(args.results) / 'pitch_manoeuvre.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
