"""The bearing FMU outside Python, in the environment of a host started from a desktop:
only ``PATH=/usr/bin:/bin`` and ``HOME``, no ``LD_PRELOAD``, no Python on the PATH.

Hosts: a minimal FMI 2.0 C host of our own (``tests/c_host/host.c``, compiled here with the
system's C compiler), ecos (``test_fmu.py``) and libcosim (libcosimpy). The reference values
come from fmpy, an independent host, driving the same FMU in this process.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from host_output import parse_host_output

ROOT = Path(__file__).resolve().parents[1]
HOST_SOURCE = ROOT / "tests" / "c_host" / "host.c"
#: the hosts' environment: nothing of this one but OpenBLAS's choice of kernels. The FMU's numpy loops sum
#: in single precision by OpenBLAS (the kept operator's inverse and its products), whose kernels, chosen
#: by OPENBLAS_CORETYPE where set and else by the CPU, round differently: on a Zen 5 machine that sets
#: OPENBLAS_CORETYPE=Haswell, a host without it differed from fmpy in this process by up to 3.6e-11
#: (relative; within the solver's tolerance, not at round-off). The hosts are compared with the same kernels.
MINIMAL_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root"),
               **{name: value for name, value in os.environ.items() if name.startswith("OPENBLAS_")}}
INPUTS = ["Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"]
OUTPUTS = ["z", "rx", "friction_torque", "max_ball_load", "ball[5].Q1", "ball[60].Q2"]
H = 0.01  # the C host's step


def host_inputs(k: int, scale: float = 1.0) -> list[float]:
    """The inputs the C host sets before step k (tests/c_host/host.c, set_inputs)."""
    return [8e3 * scale, -3e3 * scale, (3e4 + 1e3 * k) * scale, 1.5e3 * scale, -2.5e3 * scale, 0.4 + 0.01 * k, 0.05]


@pytest.fixture(scope="module")
def c_host(tmp_path_factory):
    compiler = next((shutil.which(c) for c in (os.environ.get("CC"), "cc", "gcc") if c and shutil.which(c)), None)
    if compiler is None:
        pytest.skip("no C compiler (cc or gcc): install gcc and libc6-dev (make does, as root)")
    binary = tmp_path_factory.mktemp("c_host") / "host"
    run = subprocess.run([compiler, "-O1", "-o", str(binary), str(HOST_SOURCE), "-ldl", "-lm"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return binary


def unzipped(fmu, folder):
    """The unzipped FMU, its GUID and the value references the C host takes."""
    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    md = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    return folder, md.guid, [str(refs[n]) for n in INPUTS + OUTPUTS]


@pytest.fixture(scope="module")
def fmu_dir(table3_fmu, tmp_path_factory):
    """The standalone FMU (the default build), unzipped."""
    return unzipped(table3_fmu, tmp_path_factory.mktemp("unzipped"))


@pytest.fixture(scope="module")
def host_fmu_dir(table3_host_fmu, tmp_path_factory):
    """The host FMU (``--runtime host``: it runs in this machine's Python), unzipped."""
    return unzipped(table3_host_fmu, tmp_path_factory.mktemp("unzipped_host"))


def run_host(c_host, fmu_dir, scenario, *extra, env=None):
    """Run the C host; returns (return code, {label: {step: values}}, status lines, log lines, stderr)."""
    folder, guid, vrs = fmu_dir
    run = subprocess.run([str(c_host), str(folder), "SlewingBearing", guid, scenario, *vrs, *extra],
                         env=dict(MINIMAL_ENV, **(env or {})), capture_output=True, text=True, timeout=300)
    values, statuses, logs, errors = parse_host_output(run.stdout)
    return run.returncode, values, statuses, logs, run.stderr + "\n".join(errors)


def fmpy_steps(fmu, steps, scale=1.0):
    """Outputs after each of ``steps`` steps with the C host's inputs, driven by fmpy here."""
    md = read_model_description(str(fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(fmu))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="SlewingBearing", instanceName="ref")
    try:
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        out = []
        for k in range(steps):
            slave.setReal([refs[n] for n in INPUTS], host_inputs(k, scale))
            slave.doStep(k * H, H)
            out.append(slave.getReal([refs[n] for n in OUTPUTS]))
        slave.terminate()
        slave.freeInstance()
    finally:
        shutil.rmtree(unzipped, ignore_errors=True)
    return out


@pytest.fixture(scope="module")
def reference(table3_fmu):
    return {1.0: fmpy_steps(table3_fmu, 8, 1.0), 2.0: fmpy_steps(table3_fmu, 6, 2.0)}


def assert_close(got, expected, rel=1e-12):
    assert got == pytest.approx(expected, rel=rel, abs=1e-300)


def test_c_host_steps_rolls_back_frees_and_reloads(c_host, fmu_dir, reference):
    code, values, _, _, err = run_host(c_host, fmu_dir, "basic")
    assert code == 0, err
    run = values["run"]
    for k in range(6):  # an independent host, fmpy, gives the same outputs
        assert_close(run[k], reference[1.0][k])
    for label in ("replay", "deserialized"):  # fmi2SetFMUstate, and a state through bytes, repeat exactly
        assert [values[label][k] for k in (3, 4, 5)] == [run[k] for k in (3, 4, 5)], label
    # freed, dlclose'd and loaded again: a new instance starts afresh
    assert [values["reload"][k] for k in range(6)] == [run[k] for k in range(6)]


def test_two_instances_in_one_c_host_are_independent(c_host, fmu_dir, reference):
    code, values, _, _, err = run_host(c_host, fmu_dir, "two")
    assert code == 0, err
    for k in range(6):
        assert_close(values["a"][k], reference[1.0][k])
        assert_close(values["b"][k], reference[2.0][k])
    assert values["a"][5] != values["b"][5]


def test_nan_step_is_refused_and_the_run_goes_on_as_if_it_had_not_happened(c_host, fmu_dir):
    code, values, statuses, logs, err = run_host(c_host, fmu_dir, "nan")
    assert code == 0, err
    # refused: fmi2Discard, not terminated, last successful time the start of the refused step
    label, k, status, terminated, last = statuses[0]
    assert (label, k, status, terminated) == ("disturbed", 3, 2, 0)
    assert last == pytest.approx(3 * H, rel=1e-15)
    # the log says why, with the status returned (Discard), not Error
    refusals = [m for m in logs if "input Fz = nan: must be finite" in m[2]]
    assert [(s, c) for s, c, _ in refusals] == [(2, "logStatusDiscard")]
    # the state is the one before the step: outputs unchanged, and the step retried from its start
    # with valid inputs, and those after it, equal those of an instance that never saw the NaN,
    # to the last bit
    assert values["after_refusal"][3] == values["disturbed"][2]
    for k in range(3, 8):
        assert values["disturbed"][k] == values["undisturbed"][k], k
    assert statuses[-1][2:4] == (0, 0)  # still not terminated after the valid steps


def test_load_instantiate_refuse_free_unload_cycles_end_cleanly(c_host, fmu_dir, reference):
    # two instances per cycle, one freed right after a refused step, then dlclose; pythonfmu 0.7.0
    # alone corrupts the heap at exit here (abort, status -6): our binary releases its holder first
    code, values, _, _, err = run_host(c_host, fmu_dir, "stress", "--cycles", "4")
    assert code == 0, err
    assert "corrupted" not in err
    for cycle in range(4):
        assert values["cycle"][cycle] == values["cycle"][0]
    assert_close(values["cycle"][0], reference[1.0][2])


def _valgrind_errors(log: str) -> list[str]:
    """Memcheck's error reports, each as its text, without the known false report of the
    dynamic loader itself (glibc's SSE2 strncmp reading past a strdup'd run path in
    dl-load.c's is_dst: an aligned over-read inside the allocator's granule)."""
    blocks, current = [], None
    for line in log.splitlines():
        text = line.split("== ", 1)[-1] if line.startswith("==") else line
        if text.startswith(("Invalid ", "Mismatched free", "Conditional jump", "Use of uninitialised")):
            current = [text]
            blocks.append(current)
        elif current is not None and text.strip():
            current.append(text)
        else:
            current = None
    return ["\n".join(b) for b in blocks if not ("strncmp" in b[1] and "is_dst (dl-load.c" in "\n".join(b))]


def test_valgrind_finds_no_heap_error_with_two_instances_and_a_refused_step(c_host, fmu_dir):
    # 20 s on an idle machine, minutes on a loaded one: opt-in; the load/free cycles above catch the abort
    if os.environ.get("SLEWING_TEST_VALGRIND") != "1":
        pytest.skip("set SLEWING_TEST_VALGRIND=1 to run the FMU under valgrind (20 s to minutes)")
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        pytest.skip("valgrind is not installed")
    folder, guid, vrs = fmu_dir
    # two instances, a refused step, both freed, dlclose, exit: where pythonfmu 0.7.0 alone
    # reads freed memory (finalizePythonInterpreter after exit's static destructors)
    run = subprocess.run([valgrind, "--num-callers=30", str(c_host), str(folder), "SlewingBearing", guid, "nan",
                          *vrs], env=MINIMAL_ENV, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "ERROR SUMMARY" in run.stderr
    assert _valgrind_errors(run.stderr) == []


def _python_minor(executable):
    run = subprocess.run([executable, "-c", "import sys; print(sys.version.split()[0])"],
                         capture_output=True, text=True, env=MINIMAL_ENV)
    return run.stdout.strip() if run.returncode == 0 else None


def test_a_host_python_without_numpy_gets_a_message_naming_what_to_install(c_host, host_fmu_dir):
    other = "/usr/bin/python3"
    version = _python_minor(other) if os.path.exists(other) else None
    minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
    if version is None or not version.startswith(minor + "."):
        pytest.skip(f"needs a system Python {minor} at /usr besides this one")
    if subprocess.run([other, "-c", "import numpy"], capture_output=True, env=MINIMAL_ENV).returncode == 0:
        pytest.skip("the system Python has numpy")
    code, _, _, logs, err = run_host(c_host, host_fmu_dir, "basic", env={"SLEWING_FMU_PYTHONHOME": "/usr"})
    assert code == 1 and "fmi2Instantiate" in err  # refused, not crashed
    text = " ".join(m for _, _, m in logs)
    assert f"needs numpy in the Python that runs it, Python {version} at /usr" in text
    assert "-m pip install numpy" in text and "SLEWING_FMU_PYTHONHOME" in text
    assert f"built with Python {sys.version.split()[0]}" in text


def test_another_python_named_by_the_variable_runs_the_fmu(c_host, host_fmu_dir, reference, tmp_path):
    # another machine, simulated: the Python named in the FMU is gone, and the user names a
    # virtual environment of the system's Python (/usr, without numpy) with numpy installed in it
    other = "/usr/bin/python3"
    version = _python_minor(other) if os.path.exists(other) else None
    minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
    if version is None or not version.startswith(minor + "."):
        pytest.skip(f"needs a system Python {minor} at /usr besides this one")
    venv = tmp_path / "venv"
    subprocess.run([other, "-m", "venv", "--without-pip", str(venv)], check=True, env=MINIMAL_ENV)
    import numpy

    pip = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target",
                          str(venv / "lib" / f"python{minor}" / "site-packages"), f"numpy=={numpy.__version__}"],
                         capture_output=True, text=True)
    if pip.returncode != 0:
        pytest.skip(f"cannot install numpy into a test environment: {pip.stderr[-300:]}")
    folder, guid, vrs = host_fmu_dir
    moved = tmp_path / "fmu"
    shutil.copytree(folder, moved)
    (moved / "resources" / "python_runtime.txt").write_text(
        f"version={sys.version.split()[0]}\nhome=/nonexistent\nlibrary=/nonexistent/lib/libpython{minor}.so.1.0\n"
        "environment=/nonexistent\n")
    code, values, _, _, err = run_host(c_host, (moved, guid, vrs), "basic")
    assert code == 1 and "fmi2Instantiate" in err  # the Python named by the FMU is gone
    code, values, _, _, err = run_host(c_host, (moved, guid, vrs), "basic", env={"SLEWING_FMU_PYTHONHOME": str(venv)})
    assert code == 0, err
    for k in range(6):  # the host FMU runs the loops compiled ahead of time (x86-64-v3: fused multiply-adds), the
        # reference numpy's: the two agree to about 1e-10, within the solver's tolerance
        assert_close(values["run"][k], reference[1.0][k], rel=1e-9)


def test_a_missing_python_gets_a_message_instead_of_a_crash(c_host, host_fmu_dir, tmp_path):
    nowhere = tmp_path / "no_python_here"
    code, _, _, logs, err = run_host(c_host, host_fmu_dir, "basic", env={"SLEWING_FMU_PYTHONHOME": str(nowhere)})
    assert code == 1 and "fmi2Instantiate" in err
    (status, category, message), = logs
    assert status == 3 and category == "logStatusError"
    minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
    assert f"the Python home {nowhere} (set by SLEWING_FMU_PYTHONHOME) holds no standard library" in message
    assert f"libpython{minor}.so.1.0" in message and "numpy" in message


def test_libcosim_runs_the_fmu_in_a_minimal_environment(table3_fmu, tmp_path):
    pytest.importorskip("libcosimpy")
    values = {"Fz": 3e4, "Mx": 1.5e3, "My": -2.5e3, "psi": 0.4, "omega": 0.05}
    script = tmp_path / "cosim.py"
    script.write_text(f"""
import json
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

log_output_level(CosimLogLevel.ERROR)
execution = CosimExecution.from_step_size(step_size=int(1e7))
index = execution.add_local_slave(CosimLocalSlave(fmu_path={str(table3_fmu)!r}, instance_name="bearing"))
refs = {{v.name.decode(): v.reference for v in execution.slave_variables(index)}}
for name, value in {values!r}.items():
    execution.real_initial_value(index, refs[name], value)
observer = CosimObserver.create_last_value()
execution.add_observer(observer)
assert execution.step(20)
print(json.dumps({{n: observer.last_real_values(index, [refs[n]])[0] for n in {OUTPUTS!r}}}))
execution.stop()
""")
    run = subprocess.run([sys.executable, str(script)], env=MINIMAL_ENV, capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    got = json.loads(run.stdout.strip().splitlines()[-1])
    ref = simulate_fmu(str(table3_fmu), stop_time=0.2, step_size=0.01, start_values=values, output=OUTPUTS)
    for name in OUTPUTS:
        assert got[name] == pytest.approx(ref[name][-1], rel=1e-12), name


def _build_machine_paths() -> set[str]:
    """Absolute paths of this machine that a built FMU could carry."""
    import site

    candidates = {str(ROOT), sys.prefix, sys.base_prefix, sys.exec_prefix, os.path.expanduser("~"),
                  tempfile.gettempdir() + "/slewing_fmu", *site.getsitepackages()}
    return {p for p in candidates if p and p.startswith("/") and len(p) > 5}


def test_the_host_fmu_holds_no_path_of_the_building_machine_outside_its_python_file(table3_host_fmu):
    paths = _build_machine_paths()
    runtime = "resources/python_runtime.txt"
    with zipfile.ZipFile(table3_host_fmu) as z:
        names = z.namelist()
        assert runtime in names and not any(n.endswith("python_paths.json") for n in names)
        for name in names:
            # numba's cache of the compiled loops (build_fmu.ship_compiled_kernels) is compiled code
            # whose pickled debug records name the sources it was compiled from, as text for error
            # messages; numba takes the code where its source, numba and the CPU match, else compiles
            if name == runtime or (name.startswith(("resources/slewing_model/friction/__pycache__/kernel.",
                                                    "resources/slewing_model/distribution/__pycache__/kernel."))
                                   and name.endswith(".nbc")):
                continue
            data = z.read(name)
            for path in paths:
                assert path.encode() not in data, f"{name} holds {path}"
        # the one file that names the Python: the building one, found by a C host without PATH
        named = dict(line.split("=", 1) for line in z.read(runtime).decode().splitlines()
                     if "=" in line and not line.startswith("#"))
    assert named["version"] == sys.version.split()[0]
    assert Path(named["home"]) == Path(sys.base_prefix) and Path(named["environment"]) == Path(sys.prefix)
    assert Path(named["library"]).exists() and Path(named["library"]).name.startswith("libpython")


def test_building_without_a_c_compiler_fails_with_what_to_install(monkeypatch):
    sys.path.insert(0, str(ROOT))
    import build_fmu

    monkeypatch.setenv("PATH", "/nonexistent")
    monkeypatch.setenv("CC", "no-such-compiler")
    with pytest.raises(RuntimeError, match="needs a C compiler.*apt-get install gcc libc6-dev"):
        build_fmu.compile_shim(Path(tempfile.gettempdir()) / "never_written.so")


def test_a_master_repeating_a_refused_step_unchanged_gets_an_error_not_an_endless_loop(table3_fmu, tmp_path):
    # fmpy's simulate_fmu retries a discarded step at the same time with the same inputs; the
    # second refusal of the very same step is fmi2Error, logged even with logging off
    script = tmp_path / "retry.py"
    script.write_text(f"""
import numpy as np
from fmpy import simulate_fmu
t = np.linspace(0, 0.1, 11)
data = np.zeros(len(t), dtype=[("time", float), ("Fz", float)])
data["time"], data["Fz"] = t, 3e4
data["Fz"][5:] = np.nan
try:
    simulate_fmu({str(table3_fmu)!r}, stop_time=0.1, step_size=0.01, input=data, output=["z"])
    print("FINISHED")
except Exception as exc:
    print("RAISED", exc)
""")
    # TMPDIR: simulate_fmu does not remove the FMU it unzipped when a step fails (FMPy issue 675,
    # https://github.com/CATIA-Systems/FMPy/issues/675)
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "TMPDIR": str(tmp_path)})
    assert "RAISED fmi2DoStep failed with status 3 (error)" in run.stdout, run.stdout + run.stderr
    assert "step at t = 0.05 refused again with the same inputs, so it cannot succeed" in run.stdout + run.stderr
    assert "input Fz = nan" in run.stdout + run.stderr


def test_an_overload_refused_inside_the_solver_leaves_no_trace(table3_fmu):
    # unlike a NaN, caught before the solve, an overload fails inside the Newton solver, which has
    # moved: the slave restores the state of before the step, and the step retried from its start
    # with the undisturbed inputs gives what the undisturbed instance gives
    md = read_model_description(str(table3_fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(table3_fmu))
    outputs = {}
    try:
        for label in ("undisturbed", "disturbed"):
            slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="SlewingBearing",
                              instanceName=label)
            slave.instantiate()
            slave.setupExperiment(startTime=0.0)
            slave.enterInitializationMode()
            slave.exitInitializationMode()
            out = []
            for k in range(6):
                if k == 3 and label == "disturbed":
                    slave.setReal([refs["Fz"]], [5e7])
                    with pytest.raises(Exception, match="status 2"):
                        slave.doStep(k * H, H)
                slave.setReal([refs[n] for n in INPUTS], host_inputs(k))
                slave.doStep(k * H, H)
                out.append(slave.getReal([refs[n] for n in OUTPUTS]))
            outputs[label] = out
            slave.terminate()
            slave.freeInstance()
    finally:
        shutil.rmtree(unzipped, ignore_errors=True)
    assert outputs["disturbed"] == outputs["undisturbed"]
