"""Bearing loads from OpenFAST channels: axes, signs, frames, units (docs/guide/openfast-loads.md)."""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from openfast_files import write_binary, write_text
from slewing_drives.load_series import LoadSeries
from slewing_model import Loads, load_bearing, solve
from slewing_model.loads.aeroelastic import UnitError, bearing_channels, bearing_loads, to_si
from slewing_model.loads.openfast import MissingChannelError, OpenFastFormatError, OutputFile, read_output

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "openfast"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"the real OpenFAST files are not here: {DATA} is absent")

B_FRAME = ["RootFxb1", "RootFyb1", "RootFzb1", "RootMxb1", "RootMyb1", "RootMzb1"]
C_FRAME = ["RootFxc1", "RootFyc1", "RootFzc1", "RootMxc1", "RootMyc1", "RootMzc1"]
YAW_P = ["YawBrFxp", "YawBrFyp", "YawBrFzp", "YawBrMxp", "YawBrMyp", "YawBrMzp"]
LOAD_UNITS = ["kN"] * 3 + ["kN·m"] * 3


def _output(time, columns: dict, units: dict, path="memory.outb") -> OutputFile:
    channels = {"Time": np.asarray(time, dtype=float)} | {k: np.asarray(v, dtype=float) for k, v in columns.items()}
    return OutputFile(path, channels["Time"], channels, {"Time": "s"} | units)


def _blade_output(t, b, pitch) -> OutputFile:
    """b-frame loads (kN, kN m) and BldPitch1 (deg) as an in-memory file."""
    return _output(t, dict(zip(B_FRAME, b.T)) | {"BldPitch1": pitch},
                   dict(zip(B_FRAME, LOAD_UNITS)) | {"BldPitch1": "deg"})


def _blade_run(n=301, seed=7):
    """A blade-root record in the b frame (kN, kN m) with the pitch moving over 0..15 deg."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 30.0, n)
    pitch = 7.5 - 7.5 * np.cos(0.2 * t)                                 # deg
    b = np.column_stack([
        230 + 40 * np.sin(0.9 * t), -30 + 60 * np.sin(1.26 * t), 600 + 120 * np.cos(1.26 * t),
        850 + 2500 * np.sin(1.26 * t), 8100 + 1500 * np.sin(0.5 * t), 5 + 80 * np.sin(1.1 * t),
    ]) + rng.normal(0, 1, (n, 6))
    return t, pitch, b


def _b_to_c(b, pitch_deg):
    """c-frame components from b-frame ones. ElastoDyn's blade axes are the coned axes pitched:
    xb = cos(t) xc - sin(t) yc, yb = sin(t) xc + cos(t) yc, zb = zc (SetCoordSy), so
    vxc = cos(t) vxb + sin(t) vyb and vyc = -sin(t) vxb + cos(t) vyb."""
    t = np.radians(pitch_deg)
    c, s = np.cos(t), np.sin(t)
    out = b.copy()
    for x, y in ((0, 1), (3, 4)):
        out[:, x] = c * b[:, x] + s * b[:, y]
        out[:, y] = -s * b[:, x] + c * b[:, y]
    return out


# --- axes and signs -----------------------------------------------------------------------------

def test_pure_flapwise_moment_tilts_the_blade_ring_about_y_with_the_downwind_side_on_the_hub():
    # RootMyb1 > 0 is the moment of a thrust pushing the blade downwind (+xb) about +yb (RootMyb1 = r x F).
    # It presses the downwind (+xb) side of the blade root towards the hub and lifts the upwind side.
    m = 5000.0                                                                  # kN m
    t = np.array([0.0, 1.0])
    out = _output(t, {n: np.full(2, m if n == "RootMyb1" else 0.0) for n in B_FRAME} | {"BldPitch1": [0.0, 0.0]},
                  dict(zip(B_FRAME, LOAD_UNITS)) | {"BldPitch1": "deg"})
    bearing = load_bearing(ROOT / "examples/bearings/pitch_bearing.toml")      # blade on the inner ring
    for mounting, sign, towards_hub_diagonal in (("tip", 1.0, 1), ("hub", -1.0, 0)):
        series = bearing_loads(out, "pitch", 1, mounting)
        assert np.allclose(series.loads, [[0, 0, 0, 0, sign * m * 1e3, 0]] * 2)  # a tilting moment about y only
        result = solve(bearing, Loads(*series.loads[0, :5]))
        phi = result.ball_angle
        downwind, upwind = np.argmin(np.abs(np.cos(phi) - 1)), np.argmin(np.abs(np.cos(phi) + 1))
        # the diagonal loaded when the blade ring is pushed towards the hub: 2 (contacts 2, 4) when +z points
        # to the tip (the ring moves to -z), 1 (contacts 1, 3) when +z points to the hub
        q = result.contact_load
        diagonal = [q[:, 0], q[:, 1]]                             # index 0: Q1 (= Q3), diagonal 1; 1: Q2 (= Q4)
        assert diagonal[towards_hub_diagonal][downwind] > 1e3
        assert diagonal[1 - towards_hub_diagonal][downwind] == pytest.approx(0.0, abs=1e-6)
        assert diagonal[1 - towards_hub_diagonal][upwind] > 1e3               # the upwind side is lifted
        assert sign * result.displacement[4] > 0                                # tilt ry of the sign of My


def test_blade_pulling_outward_loads_diagonal_1_when_the_blade_is_on_the_inner_ring_and_z_points_to_the_tip():
    t = np.array([0.0, 1.0])
    out = _output(t, {n: np.full(2, 600.0 if n == "RootFzb1" else 0.0) for n in B_FRAME} | {"BldPitch1": [0, 0]},
                  dict(zip(B_FRAME, LOAD_UNITS)) | {"BldPitch1": "deg"})
    bearing = load_bearing(ROOT / "examples/bearings/pitch_bearing.toml")
    cases = [("tip", "inner", 0), ("tip", "outer", 1), ("hub", "inner", 1), ("hub", "outer", 0)]
    for mounting, moving_ring, diagonal in cases:
        series = bearing_loads(out, "pitch", 1, mounting)
        assert series.loads[0, 2] == pytest.approx((6e5 if mounting == "tip" else -6e5))
        q = solve(dataclasses.replace(bearing, moving_ring=moving_ring), Loads(Fz=series.loads[0, 2])).contact_load
        assert np.all(q[:, diagonal] > 20 * q[:, 1 - diagonal]), (mounting, moving_ring)


def test_pitch_angle_and_drive_moment_signs():
    # OpenFAST pitches about -zb, so psi = -BldPitch with +z to the tip and +BldPitch with +z to the hub.
    # RootMzb1 > 0 is a moment about +zb on the blade ring: it turns the blade towards lower pitch, so it
    # opposes pitching to feather; the series' Mz is positive when it opposes positive psi.
    t = np.linspace(0.0, 2.0, 21)
    pitch = 3.0 * t                                                                   # 3 deg/s
    out = _output(t, {n: np.full(t.size, 40.0 if n == "RootMzb1" else 0.0) for n in B_FRAME} | {"BldPitch1": pitch},
                  dict(zip(B_FRAME, LOAD_UNITS)) | {"BldPitch1": "deg"})
    tip, hub = bearing_loads(out, "pitch", 1, "tip"), bearing_loads(out, "pitch", 1, "hub")
    assert np.allclose(hub.psi, np.radians(pitch)) and np.allclose(tip.psi, -np.radians(pitch))
    assert np.allclose(hub.omega, math.radians(3.0)) and np.allclose(tip.omega, -math.radians(3.0))
    assert np.allclose(hub.loads[:, 5], 4e4) and np.allclose(tip.loads[:, 5], -4e4)
    # either way the moment pushes towards lower pitch: -Mz * d(psi)/d(pitch) < 0
    for series, dpsi in ((hub, 1.0), (tip, -1.0)):
        assert np.all(-series.loads[:, 5] * dpsi < 0)


# --- frames -------------------------------------------------------------------------------------

def test_c_frame_and_b_frame_files_of_the_same_run_give_the_same_bearing_loads(tmp_path):
    t, pitch, b = _blade_run()
    c = _b_to_c(b, pitch)
    units = ["s"] + LOAD_UNITS + ["deg"]
    b_file = write_binary(tmp_path / "b.outb", t, ["Time"] + B_FRAME + ["BldPitch1"], units,
                          np.column_stack([b, pitch]), 3)
    c_file = write_binary(tmp_path / "c.outb", t, ["Time"] + C_FRAME + ["BldPitch1"], units,
                          np.column_stack([c, pitch]), 3)
    assert bearing_channels(b_file)["frame"] == "b" and bearing_channels(c_file)["frame"] == "c"
    for mounting in ("tip", "hub"):
        for frame in ("rotating", "fixed"):
            from_b = bearing_loads(b_file, "pitch", 1, mounting, frame=frame)
            from_c = bearing_loads(c_file, "pitch", 1, mounting, frame=frame)
            assert np.allclose(from_b.loads, from_c.loads, rtol=1e-12, atol=1e-6)
            assert np.array_equal(from_b.psi, from_c.psi) and from_b.load_frame == frame
    # the rotating frame is the blade's: the b channels themselves (SI); the fixed frame is the hub's: the c ones
    rot = bearing_loads(c_file, "pitch", 1, "tip", frame="rotating")
    fixed = bearing_loads(b_file, "pitch", 1, "tip", frame="fixed")
    assert np.allclose(rot.loads[:, :5], b[:, :5] * 1e3, rtol=1e-12)
    assert np.allclose(fixed.loads[:, :5], c[:, :5] * 1e3, rtol=1e-12)


def test_the_fixed_frame_is_the_rotating_one_turned_by_psi_as_the_simulator_does():
    t, pitch, b = _blade_run(n=50)
    out = _blade_output(t, b, pitch)
    for mounting in ("tip", "hub"):
        rot = bearing_loads(out, "pitch", 1, mounting, frame="rotating")
        fixed = bearing_loads(out, "pitch", 1, mounting, frame="fixed")
        for k in range(t.size):
            turned = Loads(*rot.loads[k, :5]).rotated(rot.psi[k]).as_array()  # SimulatorSettings(load_frame="rotating")
            assert np.allclose(turned, fixed.loads[k, :5], rtol=1e-12, atol=1e-6)


@needs_data
def test_openfast_own_c_and_b_moments_agree_with_our_turn_by_bldpitch():
    # The IEA-15MW OpenFAST file has both RootM*b1 and RootM*c1: our c -> b turn must reproduce OpenFAST's b.
    out = read_output(DATA / "pCrunch_step_0.IEA15MW_floating_OpenFAST_stepwind_100s.outb")
    t = out.time
    moments = {n: out.channels[n] for n in ("RootMxc1", "RootMyc1", "RootMzc1")}
    zeros = {n: np.zeros_like(t) for n in ("RootFxc1", "RootFyc1", "RootFzc1")}
    units = {n: "kN" for n in zeros} | {n: out.units[n] for n in moments} | {"BldPitch1": "deg"}
    c_only = _output(t, zeros | moments | {"BldPitch1": out.channels["BldPitch1"]}, units)
    series = bearing_loads(c_only, "pitch", 1, "tip", source="c")
    levels = {n: (out.channels[n].max() - out.channels[n].min()) / 65535
              for n in ("RootMxb1", "RootMyb1", "RootMxc1", "RootMyc1", "BldPitch1")}
    # 16-bit levels: each of the b channel and the two c channels is within half a level, and the pitch's half
    # level (rad) times the moment; the turn moves the moments by up to 10 deg * 55 MN m, far above that
    moment = np.hypot(out.channels["RootMxc1"], out.channels["RootMyc1"]).max()
    for k, name in ((3, "RootMxb1"), (4, "RootMyb1")):
        bound = 0.5 * (levels[name] + levels["RootMxc1"] + levels["RootMyc1"]
                       + math.radians(levels["BldPitch1"]) * moment) + 0.01            # kN m (+ single precision)
        error = np.abs(series.loads[:, k] / 1e3 - out.channels[name])
        assert error.max() < bound, (name, error.max(), bound)
    turn = np.abs(out.channels["RootMxb1"] - out.channels["RootMxc1"]).max()
    assert turn > 1000 * bound                                                   # the check has teeth


@needs_data
def test_fast_v8_b_frame_and_fast_v7_c_frame_runs_agree_loosely():
    # Test 18 in FAST v8 (b channels) and FAST v7 (c channels): the same turbine and wind file, but different
    # aerodynamics (AeroDyn 15 / 13) and pitch controllers, so only the mean loads are compared, within 5 %.
    v8 = bearing_loads(DATA / "NREL5MW_Land_FASTv8_CertTest18_turb12mps_60s.outb", "pitch", 1)
    v7 = bearing_loads(DATA / "NREL5MW_Land_FASTv7_CertTest18_turb12mps_60s.outb", "pitch", 1)
    for k in (0, 2, 4):                                                          # Fx, Fz (axial), My (flapwise)
        assert v7.loads[:, k].mean() == pytest.approx(v8.loads[:, k].mean(), rel=0.05)
    assert v8.loads[:, 4].mean() == pytest.approx(8126e3, abs=1e3)               # the data's README: RootMyb1 8126 kN m


# --- the yaw bearing ----------------------------------------------------------------------------

def _yaw_run(n=201):
    t = np.linspace(0.0, 20.0, n)
    yaw = 10.0 * np.sin(0.1 * t)                                                  # deg
    p = np.column_stack([595 + 150 * np.sin(t), -40 + 30 * np.cos(0.7 * t), -3477 + 20 * np.sin(2 * t),
                         -500 + 800 * np.sin(1.26 * t), 1204 + 900 * np.sin(0.5 * t), -396 + 800 * np.sin(0.3 * t)])
    return t, yaw, p


def test_yaw_bearing_mapping():
    t, yaw, p = _yaw_run()
    units = dict(zip(YAW_P, LOAD_UNITS)) | {"YawPzn": "deg"}
    out = _output(t, dict(zip(YAW_P, p.T)) | {"YawPzn": yaw}, units)
    up = bearing_loads(out, "yaw")
    # psi: the nacelle yaws about +zp (ElastoDyn: xn = cos(yaw) xp + sin(yaw) yp)
    assert np.allclose(up.psi, np.radians(yaw))
    # rotating frame = nacelle axes: components along xn, yn
    a = np.radians(yaw)
    assert np.allclose(up.loads[:, 0], 1e3 * (np.cos(a) * p[:, 0] + np.sin(a) * p[:, 1]))
    assert np.allclose(up.loads[:, 1], 1e3 * (-np.sin(a) * p[:, 0] + np.cos(a) * p[:, 1]))
    assert np.allclose(up.loads[:, 3], 1e3 * (np.cos(a) * p[:, 3] + np.sin(a) * p[:, 4]))
    # the weight pushes the nacelle's ring down (-z with +z up); Mz opposes positive yaw when YawBrMzp < 0
    assert np.allclose(up.loads[:, 2], 1e3 * p[:, 2]) and np.all(up.loads[:, 2] < 0)
    assert np.allclose(up.loads[:, 5], -1e3 * p[:, 5])
    # the fixed frame is the tower top's: the p channels themselves
    fixed = bearing_loads(out, "yaw", frame="fixed")
    assert np.allclose(fixed.loads[:, :5], 1e3 * p[:, :5])
    # mounted upside down: y and z change sign, psi too
    down = bearing_loads(out, "yaw", mounting="down")
    assert np.allclose(down.loads * [1, -1, -1, 1, -1, -1], up.loads) and np.allclose(down.psi, -up.psi)
    # a file with the nacelle-frame channels (in N and N-m) gives the same
    c, s_ = np.cos(a), np.sin(a)
    n = np.column_stack([c * p[:, 0] + s_ * p[:, 1], -s_ * p[:, 0] + c * p[:, 1], p[:, 2],
                         c * p[:, 3] + s_ * p[:, 4], -s_ * p[:, 3] + c * p[:, 4], p[:, 5]]) * 1e3
    n_names = [name[:-1] + "n" for name in YAW_P]
    n_file = _output(t, dict(zip(n_names, n.T)) | {"YawPzn": yaw},
                     dict(zip(n_names, ["N"] * 3 + ["N-m"] * 3)) | {"YawPzn": "deg"})
    assert bearing_channels(n_file, "yaw")["frame"] == "n"
    from_n = bearing_loads(n_file, "yaw")
    assert np.allclose(from_n.loads, up.loads, rtol=1e-12, atol=1e-6)
    assert np.allclose(bearing_loads(n_file, "yaw", frame="fixed").loads, fixed.loads, rtol=1e-12, atol=1e-6)


def test_yaw_rate_channel_is_used_when_present_and_agrees_with_the_angle():
    t, yaw, p = _yaw_run(n=2001)
    units = dict(zip(YAW_P, LOAD_UNITS)) | {"NacYaw": "deg", "NacYawVel": "deg/s"}
    rate = 10.0 * 0.1 * np.cos(0.1 * t)                                          # d(yaw)/dt, deg/s
    with_rate = bearing_loads(_output(t, dict(zip(YAW_P, p.T)) | {"NacYaw": yaw, "NacYawVel": rate}, units), "yaw")
    assert np.allclose(with_rate.omega, np.radians(rate), rtol=0, atol=1e-15)
    without = bearing_loads(_output(t, dict(zip(YAW_P, p.T)) | {"NacYaw": yaw}, units), "yaw")
    # central differences, step 0.01 s: error h^2/6 |yaw'''| = 1.7e-7 deg/s (one-sided at the ends: h/2 |yaw''|)
    assert np.allclose(without.omega[1:-1], np.radians(rate[1:-1]), atol=math.radians(1e-6))
    assert np.allclose(without.omega, np.radians(rate), atol=math.radians(0.005 * 0.1 * 1.0))


# --- units --------------------------------------------------------------------------------------

def test_unit_conversion_to_si():
    assert to_si([2.0], "kN", "force")[0] == 2000.0
    assert to_si([2.0], "(kN)", "force")[0] == 2000.0
    for spelling in ("kN·m", "kN\u00b7m", "kNÂ·m", "kN-m", "kNm", "kN*m", "kN m", "KN-M"):
        assert to_si([2.0], spelling, "moment")[0] == 2000.0, spelling
    assert to_si([3.0], "N·m", "moment")[0] == 3.0 and to_si([3.0], "MN-m", "moment")[0] == 3e6
    assert to_si([180.0], "deg", "angle")[0] == pytest.approx(math.pi)
    assert to_si([60.0], "rpm", "rate")[0] == pytest.approx(2 * math.pi)
    assert to_si([90.0], "deg/s", "rate")[0] == pytest.approx(math.pi / 2)
    with pytest.raises(UnitError, match=r"f.outb: channel RootMyb1 has unit 'kN', not a moment unit"):
        to_si([1.0], "kN", "moment", name="RootMyb1", path="f.outb")
    with pytest.raises(UnitError, match="'furlong'"):
        to_si([1.0], "furlong", "force", name="X")


def test_the_same_run_in_other_units_gives_the_same_si_loads(tmp_path):
    t, pitch, b = _blade_run(n=40)
    names = ["Time"] + B_FRAME + ["BldPitch1"]
    kn = write_binary(tmp_path / "kn.outb", t, names, ["s"] + LOAD_UNITS + ["deg"], np.column_stack([b, pitch]), 3)
    si = write_binary(tmp_path / "n.outb", t, names, ["s"] + ["N"] * 3 + ["N-m"] * 3 + ["rad"],
                      np.column_stack([b * 1e3, np.radians(pitch)]), 3)
    a, c = bearing_loads(kn, "pitch"), bearing_loads(si, "pitch")
    assert np.allclose(a.loads, c.loads, rtol=1e-12) and np.allclose(a.psi, c.psi, rtol=1e-12)


def test_latin1_text_file_is_converted_to_si(tmp_path):
    t, pitch, b = _blade_run(n=30)
    path = write_text(tmp_path / "run.out", t, ["Time"] + B_FRAME + ["BldPitch1"], ["s"] + LOAD_UNITS + ["deg"],
                      np.column_stack([b, pitch]), encoding="latin-1")
    assert b"kN\xb7m" in path.read_bytes()
    series = bearing_loads(path, "pitch")
    assert np.allclose(series.loads[:, 4], 1e3 * b[:, 4], rtol=5e-4)            # ES10.3E2: 4 digits
    assert np.allclose(series.psi, -np.radians(pitch), rtol=5e-4, atol=1e-7)


# --- windows, errors, CSV -----------------------------------------------------------------------

def test_time_window_keeps_the_rate_of_the_whole_record():
    t, pitch, b = _blade_run()
    out = _blade_output(t, b, pitch)
    whole, part = bearing_loads(out, "pitch"), bearing_loads(out, "pitch", t_start=10.0, t_end=20.0)
    keep = (t >= 10.0 - 1e-9) & (t <= 20.0 + 1e-9)
    assert part.time[0] == pytest.approx(10.0) and part.time[-1] == pytest.approx(20.0)
    assert np.array_equal(part.omega, whole.omega[keep]) and np.array_equal(part.loads, whole.loads[keep])
    with pytest.raises(ValueError, match="holds 0 rows"):
        bearing_loads(out, "pitch", t_start=100.0)
    with pytest.raises(ValueError, match="t_start must be before t_end"):
        bearing_loads(out, "pitch", t_start=5.0, t_end=1.0)


def test_missing_channel_is_named_with_the_file(tmp_path):
    t, pitch, b = _blade_run(n=20)
    names = ["Time"] + B_FRAME[:5] + ["BldPitch1"]                                # no RootMzb1
    path = write_binary(tmp_path / "nomz.outb", t, names, ["s"] + LOAD_UNITS[:5] + ["deg"],
                        np.column_stack([b[:, :5], pitch]), 2)
    with pytest.raises(MissingChannelError, match="RootMzb1") as err:
        bearing_loads(path, "pitch")
    assert "nomz.outb" in str(err.value)
    with pytest.raises(MissingChannelError, match="BldPitch2"):                     # blade 2's pitch
        bearing_loads(_output(t, {n.replace("1", "2"): v for n, v in zip(B_FRAME, b.T)},
                              {n.replace("1", "2"): u for n, u in zip(B_FRAME, LOAD_UNITS)}), "pitch", 2)
    with pytest.raises(MissingChannelError, match="YawPzn or NacYaw"):
        bearing_loads(_output(t, dict(zip(YAW_P, b.T)), dict(zip(YAW_P, LOAD_UNITS))), "yaw")


def test_non_finite_channel_and_bad_options_are_refused():
    t, pitch, b = _blade_run(n=20)
    b[7, 4] = np.nan
    out = _blade_output(t, b, pitch)
    with pytest.raises(OpenFastFormatError, match=f"RootMyb1 is not finite .* at t = {t[7]:g} s"):
        bearing_loads(out, "pitch")
    for kwargs, message in (({"bearing": "tower"}, "bearing = 'tower'"), ({"mounting": "up"}, "mounting = 'up'"),
                            ({"blade": 0}, "blade = 0"), ({"frame": "hub"}, "frame = 'hub'"),
                            ({"source": "p"}, "source = 'p'")):
        with pytest.raises(ValueError, match=message):
            bearing_loads(out, **kwargs)


def test_load_series_csv_round_trip_with_motion_and_frame(tmp_path):
    t, pitch, b = _blade_run(n=25)
    out = _blade_output(t, b, pitch)
    series = bearing_loads(out, "pitch", frame="fixed")
    series.write_csv(tmp_path / "loads.csv", comments=["a comment"])
    text = (tmp_path / "loads.csv").read_text().splitlines()
    assert text[:3] == ["# a comment", "# load_frame = fixed", "time,Fx,Fy,Fz,Mx,My,Mz,psi,omega"]
    back = LoadSeries.read_csv(tmp_path / "loads.csv")
    assert back.load_frame == "fixed" and back.has_motion
    assert np.allclose(back.loads, series.loads, rtol=1e-5) and np.allclose(back.psi, series.psi, rtol=1e-8)
    assert np.allclose(back.omega, series.omega, rtol=1e-5)
    assert back.motion_at(t[3]) == pytest.approx((series.psi[3], series.omega[3]), rel=1e-5)


def test_old_load_series_header_is_still_read():
    shipped = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    assert shipped.loads.shape[1] == 6 and not shipped.has_motion and shipped.load_frame == "rotating"
    with pytest.raises(ValueError, match="no recorded motion"):
        shipped.motion_at(0.0)


def test_bad_load_series_header_is_refused(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("time,Fx,Fy,Fz,Mx,My,Mz,psi\n0,1,2,3,4,5,6,7\n1,1,2,3,4,5,6,7\n")
    with pytest.raises(ValueError, match="header must be"):
        LoadSeries.read_csv(path)
