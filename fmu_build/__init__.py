"""The build-time code that packages the FMUs (never inside an FMU, never imported by ``slewing_model``).

``build_fmu.py`` at the repository root is the entry point (``.venv/bin/python build_fmu.py BEARING.toml``);
it uses this package's modules:

* :mod:`fmu_build.shim`: the FMU's Linux binary, our layer in front of pythonfmu's, and the file that
  names the Python the FMU runs in (shared by the bearing, drive and time-table FMUs);
* :mod:`fmu_build.runtime`: the Python runtime a standalone FMU carries;
* :mod:`fmu_build.win64`: the FMU's standalone Windows (win64) binary and runtime, built on Linux;
* :mod:`fmu_build.aot`: the loops compiled ahead of time (``build_fmu.py --aot``);
* :mod:`fmu_build.bytecode`: the modules' bytecode the FMU carries beside their sources;
* :mod:`fmu_build.drive`: the drive FMU and the time-table FMUs
  (``.venv/bin/python -m fmu_build.drive DRIVE.toml``).
"""
