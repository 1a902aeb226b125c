#!/usr/bin/env python3
"""Build the slewing bearing FMU (FMI 2.0 co-simulation) for one bearing definition.

    python build_fmu.py BEARING.toml [-o FILE.fmu] [--bc free|clamped|frictionless] [--mesh coarse|fine]

Builds (or takes from the cache) the ring superelement, then packages with
pythonfmu: the slave ``fmu_src/SlewingBearing.py``, the run-time modules of
``slewing_model`` (numpy only: no scipy, no scikit-fem), ``bearing.json`` (the
definition in SI units) and ``superelement.npz``.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
#: modules of slewing_model the FMU runs with (run-time part: numpy and the standard library)
RUNTIME_MODULES = ("__init__", "geometry", "errors", "contact", "assembly", "bime", "ring_stiffness",
                   "friction", "simulator")


def build_fmu(bearing_file, output=None, *, bc="free", mesh="coarse", progress=False) -> Path:
    """Build the FMU of ``bearing_file``; returns the path of the ``.fmu``.

    Parameters
    ----------
    bearing_file : path
        Bearing definition (TOML).
    output : path, optional
        FMU file; default ``SlewingBearing_<name>.fmu`` beside the definition's name, in ``build/``.
    bc : {"free", "clamped", "frictionless"}
        Ring support of the superelement.
    mesh : {"coarse", "fine"}
    """
    from pythonfmu import FmuBuilder

    from slewing_model import load_bearing
    from slewing_model.superelement import build_superelement

    bearing = load_bearing(bearing_file)
    superelement = build_superelement(bearing, mesh=mesh, bc=bc, progress=progress)
    output = Path(output) if output else ROOT / "build" / f"SlewingBearing_{Path(bearing_file).stem}.fmu"
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="slewing_fmu_") as tmp:
        tmp = Path(tmp)
        package = tmp / "slewing_model"
        package.mkdir()
        for name in RUNTIME_MODULES:
            source = ROOT / "slewing_model" / f"{name}.py"
            if source.exists():
                shutil.copy2(source, package / source.name)
        (tmp / "bearing.json").write_text(json.dumps(bearing.to_dict()))
        superelement.save(tmp / "superelement.npz")
        built = FmuBuilder.build_FMU(
            ROOT / "fmu_src" / "SlewingBearing.py", dest=output,
            project_files=[package, tmp / "bearing.json", tmp / "superelement.npz"],
            canGetAndSetFMUstate=True, canSerializeFMUstate=True,
            needsExecutionTool=True, canHandleVariableCommunicationStepSize=True,
        )
    return Path(built)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bearing", help="bearing definition (TOML)")
    parser.add_argument("-o", "--output", help="FMU file to write")
    parser.add_argument("--bc", choices=("free", "clamped", "frictionless"), default="free")
    parser.add_argument("--mesh", choices=("coarse", "fine"), default="coarse")
    args = parser.parse_args(argv)
    path = build_fmu(args.bearing, args.output, bc=args.bc, mesh=args.mesh, progress=True)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
