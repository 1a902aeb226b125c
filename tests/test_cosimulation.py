"""Pitch drive co-simulated with the real bearing FMU (fmpy step loop)."""

import numpy as np
import pytest

from slewing_drives import DriveParameters, LoadSeries
from slewing_drives.cosimulation import run_manoeuvre

from conftest import ROOT


@pytest.fixture(scope="module")
def manoeuvre(table3_fmu):
    # the table3 bearing stands in for a pitch bearing: a constant-speed pitch ramp (half the
    # rate limit) from 0.2 s under a constant axial load and load moment, friction on and off
    drive = DriveParameters.from_toml(ROOT / "examples/drives/pitch_drive.toml")
    t = np.array([0.0, 10.0])
    loads = LoadSeries(t, np.array([[0.0, 0.0, 3e4, 0.0, 0.0, 100.0]] * 2))
    speed = 0.5 * drive.rate_limit
    command = lambda t: speed * max(t - 0.2, 0.0)  # noqa: E731
    runs = {friction: run_manoeuvre(table3_fmu, drive, loads, command, t_end=4.0, dt=0.01,
                                    start_values={"preload": 10e-6}, friction=friction)
            for friction in (True, False)}
    return drive, runs, speed


def _moving(r):
    """Steps during which the ring kept moving forward (no stick within the step)."""
    k = np.arange(1, len(r.time))
    return k[(r.speed[k] > 0) & (r.speed[k - 1] > 0)]


@pytest.mark.parametrize("friction", [True, False])
def test_motor_torque_carries_the_reported_friction(manoeuvre, friction):
    # Newton on the ring over each communication step: J dw/dt = motor torque at the ring (step mean)
    # - load moment - the bearing friction torque the FMU reported for that step
    drive, runs, _ = manoeuvre
    r = runs[friction]
    k = _moving(r)
    assert k.size > 300
    acceleration_torque = drive.inertia * (r.speed[k] - r.speed[k - 1]) / 0.01
    balance = r.ring_torque[k] - r.load_moment[k] - r.friction_torque[k]
    assert np.allclose(acceleration_torque, balance, rtol=1e-9, atol=1e-9 * np.abs(r.ring_torque).max())
    if friction:
        assert r.friction_torque[k].min() > 0.1 * r.load_moment[k].max()  # the bearing's friction matters here
    else:
        assert np.all(r.friction_torque == 0.0)


def test_bearing_friction_costs_motor_energy_and_safety_holds(manoeuvre):
    _, runs, _ = manoeuvre
    assert runs[True].motor_energy > runs[False].motor_energy
    for r in runs.values():
        assert np.all(r.outputs["static_safety_factor"] > 1.0)
        assert np.all(np.diff(r.angle[r.time > 0.5]) > 0)  # follows the ramp


def test_shipped_load_series_is_the_seeded_generator(tmp_path):
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_load_series", ROOT / "examples/loads/make_load_series.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    from slewing_drives.load_series import synthetic_blade_root_loads

    fresh = synthetic_blade_root_loads(**module.BLADE_ROOT)
    shipped = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    assert np.allclose(shipped.loads, fresh.loads, rtol=1e-5, atol=1e-3)
    assert shipped.at(0.005)[4] == pytest.approx(0.5 * (shipped.loads[0, 4] + shipped.loads[1, 4]))


def test_failure_quotes_the_fmu_log(table3_fmu):
    # an overload the bearing cannot carry: the FMU discards the step and says why; the error quotes it
    drive = DriveParameters.from_toml(ROOT / "examples/drives/pitch_drive.toml")
    loads = LoadSeries(np.array([0.0, 1.0]), np.array([[0.0, 0.0, 5e7, 0.0, 0.0, 0.0]] * 2))
    seen = []
    with pytest.raises(RuntimeError, match="beyond what the bearing can carry"):
        run_manoeuvre(table3_fmu, drive, loads, lambda t: 0.0, t_end=0.05, dt=0.01, logger=seen.append)
    assert any("beyond what the bearing can carry" in m for m in seen)
