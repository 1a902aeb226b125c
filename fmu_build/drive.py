"""Build the slewing drive FMU (FMI 2.0 co-simulation) for one drive definition, and time-table FMUs.

    python -m fmu_build.drive DRIVE.toml [-o FILE.fmu] [--torque-constant N.m/A]

The drive FMU packages ``fmu_src/SlewingDrive.py`` with ``slewing_drives/drive.py``
(numpy and the standard library only) and the definition in SI units
(``drive.json``). :func:`build_table_fmu` packages ``fmu_src/TimeTable.py`` with
a table of signals against time (the load series and the angle command of the
pitch system SSP, ``examples/ssp/build_ssp.py``).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import shutil
import sys
import tempfile
from pathlib import Path

from fmu_build.shim import install_python_shim, pythonfmu_build  # the FMU's Linux layer: no LD_PRELOAD in C hosts

ROOT = Path(__file__).resolve().parents[1]


def build_drive_fmu(drive_file, output=None, *, torque_constant: float = 1.5, win64: bool = True) -> Path:
    """Build the FMU of ``drive_file`` (``examples/drives/*.toml``); returns the path of the ``.fmu``.

    Parameters
    ----------
    drive_file : path
        Drive definition (TOML), read by :meth:`slewing_drives.DriveParameters.from_toml`.
    output : path, optional
        FMU file; default ``build/SlewingDrive_<name>.fmu``.
    torque_constant : float, N m/A
        Motor torque per ampere, for the FMU's ``motor_current`` output only (the drive
        definitions have none; 1.5 N m/A is an illustrative servo-motor value). A tunable
        parameter of the FMU.
    win64 : bool
        Also carry the standalone Windows binary (default; :mod:`fmu_build.win64`).
    """
    from slewing_drives import DriveParameters

    params = DriveParameters.from_toml(drive_file)
    definition = {k: v for k, v in dataclasses.asdict(params).items() if k != "sources"}
    definition["torque_constant"] = float(torque_constant)
    output = Path(output) if output else ROOT / "build" / f"SlewingDrive_{Path(drive_file).stem}.fmu"
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="slewing_drive_fmu_") as tmp:
        tmp = Path(tmp)
        package = tmp / "slewing_drives"
        package.mkdir()
        (package / "__init__.py").write_text('"""The drive model alone (the FMU runs with numpy only)."""\n')
        shutil.copy2(ROOT / "slewing_drives" / "drive.py", package / "drive.py")
        (tmp / "drive.json").write_text(json.dumps(definition))
        built = pythonfmu_build(ROOT / "fmu_src" / "SlewingDrive.py", dest=output,
                                project_files=[package, tmp / "drive.json"],
                                canGetAndSetFMUstate=True, canSerializeFMUstate=True,
                                needsExecutionTool=True, canHandleVariableCommunicationStepSize=True)
    install_python_shim(built, "SlewingDrive", win64=win64)  # runs in C hosts without LD_PRELOAD (fmu_build/shim.py)
    return Path(built)


def build_table_fmu(output, name: str, time, columns, values, *, interpolation: str = "linear",
                    win64: bool = True) -> Path:
    """Build a time-table FMU (``fmu_src/TimeTable.py``); returns the path of the ``.fmu``.

    Parameters
    ----------
    output : path
    name : str
        What the table is (in the FMU's description).
    time : sequence of float, s
        Strictly increasing.
    columns : list of (name, unit, description)
        One output per column; units from :data:`TimeTable.UNITS` (SI).
    values : array-like (len(time), len(columns))
    interpolation : {"linear", "previous"}
        Linear between rows, or each row's value held until the next row (a step table).
    win64 : bool
        Also carry the standalone Windows binary (default; :mod:`fmu_build.win64`).
    """
    import numpy as np
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    if interpolation not in ("linear", "previous"):
        raise ValueError(f"interpolation = {interpolation!r}: must be 'linear' or 'previous'")
    if time.ndim != 1 or time.size < 1 or np.any(np.diff(time) <= 0) or not np.all(np.isfinite(time)):
        raise ValueError("time: must be a non-empty, finite, strictly increasing sequence")
    if values.shape != (time.size, len(columns)) or not np.all(np.isfinite(values)):
        raise ValueError(f"values: must be finite, of shape ({time.size}, {len(columns)}); got {values.shape}")
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="slewing_table_fmu_") as tmp:
        tmp = Path(tmp)
        (tmp / "table.json").write_text(json.dumps({
            "name": name, "interpolation": interpolation, "time": time.tolist(),
            "columns": [list(c) for c in columns], "values": values.tolist()}))
        built = pythonfmu_build(ROOT / "fmu_src" / "TimeTable.py", dest=output, project_files=[tmp / "table.json"],
                                canGetAndSetFMUstate=True, canSerializeFMUstate=True, needsExecutionTool=True,
                                canHandleVariableCommunicationStepSize=True)
    install_python_shim(built, "TimeTable", win64=win64)
    return Path(built)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmu_build.drive", description=__doc__.splitlines()[0])
    parser.add_argument("drive", help="drive definition (TOML), e.g. examples/drives/pitch_drive.toml")
    parser.add_argument("-o", "--output", help="FMU file to write")
    parser.add_argument("--torque-constant", type=float, default=1.5, metavar="N.m/A",
                        help="motor torque constant, for the motor_current output (default 1.5)")
    parser.add_argument("--win64", action=argparse.BooleanOptionalAction, default=True,
                        help="carry a standalone Windows (win64) binary (default: yes)")
    args = parser.parse_args(argv)
    print(f"wrote {build_drive_fmu(args.drive, args.output, torque_constant=args.torque_constant, win64=args.win64)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
