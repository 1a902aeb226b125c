import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
BEARINGS = ROOT / "examples" / "bearings"


@pytest.fixture(scope="session")
def table1():
    from slewing_model import load_bearing

    return load_bearing(BEARINGS / "table1.toml")


@pytest.fixture(scope="session")
def table3():
    from slewing_model import load_bearing

    return load_bearing(BEARINGS / "table3.toml")


@pytest.fixture
def double_operator(monkeypatch):
    """New reduced operators inverted in double precision (``reduced_operator.OPERATOR_PRECISION``), for
    tests of the operator's algebra (bordering, turning, the step) to round-off; single precision's
    own accuracy is tested by itself (test_flexible_solver.py)."""
    import numpy as np

    from slewing_model.rings import reduced_operator

    monkeypatch.setattr(reduced_operator, "OPERATOR_PRECISION", np.float64)


@pytest.fixture
def rigid_loop_calls(monkeypatch):
    """The calls of the rigid model's compiled loop (``distribution.kernel._rigid_solve``), counted: a
    list that gains an entry each time a solver runs it."""
    from slewing_model.distribution import bime

    calls = []
    loop = bime.compiled_rigid_solve()
    monkeypatch.setattr(bime, "compiled_rigid_solve", lambda: lambda *args: calls.append(1) or loop(*args))
    return calls


# a session's folders take about 3.5 GB at their largest (built FMUs, unzipped ones, wine runs)
DISK_NEEDED = 5e9
FREE_AT_START = pytest.StashKey[tuple]()


def pytest_sessionstart(session):
    # a full disk fails tests at random places with OSError (as it did on a CI machine): say so first
    folder = tempfile.gettempdir()
    free = shutil.disk_usage(folder).free
    session.config.stash[FREE_AT_START] = folder, free
    if free < DISK_NEEDED:
        pytest.exit(f"{free / 1e9:.1f} GB free in the temporary directory {folder}: the tests need "
                    f"{DISK_NEEDED / 1e9:.0f} GB (built and unzipped FMUs, wine runs); free some space first",
                    returncode=3)


def pytest_terminal_summary(terminalreporter, config):
    # shown even with -q: the first thing to look at when tests fail with OSError
    if FREE_AT_START in config.stash:
        folder, free = config.stash[FREE_AT_START]
        terminalreporter.write_line(f"disk: {free / 1e9:.1f} GB free in {folder} at the start, "
                                    f"{shutil.disk_usage(folder).free / 1e9:.1f} GB at the end")


# left in the temporary directory by design, not by a leak: distributed's scratch root (its lock files)
KEPT_IN_TMPDIR = {"dask-scratch-space"}


@pytest.fixture(autouse=True, scope="session")
def _private_tmpdir(tmp_path_factory):
    """The temporary directory of the tests and of every process they start is a folder of this
    session's, removed with the session's other folders when it passes. Whatever is left in it at
    the end is a leak, and fails the session: an unzipped FMU is 130-330 MB, and such leaks, run
    after run, once filled a CI machine's disk."""
    folder = tmp_path_factory.mktemp("tmpdir", numbered=False)
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("TMPDIR", str(folder))
        patch.setattr(tempfile, "tempdir", str(folder))
        yield folder
    left = sorted(path.name for path in folder.iterdir() if path.name not in KEPT_IN_TMPDIR)
    assert not left, (f"the tests left {left} in their temporary directory {folder}: "
                      "a test must remove what it unzips or writes there (or write it in its tmp_path)")


@pytest.fixture(autouse=True, scope="session")
def _cache_dir(tmp_path_factory):
    # superelements built by the tests go to a private cache, not the user's; the loops compiled ahead of time
    # are taken from the user's (keyed by their sources, numba and the Python ABI), which `make test` fills
    # first (the Makefile's COMPILE_LOOPS and COMPILE_LOOPS_AOT), so that the test workers do not each compile them (a minute a target)
    import sys

    sys.path.insert(0, str(ROOT))
    from fmu_build.aot import CACHE_VARIABLE, aot_cache_dir

    os.environ.setdefault(CACHE_VARIABLE, str(aot_cache_dir()))
    # one cache for the session's workers (pytest-xdist), so that a superelement one built the other loads
    # (a save writes a file of its own process, then renames it: two workers saving one path do not collide)
    base = tmp_path_factory.getbasetemp()
    shared = base.parent / "cache" if os.environ.get("PYTEST_XDIST_WORKER") else base / "cache"
    shared.mkdir(exist_ok=True)
    os.environ.setdefault("SLEWING_CACHE_DIR", str(shared))
    # the win64 half's loops (about 2.5 minutes under wine, once per version of the loops) are taken from that
    # cache only: where they are not there the FMUs' win64 halves run numpy's loops and the test of the win64
    # module is skipped, saying how to compile them (SLEWING_BUILD_WIN64_AOT=1 compiles them in the tests)
    if os.environ.get("SLEWING_BUILD_WIN64_AOT") != "1":
        os.environ.setdefault("SLEWING_WIN64_AOT_CACHED_ONLY", "1")


def _build_table3(tmp_path_factory, name, **options):
    """The FMU ``name`` of table3_errors.toml, built once a session: under pytest-xdist the workers share
    it (the first to ask builds it, in its own folder, then moves it into the session's ``shared_fmus``
    folder; another asking meanwhile waits for it), instead of each worker building its own (half a
    minute of CPU each)."""
    import fcntl
    import sys

    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu

    def build():
        path = tmp_path_factory.mktemp("fmu") / name
        return build_fmu(BEARINGS / "table3_errors.toml", path, mesh="coarse", bc="free", **options)

    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return build()
    shared = tmp_path_factory.getbasetemp().parent / "shared_fmus"     # the session's, beside the workers'
    shared.mkdir(exist_ok=True)
    with open(shared / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (shared / name).exists():               # a failed build leaves nothing: the next worker tries
            os.replace(build(), shared / name)
    return shared / name


@pytest.fixture(scope="session")
def table3_fmu(tmp_path_factory):
    """The bearing FMU of table3 with synthetic errors (coarse superelement, free rings), built once:
    FMI 2.0, standalone (it carries its Python runtime), with numpy's loops (``--no-numba``; the default
    build, with the loops compiled ahead of time, is :func:`table3_aot_fmu`)."""
    return _build_table3(tmp_path_factory, "SlewingBearing_table3.fmu", numba=False)


@pytest.fixture(scope="session")
def table3_fmu3(tmp_path_factory):
    """The FMI 3.0 FMU of table3_fmu's bearing, standalone, numpy's loops."""
    return _build_table3(tmp_path_factory, "SlewingBearing3_table3.fmu", fmi_version=3, numba=False)


#: the platform tests in full (every FMU under every Windows host, the SSP under wine): tests/win64/run_all.sh sets
#: SLEWING_TEST_PLATFORMS_FULL=1; `make test` runs each host on one or two FMUs, so that every platform is
#: covered within the CI's 20 minutes
PLATFORMS_FULL = os.environ.get("SLEWING_TEST_PLATFORMS_FULL") == "1"


def platform_cases(cases, make_test):
    """``cases`` in full with SLEWING_TEST_PLATFORMS_FULL=1, else those in ``make_test``."""
    return list(cases) if PLATFORMS_FULL else [case for case in cases if case in make_test]


#: the FMUs with numba's loops are tested (opt-in: they compile numba's loops for three CPUs)
NUMBA_FMU_OPT_IN = os.environ.get("SLEWING_TEST_NUMBA_FMU") == "1"


def needs_numba_fmu_opt_in():
    """Skip unless SLEWING_TEST_NUMBA_FMU=1 (:data:`NUMBA_FMU_OPT_IN`)."""
    if not NUMBA_FMU_OPT_IN:
        pytest.skip("SKIPPED: the --numba FMU's tests are opt-in (numba's loops compiled for three CPUs, about 3 "
                    "minutes): set SLEWING_TEST_NUMBA_FMU=1")


def _needs_numba():
    from slewing_model.numerics import compiled

    if not compiled._numba_installed():
        pytest.skip("numba is not installed here")


@pytest.fixture(scope="session")
def table3_numba_fmu(tmp_path_factory):
    """table3_fmu's bearing built with ``--numba``: standalone, with numba, llvmlite and numba's cache of
    the compiled loops (for this CPU, an x86-64-v3 one and a generic x86-64). Opt-in (SLEWING_TEST_NUMBA_FMU=1):
    compiling numba's loops for the two other CPUs takes about 3 minutes of the CI's 20, for a build that
    is no longer the default."""
    _needs_numba()
    needs_numba_fmu_opt_in()
    return _build_table3(tmp_path_factory, "SlewingBearing_table3_numba.fmu", numba=True)


@pytest.fixture(scope="session")
def table3_aot_fmu(tmp_path_factory):
    """table3_fmu's bearing as build_fmu.py builds it by default where numba is installed (``--aot``):
    standalone, with the loops compiled ahead of time (fmu_build/aot.py) and no numba."""
    _needs_numba()
    return _build_table3(tmp_path_factory, "SlewingBearing_table3_aot.fmu", aot=True)


@pytest.fixture(scope="session")
def table3_host_fmu(tmp_path_factory):
    """The light "tool coupling" FMU of table3_fmu's bearing (``--runtime host``): it runs in this
    machine's Python, or one named by SLEWING_FMU_PYTHONHOME; with the loops compiled ahead of time where
    numba is installed here, as by default."""
    return _build_table3(tmp_path_factory, "SlewingBearing_table3_host.fmu", runtime="host")


def benchmark_case(name: str, steps: int):
    """A benchmark case (``benchmarks/cases.py``) of ``steps`` steps, its bearing and the bearing's
    coarse superelement (free rings)."""
    import sys

    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from benchmarks.cases import CASES
    from slewing_model import load_bearing
    from slewing_model.rings.superelement import build_superelement

    case = CASES[name](steps)
    bearing = load_bearing(case.bearing)
    return case, bearing, build_superelement(bearing, mesh="coarse", bc="free")


def simulators_per_kernel(name: str, steps: int, setting: str):
    """A benchmark case (:func:`benchmark_case`) and two simulators of it that differ only in the
    kernel ``setting`` (``"friction_kernel"`` or ``"contact_kernel"``): ``{"numpy": ..., "compiled": ...}``."""
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    case, bearing, superelement = benchmark_case(name, steps)
    frame = "rotating" if case.parameters["load_frame"] == 2 else "fixed"
    return case, {k: BearingSimulator(bearing, superelement, SimulatorSettings(
        ring_model="flexible", load_frame=frame, **{setting: k})) for k in ("numpy", "compiled")}


def through_json(value):
    """A state (or part of one) serialised as a master's FMU state is: through :func:`encode_state`, JSON
    text and :func:`decode_state` (what is kept in memory only, the held answer, is left out)."""
    import json

    from slewing_model.simulation.simulator import decode_state, encode_state

    return decode_state(json.loads(json.dumps(encode_state(value))))


def symmetric_block_circulant(balls: int, seed: int = 0) -> np.ndarray:
    """A random symmetric block-circulant matrix (4 balls x 4 balls) as the rings' compliance is:
    block (b, c) = C_(c-b mod B), C_(-k) = C_k^T."""
    rng = np.random.default_rng(seed)
    blocks = rng.standard_normal((balls, 4, 4))
    blocks = 0.5 * (blocks + blocks[(-np.arange(balls)) % balls].transpose(0, 2, 1))
    k = (np.arange(balls)[None, :] - np.arange(balls)[:, None]) % balls
    return blocks[k].transpose(0, 2, 1, 3).reshape(4 * balls, 4 * balls)


def has_x86_64_v3() -> bool:
    """Whether this CPU has the x86-64 psABI's level 3, read from the kernel's /proc/cpuinfo flags (not
    from LLVM, which the FMU asks): AVX, AVX2, BMI1/2, F16C, FMA, LZCNT (abm), MOVBE, XSAVE and level 2's."""
    flags = set()
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("flags"):
            flags = set(line.split(":", 1)[1].split())
            break
    return {"avx", "avx2", "bmi1", "bmi2", "f16c", "fma", "abm", "movbe", "xsave", "cx16", "lahf_lm", "popcnt",
            "pni", "sse4_1", "sse4_2", "ssse3"} <= flags
