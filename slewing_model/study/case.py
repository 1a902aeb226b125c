"""One case of a study: a bearing variant stepped through a load series.

:func:`run_case` is what a Dask worker runs. It takes everything it needs in its
argument (the bearing, its superelement, the load series: no files, so a worker
on another machine needs only the package), steps
:class:`slewing_model.simulation.simulator.BearingSimulator` -- the simulator the FMU runs --
through the series with the recorded motion, and returns the time series, the
statistics and the per-ball load spectrum. A case that cannot be computed (a load
beyond the bearing's capacity, no equilibrium, a bad input) comes back with its
reason in ``status`` instead of raising, so that the other cases finish.

Statistics (SI units)
    ``friction_torque_mean``, ``friction_torque_max``, ``friction_torque_p99``: of the
    full-sliding friction torque magnitude ``T`` (what the drive must overcome when it
    moves), mean weighted by time (trapezoidal rule);
    ``friction_energy``: ``integral |T omega| dt`` (J, trapezoidal rule), the work the
    drive spends against friction over the motion; ``rotation``: ``integral |omega| dt``;
    ``max_ball_load`` (N), ``max_contact_pressure`` (Pa), ``min_static_safety_factor``
    (ISO 76); ``equivalent_ball_load``: the largest, over balls and diagonals, of the
    cubic mean ``(sum v Q^3 / sum v)^(1/3)`` of the diagonal load ``Q`` weighted by
    the ring rotation ``v = |omega| dt`` (by time when the ring stands still), the
    dynamic equivalent load of the rolling-contact life formula.

Life and wear (:mod:`slewing_model.life`; the user guide's life and wear page)
    ``life_L10_h``: the ISO/TS 16281 rating life of the raceways with the oscillation rule, in hours
    of the case's duty repeated, and ``life_worst_track`` (contact 1..4); ``life_damage_per_h``;
    ``life_map_L10_h``: the same from the raceway damage map; ``life_dg03_L10_h`` and
    ``life_dg03_ratio`` (DG03's life over ours); ``life_cycles`` (rainflow count of ``psi``);
    ``life_share_x2b_below_1`` and ``life_share_below_critical`` (shares of the cycles);
    ``life_relubrication_gap_s``; ``life_micro_cycles`` (cycles left out of the two shares counted by
    cycles: swings below 10 steps of the series' angle resolution) and the two shares weighted by
    damage, ``life_damage_share_x2b_below_1`` and ``life_damage_share_below_critical``. A value that
    does not exist (no worst track without damage, no ratio or share without cycles) is an empty
    cell. The raceway map (4 tracks x slices) and the cycles (swing,
    count, x/2b) come back in ``CaseResult.life``.

Load spectrum (for a life calculation)
    Per ball and diagonal (``13``: contacts 1 and 3; ``24``: 2 and 4), the time and
    the ring rotation spent with the diagonal load in each of ``histogram_bins``
    equal bins from 0 to the case's largest diagonal load.
"""
from __future__ import annotations

import math
import os
import socket
import time
from dataclasses import dataclass

import numpy as np

from ..distribution.bime import Loads
from ..life import LifeAccumulator, LifeModel, analyse_run
from ..life.duty import life_files
from ..simulation.simulator import BearingSimulator, SimulatorSettings
from .series import MotionSeries

#: the columns of a case's time series
TIMESERIES_COLUMNS = ("time", "psi", "omega", "Fx", "Fy", "Fz", "Mx", "My", "Mz", "x", "y", "z", "rx", "ry",
                      "friction_torque", "friction_torque_magnitude", "max_ball_load", "max_contact_pressure",
                      "static_safety_factor", "balls_in_four_point_contact")
STATISTICS = ("friction_torque_mean", "friction_torque_max", "friction_torque_p99", "friction_energy",
              "max_ball_load", "max_contact_pressure", "min_static_safety_factor", "equivalent_ball_load",
              "rotation", "duration", "steps",
              "life_L10_h", "life_worst_track", "life_damage_per_h", "life_map_L10_h", "life_dg03_L10_h",
              "life_dg03_ratio", "life_cycles", "life_share_x2b_below_1", "life_share_below_critical",
              "life_relubrication_gap_s", "life_micro_cycles", "life_damage_share_x2b_below_1",
              "life_damage_share_below_critical")
HISTOGRAM_COLUMNS = ("ball", "diagonal", "load_lower_N", "load_upper_N", "time_s", "rotation_rad")


@dataclass(frozen=True)
class CaseTask:
    """What a worker needs to run one case (picklable, no file names).

    Attributes
    ----------
    key : str
        The case's key (16 hex digits).
    bearing : Bearing
        As read from its file (with its own errors, if any).
    superelement : Superelement or None
        For ``variant["ring_model"] == "flexible"``; built once per bearing variant.
    series : MotionSeries
        Loads and motion of the moving ring, SI units.
    variant : dict
        ``ring_model``, ``preload_um`` (um), ``friction_coefficient``, ``error_seed``,
        ``synthetic_errors``.
    simulation : dict
        The study's ``[simulation]`` settings (:attr:`Case.simulation`).
    """

    key: str
    bearing: object
    superelement: object
    series: MotionSeries
    variant: dict
    simulation: dict


@dataclass(frozen=True)
class CaseResult:
    """What a case returns.

    Attributes
    ----------
    key : str
        The case's key.
    status : str
        ``"ok"`` or the error in one line.
    elapsed : float, s
        Wall time of the case on its worker.
    worker : str
        ``host:pid`` of the process that ran it.
    timeseries : ndarray (n, 20) or None
        One row a step: ``time`` (s), ``psi`` (rad), ``omega`` (rad/s), ``Fx, Fy, Fz`` (N),
        ``Mx, My, Mz`` (N m), ``x, y, z`` (m), ``rx, ry`` (rad), ``friction_torque`` and
        ``friction_torque_magnitude`` (N m), ``max_ball_load`` (N), ``max_contact_pressure``
        (Pa), ``static_safety_factor``, ``balls_in_four_point_contact``.
    statistics : dict or None
        As written to ``result.json`` (an infinite value is "inf", no value None); the
        statistics listed above, SI units.
    histogram : ndarray (m, 6) or None
        The load spectrum, one row a ball, diagonal and bin: ``ball``, ``diagonal``,
        ``load_lower_N``, ``load_upper_N`` (N), ``time_s`` (s), ``rotation_rad`` (rad).
    life : dict or None
        ``damage_map`` (4, slices) of contacts 1..4; ``swing`` (rad), ``count`` and ``travel_ratio``
        (x/2b) of the rainflow cycles; ``peak_pressure`` (4,), Pa.
    """

    key: str
    status: str
    elapsed: float
    worker: str
    timeseries: np.ndarray | None = None
    statistics: dict | None = None
    histogram: np.ndarray | None = None
    life: dict | None = None


def one_line(exc: BaseException) -> str:
    """``Type: first line of the message``."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")


def case_bearing(bearing, variant: dict):
    """The bearing of a variant: the file's, or with the seeded synthetic errors."""
    seed = variant.get("error_seed")
    if seed is None:
        return bearing
    from ..bearing.manufacturing import errors_from_table

    params = variant.get("synthetic_errors")
    if params is None:
        source = (bearing.source or {}).get("errors", {}) if isinstance(bearing.source, dict) else {}
        params = source.get("synthetic") if isinstance(source, dict) else None
        if params is None:
            raise ValueError(f"bearings.error_seeds = {seed}: the study gives no [bearings.synthetic_errors] and "
                             f"the bearing file {bearing.name!r} has no [errors.synthetic] table")
        params = {k: v for k, v in params.items() if k != "seed"}
    errors = errors_from_table({"synthetic": {**params, "seed": int(seed)}}, ".", bearing.ball_count)
    return bearing.with_errors(errors)


def simulator_for(task: CaseTask):
    """The :class:`BearingSimulator` of a case."""
    v, s = task.variant, task.simulation
    bearing = case_bearing(task.bearing, v)
    tolerances = {k: s[k] for k in ("tolerance", "friction_tolerance") if s.get(k) is not None}
    settings = SimulatorSettings(
        ring_model=v["ring_model"], moving_ring=s.get("moving_ring") or bearing.moving_ring,
        load_frame=task.series.load_frame,
        preload=None if v.get("preload_um") is None else v["preload_um"] * 1e-6,
        friction_coefficient=v["friction_coefficient"], seal_torque=s["seal_torque_Nm"],
        omega_regularisation=s["omega_regularisation_rad_s"], **tolerances)
    return BearingSimulator(bearing, task.superelement if v["ring_model"] == "flexible" else None, settings)


def run_case(task: CaseTask) -> CaseResult:
    """Step one case through its series: what a Dask worker runs.

    Never raises for a case that cannot be computed: its ``status`` says why.

    Parameters
    ----------
    task : CaseTask
        The bearing, its superelement, the series and the settings (no files).

    Returns
    -------
    CaseResult
        Time series, statistics, load spectrum and life of the case, or its error.
    """

    start = time.perf_counter()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    series = task.series
    n = series.time.size
    k = -1
    try:
        sim = simulator_for(task)
        out = np.empty((n, len(TIMESERIES_COLUMNS)))
        out[:, 0], out[:, 1], out[:, 2], out[:, 3:9] = series.time, series.psi, series.omega, series.loads
        diagonal = np.empty((n, sim.bearing.ball_count, 2), dtype=np.float32)
        life = LifeAccumulator(LifeModel(sim.bearing, sim.settings.moving_ring, sim.settings.load_frame), record=True)
        for k in range(n):
            r = sim.step(Loads.from_array(series.loads[k, :5]), float(series.psi[k]), float(series.omega[k]))
            d = r.distribution
            life.step(float(series.time[k]), float(series.psi[k]), d, series.loads[k, :5])
            out[k, 9:14] = d.displacement
            out[k, 14:] = (r.friction_torque, r.friction_torque_magnitude, d.max_ball_load, d.max_contact_pressure,
                           d.static_safety_factor, d.balls_in_four_point_contact)
            q = d.contact_load
            diagonal[k, :, 0] = np.maximum(q[:, 0], q[:, 2])
            diagonal[k, :, 1] = np.maximum(q[:, 1], q[:, 3])
    except Exception as exc:  # noqa: BLE001 - every failure of a case is its result
        where = f" at t = {series.time[k]:.6g} s (step {k + 1} of {n})" if k >= 0 else ""
        return CaseResult(task.key, one_line(exc).replace(": ", f"{where}: ", 1) if where else one_line(exc),
                          time.perf_counter() - start, worker)
    stats, histogram = statistics(out, diagonal, task.simulation["histogram_bins"])
    try:
        result = analyse_run(life)
    except Exception as exc:  # noqa: BLE001 - e.g. rainflow not installed: the case's other results stand
        return CaseResult(task.key, "ok", time.perf_counter() - start, worker, out, json_ready(stats), histogram,
                          {"error": one_line(exc)})
    stats.update(result.summary())
    stats = json_ready(stats)           # as result.json holds them: inf as "inf", no value as None
    cycles = {**life_files(result, life.model), "peak_pressure": result.peak_pressure}
    return CaseResult(task.key, "ok", time.perf_counter() - start, worker, out, stats, histogram, cycles)


def model_critical(sim) -> np.ndarray:
    """Critical angles of contacts 1..4 of the simulator's bearing, rad."""
    from ..life.oscillation import critical_angle
    from ..life.rating import TRACK_RINGS

    b = sim.bearing
    return np.array([float(critical_angle(b.ball_count, b.ball_diameter, b.pitch_diameter, b.contact_angle, r))
                     for r in TRACK_RINGS])


def time_weights(t: np.ndarray) -> np.ndarray:
    """Trapezoidal-rule weights of samples at times ``t`` (they sum to ``t[-1] - t[0]``)."""
    dt = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += dt / 2
    w[1:] += dt / 2
    return w


def _nice_ceiling(x: float) -> float:
    """The smallest of 1, 2, 2.5, 5 times a power of ten that is >= x (> 0)."""
    if x <= 0:
        return 1.0
    p = 10.0 ** math.floor(math.log10(x))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        if m * p >= x * (1 - 1e-12):
            return m * p
    return 10.0 * p  # pragma: no cover


def json_ready(data):
    """``data`` with every non-finite number made JSON (RFC 8259 has no Infinity or NaN): an infinite
    value (a life without damage) becomes the string ``"inf"`` (``"-inf"``), which ``float()`` reads
    back; NaN (a value that does not exist) becomes ``null``. Numpy scalars and arrays become
    numbers and lists."""
    if isinstance(data, dict):
        return {k: json_ready(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [json_ready(v) for v in data]
    if isinstance(data, np.ndarray):
        return json_ready(data.tolist())
    if isinstance(data, (bool, np.bool_)):
        return bool(data)
    if isinstance(data, (int, np.integer)):
        return int(data)
    if isinstance(data, (float, np.floating)):
        x = float(data)
        if math.isnan(x):
            return None
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        return x
    return data


def statistics(out: np.ndarray, diagonal: np.ndarray, bins: int) -> tuple[dict, np.ndarray]:
    """Statistics and load spectrum of a stepped case (see the module docstring).

    Parameters
    ----------
    out : ndarray (n, len(TIMESERIES_COLUMNS))
    diagonal : ndarray (n, B, 2), N
        Load of each ball's two diagonals at each step.
    bins : int
    """
    col = {c: out[:, j] for j, c in enumerate(TIMESERIES_COLUMNS)}
    w = time_weights(col["time"])
    torque = col["friction_torque_magnitude"]
    speed = np.abs(col["omega"])
    duration = float(w.sum())
    stats = {
        "friction_torque_mean": float(np.dot(w, torque) / duration),
        "friction_torque_max": float(torque.max()),
        "friction_torque_p99": float(np.percentile(torque, 99)),
        "friction_energy": float(np.dot(w, torque * speed)),
        "max_ball_load": float(col["max_ball_load"].max()),
        "max_contact_pressure": float(col["max_contact_pressure"].max()),
        "min_static_safety_factor": float(col["static_safety_factor"].min()),
        "rotation": float(np.dot(w, speed)),
        "duration": duration,
        "steps": int(out.shape[0]),
    }
    v = w * speed if np.dot(w, speed) > 0 else w
    q = diagonal.astype(float)
    cubic = np.einsum("k,kbd->bd", v, q ** 3) / v.sum()
    stats["equivalent_ball_load"] = float(np.cbrt(cubic).max())

    top = _nice_ceiling(float(q.max()))
    edges = np.linspace(0.0, top, bins + 1)
    index = np.clip(np.searchsorted(edges, q, side="right") - 1, 0, bins - 1)        # (n, B, 2)
    n, balls, _ = q.shape
    time_at = np.zeros((balls, 2, bins))
    rotation_at = np.zeros((balls, 2, bins))
    b_idx = np.broadcast_to(np.arange(balls)[None, :, None], index.shape)
    d_idx = np.broadcast_to(np.arange(2)[None, None, :], index.shape)
    wk = np.broadcast_to(w[:, None, None], index.shape)
    np.add.at(time_at, (b_idx, d_idx, index), wk)
    np.add.at(rotation_at, (b_idx, d_idx, index), wk * speed[:, None, None])
    b, d, j = np.nonzero(time_at > 0)
    histogram = np.column_stack([b + 1, np.where(d == 0, 13, 24), edges[j], edges[j + 1], time_at[b, d, j],
                                 rotation_at[b, d, j]])
    return stats, histogram
