"""Wind at the hub of a turbine: steady, steps, IEC 61400-1 turbulence and gusts, shear.

Every function returns a :class:`WindSeries`: the hub-height longitudinal wind speed
(m/s) and the horizontal wind direction (rad) against time (s), sampled at a fixed
step from 0 to (at least) the requested duration. The wind conditions follow
IEC 61400-1 ed. 3 (2005), clause 6.3 (the same formulas are in ed. 4 (2019), which
adds the turbulence category A+):

* :func:`kaimal` -- Normal Turbulence Model (NTM, 6.3.1.3) with the Kaimal
  longitudinal spectrum of Annex B at the hub point, seeded, by inverse FFT;
* :func:`extreme_operating_gust` -- EOG (6.3.2.2);
* :func:`extreme_direction_change` -- EDC (6.3.2.4);
* :func:`steady`, :func:`step_change` -- test inputs;
* :func:`read_wind` -- a series of the user's (two columns, or OpenFAST's uniform
  wind format, which TurbSim writes as its hub-height ``.hh`` file); :func:`write_wind`
  writes that format, for OpenFAST;
* :func:`shear` -- the Normal Wind Profile's power law (NWP, 6.3.1.2), to carry the
  hub speed to a point of a blade at :func:`blade_height`.

Conventions: ``direction`` is the direction the wind blows towards, about the vertical
axis (z up), counterclockwise seen from above, 0 along the turbine's reference x axis
(downwind along the nacelle at zero yaw): the sign of the nacelle's yaw angle, so that
``direction - nacelle_heading`` is the yaw misalignment (ROSCO's nacelle vane signal).
OpenFAST's InflowWind counts its wind direction the other way round (clockwise seen
from above); :func:`read_wind` converts it.

Examples
--------
>>> from slewing_turbine.wind import kaimal, shear
>>> wind = kaimal(11.4, 600.0, 0.05, seed=1)           # m/s, s, s; IEC class B
>>> round(float(wind.speed[:-1].std()), 4)              # sigma1 = 0.14 (0.75 * 11.4 + 5.6)
1.981
>>> wind.speed_at(100.0) > 0                            # m/s, interpolated linearly
True
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Reference turbulence intensity I_ref per turbulence category (IEC 61400-1 ed. 3 6.2,
#: Table 1; A+ from ed. 4 6.2, Table 1)
REFERENCE_TURBULENCE_INTENSITY = {"A+": 0.18, "A": 0.16, "B": 0.14, "C": 0.12}
#: Reference wind speed V_ref (10 min mean, 50-year) per wind turbine class, m/s (ed. 3 6.2, Table 1)
REFERENCE_WIND_SPEED = {"I": 50.0, "II": 42.5, "III": 37.5}
#: Duration of the extreme operating gust, s (ed. 3 6.3.2.2)
EOG_PERIOD = 10.5
#: Duration of the extreme direction change, s (ed. 3 6.3.2.4)
EDC_PERIOD = 6.0
#: Power-law shear exponent of the Normal Wind Profile (ed. 3 6.3.1.2)
NWP_EXPONENT = 0.2

_TIME_TOLERANCE = 1e-6  # s: how far outside its span a series may be asked for (round-off of step times)


@dataclass(frozen=True, eq=False)  # arrays: no element-wise __eq__
class WindSeries:
    """Hub-height wind against time, interpolated linearly between samples.

    Attributes
    ----------
    time : ndarray (n,), s
        Sample times, strictly increasing, n >= 2.
    speed : ndarray (n,), m/s
        Longitudinal (horizontal) wind speed at the hub, >= 0.
    direction : ndarray (n,) or float, rad
        Direction the wind blows towards, counterclockwise seen from above (the sign of
        the nacelle's yaw angle); a number is the same at every time (default 0: along
        the turbine's reference axis). Stored as an array (n,).

    Raises
    ------
    ValueError
        Naming the field, the first offending value and the rule: a shape that does not
        match ``time``, a value that is not finite, time not strictly increasing, a
        negative speed.

    Examples
    --------
    >>> from slewing_turbine.wind import WindSeries
    >>> wind = WindSeries(time=[0.0, 10.0], speed=[8.0, 12.0])
    >>> float(wind.speed_at(2.5))                           # m/s
    9.0
    """

    time: np.ndarray
    speed: np.ndarray
    direction: np.ndarray | float = 0.0

    def __post_init__(self):
        time = _finite_array("time", self.time, "s")
        if time.ndim != 1 or time.size < 2:
            raise ValueError(f"WindSeries.time: shape {time.shape}: must be one-dimensional with at least 2 samples")
        steps = np.diff(time)
        if np.any(steps <= 0):
            k = int(np.argmax(steps <= 0))
            raise ValueError(f"WindSeries.time[{k + 1}] = {float(time[k + 1])!r} s after time[{k}] = "
                             f"{float(time[k])!r} s: time must be strictly increasing")
        speed = _finite_array("speed", self.speed, "m/s")
        if speed.shape != time.shape:
            raise ValueError(f"WindSeries.speed: shape {speed.shape}, expected {time.shape} (one value per time)")
        if np.any(speed < 0):
            k = int(np.argmax(speed < 0))
            raise ValueError(f"WindSeries.speed[{k}] = {float(speed[k])!r} m/s: must be >= 0")
        direction = _finite_array("direction", self.direction, "rad")
        if direction.ndim == 0:
            direction = np.full(time.shape, float(direction))
        elif direction.shape != time.shape:
            raise ValueError(f"WindSeries.direction: shape {direction.shape}, expected {time.shape} or a number")
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "speed", speed)
        object.__setattr__(self, "direction", direction)

    @property
    def duration(self) -> float:
        """Time span of the series, s."""
        return float(self.time[-1] - self.time[0])

    def speed_at(self, t):
        """Hub wind speed at times within the series, interpolated linearly.

        Parameters
        ----------
        t : float or array_like, s
            Time(s) in ``[time[0], time[-1]]``.

        Returns
        -------
        float or ndarray, m/s
            The speed, of the shape of ``t``.

        Raises
        ------
        ValueError
            If a time lies outside the series (by more than 1e-6 s).
        """
        return self._interpolate(t, self.speed)

    def direction_at(self, t):
        """Wind direction at times within the series, interpolated linearly.

        Parameters
        ----------
        t : float or array_like, s
            Time(s) in ``[time[0], time[-1]]``.

        Returns
        -------
        float or ndarray, rad
            The direction, of the shape of ``t``.

        Raises
        ------
        ValueError
            If a time lies outside the series (by more than 1e-6 s).
        """
        return self._interpolate(t, self.direction)

    def _interpolate(self, t, values):
        t = np.asarray(t, dtype=float)
        first, last = float(self.time[0]), float(self.time[-1])
        inside = (t >= first - _TIME_TOLERANCE) & (t <= last + _TIME_TOLERANCE)   # False for nan
        if not np.all(inside):
            bad = float(t[~inside].ravel()[0])
            raise ValueError(f"t = {bad!r} s: outside the wind series [{first!r}, {last!r}] s")
        out = np.interp(t, self.time, values)
        return float(out) if out.ndim == 0 else out


def _finite_array(name, value, unit):
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"WindSeries.{name} = {value!r}: must be numbers ({unit})") from exc
    if not np.all(np.isfinite(array)):
        k = np.flatnonzero(~np.isfinite(array.ravel()))[0]
        where = f"[{k}]" if array.ndim else ""
        raise ValueError(f"WindSeries.{name}{where} = {float(array.ravel()[k])!r} {unit}: must be finite")
    return array


def _show(value):
    """repr of a value for a message: numpy scalars as plain numbers."""
    return repr(float(value)) if isinstance(value, (np.floating, np.integer)) else repr(value)


def _number(name, value, unit, rule, ok):
    """``value`` as a float; ValueError naming it unless it is a real number for which ``ok`` holds."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) or not (
            math.isfinite(value) and ok(value)):
        raise ValueError(f"{name} = {_show(value)}{' ' + unit if unit else ''}: must be a finite number{rule}")
    return float(value)


def _positive(name, value, unit):
    """``value`` as a float; ValueError unless it is a finite number > 0."""
    return _number(name, value, unit, " > 0", lambda v: v > 0)


def _non_negative(name, value, unit):
    """``value`` as a float; ValueError unless it is a finite number >= 0."""
    return _number(name, value, unit, " >= 0", lambda v: v >= 0)


def _grid(duration, dt):
    """Sample times 0, dt, ..., n dt with n dt >= duration (n = ceil(duration / dt)), and n."""
    duration = _positive("duration", duration, "s")
    dt = _positive("dt", dt, "s")
    if dt > duration:
        raise ValueError(f"dt = {dt!r} s: must not exceed duration = {duration!r} s")
    n = int(math.ceil(duration / dt - 1e-9))
    return np.arange(n + 1) * dt, n


def reference_turbulence_intensity(turbulence_class) -> float:
    """I_ref of a turbulence category (IEC 61400-1 ed. 3 6.2, Table 1; A+: ed. 4).

    Parameters
    ----------
    turbulence_class : {"A+", "A", "B", "C"} or float
        The category, or I_ref itself (class S: a value in (0, 1)).

    Returns
    -------
    float
        I_ref: 0.18 (A+), 0.16 (A), 0.14 (B), 0.12 (C).
    """
    if isinstance(turbulence_class, str):
        if turbulence_class not in REFERENCE_TURBULENCE_INTENSITY:
            raise ValueError(f"turbulence_class = {turbulence_class!r}: must be one of "
                             f"{', '.join(REFERENCE_TURBULENCE_INTENSITY)} or a reference intensity in (0, 1)")
        return REFERENCE_TURBULENCE_INTENSITY[turbulence_class]
    value = _positive("turbulence_class (reference turbulence intensity)", turbulence_class, "")
    if value >= 1:
        raise ValueError(f"turbulence_class = {value!r}: a reference turbulence intensity must lie in (0, 1)")
    return value


def reference_wind_speed(wind_class) -> float:
    """V_ref of a wind turbine class (IEC 61400-1 ed. 3 6.2, Table 1), m/s.

    Parameters
    ----------
    wind_class : {"I", "II", "III"} or float
        The class, or V_ref itself in m/s (class S).

    Returns
    -------
    float, m/s
        50 (I), 42.5 (II), 37.5 (III).
    """
    if isinstance(wind_class, str):
        if wind_class not in REFERENCE_WIND_SPEED:
            raise ValueError(f"wind_class = {wind_class!r}: must be one of {', '.join(REFERENCE_WIND_SPEED)} "
                             "or a reference wind speed in m/s")
        return REFERENCE_WIND_SPEED[wind_class]
    return _positive("wind_class (reference wind speed)", wind_class, "m/s")


def turbulence_sigma(mean_speed, turbulence_class="B") -> float:
    """Standard deviation sigma1 of the longitudinal wind of the NTM, m/s.

    IEC 61400-1 ed. 3 6.3.1.3: ``sigma1 = I_ref (0.75 V_hub + b)``, b = 5.6 m/s (the
    90 % quantile of sigma1 at the hub height's 10-minute mean speed V_hub).

    Parameters
    ----------
    mean_speed : float, m/s
        V_hub.
    turbulence_class : {"A+", "A", "B", "C"} or float
        Turbulence category, or I_ref itself.

    Returns
    -------
    float, m/s
    """
    mean_speed = _non_negative("mean_speed", mean_speed, "m/s")
    return reference_turbulence_intensity(turbulence_class) * (0.75 * mean_speed + 5.6)


def turbulence_scale(hub_height) -> float:
    """Longitudinal turbulence scale parameter Lambda1, m.

    IEC 61400-1 ed. 3 6.3.1.3: ``Lambda1 = 0.7 z`` for ``z <= 60 m``, 42 m above.

    Parameters
    ----------
    hub_height : float, m

    Returns
    -------
    float, m
    """
    hub_height = _positive("hub_height", hub_height, "m")
    return 0.7 * min(hub_height, 60.0)


def kaimal_spectrum(frequency, mean_speed, *, turbulence_class="B", hub_height=90.0):
    """One-sided Kaimal spectrum of the longitudinal wind of the NTM, (m/s)^2/Hz.

    IEC 61400-1 ed. 3 Annex B (Kaimal model): ``S_1(f) = 4 sigma1^2 (L_1/V_hub) /
    (1 + 6 f L_1/V_hub)^(5/3)``, integral scale ``L_1 = 8.1 Lambda1`` (Table B.1); its
    integral over ``f`` from 0 to infinity is ``sigma1^2``.

    Parameters
    ----------
    frequency : float or array_like, Hz
        f >= 0.
    mean_speed : float, m/s
        V_hub, > 0.
    turbulence_class : {"A+", "A", "B", "C"} or float
        Turbulence category, or I_ref itself.
    hub_height : float, m

    Returns
    -------
    float or ndarray, (m/s)^2/Hz
    """
    mean_speed = _positive("mean_speed", mean_speed, "m/s")
    f = np.asarray(frequency, dtype=float)
    if np.any(~np.isfinite(f)) or np.any(f < 0):
        bad = float(f[~(np.isfinite(f) & (f >= 0))].ravel()[0])
        raise ValueError(f"frequency = {bad!r} Hz: must be finite and >= 0")
    sigma = turbulence_sigma(mean_speed, turbulence_class)
    time_scale = 8.1 * turbulence_scale(hub_height) / mean_speed  # L_1 / V_hub, s
    return 4.0 * sigma**2 * time_scale / (1.0 + 6.0 * f * time_scale) ** (5.0 / 3.0)


def steady(speed, duration, dt, *, direction=0.0) -> WindSeries:
    """Constant wind.

    Parameters
    ----------
    speed : float, m/s
    duration : float, s
        The series spans ``[0, n dt]``, ``n = ceil(duration / dt)``.
    dt : float, s
        Sample step.
    direction : float, rad
        Wind direction (default 0).

    Returns
    -------
    WindSeries
    """
    time, _ = _grid(duration, dt)
    speed = _non_negative("speed", speed, "m/s")
    return WindSeries(time, np.full(time.shape, speed), direction)


def step_change(before, after, at, duration, dt, *, direction=0.0) -> WindSeries:
    """A step of the wind speed.

    Parameters
    ----------
    before, after : float, m/s
        Speed at the samples before ``at`` and at the samples from ``at`` on.
    at : float, s
        Time of the step, in ``(0, duration)``; the linear interpolation between samples
        makes it a ramp over the sample step that contains ``at``.
    duration, dt : float, s
        Span and step of the samples, as :func:`steady`.
    direction : float, rad

    Returns
    -------
    WindSeries
    """
    time, _ = _grid(duration, dt)
    before = _non_negative("before", before, "m/s")
    after = _non_negative("after", after, "m/s")
    at = _positive("at", at, "s")
    if at >= time[-1]:
        raise ValueError(f"at = {at!r} s: must lie before the end of the series, {float(time[-1])!r} s")
    # a sample within round-off of `at` belongs to the new speed
    return WindSeries(time, np.where(time >= at - 1e-9 * dt, after, before), direction)


#: the shortest period of a :func:`kaimal` realisation, s: IEC's 10 minutes, over which sigma1 is defined
KAIMAL_PERIOD = 600.0


def kaimal(mean_speed, duration, dt, *, seed, turbulence_class="B", hub_height=90.0, rescale=True,
           period=KAIMAL_PERIOD) -> WindSeries:
    """Seeded turbulent hub-height wind of the IEC Normal Turbulence Model.

    The longitudinal wind at the hub point (no spatial field: the whole rotor sees it)
    with the Kaimal spectrum :func:`kaimal_spectrum` (IEC 61400-1 ed. 3 6.3.1.3 and
    Annex B), by inverse FFT with random phases: with ``n = ceil(duration / dt)``
    samples of period ``T = n dt`` and ``f_k = k / T``, the Fourier coefficient of
    bin ``k`` (``1 <= k < n/2``) has the amplitude ``(n/2) sqrt(2 S_1(f_k) / T)`` (the
    variance ``S_1(f_k) / T`` of the band ``[(k-1/2)/T, (k+1/2)/T]``) and a phase drawn
    uniformly from ``[0, 2 pi)`` by ``numpy.random.default_rng(seed)``; the mean and
    the Nyquist bin are 0. The realisation is periodic with period ``T``: its sample at
    ``t = T`` repeats the first, and its statistics are those of the first ``n``.

    ``T`` is at least ``period`` (default 600 s, IEC's 10 minutes, over which sigma1 is
    defined): a shorter run gets the first ``duration`` s of a 10-minute realisation. A
    realisation as short as the run, scaled to sigma1, would put the whole variance into
    the frequencies above ``1/T`` and so carry about twice the spectrum's turbulence at
    the loads' frequencies for a 10 s run (1.6 times for 30 s).

    Parameters
    ----------
    mean_speed : float, m/s
        V_hub, the 10-minute mean at the hub, > 0.
    duration : float, s
        The span of the series (``m dt >= duration``, ``m = ceil(duration / dt)``).
    dt : float, s
        Sample step; the spectrum is resolved up to the Nyquist frequency ``1 / (2 dt)``.
    seed : int or numpy.random.SeedSequence
        Seed of the phases: the same seed gives the same series.
    turbulence_class : {"A+", "A", "B", "C"} or float
        Turbulence category (default B, as the NREL 5MW's IEC class IB), or I_ref.
    hub_height : float, m
        Sets Lambda1 (default 90 m, the NREL 5MW's).
    rescale : bool
        Scale the fluctuation to the standard deviation sigma1 exactly (default). Without,
        the series carries the spectrum's variance between ``1/(2T)`` and the Nyquist
        frequency only (about 92 % of sigma1^2 for 600 s at 13 m/s, 90 m).
    period : float or None, s
        The shortest period ``T`` of the realisation (default :data:`KAIMAL_PERIOD`, 600 s);
        None: ``T`` is the run's span (the series then is periodic).

    Returns
    -------
    WindSeries
        ``m + 1`` samples at ``0, dt, ..., m dt``; direction 0.

    Raises
    ------
    ValueError
        If a speed, time or height is not a finite positive number, or a class is unknown.
    """
    mean_speed = _positive("mean_speed", mean_speed, "m/s")
    time, m = _grid(duration, dt)
    n = m if period is None else max(m, int(math.ceil(_positive("period", period, "s") / float(dt) - 1e-9)))
    if n < 4:
        raise ValueError(f"duration / dt = {n}: need at least 4 samples for a spectrum")
    sigma = turbulence_sigma(mean_speed, turbulence_class)
    period = n * float(dt)
    f = np.fft.rfftfreq(n, float(dt))[1:]            # f_k = k / T, k = 1 ... floor(n/2)
    spectrum = kaimal_spectrum(f, mean_speed, turbulence_class=turbulence_class, hub_height=hub_height)
    # one-sided spectrum -> rfft coefficients: a cosine of amplitude a = sqrt(2 S df) has
    # the coefficient n a / 2 (numpy's unnormalised forward transform)
    amplitude = 0.5 * n * np.sqrt(2.0 * spectrum / period)
    phase = np.random.default_rng(seed).uniform(0.0, 2.0 * np.pi, f.size)
    coefficients = np.zeros(n // 2 + 1, dtype=complex)
    coefficients[1:] = amplitude * np.exp(1j * phase)
    if n % 2 == 0:
        coefficients[-1] = 0.0                       # Nyquist bin: a real coefficient only; left out
    fluctuation = np.fft.irfft(coefficients, n)
    fluctuation -= fluctuation.mean()                # 0 up to round-off already
    if rescale:
        fluctuation *= sigma / fluctuation.std()
    speed = (mean_speed + np.append(fluctuation, fluctuation[0]))[:m + 1]  # periodic: u(T) = u(0)
    if np.any(speed < 0):
        # NTM at a low mean speed: the Gaussian model allows negative values; a wind speed cannot be
        k = int(np.argmax(speed < 0))
        raise ValueError(f"kaimal: mean_speed = {mean_speed!r} m/s with sigma1 = {sigma:.3g} m/s gives a negative "
                         f"speed ({speed[k]:.3g} m/s at t = {time[k]:.3g} s): use a higher mean speed or another seed")
    return WindSeries(time, speed)


def _eog_gust_speed(mean_speed, wind_class, turbulence_class, rotor_diameter, hub_height):
    # IEC 61400-1 ed. 3 6.3.2.2: V_gust = min(1.35 (V_e1 - V_hub), 3.3 sigma1 / (1 + 0.1 D / Lambda1)),
    # with the 1-year extreme wind speed V_e1 = 0.8 V_e50 and V_e50 = 1.4 V_ref at the hub (EWM, 6.3.2.1)
    v_e1 = 0.8 * 1.4 * reference_wind_speed(wind_class)
    sigma = turbulence_sigma(mean_speed, turbulence_class)
    return min(1.35 * (v_e1 - mean_speed),
               3.3 * sigma / (1.0 + 0.1 * rotor_diameter / turbulence_scale(hub_height)))


def eog_gust_speed(mean_speed, *, wind_class="I", turbulence_class="B", rotor_diameter=126.0,
                   hub_height=90.0) -> float:
    """Gust magnitude V_gust of the extreme operating gust, m/s.

    IEC 61400-1 ed. 3 6.3.2.2: ``V_gust = min(1.35 (V_e1 - V_hub), 3.3 sigma1 / (1 + 0.1 D /
    Lambda1))``, with ``V_e1 = 0.8 V_e50 = 0.8 * 1.4 V_ref`` at the hub (6.3.2.1).

    Parameters
    ----------
    mean_speed : float, m/s
        V_hub, in ``[0, V_e1)``.
    wind_class : {"I", "II", "III"} or float
        Wind turbine class (default I, the NREL 5MW's), or V_ref in m/s.
    turbulence_class : {"A+", "A", "B", "C"} or float
        Turbulence category (default B), or I_ref.
    rotor_diameter : float, m
        D (default 126 m, the NREL 5MW's).
    hub_height : float, m
        Sets Lambda1 (default 90 m).

    Returns
    -------
    float, m/s
    """
    mean_speed = _non_negative("mean_speed", mean_speed, "m/s")
    rotor_diameter = _positive("rotor_diameter", rotor_diameter, "m")
    v_e1 = 0.8 * 1.4 * reference_wind_speed(wind_class)
    if mean_speed >= v_e1:
        raise ValueError(f"mean_speed = {mean_speed!r} m/s: must be below V_e1 = {v_e1:.4g} m/s (the 1-year "
                         "extreme wind speed of the wind class): the EOG is an operating condition")
    return _eog_gust_speed(mean_speed, wind_class, turbulence_class, rotor_diameter, hub_height)


def _event_window(start, duration, dt, period, name):
    time, _ = _grid(duration, dt)
    start = _non_negative("start", start, "s")
    if start + period > time[-1] + 1e-9 * period:
        raise ValueError(f"start = {start!r} s: the {name} ({period} s) must end within the series "
                         f"(ends at {float(time[-1])!r} s)")
    return time, start


def extreme_operating_gust(mean_speed, start, duration, dt, *, wind_class="I", turbulence_class="B",
                           rotor_diameter=126.0, hub_height=90.0) -> WindSeries:
    """Extreme operating gust (EOG) at the hub.

    IEC 61400-1 ed. 3 6.3.2.2: ``V(t) = V_hub - 0.37 V_gust sin(3 pi t'/T) (1 - cos(2 pi t'/T))``
    for ``0 <= t' = t - start <= T``, ``T = 10.5 s``, and ``V_hub`` otherwise: a dip, a rise
    to ``V_hub + 0.74 V_gust`` at ``T/2`` and a second dip, symmetric about ``T/2``
    (V_gust: :func:`eog_gust_speed`).

    Parameters
    ----------
    mean_speed : float, m/s
        V_hub.
    start : float, s
        Time the gust begins, >= 0; it must end within ``duration``.
    duration, dt : float, s
        Span and sample step, as :func:`steady`.
    wind_class : {"I", "II", "III"} or float
        Wind turbine class (default I), or V_ref in m/s.
    turbulence_class : {"A+", "A", "B", "C"} or float
        Turbulence category (default B), or I_ref.
    rotor_diameter : float, m
        D (default 126 m).
    hub_height : float, m
        Sets Lambda1 (default 90 m).

    Returns
    -------
    WindSeries
        Direction 0.

    Examples
    --------
    >>> from slewing_turbine.wind import extreme_operating_gust, eog_gust_speed
    >>> wind = extreme_operating_gust(11.4, 5.0, 20.0, 0.05)     # NREL 5MW, class IB
    >>> gust = eog_gust_speed(11.4)                               # m/s
    >>> bool(abs(wind.speed.max() - (11.4 + 0.74 * gust)) < 1e-9)
    True
    """
    gust = eog_gust_speed(mean_speed, wind_class=wind_class, turbulence_class=turbulence_class,
                          rotor_diameter=rotor_diameter, hub_height=hub_height)
    time, start = _event_window(start, duration, dt, EOG_PERIOD, "gust")
    # t' clipped to [0, T]: outside the gust 1 - cos(2 pi t'/T) is exactly 0, so is the change
    tau = np.clip(time - start, 0.0, EOG_PERIOD)
    change = -0.37 * gust * np.sin(3.0 * np.pi * tau / EOG_PERIOD) * (1.0 - np.cos(2.0 * np.pi * tau / EOG_PERIOD))
    return WindSeries(time, float(mean_speed) + change)


def edc_direction_change(mean_speed, *, turbulence_class="B", rotor_diameter=126.0, hub_height=90.0) -> float:
    """Magnitude theta_e of the extreme direction change, rad.

    IEC 61400-1 ed. 3 6.3.2.4: ``theta_e = 4 arctan(sigma1 / (V_hub (1 + 0.1 D / Lambda1)))``,
    limited to 180 deg.

    Parameters
    ----------
    mean_speed : float, m/s
        V_hub, > 0.
    turbulence_class, rotor_diameter, hub_height
        As :func:`eog_gust_speed`.

    Returns
    -------
    float, rad
        In ``(0, pi]``.
    """
    mean_speed = _positive("mean_speed", mean_speed, "m/s")
    rotor_diameter = _positive("rotor_diameter", rotor_diameter, "m")
    sigma = turbulence_sigma(mean_speed, turbulence_class)
    theta = 4.0 * math.atan(sigma / (mean_speed * (1.0 + 0.1 * rotor_diameter / turbulence_scale(hub_height))))
    return min(theta, math.pi)


def extreme_direction_change(mean_speed, start, duration, dt, *, sign=1, turbulence_class="B",
                             rotor_diameter=126.0, hub_height=90.0) -> WindSeries:
    """Extreme direction change (EDC) at a constant hub speed.

    IEC 61400-1 ed. 3 6.3.2.4: ``theta(t) = 0.5 theta_e (1 - cos(pi t'/T))`` for
    ``0 <= t' = t - start <= T``, ``T = 6 s``, 0 before and ``theta_e`` after
    (theta_e: :func:`edc_direction_change`).

    Parameters
    ----------
    mean_speed : float, m/s
        V_hub, constant.
    start : float, s
        Time the change begins, >= 0; it must end within ``duration``.
    duration, dt : float, s
        Span and sample step, as :func:`steady`.
    sign : {1, -1}
        Counterclockwise (1, default) or clockwise seen from above: the standard asks for both.
    turbulence_class, rotor_diameter, hub_height
        As :func:`eog_gust_speed`.

    Returns
    -------
    WindSeries
    """
    if sign not in (1, -1):
        raise ValueError(f"sign = {_show(sign)}: must be 1 or -1")
    theta = sign * edc_direction_change(mean_speed, turbulence_class=turbulence_class,
                                        rotor_diameter=rotor_diameter, hub_height=hub_height)
    time, start = _event_window(start, duration, dt, EDC_PERIOD, "direction change")
    tau = np.clip(time - start, 0.0, EDC_PERIOD)
    direction = 0.5 * theta * (1.0 - np.cos(np.pi * tau / EDC_PERIOD))
    direction[time >= start + EDC_PERIOD] = theta
    return WindSeries(time, np.full(time.shape, float(mean_speed)), direction)


def shear(speed_hub, height, hub_height, exponent=NWP_EXPONENT):
    """Wind speed at a height from the hub speed: the power law of the NWP.

    IEC 61400-1 ed. 3 6.3.1.2: ``V(z) = V_hub (z / z_hub)^alpha``, ``alpha = 0.2``.

    Parameters
    ----------
    speed_hub : float or array_like, m/s
        V_hub (broadcast against ``height``).
    height : float or array_like, m
        z, > 0 (e.g. :func:`blade_height`).
    hub_height : float, m
        z_hub, > 0.
    exponent : float
        alpha (default 0.2); 0 gives no shear.

    Returns
    -------
    float or ndarray, m/s
    """
    hub_height = _positive("hub_height", hub_height, "m")
    exponent = _number("exponent", exponent, "", "", lambda v: True)
    z = np.asarray(height, dtype=float)
    if np.any(~np.isfinite(z)) or np.any(z <= 0):
        bad = float(z[~(np.isfinite(z) & (z > 0))].ravel()[0])
        raise ValueError(f"height = {bad!r} m: must be finite and > 0 (the power law holds above ground)")
    v = np.asarray(speed_hub, dtype=float) * (z / hub_height) ** exponent
    return float(v) if v.ndim == 0 else v


def blade_height(azimuth, radius, hub_height, precone=0.0, tilt=0.0):
    """Height above ground of a point on a blade's pitch axis.

    With OpenFAST's (ElastoDyn's) conventions: ``azimuth`` 0 has the blade pointing up
    (blade 1 at azimuth 0, blade k at ``azimuth + 2 pi (k - 1) / 3``); ``precone`` is
    ElastoDyn's PreCone, positive when the blade tips lean downwind; ``tilt`` is its
    ShftTilt, positive when the shaft's downwind end is higher (the NREL 5MW has
    PreCone -2.5 deg and ShftTilt -5 deg). Then::

        z = hub_height + radius (sin(precone) sin(tilt) + cos(precone) cos(azimuth) cos(tilt))

    Parameters
    ----------
    azimuth : float or array_like, rad
        Blade azimuth (broadcast against ``radius``).
    radius : float or array_like, m
        Distance from the rotor apex along the blade's (coned) pitch axis (for AeroDyn's
        nodes: the hub radius plus BlSpn).
    hub_height : float, m
        Height of the rotor apex above ground.
    precone, tilt : float, rad
        As above (default 0).

    Returns
    -------
    float or ndarray, m
    """
    hub_height = _positive("hub_height", hub_height, "m")
    precone = _number("precone", precone, "rad", " with magnitude below pi/2", lambda v: abs(v) < 0.5 * math.pi)
    tilt = _number("tilt", tilt, "rad", " with magnitude below pi/2", lambda v: abs(v) < 0.5 * math.pi)
    psi = np.asarray(azimuth, dtype=float)
    r = np.asarray(radius, dtype=float)
    z = hub_height + r * (math.sin(precone) * math.sin(tilt) + math.cos(precone) * np.cos(psi) * math.cos(tilt))
    return float(z) if np.ndim(z) == 0 else z


def read_wind(path) -> WindSeries:
    """Read a hub-height wind series from a text file.

    Columns separated by blanks or commas: time (s), speed (m/s), optionally the wind
    direction in degrees and further columns as in OpenFAST's uniform wind files
    (InflowWind WindType 2; TurbSim's hub-height ``.hh`` output)::

        time  speed  direction  vertical_speed  horizontal_shear  power_law_exponent  linear_shear  gust_speed

    The speed is ``speed + gust_speed`` (InflowWind's hub-height speed); the direction,
    clockwise seen from above in these files, is returned counterclockwise in rad
    (:class:`WindSeries`). Vertical speed and shears are not read (apply :func:`shear`
    with the file's exponent). Lines starting with ``#`` or ``!`` and blank lines are
    comments; lines before the first numeric line are a header.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    WindSeries

    Raises
    ------
    ValueError
        Naming the file and line: a line that is not numbers after the data began, a row
        with a different number of columns, fewer than two rows; or a value that
        :class:`WindSeries` refuses.
    """
    rows, first = [], None
    with open(path) as fh:
        for number, line in enumerate(fh, start=1):
            text = line.strip()
            if not text or text[0] in "#!":
                continue
            fields = text.replace(",", " ").split()
            try:
                values = [float(v) for v in fields]
            except ValueError:
                if rows:
                    raise ValueError(f"{path}, line {number}: {text!r}: expected numbers") from None
                continue                              # a header line before the data
            if len(values) < 2:
                raise ValueError(f"{path}, line {number}: {text!r}: need at least two columns (time, speed)")
            if first is None:
                first = len(values)
            elif len(values) != first:
                raise ValueError(f"{path}, line {number}: {len(values)} columns, the first data line has {first}")
            rows.append(values)
    if len(rows) < 2:
        raise ValueError(f"{path}: {len(rows)} data line(s): need at least two")
    data = np.array(rows)
    speed = data[:, 1] + (data[:, 7] if data.shape[1] >= 8 else 0.0)
    direction = -np.radians(data[:, 2]) if data.shape[1] >= 3 else 0.0
    try:
        return WindSeries(data[:, 0], speed, direction)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def write_wind(wind, path, *, shear_exponent=NWP_EXPONENT, comments=()) -> None:
    """Write a series in OpenFAST's uniform wind format (InflowWind WindType 2).

    Eight columns: time (s), speed (m/s), direction (deg, clockwise seen from above as
    InflowWind counts it), vertical speed 0, horizontal shear 0, the power-law exponent,
    linear vertical shear 0 and gust speed 0; InflowWind's input file gives the reference
    height (the hub height) and length. :func:`read_wind` reads it back.

    Parameters
    ----------
    wind : WindSeries
    path : str or path-like
        The file written.
    shear_exponent : float
        The power-law column (default 0.2, the NWP's), as :func:`shear` applies it.
    comments : sequence of str, optional
        Lines written at the top of the file, each after a ``!``.
    """
    shear_exponent = _number("shear_exponent", shear_exponent, "", "", lambda v: True)
    with open(path, "w") as fh:
        for line in comments:
            fh.write(f"! {line}\n")
        fh.write("! Time  Wind   Wind  Vert.  Horiz.  Vert.   LinV   Gust\n"
                 "!       Speed  Dir   Speed  Shear   Shear   Shear  Speed\n"
                 "! (s)   (m/s)  (deg) (m/s)  (-)     (-)     (-)    (m/s)\n")
        for t, v, d in zip(wind.time, wind.speed, wind.direction):
            fh.write(f"{t:.10g} {v:.10g} {-math.degrees(d):.10g} 0 0 {shear_exponent:.6g} 0 0\n")


__all__ = ["WindSeries", "steady", "step_change", "kaimal", "kaimal_spectrum", "turbulence_sigma", "turbulence_scale",
           "reference_turbulence_intensity", "reference_wind_speed", "eog_gust_speed", "extreme_operating_gust",
           "edc_direction_change", "extreme_direction_change", "shear", "blade_height", "read_wind",
           "write_wind"]
