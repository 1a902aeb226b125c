"""The floor-lowered standalone FMU: glibc 2.28 and GCC 6's libstdc++, shown in Debian 11.

``tests/linux_floor/build.sh`` builds, in a Debian 11 ("bullseye") build chroot, a CPython 3.11 with the venv's
numpy, numba and llvmlite wheels, pythonfmu's FMI 2.0 export library and fmusim; ``build_fmu.py --linux-floor``
carries them. Here the FMUs built so run in the *bare* Debian 11 system (glibc 2.31, no Python, no compiler) of
tests/test_standalone.py: fmusim and our C host, against fmpy on this machine.

Building CPython takes minutes: ``make test`` builds it once as root before the tests (tests/platform_builds.py,
kept in /var/cache) and runs these tests with 5 fmusim runs per FMU and numpy's loops in both FMUs; without
root they are skipped, saying so. ``bash tests/linux_floor/run_all.sh`` runs them with 20 and the FMI 2.0 FMU
with numba's loops; ``SLEWING_BUILD_LINUX_FLOOR=1`` builds it from pytest.
"""
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from conftest import NUMBA_FMU_OPT_IN  # the FMI 2.0 floor FMU with numba's loops: opt-in
from test_standalone import (CHROOTS, HOST_RUNS, _readelf_glibc_needs, above, assert_fmusim_runs_as_fmpy, bare_system,
                             fmpy_steps, glibc_of, hosts, run_host, runtime_of)

ROOT = Path(__file__).resolve().parents[1]
BUILD_SCRIPT = ROOT / "tests" / "linux_floor" / "build.sh"
FLOOR_DIR = CHROOTS / "linux-floor"
SYSTEM = "bullseye"          # Debian 11, glibc 2.31: the bare test target
FLOOR = "2.28"               # the glibc floor reached (RHEL 8, Debian 10)
GLIBCXX_FLOOR = "3.4.22"     # GCC 6's libstdc++ (llvmlite's wheel; the export library has its libstdc++ linked in)
RTOL = 1e-9
#: fmusim runs per FMU: 20 in tests/linux_floor/run_all.sh, 5 in `make test` (a run of the numba FMU takes 4-5 s)
FMUSIM_RUNS = int(os.environ.get("SLEWING_FLOOR_FMUSIM_RUNS", "5"))

__all__ = ["hosts"]          # the C host fixture of test_standalone, used here

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason="SKIPPED, not root: the floor-lowered FMU's tests need "
                                "chroot (CI runs as root)")


def _version(text: str) -> tuple:
    return tuple(int(x) for x in text.split("."))


@pytest.fixture(scope="module")
def floor_dir():
    """The folder build.sh fills (the interpreter, the export library, fmusim for Debian 11), built where asked."""
    sys.path.insert(0, str(ROOT))
    from build_fmu import linux_floor

    if os.environ.get("SLEWING_BUILD_LINUX_FLOOR"):
        run = subprocess.run(["bash", str(BUILD_SCRIPT)], capture_output=True, text=True, timeout=3600)
        assert run.returncode == 0, run.stderr[-3000:]
    try:
        found = linux_floor(FLOOR_DIR)
    except RuntimeError:
        pytest.skip(f"SKIPPED: the floor-lowered runtime is not built in {FLOOR_DIR} (CPython in a Debian 11 "
                    "chroot, 2 to 4 minutes; make test builds it as root): run tests/platform_builds.py, or set "
                    "SLEWING_BUILD_LINUX_FLOOR=1")
    from importlib.metadata import version
    import fmu_build.runtime

    theirs = fmu_build.runtime.interpreter(found["runtime_python"])["packages"]
    ours = {name: version(name) for name in theirs}
    if theirs != ours:
        pytest.skip(f"SKIPPED: the floor-lowered runtime in {FLOOR_DIR} has {theirs}, this venv {ours}: "
                    "rebuild it with tests/linux_floor/run_all.sh")
    return found


@pytest.fixture(scope="module")
def floor_fmus(floor_dir, tmp_path_factory):
    """table3's bearing, standalone, built with --linux-floor: FMI 2.0 (pythonfmu's export library built in Debian
    11) with numba's loops, as ``--linux-floor`` builds by default, where SLEWING_TEST_NUMBA_FMU=1
    (tests/linux_floor/run_all.sh sets it: numba's loops compiled for three CPUs take minutes), else with
    numpy's; FMI 3.0 with numpy's loops. No win64 half (it is the same as the default build's)."""
    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu
    from slewing_model.numerics import compiled

    folder = tmp_path_factory.mktemp("floor")
    bearing = ROOT / "examples" / "bearings" / "table3_errors.toml"
    return {2: build_fmu(bearing, folder / "floor2.fmu", mesh="coarse", numba=compiled.AVAILABLE and NUMBA_FMU_OPT_IN,
                         win64=False,
                         **floor_dir),
            3: build_fmu(bearing, folder / "floor3.fmu", mesh="coarse", fmi_version=3, numba=False, win64=False,
                         runtime_python=floor_dir["runtime_python"])}


@pytest.mark.parametrize("version", [2, 3])
def test_the_floor_is_glibc_2_28_and_gcc_6s_libstdcxx_and_is_what_readelf_reads(version, floor_fmus, tmp_path):
    stated = runtime_of(floor_fmus[version])
    assert _version(stated["glibc"]) <= _version(FLOOR), stated
    assert _version(stated["glibcxx"] or "0") <= _version(GLIBCXX_FLOOR), stated
    assert stated["version"].startswith(f"{sys.version_info[0]}.{sys.version_info[1]}.")
    if shutil.which("readelf"):
        with zipfile.ZipFile(floor_fmus[version]) as z:
            z.extractall(tmp_path)
        assert stated["glibc"] == _readelf_glibc_needs(tmp_path / "binaries")
    assert _version(glibc_of(bare_system(SYSTEM))) >= _version(FLOOR)       # Debian 11: 2.31


@pytest.fixture(scope="module")
def fmusim_bullseye(floor_dir):
    binary = FLOOR_DIR / "fmusim-0.0.39-bullseye"
    if not binary.exists():
        pytest.skip(f"SKIPPED: fmusim for Debian 11 is not built in {FLOOR_DIR} (tests/linux_floor/build.sh)")
    return binary


@pytest.mark.parametrize("version", [2, 3])
def test_fmusim_runs_the_floor_lowered_fmu_in_debian_11_every_time(version, floor_fmus, fmusim_bullseye):
    assert_fmusim_runs_as_fmpy(bare_system(SYSTEM), fmusim_bullseye, floor_fmus[version], FMUSIM_RUNS, rel=RTOL)


@pytest.mark.parametrize("version", [2, 3])
def test_our_c_host_runs_the_floor_lowered_fmu_in_debian_11_as_fmpy_does(version, hosts, floor_fmus):
    system = bare_system(SYSTEM)
    fmu = floor_fmus[version]
    reference = fmpy_steps(fmu, version, 8)
    for _ in range(HOST_RUNS):  # load, step, roll back, free, unload, reload, exit
        code, values, _, logs, output = run_host(system, hosts[version], fmu, version, "basic", folder=f"floor{version}")
        assert code == 0 and output.rstrip().endswith("done"), output[-3000:]
        for label, steps in (("run", range(6)), ("replay", range(3, 6)), ("deserialized", range(3, 6)),
                             ("reload", range(6))):
            for k in steps:
                assert values[label][k] == pytest.approx(reference[k], rel=RTOL, abs=1e-300), (label, k)
    if "numba==" in runtime_of(fmu)["packages"]:   # numba's loops load (or compile) in Debian 11 too
        assert any("loops compiled by numba" in line for line in logs), logs
    code, values, statuses, logs, output = run_host(system, hosts[version], fmu, version, "nan",
                                                    folder=f"floor{version}")
    assert code == 0, output[-3000:]
    assert any("input Fz = nan: must be finite" in line for line in logs), logs
    assert values["after_refusal"][3] == pytest.approx(reference[2], rel=RTOL, abs=1e-300)


def test_below_the_floor_the_fmu_still_says_which_glibc_it_needs(hosts, floor_fmus, tmp_path):
    # no system older than Debian 11 is at hand (buster, glibc 2.28, has left deb.debian.org; stretch too): the
    # floor-lowered FMU with its stated floor raised one above Debian 11's glibc must be refused there with the message
    system = bare_system(SYSTEM)
    have = glibc_of(system)
    fmu, floor = above(floor_fmus[2], have, tmp_path)
    assert floor == "2.32"
    code, _, _, logs, output = run_host(system, hosts[2], fmu, 2, "basic", folder="floor_above")
    assert code == 1 and "error fmi2Instantiate" in output, output[-3000:]
    # the libstdc++ named is the FMU's stated one: GCC 6's with numba's llvmlite, GCC 5's with numpy's loops
    gcc = {"3.4.22": 6, "3.4.21": 5}[runtime_of(floor_fmus[2])["glibcxx"]]
    assert any("this FMU needs glibc 2.32 or newer (Linux x86-64, for example RHEL 9, Ubuntu 22.04, Debian 12 or "
               f"newer, with libstdc++ of GCC {gcc} or newer, as they have); this machine has glibc 2.31" in line
               for line in logs), logs


def test_the_floor_lowered_fmu_gives_the_default_builds_numbers(floor_fmus, table3_fmu3):
    # CPython 3.11.2 built in Debian 11, libm's exp/log/pow of glibc 2.2.5's version: the same numbers as the
    # default build (this machine's Python) to 1e-9, both FMI 3.0 with numpy's loops, driven by fmpy here
    floor, default = fmpy_steps(floor_fmus[3], 3, 8), fmpy_steps(table3_fmu3, 3, 8)
    assert floor == pytest.approx(default, rel=RTOL, abs=1e-300)
