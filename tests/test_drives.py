"""Pitch and yaw drive models (python-control) without the bearing."""

import control
import numpy as np
import pytest

from slewing_drives.drive import DRIVE_FILE_KEYS, DriveParameters, ElectricDrive, linear_model

DRIVES = ["examples/drives/pitch_drive.toml", "examples/drives/yaw_drive.toml"]


def _simulate(params, command, t_end, dt, load=0.0, friction=0.0):
    drive = ElectricDrive(params)
    t = np.arange(0.0, t_end, dt)
    angle, speed, torque = [], [], []
    for tk in t:
        s = drive.step(command(tk), dt, load, friction)
        angle.append(s.angle)
        speed.append(s.speed)
        torque.append(s.mean_motor_torque)
    return t + dt, np.array(angle), np.array(speed), np.array(torque)


@pytest.mark.parametrize("path", DRIVES)
def test_small_step_follows_the_linear_model(path):
    # a step small enough for no limit to act: the discrete drive equals python-control's
    # step response of the same closed loop (matrix exponential of the state space)
    p = DriveParameters.from_toml(path)
    sys = linear_model(p)
    assert np.all(np.real(control.poles(sys)) < 0)
    step = 0.02 * p.rate_limit / p.position_gain
    t_end = 8.0 / min(abs(np.real(control.poles(sys))))
    dt = t_end / 2000
    t, angle, _, _ = _simulate(p, lambda _: step, t_end, dt)
    response = control.step_response(sys * step, T=np.concatenate([[0.0], t]))  # first point is t = 0
    assert np.abs(angle - response.outputs[1:]).max() < 0.01 * step


@pytest.mark.parametrize("path", DRIVES)
def test_error_decays_at_the_slowest_pole(path):
    p = DriveParameters.from_toml(path)
    sys = linear_model(p)
    slowest = max(np.real(control.poles(sys)))
    step = 0.02 * p.rate_limit / p.position_gain
    t_end = 10.0 / abs(slowest)
    t, angle, _, _ = _simulate(p, lambda _: step, t_end, t_end / 4000)
    late = (t > 0.5 * t_end) & (t < 0.8 * t_end)
    rate = np.polyfit(t[late], np.log(np.abs(step - angle[late])), 1)[0]
    assert rate == pytest.approx(slowest, rel=0.05)


@pytest.mark.parametrize("path", DRIVES)
def test_large_step_is_rate_limited(path):
    p = DriveParameters.from_toml(path)
    step = 20 * p.rate_limit / p.position_gain
    t, angle, speed, torque = _simulate(p, lambda _: step, 3 * step / p.rate_limit, 0.01)
    assert speed.max() <= p.rate_limit * 1.005
    assert speed.max() >= p.rate_limit * 0.99
    assert np.abs(torque).max() <= p.torque_limit * (1 + 1e-12)
    assert angle[-1] == pytest.approx(step, rel=0.01)


@pytest.mark.parametrize("path", DRIVES)
def test_steady_motor_torque_balances_friction_through_the_gear(path):
    # constant-speed ramp against a constant Coulomb friction torque: motor torque = T_f / (N eta n)
    p = DriveParameters.from_toml(path)
    friction = 0.3 * p.torque_limit * p.torque_gain
    speed = 0.3 * p.rate_limit
    settle = 15.0 / abs(max(np.real(control.poles(linear_model(p)))))  # 15 time constants of the slowest pole
    t, angle, spd, torque = _simulate(p, lambda tk: speed * tk, settle, 0.02, friction=friction)
    assert spd[-1] == pytest.approx(speed, rel=1e-3)
    expected = friction / (p.gear_ratio * p.efficiency * p.motor_count)
    assert torque[-1] == pytest.approx(expected, rel=1e-3)


def test_friction_holds_a_ring_the_drive_does_not_push(tmp_path):
    # stick: an external load below the friction torque does not move a ring with no command change
    p = DriveParameters.from_toml(DRIVES[0])
    drive = ElectricDrive(p)
    for _ in range(100):
        drive.step(0.0, 0.01, load_torque=5e3, friction_torque=2e4)
    assert drive.state.speed == 0.0 and drive.state.angle == 0.0


def _drive_file(tmp_path, drop=None, change=None, extra=None) -> str:
    """examples/drives/pitch_drive.toml with one line dropped, one value changed or one line added."""
    lines = []
    for line in open(DRIVES[0]).read().splitlines():
        key = line.split("=")[0].strip()
        if key == drop:
            continue
        if change and key == change[0]:
            line = f"{key} = {change[1]}"
        lines.append(line)
        if extra and line.strip() == f"[{extra[0]}]":
            lines.append(extra[1])
    path = tmp_path / "drive.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


@pytest.mark.parametrize("table, key, _attribute, _to_si, rule, default", DRIVE_FILE_KEYS,
                         ids=[k[1] for k in DRIVE_FILE_KEYS])
def test_a_bad_drive_file_is_refused_naming_the_table_the_key_the_value_and_the_rule(
        tmp_path, table, key, _attribute, _to_si, rule, default):
    # a value just outside the rule, a non-number, a missing key (where required): each message names the file's key
    outside = {"a finite number > 0": "0.0", "a finite number >= 0": "-1e-9", "a whole number >= 1": "1.5",
               "in (0, 1]": "1.01"}[rule]
    for value in (outside, '"fast"', "nan"):
        with pytest.raises(ValueError) as refused:
            DriveParameters.from_toml(_drive_file(tmp_path, change=(key, value)))
        assert f"[{table}] {key} = " in str(refused.value) and f"must be {rule}" in str(refused.value)
    if default is None:
        with pytest.raises(ValueError, match=rf"\[{table}\] {key} is missing"):
            DriveParameters.from_toml(_drive_file(tmp_path, drop=key))
    else:
        assert getattr(DriveParameters.from_toml(_drive_file(tmp_path, drop=key)), _attribute) == default


def test_an_unknown_key_or_table_of_a_drive_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"\[control\] speed_gain: unknown key"):
        DriveParameters.from_toml(_drive_file(tmp_path, extra=("control", "speed_gain = 900.0")))
    with pytest.raises(ValueError, match=r"unknown table \[motor\]"):
        path = _drive_file(tmp_path)
        with open(path, "a") as fh:
            fh.write("[motor]\nkt = 1.5\n")
        DriveParameters.from_toml(path)


def test_the_drive_file_keys_convert_to_si():
    # the rate limit is the one key in other units than SI: deg/s in the file, rad/s in DriveParameters
    p = DriveParameters.from_toml(DRIVES[0])
    assert p.rate_limit == pytest.approx(np.radians(8.0), rel=1e-15)
    assert p.torque_limit == 120.0 and p.motor_count == 1 and isinstance(p.motor_count, int)
