"""ROSCO's controller library called in process (slewing_turbine.controller).

The expected values come from ROSCO's parameter file (read here) and from ROSCO's
control laws in its Fortran source (rosco/controller/src, ROSCO 2.10.6): the pitch
limits and rate limit (Controllers.f90, PitchControl: saturate, then ratelimit), the
region-2 torque law ``VS_Rgn2K * omega_g^2`` of ``VS_ControlMode 1`` (VariableSpeedControl),
the inverse Coleman transform of the individual pitch controller (IPC) and the yaw rate
state machine (YawRateControl: +-Y_Rate beyond the deadband Y_ErrThresh).
"""
import gc
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosco", reason="ROSCO's library: pip install --no-deps rosco==2.10.6 (Python >= 3.11)")

from slewing_turbine.controller import Measurements, RoscoController, RoscoError, read_discon  # noqa: E402

DISCON = Path(__file__).resolve().parents[1] / "examples" / "turbines" / "nrel5mw" / "DISCON.IN"
DT = 0.01
RATED_GEN_SPEED = 122.90967  # rad/s, VS_RefSpd of the file (checked below)


def _measure(t, gen_speed, wind, pitch, torque=40e3, **kw):
    return Measurements(time=t, rotor_speed=gen_speed / 97.0, generator_speed=gen_speed, generator_torque=torque,
                        blade_pitch=np.full(3, pitch) if np.ndim(pitch) == 0 else pitch, wind_speed=wind, **kw)


def _run(controller, gen_speed, wind, steps, t0=0.0):
    """Ideal pitch drives: the measured pitch is the previous command."""
    pitch, torque, out = np.zeros(3), 40e3, []
    for i in range(1, steps + 1):
        t = t0 + i * DT
        cmd = controller.step(_measure(t, gen_speed(t) if callable(gen_speed) else gen_speed,
                                       wind(t) if callable(wind) else wind, pitch, torque))
        pitch, torque = cmd.pitch, cmd.generator_torque
        out.append((cmd.generator_torque, *cmd.pitch, cmd.yaw_rate))
    return np.array(out)


def test_read_discon_gives_the_files_values():
    p = read_discon(DISCON)
    assert p["VS_RefSpd"] == RATED_GEN_SPEED
    assert p["PC_MaxRat"] == 0.1745 and p["PC_MinRat"] == -0.1745
    assert p["Y_ErrThresh"] == [4.0, 8.0]
    assert p["PerfFileName"] == "Cp_Ct_Cq.NREL5MW.txt"
    assert p["LoggingLevel"] == 1  # the file as shipped; the controller runs a copy with 0


def test_two_controllers_in_one_process_are_independent():
    # ROSCO keeps its state in static variables: a shared library would mix the three runs
    # (or refuse the second initialisation: "already been loaded")
    with RoscoController(DISCON, DT) as a, RoscoController(DISCON, DT) as b, RoscoController(DISCON, DT) as c:
        pa, pb, pc = np.zeros(3), np.zeros(3), np.zeros(3)
        out_a, out_b, out_c = [], [], []
        for i in range(1, 1501):
            t = i * DT
            ca = a.step(_measure(t, 125.0, 14.0, pa))
            cc = c.step(_measure(t, 100.0 + 0.01 * i, 9.0, pc))  # stepped in between, with other inputs
            cb = b.step(_measure(t, 125.0, 14.0, pb))
            pa, pb, pc = ca.pitch, cb.pitch, cc.pitch
            out_a.append((ca.generator_torque, *ca.pitch))
            out_b.append((cb.generator_torque, *cb.pitch))
            out_c.append((cc.generator_torque, *cc.pitch))
    out_a, out_b, out_c = map(np.array, (out_a, out_b, out_c))
    assert np.array_equal(out_a, out_b)
    assert np.abs(out_a - out_c).max() > 1.0  # the third controller did something else
    assert out_a[-1, 1] > 0.01                # and the first pitched (above rated speed)


def test_pitch_commands_respect_limits_and_rate_limit():
    p = read_discon(DISCON)
    lo, hi, rate = p["PC_MinPit"], p["PC_MaxPit"], p["PC_MaxRat"]
    # without peak shaving (PS_Mode 0): its minimum pitch follows the wind speed estimate, which these
    # made-up inputs keep high; the limits checked here are the hardware ones, applied last
    with RoscoController(DISCON, DT, overrides={"PS_Mode": 0}) as c:
        # overspeed in a strong wind for 20 s (the pitch runs up to its upper limit), then underspeed
        # in a weak wind for 20 s (down to its lower limit)
        out = _run(c, lambda t: 160.0 if t < 20.0 else 60.0, lambda t: 20.0 if t < 20.0 else 6.0, 4000)
    pitch = out[:, 1:4]
    step = np.abs(np.diff(pitch, axis=0))
    tol = 1e-6  # float32 commands
    assert pitch.min() >= lo - tol and pitch.max() <= hi + tol
    assert step.max() <= rate * DT * (1 + 1e-4) + tol
    # the limits are reached, so that the checks above could fail
    assert pitch[:2000].max() == pytest.approx(hi, abs=tol)
    assert pitch[2000:].min() == pytest.approx(lo, abs=tol)
    assert step.max() == pytest.approx(rate * DT, rel=1e-4)


def test_region_2_torque_is_k_omega_squared():
    # the file's own law (VS_ControlMode 2) is a PI controller on the speed error to a reference from the
    # wind speed estimate (TSR tracking): no closed form to check; mode 1's region 2 is one
    # VS_ControlMode 1 (k omega^2 with PI transitions): in region 2 (VS_MinOMSpd < omega_g < VS_RefSpd,
    # pitch at fine pitch) GenTq = VS_Rgn2K * GenSpeedF^2, GenSpeedF the low-passed generator speed;
    # with a constant speed the filter has settled after 30 s (corner 1.57 rad/s)
    p = read_discon(DISCON)
    k = p["VS_Rgn2K"]
    assert p["VS_MinOMSpd"] < 60.0 and 110.0 < p["VS_RefSpd"]
    for gen_speed in (60.0, 90.0, 110.0):
        with RoscoController(DISCON, DT, overrides={"VS_ControlMode": 1}) as c:
            out = _run(c, gen_speed, 7.0, 3000)
        assert out[-1, 0] == pytest.approx(k * gen_speed**2, rel=1e-6)
        assert np.all(out[-1, 1:4] == 0.0)
        # the torque rate limit VS_MaxRat holds on the way
        assert np.abs(np.diff(out[:, 0])).max() <= p["VS_MaxRat"] * DT * (1 + 1e-5)


def test_individual_pitch_follows_each_blades_azimuth():
    # IPC_ControlMode 1 with an integral gain (ROSCO's Tune_Cases/NREL5MW_PassThrough.yaml value):
    # a 1P out-of-plane moment, largest on the blade pointing up, is integrated in the
    # fixed frame and sent back through the inverse Coleman transform: each blade gets
    # a cos(psi_k) + b sin(psi_k) with its own azimuth psi_k = psi + 2 pi k / 3, the same a and b
    # for all blades, the largest pitch when pointing up
    omega = 1.2671  # rad/s
    revolution = int(2 * np.pi / omega / DT)
    results = {}
    for mode in (0, 1):
        with RoscoController(DISCON, DT, overrides={"IPC_ControlMode": mode, "IPC_KI": [1e-8, 0.0]}) as c:
            az, pitch, azimuth = 0.0, [], []
            for i in range(1, (6001 if mode else 1001)):  # 60 s: the integrator builds up
                az = (az + omega * DT) % (2 * np.pi)
                moop = 8e6 + 1.5e6 * np.cos(az + np.arange(3) * 2 * np.pi / 3)
                cmd = c.step(_measure(i * DT, omega * 97.0, 16.0, math.radians(8.0), 43e3, azimuth=az,
                                      root_moop=moop))
                pitch.append(cmd.pitch)
                azimuth.append(az)
        results[mode] = np.array(pitch), np.array(azimuth)
    pitch, azimuth = results[0]
    assert np.array_equal(pitch[:, 0], pitch[:, 1]) and np.array_equal(pitch[:, 0], pitch[:, 2])
    pitch, azimuth = results[1]
    last = slice(-revolution, None)
    assert np.ptp(pitch[-1]) > math.radians(1.0)
    fits = []
    for k in range(3):
        psi = azimuth[last] + k * 2 * np.pi / 3
        basis = np.c_[np.cos(psi), np.sin(psi), np.ones_like(psi)]
        coef, *_ = np.linalg.lstsq(basis, pitch[last, k], rcond=None)
        assert np.sqrt(np.mean((basis @ coef - pitch[last, k]) ** 2)) < math.radians(0.02)
        fits.append(coef)
    fits = np.array(fits)
    assert fits[0, 0] > math.radians(0.5)                      # pitches most when up (cos term > 0)
    assert np.abs(fits[:, 0] - fits[0, 0]).max() < 0.02 * fits[0, 0]
    assert np.abs(fits[:, 1]).max() < 0.1 * fits[0, 0]


@pytest.mark.parametrize("direction_deg, sign", [(12.0, 1.0), (-12.0, -1.0), (5.0, 0.0)])
def test_yaw_mode_commands_plus_minus_yaw_rate(direction_deg, sign):
    p = read_discon(DISCON)
    rate = p["Y_Rate"]
    assert p["Y_uSwitch"] == 0.0 and abs(direction_deg) != p["Y_ErrThresh"][1]
    with RoscoController(DISCON, DT, overrides={"Y_ControlMode": 1}) as c:
        heading, rates = 0.0, []
        for i in range(1, 4001 if sign else 2001):  # starts after 6 s, 12 deg at 0.5 deg/s take 24 s
            cmd = c.step(_measure(i * DT, 115.0, 10.0, 0.0, nacelle_heading=heading,
                                  wind_direction=math.radians(direction_deg)))
            heading += cmd.yaw_rate * DT
            rates.append(cmd.yaw_rate)
    values = set(np.unique(rates).tolist())
    if sign == 0.0:  # inside the deadband Y_ErrThresh (8 deg): no yawing
        assert values == {0.0}
    else:  # yaws at Y_Rate towards the wind, stops when the error changes sign
        assert values == {0.0, float(np.float32(sign * rate))}
        assert math.degrees(heading) == pytest.approx(direction_deg, abs=0.5)


def test_nothing_is_written_into_the_working_directory(tmp_path, monkeypatch):
    # the file as shipped has LoggingLevel 1 (a 40 MB .dbg file per 600 s in the working directory)
    monkeypatch.chdir(tmp_path)
    c = RoscoController(DISCON, DT)
    directory = c.directory
    _run(c, 125.0, 14.0, 1100)  # past t = 10 s, when ROSCO's logging prints and writes
    assert c.parameters["LoggingLevel"] == 0
    assert Path(c.parameters["PerfFileName"]).is_absolute()
    assert "Running ROSCO" in c.startup_output
    c.close()
    c.close()
    assert list(tmp_path.iterdir()) == []
    assert not directory.exists()
    with pytest.raises(RuntimeError, match="closed"):
        c.step(_measure(1.0, 120.0, 12.0, 0.0))


def test_bad_inputs_are_refused_with_the_reason(tmp_path):
    for dt in (0.0, -0.01, float("nan")):
        with pytest.raises(ValueError, match=r"dt = .*must be a finite number > 0"):
            RoscoController(DISCON, dt)
    with pytest.raises(FileNotFoundError, match="no_such_DISCON.IN"):
        RoscoController(tmp_path / "no_such_DISCON.IN", DT)
    # a missing performance table would end the process in ROSCO's Fortran: refused before
    with pytest.raises(FileNotFoundError, match="PerfFileName"):
        RoscoController(DISCON, DT, overrides={"PerfFileName": "missing_table.txt"})
    with pytest.raises(KeyError, match="PC_MaxRate"):
        RoscoController(DISCON, DT, overrides={"PC_MaxRate": 0.1})
    with RoscoController(DISCON, DT) as c:
        with pytest.raises(ValueError, match=r"Measurements\.rotor_speed = nan: must be finite"):
            c.step(Measurements(0.01, float("nan"), 120.0, 4e4, np.zeros(3), 12.0))
        with pytest.raises(ValueError, match=r"Measurements\.blade_pitch = .*must be finite"):
            c.step(Measurements(0.01, 1.2, 120.0, 4e4, np.array([0.0, np.inf, 0.0]), 12.0))
        with pytest.raises(ValueError, match="3 values"):
            c.step(Measurements(0.01, 1.2, 120.0, 4e4, np.zeros(2), 12.0))
        cmd = c.step(_measure(0.01, 120.0, 12.0, 0.0))  # the refused calls did not reach ROSCO
        assert np.isfinite(cmd.generator_torque)
        c.step(_measure(0.02, 120.0, 12.0, cmd.pitch), last=True)
        with pytest.raises(RuntimeError, match="last call"):
            c.step(_measure(0.03, 120.0, 12.0, cmd.pitch))


def test_an_aborting_controller_raises_its_message():
    # ROSCO's own input check (ReadSetParameters.f90, CheckInputs) sets aviFAIL < 0
    with pytest.raises(RoscoError, match="PC_MaxRat must be greater than zero"):
        RoscoController(DISCON, DT, overrides={"PC_MaxRat": -0.1})
    # the failed instance left nothing behind: a new one starts
    with RoscoController(DISCON, DT) as c:
        assert np.isfinite(c.step(_measure(0.01, 120.0, 12.0, 0.0)).generator_torque)


def test_an_instance_dropped_without_close_removes_its_copy():
    c = RoscoController(DISCON, DT)
    directory = c.directory
    assert (directory / "rosco" / "lib").is_dir()
    del c
    gc.collect()
    assert not directory.exists()
