"""The turbine loop's figures (slewing_turbine.loop.summary, slewing_turbine.study.summary_row) on synthetic
runs whose figures have closed forms: the settle window leaves a wild start-up out, and the pitch
oscillations' x/2b shares follow from the rolling travel of a known swing over a known contact width."""
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rainflow", reason="the x/2b shares count rainflow cycles (the 'life' extra)")

from slewing_drives import DriveParameters  # noqa: E402
from slewing_turbine import loop  # noqa: E402
from slewing_turbine.rotor import Drivetrain  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DT = 0.01
RPM = math.pi / 30.0


def _result(time, rotor_speed, pitch, *, aero_torque=2.0e6, generator_torque=2.0e4, motor_torque=50.0,
            motor_power=100.0, contact_b=None, contact_angle=None, geometry=None):
    """A TurbineResult of electric drives from given histories: the three blades at ``pitch`` (n,), the
    demand one step ahead of it, constant torques, the motors' delivered energy growing at ``motor_power``
    (W per drive)."""
    n = time.size
    p3 = np.repeat(pitch[:, None], 3, axis=1)
    demand = np.vstack([p3[1:], p3[-1:]])
    rate = np.gradient(p3, DT, axis=0)
    nan_first = lambda a: np.concatenate([np.full((1,) + a.shape[1:], np.nan), a[1:]])  # noqa: E731
    aero = nan_first(np.full(n, aero_torque))
    zeros3 = np.zeros((n, 3))
    params = DriveParameters.from_toml(ROOT / "examples" / "drives" / "pitch_drive.toml")
    drivetrain = Drivetrain.from_nrel5mw()
    energies = loop.rotor_energies(time, rotor_speed, aero, np.full(n, generator_torque), drivetrain)
    energies.update(motor=np.full(3, motor_power * (time[-1] - time[0])), friction=np.zeros(3),
                    load_moment=np.zeros(3))
    return loop.TurbineResult(
        time=time, wind=np.full(n, 13.0), rotor_speed=rotor_speed, azimuth=np.zeros(n),
        generator_torque=np.full(n, generator_torque), aero_torque=aero, pitch_demand=demand, pitch=p3,
        pitch_rate=rate, motor_torque=nan_first(np.full((n, 3), motor_torque)), friction_torque=nan_first(zeros3),
        load_moment=nan_first(zeros3), root_loads=np.full((n, 3, 6), np.nan), root_moop=zeros3,
        step_seconds=np.zeros(n), energies=energies, drives="electric", bearings=None, aero="bem", friction=False,
        drive_params=params, drivetrain=drivetrain,
        motor_energy=motor_power * (time - time[0])[:, None] * np.ones(3), contact_b=contact_b,
        contact_angle=contact_angle, bearing_geometry=geometry, settle=0.0)


def test_settle_leaves_a_wild_start_up_out_of_every_figure():
    """A 40 s run whose first 10 s are a wild start-up (rotor at 20 rpm, the blades pitching 0 -> 40 deg at
    8 deg/s and back) and then steady oscillations: rotor 12 +- 0.5 rpm (0.5 Hz), pitch 5 + 1 sin(2 pi 0.25 t)
    deg. With settle = 10 s the figures are the closed forms of the steady part alone: overspeed
    ``12.5 / 12.1 - 1``, speed std ``0.5 / sqrt 2`` rpm, travel ``4 A f T``, actuator duty cycle
    ``travel / (rate limit T)``, mean rotor speed 12 rpm, the drive energy ``P T`` of the window and the
    electrical energy ``eta Ng Tg omega_mean T``; without it the start-up dominates them."""
    time = np.arange(0.0, 40.0 + DT / 2, DT)
    wild = time < 10.0
    steady_t = time - 10.0
    rpm = np.where(wild, 20.0, 12.0 + 0.5 * np.sin(2 * math.pi * 0.5 * steady_t))
    up = np.minimum(8.0 * time, 80.0 - 8.0 * time)                   # 0 -> 40 deg at 5 s -> 0 deg at 10 s
    amplitude, f = 1.0, 0.25
    pitch_deg = np.where(wild, up, 5.0 + amplitude * np.sin(2 * math.pi * f * steady_t))
    r = _result(time, rpm * RPM, np.radians(pitch_deg))

    window = 30.0
    s = loop.summary(r, settle=10.0)
    assert s["settle time [s]"] == pytest.approx(10.0)
    assert s["overspeed [%]"] == pytest.approx(100 * (12.5 / 12.1 - 1), abs=1e-3)
    assert s["rotor speed mean [rpm]"] == pytest.approx(12.0, abs=1e-3)
    assert s["rotor speed std [rpm]"] == pytest.approx(0.5 / math.sqrt(2), rel=1e-3)
    travel = 4 * amplitude * f * window                  # deg (the window starts at the sample at 10 s)
    assert s["pitch travel [deg]"] == pytest.approx(travel, rel=2e-3)
    rate_limit = math.degrees(r.drive_params.rate_limit)
    assert s["actuator duty cycle [%]"] == pytest.approx(100 * travel / (rate_limit * window), rel=2e-3)
    assert s["drive energy [kJ]"] == pytest.approx(3 * 100.0 * window / 1e3, rel=1e-9)
    d = r.drivetrain
    omega = r.rotor_speed[1000:]
    electrical = d.generator_efficiency * d.gear_ratio * 2.0e4 * np.sum(0.5 * (omega[1:] + omega[:-1])) * DT
    assert s["electrical energy [kWh]"] == pytest.approx(electrical / 3.6e6, rel=1e-9)
    assert electrical / 3.6e6 == pytest.approx(d.generator_efficiency * d.gear_ratio * 2.0e4 * 12.0 * RPM
                                               * window / 3.6e6, rel=1e-3)
    assert abs(s["rotor energy residual / aero energy"]) < 1.0   # a window of its own, not the run's
    # the whole run: the start-up's overspeed and travel
    whole = loop.summary(r, settle=0.0)
    assert whole["overspeed [%]"] == pytest.approx(100 * (20.0 / 12.1 - 1), abs=1e-3)
    assert whole["pitch travel [deg]"] > travel + 80.0
    # the run's own settle time is the default; a settle as long as the run is refused
    r.settle = 10.0
    assert loop.summary(r) == s
    with pytest.raises(ValueError, match="settle"):
        loop.summary(r, settle=40.0)


def test_default_settle_is_twenty_seconds_or_half_a_short_run():
    assert loop.resolve_settle(None, 60.0) == 20.0
    assert loop.resolve_settle(None, 6.0) == 3.0
    assert loop.resolve_settle(5.0, 6.0) == 5.0
    with pytest.raises(ValueError):
        loop.resolve_settle(6.0, 6.0)


def test_x_over_2b_shares_of_a_pitch_history_with_known_swings():
    """The blade pitches 10 cycles of +-0.3 deg, then 10 of +-1.0 deg (0.5 Hz), its bearing's widest patch
    ``b`` constant at the contact angle 45 deg: each cycle's x/2b is the closed form
    ``2 A (dm / 4)(1 - gamma^2) / 2b``, ``gamma = Dw cos(alpha) / dm``; with ``b`` chosen so that the small
    cycles give 0.8 and the large ones 0.8 / 0.3 = 2.67, half of the cycles are below 1 (the series' end
    and start give the rainflow residue its half cycles: 50 % +- 5 %), and summary_row gives the
    per-blade shares."""
    from slewing_turbine.study import summary_row

    dm, dw, alpha = 1.8, 0.045, math.radians(45.0)
    gamma = dw * math.cos(alpha) / dm
    small, large = math.radians(0.3), math.radians(1.0)
    x_small = 2 * small * dm / 4 * (1 - gamma**2)
    b = x_small / (2 * 0.8)
    time = np.arange(0.0, 40.0 + DT / 2, DT)
    amplitude = np.where(time < 20.0, small, large)
    pitch = math.radians(5.0) + amplitude * np.sin(2 * math.pi * 0.5 * time)
    n = time.size
    contact_b = np.zeros((n, 3, 4))
    contact_b[:, :, [0, 2]] = b                      # two loaded contacts, the others unloaded
    contact_angle = np.full((n, 3, 4), alpha)
    r = _result(time, np.full(n, 12.0 * RPM), pitch, contact_b=contact_b, contact_angle=contact_angle,
                geometry=(dm, dw))
    swing, count, ratio, counted = loop.wear_cycles(r, 0)
    assert counted.all()
    for amp, x2b in ((small, 0.8), (large, 0.8 * large / small)):
        whole_swing = np.isclose(swing, 2 * amp, rtol=1e-9)
        assert count[whole_swing].sum() >= 9.5             # ten cycles (as rainflow's half cycles here)
        np.testing.assert_allclose(ratio[whole_swing], x2b, rtol=1e-9)
    np.testing.assert_allclose(ratio, 0.8 * swing / (2 * small), rtol=1e-9)   # x proportional to the swing
    shares = loop.wear_shares(r, 0)
    assert shares["below"] == pytest.approx(0.5, abs=0.05)
    assert shares["below"] + shares["above"] == pytest.approx(1.0)
    row = summary_row(r, settle=0.0)
    for k in (1, 2, 3):
        assert row[f"x2b_below_1_pct_{k}"] == pytest.approx(100 * shares["below"])
        assert row[f"oscillations_{k}"] == pytest.approx(shares["cycles"])
    assert row["x_2b_below_1_worst_blade_pct"] == pytest.approx(100 * shares["below"])
    # the window after 20 s holds only the large cycles: none below 1
    late = loop.wear_shares(r, 0, i0=2000)
    assert late["below"] == 0.0 and late["cycles"] >= 9.5
