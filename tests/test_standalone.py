"""The standalone FMUs on bare Debian systems that have no Python at all.

A user receives the ``.fmu`` and imports it on their own machine. Here that machine is a Debian
minbase system made with debootstrap (Debian 12 "bookworm" and 13 "trixie": no Python, no
numpy, no compiler), entered with chroot, and the hosts are independent C programs that know
nothing of Python: fmusim (the Modelica Association's Reference-FMUs simulator, built here from
``../shared/vendor``) and our own FMI 2.0 / 3.0 host (``tests/c_host/host.c``). Their outputs
must equal fmpy's, driving the same FMU on the building machine, to :data:`SAME_FMU`.

A system below the FMU's glibc floor (Debian 11 "bullseye", glibc 2.31, below the default build's
floor) must get a message naming the floor through the host's logger, not a bare loader error. An
FMU whose floor Debian 11 meets (``build_fmu.py --linux-floor``: 2.28, tests/test_linux_floor.py)
is checked there with its stated floor raised above Debian 11's.

The systems are made once and kept in ``$SLEWING_CHROOT_DIR`` (default
``/var/cache/slewing-chroots``). It all needs root (debootstrap, chroot): without root the
tests are skipped, and the skip says so.
"""
import fcntl
import os
import re
import shutil
import subprocess
import sys
import zipfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.validation import validate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from conftest import has_x86_64_v3
from host_output import parse_host_output

ROOT = Path(__file__).resolve().parents[1]
HOST = ROOT / "tests" / "c_host"
VENDOR = ROOT.parent / "shared" / "vendor" / "fmusim-v0.0.39"
CHROOTS = Path(os.environ.get("SLEWING_CHROOT_DIR", "/var/cache/slewing-chroots"))
RELEASES = {"bookworm": "Debian 12", "trixie": "Debian 13"}
BELOW_FLOOR = "bullseye"  # Debian 11, glibc 2.31: below the default build's floor (the building Python's)
INPUTS = ["Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"]
OUTPUTS = ["z", "rx", "friction_torque", "max_ball_load", "static_safety_factor"]
H = 0.01
#: how far a host's outputs may be from fmpy's driving the same FMU on the same machine: the same code and CPU,
#: but another process can sum in another order, and the solver's stop rule carries that round-off on. On this
#: project's AMD EPYC machine the bare systems' hosts give friction torques 2e-10 from fmpy's (7e-12 on other
#: machines), and the FMU unpacked in another folder, or the system with /proc and /sys mounted, moves them by
#: as much: something of the process's layout, not of the FMU, orders the sums. The
#: project's other tests of one FMU in another environment hold the same 1e-9 (tests/test_linux_floor.py,
#: tests/test_win64.py)
SAME_FMU = 1e-9
#: fmusim's runs of each FMU in each bare system: 3 in ``make test`` (more would bring the CI near its 20 minutes
#: on a slow day); SLEWING_FMUSIM_RUNS=20 for the 20 of docs/fmu/hosts.md
FMUSIM_RUNS = int(os.environ.get("SLEWING_FMUSIM_RUNS", "3"))
HOST_RUNS = int(os.environ.get("SLEWING_HOST_RUNS", "2"))  # our C host's basic scenario, repeated
MODEL = {2: "SlewingBearing", 3: "SlewingBearing3"}

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason="SKIPPED, not root: the standalone FMU's bare-system "
                                "tests need root for debootstrap and chroot (CI runs as root)")


def host_inputs(k: int, scale: float = 1.0) -> list[float]:
    """The inputs the C host sets before step k (tests/c_host/host.c, set_inputs)."""
    return [8e3 * scale, -3e3 * scale, (3e4 + 1e3 * k) * scale, 1.5e3 * scale, -2.5e3 * scale, 0.4 + 0.01 * k, 0.05]


# ---- the bare systems, the hosts, the FMUs ----------------------------------------------------
@contextmanager
def system_lock(release: str):
    """Held while a bare system is made or fmusim runs in it: ``make test`` runs the test files on
    two processes, and this file and tests/test_linux_floor.py use the same systems."""
    CHROOTS.mkdir(parents=True, exist_ok=True)
    with open(CHROOTS / f"{release}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        yield


def bare_system(release: str) -> Path:
    """A Debian minbase system of ``release``, made once with debootstrap and kept."""
    target = CHROOTS / release
    if (target / "usr" / "bin").is_dir():
        return target
    with system_lock(release):
        return _make_bare_system(release, target)


def _make_bare_system(release: str, target: Path) -> Path:
    if (target / "usr" / "bin").is_dir():              # made by the other process meanwhile
        return target
    debootstrap = shutil.which("debootstrap") or "/usr/sbin/debootstrap"
    if not os.path.exists(debootstrap):
        pytest.fail("debootstrap is not installed: `make` installs it (apt-get install debootstrap)")
    partial = CHROOTS / f"{release}.partial"
    shutil.rmtree(partial, ignore_errors=True)
    run = subprocess.run([debootstrap, "--variant=minbase", release, str(partial)], capture_output=True, text=True,
                         timeout=900)
    assert run.returncode == 0, f"debootstrap {release} failed:\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
    for deb in (partial / "var/cache/apt/archives").glob("*.deb"):    # installed: the packages are not needed
        deb.unlink()
    partial.rename(target)
    return target


def in_system(system: Path, *command, timeout=300):
    """Run ``command`` (paths inside the system) in ``system`` as a desktop session would: only PATH and HOME."""
    chroot = shutil.which("chroot") or "/usr/sbin/chroot"
    return subprocess.run([chroot, str(system), "/usr/bin/env", "-i", "PATH=/usr/bin:/bin", "HOME=/tmp", *command],
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """Our C host for FMI 2.0 and 3.0, linked to start on any x86-64 glibc (tests/c_host/start.c)."""
    folder = tmp_path_factory.mktemp("hosts")
    built = {}
    for version, flags in ((2, []), (3, ["-DFMI3"])):
        binary = folder / f"host{version}"
        run = subprocess.run(["cc", "-O1", *flags, "-include", str(ROOT / "fmu_src" / "shim" / "glibc_compat.h"),
                              "-nostartfiles", "-o", str(binary), str(HOST / "start.c"), str(HOST / "host.c"),
                              "-Wl,--no-as-needed", "-l:libdl.so.2", "-lm"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        built[version] = binary
    return built


@pytest.fixture(scope="module")
def fmusim(tmp_path_factory):
    """fmusim v0.0.39 built from ../shared/vendor, its own libraries linked in (--static)."""
    if not (VENDOR / "build.sh").exists():
        pytest.skip(f"fmusim's source is not at {VENDOR}")
    binary = tmp_path_factory.mktemp("fmusim") / "fmusim"
    run = subprocess.run(["bash", str(VENDOR / "build.sh"), str(binary), "--static"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-3000:]
    return binary


@pytest.fixture(scope="module")
def standalone(table3_fmu, table3_fmu3):
    """The standalone FMUs of table3 with numpy's loops (``--no-numba``), per FMI version."""
    return {2: table3_fmu, 3: table3_fmu3}


def runtime_of(fmu) -> dict:
    with zipfile.ZipFile(fmu) as z:
        text = z.read("resources/python_runtime.txt").decode()
    return dict(line.split("=", 1) for line in text.splitlines() if "=" in line and not line.startswith("#"))


def fmpy_steps(fmu, version, steps):
    """Outputs after each of ``steps`` steps with the C host's inputs, driven by fmpy on this machine."""
    md = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(fmu))
    out = []
    try:
        if version == 2:
            slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=MODEL[2], instanceName="ref")
            slave.instantiate()
            slave.setupExperiment(startTime=0.0)
        else:
            slave = FMU3Slave(guid=md.instantiationToken, unzipDirectory=unzipped, modelIdentifier=MODEL[3],
                              instanceName="ref")
            slave.instantiate()
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        for k in range(steps):
            if version == 2:
                slave.setReal([refs[n] for n in INPUTS], host_inputs(k))
                slave.doStep(k * H, H)
                out.append(slave.getReal([refs[n] for n in OUTPUTS]))
            else:
                slave.setFloat64([refs[n] for n in INPUTS], host_inputs(k))
                slave.doStep(k * H, H)
                out.append(slave.getFloat64([refs[n] for n in OUTPUTS]))
        slave.terminate()
        slave.freeInstance()
    finally:
        shutil.rmtree(unzipped, ignore_errors=True)
    return np.array(out)


#: the FMUs this process unzipped into a bare system's /tmp (each some 100 MB with numba's cache): removed
#: after each test, so that the kept systems do not grow by what the tests unpack
PLACED: list[Path] = []


def remove_placed() -> None:
    """Remove what :func:`place` unzipped into the bare systems (an error if something stays)."""
    left = []
    while PLACED:
        path = PLACED.pop()
        shutil.rmtree(path, ignore_errors=True)
        left += [str(path)] if path.exists() else []
    assert not left, f"could not remove the FMUs unzipped into the bare systems: {left}"


@pytest.fixture(autouse=True)
def _remove_placed_fmus():
    yield
    remove_placed()


def place(fmu, system: Path, name: str) -> tuple[str, str, list[str]]:
    """Unzip ``fmu`` into ``system``'s /tmp/<name> (removed after the test: :data:`PLACED`); returns (its
    path inside, token, value references)."""
    md = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    inside = f"/tmp/{name}"
    shutil.rmtree(system / inside.lstrip("/"), ignore_errors=True)
    PLACED.append(system / inside.lstrip("/"))
    with zipfile.ZipFile(fmu) as z:
        z.extractall(system / inside.lstrip("/"))
    token = md.guid if md.fmiVersion.startswith("2") else md.instantiationToken
    return inside, token, [str(refs[n]) for n in INPUTS + OUTPUTS]


def run_host(system, host, fmu, version, scenario, folder=None):
    """Our C host on ``fmu`` inside ``system``: (return code, {label: {step: values}}, statuses, logs, output)."""
    shutil.copy2(host, system / "tmp" / host.name)
    inside, token, vrs = place(fmu, system, folder or f"fmu{version}")
    try:
        run = in_system(system, f"/tmp/{host.name}", inside, MODEL[version], token, scenario, *vrs)
    finally:         # also for tests/test_linux_floor.py, which has no fixture of its own for it
        remove_placed()
    values, statuses, logs, _ = parse_host_output(run.stdout)
    logs = [f"{status} {category} {message}" for status, category, message in logs]
    return run.returncode, values, statuses, logs, run.stdout + run.stderr


# ---- the tests ----------------------------------------------------------------------------------
@pytest.mark.parametrize("release", [*RELEASES, BELOW_FLOOR])
def test_the_bare_systems_have_no_python(release):
    system = bare_system(release)
    found = [str(p.relative_to(system)) for folder in ("usr/bin", "usr/lib", "usr/local")
             for p in (system / folder).glob("**/*python*")]
    assert found == []


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("release", list(RELEASES))
def test_our_c_host_steps_rolls_back_and_refuses_a_nan_in_a_bare_system_as_fmpy_does(release, version, hosts,
                                                                                      standalone):
    system = bare_system(release)
    fmu = standalone[version]
    reference = fmpy_steps(fmu, version, 8)
    for _ in range(HOST_RUNS):  # load, step, roll back, free, unload, reload, exit: every run exits 0
        code, values, _, _, output = run_host(system, hosts[version], fmu, version, "basic")
        assert code == 0 and output.rstrip().endswith("done"), output[-3000:]
        for label, steps in (("run", range(6)), ("replay", range(3, 6)), ("deserialized", range(3, 6)),
                             ("reload", range(6))):
            for k in steps:  # the state set back, or deserialized, repeats the steps; a reloaded binary starts afresh
                assert values[label][k] == pytest.approx(reference[k], rel=SAME_FMU, abs=1e-300), (label, k)
    code, values, statuses, logs, output = run_host(system, hosts[version], fmu, version, "nan")
    assert code == 0, output[-3000:]
    # the NaN step is refused (Discard) with its reason, the state stays that of step 2, and the run goes on
    assert ("disturbed", 3, 2, 0, pytest.approx(0.03)) in statuses
    assert any("input Fz = nan: must be finite" in line for line in logs), logs
    assert values["after_refusal"][3] == pytest.approx(reference[2], rel=SAME_FMU, abs=1e-300)
    for k in (4, 5, 6, 7):
        assert values["disturbed"][k] == values["undisturbed"][k]
    assert statuses[-1][2:4] == (0, 0)


def assert_fmusim_runs_as_fmpy(system: Path, fmusim_binary: Path, fmu, runs: int, rel: float):
    """fmusim runs ``fmu`` ``runs`` times in ``system`` with the C host's inputs; every run exits 0, gives
    fmpy's outputs (driving the same FMU on this machine) to ``rel`` and leaves no unpacked FMU behind."""
    with system_lock(system.name):
        try:
            _fmusim_runs_as_fmpy(system, fmusim_binary, fmu, runs, rel)
        finally:     # its copy of the FMU and of fmusim, its input and output
            shutil.rmtree(system / "tmp" / "fmusim_run", ignore_errors=True)


def _fmusim_runs_as_fmpy(system: Path, fmusim_binary: Path, fmu, runs: int, rel: float):
    folder = system / "tmp" / "fmusim_run"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    shutil.copy2(fmusim_binary, folder / "fmusim")
    shutil.copy2(fmu, folder / "bearing.fmu")
    t = np.round(np.arange(21) * H, 10)
    rows = ["time," + ",".join(INPUTS)] + [f"{tk:.2f}," + ",".join(repr(x) for x in host_inputs(k))
                                           for k, tk in enumerate(t)]
    (folder / "input.csv").write_text("\n".join(rows) + "\n")
    data = np.zeros(len(t), dtype=[("time", float)] + [(n, float) for n in INPUTS])
    data["time"] = t
    for i, name in enumerate(INPUTS):
        data[name] = [host_inputs(k)[i] for k in range(len(t))]
    expected = simulate_fmu(str(fmu), stop_time=0.2, step_size=H, output_interval=H, input=data, output=OUTPUTS)
    outputs = sum((["--output-variable", n] for n in OUTPUTS), [])
    for run_index in range(runs):
        run = in_system(system, "/tmp/fmusim_run/fmusim", "--interface-type", "cs", "--stop-time", "0.2",
                        "--output-interval", str(H), "--input-file", "/tmp/fmusim_run/input.csv", *outputs,
                        "--output-file", "/tmp/fmusim_run/out.csv", "/tmp/fmusim_run/bearing.fmu")
        assert run.returncode == 0, f"run {run_index}: exit {run.returncode}\n{run.stdout[-2000:]}{run.stderr[-2000:]}"
        got = np.genfromtxt(folder / "out.csv", delimiter=",", names=True)
        for name in OUTPUTS:  # fmusim writes 16 significant digits
            assert got[name] == pytest.approx(expected[name], rel=rel, abs=1e-300), (run_index, name)
    assert not list((system / "tmp").glob("fmusim.*")), "fmusim left its unpacked FMU behind"


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("release", list(RELEASES))
def test_fmusim_runs_the_standalone_fmu_every_time_and_exits_cleanly(release, version, fmusim, standalone):
    assert_fmusim_runs_as_fmpy(bare_system(release), fmusim, standalone[version], FMUSIM_RUNS, rel=SAME_FMU)


@pytest.mark.parametrize("version", [2, 3])
def test_fmusim_saves_the_final_state_and_a_run_from_it_goes_on_as_one_run_does(version, fmusim, standalone,
                                                                                 tmp_path):
    # fmusim's --final-fmu-state-file serializes the state and hands fmi2FreeFMUstate the state itself, not its
    # address; --initial-fmu-state-file restores it right after instantiation and steps without initializing:
    # the layer must accept both, and the second half must be the single run's second half
    t = np.round(np.arange(21) * H, 10)
    rows = ["time," + ",".join(INPUTS)] + [f"{tk:.2f}," + ",".join(repr(x) for x in host_inputs(k))
                                           for k, tk in enumerate(t)]
    (tmp_path / "input.csv").write_text("\n".join(rows) + "\n")
    outputs = sum((["--output-variable", n] for n in OUTPUTS), [])

    def fmusim_run(name, start, stop, *state):
        run = subprocess.run([str(fmusim), "--interface-type", "cs", "--start-time", str(start), "--stop-time",
                              str(stop), "--output-interval", str(H), "--input-file", str(tmp_path / "input.csv"),
                              *outputs, *state, "--output-file", str(tmp_path / name), str(standalone[version])],
                             capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, f"{name}: exit {run.returncode}\n{run.stdout[-2000:]}{run.stderr[-2000:]}"
        return np.genfromtxt(tmp_path / name, delimiter=",", names=True)

    whole = fmusim_run("whole.csv", 0, 0.2)
    fmusim_run("first.csv", 0, 0.1, "--final-fmu-state-file", str(tmp_path / "state.bin"))
    assert (tmp_path / "state.bin").read_bytes()[:8] == b"SLWFMUST"      # the layer's header on the state
    second = fmusim_run("second.csv", 0.1, 0.2, "--initial-fmu-state-file", str(tmp_path / "state.bin"))
    tail = whole[-len(second):]
    assert np.allclose(tail["time"], second["time"], rtol=0, atol=1e-12)
    assert second["time"][0] == pytest.approx(0.1) and len(second) == 11
    for name in OUTPUTS:  # fmusim writes 16 significant digits
        assert second[name] == pytest.approx(tail[name], rel=SAME_FMU, abs=1e-300), name
    # the inputs change every step: a restore that lost the state (started over) would differ at once
    assert not np.allclose(whole["z"][:11], whole["z"][10:], rtol=1e-6)


def glibc_of(system: Path) -> str:
    """The glibc version of a bare system (X.Y), as its ldd prints it."""
    have = re.search(r"GNU C Library[^\n]*?release version (\d+\.\d+)|ldd \(.*\) (\d+\.\d+)",
                     in_system(system, "/usr/bin/ldd", "--version").stdout)
    return have.group(1) or have.group(2)


def above(fmu, have: str, folder: Path) -> tuple[Path, str]:
    """``fmu`` and its floor where the floor is above glibc ``have``; else a copy of ``fmu`` whose stated
    floor is raised to one minor version above ``have`` (the layer's check, not the loader, must refuse it)."""
    floor = runtime_of(fmu)["glibc"]
    if tuple(map(int, have.split("."))) < tuple(map(int, floor.split("."))):
        return fmu, floor
    major, minor = have.split(".")
    floor = f"{major}.{int(minor) + 1}"
    raised = folder / f"above_{Path(fmu).name}"
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(raised, "w") as dst:
        for info in src.infolist():
            data = src.read(info.filename)
            if info.filename == "resources/python_runtime.txt":
                data = re.sub(rb"glibc=.*", f"glibc={floor}".encode(), data)
            dst.writestr(info, data)
    return raised, floor


@pytest.mark.parametrize("version", [2, 3])
def test_below_the_glibc_floor_the_fmu_says_which_glibc_it_needs(version, hosts, standalone, tmp_path):
    system = bare_system(BELOW_FLOOR)
    have = glibc_of(system)
    fmu, floor = above(standalone[version], have, tmp_path)
    code, _, _, logs, output = run_host(system, hosts[version], fmu, version, "basic")
    assert code == 1 and "error fmi2Instantiate" in output  # refused, not crashed, not a loader error
    assert any(f"this FMU needs glibc {floor} or newer" in line and f"this machine has glibc {have}" in line
               for line in logs), output


def test_a_runtime_staged_from_debians_python3_runs_in_a_bare_system(hosts, standalone, tmp_path):
    # a distribution's Python: its libpython and _ctypes have no RUNPATH to the bundled libexpat and
    # libffi (the layer loads them first), and its site module adds dist-packages, not the
    # runtime's site-packages (the layer adds that)
    debian = Path("/usr/bin/python3")
    probe = subprocess.run([str(debian), "-c", "import sys, sysconfig, os; print(sys.version_info[:2] == (3, 11)); "
                            "print(os.path.isfile(os.path.join(sysconfig.get_config_var('LIBDIR') or '', "
                            "sysconfig.get_config_var('INSTSONAME') or '')))"], capture_output=True, text=True) \
        if debian.exists() else None
    if probe is None or probe.stdout.split() != ["True", "True"]:
        pytest.skip("needs Debian's python3 3.11 with its shared library at /usr/bin/python3")
    packages = tmp_path / "packages"
    pip = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--target", str(packages),
                          f"numpy=={np.__version__}"], capture_output=True, text=True)
    if pip.returncode != 0:
        pytest.skip(f"cannot install numpy for Debian's python3: {pip.stderr[-300:]}")
    staged = subprocess.run([str(debian), "-c", "import fmu_build.runtime, json, sys; r = fmu_build.runtime.runtime("
                             f"'binaries/linux64', cache_dir={str(tmp_path / 'cache')!r}); "
                             "print(json.dumps([str(r.archive), r.python, r.glibc]))"],
                            env={"PATH": "/usr/bin:/bin", "PYTHONPATH": f"{packages}:{ROOT}"},
                            capture_output=True, text=True, cwd=tmp_path)
    assert staged.returncode == 0, staged.stderr[-3000:]
    archive, version, glibc = __import__("json").loads(staged.stdout.strip().splitlines()[-1])
    fmu = tmp_path / "debian.fmu"
    with zipfile.ZipFile(standalone[2]) as src, zipfile.ZipFile(fmu, "w") as dst:
        for info in src.infolist():
            if info.filename.startswith("binaries/linux64/python/"):
                continue
            data = src.read(info.filename)
            if info.filename == "resources/python_runtime.txt":
                data = re.sub(rb"version=.*", f"version={version}".encode(), data)
                data = re.sub(rb"glibc=.*", f"glibc={glibc}".encode(), data)
            dst.writestr(info, data)
        with zipfile.ZipFile(archive) as runtime:
            for info in runtime.infolist():
                dst.writestr(info, runtime.read(info.filename))
    reference = fmpy_steps(standalone[2], 2, 6)
    code, values, _, _, output = run_host(bare_system("trixie"), hosts[2], fmu, 2, "basic")
    assert code == 0, output[-3000:]
    for k in range(6):
        assert values["run"][k] == pytest.approx(reference[k], rel=SAME_FMU, abs=1e-300), k


def test_an_fmu_unpacked_in_a_folder_with_a_non_ascii_name_runs_in_the_c_locale(hosts, standalone):
    # env -i: no LANG, the C locale; the FMU's Python runs in UTF-8 mode all the same
    reference = fmpy_steps(standalone[2], 2, 6)
    code, values, _, _, output = run_host(bare_system("bookworm"), hosts[2], standalone[2], 2, "basic",
                                          folder="Lager für Blattlager")
    assert code == 0, output[-3000:]
    for k in range(6):
        assert values["run"][k] == pytest.approx(reference[k], rel=SAME_FMU, abs=1e-300), k


def test_a_host_linked_to_libpython_that_did_not_start_it_gets_a_message(standalone, tmp_path):
    import sysconfig

    libdir = sysconfig.get_config_var("LIBDIR")
    minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
    host = tmp_path / "linked_host"
    build = subprocess.run(["cc", "-O1", "-o", str(host), str(HOST / "host.c"), "-Wl,--no-as-needed", f"-L{libdir}",
                            f"-lpython{minor}", f"-Wl,-rpath,{libdir}", "-ldl", "-lm"], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    assert f"libpython{minor}" in subprocess.run(["ldd", str(host)], capture_output=True, text=True).stdout
    folder = tmp_path / "fmu"
    with zipfile.ZipFile(standalone[2]) as z:
        z.extractall(folder)
    md = read_model_description(str(standalone[2]))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    run = subprocess.run([str(host), str(folder), MODEL[2], md.guid, "basic", *(str(refs[n]) for n in INPUTS + OUTPUTS)],
                         capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}, timeout=120)
    assert run.returncode == 1 and "error fmi2Instantiate" in run.stdout, run.stdout + run.stderr  # no crash
    assert "holds a Python library" in run.stdout and "not started" in run.stdout


def _readelf_glibc_needs(folder: Path) -> str:
    """The newest GLIBC_ version any ELF file below ``folder`` needs, read by binutils' readelf."""
    newest = (0, 0)
    for f in folder.rglob("*"):
        if not f.is_file() or f.read_bytes()[:4] != b"\x7fELF":
            continue
        out = subprocess.run(["readelf", "-V", "-W", str(f)], capture_output=True, text=True).stdout
        section = out.split("Version needs section", 1)[-1] if "Version needs section" in out else ""
        for major, minor in re.findall(r"Name: GLIBC_(\d+)\.(\d+)", section):
            newest = max(newest, (int(major), int(minor)))
    return f"{newest[0]}.{newest[1]}"


@pytest.mark.parametrize("version", [2, 3])
def test_the_stated_floor_is_the_newest_glibc_any_binary_of_the_fmu_needs(version, standalone, tmp_path):
    if shutil.which("readelf") is None:
        pytest.skip("binutils' readelf is not installed")
    with zipfile.ZipFile(standalone[version]) as z:
        z.extractall(tmp_path)
    assert runtime_of(standalone[version])["glibc"] == _readelf_glibc_needs(tmp_path / "binaries")


@pytest.fixture(scope="module")
def numba_fmu(table3_numba_fmu):
    """The ``--numba`` build: standalone, with numba, llvmlite and the compiled loops' cache."""
    return table3_numba_fmu


def _cache_files(system, inside):
    package = system / inside.lstrip("/") / "resources/slewing_model"
    return sorted(p.relative_to(package).as_posix() for p in package.glob("*/__pycache__/*.nb*"))


def test_the_default_build_carries_the_loops_compiled_ahead_of_time_and_runs_them_in_a_bare_system(hosts,
                                                                                                    table3_aot_fmu):
    packages = runtime_of(table3_aot_fmu)["packages"]
    assert "numpy==" in packages and "numba" not in packages and "llvmlite" not in packages
    assert validate_fmu(str(table3_aot_fmu)) == []
    assert_no_building_paths(table3_aot_fmu)
    system = bare_system("bookworm")
    reference = fmpy_steps(table3_aot_fmu, 2, 6)
    code, values, _, logs, output = run_host(system, hosts[2], table3_aot_fmu, 2, "basic")
    assert code == 0, output[-3000:]
    # the bare system has no /proc mounted: the FMU cannot read the CPU's features there and takes its generic module
    target = "x86-64-v3" if has_x86_64_v3() and (system / "proc" / "cpuinfo").exists() else "generic"
    assert any(f"loops compiled ahead of time for {target}" in line for line in logs), logs
    for k in range(6):
        assert values["run"][k] == pytest.approx(reference[k], rel=SAME_FMU, abs=1e-300), k
    for k in range(3, 6):
        assert values["replay"][k] == values["run"][k]


def test_the_numba_build_carries_numba_and_runs_its_compiled_loops_in_a_bare_system(hosts, numba_fmu):
    assert validate_fmu(str(numba_fmu)) == []
    assert "numba==" in runtime_of(numba_fmu)["packages"]
    assert_no_building_paths(numba_fmu)
    system = bare_system("bookworm")
    reference = fmpy_steps(numba_fmu, 2, 6)
    code, values, _, logs, output = run_host(system, hosts[2], numba_fmu, 2, "basic")
    assert code == 0, output[-3000:]
    assert any("loops compiled by numba for this CPU" in line for line in logs), logs
    for k in range(6):
        assert values["run"][k] == pytest.approx(reference[k], rel=SAME_FMU, abs=1e-300), k
    for k in range(3, 6):
        assert values["replay"][k] == values["run"][k]


@pytest.mark.parametrize("user_cpu", [None, "generic"])
def test_on_another_cpu_the_fmu_takes_its_portable_loops_instead_of_compiling(hosts, numba_fmu, user_cpu):
    # another machine, simulated: the CPU the FMU names as its building one is not this one. The FMU takes
    # its x86-64-v3 loops where this CPU has that level's features, else (or where the user set
    # NUMBA_CPU_NAME=generic) its generic ones
    system = bare_system("trixie")
    shutil.copy2(hosts[2], system / "tmp" / hosts[2].name)
    inside, token, vrs = place(numba_fmu, system, f"fmu_other_cpu_{user_cpu}")
    (system / inside.lstrip("/") / "resources" / "numba_target.txt").write_text("someothercpu +sse2\n")
    before = _cache_files(system, inside)
    environment = [] if user_cpu is None else [f"NUMBA_CPU_NAME={user_cpu}"]
    started = __import__("time").perf_counter()
    run = in_system(system, *environment, f"/tmp/{hosts[2].name}", inside, MODEL[2], token, "basic", *vrs)
    elapsed = __import__("time").perf_counter() - started
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    cpu = "an x86-64-v3 CPU" if user_cpu is None and has_x86_64_v3() else "a generic x86-64 CPU"
    assert f"loops compiled by numba for {cpu}" in run.stdout
    assert _cache_files(system, inside) == before        # numba compiled nothing: it found those loops
    reference = fmpy_steps(numba_fmu, 2, 6)
    rows = {int(line.split()[1]): [float(x) for x in line.split()[2:]] for line in run.stdout.splitlines()
            if line.startswith("run ")}
    for k in range(6):  # other machine code (generic: no AVX, no FMA): the same numbers to the solver's round-off
        assert rows[k] == pytest.approx(reference[k], rel=1e-9, abs=1e-300), k
    assert elapsed < 30, f"{elapsed:.0f} s: compiling the loops takes about a minute"


# ---- no path of the building machine --------------------------------------------------------------
def building_paths() -> set[str]:
    """Absolute paths of this machine that a built FMU could carry (its Pythons, the project, the temporary builds)."""
    import site
    import sysconfig
    import tempfile

    candidates = {str(ROOT), sys.prefix, sys.base_prefix, sys.exec_prefix, *site.getsitepackages(),
                  sysconfig.get_config_var("prefix"), tempfile.gettempdir() + "/slewing_", os.path.expanduser("~")}
    return {p for p in candidates if p and p.startswith("/") and len(p) > 5}


def assert_no_building_paths(fmu):
    """No file of ``fmu`` (the Linux and the win64 binaries and runtimes alike) holds a path of this machine,
    as UTF-8 or as the UTF-16 of Windows files, nor in the form wine gives it (Z:\\...)."""
    paths = building_paths()
    with zipfile.ZipFile(fmu) as z:
        for name in z.namelist():
            data = z.read(name)
            for path in paths:
                windows = "Z:" + path.replace("/", "\\")
                for form in (path.encode(), path.encode("utf-16-le"), windows.encode(), windows.encode("utf-16-le")):
                    assert form not in data, f"{fmu}: {name} holds {path}"


@pytest.fixture(scope="module")
def table_fmu(tmp_path_factory):
    sys.path.insert(0, str(ROOT))
    from fmu_build.drive import build_table_fmu

    return build_table_fmu(tmp_path_factory.mktemp("table") / "command.fmu", "a command", [0.0, 1.0],
                           [("command", "rad", "pitch angle command")], [[0.0], [0.1]])


def test_no_file_inside_the_standalone_fmus_holds_a_path_of_the_building_machine(standalone, pitch_drive_fmu,
                                                                                 table_fmu):
    for fmu in (*standalone.values(), pitch_drive_fmu, table_fmu):
        assert runtime_of(fmu)["runtime"] == "standalone"
        with zipfile.ZipFile(fmu) as z:  # the check covers the win64 binary and runtime too (fmu_build/win64.py)
            assert any(n.startswith(("binaries/win64/python/", "binaries/x86_64-windows/python/")) for n in z.namelist())
        assert_no_building_paths(fmu)


def test_the_drive_and_table_fmus_of_the_ssp_are_standalone_and_valid(pitch_drive_fmu, table_fmu):
    for fmu in (pitch_drive_fmu, table_fmu):
        assert validate_fmu(str(fmu)) == []
        with zipfile.ZipFile(fmu) as z:
            assert "binaries/linux64/python/lib/libpython3.11.so.1.0".replace(
                "3.11", f"{sys.version_info[0]}.{sys.version_info[1]}") in z.namelist()


@pytest.fixture(scope="module")
def pitch_drive_fmu(tmp_path_factory):
    sys.path.insert(0, str(ROOT))
    from fmu_build.drive import build_drive_fmu

    return build_drive_fmu(ROOT / "examples" / "drives" / "pitch_drive.toml",
                           tmp_path_factory.mktemp("drive") / "SlewingDrive_pitch.fmu")


def test_the_path_check_finds_a_path_written_into_an_fmu(standalone, tmp_path):
    # the check above can fail: an FMU with the project's path added in one file is caught
    planted = tmp_path / "planted.fmu"
    shutil.copy2(standalone[2], planted)
    with zipfile.ZipFile(planted, "a") as z:
        z.writestr("resources/planted.txt", f"built in {ROOT}\n")
    with pytest.raises(AssertionError, match="planted.txt holds"):
        assert_no_building_paths(planted)
    planted_wide = tmp_path / "planted_wide.fmu"          # and a Windows file's UTF-16 string
    shutil.copy2(standalone[3], planted_wide)
    with zipfile.ZipFile(planted_wide, "a") as z:
        z.writestr("binaries/x86_64-windows/planted.dll", f"built in {ROOT}".encode("utf-16-le"))
    with pytest.raises(AssertionError, match="planted.dll holds"):
        assert_no_building_paths(planted_wide)
