"""The closed turbine loop (slewing_turbine.loop): ROSCO, the rotor, the BEM and three pitch drives on their
pitch bearings. Each check compares the loop with a closed form or with an independent implementation."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

if sys.version_info < (3, 11):
    pytest.skip("the turbine loop needs rosco 2.10.6, which needs Python >= 3.11", allow_module_level=True)
pytest.importorskip("rosco", reason="the turbine loop needs ROSCO's library: pip install --no-deps rosco==2.10.6")

from slewing_drives import DriveParameters  # noqa: E402
from slewing_model import Loads  # noqa: E402
from slewing_turbine import loop  # noqa: E402
from slewing_turbine.wind import kaimal  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
DT = 0.01
#: a blade-root load of the NREL 5MW at 12-13 m/s (blade frame, N and N m): the FAST v8 run's means
ROOT_LOAD = Loads(Fx=-1.0e5, Fy=1.5e5, Fz=6.0e5, Mx=0.8e6, My=7.9e6)


@pytest.fixture(scope="module")
def pitch_drive():
    """One motor's drive (162 kN m at the ring), which a pitching moment of 140 kN m nearly saturates."""
    return DriveParameters.from_toml(ROOT / "examples" / "drives" / "pitch_drive.toml")


@pytest.fixture(scope="module")
def rigid_bearings():
    """Three pitch bearings with rigid rings and friction (the loop's bearings, no superelement to build)."""
    return loop.make_bearings(loop.TurbineConfig(), "rigid", friction=True, count=2)


def _axis(params, bearing, load_moment):
    axis = loop.PitchAxis(params, bearing, pitch=0.0)
    axis.hold(load_moment)
    return axis


def _run_axis(axis, demand, steps, load_moment, loads=ROOT_LOAD):
    """Step one pitch axis through ``demand(t)``; per step the pitch, its rate, one motor's mean torque and
    the friction torque the drive got."""
    out = np.zeros((steps + 1, 4))
    for i in range(1, steps + 1):
        s = axis.step(demand((i - 1) * DT), DT, loads, load_moment)
        out[i] = s.angle, s.speed, s.mean_motor_torque, axis.friction
    return out


def test_friction_takes_its_torque_from_the_drives_acceleration(pitch_drive, rigid_bearings):
    """A demand running ahead faster than the drive can follow (3 deg ahead, then 20 deg/s) under a pitching
    moment ``L`` near what the motor can hold: the position loop asks for the rate limit ``w_max`` at once,
    the speed loop's torque is at the motor's limit, and the pitch accelerates at
    ``a = (motor_count eta N T_max - T_friction - L) / J`` (the bearing's friction torque from its answer)
    until the torque leaves its limit at ``w_s = b w_max - (T_max - L / (motor_count eta N)) / K_v``; then
    the speed PI settles at the rate limit. Closed form of the lag behind ``w_max t`` at the end:
    the speed integrator's growth ``(T_friction / (motor_count eta N) + K_v (1 - b) w_max) / K_vi`` (zero
    error at its start, frozen while the torque is at its limit) plus the saturated phase's
    ``w_max t_e - a t_e^2 / 2 + D (t_e - tau)``, ``t_e = (w_s + D) / a``, where
    ``D = motor_count eta N (T_max - T_0) tau / J`` is the speed the motor's current loop (``tau``) costs
    as its torque rises from the holding torque ``T_0``. With and without the bearing's friction."""
    p, load = pitch_drive, 140e3                   # N m of pitching moment against the drive (T_max: 162 kN m)
    demand = lambda t: math.radians(3.0) + math.radians(20.0) * t   # noqa: E731
    steps = 150
    g, w_max, tau = p.torque_gain, p.rate_limit, p.torque_time_constant
    lags = {}
    for friction, bearing in (("on", rigid_bearings[0]), ("off", None)):
        r = _run_axis(_axis(p, bearing, load), demand, steps, load)
        t_friction = float(np.mean(r[1:, 3]))
        if friction == "on":
            assert t_friction > 5e3 and np.ptp(r[1:, 3]) < 0.01 * t_friction      # N m, nearly constant
        else:
            assert np.all(r[:, 3] == 0.0)
        a = (g * p.torque_limit - t_friction - load) / p.inertia
        saturated = np.flatnonzero(r[1:, 2] >= p.torque_limit * (1 - 1e-6)) + 1    # the whole step at T_max
        assert saturated.size >= 5, friction
        np.testing.assert_allclose((r[saturated, 1] - r[saturated - 1, 1]) / DT,    # each step's own friction
                                   (g * p.torque_limit - r[saturated, 3] - load) / p.inertia, rtol=1e-5)
        w_s = p.speed_setpoint_weight * w_max - (p.torque_limit - load / g) / p.speed_gain
        d = g * (p.torque_limit - load / g) * tau / p.inertia
        t_e = (w_s + d) / a
        expected = ((t_friction / g + p.speed_gain * (1 - p.speed_setpoint_weight) * w_max) / p.speed_integral_gain
                    + w_max * t_e - 0.5 * a * t_e**2 + d * (t_e - tau))
        lags[friction] = (w_max * steps * DT - r[-1, 0], expected)
        assert abs(r[-1, 1] - w_max) < 1e-3 * w_max                 # at the rate limit at the end
        assert lags[friction][0] == pytest.approx(expected, rel=0.02), friction
    measured = lags["on"][0] - lags["off"][0]
    assert measured > math.radians(0.3)                              # what the friction costs: 0.59 deg
    assert measured == pytest.approx(lags["on"][1] - lags["off"][1], rel=0.06)


def test_ramp_lag_integrates_to_rate_over_the_position_integral_gain(pitch_drive, rigid_bearings):
    """A ramp the drive can follow (2 deg/s, from rest, friction on): once on the ramp the position PI's
    integral alone holds the speed reference, ``Ki int(e) dt = rate``: the area under the lag is
    ``rate / Ki`` whatever the friction and the load (the speed loop's integrator carries those). The drive
    integrates its error at the start of each of its 10 inner steps against the demand held over the step,
    so the lag sampled at the steps' ends misses ``0.55 rate dt`` per unit of time (slewing_drives.drive);
    the loop's slow pole (-0.27/s) has decayed to 1e-3 after 25 s."""
    p, load = pitch_drive, 20e3
    rate = math.radians(2.0)
    demand = lambda t: rate * t   # noqa: E731
    steps = 2500
    r = _run_axis(_axis(p, rigid_bearings[1], load), demand, steps, load)
    assert r[1:, 3].min() > 5e3                                # friction on throughout
    held = rate * np.arange(steps) * DT                        # the demand over the step ending at i
    error = held - r[1:, 0]
    area = float(np.sum(error) * DT) + 0.55 * rate * DT * steps * DT
    assert area == pytest.approx(rate / p.position_integral_gain, rel=0.005)
    assert abs(r[-1, 1] - rate) < 1e-3 * rate                  # on the ramp at the end
    assert abs(error[-1]) < rate * DT                          # no steady lag: within a step's travel


# ---- the closed loop --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def wind30():
    return kaimal(13.0, 30.0, DT, seed=7)


@pytest.fixture(scope="module")
def frictionless_run(wind30, rigid_bearings):
    """6 s of the loop with BEM aero and electric drives on rigid bearings with their friction off."""
    bearings = loop.make_bearings(loop.TurbineConfig(), "rigid", friction=False)
    return loop.run_turbine(loop.TurbineConfig(), wind30, t_end=6.0, dt=DT, drives="electric", bearings="rigid",
                            friction=False, aero="bem", bearing_simulators=bearings)


def test_without_friction_the_drive_torque_is_inertia_and_load_moment(frictionless_run):
    """Friction off: at every step, motors' torque at the ring minus the blade's pitching moment equals the
    drive's inertia times its acceleration (the drive's mechanics are exact for the torque held over each
    inner step; the steps where the speed changes sign stop the ring within an inner step and are left out)."""
    r, p = frictionless_run, frictionless_run.drive_params
    assert np.all(r.friction_torque[1:] == 0.0)
    assert np.abs(r.load_moment[1:]).max() > 1e3               # the BEM's pitching moments reached the drives
    acceleration = np.diff(r.pitch_rate, axis=0) / DT
    torque = p.torque_gain * r.motor_torque[1:] - r.load_moment[1:]
    same_sign = r.pitch_rate[1:] * r.pitch_rate[:-1] > 0
    assert same_sign.mean() > 0.9
    scale = p.torque_gain * p.torque_limit
    np.testing.assert_allclose(p.inertia * acceleration[same_sign], torque[same_sign], rtol=0, atol=1e-9 * scale)
    # where it does change sign, the ring stopped for what is left of one inner step (0.1 of the step): the
    # impulse lost is at most that inner step's torque
    lost = np.abs(p.inertia * acceleration[~same_sign] - torque[~same_sign])
    assert np.all(lost <= 0.1 * (scale + np.abs(r.load_moment[1:][~same_sign])))


def test_rotor_energy_balance_closes(frictionless_run):
    """Aero work in = generator work out (electrical + generator loss + gearbox loss) + kinetic change, with
    the work at each step's mean speed (exact for the explicit Euler step), recomputed from the arrays."""
    r = frictionless_run
    d = r.drivetrain
    w = r.rotor_speed
    mean = 0.5 * (w[1:] + w[:-1])
    aero = np.sum(r.aero_torque[1:] * mean * DT)
    shaft = np.sum(d.gear_ratio * r.generator_torque[:-1] / d.gearbox_efficiency * mean * DT)
    kinetic = 0.5 * d.rotor_inertia * (w[-1] ** 2 - w[0] ** 2)
    assert aero > 1e6                                           # J: the rotor did work
    assert abs(aero - shaft - kinetic) < 1e-3 * aero           # the gate
    assert abs(aero - shaft - kinetic) < 1e-9 * aero           # what explicit Euler gives
    e = r.energies
    assert e["aero"] == pytest.approx(aero, rel=1e-12)
    assert e["electrical"] + e["generator_loss"] + e["gearbox_loss"] == pytest.approx(shaft, rel=1e-12)
    assert e["electrical"] == pytest.approx(d.generator_efficiency * shaft * d.gearbox_efficiency, rel=1e-12)


def test_ideal_drives_with_the_cp_table_reproduce_rosco_sim(wind30):
    """drives="ideal", aero="cp_table" is ROSCO's Sim (slewing_turbine.rotor.simulate_like_rosco_sim) sample for
    sample over 30 s of turbulent wind: the same rotor speed, generator torque and pitch to round-off."""
    from slewing_turbine.rotor import CpTable, simulate_like_rosco_sim

    config = loop.TurbineConfig()
    r = loop.run_turbine(config, wind30, t_end=30.0, dt=DT, drives="ideal", aero="cp_table")
    n = r.time.size
    assert n == 3001
    ref = simulate_like_rosco_sim(wind30.time[:n], wind30.speed[:n], discon_in=config.path(config.discon),
                                  cp_table=CpTable.read(config.path(config.cp_table)))
    np.testing.assert_allclose(r.rotor_speed, ref.rotor_speed, rtol=1e-12, atol=0)
    np.testing.assert_allclose(r.generator_torque, ref.generator_torque, rtol=1e-12, atol=1e-9)
    for k in range(3):
        np.testing.assert_allclose(r.pitch_demand[:, k], ref.pitch, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(r.pitch[1:], r.pitch_demand[:-1])        # ideal: the blades at the last demand
    assert np.ptp(r.pitch_demand[:, 0]) > math.radians(2.0)                  # the pitch controller acted
    assert np.ptp(r.rotor_speed) > 0.05                                      # rad/s


def test_pitch_drive_energy_balance_closes(frictionless_run):
    """Each drive: the motors' work at the ring = work against the blade's pitching moment + change of the
    drive's kinetic energy (friction off), the work from the recorded arrays."""
    r, p = frictionless_run, frictionless_run.drive_params
    dpitch = np.diff(r.pitch, axis=0)
    ring = np.sum(p.torque_gain * r.motor_torque[1:] * dpitch, axis=0)
    load = np.sum(r.load_moment[1:] * dpitch, axis=0)
    kinetic = 0.5 * p.inertia * (r.pitch_rate[-1] ** 2 - r.pitch_rate[0] ** 2)
    scale = np.sum(np.abs(p.torque_gain * r.motor_torque[1:] * dpitch), axis=0)
    assert np.all(np.abs(ring - load - kinetic) < 2e-3 * scale)
    np.testing.assert_allclose(r.energies["load_moment"], load, rtol=1e-12)


def test_loop_feeds_the_bearing_as_the_library_maps_blade_root_loads():
    """The loop's bearing inputs (the blade frame's Fx..My, psi = -pitch) and the drive's load torque in
    pitch coordinates (+Mz) are slewing_turbine.blade_loads.bearing_inputs' (the mapping that reads
    OpenFAST's RootF*b/RootM*b: ``load_moment`` there opposes +psi = -pitch, so it is -Mz)."""
    from slewing_turbine.blade_loads import RootLoads, bearing_inputs

    root = RootLoads(Fx=1.1e5, Fy=-2.2e5, Fz=6.3e5, Mx=1.4e6, My=8.5e6, Mz=-4.6e4)
    loads, load_moment, psi = bearing_inputs(root, pitch=0.2)
    assert loads.as_array().tolist() == [root.Fx, root.Fy, root.Fz, root.Mx, root.My]
    assert load_moment == -root.Mz and psi == -0.2


def test_individual_pitch_control_gets_the_root_moments_and_the_azimuth(wind30):
    """With ROSCO's IPC on (``IPC_KI`` of ROSCO's NREL5MW pass-through tuning), the out-of-plane root moments
    and the azimuth the loop sends make the three demands differ by a 1P signal: each blade pitches more when
    it is up, where the sheared wind loads it most (azimuth 0: blade 1 up). Off, the three are equal."""
    ipc = loop.TurbineConfig(discon_overrides={"IPC_ControlMode": 1, "IPC_KI": [1e-8, 0.0]})
    r = loop.run_turbine(ipc, wind30, t_end=15.0, dt=DT, drives="ideal", aero="bem")
    late = r.time > 5.0
    individual = r.pitch_demand[late, 0] - r.pitch_demand[late].mean(axis=1)
    assert np.ptp(individual) > math.radians(0.5)
    assert np.corrcoef(individual, np.cos(r.azimuth[late]))[0, 1] > 0.5
    assert np.mean(r.root_moop[1:]) > 1e6                      # N m: the BEM's flap moments reached ROSCO
    plain = loop.run_turbine(None, wind30, t_end=3.0, dt=DT, drives="ideal", aero="bem")
    assert np.all(np.ptp(plain.pitch_demand, axis=1) == 0.0)


def test_summary_reports_the_figures(frictionless_run):
    s = loop.summary(frictionless_run)
    for key in ("pitch tracking error RMS [deg]", "pitch tracking error max [deg]", "motor torque peak [N m]",
                "motor torque RMS [N m]", "drive energy [kJ]", "time above continuous torque [%]",
                "actuator duty cycle [%]", "rotor speed std [rpm]", "overspeed [%]", "friction torque mean [kN m]",
                "friction torque peak [kN m]"):
        assert math.isfinite(s[key]), key
    assert s["friction torque peak [kN m]"] == 0.0
    assert s["motor torque peak [N m]"] <= frictionless_run.drive_params.torque_limit * (1 + 1e-12)
    # the default settle time: half of this 6 s run (20 s in a run of 40 s or more)
    assert frictionless_run.settle == 3.0 and s["settle time [s]"] == pytest.approx(3.0)
    rpm = frictionless_run.rotor_speed * 30 / math.pi
    window = frictionless_run.time >= 3.0 - 1e-9
    assert s["overspeed [%]"] == pytest.approx(max(0.0, 100 * (rpm[window].max() / 12.1 - 1)))
    whole = loop.summary(frictionless_run, settle=0.0)
    assert whole["overspeed [%]"] == pytest.approx(max(0.0, 100 * (rpm.max() / 12.1 - 1)))
    # the whole run's drive energy is the drives' own count; the window's is its part of it
    assert whole["drive energy [kJ]"] == pytest.approx(np.sum(frictionless_run.energies["motor"]) / 1e3, rel=1e-12)
    assert 0.0 <= s["drive energy [kJ]"] <= whole["drive energy [kJ]"]
    assert abs(s["rotor energy residual / aero energy"]) < 1e-9            # the window's balance closes too


def test_bad_options_are_refused(wind30):
    with pytest.raises(ValueError, match="drives"):
        loop.run_turbine(None, wind30, t_end=1.0, drives="hydraulic")
    with pytest.raises(ValueError, match="bearings need drives"):
        loop.run_turbine(None, wind30, t_end=1.0, drives="ideal", bearings="rigid")
    with pytest.raises(ValueError, match="Cp table"):
        loop.run_turbine(None, wind30, t_end=1.0, drives="electric", bearings="rigid", aero="cp_table")
