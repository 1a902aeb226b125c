"""The drive FMU (fmu_build/drive.py) alone: the checks of test_drives.py run through it, and its
outputs against slewing_drives' ElectricDrive step for step."""
import math
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

import test_drives
from conftest import ROOT
from slewing_drives.drive import DriveParameters, ElectricDrive

DRIVES = test_drives.DRIVES


@pytest.fixture(scope="module")
def drive_fmus(tmp_path_factory):
    """The FMU of each drive definition, by drive name."""
    sys.path.insert(0, str(ROOT))
    from fmu_build.drive import build_drive_fmu

    folder = tmp_path_factory.mktemp("drive_fmu")
    return {DriveParameters.from_toml(ROOT / path).name: build_drive_fmu(ROOT / path, folder / f"{Path(path).stem}.fmu")
            for path in DRIVES}


class _Drive:
    """A drive FMU instance stepped from Python (fmpy), logging on."""

    def __init__(self, path, start_values=None):
        self.messages = []
        md = read_model_description(str(path))
        self.unzipped = extract(str(path))
        self.refs = {v.name: v.valueReference for v in md.modelVariables}
        from slewing_drives.cosimulation import logging_callbacks

        self._callbacks = logging_callbacks(lambda c, i, s, cat, m: self.messages.append(m.decode()))
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.unzipped,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName="drive")
        self.fmu.instantiate(loggingOn=True, callbacks=self._callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        for name, value in (start_values or {}).items():
            (self.fmu.setInteger if isinstance(value, int) else self.fmu.setReal)([self.refs[name]], [value])
        self.fmu.enterInitializationMode()
        try:   # a bad parameter is refused here (through the FMU's Linux layer) or at the first step
            self.fmu.exitInitializationMode()
            self.initialised = True
        except Exception:
            self.initialised = False
        self._in = [self.refs[n] for n in ("command", "load_moment", "friction_torque")]
        self._out = [self.refs[n] for n in ("psi", "omega", "motor_torque", "motor_current", "ring_torque")]

    def step(self, t, dt, command, load, friction):
        self.fmu.setReal(self._in, [command, load, friction])
        self.fmu.doStep(t, dt)
        return self.fmu.getReal(self._out)

    def close(self):
        if self.initialised:
            self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.unzipped, ignore_errors=True)


@pytest.fixture
def through_fmu(drive_fmus, monkeypatch):
    """test_drives' simulation, run through the drive's FMU instead of ElectricDrive; yields the
    FMUs it ran."""
    ran = []

    def simulate(params, command, t_end, dt, load=0.0, friction=0.0):
        ran.append(drive_fmus[params.name])
        drive = _Drive(drive_fmus[params.name])
        t = np.arange(0.0, t_end, dt)
        rows = np.array([drive.step(tk, dt, command(tk), load, friction) for tk in t])
        drive.close()
        return t + dt, rows[:, 0], rows[:, 1], rows[:, 2]

    monkeypatch.setattr(test_drives, "_simulate", simulate)
    yield ran
    assert ran  # the check did run through the FMU


@pytest.mark.parametrize("path", DRIVES)
def test_small_step_follows_the_linear_model(through_fmu, path):
    test_drives.test_small_step_follows_the_linear_model(path)


@pytest.mark.parametrize("path", DRIVES)
def test_large_step_is_rate_limited(through_fmu, path):
    test_drives.test_large_step_is_rate_limited(path)


@pytest.mark.parametrize("path", DRIVES)
def test_steady_motor_torque_balances_friction_through_the_gear(through_fmu, path):
    test_drives.test_steady_motor_torque_balances_friction_through_the_gear(path)


def test_model_description_is_valid(drive_fmus):
    for path in drive_fmus.values():
        assert validate_fmu(str(path)) == []
        md = read_model_description(str(path))
        variables = {v.name: v for v in md.modelVariables}
        for name in ("command", "friction_torque", "load_moment"):
            assert variables[name].causality == "input"
        for name, unit in (("psi", "rad"), ("omega", "rad/s"), ("motor_torque", "N.m"), ("motor_current", "A")):
            assert variables[name].causality == "output" and variables[name].unit == unit
        assert all(v.description for v in md.modelVariables)


@pytest.mark.parametrize("path", DRIVES)
def test_fmu_steps_as_the_python_drive_with_load_friction_and_stick_slip(drive_fmus, path):
    # a slow ramp (stick-slip) and then a large step (rate limit) against a load moment and a friction torque
    # that change every step: the FMU holds the first load moment at its first step, as run_manoeuvre holds it
    # before its first step, and then gives ElectricDrive's numbers, bit for bit
    p = DriveParameters.from_toml(ROOT / path)
    dt = 0.01 if "pitch" in path else 0.05
    steps = 800
    t = np.arange(steps) * dt
    big = 2 * p.rate_limit * steps * dt / 5
    command = np.where(t < steps * dt / 2, 0.002 * p.rate_limit * t, big)
    scale = p.torque_limit * p.torque_gain
    load = 0.2 * scale * (1 + 0.3 * np.sin(2 * math.pi * t / (steps * dt / 3)))
    friction = 0.15 * scale * (1 + 0.2 * np.cos(2 * math.pi * t / (steps * dt / 7)))
    reference = ElectricDrive(p)
    reference.hold(load[0])
    fmu = _Drive(drive_fmus[p.name], {"torque_constant": 2.0})
    speeds = []
    try:
        for k in range(steps):
            got = fmu.step(t[k], dt, command[k], load[k], friction[k])
            s = reference.step(command[k], dt, load_torque=load[k], friction_torque=friction[k])
            expected = [s.angle, s.speed, s.mean_motor_torque, s.mean_motor_torque / 2.0,
                        p.torque_gain * s.mean_motor_torque]
            assert got == expected, k
            speeds.append(s.speed)
    finally:
        fmu.close()
    stuck = (np.array(speeds) == 0.0).astype(int)
    assert np.sum(np.diff(stuck) == 1) >= 2  # the ramp is followed by stick-slip: the ring stuck again twice
    assert np.max(np.abs(speeds)) == pytest.approx(p.rate_limit, rel=0.05)  # the step runs at about the rate limit


def test_friction_holds_a_ring_the_drive_does_not_push(drive_fmus):
    p = DriveParameters.from_toml(ROOT / DRIVES[0])
    fmu = _Drive(drive_fmus[p.name])
    try:
        for k in range(100):
            psi, omega, *_ = fmu.step(0.01 * k, 0.01, 0.0, 5e3, 2e4)
            assert psi == 0.0 and omega == 0.0
    finally:
        fmu.close()


def test_rollback_repeats_steps(drive_fmus):
    fmu = _Drive(drive_fmus[DriveParameters.from_toml(ROOT / DRIVES[0]).name])
    try:
        for k in range(20):
            fmu.step(0.01 * k, 0.01, 0.05, 3e4, 1e4)
        state = fmu.fmu.getFMUstate()
        first = [fmu.step(0.01 * k, 0.01, 0.05, 3e4, 1e4) for k in range(20, 40)]
        fmu.fmu.setFMUstate(state)
        assert [fmu.step(0.01 * k, 0.01, 0.05, 3e4, 1e4) for k in range(20, 40)] == first
        fmu.fmu.freeFMUstate(state)
    finally:
        fmu.close()


@pytest.mark.parametrize("values,message", [
    ({"efficiency": 1.5}, "parameter efficiency = 1.5: must lie in (0, 1]"),
    ({"ring_inertia": -1.0}, "parameter ring_inertia = -1.0: must be a finite number > 0"),
])
def test_bad_parameter_is_refused_with_a_logged_reason(drive_fmus, values, message):
    fmu = _Drive(drive_fmus[DriveParameters.from_toml(ROOT / DRIVES[0]).name], values)
    try:
        if fmu.initialised:
            with pytest.raises(Exception):
                fmu.step(0.0, 0.01, 0.1, 0.0, 0.0)
        assert any(message in m for m in fmu.messages), fmu.messages
    finally:
        fmu.close()


def test_nan_input_is_refused_with_a_logged_reason(drive_fmus):
    # refused as the bearing FMU refuses a bad input: fmi2Discard, the reason logged, the state kept;
    # the step retried from its start with a valid input, and the run after it, give what an
    # instance that never saw the NaN gives, to the last bit
    path = drive_fmus[DriveParameters.from_toml(ROOT / DRIVES[0]).name]
    fmu, undisturbed = _Drive(path), _Drive(path)
    try:
        before = [fmu.step(0.01 * k, 0.01, 0.05, 3e4, 1e4) for k in range(3)]
        with pytest.raises(Exception, match="status 2"):
            fmu.step(0.03, 0.01, float("nan"), 3e4, 1e4)
        refusals = [m for m in fmu.messages if "input command = nan: must be finite (not NaN or infinite)" in m]
        assert refusals and all("step refused, state kept" in m for m in refusals), fmu.messages
        assert fmu.fmu.getReal(fmu._out) == before[-1]   # the state of before the step
        assert not fmu.fmu.getBooleanStatus(3)           # fmi2Terminated: false, the run goes on
        after = [fmu.step(0.01 * k, 0.01, 0.05, 3e4, 1e4) for k in range(3, 8)]
        reference = [undisturbed.step(0.01 * k, 0.01, 0.05, 3e4, 1e4) for k in range(8)]
        assert before + after == reference
    finally:
        fmu.close()
        undisturbed.close()


def test_a_nan_input_refused_again_unchanged_is_an_error(drive_fmus):
    # a master that retries the refused step with the same inputs (fmpy's simulate_fmu) gets fmi2Error
    fmu = _Drive(drive_fmus[DriveParameters.from_toml(ROOT / DRIVES[0]).name])
    try:
        with pytest.raises(Exception, match="status 2"):
            fmu.step(0.0, 0.01, 0.1, float("inf"), 0.0)
        with pytest.raises(Exception, match="status 3"):
            fmu.step(0.0, 0.01, 0.1, float("inf"), 0.0)
        assert any("refused again with the same inputs, so it cannot succeed" in m and "input load_moment = inf" in m
                   for m in fmu.messages), fmu.messages
    finally:
        fmu.initialised = False  # in the state Error: fmi2FreeInstance, not fmi2Terminate
        fmu.close()

