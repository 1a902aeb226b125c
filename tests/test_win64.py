"""The standalone FMUs' Windows (win64) binary, under wine: no Windows machine, no Python on the "Windows" side
but the FMU's own (fmu_build/win64.py).

Each FMU (the FMI 2.0 and 3.0 bearing FMUs and the drive FMU) runs in
(a) our C host (tests/c_host/host.c) cross-compiled with mingw-w64: steps, state get/set/serialize,
    free, FreeLibrary and reload;
(b) fmpy 0.3.32 on the official embeddable CPython 3.11.9 (a Python host: the FMU uses its interpreter);
(c) fmusim v0.0.39 cross-compiled with mingw-w64 (tests/win64/build_fmusim.sh, which `make test` runs once as root:
    tests/platform_builds.py);
``SLEWING_WINE_RUNS`` times each (1 in ``make test``, 5 in ``tests/win64/run_all.sh``); every run exits 0 and gives
fmpy's outputs on Linux within 1e-9 relative. ``make test`` runs every FMU in (a), the FMI 3.0 bearing in (b), the FMI
2.0 bearing in (c) and the drive beside a bearing in one process; ``tests/win64/run_all.sh``
(``SLEWING_TEST_PLATFORMS_FULL=1``) runs every FMU in every host, the SSP's four FMUs together and, with
``SLEWING_TEST_NUMBA_FMU=1``, the ``--win64-numba`` FMU. These FMUs run numpy's loops (``--no-numba``); the default build's
(``--aot``) win64 half runs the loops compiled ahead of time for Windows, in our C host too. The runtime carries
what the FMU imports (the import audit's lists in fmu_build/win64.py): these runs show that nothing is missing.

The tolerance: the Windows half runs another numpy (1.26.4 with its OpenBLAS, against 2.x on Linux) and
another C library's libm (wine's ucrtbase against glibc), so the last bits of the solver's
floating-point results may differ; both Newton solvers converge to 1e-12 or better. 1e-9 is what the
Linux tests allow between machine codes (numba's generic loops). The Newton step rounds its right side to
single precision for the kept inverse's product (``reduced_operator.single_product``), so a round-off
difference can change one such rounding and the two halves' equilibria differ within the solver's
tolerance: measured 2.6e-10 (the friction torque in the C host's six steps; z 1e-11, the others below
6e-11). ``SLEWING_WIN64_REL`` sets another tolerance, to measure the margin.

Wine (Debian's wine 8) and mingw-w64 are installed by ``make`` as root; the prefix and the Windows Python
are kept in ``$SLEWING_WINE_DIR`` (default /var/cache/slewing-wine). Without root or without them the
tests are skipped, saying why.
"""
import os
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import win64_tools as w  # noqa: E402
from conftest import has_x86_64_v3, needs_numba_fmu_opt_in, platform_cases, PLATFORMS_FULL  # noqa: E402
from host_output import parse_host_output  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RUNS = int(os.environ.get("SLEWING_WINE_RUNS", "1"))
STEPS = 6
FMPY_STEPS = ROOT / "tests" / "win64" / "fmpy_steps.py"
BEARING_INPUTS = ["Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"]
BEARING_OUTPUTS = ["z", "rx", "friction_torque", "max_ball_load", "static_safety_factor"]
#: the drive has three inputs: the C host's seven values assigned in order, the later one winning (load_moment
#: -2.5e3 N.m, friction_torque 3e4 + 1e3 k N.m, command 0.05 rad)
DRIVE_INPUTS = ["load_moment", "load_moment", "friction_torque", "load_moment", "load_moment", "command", "command"]
DRIVE_OUTPUTS = ["psi", "omega", "motor_torque", "ring_torque"]
#: case: (FMI version, model identifier, inputs, outputs)
CASES = {"bearing2": (2, "SlewingBearing", BEARING_INPUTS, BEARING_OUTPUTS),
         "bearing3": (3, "SlewingBearing3", BEARING_INPUTS, BEARING_OUTPUTS),
         "drive": (2, "SlewingDrive", DRIVE_INPUTS, DRIVE_OUTPUTS)}
REL = float(os.environ.get("SLEWING_WIN64_REL", "1e-9"))

pytestmark = [
    pytest.mark.skipif(os.geteuid() != 0, reason="SKIPPED, not root: the win64 tests need wine and mingw-w64, "
                       "which `make` installs as root, and keep wine's prefix in /var/cache (CI runs as root)"),
    pytest.mark.skipif(bool(w.missing_tools()), reason=f"SKIPPED: {w.missing_tools()}"),
]


@pytest.fixture(scope="module")
def drive_fmu(tmp_path_factory):
    sys.path.insert(0, str(ROOT))
    from fmu_build.drive import build_drive_fmu

    return build_drive_fmu(ROOT / "examples" / "drives" / "pitch_drive.toml",
                           tmp_path_factory.mktemp("drive") / "SlewingDrive_pitch.fmu")


@pytest.fixture(scope="module")
def fmus(table3_fmu, table3_fmu3, drive_fmu):
    return {"bearing2": table3_fmu, "bearing3": table3_fmu3, "drive": drive_fmu}


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    return w.c_hosts(tmp_path_factory.mktemp("win_hosts"))


def parse_steps(text: str) -> np.ndarray:
    return np.array([[float(v) for v in line.split()[2:]] for line in text.splitlines() if line.startswith("step ")])


_references = {}


def reference(case, fmu) -> np.ndarray:
    """Outputs of the first STEPS steps of ``fmu``, fmpy on Linux (this machine's Python); once per FMU."""
    if (case, str(fmu)) not in _references:
        _, _, inputs, outputs = CASES[case]
        run = subprocess.run([sys.executable, str(FMPY_STEPS), str(fmu), str(STEPS), ",".join(inputs),
                              ",".join(outputs)], capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr[-3000:]
        _references[case, str(fmu)] = parse_steps(run.stdout)
    return _references[case, str(fmu)]


def refs_of(fmu):
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    token = md.guid if md.fmiVersion.startswith("2") else md.instantiationToken
    return token, {v.name: v.valueReference for v in md.modelVariables}


def run_c_host(host, fmu, case, folder, scenario="basic"):
    version, identifier, inputs, outputs = CASES[case]
    token, refs = refs_of(fmu)
    vrs = [str(refs[n]) for n in inputs + outputs]
    return w.wine(host, w.windows_path(folder), identifier, token, scenario, *vrs, timeout=600)


def test_the_fmus_carry_a_standalone_win64_binary(fmus):
    for case, fmu in fmus.items():
        version, identifier, _, _ = CASES[case]
        folder = "binaries/win64" if version == 2 else "binaries/x86_64-windows"
        with zipfile.ZipFile(fmu) as z:
            names = set(z.namelist())
            described = z.read("resources/python_runtime.txt").decode()
        for name in (f"{identifier}.dll", "pythonfmu-export.dll", "python/python311.dll", "python/python3.dll",
                     "python/python311.zip", "python/vcruntime140.dll", "python/vcruntime140_1.dll",
                     "python/msvcp140.dll", "python/Lib/site-packages/numpy/__init__.py"):
            assert f"{folder}/{name}" in names, (case, name)
        assert f"{folder}/python/python311._pth" not in names          # the layer sets the search path
        assert "win64_version=3.11.9" in described and "win64_packages=numpy==1.26.4" in described


def test_our_layer_needs_only_kernel32_and_msvcrt(fmus, tmp_path):
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    if objdump is None:
        pytest.skip("binutils-mingw-w64-x86-64 is not installed")
    for case, fmu in fmus.items():
        version, identifier, _, _ = CASES[case]
        folder = "binaries/win64" if version == 2 else "binaries/x86_64-windows"
        with zipfile.ZipFile(fmu) as z:
            (tmp_path / "layer.dll").write_bytes(z.read(f"{folder}/{identifier}.dll"))
        imports = subprocess.run([objdump, "-p", str(tmp_path / "layer.dll")], capture_output=True, text=True).stdout
        assert sorted(line.split()[-1] for line in imports.splitlines() if "DLL Name" in line) == \
            ["KERNEL32.dll", "msvcrt.dll"], case


@pytest.mark.parametrize("case", list(CASES))
def test_our_c_host_built_with_mingw_runs_the_win64_binary_under_wine(case, fmus, hosts, tmp_path):
    version = CASES[case][0]
    fmu = fmus[case]
    expected = reference(case, fmu)
    folder = w.unpack(fmu, tmp_path / "fmu")
    for run_index in range(RUNS):  # load, step, roll back, deserialize, free, FreeLibrary, reload, exit
        run = run_c_host(hosts[version], fmu, case, folder)
        assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), \
            f"run {run_index}: exit {run.returncode}\n{run.stdout[-3000:]}{run.stderr[-3000:]}"
        values, _, _, _ = parse_host_output(run.stdout)
        for k in range(STEPS):
            assert values["run"][k] == pytest.approx(expected[k], rel=REL, abs=1e-300), (run_index, k)
            assert values["reload"][k] == values["run"][k]            # a reloaded binary starts afresh
        for k in range(3, STEPS):
            assert values["replay"][k] == values["run"][k]            # the state set back repeats the steps
            assert values["deserialized"][k] == values["run"][k]


@pytest.mark.parametrize("case", platform_cases(CASES, make_test=["bearing3"]))
def test_fmpy_on_the_embeddable_windows_python_runs_the_win64_binary_under_wine(case, fmus):
    python = w.windows_python()
    _, _, inputs, outputs = CASES[case]
    expected = reference(case, fmus[case])
    for run_index in range(RUNS):
        run = w.wine(python, w.windows_path(FMPY_STEPS), w.windows_path(fmus[case]), STEPS, ",".join(inputs),
                     ",".join(outputs))
        assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), \
            f"run {run_index}: exit {run.returncode}\n{run.stdout[-3000:]}{run.stderr[-3000:]}"
        got = parse_steps(run.stdout)
        assert got.shape == expected.shape
        for k in range(STEPS):
            assert got[k] == pytest.approx(expected[k], rel=REL, abs=1e-300), (run_index, k)


@pytest.fixture(scope="module")
def numba_fmu(tmp_path_factory):
    """table3_fmu's bearing (with its ring errors) built with ``--win64-numba``: both halves with numba's
    loops (the Windows ones compiled under wine at build time, kept beside the tests' wine prefix once per
    version of the loops). That compilation takes about five minutes under wine (two CPUs): until it is
    kept, the test is skipped, saying so (run tests/win64/run_all.sh, or set SLEWING_BUILD_WIN64_NUMBA=1)."""
    needs_numba_fmu_opt_in()
    sys.path.insert(0, str(ROOT))
    import fmu_build.win64
    from build_fmu import build_fmu

    kept = {"SLEWING_WIN64_BUILD_DIR": str(w.WINE_DIR / "build"), "WINEPREFIX": str(w.PREFIX)}
    with pytest.MonkeyPatch.context() as patch:
        for name, value in kept.items():
            patch.setenv(name, value)
        # the package folder named without compiling numba's loops for three CPUs (build_fmu.compiled_kernel_files):
        # the skip is decided before any compilation
        if not (fmu_build.win64.kernels_folder(ROOT / "slewing_model") / "slewing_model").exists() \
                and not os.environ.get("SLEWING_BUILD_WIN64_NUMBA"):
            pytest.skip(f"SKIPPED: the loops for --win64-numba are not compiled under wine yet (about 5 minutes, kept "
                        f"in {kept['SLEWING_WIN64_BUILD_DIR']}): run tests/win64/run_all.sh, or set "
                        "SLEWING_BUILD_WIN64_NUMBA=1")
        return build_fmu(ROOT / "examples" / "bearings" / "table3_errors.toml",
                         tmp_path_factory.mktemp("numba") / "t3.fmu", mesh="coarse", numba=True, win64_numba=True)


def test_a_win64_half_with_numba_runs_the_compiled_loops_from_its_cache_under_wine(numba_fmu, hosts, tmp_path):
    """``--win64-numba``: our C host under wine loads the FMU, whose log says the loops are compiled by
    numba (for an x86-64-v3 CPU where this one has its features, else a generic x86-64 one, from the FMU's
    numba cache: an instantiation that compiled them would
    take minutes under wine), and its outputs are the Linux half's (fmpy on Linux) within REL. The
    second run of an unpacked copy is timed too: numba writes nothing it lacked."""
    expected = reference("bearing2", numba_fmu)
    folder = w.unpack(numba_fmu, tmp_path / "fmu")
    with zipfile.ZipFile(numba_fmu) as z:
        names = z.namelist()
    assert any(n.startswith("binaries/win64/python/Lib/site-packages/numba/") for n in names)
    assert any(n.endswith("llvmlite.dll") for n in names)
    for run_index in range(2):
        start = time.perf_counter()
        run = run_c_host(hosts[2], numba_fmu, "bearing2", folder)
        seconds = time.perf_counter() - start
        assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), \
            f"run {run_index}: exit {run.returncode}\n{run.stdout[-3000:]}{run.stderr[-3000:]}"
        values, _, logs, _ = parse_host_output(run.stdout)
        cpu = "an x86-64-v3 CPU" if has_x86_64_v3() else "a generic x86-64 CPU"
        assert any(f"loops compiled by numba for {cpu} (Windows)" in m for _, _, m in logs), logs
        assert seconds < 90, f"run {run_index}: {seconds:.0f} s (numba compiled the loops at instantiation?)"
        for k in range(STEPS):
            assert values["run"][k] == pytest.approx(expected[k], rel=REL, abs=1e-300), (run_index, k)


def test_the_win64_half_runs_the_loops_compiled_ahead_of_time(table3_aot_fmu, hosts, tmp_path):
    """``--aot`` (build_fmu.py's default): the win64 half carries the loops compiled ahead of time for Windows
    (fmu_build.win64.aot_module: numba's pycc under wine, mingw-w64's link), a module that needs KERNEL32,
    msvcrt and python311.dll only; our C host under wine runs them (the FMU's log says so) and its outputs
    are the Linux half's (fmpy on Linux) within REL, a reloaded binary's and the replayed states' exactly."""
    import fmu_build.win64

    module = f"binaries/win64/python/Lib/site-packages/slewing_kernels{fmu_build.win64.AOT_SUFFIX}"
    with zipfile.ZipFile(table3_aot_fmu) as z:
        if module not in z.namelist() and os.environ.get(fmu_build.win64.AOT_CACHED_ONLY) == "1":
            pytest.skip("SKIPPED: the win64 loops are not compiled yet (about 2.5 minutes under wine, once per "
                        "version of the loops, kept in the aot cache; make test compiles them as root): run "
                        "tests/platform_builds.py, or set SLEWING_BUILD_WIN64_AOT=1")
        assert module in z.namelist()
        (tmp_path / "module.pyd").write_bytes(z.read(module))
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    if objdump:
        imports = subprocess.run([objdump, "-p", str(tmp_path / "module.pyd")], capture_output=True, text=True).stdout
        assert sorted(line.split()[-1] for line in imports.splitlines() if "DLL Name" in line) == \
            ["KERNEL32.dll", "msvcrt.dll", "python311.dll"]
    expected = reference("bearing2", table3_aot_fmu)
    folder = w.unpack(table3_aot_fmu, tmp_path / "fmu")
    run = run_c_host(hosts[2], table3_aot_fmu, "bearing2", folder)
    assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), run.stdout[-3000:] + run.stderr[-3000:]
    values, _, logs, _ = parse_host_output(run.stdout)
    assert any("loops compiled ahead of time" in m for _, _, m in logs), logs
    for k in range(STEPS):
        assert values["run"][k] == pytest.approx(expected[k], rel=REL, abs=1e-300), k
        assert values["reload"][k] == values["run"][k]
    for k in range(3, STEPS):
        assert values["replay"][k] == values["run"][k]
        assert values["deserialized"][k] == values["run"][k]


def test_the_win64_runtime_carries_what_the_fmu_imports(fmus):
    """The import audit's lists (fmu_build/win64.py): the standard library's kept modules are there and the
    others are not, nor numpy's f2py, testing and test modules; the runs above show that nothing the FMU
    imports is missing."""
    import io

    import fmu_build.win64

    with zipfile.ZipFile(fmus["bearing2"]) as z:
        names = set(z.namelist())
        stdlib = zipfile.ZipFile(io.BytesIO(z.read("binaries/win64/python/python311.zip")))
    tops = {n.split("/")[0].removesuffix(".pyc") for n in stdlib.namelist()}
    assert tops <= fmu_build.win64.STDLIB_KEPT and {"encodings", "json", "pickle", "traceback", "ctypes"} <= tops
    assert not tops & {"asyncio", "email", "unittest", "multiprocessing", "lib2to3", "pydoc_data"}
    site = "binaries/win64/python/Lib/site-packages/numpy/"
    assert f"{site}core/_multiarray_umath.cp311-win_amd64.pyd" in names
    assert not any(n.startswith((f"{site}f2py/", f"{site}testing/", f"{site}core/_simd.")) for n in names)
    assert not any(n.endswith(".pyi") or "/tests/" in n for n in names if n.startswith("binaries/win64/"))
    assert "binaries/win64/python/_ctypes.pyd" in names and "binaries/win64/python/_asyncio.pyd" not in names


BLAS_THREADS = r"""
import importlib.util, sys
spec = importlib.util.spec_from_file_location("blas", sys.argv[1])
blas = importlib.util.module_from_spec(spec)
spec.loader.exec_module(blas)
get, set_ = blas._openblas_threads()
set_(2)
with blas.blas_threads(1):
    inside = get()
print("threads", inside, get(), [p.rsplit(chr(92), 1)[-1] for p in blas._openblas_paths()])
"""


def test_the_blas_threads_of_a_step_are_set_on_windows_too():
    """numpy 1.26's OpenBLAS on the embeddable Windows Python (the win64 FMU's) is found beside numpy's
    package, so a step's BLAS work (numpy's loops: the win64 half's) runs on the settings' one thread and
    the host's count comes back after it, as on Linux (tests/test_blas.py)."""
    run = w.wine(w.windows_python(), "-c", BLAS_THREADS, w.windows_path(ROOT / "slewing_model" / "numerics" / "blas.py"))
    assert run.returncode == 0, run.stdout + run.stderr
    word, inside, after, paths = run.stdout.strip().splitlines()[-1].split(" ", 3)
    assert (word, inside, after) == ("threads", "1", "2"), run.stdout
    assert "openblas" in paths.lower() and ".dll" in paths.lower(), paths


def test_a_missing_python_library_is_reported_through_the_hosts_logger(fmus, hosts, tmp_path):
    folder = w.unpack(fmus["bearing2"], tmp_path / "broken")
    (folder / "binaries" / "win64" / "python" / "python311.dll").unlink()
    run = run_c_host(hosts[2], fmus["bearing2"], "bearing2", folder)
    _, _, logs, _ = parse_host_output(run.stdout)
    assert run.returncode == 1 and "error fmi2Instantiate" in run.stdout, run.stdout + run.stderr  # refused, no crash
    assert any("the FMU's Python runtime is incomplete" in m and "python311.dll is missing" in m
               for _, _, m in logs), run.stdout


def test_the_win64_half_ignores_the_hosts_python_variables(fmus, hosts, tmp_path):
    # an isolated start: PYTHONHOME and PYTHONPATH of the host pointing to nonsense change nothing
    folder = w.unpack(fmus["bearing2"], tmp_path / "isolated")
    token, refs = refs_of(fmus["bearing2"])
    vrs = [str(refs[n]) for n in BEARING_INPUTS + BEARING_OUTPUTS]
    run = w.wine(hosts[2], w.windows_path(folder), "SlewingBearing", token, "basic", *vrs,
                 env={"PYTHONHOME": "C:\\nowhere", "PYTHONPATH": "C:\\nowhere", "WINEPATH": "C:\\nowhere"})
    assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), run.stdout[-3000:] + run.stderr[-3000:]


def test_without_wines_own_cpp_runtime_the_fmu_brings_its_own(fmus, hosts, tmp_path):
    # wine's builtin msvcp140/vcruntime140 blocked: only the FMU's copies can serve (a Windows machine
    # without the Visual C++ Redistributable)
    folder = w.unpack(fmus["bearing3"], tmp_path / "no_vc")
    token, refs = refs_of(fmus["bearing3"])
    vrs = [str(refs[n]) for n in BEARING_INPUTS + BEARING_OUTPUTS]
    run = w.wine(hosts[3], w.windows_path(folder), "SlewingBearing3", token, "basic", *vrs,
                 env={"WINEDLLOVERRIDES": "mscoree,mshtml=;msvcp140,vcruntime140,vcruntime140_1=n"})
    assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), run.stdout[-3000:] + run.stderr[-3000:]


# ---- fmusim cross-compiled with mingw (tests/win64/build_fmusim.sh) -----------------------------------------
#: inputs per case for fmusim's CSV, one column each: the values the C host's order leaves (see DRIVE_INPUTS)
FMUSIM_INPUTS = {"bearing2": BEARING_INPUTS, "bearing3": BEARING_INPUTS, "drive": ["command", "friction_torque",
                                                                                    "load_moment"]}


def fmusim_inputs(case, k):
    u = [8e3, -3e3, 3e4 + 1e3 * k, 1.5e3, -2.5e3, 0.4 + 0.01 * k, 0.05]
    return u if case != "drive" else [u[6], u[2], u[4]]


@pytest.fixture(scope="module")
def fmusim():
    """fmusim.exe, built once per version of the build script and kept in $SLEWING_WINE_DIR (about 5 minutes the
    first time: libxml2, sundials and minizip for mingw from Debian's sources). `make test` builds it before
    the tests (tests/platform_builds.py); here it is built only with SLEWING_BUILD_FMUSIM=1."""
    if not (ROOT.parent / "shared" / "vendor" / "fmusim-v0.0.39" / "build.sh").exists() \
            and not os.environ.get("SLEWING_FMUSIM_SOURCE"):
        pytest.skip("fmusim's source is not at ../shared/vendor/fmusim-v0.0.39")
    if not w.fmusim_binary().exists() and not os.environ.get("SLEWING_BUILD_FMUSIM"):
        pytest.skip("SKIPPED: fmusim for mingw is not built yet (about 5 minutes): run tests/platform_builds.py "
                    "or tests/win64/run_all.sh, or set SLEWING_BUILD_FMUSIM=1")
    return w.build_fmusim()


@pytest.mark.parametrize("case", platform_cases(CASES, make_test=["bearing2"]))
def test_fmusim_built_with_mingw_runs_the_win64_binary_under_wine(case, fmus, fmusim, tmp_path):
    from fmpy import simulate_fmu

    _, _, _, outputs = CASES[case]
    names = FMUSIM_INPUTS[case]
    t = np.round(np.arange(21) * 0.01, 10)
    rows = ["time," + ",".join(names)] + [f"{tk:.2f}," + ",".join(repr(x) for x in fmusim_inputs(case, k))
                                          for k, tk in enumerate(t)]
    (tmp_path / "input.csv").write_text("\n".join(rows) + "\n")
    data = np.zeros(len(t), dtype=[("time", float)] + [(n, float) for n in names])
    data["time"] = t
    for i, name in enumerate(names):
        data[name] = [fmusim_inputs(case, k)[i] for k in range(len(t))]
    expected = simulate_fmu(str(fmus[case]), stop_time=0.2, step_size=0.01, output_interval=0.01, input=data,
                            output=outputs)
    shutil.copy2(fmus[case], tmp_path / "model.fmu")
    arguments = sum((["--output-variable", n] for n in outputs), [])
    for run_index in range(RUNS):
        out = tmp_path / f"out{run_index}.csv"
        run = w.wine(fmusim, "--interface-type", "cs", "--stop-time", "0.2", "--output-interval", "0.01",
                     "--input-file", w.windows_path(tmp_path / "input.csv"), *arguments,
                     "--output-file", w.windows_path(out), w.windows_path(tmp_path / "model.fmu"))
        assert run.returncode == 0, f"run {run_index}: exit {run.returncode}\n{run.stdout[-2000:]}{run.stderr[-2000:]}"
        got = np.genfromtxt(out, delimiter=",", names=True)
        for name in outputs:  # fmusim writes 16 significant digits
            assert got[name] == pytest.approx(expected[name], rel=REL, abs=1e-300), (run_index, name)


def fmpy_single(fmu, input_name, output_name, values):
    """Outputs of fmpy on Linux stepping ``fmu`` with one input set to ``values`` in turn (tests/win64/two_fmus.c)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    folder = extract(str(fmu))
    try:
        slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName="single")
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        out = []
        for k, value in enumerate(values):
            slave.setReal([refs[input_name]], [value])
            slave.doStep(k * 0.01, 0.01)
            out.append(slave.getReal([refs[output_name]])[0])
        slave.terminate()
        slave.freeInstance()
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return out


@pytest.mark.parametrize("first", platform_cases(["bearing2", "drive"], make_test=["drive"]))
def test_two_of_our_fmus_in_one_windows_c_process(first, fmus, tmp_path):
    # the first FMU starts its Python; the second finds it running and uses it (its own folders appended)
    program = w.mingw(tmp_path / "two_fmus.exe", [ROOT / "tests" / "win64" / "two_fmus.c"])
    signals = {"bearing2": ("Fz", "z", 3e4, 1e3), "drive": ("command", "psi", 0.0, 0.01)}  # input, output, base, step
    order = [first, "drive" if first == "bearing2" else "bearing2"]
    arguments = []
    for case in order:
        _, identifier, _, _ = CASES[case]
        token, refs = refs_of(fmus[case])
        folder = w.unpack(fmus[case], tmp_path / case)
        name_in, name_out, base, step = signals[case]
        arguments += [w.windows_path(folder), identifier, token, str(refs[name_in]), str(refs[name_out]), repr(base),
                      repr(step)]
    run = w.wine(program, *arguments)
    assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), run.stdout[-3000:] + run.stderr[-3000:]
    rows = {(line.split()[0], int(line.split()[1])): float(line.split()[2]) for line in run.stdout.splitlines()
            if line[:2] in ("a ", "b ")}
    for label, case in zip("ab", order):
        name_in, name_out, base, step = signals[case]
        expected = fmpy_single(fmus[case], name_in, name_out, [base + step * k for k in range(4)])
        assert [rows[label, k] for k in range(4)] == pytest.approx(expected, rel=REL, abs=1e-300), case


@pytest.mark.skipif(not PLATFORMS_FULL, reason="SKIPPED in make test (about a minute under wine): the SSP's four "
                    "FMUs together under wine run in tests/win64/run_all.sh (SLEWING_TEST_PLATFORMS_FULL=1)")
def test_the_ssps_four_fmus_carry_win64_and_run_together_in_fmpy_on_windows(table3_fmu, drive_fmu, tmp_path):
    # the pitch system SSP of test_ssp.py (bearing, drive, two time tables), built as build_ssp.py builds it:
    # every FMU carries its win64 binary; fmpy's simulate_ssp on the embeddable Windows Python runs all four
    # in one process (the first starts the FMU's Python only where the host has none: here the host's is used)
    sys.path.insert(0, str(ROOT / "examples" / "ssp"))
    from build_ssp import build_ssp, step_command
    from slewing_drives import LoadSeries
    from ssp_hosts import COMPARED, run_fmpy

    shipped = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    loads = LoadSeries(shipped.time, shipped.loads * np.array([0.02, 0.02, 0.02, 0.001, 0.001, 0.1]))
    stop, dt = 0.3, 0.01
    ssp = build_ssp(tmp_path / "pitch_system.ssp", table3_fmu, drive_fmu, loads, step_command(5.0, 0.1, 0.9),
                    bearing_parameters={"load_frame": 2, "ring_model": 1, "preload": 10e-6}, stop_time=stop,
                    step_size=dt)
    with zipfile.ZipFile(ssp) as z:
        for name in ("loads", "command", "drive", "bearing"):
            (tmp_path / f"{name}.fmu").write_bytes(z.read(f"resources/{name}.fmu"))
            with zipfile.ZipFile(tmp_path / f"{name}.fmu") as fmu:
                names = fmu.namelist()
            assert any(n.startswith("binaries/win64/python/python311.dll") for n in names), name
            assert any(n.startswith("binaries/linux64/python/") for n in names), name
    expected = run_fmpy(ssp, list(COMPARED), stop_time=stop, step_size=dt)
    run = w.wine(w.windows_python(), w.windows_path(ROOT / "tests" / "win64" / "ssp_run.py"), w.windows_path(ssp),
                 stop, dt)
    assert run.returncode == 0 and run.stdout.rstrip().endswith("done"), run.stdout[-3000:] + run.stderr[-3000:]
    got = {line.split()[0]: np.array([float(v) for v in line.split()[1:]]) for line in run.stdout.splitlines()
           if line.split() and line.split()[0] in ("time", *COMPARED)}
    for name in ("time", *COMPARED):
        assert got[name] == pytest.approx(np.asarray(expected[name]), rel=REL, abs=1e-12), name


def test_a_non_ascii_folder_is_refused_with_a_message_not_a_crash(fmus, hosts, tmp_path):
    # a known limit of pythonfmu's Windows DLL (docs/fmu/hosts.md): given such a folder it fails or crashes
    # the host, so our layer refuses it first, saying why; the host goes on
    for case in ("bearing2", "bearing3"):
        folder = w.unpack(fmus[case], tmp_path / f"Lager für {case}")
        run = run_c_host(hosts[CASES[case][0]], fmus[case], case, folder)
        _, _, logs, _ = parse_host_output(run.stdout)
        assert run.returncode == 1 and "error fmi2Instantiate" in run.stdout, run.stdout[-3000:] + run.stderr[-3000:]
        assert any("a character beyond ASCII" in m and "Unpack the FMU in a folder with an ASCII path" in m
                   for _, _, m in logs), run.stdout[-3000:]
        if "Unhandled" in run.stderr:
            # seen once in five runs (a CI run on the loaded machine): after the refusal and the host's
            # exit(1), wine reports a page fault reading address 8 at the process's exit; our layer had
            # loaded nothing (the check comes before Python and pythonfmu's DLL). Not diagnosed: the
            # refusal above is asserted; the crash at exit is reported as an expected failure, not hidden
            pytest.xfail(f"{case}: wine page fault at the test host's exit after the refusal (intermittent, "
                         "not diagnosed)")
