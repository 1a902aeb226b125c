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
import site
import sys
import sysconfig
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
from slewing_model import RUNTIME_MODULES  # noqa: E402  (the modules of slewing_model the FMU runs with)


def build_fmu(bearing_file, output=None, *, bc="free", mesh="fine", progress=False, fmi_version=2) -> Path:
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
        Superelement mesh; "fine" (default) is within 0.5 % of a finer one, "coarse" is for tests.
    fmi_version : {2, 3}
        2 (default): FMI 2.0 with pythonfmu, per-ball results as scalars ``ball[i].Q1``...;
        3: FMI 3.0 with pythonfmu3 (``fmu_src/SlewingBearing3.py``), per-ball results as arrays.
    """
    if fmi_version not in (2, 3):
        raise ValueError(f"fmi_version = {fmi_version!r}: must be 2 or 3")
    from pythonfmu import FmuBuilder

    from slewing_model import load_bearing
    from slewing_model.superelement import build_superelement

    bearing = load_bearing(bearing_file)
    superelement = build_superelement(bearing, mesh=mesh, bc=bc, progress=progress)
    stem = "SlewingBearing3" if fmi_version == 3 else "SlewingBearing"
    output = Path(output) if output else ROOT / "build" / f"{stem}_{Path(bearing_file).stem}.fmu"
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
        # where numpy lives in the building environment: the FMU's fallback when its host lacks numpy
        (tmp / "python_paths.json").write_text(json.dumps(sorted(set(site.getsitepackages()))))
        superelement.save(tmp / "superelement.npz")
        if fmi_version == 3:  # the variable tables are shared with the FMI 2.0 slave (bearing_variables.py)
            return _build_fmi3(output, [package, tmp / "bearing.json", tmp / "superelement.npz",
                                        ROOT / "fmu_src" / "bearing_variables.py"])
        built = FmuBuilder.build_FMU(
            ROOT / "fmu_src" / "SlewingBearing.py", dest=output,
            project_files=[package, tmp / "bearing.json", tmp / "superelement.npz", tmp / "python_paths.json",
                           ROOT / "fmu_src" / "bearing_variables.py"],
            canGetAndSetFMUstate=True, canSerializeFMUstate=True,
            needsExecutionTool=True, canHandleVariableCommunicationStepSize=True,
        )
    return Path(built)


def _build_fmi3(output: Path, project_files) -> Path:
    """Package ``fmu_src/SlewingBearing3.py`` with pythonfmu3 (which writes ``<modelName>.fmu`` into a folder)."""
    from pythonfmu3 import FmuBuilder as Fmu3Builder

    with tempfile.TemporaryDirectory(prefix="slewing_fmu3_") as folder:
        built = Fmu3Builder.build_FMU(ROOT / "fmu_src" / "SlewingBearing3.py", dest=folder,
                                      project_files=project_files, needsExecutionTool=True,
                                      canGetAndSetFMUState=True, canSerializeFMUState=True,
                                      canHandleVariableCommunicationStepSize=True)
        shutil.move(str(built), output)
    return output


def host_environment() -> dict[str, str]:
    """Environment a C or C++ host on Linux needs to run the FMU.

    pythonfmu's binary is not linked to libpython, and numpy's C extensions need
    libpython's symbols loaded globally; nothing inside the FMU can do that (even
    ``ctypes`` is such an extension), so the host process must preload it."""
    libpython = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("INSTSONAME")
    return {"LD_PRELOAD": str(libpython)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bearing", nargs="?", help="bearing definition (TOML)")
    parser.add_argument("-o", "--output", help="FMU file to write")
    parser.add_argument("--bc", choices=("free", "clamped", "frictionless"), default="free")
    parser.add_argument("--mesh", choices=("coarse", "fine"), default="fine")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="FMI 2.0 (default; per-ball scalars) or FMI 3.0 (pythonfmu3; per-ball arrays)")
    parser.add_argument("--host-env", action="store_true",
                        help="only print the environment a C/C++ host on Linux needs (LD_PRELOAD of libpython)")
    args = parser.parse_args(argv)
    if args.host_env:
        for key, value in host_environment().items():
            print(f"export {key}={value}")
        return 0
    if args.bearing is None:
        parser.error("the bearing definition is required")
    path = build_fmu(args.bearing, args.output, bc=args.bc, mesh=args.mesh, progress=True,
                      fmi_version=args.fmi_version)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
