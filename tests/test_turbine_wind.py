"""Wind inputs of the turbine loop (slewing_turbine.wind) against IEC 61400-1's formulas.

The expected values are computed here from the standard's formulas (ed. 3, 6.3 and Annex B),
written out again rather than taken from the module.
"""
import math

import numpy as np
import pytest
from scipy import integrate, optimize, stats
from scipy.spatial.transform import Rotation

from slewing_turbine.wind import (WindSeries, blade_height, extreme_direction_change, extreme_operating_gust,
                                  kaimal, kaimal_spectrum, read_wind, shear, steady, step_change,
                                  write_wind)

I_REF = {"A+": 0.18, "A": 0.16, "B": 0.14, "C": 0.12}          # IEC 61400-1 ed. 3 Table 1 (A+: ed. 4)
V_REF = {"I": 50.0, "II": 42.5, "III": 37.5}                     # m/s


def sigma1(v_hub, category):
    return I_REF[category] * (0.75 * v_hub + 5.6)                # NTM, 6.3.1.3


def lambda1(z_hub):
    return 0.7 * z_hub if z_hub <= 60.0 else 42.0                # 6.3.1.3


def spectrum(f, v_hub, category, z_hub):
    """Kaimal S_1(f) of Annex B, L_1 = 8.1 Lambda1."""
    s, tl = sigma1(v_hub, category), 8.1 * lambda1(z_hub) / v_hub
    return 4 * s**2 * tl / (1 + 6 * f * tl) ** (5 / 3)


def spectrum_integral(f_low, f_high, v_hub, category, z_hub):
    """Closed form of the integral of S_1 from f_low to f_high: sigma1^2 [(1 + 6 f L/V)^(-2/3)] between the bounds."""
    s, tl = sigma1(v_hub, category), 8.1 * lambda1(z_hub) / v_hub
    return s**2 * ((1 + 6 * f_low * tl) ** (-2 / 3) - (1 + 6 * f_high * tl) ** (-2 / 3))


# ---------------------------------------------------------------- Kaimal (NTM)

@pytest.mark.parametrize("v_hub, category, z_hub", [(11.4, "B", 90.0), (13.0, "A", 90.0), (6.0, "C", 50.0),
                                                     (20.0, "A+", 120.0)])
def test_kaimal_rescaled_has_sigma1_and_the_exact_mean(v_hub, category, z_hub):
    wind = kaimal(v_hub, 600.0, 0.05, seed=7, turbulence_class=category, hub_height=z_hub)
    assert wind.time[0] == 0.0 and wind.time[-1] == pytest.approx(600.0) and wind.time.size == 12001
    u = wind.speed[:-1]                                          # one period; the last sample repeats the first
    assert wind.speed[-1] == wind.speed[0]
    assert abs(u.mean() - v_hub) < 1e-12 * v_hub
    assert u.std() == pytest.approx(sigma1(v_hub, category), rel=1e-12)
    assert np.all(wind.direction == 0.0)


def test_kaimal_without_rescaling_carries_the_spectrum_variance():
    v, cat, z, T, dt = 13.0, "B", 90.0, 600.0, 0.05
    wind = kaimal(v, T, dt, seed=3, turbulence_class=cat, hub_height=z, rescale=False)
    u = wind.speed[:-1] - v
    n = u.size
    f = np.arange(1, n // 2) / T                                 # the bins below Nyquist
    # Parseval: the variance is the sum of the bins' variances S(f_k) / T, whatever the phases
    assert u.var() == pytest.approx(np.sum(spectrum(f, v, cat, z)) / T, rel=1e-9)
    # ... which is the integral of S over the bins' bands, from 1/(2T) to the Nyquist frequency (closed form);
    # from 1/T instead the integral is ~8 % smaller in variance: the first bin stands for [1/(2T), 3/(2T)]
    f_nyquist = 0.5 / dt
    assert u.std() == pytest.approx(math.sqrt(spectrum_integral(0.5 / T, f_nyquist, v, cat, z)), rel=0.01)
    assert u.std() == pytest.approx(math.sqrt(spectrum_integral(1.0 / T, f_nyquist, v, cat, z)), rel=0.06)
    assert u.std() < sigma1(v, cat)                              # the part below 1/(2T) is missing


def test_kaimal_periodogram_follows_the_spectrum():
    v, cat, z, T, dt = 11.4, "B", 90.0, 300.0, 0.05
    n = round(T / dt)
    f = np.fft.rfftfreq(n, dt)
    expected = spectrum(f[1:-1], v, cat, z)
    periodograms = []
    for seed in range(4):
        u = kaimal(v, T, dt, seed=seed, turbulence_class=cat, hub_height=z, rescale=False, period=None).speed[:-1] - v
        p = 2 * np.abs(np.fft.rfft(u)) ** 2 * dt / n             # one-sided periodogram, (m/s)^2/Hz
        assert p[0] < 1e-20 and p[-1] < 1e-20                    # no mean, no Nyquist bin
        periodograms.append(p[1:-1])
    mean = np.mean(periodograms, axis=0)
    # in octave bands (and, as the amplitudes are set, in every bin)
    edges = 2.0 ** np.arange(math.floor(math.log2(f[1])), math.ceil(math.log2(f[-1])) + 1)
    for lo, hi in zip(edges[:-1], edges[1:]):
        band = (f[1:-1] >= lo) & (f[1:-1] < hi)
        if band.any():
            assert mean[band].mean() == pytest.approx(expected[band].mean(), rel=1e-6), (lo, hi)
    assert np.allclose(mean, expected, rtol=1e-6)
    # rescaled: the same shape, scaled to sigma1^2 in all
    u = kaimal(v, T, dt, seed=0, turbulence_class=cat, hub_height=z, period=None).speed[:-1] - v
    ratio = (2 * np.abs(np.fft.rfft(u)) ** 2 * dt / n)[1:-1] / expected
    assert np.ptp(ratio) < 1e-6 * ratio.mean()
    assert ratio.mean() == pytest.approx(sigma1(v, cat) ** 2 / np.sum(expected / T), rel=1e-9)


def test_kaimal_phases_are_uniform_and_seeded():
    v, T, dt = 11.4, 300.0, 0.05
    a = kaimal(v, T, dt, seed=11, period=None)
    b = kaimal(v, T, dt, seed=11, period=None)
    c = kaimal(v, T, dt, seed=12, period=None)
    assert np.array_equal(a.speed, b.speed)                      # reproducible
    assert not np.allclose(a.speed, c.speed)                     # another seed, another series
    phase_a = np.angle(np.fft.rfft(a.speed[:-1])[1:-1])
    phase_c = np.angle(np.fft.rfft(c.speed[:-1])[1:-1])
    # uniform on (-pi, pi] and independent between seeds (Kolmogorov-Smirnov, 3000 phases each)
    assert stats.kstest(phase_a, stats.uniform(-np.pi, 2 * np.pi).cdf).pvalue > 1e-3
    assert stats.kstest(np.mod(phase_a - phase_c, 2 * np.pi), stats.uniform(0, 2 * np.pi).cdf).pvalue > 1e-3
    # ... so the values are Gaussian (many independent phases): skewness and excess kurtosis near 0
    u = (a.speed[:-1] - v) / a.speed[:-1].std()
    assert abs(stats.skew(u)) < 0.5 and abs(stats.kurtosis(u)) < 1.0


def test_kaimal_spectrum_integrates_to_sigma1_squared():
    for cat, z in [("B", 90.0), ("A", 40.0)]:
        total, _ = integrate.quad(lambda f: float(kaimal_spectrum(f, 10.0, turbulence_class=cat, hub_height=z)),
                                  0, np.inf, limit=200)
        assert total == pytest.approx(sigma1(10.0, cat) ** 2, rel=1e-6)
        assert kaimal_spectrum(0.3, 10.0, turbulence_class=cat, hub_height=z) == pytest.approx(
            spectrum(0.3, 10.0, cat, z), rel=1e-12)


def test_class_s_values_are_taken_as_given():
    # a number for the turbulence category is I_ref, for the wind class V_ref (class S)
    wind = kaimal(9.0, 600.0, 0.1, seed=2, turbulence_class=0.1)
    assert wind.speed[:-1].std() == pytest.approx(0.1 * (0.75 * 9.0 + 5.6), rel=1e-12)
    gust = extreme_operating_gust(30.0, 1.0, 12.0, 0.05, wind_class=30.0, turbulence_class=0.1)
    assert gust.speed.max() == pytest.approx(30.0 + 0.74 * 1.35 * (0.8 * 1.4 * 30.0 - 30.0), rel=1e-9)
    with pytest.raises(ValueError, match=r"turbulence_class = 1.5: a reference turbulence intensity must lie"):
        kaimal(9.0, 120.0, 0.1, seed=2, turbulence_class=1.5)


def test_kaimal_refuses_bad_input():
    with pytest.raises(ValueError, match=r"mean_speed = 0.0 m/s: must be a finite number > 0"):
        kaimal(0.0, 600.0, 0.05, seed=1)
    with pytest.raises(ValueError, match=r"turbulence_class = 'D'"):
        kaimal(10.0, 600.0, 0.05, seed=1, turbulence_class="D")
    with pytest.raises(ValueError, match=r"dt = -0.05 s"):
        kaimal(10.0, 600.0, -0.05, seed=1)
    with pytest.raises(ValueError, match=r"hub_height = 0.0 m"):
        kaimal(10.0, 600.0, 0.05, seed=1, hub_height=0.0)
    with pytest.raises(TypeError):
        kaimal(10.0, 600.0, 0.05)                                # the seed is required
    with pytest.raises(ValueError, match=r"negative speed"):
        kaimal(0.5, 600.0, 0.05, seed=1, turbulence_class="A")   # sigma1 = 0.96 m/s around 0.5 m/s


# ---------------------------------------------------------------- EOG and EDC

def _eog_shape(t, period=10.5):
    """sin(3 pi t/T) (1 - cos(2 pi t/T)) and its time derivative."""
    w3, w2 = 3 * np.pi / period, 2 * np.pi / period
    return (np.sin(w3 * t) * (1 - np.cos(w2 * t)),
            w3 * np.cos(w3 * t) * (1 - np.cos(w2 * t)) + np.sin(w3 * t) * w2 * np.sin(w2 * t))


@pytest.mark.parametrize("v_hub, wind_class, category, diameter, z_hub", [
    (11.4, "I", "B", 126.0, 90.0),       # NREL 5MW (class IB) at rated speed: the turbulence branch
    (25.0, "II", "A", 80.0, 50.0),       # Lambda1 = 35 m
    (40.0, "III", "A", 126.0, 90.0),     # near V_e1 = 42 m/s: the 1.35 (V_e1 - V_hub) branch
])
def test_eog_has_the_published_shape(v_hub, wind_class, category, diameter, z_hub):
    T, start, dt = 10.5, 5.0, 0.01
    v_e1 = 0.8 * 1.4 * V_REF[wind_class]                         # EWM, 6.3.2.1
    v_gust = min(1.35 * (v_e1 - v_hub), 3.3 * sigma1(v_hub, category) / (1 + 0.1 * diameter / lambda1(z_hub)))
    if v_hub == 11.4:
        assert v_gust == pytest.approx(3.3 * 0.14 * 14.15 / 1.3)  # 5.03 m/s
    if v_hub == 40.0:
        assert v_gust == pytest.approx(1.35 * 2.0)
    wind = extreme_operating_gust(v_hub, start, 25.0, dt, wind_class=wind_class, turbulence_class=category,
                                  rotor_diameter=diameter, hub_height=z_hub)
    t, v = wind.time, wind.speed
    outside = (t <= start + 1e-9) | (t >= start + T - 1e-9)
    assert np.all(v[outside] == v_hub)                           # no change before, at the ends and after
    # the maximum V_hub + 0.74 V_gust at T/2 (a sample there: 10.25 s)
    k = int(np.argmax(v))
    assert t[k] == pytest.approx(start + T / 2, abs=dt / 2)
    assert v[k] == pytest.approx(v_hub + 0.74 * v_gust, abs=1e-9 * v_hub)
    # two minima, symmetric about T/2, at the root of the shape's derivative in (0, T/3)
    t_min = optimize.brentq(lambda s: _eog_shape(s)[1], 1e-6, T / 3, xtol=1e-12)
    v_min = v_hub - 0.37 * v_gust * _eog_shape(t_min)[0]
    first, second = t < start + T / 2, t > start + T / 2
    for half, t_expected in ((first, start + t_min), (second, start + T - t_min)):
        k = np.flatnonzero(half)[np.argmin(v[half])]
        assert t[k] == pytest.approx(t_expected, abs=dt)
        assert v[k] == pytest.approx(v_min, abs=1e-4)            # sampling error at the flat minimum: < 1e-4 m/s
    assert v_min < v_hub < v_hub + 0.74 * v_gust


def test_eog_refuses_speeds_at_or_above_v_e1_and_a_late_start():
    with pytest.raises(ValueError, match=r"mean_speed = 56.0 m/s: must be below V_e1 = 56 m/s"):
        extreme_operating_gust(56.0, 5.0, 30.0, 0.05)
    with pytest.raises(ValueError, match=r"start = 20.0 s: the gust \(10.5 s\) must end within the series"):
        extreme_operating_gust(11.4, 20.0, 30.0, 0.05)
    with pytest.raises(ValueError, match=r"wind_class = 'IV'"):
        extreme_operating_gust(11.4, 5.0, 30.0, 0.05, wind_class="IV")


@pytest.mark.parametrize("sign", [1, -1])
def test_edc_turns_by_theta_e(sign):
    v_hub, T, start = 11.4, 6.0, 2.0
    theta_e = 4 * math.atan(sigma1(v_hub, "B") / (v_hub * (1 + 0.1 * 126.0 / 42.0)))   # 6.3.2.4
    wind = extreme_direction_change(v_hub, start, 12.0, 0.01, sign=sign)
    assert np.all(wind.speed == v_hub)
    assert np.all(wind.direction[wind.time <= start] == 0.0)
    assert wind.direction_at(start + T / 2) == pytest.approx(sign * theta_e / 2, rel=1e-9)
    assert np.allclose(wind.direction[wind.time >= start + T], sign * theta_e, rtol=1e-12)
    assert np.all(sign * np.diff(wind.direction) >= 0)           # monotonic


# ---------------------------------------------------------------- shear and blade geometry

def test_shear_is_the_power_law():
    assert shear(11.4, 90.0, 90.0) == 11.4                       # exact at the hub
    assert shear(11.4, 153.0, 90.0) == pytest.approx(11.4 * (153.0 / 90.0) ** 0.2, rel=1e-14)
    assert shear(11.4, 27.0, 90.0, exponent=0.14) == pytest.approx(11.4 * 0.3**0.14, rel=1e-14)
    assert shear(11.4, 27.0, 90.0, exponent=0.0) == 11.4
    speeds, heights = np.array([[8.0], [12.0]]), np.array([30.0, 90.0, 150.0])
    out = shear(speeds, heights, 90.0)
    assert out.shape == (2, 3) and out[1, 1] == 12.0
    assert out[0, 2] / out[0, 0] == pytest.approx(5.0**0.2, rel=1e-14)   # ratio of two heights
    with pytest.raises(ValueError, match=r"height = -1.0 m: must be finite and > 0"):
        shear(10.0, [50.0, -1.0], 90.0)
    with pytest.raises(ValueError, match=r"hub_height = 0 m"):
        shear(10.0, 50.0, 0)


def test_blade_height_follows_openfast_azimuth_precone_and_tilt():
    # azimuth 0: blade up; pi: down; pi/2: level with the hub
    assert blade_height(0.0, 61.5, 90.0) == pytest.approx(151.5)
    assert blade_height(np.pi, 61.5, 90.0) == pytest.approx(28.5)
    assert blade_height(np.pi / 2, 61.5, 90.0) == pytest.approx(90.0, abs=1e-12)
    # with ElastoDyn's PreCone (tips downwind > 0) and ShftTilt (downwind shaft end up > 0): the blade axis
    # (z up) coned about the y axis (x downwind, y to the left), turned by the azimuth about the shaft and
    # tilted with the shaft, by scipy's rotations
    precone, tilt = np.radians(-2.5), np.radians(-5.0)           # the NREL 5MW
    azimuth = np.linspace(0, 2 * np.pi, 13)
    z = []
    for psi in azimuth:
        r = (Rotation.from_euler("y", -tilt) * Rotation.from_euler("x", psi) * Rotation.from_euler("y", precone))
        z.append(90.0 + 63.0 * r.apply([0.0, 0.0, 1.0])[2])
    assert np.allclose(blade_height(azimuth, 63.0, 90.0, precone, tilt), z, rtol=0, atol=1e-9)
    # an upwind-coned, up-tilted rotor: the level blade is slightly above the hub
    assert blade_height(np.pi / 2, 63.0, 90.0, precone, tilt) > 90.0
    with pytest.raises(ValueError, match=r"precone = 2.0 rad"):
        blade_height(0.0, 63.0, 90.0, precone=2.0)


# ---------------------------------------------------------------- the series, simple inputs and files

def test_steady_and_step_change_cover_the_duration():
    w = steady(8.0, 10.0, 0.3)                                   # 10 / 0.3 is not whole: 34 steps to 10.2 s
    assert w.time[-1] == pytest.approx(10.2) and np.all(w.speed == 8.0) and w.duration >= 10.0
    s = step_change(8.0, 12.0, 5.0, 10.0, 0.1)
    assert np.all(s.speed[s.time < 4.95] == 8.0) and np.all(s.speed[s.time > 4.95] == 12.0)
    assert s.speed_at(4.95) == pytest.approx(10.0)               # the ramp across the step's sample step
    assert s.speed_at([0.0, 10.0]).tolist() == [8.0, 12.0]
    with pytest.raises(ValueError, match=r"t = 10.5 s: outside the wind series"):
        s.speed_at(10.5)
    with pytest.raises(ValueError, match=r"at = 12.0 s: must lie before the end"):
        step_change(8.0, 12.0, 12.0, 10.0, 0.1)


@pytest.mark.parametrize("kwargs, message", [
    (dict(time=[0.0, 1.0, 1.0], speed=[1.0, 1.0, 1.0]),
     r"WindSeries.time\[2\] = 1.0 s after time\[1\] = 1.0 s: time must be strictly increasing"),
    (dict(time=[0.0, 1.0], speed=[1.0, float("nan")]), r"WindSeries.speed\[1\] = nan m/s: must be finite"),
    (dict(time=[0.0, 1.0], speed=[1.0, -0.5]), r"WindSeries.speed\[1\] = -0.5 m/s: must be >= 0"),
    (dict(time=[0.0, 1.0], speed=[1.0, 2.0, 3.0]), r"WindSeries.speed: shape \(3,\), expected \(2,\)"),
    (dict(time=[0.0], speed=[1.0]), r"WindSeries.time: shape \(1,\): must be one-dimensional with at least 2"),
    (dict(time=[0.0, 1.0], speed=[1.0, 1.0], direction=[0.0, 0.1, 0.2]), r"WindSeries.direction: shape \(3,\)"),
    (dict(time=[0.0, float("inf")], speed=[1.0, 1.0]), r"WindSeries.time\[1\] = inf s: must be finite"),
])
def test_wind_series_refuses_bad_values(kwargs, message):
    with pytest.raises(ValueError, match=message):
        WindSeries(**kwargs)


def test_read_wind_reads_two_columns_and_openfast_uniform_wind(tmp_path):
    plain = tmp_path / "wind.csv"
    plain.write_text("time,speed\n0.0,8.0\n1.0,9.5\n2.0,11.0\n")
    w = read_wind(plain)
    assert w.time.tolist() == [0.0, 1.0, 2.0] and w.speed.tolist() == [8.0, 9.5, 11.0]
    assert np.all(w.direction == 0.0)
    # OpenFAST's uniform wind (InflowWind WindType 2): direction in degrees, clockwise seen from above;
    # the gust speed column adds to the speed
    uniform = tmp_path / "wind.hh"
    uniform.write_text("! Wind file\n!Time Wind Wind Vert. Horiz. Vert. LinV Gust\n!  Speed Dir Speed Shear Shear "
                       "Shear Speed\n0.0 10.0 0.0 0.0 0.0 0.2 0.0 0.0\n\n10.0 10.0 30.0 0.0 0.0 0.2 0.0 1.5\n")
    w = read_wind(uniform)
    assert w.speed.tolist() == [10.0, 11.5]
    assert w.direction == pytest.approx([0.0, -math.pi / 6])
    bad = tmp_path / "bad.txt"
    bad.write_text("# t u\n0 8\n1 x\n")
    with pytest.raises(ValueError, match=r"bad.txt, line 3: '1 x': expected numbers"):
        read_wind(bad)
    bad.write_text("0 8\n1 -2\n")
    with pytest.raises(ValueError, match=r"bad.txt: WindSeries.speed\[1\] = -2.0 m/s: must be >= 0"):
        read_wind(bad)


def test_write_wind_round_trips_through_read_wind(tmp_path):
    wind = extreme_direction_change(11.4, 1.0, 8.0, 0.1, sign=-1)
    wind = WindSeries(wind.time, kaimal(11.4, 8.0, 0.1, seed=5).speed, wind.direction)
    path = tmp_path / "edc.wnd"
    write_wind(wind, path, comments=["EDC at 11.4 m/s"])
    lines = path.read_text().splitlines()
    assert lines[0] == "! EDC at 11.4 m/s" and len(lines) == 4 + wind.time.size
    last = [float(x) for x in lines[-1].split()]
    assert len(last) == 8 and last[2] > 0 and last[5] == 0.2      # clockwise degrees; the power-law column
    back = read_wind(path)
    for name in ("time", "speed", "direction"):
        assert np.allclose(getattr(back, name), getattr(wind, name), rtol=1e-9, atol=1e-12), name


def test_a_short_kaimal_run_is_the_start_of_a_ten_minute_realisation():
    """sigma1 is a 10-minute figure: a 30 s run is the first 30 s of the 600 s realisation of its seed, so its
    step-to-step changes (the high frequencies that load the blades) are the spectrum's; a realisation as
    short as the run (period=None), scaled to sigma1, has the whole variance above 1/(30 s) and larger ones."""
    v, dt = 13.0, 0.01
    full = kaimal(v, 600.0, dt, seed=5)
    short = kaimal(v, 30.0, dt, seed=5)
    assert short.time[-1] == pytest.approx(30.0) and short.time.size == 3001
    assert np.array_equal(short.speed, full.speed[:short.speed.size])
    rms = lambda u: float(np.sqrt(np.mean(np.diff(u) ** 2)))        # noqa: E731
    reference = rms(full.speed)
    assert rms(short.speed) == pytest.approx(reference, rel=0.1)
    assert rms(kaimal(v, 30.0, dt, seed=5, period=None).speed) > 1.3 * reference
