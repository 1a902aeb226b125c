"""The FMU obeys the FMI co-simulation state machine: every call the standard forbids, and every call
with an argument or a variable the FMU cannot take, is refused with Error and a logged message that
names the function, and changes nothing: the same instance then completes a legal run equal, to the
last bit, to a fresh instance's.

The cases are generated from the table in tests/fmi_state_machine.py: each (state, function not allowed
there), and the argument and variable cases in the states where their function is allowed. Each runs
through fmpy's low-level API and through our C host (tests/c_host/misuse.c, FMI 2.0 and 3.0), on the
bearing FMU (FMI 2.0 and 3.0), and a subset on the drive and time-table FMUs. Each (runner, FMU, state)
is one process (a crash ends only that one, and is reported): one instance reaches the state, makes
every refused call of the state, and completes the legal run. Each process's script (``*.txt``) and what it
printed (``*.out``) are kept in the test's ``misuse_runs`` folder. SLEWING_TEST_VALGRIND=1 also runs three of
the C host's scripts under valgrind (minutes).
"""
import os
import shutil
import subprocess
import sys
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

import fmi_state_machine as sm

ROOT = Path(__file__).resolve().parents[1]
HOST_SOURCE = ROOT / "tests" / "c_host" / "misuse.c"
RUNNER = Path(sm.__file__)
#: the runners' environment: a desktop's (as tests/test_fmu_hosts.py), OpenBLAS's kernels as here
MINIMAL_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root"),
               **{name: value for name, value in os.environ.items() if name.startswith("OPENBLAS_")}}
BEARING_INPUTS = ["Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"]
DRIVE_INPUTS = ["command", "load_moment", "friction_torque"]
ERROR = 3


def bearing_inputs(k):
    return [8e3, -3e3, 3e4 + 1e3 * k, 1.5e3, -2.5e3, 0.4 + 0.01 * k, 0.05]


def drive_inputs(k):
    return [0.02 * (k + 1), 1e4 * (1 + 0.1 * k), 50.0]


#: the FMUs: version, states' extra (a NaN input reaches StepFailed), the cases kept (None: all)
SUBSET = ("DoStep in Instantiated", "DoStep in InitializationMode", "DoStep in Terminated",
          "ExitInitializationMode in StepComplete", "SetupExperiment in StepComplete", "GetReal in Instantiated",
          "an output", "an unknown value reference", "step size 0", "5 s back", "70 bytes of garbage",
          "another FMU")
FMUS = {"bearing2": (2, "Fz", None), "bearing3": (3, "Fz", None), "drive": (2, None, SUBSET),
        "table": (2, None, SUBSET)}
APIS = ("fmpy", "c")
#: the variables the variable cases use, per FMU (checked against the modelDescription)
NAMED = {"bearing2": {"max_ball_load", "preload", "ring_model"}, "bearing3": {"max_ball_load", "preload", "ring_model"},
         "drive": set(), "table": set()}


def _states(key):
    version, nan, _ = FMUS[key]
    states = sm.FMI2_STATES if version == 2 else sm.FMI3_STATES
    return [s for s in states if s != "StepFailed" or nan]


def _case_names(key, state):
    """The cases' names, from the table alone (collection time); those the FMU cannot have are skipped
    at run time."""
    version, _, subset = FMUS[key]
    table = sm.FMI2_ALLOWED if version == 2 else sm.FMI3_ALLOWED
    names = []
    for short, text, states, _ in sm.VARIABLE_CASES:
        function = sm.version_name(version, short)
        where = states if states != "allowed" else _states(key)
        if state in where and sm.allowed(version, function, state):
            names.append(f"{function} with {text} in {state}")
    names += [f"{f} in {state}" for f in sorted(table, key=sm.order) if not sm.allowed(version, f, state)]
    if subset is not None:
        names = [n for n in names if any(s in n for s in subset)]
    return names


CASES = [(api, key, state, name) for key in FMUS for api in APIS for state in _states(key)
         for name in _case_names(key, state)]
RUNS = [(api, key, state) for key in FMUS for api in APIS for state in _states(key)]


# ---- the FMUs and the runners ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def extra_fmus(tmp_path_factory):
    """The drive FMU (pitch drive) and a time-table FMU, Linux binaries only."""
    sys.path.insert(0, str(ROOT))
    from fmu_build.drive import build_drive_fmu, build_table_fmu

    folder = tmp_path_factory.mktemp("misuse_fmus")
    return {"drive": build_drive_fmu(ROOT / "examples" / "drives" / "pitch_drive.toml", folder / "drive.fmu",
                                     win64=False),
            "table": build_table_fmu(folder / "table.fmu", "a command", [0.0, 1.0],
                                     [("command", "rad", "pitch angle command")], [[0.0], [0.1]], win64=False)}


@pytest.fixture(scope="module")
def fmus(table3_fmu, table3_fmu3, extra_fmus, tmp_path_factory):
    """key -> (sm.Fmu, unzipped folder)."""
    paths = {"bearing2": table3_fmu, "bearing3": table3_fmu3, **extra_fmus}
    out = {}
    for key, path in paths.items():
        folder = tmp_path_factory.mktemp(f"misuse_{key}")
        with zipfile.ZipFile(path) as z:  # the Linux half: the Windows binaries and runtime are not run here
            z.extractall(folder, [n for n in z.namelist()
                                  if not n.startswith(("binaries/win64/", "binaries/x86_64-windows/"))])
        if key.startswith("bearing"):
            fmu = sm.Fmu.read(key, path, BEARING_INPUTS, bearing_inputs, 0.01, FMUS[key][1])
        elif key == "drive":
            fmu = sm.Fmu.read(key, path, DRIVE_INPUTS, drive_inputs, 0.01)
        else:
            fmu = sm.Fmu.read(key, path, step=0.1)
        missing = NAMED[key] - set(fmu.variables)
        assert not missing, f"{key}: the variable cases name {missing}, which the FMU does not have"
        out[key] = (fmu, folder)
    return out


@pytest.fixture(scope="module")
def c_hosts(tmp_path_factory):
    compiler = next((shutil.which(c) for c in (os.environ.get("CC"), "cc", "gcc") if c and shutil.which(c)), None)
    if compiler is None:
        pytest.skip("no C compiler (cc or gcc): install gcc and libc6-dev (make does, as root)")
    folder = tmp_path_factory.mktemp("misuse_host")
    hosts = {}
    for version, flags in ((2, []), (3, ["-DFMI3"])):
        hosts[version] = folder / f"misuse{version}"
        run = subprocess.run([compiler, "-O1", "-Wall", *flags, "-o", str(hosts[version]), str(HOST_SOURCE),
                              "-ldl", "-lm"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
    return hosts


def command(api, fmu, folder, script, c_hosts):
    if api == "c":
        return [str(c_hosts[fmu.version]), str(folder), fmu.model_identifier, fmu.guid, str(script)]
    return [sys.executable, str(RUNNER), fmu.path, str(folder), str(script)]


class Run:
    """One runner process: its script, return code, calls by line index, stderr."""

    def __init__(self, api, fmu, folder, lines, path, c_hosts, wrapper=()):
        path.write_text("\n".join(lines) + "\n")
        self.lines = lines
        proc = subprocess.run([*wrapper, *command(api, fmu, folder, path, c_hosts)], env=MINIMAL_ENV,
                              capture_output=True, text=True, timeout=600, cwd=path.parent)
        self.returncode, self.stdout, self.stderr = proc.returncode, proc.stdout, proc.stderr
        path.with_suffix(".out").write_text(proc.stdout + "\nstderr:\n" + proc.stderr)  # kept for a look
        self.calls = sm.parse(proc.stdout)

    def crash(self):
        """How the process ended, when not with 0 after its last line."""
        if self.returncode < 0:
            last = max(self.calls, default=-1)
            nxt = next((i for i in range(last + 1, len(self.lines)) if not self.lines[i].startswith("@")), None)
            where = f"at script line {nxt}: {self.lines[nxt][:80]!r}" if nxt is not None else "at the end"
            return f"killed by signal {-self.returncode} {where}"
        if self.returncode != 0 or not self.stdout.rstrip().endswith("done"):
            return f"exit status {self.returncode}; stderr: {self.stderr[-1500:]}"
        return None


@pytest.fixture(scope="module")
def runs(fmus, c_hosts, tmp_path_factory):
    """(api, key) -> {"fresh": (Run, output indices), state: (Run, sm.StateScript)}: each FMU's fresh run
    first (its state is another FMU's for the next), then every state's run, two processes at a time."""
    folder = tmp_path_factory.mktemp("misuse_runs")
    garbage = folder / "garbage.bin"
    garbage.write_bytes(bytes((37 * i + 11) % 256 for i in range(70)))
    out = {}
    # the foreign state of each FMU: another FMU's real state (the drive's for the FMI 2.0 bearing)
    foreign = {"bearing2": "drive", "bearing3": "bearing2", "drive": "bearing2", "table": "drive"}
    order = ["drive", "bearing2", "bearing3", "table"]
    with ThreadPoolExecutor(max_workers=2) as pool:
        def fresh(api, key):
            fmu, unzipped = fmus[key]
            lines, outputs = sm.fresh_script(fmu, str(folder / f"{api}_{key}_state.bin"))
            return Run(api, fmu, unzipped, lines, folder / f"{api}_{key}_fresh.txt", c_hosts), outputs

        for key in order:
            for api, result in zip(APIS, pool.map(lambda a: fresh(a, key), APIS)):
                out[api, key] = {"fresh": result}
        jobs = {}
        for key in order:
            fmu, unzipped = fmus[key]
            for api in APIS:
                files = {"own": str(folder / f"{api}_{key}_state.bin"), "garbage": str(garbage),
                         "foreign": str(folder / f"{api}_{foreign[key]}_state.bin")}
                for state in _states(key):
                    s = sm.state_script(fmu, state, files, FMUS[key][2])
                    jobs[api, key, state] = (s, pool.submit(Run, api, fmu, unzipped, s.lines,
                                                            folder / f"{api}_{key}_{state}.txt", c_hosts))
        for (api, key, state), (s, job) in jobs.items():
            out[api, key][state] = (job.result(), s)
    return out


def _reached(run, script):
    """Why the state was not reached, or None."""
    for i in script.reach:
        call = run.calls.get(i)
        expected = (2,) if script.state == "StepFailed" and i == script.reach[-1] else (0, 1)
        if call is None or call.status not in expected:
            return (f"reaching {script.state}: {script.lines[i][:80]!r} returned "
                    f"{None if call is None else call.status} (expected {expected}); "
                    f"{run.crash() or ''} log: {[] if call is None else call.logs}")
    return None


# ---- the tests ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("api, key, state, name", CASES, ids=[f"{a}-{k}-{n}" for a, k, _, n in CASES])
def test_a_forbidden_call_is_refused_with_error_and_a_message_naming_the_function(runs, api, key, state, name):
    run, script = runs[api, key][state]
    index = next((i for i, case in script.cases.items() if case.name == name), None)
    if index is None:
        pytest.skip(f"{key} has no variable this case needs ({name})")
    problem = _reached(run, script)
    assert problem is None, problem
    call = run.calls.get(index)
    assert call is not None, f"{name}: no answer: the host ended first ({run.crash()})"
    function = script.lines[index].split()[0]
    assert call.status == ERROR, (f"{name}: {script.lines[index][:120]!r} returned {call.status}, "
                                  f"not Error ({ERROR}); log: {call.logs}")
    errors = [m for s, _, m in call.logs if s == ERROR]
    assert any(function in m for m in errors), \
        f"{name}: no message with status Error naming {function}; log: {call.logs}"


@pytest.mark.parametrize("api, key, state", RUNS, ids=[f"{a}-{k}-{s}" for a, k, s in RUNS])
def test_after_the_refused_calls_the_instance_completes_a_fresh_instances_run_bit_for_bit(runs, api, key, state):
    fresh, outputs = runs[api, key]["fresh"]
    assert fresh.crash() is None, f"the fresh instance's run: {fresh.crash()}"
    assert all(fresh.calls[i].status == 0 for i in range(len(fresh.lines))), \
        [(fresh.lines[i][:60], c.status, c.logs) for i, c in fresh.calls.items() if c.status != 0]
    expected = [[x for i in read for x in fresh.calls[i].values] for read in outputs]
    assert len(expected) == sm.STEPS and all(expected)
    run, script = runs[api, key][state]
    problem = _reached(run, script)
    assert problem is None, problem
    assert run.crash() is None, f"{state}: the host did not end cleanly: {run.crash()}"
    for i in script.complete:
        call = run.calls[i]
        assert call.status == 0, \
            f"{state}: the legal run's {script.lines[i][:80]!r} returned {call.status}: {call.logs}"
    got = [[x for i in read for x in run.calls[i].values] for read in script.outputs]
    want = expected[script.first_step:script.first_step + len(got)]
    assert len(got) == len(want) > 0
    for k, (a, b) in enumerate(zip(got, want)):
        differ = [j for j, (x, y) in enumerate(zip(a, b)) if x.hex() != y.hex()]
        assert len(a) == len(b) and not differ, \
            f"{state}: outputs after step {script.first_step + k} differ from a fresh instance's at {differ[:5]}"


def test_the_cases_collected_are_those_the_scripts_make(runs):
    # the names collected from the table alone equal the cases made from each FMU's modelDescription: none is
    # skipped on the bearing, and the drive and the time table lack only what they have no variable for
    for (api, key), by_state in runs.items():
        for state in _states(key):
            made = [case.name for case in by_state[state][1].cases.values()]
            collected = _case_names(key, state)
            assert set(made) <= set(collected), (api, key, state, set(made) - set(collected))
            if key.startswith("bearing"):
                assert sorted(made) == sorted(collected), (api, key, state, set(collected) - set(made))


def test_the_comparison_sees_a_change_that_a_call_lets_through(runs, fmus, c_hosts, tmp_path):
    # the control of the test above: a legal call that changes the run (a tunable parameter set between steps,
    # in place of the refused calls) shows in the outputs compared, from the first step after it on
    fmu, folder = fmus["bearing2"]
    fresh, outputs = runs["c", "bearing2"]["fresh"]
    script = sm.state_script(fmu, "StepComplete", {}, subset=())
    start = script.lines.index("@ complete StepComplete")
    lines = script.lines[:start] + [f"fmi2SetReal {fmu.vr('friction_coefficient')} 0.2"] + script.lines[start:]
    run = Run("c", fmu, folder, lines, tmp_path / "control.txt", c_hosts)
    assert run.crash() is None and all(c.status == 0 for c in run.calls.values())
    shifted = [[i + 1 for i in read] for read in script.outputs]
    got = [[x for i in read for x in run.calls[i].values] for read in shifted]
    want = [[x for i in read for x in fresh.calls[i].values] for read in outputs][script.first_step:]
    assert got[0] == want[0]  # the outputs of before the change
    assert got[1] != want[1] and got[2] != want[2]


def test_the_table_gives_every_state_its_refused_calls():
    # the standard's table, read back: a few rows that the cases rest on
    assert not sm.allowed(2, "fmi2DoStep", "Instantiated") and not sm.allowed(2, "fmi2DoStep", "Terminated")
    assert sm.allowed(2, "fmi2GetReal", "Terminated") and not sm.allowed(2, "fmi2GetReal", "Instantiated")
    assert not sm.allowed(3, "fmi3SetFloat64", "Terminated") and sm.allowed(3, "fmi3DoStep", "StepMode")
    # every reachable state forbids something, and every function is forbidden somewhere reached or allowed
    for version, states in ((2, sm.FMI2_STATES), (3, sm.FMI3_STATES)):
        table = sm.FMI2_ALLOWED if version == 2 else sm.FMI3_ALLOWED
        for state in states:
            assert any(not sm.allowed(version, f, state) for f in table), state
    assert len(CASES) > 150, len(CASES)


def test_valgrind_finds_no_invalid_access_in_the_refused_calls(fmus, c_hosts, runs, tmp_path):
    # minutes on a loaded machine: opt-in
    if os.environ.get("SLEWING_TEST_VALGRIND") != "1":
        pytest.skip("set SLEWING_TEST_VALGRIND=1 to run the C host's scripts under valgrind (minutes)")
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        pytest.skip("valgrind is not installed")
    from test_fmu_hosts import _valgrind_errors

    problems = []
    for key, state in (("bearing2", "StepComplete"), ("bearing2", "Terminated"), ("bearing3", "StepMode")):
        fmu, folder = fmus[key]
        script = runs["c", key][state][1]
        run = Run("c", fmu, folder, script.lines, tmp_path / f"{key}_{state}.txt", c_hosts,
                  wrapper=(valgrind, "--num-callers=30"))
        if run.crash():
            problems.append(f"{key} {state}: {run.crash()}")
        # (a legal run alone reports none: an invalid access here comes with a call that was let through)
        invalid = [e for e in _valgrind_errors(run.stderr) if e.startswith(("Invalid read", "Invalid write",
                                                                            "Invalid free"))]
        problems += [f"{key} {state}: {e[:1500]}" for e in invalid]
    assert problems == []
