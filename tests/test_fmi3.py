"""The FMI 3.0 bearing FMU (pythonfmu3, per-ball arrays) against the FMI 2.0 one, both driven by fmpy."""
import math
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from conftest import BEARINGS, ROOT

sys.path.insert(0, str(ROOT / "fmu_src"))
from bearing_variables import BALL_ARRAYS, INPUTS, INTEGER_PARAMETERS, OUTPUTS, REAL_PARAMETERS  # noqa: E402

BALLS = 67  # table3


@pytest.fixture(scope="module")
def fmu3(table3_fmu3):
    """The FMI 3.0 FMU of the table3_fmu fixture's bearing (coarse superelement, free rings, standalone)."""
    return table3_fmu3


def test_model_description_is_valid_with_arrays(fmu3, table3_fmu):
    assert validate_fmu(str(fmu3)) == []
    md = read_model_description(str(fmu3))
    assert md.fmiVersion == "3.0"
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    variables = {v.name: v for v in md.modelVariables}
    for v in md.modelVariables:
        assert v.description, v.name
        if v.type == "Float64":
            assert v.unit, v.name
    # the FMI 2.0 FMU's inputs, parameters and scalar outputs, with the same units and causalities
    md2 = read_model_description(str(table3_fmu))
    scalars2 = {v.name: v for v in md2.modelVariables if not v.name.startswith("ball[")}
    assert set(scalars2) == set(variables) - {"time"} - {name for name, *_ in BALL_ARRAYS}
    for name, v2 in scalars2.items():
        v3 = variables[name]
        assert (v3.causality, v3.variability, v3.unit, v3.description) == (v2.causality, v2.variability, v2.unit,
                                                                         v2.description), name
        if v2.causality in ("input", "parameter"):
            assert float(v3.start) == pytest.approx(float(v2.start), rel=1e-15), name
    for name, unit, columns, _, _ in BALL_ARRAYS:
        v = variables[name]
        assert v.causality == "output" and v.unit == unit
        assert [int(d.start) for d in v.dimensions] == [BALLS, len(columns)]
    # every output depends on every input; initial unknowns also on the parameters
    inputs = {variables[name] for name, _, _ in INPUTS}
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    assert {u.variable for u in md.outputs} == set(outputs)
    assert all(set(u.dependencies) == inputs for u in md.outputs)
    parameters = {variables[name] for name, *_ in REAL_PARAMETERS + INTEGER_PARAMETERS}
    assert all(set(u.dependencies) == inputs | parameters for u in md.initialUnknowns)
    assert md.defaultExperiment is not None
    # 6 B scalars in FMI 2.0, three arrays in FMI 3.0
    assert sum(v.name.startswith("ball[") for v in md2.modelVariables) == 8 * BALLS


class _Pair:
    """The FMI 2.0 and FMI 3.0 FMUs of one bearing, instantiated side by side (logging on);
    ``fmu2 = None``: the FMI 3.0 FMU alone."""

    def __init__(self, fmu2, fmu3, start_values=None):
        from slewing_drives.cosimulation import logging_callbacks

        self.messages = {2: [], 3: []}
        self.md3 = read_model_description(str(fmu3))
        self.dirs = [extract(str(fmu3))]
        self.refs3 = {v.name: v.valueReference for v in self.md3.modelVariables}
        self.f2 = None
        if fmu2 is not None:
            self.md2 = read_model_description(str(fmu2))
            self.dirs.append(extract(str(fmu2)))
            self.refs2 = {v.name: v.valueReference for v in self.md2.modelVariables}
            self._callbacks = logging_callbacks(lambda c, i, s, cat, m: self.messages[2].append(m.decode()))
            self.f2 = FMU2Slave(guid=self.md2.guid, unzipDirectory=self.dirs[1],
                                modelIdentifier=self.md2.coSimulation.modelIdentifier, instanceName="fmi2")
            self.f2.instantiate(loggingOn=True, callbacks=self._callbacks)
        self.f3 = FMU3Slave(guid=self.md3.guid, unzipDirectory=self.dirs[0],
                            modelIdentifier=self.md3.coSimulation.modelIdentifier, instanceName="fmi3")
        self.f3.instantiate(loggingOn=True, logMessage=lambda env, status, cat, m: self.messages[3].append(m.decode()))
        for name, value in (start_values or {}).items():
            if isinstance(value, int):
                self.f3.setInt32([self.refs3[name]], [value])
            else:
                self.f3.setFloat64([self.refs3[name]], [value])
        self.f3.enterInitializationMode(startTime=0.0)
        self.f3.exitInitializationMode()
        if self.f2 is not None:
            self.f2.setupExperiment(startTime=0.0)
            for name, value in (start_values or {}).items():
                (self.f2.setInteger if isinstance(value, int) else self.f2.setReal)([self.refs2[name]], [value])
            self.f2.enterInitializationMode()
            self.f2.exitInitializationMode()

    def set(self, **inputs):
        self.f2.setReal([self.refs2[k] for k in inputs], list(inputs.values()))
        self.f3.setFloat64([self.refs3[k] for k in inputs], list(inputs.values()))

    def scalars(self):
        names = [name for name, _, _ in OUTPUTS]
        a = self.f2.getReal([self.refs2[n] for n in names]) + self.f2.getInteger([self.refs2["balls_in_four_point_contact"]])
        b = self.f3.getFloat64([self.refs3[n] for n in names]) + self.f3.getInt32([self.refs3["balls_in_four_point_contact"]])
        return np.array(a, dtype=float), np.array(b, dtype=float)

    def arrays(self):
        """Per-ball results: FMI 2.0 scalars gathered into arrays, and the FMI 3.0 arrays."""
        pairs = {}
        for name, _, columns, _, _ in BALL_ARRAYS:
            refs = [self.refs2[f"ball[{i + 1}].{c}"] for i in range(BALLS) for c in columns]
            a = np.array(self.f2.getReal(refs)).reshape(BALLS, len(columns))
            b = np.array(self.f3.getFloat64([self.refs3[name]], nValues=BALLS * len(columns))).reshape(BALLS, -1)
            pairs[name] = (a, b)
        return pairs

    def close(self):
        for f in (self.f2, self.f3):
            if f is None:
                continue
            f.terminate()
            f.freeInstance()
        for d in self.dirs:
            shutil.rmtree(d, ignore_errors=True)


def _inputs(k):
    """Changing loads and a turning ring: step k of the comparison run."""
    t = 0.01 * k
    return {"Fx": 4e3 * math.sin(3 * t), "Fy": -2e3, "Fz": 1.5e4 + 4e4 * t, "Mx": 1.5e3 * math.cos(5 * t),
            "My": -2e3 + 1e4 * t, "psi": 0.5 * t + 0.3 * t * t, "omega": 0.5 + 0.6 * t}


@pytest.fixture(scope="module")
def comparison(table3_fmu, fmu3):
    """40 steps of both FMUs with the same changing inputs: scalar outputs and per-ball results of each step."""
    pair = _Pair(table3_fmu, fmu3, {"preload": 5e-6})
    steps = []
    try:
        for k in range(40):
            pair.set(**_inputs(k))
            pair.f2.doStep(0.01 * k, 0.01)
            pair.f3.doStep(0.01 * k, 0.01)
            steps.append((pair.scalars(), pair.arrays()))
    finally:
        pair.close()
    return steps


def test_scalar_outputs_equal_the_fmi2_fmu(comparison):
    friction = []
    for (a, b), _ in comparison:
        assert np.all(np.abs(b - a) <= 1e-12 * np.abs(a)), (a, b)
        friction.append(a[[name for name, _, _ in OUTPUTS].index("friction_torque_magnitude")])
    # the run is not trivial: the friction torque and the four-point contact count change over it
    assert np.ptp(friction) > 0.05 * np.mean(friction)
    assert len({int(a[-1]) for (a, _), _ in comparison}) > 1


def test_arrays_equal_the_fmi2_per_ball_scalars(comparison):
    for _, arrays in comparison:
        for name, (a, b) in arrays.items():
            assert np.array_equal(a, b), name
    _, last = comparison[-1]
    q = last["contact_load"][1]
    # row-major layout: contacts 1 and 3 (and 2 and 4) of one ball carry the same load
    assert np.array_equal(q[:, 0], q[:, 2]) and np.array_equal(q[:, 1], q[:, 3]) and q.max() > 0
    d = last["interference"][1]
    assert np.all((d > 0) == (q[:, :2] > 0))  # a ball diagonal is loaded exactly where it is compressed


def test_rollback_and_serialized_state_repeat_steps(fmu3):
    pair = _Pair(None, fmu3)
    f, refs = pair.f3, pair.refs3
    names = ["z", "friction_torque", "max_ball_load"]

    def run(k0):
        out = []
        for k in range(k0, k0 + 3):
            f.setFloat64([refs[n] for n in _inputs(k)], list(_inputs(k).values()))
            f.doStep(0.01 * k, 0.01)
            out.append(f.getFloat64([refs[n] for n in names]) + f.getFloat64([refs["contact_load"]], nValues=4 * BALLS))
        return out

    try:
        run(0)
        state = f.getFMUState()
        serialized = f.serializeFMUState(state)
        first = run(3)
        f.setFMUState(state)
        assert run(3) == first
        f.setFMUState(f.deserializeFMUState(serialized))
        assert run(3) == first
        f.freeFMUState(state)
    finally:
        pair.close()


@pytest.mark.parametrize("inputs,message", [
    ({"Fz": float("nan")}, "input Fz = nan: must be finite"),
    ({"omega": float("inf")}, "input omega = inf: must be finite"),
    ({"Fz": 5e7}, "beyond what the bearing can carry"),
])
def test_bad_input_is_refused_as_by_the_fmi2_fmu(table3_fmu, fmu3, inputs, message):
    pair = _Pair(table3_fmu, fmu3)
    try:
        pair.set(**inputs)
        for version, f in ((2, pair.f2), (3, pair.f3)):
            with pytest.raises(FMICallException) as info:
                f.doStep(0.0, 0.01)
            assert info.value.status == 2, (version, info.value)  # Discard: the state kept
            assert any(message in m for m in pair.messages[version]), (version, pair.messages[version])
        # both instances are still alive: a good input steps again from the refused step's start, to the
        # same outputs
        pair.set(Fz=1e4, omega=0.1)
        pair.f2.doStep(0.0, 0.01)
        pair.f3.doStep(0.0, 0.01)
        a, b = pair.scalars()
        assert np.all(np.abs(b - a) <= 1e-12 * np.abs(a))
    finally:
        pair.close()


def _refused_parameter(path, version, name, value):
    """Instantiate one FMU with a bad integer parameter, initialise and step it: the call that was
    refused (its fmpy method name), its status, and the log."""
    messages = []
    md = read_model_description(str(path))
    unzipped = extract(str(path))
    ref = {v.name: v.valueReference for v in md.modelVariables}[name]
    kwargs = dict(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="bad")
    if version == 2:
        from slewing_drives.cosimulation import logging_callbacks

        f = FMU2Slave(**kwargs)
        callbacks = logging_callbacks(lambda c, i, s, cat, m: messages.append(m.decode()))
        f.instantiate(loggingOn=True, callbacks=callbacks)
        f.setupExperiment(startTime=0.0)
        f.setInteger([ref], [value])
        enter = f.enterInitializationMode
    else:
        f = FMU3Slave(**kwargs)
        f.instantiate(loggingOn=True, logMessage=lambda env, status, cat, m: messages.append(m.decode()))
        f.setInt32([ref], [value])
        enter = lambda: f.enterInitializationMode(startTime=0.0)  # noqa: E731
    refused = None
    try:
        for call, function in (("enterInitializationMode", enter), ("exitInitializationMode", f.exitInitializationMode),
                               ("doStep", lambda: f.doStep(0.0, 0.01))):
            try:
                function()
            except FMICallException as e:
                refused = (call, e.status)
                break
    finally:
        f.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    return refused, messages


def test_unknown_parameter_value_is_an_error_at_the_end_of_initialization(table3_fmu, fmu3):
    for version, path in ((2, table3_fmu), (3, fmu3)):
        refused, messages = _refused_parameter(path, version, "ring_model", 7)
        assert refused == ("exitInitializationMode", 3), (version, refused)  # fmi2Error / fmi3Error
        assert any("parameter ring_model = 7: must be one of 1 (rigid), 2 (flexible)" in m for m in messages), \
            (version, messages)


def test_same_step_refused_twice_is_an_error(table3_fmu, fmu3):
    pair = _Pair(table3_fmu, fmu3)
    try:
        pair.set(Fz=float("nan"))
        for version, f in ((2, pair.f2), (3, pair.f3)):
            statuses = []
            for _ in range(2):
                with pytest.raises(FMICallException) as info:
                    f.doStep(0.0, 0.01)
                statuses.append(info.value.status)
            assert statuses == [2, 3], (version, statuses)  # Discard, then Error
            assert any("refused again with the same inputs" in m for m in pair.messages[version]), version
        # FMI 3.0: after the Error only getters, the FMU state functions, reset and freeInstance
        with pytest.raises(FMICallException) as info:
            pair.f3.doStep(0.0, 0.01)
        assert info.value.status == 3
        assert "fmi3DoStep: not allowed in state Error (allowed: StepMode)" in pair.messages[3][-1]
        pair.f3.reset()
        pair.f3.enterInitializationMode(startTime=0.0)
        pair.f3.exitInitializationMode()
        pair.f3.setFloat64([pair.refs3["Fz"]], [1e4])
        pair.f3.doStep(0.0, 0.01)
    finally:
        pair.f2.freeInstance()
        pair.f3.freeInstance()
        for d in pair.dirs:
            shutil.rmtree(d, ignore_errors=True)


def _fresh3(fmu3, messages):
    md = read_model_description(str(fmu3))
    unzipped = extract(str(fmu3))
    f = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="rules")
    f.instantiate(loggingOn=False, logMessage=lambda env, status, cat, m: messages.append((status, m.decode())))
    return f, unzipped, {v.name: v.valueReference for v in md.modelVariables}


@pytest.mark.parametrize("misuse,text", [
    (lambda f, r: f.doStep(0.0, 0.01), "fmi3DoStep: not allowed in state Instantiated (allowed: StepMode)"),
    (lambda f, r: f.setFloat64([r["z"]], [1.0]), "fmi3SetFloat64: z (value reference 20) is an output"),
    (lambda f, r: f.setFloat64([999], [1.0]), "fmi3SetFloat64: value reference 999 is not a variable of this FMU"),
    (lambda f, r: f.setFloat64([r["ring_model"]], [1.0]), "is of type Int32, not Float64"),
    (lambda f, r: f.getFloat64([r["contact_load"]], nValues=3), "fmi3GetFloat64: nValues = 3"),
    (lambda f, r: f.deserializeFMUState(b"garbage" * 10), "(no header: wrong magic)"),
    (lambda f, r: f.enterEventMode(), "fmi3EnterEventMode: not allowed"),
])
def test_a_call_the_standard_forbids_is_an_error_that_changes_nothing(fmu3, misuse, text):
    messages = []
    f, unzipped, refs = _fresh3(fmu3, messages)
    try:
        with pytest.raises(FMICallException) as info:
            misuse(f, refs)
        assert info.value.status == 3  # fmi3Error, not forwarded
        assert any(status == 3 and text in m for status, m in messages), messages  # logged with logging off
        # the instance runs on as a fresh one
        f.enterInitializationMode(startTime=0.0)
        f.exitInitializationMode()
        f.setFloat64([refs["Fz"]], [1e4])
        f.doStep(0.0, 0.01)
        assert f.getFloat64([refs["z"]])[0] != 0
    finally:
        f.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)


def test_a_corrupted_serialized_state_is_refused_before_it_reaches_python(fmu3):
    # the header holds the payload's CRC-32: one byte changed in the content is fmi3Error, and the
    # instance runs on (its own serialized state, intact, is read back and stepped from)
    messages = []
    f, unzipped, refs = _fresh3(fmu3, messages)
    try:
        f.enterInitializationMode(startTime=0.0)
        f.exitInitializationMode()
        for k in range(2):
            f.setFloat64([refs[n] for n in _inputs(k)], list(_inputs(k).values()))
            f.doStep(0.01 * k, 0.01)
        state = f.getFMUState()
        serialized = f.serializeFMUState(state)
        corrupted = bytearray(serialized)
        corrupted[-2] ^= 0x01
        with pytest.raises(FMICallException) as info:
            f.deserializeFMUState(bytes(corrupted))
        assert info.value.status == 3
        assert any(status == 3 and "fmi3DeserializeFMUState" in m and "checksum does not match: corrupted" in m
                   for status, m in messages), messages
        f.setFMUState(f.deserializeFMUState(serialized))
        f.doStep(0.02, 0.01)
        f.freeFMUState(state)
    finally:
        f.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)


def test_nvalues_is_checked_without_the_model_description(fmu3):
    # the number of values of each variable comes from resources/fmi_variables.tsv: a host that unpacks
    # only the binaries and resources (fmpy's simulate_fmu may) gets the same check
    messages = []
    md = read_model_description(str(fmu3))
    unzipped = extract(str(fmu3))
    (Path(unzipped) / "modelDescription.xml").unlink()
    f = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="no_description")
    f.instantiate(loggingOn=False, logMessage=lambda env, status, cat, m: messages.append((status, m.decode())))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    try:
        f.enterInitializationMode(startTime=0.0)
        f.exitInitializationMode()
        with pytest.raises(FMICallException):
            f.getFloat64([refs["contact_load"]], nValues=3)
        assert any(status == 3 and f"has {4 * BALLS} values" in m for status, m in messages), messages
        assert len(f.getFloat64([refs["contact_load"]], nValues=4 * BALLS)) == 4 * BALLS
    finally:
        f.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)


def test_steps_continue_where_the_last_one_ended(fmu3):
    messages = []
    f, unzipped, refs = _fresh3(fmu3, messages)
    try:
        f.enterInitializationMode(startTime=1.0)
        f.exitInitializationMode()
        f.setFloat64([refs["Fz"]], [1e4])
        for t, h, text in ((0.0, 0.01, "currentCommunicationPoint = 0 but the instance is at t = 1"),
                           (1.0, 0.0, "communicationStepSize = 0 must be > 0")):
            with pytest.raises(FMICallException) as info:
                f.doStep(t, h)
            assert info.value.status == 3 and text in messages[-1][1], messages
        f.doStep(1.0, 0.01)
        state = f.getFMUState()
        f.doStep(1.01, 0.01)
        with pytest.raises(FMICallException):
            f.doStep(1.01, 0.01)  # back in time without a state
        f.setFMUState(state)  # the state's time: 1.01
        f.doStep(1.01, 0.01)
        f.freeFMUState(state)
        f.terminate()
        with pytest.raises(FMICallException):
            f.doStep(1.02, 0.01)
        assert "fmi3DoStep: not allowed in state Terminated" in messages[-1][1]
    finally:
        f.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)


def test_array_setter_reshapes_without_numpy_2_refusal(fmu3, tmp_path):
    # pythonfmu3 0.3.4 registers np.reshape(v, newshape=...) as the setter of every array;
    # the slave registers its own, which the default state restore would call
    import zipfile

    with zipfile.ZipFile(fmu3) as z:
        z.extractall(tmp_path)
    resources = tmp_path / "resources"
    sys.path.insert(0, str(resources))
    try:
        import importlib

        module = importlib.import_module("SlewingBearing3")
        slave = module.SlewingBearing3(instance_name="inproc", resources=str(resources))
    finally:
        sys.path.remove(str(resources))
    var = next(v for v in slave.vars.values() if v.name == "contact_load")
    values = np.arange(4.0 * BALLS)
    slave.set_float64([var.value_reference], values.tolist())
    assert slave._arrays["contact_load"].shape == (BALLS, 4)
    assert slave.get_float64([var.value_reference]) == values.tolist()


INPROCESS_THEN_BUILD = """
import sys
from fmpy import simulate_fmu
from fmu_build.shim import installed_builder
fmu, package = sys.argv[1], sys.argv[2]
simulate_fmu(fmu, stop_time=0.02, output_interval=0.01)  # in this process: its package copy comes first
copy = sys.modules[package]
try:
    __import__(package, fromlist=["FmuBuilder"]).FmuBuilder
    print("plain import found the builder")
except AttributeError:
    print("plain import: the FMU's copy, no builder")
with installed_builder(package) as builder:
    print("installed:", sys.modules[builder.__module__].__file__)
print("after:", sys.modules[package] is copy)
"""


@pytest.mark.parametrize("version", [2, 3])
def test_a_build_after_an_fmu_ran_in_process_uses_the_installed_builder(version, table3_fmu, fmu3):
    """fmpy runs an FMU in the calling process, where the FMU's own copy of pythonfmu (pythonfmu3), without its
    builder, then comes first: a build in that process still takes the installed package's builder, and the
    FMU's copy is back after it."""
    import subprocess
    import sysconfig

    fmu, package = {2: (table3_fmu, "pythonfmu"), 3: (fmu3, "pythonfmu3")}[version]
    run = subprocess.run([sys.executable, "-c", INPROCESS_THEN_BUILD, str(fmu), package], capture_output=True,
                         text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    lines = run.stdout.splitlines()
    assert "plain import: the FMU's copy, no builder" in lines, run.stdout
    installed = Path(next(line for line in lines if line.startswith("installed:")).split(": ", 1)[1])
    assert installed.is_relative_to(Path(sysconfig.get_paths()["purelib"]).resolve()) or \
        installed.is_relative_to(Path(sysconfig.get_paths()["purelib"])), installed
    assert "after: True" in lines, run.stdout


TABLE_AFTER_TABLE = """
import sys
from fmpy import simulate_fmu
folder, step = sys.argv[1], sys.argv[2]
if step == "first":
    from fmu_build.drive import build_table_fmu
    build_table_fmu(folder + "/a.fmu", "a", [0.0, 1.0], [("Fz", "N", "axial force")], [[1.0], [3.0]], win64=False)
    sys.exit()
ran = simulate_fmu(folder + "/a.fmu", stop_time=0.5, output_interval=0.5)   # in process, before any build here
from fmu_build.drive import build_table_fmu
second = build_table_fmu(folder + "/b.fmu", "b", [0.0, 1.0], [("Fz", "N", "axial force")], [[10.0], [30.0]],
                         win64=False)
print(float(ran["Fz"][-1]), float(simulate_fmu(str(second), stop_time=0.5, output_interval=0.5)["Fz"][-1]))
"""


def test_an_fmu_built_where_one_of_the_same_slave_ran_in_process_is_built_from_the_slave_script(tmp_path):
    """A time-table FMU run in a process leaves its copies of pythonfmu and of its slave module (``TimeTable``)
    in ``sys.modules``: a second time-table FMU built then in that process is built from the installed builder
    and ``fmu_src/TimeTable.py``, and gives its own table (linear interpolation at 0.5 s)."""
    import subprocess

    for step in ("first", "second"):
        run = subprocess.run([sys.executable, "-c", TABLE_AFTER_TABLE, str(tmp_path), step], capture_output=True,
                             text=True, cwd=ROOT, timeout=300)
        assert run.returncode == 0, run.stderr[-3000:]
    assert [float(v) for v in run.stdout.split()[-2:]] == [2.0, 20.0]
