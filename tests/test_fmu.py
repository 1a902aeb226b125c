"""The bearing FMU, driven by fmpy (and by the ecos C++ host): model description,
outputs against the library, rollback, instances, bad input."""
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from slewing_model import Loads, load_bearing
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

ROOT = Path(__file__).resolve().parents[1]
BEARING = ROOT / "examples" / "bearings" / "table3_errors.toml"


def test_model_description_is_valid(table3_fmu):
    assert validate_fmu(str(table3_fmu)) == []
    md = read_model_description(str(table3_fmu))
    variables = {v.name: v for v in md.modelVariables}
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    for v in md.modelVariables:
        assert v.description, v.name
        if v.type == "Real":
            assert v.unit, v.name
    for name in ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"):
        assert variables[name].causality == "input" and variables[name].start is not None
    names = set(variables)
    assert {"ball[67].Q4", "ball[1].alpha13", "ball[67].alpha24", "friction_torque", "static_safety_factor"} <= names
    assert {u.variable.name for u in md.initialUnknowns} == {v.name for v in md.modelVariables if v.causality == "output"}
    assert md.defaultExperiment is not None


def test_runtime_is_numpy_only(table3_fmu, tmp_path):
    # the FMU's Python must not need scipy or scikit-fem: run it with both made unimportable
    script = tmp_path / "run.py"
    script.write_text(
        "import sys\nsys.modules['scipy'] = None\nsys.modules['skfem'] = None\n"
        "from fmpy import simulate_fmu\n"
        f"r = simulate_fmu({str(table3_fmu)!r}, stop_time=0.02, step_size=0.01, start_values={{'Fz': 2e4}})\n"
        "print(r['max_ball_load'][-1])\n")
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert float(out.stdout.split()[-1]) > 0
    with zipfile.ZipFile(table3_fmu) as z:
        # the model's sources (resources/), not the Python runtime the FMU carries (binaries/)
        sources = [z.read(n).decode() for n in z.namelist()
                   if n.startswith("resources/") and n.endswith(".py") and "pythonfmu" not in n]
    assert not any("import scipy" in s or "from scipy" in s or "skfem" in s for s in sources)


#: the modules of pythonfmu's package that build FMUs (an FMU never imports them)
BUILDER_MODULES = ("builder.py", "csvbuilder.py", "deploy.py", "__main__.py")


def test_the_fmus_pythonfmu_does_not_import_its_builder(table3_fmu, table3_fmu3):
    """pythonfmu's FMU builder (argparse, zipfile, xml: 30-40 ms of each instantiation) is not imported by the
    FMU's copy of pythonfmu, FMI 2.0 and 3.0; its slave classes are (the FMU runs: the tests above)."""
    for fmu, package in ((table3_fmu, "pythonfmu"), (table3_fmu3, "pythonfmu3")):
        with zipfile.ZipFile(fmu) as z:
            init = z.read(f"resources/{package}/__init__.py").decode()
            modules = {n: z.read(n).decode() for n in z.namelist() if n.startswith(f"resources/{package}/")
                       and n.endswith(".py") and n.rsplit("/", 1)[1] not in BUILDER_MODULES}
        assert "from .builder import" not in init, init
        assert re.search(r"^from \.fmi[23]slave import", init, flags=re.M), init
        # nor pathlib (unused) and xml (the model description's) at import: fmu_build/shim.py's RUN_TIME_EDITS
        assert modules and not [n for n, text in modules.items()
                                if re.search(r"^(from|import) (pathlib|xml)", text, flags=re.M)], list(modules)


#: run with an unpacked FMU's resources (argv[1]) first on the path: instantiates the slave as pythonfmu does,
#: initialises it, takes a step and prints the modules that imported (not those this Python starts with)
_INSTANTIATE = """
import sys
started = set(sys.modules)
sys.path.insert(0, sys.argv[1])
import SlewingBearing
slave = SlewingBearing.SlewingBearing(instance_name='x', resources=sys.argv[1], visible=False)
slave.enter_initialization_mode()
slave.exit_initialization_mode()
slave.Fz = 3e4
assert slave.do_step(0.0, 0.01)
print(' '.join(sorted(set(sys.modules) - started)))
"""


def test_an_instance_imports_no_xml_pathlib_zipfile_or_traceback(table3_fmu, tmp_path):
    """What an instance's start and step leave out: xml (the model description's, written when the FMU is built),
    pathlib (imported by pythonfmu, unused; made lazy or left out in the FMU's copy), zipfile and shutil (an .npz
    file's: the FMU carries the superelement as .npy files), traceback (an error's) and the connected structures'
    module (a bearing without them)."""
    with zipfile.ZipFile(table3_fmu) as z:
        z.extractall(tmp_path, [n for n in z.namelist() if n.startswith("resources/")])
    run = subprocess.run([sys.executable, "-c", _INSTANTIATE, str(tmp_path / "resources")], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    modules = set(run.stdout.split())
    assert {"SlewingBearing", "pythonfmu.fmi2slave", "slewing_model.simulation.simulator"} <= modules
    assert not modules & {"xml", "xml.etree.ElementTree", "pathlib", "zipfile", "shutil", "traceback",
                          "slewing_model.bearing.connection"}, sorted(modules)


LOADS = {"Fx": 8e3, "Fy": -3e3, "Fz": 3e4, "Mx": 1.5e3, "My": -2.5e3, "psi": 0.4, "omega": 0.05}


def _library_steps(loads, psi, omega, steps, **settings):
    """The library used as the FMU uses it: ``steps`` warm-started steps with these inputs."""
    from slewing_model.rings.superelement import build_superelement

    bearing = load_bearing(BEARING)
    se = build_superelement(bearing, mesh="coarse", bc="free")
    sim = BearingSimulator(bearing, se, SimulatorSettings(**settings))
    return [sim.step(loads, psi, omega) for _ in range(steps)]


def test_constant_loads_give_the_library_solution(table3_fmu):
    names = ["x", "z", "rx", "ry", "friction_torque", "friction_torque_magnitude", "max_ball_load",
             "max_contact_pressure", "static_safety_factor", "ball[1].Q1", "ball[20].Q2", "ball[40].alpha13"]
    res = simulate_fmu(str(table3_fmu), stop_time=0.03, step_size=0.01, start_values=LOADS, output=names)
    # fmpy: outputs at initialisation, then 3 steps; the library steps as often
    steps = _library_steps(Loads(*(LOADS[k] for k in ("Fx", "Fy", "Fz", "Mx", "My"))), LOADS["psi"], LOADS["omega"], 4)
    ref = steps[-1]
    d = ref.distribution
    expected = {"x": d.displacement[0], "z": d.displacement[2], "rx": d.displacement[3], "ry": d.displacement[4],
                "friction_torque": ref.friction_torque, "friction_torque_magnitude": ref.friction_torque_magnitude,
                "max_ball_load": d.max_ball_load, "max_contact_pressure": d.max_contact_pressure,
                "static_safety_factor": d.static_safety_factor, "ball[1].Q1": d.contact_load[0, 0],
                "ball[20].Q2": d.contact_load[19, 1], "ball[40].alpha13": d.contact_angle[39, 0]}
    for name, value in expected.items():
        assert res[name][-1] == pytest.approx(value, rel=1e-9, abs=1e-12), name
    assert ref.friction_torque < 0 < LOADS["omega"]  # opposes the speed
    # the warm starts change the converged friction torque by less than its tolerance
    # (SimulatorSettings.friction_tolerance = 1e-5 bounds the relative torque error)
    assert steps[0].friction_torque == pytest.approx(ref.friction_torque, rel=1e-5)


def _inputs(t, **columns):
    names = ["time", "Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"]
    data = np.zeros(len(t), dtype=[(n, np.float64) for n in names])
    data["time"] = t
    for k, v in columns.items():
        data[k] = v
    return data


def test_outputs_follow_a_load_ramp_smoothly(table3_fmu):
    t = np.linspace(0, 1, 101)
    res = simulate_fmu(str(table3_fmu), stop_time=1.0, step_size=0.01, input=_inputs(t, Fz=1e4 + 5e4 * t, omega=0.02),
                       output=["z", "max_ball_load", "friction_torque_magnitude"])
    z, q = res["z"][2:], res["max_ball_load"][2:]
    assert np.all(np.diff(z) > 0) and np.all(np.diff(q) > 0)
    # smooth: no jump larger than a few times the mean increment
    for y in (z, q, res["friction_torque_magnitude"][2:]):
        steps = np.abs(np.diff(y))
        assert steps.max() < 5 * steps.mean()


def test_friction_varies_with_psi_and_opposes_omega(table3_fmu):
    period = 2.0
    t = np.linspace(0, period, 201)
    results = {}
    for sign in (1, -1):
        # a slight preload: the errors under the balls decide which balls keep four contacts
        res = simulate_fmu(str(table3_fmu), stop_time=period, step_size=0.01, start_values={"preload": 5e-6},
                           input=_inputs(t, Fz=5e3, psi=sign * 2 * np.pi * t / period, omega=sign * 2 * np.pi / period),
                           output=["friction_torque", "friction_torque_magnitude"])
        results[sign] = res
        torque = res["friction_torque"][1:]
        assert np.all(np.sign(torque) == -sign)
        magnitude = res["friction_torque_magnitude"][1:]
        assert np.ptp(magnitude) > 0.05 * magnitude.mean()  # errors under the balls change with psi


def _slave(path, name="bearing"):
    """An instantiated FMU2Slave whose log messages are collected in ``messages``."""
    from slewing_drives.cosimulation import logging_callbacks

    md = read_model_description(str(path))
    unzipped = extract(str(path))
    messages = []

    def logger(component, instance, status, category, message):
        messages.append(message.decode())

    callbacks = logging_callbacks(logger)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=name)
    fmu.instantiate(loggingOn=True, callbacks=callbacks)
    fmu._keep_callbacks = callbacks  # the C side keeps pointers to them
    refs = {v.name: v.valueReference for v in md.modelVariables}
    return fmu, refs, messages, unzipped


@pytest.fixture
def slave(table3_fmu):
    fmu, refs, messages, unzipped = _slave(table3_fmu)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    yield fmu, refs, messages
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)


def _step(fmu, refs, t, **inputs):
    fmu.setReal([refs[k] for k in inputs], list(inputs.values()))
    fmu.doStep(t, 0.01)
    names = ["z", "rx", "friction_torque", "max_ball_load", "ball[5].Q1", "ball[60].Q2"]
    return fmu.getReal([refs[n] for n in names])


def test_a_static_safety_factor_below_one_is_logged_as_a_warning_when_it_starts(slave):
    # table3 under Fz = 3 MN: its largest contact pressure passes ISO 76's 4200 MPa (the library's
    # LoadDistribution.warnings); a valid result, so the step is done, and the host is told once
    fmu, refs, messages = slave
    factors = []
    for k, fz in enumerate([1e5, 3e6, 3e6, 1e5, 3e6]):
        fmu.setReal([refs["Fz"]], [fz])
        # the step's status stays fmi2OK: the warning is for the log (hosts such as fmusim end on fmi2Warning)
        assert fmu.fmi2DoStep(fmu.component, k * 0.01, 0.01, 1) == 0
        factors.append(fmu.getReal([refs["static_safety_factor"]])[0])
    assert factors[0] > 1 and factors[1] < 1 and factors[3] > 1
    warned = [m for m in messages if "static safety factor" in m and "is below 1" in m]
    assert len(warned) == 2, warned                 # where it starts, and again after it cleared
    assert f"static safety factor {factors[1]:.3g} is below 1" in warned[0]
    assert "t = 0.01" in warned[0] and "t = 0.04" in warned[1]


def test_bounded_steps_answer_as_the_library_and_flag_what_they_carry_over(table3_fmu):
    """step_work = 2 (bounded): a tilting moment turned by a quarter turn in one step is answered
    over several steps, each flagged by equilibrium_residual above the tolerance until the
    equilibrium is reached; the values are the library's bounded simulator's (the FMU holds no
    physics). (A moment reversed, as this test had it, is now reached within one step's bound
    here: the held-rings start, ``BimeSolver._held_rings_start``.)"""
    from slewing_model.rings.superelement import build_superelement

    fmu, refs, _, unzipped = _slave(table3_fmu)
    names = ["equilibrium_residual", "z", "rx", "max_ball_load", "friction_torque", "ball[20].Q2"]
    inputs = ["Fz", "Mx", "My", "psi", "omega"]
    forward, turned = [1e5, 1.5e4, 5e4, 0.4, 0.05], [1e5, -5e4, 1.5e4, 0.4, 0.05]
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setInteger([refs["step_work"]], [2])
    fmu.setReal([refs[n] for n in inputs], forward)                  # the inputs at the start, as hosts set them
    fmu.exitInitializationMode()
    bearing = load_bearing(BEARING)
    sim = BearingSimulator(bearing, build_superelement(bearing, mesh="coarse", bc="free"),
                           SimulatorSettings(step_work="bounded", friction_kernel="numpy", contact_kernel="numpy"))
    sim.step(Loads(Fz=forward[0], Mx=forward[1], My=forward[2]), forward[3], forward[4])
    residuals = []
    try:
        for k in range(10):
            values = forward if k < 2 else turned
            fmu.setReal([refs[n] for n in inputs], values)
            assert fmu.fmi2DoStep(fmu.component, 0.01 * k, 0.01, 1) == 0
            out = dict(zip(names, fmu.getReal([refs[n] for n in names])))
            r = sim.step(Loads(Fz=values[0], Mx=values[1], My=values[2]), values[3], values[4])
            d = r.distribution
            expected = {"equilibrium_residual": d.residual, "z": d.displacement[2], "rx": d.displacement[3],
                        "max_ball_load": d.max_ball_load, "friction_torque": r.friction_torque,
                        "ball[20].Q2": d.contact_load[19, 1]}
            for name, value in expected.items():
                assert out[name] == pytest.approx(value, rel=1e-9, abs=1e-15), (k, name)
            residuals.append(out["equilibrium_residual"])
    finally:
        fmu.terminate()
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    tolerance = 1e-7                                        # the parameter's default
    assert max(residuals[:2]) <= tolerance < residuals[2]    # the turned moment's step is flagged ...
    assert residuals[-1] <= tolerance                       # ... and the equilibrium reached within 8 steps


def test_rollback_repeats_steps_exactly(slave):
    fmu, refs, _ = slave
    for k in range(3):
        _step(fmu, refs, 0.01 * k, Fz=1e4 * (k + 1), psi=0.1 * k, omega=0.1)
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    first = [_step(fmu, refs, 0.03 + 0.01 * k, Fz=4e4 + 3e3 * k, Mx=500.0 * k, psi=0.3 + 0.1 * k, omega=0.1)
             for k in range(4)]
    fmu.setFMUstate(state)
    again = [_step(fmu, refs, 0.03 + 0.01 * k, Fz=4e4 + 3e3 * k, Mx=500.0 * k, psi=0.3 + 0.1 * k, omega=0.1)
             for k in range(4)]
    assert again == first
    fmu.setFMUstate(fmu.deSerializeFMUstate(serialized))
    assert [_step(fmu, refs, 0.03 + 0.01 * k, Fz=4e4 + 3e3 * k, Mx=500.0 * k, psi=0.3 + 0.1 * k, omega=0.1)
            for k in range(4)] == first
    fmu.freeFMUstate(state)


def test_a_corrupted_serialized_state_is_refused_and_the_instance_runs_on(slave):
    # the header holds the payload's CRC-32: one byte changed in the content is fmi2Error before
    # pythonfmu reads it, and the intact state is read back and stepped from
    fmu, refs, messages = slave
    for k in range(2):
        _step(fmu, refs, 0.01 * k, Fz=1e4 * (k + 1), omega=0.1)
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    corrupted = bytearray(serialized)
    corrupted[-2] ^= 0x01
    with pytest.raises(Exception, match="status 3"):
        fmu.deSerializeFMUstate(bytes(corrupted))
    assert any("fmi2DeSerializeFMUstate" in m and "checksum does not match: corrupted" in m for m in messages), messages
    fmu.setFMUstate(fmu.deSerializeFMUstate(serialized))
    _step(fmu, refs, 0.02, Fz=3e4, omega=0.1)
    fmu.freeFMUstate(state)


def test_two_instances_run_independently(table3_fmu):
    runs = {}
    for loads in ({"Fz": 2e4}, {"Fz": 5e4, "My": 3e3}):
        fmu, refs, _, unzipped = _slave(table3_fmu, name="alone")
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        runs[tuple(loads)] = [_step(fmu, refs, 0.01 * k, psi=0.05 * k, omega=0.05, **loads) for k in range(3)]
        fmu.terminate()
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    a, ra, _, ua = _slave(table3_fmu, name="a")
    b, rb, _, ub = _slave(table3_fmu, name="b")
    for f in (a, b):
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
        f.exitInitializationMode()
    out_a, out_b = [], []
    for k in range(3):  # interleaved in one process
        out_a.append(_step(a, ra, 0.01 * k, psi=0.05 * k, omega=0.05, Fz=2e4))
        out_b.append(_step(b, rb, 0.01 * k, psi=0.05 * k, omega=0.05, Fz=5e4, My=3e3))
    assert out_a == runs[("Fz",)] and out_b == runs[("Fz", "My")]
    for f in (a, b):
        f.terminate()
        f.freeInstance()
    for folder in (ua, ub):
        shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.parametrize("inputs,message", [
    ({"Fz": float("nan")}, "input Fz = nan: must be finite"),
    ({"omega": float("inf")}, "input omega = inf: must be finite"),
    ({"Fz": 5e7}, "beyond what the bearing can carry"),
])
def test_bad_input_is_refused_with_a_logged_reason(slave, inputs, message):
    fmu, refs, messages = slave
    fmu.setReal([refs[k] for k in inputs], list(inputs.values()))
    with pytest.raises(Exception) as info:
        fmu.doStep(0.0, 0.01)
    assert "fmi2Discard" in str(info.value) or "status 2" in str(info.value)
    assert any(message in m for m in messages), messages
    # the instance is still alive: the step retried from its start with a good input succeeds
    fmu.setReal([refs["Fz"], refs["omega"]], [1e4, 0.1])
    fmu.doStep(0.0, 0.01)
    fmu.doStep(0.01, 0.01)


def test_a_step_must_start_at_the_instance_time(slave):
    # a later currentCommunicationPoint would skip an interval: fmi2Error, nothing changed; after a
    # refused step, the next starts at the refused step's start, not at its end
    fmu, refs, messages = slave
    _step(fmu, refs, 0.0, Fz=1e4, omega=0.1)
    with pytest.raises(Exception, match="status 3"):
        fmu.doStep(0.02, 0.01)
    assert any("fmi2DoStep: currentCommunicationPoint = 0.02 but the last step ended at 0.01" in m
               for m in messages), messages
    fmu.setReal([refs["Fz"]], [float("nan")])
    with pytest.raises(Exception, match="status 2"):
        fmu.doStep(0.01, 0.01)
    fmu.setReal([refs["Fz"]], [2e4])
    with pytest.raises(Exception, match="status 3"):
        fmu.doStep(0.02, 0.01)
    assert any("fmi2DoStep: currentCommunicationPoint = 0.02 but the refused step started at 0.01" in m
               for m in messages), messages
    fmu.doStep(0.01, 0.01)
    fmu.doStep(0.02, 0.01)


def test_the_error_state_allows_what_the_standard_allows(slave):
    # the same step refused twice is an Error of the model: the state Error allows the getters, the
    # status and FMU state functions (FMI 2.0 section 4.2.4); fmi2SetFMUstate leaves it
    fmu, refs, messages = slave
    _step(fmu, refs, 0.0, Fz=1e4, omega=0.1)
    state = fmu.getFMUstate()
    before = fmu.getReal([refs["z"]])
    fmu.setReal([refs["Fz"]], [float("nan")])
    for status in (2, 3):
        with pytest.raises(Exception, match=f"status {status}"):
            fmu.doStep(0.01, 0.01)
    assert fmu.getBooleanStatus(3)                                   # fmi2Terminated
    assert fmu.getReal([refs["z"]]) == before                         # getters answer
    for call, name in ((lambda: fmu.setReal([refs["Fz"]], [1e4]), "fmi2SetReal"),
                       (lambda: fmu.doStep(0.01, 0.01), "fmi2DoStep"),
                       (lambda: fmu.terminate(), "fmi2Terminate")):
        with pytest.raises(Exception, match="status 3"):
            call()
        assert any(f"{name}: not allowed in state Error" in m for m in messages), (name, messages)
    fmu.setFMUstate(state)                                           # back to StepComplete at t = 0.01
    assert not fmu.getBooleanStatus(3)
    _step(fmu, refs, 0.01, Fz=2e4, omega=0.1)
    fmu.freeFMUstate(state)


def test_bad_input_is_explained_in_the_log(slave):
    fmu, refs, messages = slave
    fmu.setReal([refs["Fz"]], [float("nan")])
    with pytest.raises(Exception):
        fmu.doStep(0.0, 0.01)
    assert any("input Fz = nan: must be finite (not NaN or infinite)" in m for m in messages), messages


def test_unknown_parameter_value_is_refused(table3_fmu):
    fmu, refs, messages, unzipped = _slave(table3_fmu)
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.setInteger([refs["ring_model"]], [7])
        fmu.enterInitializationMode()
        with pytest.raises(Exception) as info:  # the instance cannot run: fmi2Error, not a discarded step
            fmu.exitInitializationMode()
        assert "status 3" in str(info.value)
        assert any("parameter ring_model = 7: must be one of 1 (rigid), 2 (flexible)" in m for m in messages), messages
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)


def _ecos_binary(tmp_path):
    try:
        import ecospy
    except ImportError:
        pytest.skip("ecospy is not installed")
    source = Path(ecospy.__file__).parent / "binaries" / "ecos"
    sys.path.insert(0, str(ROOT / "examples" / "ssp"))
    from ssp_hosts import libtbb_missing

    if (missing := libtbb_missing()) is not None:
        pytest.skip(f"{missing} (make installs it when run as root)")
    binary = tmp_path / "ecos"
    shutil.copy2(source, binary)
    binary.chmod(0o755)  # the wheel ships it without the executable bit
    return binary


def test_ecos_cpp_host_gives_the_fmpy_outputs(table3_fmu, tmp_path):
    ecos = _ecos_binary(tmp_path)
    fmu = tmp_path / "bearing.fmu"
    shutil.copy2(table3_fmu, fmu)
    values = {"Fz": 3e4, "Mx": 1.5e3, "My": -2.5e3, "psi": 0.4, "omega": 0.05}
    actions = "".join(f'<ecos:variable id="instance::{k}"><ecos:real value="{v!r}"/></ecos:variable>'
                      for k, v in values.items())
    scenario = tmp_path / "scenario.xml"
    scenario.write_text('<?xml version="1.0" encoding="UTF-8"?>\n'
                        '<ecos:Scenario xmlns:ecos="http://github.com/Ecos-platform/libecos/resources/schema/ScenarioConfig">'
                        f'<ecos:action t="0">{actions}</ecos:action></ecos:Scenario>')
    # what a host started from a desktop has: no preload, no Python on PATH
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root"), "TMPDIR": str(tmp_path)}
    # 20 steps: ecos 0.7.2 divides by zero (SIGFPE) in its progress report for runs of fewer than 10 steps
    run = subprocess.run([str(ecos), "simulate", "--path", str(fmu), "--stepSize", "0.01", "--stopTime", "0.2",
                          "--scenarioConfig", str(scenario), "--noParallel", "-l", "warn"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    rows = [line.split(",") for line in (tmp_path / "bearing.csv").read_text().splitlines()]
    header = [h.strip() for h in rows[0]]
    last = rows[-1]
    names = ["z", "max_ball_load", "friction_torque", "ball[1].Q1", "ball[30].Q3", "ball[50].alpha24"]
    got = {n: float(last[header.index(f"instance::{n}[REAL]")]) for n in names}
    ref = simulate_fmu(str(table3_fmu), stop_time=0.2, step_size=0.01, start_values=values, output=names)
    for n in names:  # ecos writes 6 decimals
        assert got[n] == pytest.approx(ref[n][-1], rel=1e-6, abs=1.5e-6), n
