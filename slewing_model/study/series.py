"""Load series with the motion of the moving ring: what one case steps through.

Three sources (the ``[[loads]]`` entries of a study file):

* our CSV, SI units, header ``time,Fx,Fy,Fz,Mx,My,Mz,psi,omega`` (what ``slewing loads``
  writes), or the older ``time,Fx,Fy,Fz,Mx,My[,Mz]`` without the motion;
* an OpenFAST / FAST output file, through :func:`slewing_model.loads.openfast.read_output` and
  :func:`slewing_model.loads.aeroelastic.bearing_loads` (pitch angle or nacelle yaw as ``psi``);
* constant loads with a steady rotation.

Without a recorded motion, ``psi = omega_rad_s * (t - t0)`` (default: the ring stands
still). With ``psi`` but no ``omega``, ``omega`` is the central difference of ``psi``.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass

import numpy as np

LOAD_COLUMNS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")


@dataclass(frozen=True)
class MotionSeries:
    """Loads and motion of the moving ring against time (SI units).

    Attributes
    ----------
    time : ndarray (n,), s
        Sample times, strictly increasing.
    loads : ndarray (n, 6)
        Fx, Fy, Fz (N), Mx, My, Mz (N m); Mz is the moment the drive works against
        (recorded, not an input of the load distribution).
    psi : ndarray (n,), rad
        Angle of the moving ring.
    omega : ndarray (n,), rad/s
        Its speed.
    load_frame : {"fixed", "rotating"}
        Frame of the loads (rotating: turns with ``psi``).
    source : str
        Where the series comes from (for messages).
    lines : tuple of int or None
        Line of the file each row was read from (for messages), None when not read from a text file.
    recorded_motion : bool
        Whether the series gave the motion (``psi`` or ``omega``); False: ``psi`` was made up (the
        ring stands still, or turns at the study's ``omega_rad_s``).
    """

    time: np.ndarray
    loads: np.ndarray
    psi: np.ndarray
    omega: np.ndarray
    load_frame: str = "fixed"
    source: str = ""
    lines: tuple | None = None
    recorded_motion: bool = True

    def where(self, k: int) -> str:
        """Where row ``k`` comes from, for messages.

        Parameters
        ----------
        k : int
            Row, 0-based.

        Returns
        -------
        str
            ``FILE, line L, t = T s`` (``row`` instead of ``line`` when not read from a text file).
        """
        line = f", line {self.lines[k]}" if self.lines is not None else f", row {k + 1}"
        return f"{self.source}{line}, t = {self.time[k]:.6g} s"

    def __post_init__(self):
        n = self.time.shape[0]
        if self.time.ndim != 1 or n < 2:
            raise ValueError(f"{self.source}: at least two time steps are needed, found {n}")
        if self.loads.shape != (n, 6) or self.psi.shape != (n,) or self.omega.shape != (n,):
            raise ValueError(f"{self.source}: loads must be ({n}, 6) and psi, omega ({n},)")
        if np.any(np.diff(self.time) <= 0):
            raise ValueError(f"{self.source}: time must be strictly increasing")
        for name, values in (("time", self.time), ("loads", self.loads), ("psi", self.psi), ("omega", self.omega)):
            if not np.all(np.isfinite(values)):
                raise ValueError(f"{self.source}: {name} holds NaN or infinite values")


def _motion(time, psi, omega, omega_default, source):
    """Complete the motion: integrate a constant speed, or differentiate the angle."""
    if psi is None and omega is None:
        w = 0.0 if omega_default is None else float(omega_default)
        return w * (time - time[0]), np.full_like(time, w)
    if omega_default is not None:
        raise ValueError(f"{source}: omega_rad_s is only for series without a recorded motion (psi, omega)")
    if psi is None:   # trapezoidal integral of the speed
        psi = np.concatenate([[0.0], np.cumsum(0.5 * (omega[1:] + omega[:-1]) * np.diff(time))])
    if omega is None:
        omega = np.gradient(psi, time)
    return np.asarray(psi, float), np.asarray(omega, float)


def _frame(source: str, stated: str | None, asked: str | None, default: str) -> str:
    """The load frame: the study's (``asked``), the series' own (``stated``), else ``default``."""
    if asked is not None and stated is not None and asked != stated:
        raise ValueError(f"{source}: load_frame = {asked!r} in the study, but the series states {stated!r}")
    return asked or stated or default


def _data_rows(lines: list[str]) -> tuple[list[list[str]], list[int]]:
    """The rows of a CSV file that are neither blank nor comments, and their line numbers in the
    file (1-based, counting the comment and blank lines), so that messages point at the true line."""
    rows, numbers = [], []
    reader = csv.reader(lines)
    for row in reader:
        if row and not row[0].lstrip().startswith("#"):
            rows.append(row)
            numbers.append(reader.line_num)
    return rows, numbers


def check_increasing_time(path, time, lines) -> None:
    """Refuse a time column that does not increase strictly, naming the file's line (comment and
    blank lines counted) where it stops, its time and the previous row's.

    ``lines`` are the file's line numbers of the values of ``time``."""
    stop = np.flatnonzero(np.diff(time) <= 0)
    if stop.size:
        k = int(stop[0]) + 1
        raise ValueError(f"{path}, line {lines[k]}: time = {time[k]:.10g} s after {time[k - 1]:.10g} s on line "
                         f"{lines[k - 1]}: time must be strictly increasing (rows out of order, or repeated?)")


def read_csv(path: str, *, omega_default: float | None = None, load_frame: str | None = None,
             default_frame: str = "fixed") -> MotionSeries:
    """Read a load series CSV (SI): ``time,Fx,Fy,Fz,Mx,My[,Mz][,psi][,omega]``; a comment line
    ``# load_frame = fixed|rotating`` states the frame of the loads.

    Raises
    ------
    ValueError
        Naming the file, line and column of what is wrong.
    """
    stated = None
    try:
        with open(path, newline="") as fh:
            lines = fh.read().splitlines()
        for line in lines:
            text = line.strip()
            if text.startswith("#") and "=" in text and text[1:].split("=")[0].strip() == "load_frame":
                stated = text.split("=", 1)[1].strip()
                if stated not in ("fixed", "rotating"):
                    raise ValueError(f"{path}: comment load_frame = {stated!r}: must be 'fixed' or 'rotating'")
        rows, numbers = _data_rows(lines)
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the load series: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text (CSV) file") from None
    if not rows:
        raise ValueError(f"{path}: empty file (a header line is required)")
    header = [h.strip() for h in rows[0]]
    required = ["time", "Fx", "Fy", "Fz", "Mx", "My"]
    if header[:6] != required:
        raise ValueError(f"{path}: header must start with {','.join(required)}, found {','.join(header)}")
    for col in header[6:]:
        if col not in ("Mz", "psi", "omega"):
            raise ValueError(f"{path}: column {col!r} unknown (after My: Mz, psi, omega)")
    if len(set(header)) != len(header):
        raise ValueError(f"{path}: a column is repeated in the header {','.join(header)}")
    data = np.empty((len(rows) - 1, len(header)))
    for i, (n, row) in enumerate(zip(numbers[1:], rows[1:])):
        if len(row) != len(header):
            raise ValueError(f"{path}, line {n}: {len(row)} values for {len(header)} columns")
        for j, text in enumerate(row):
            try:
                data[i, j] = float(text)
            except ValueError:
                raise ValueError(f"{path}, line {n}, column {header[j]} = {text!r}: must be a number") from None
            if not math.isfinite(data[i, j]):
                raise ValueError(f"{path}, line {n}, column {header[j]} = {text!r}: must be finite")
    col = {h: data[:, j] for j, h in enumerate(header)}
    if len(data) < 2:
        raise ValueError(f"{path}: at least two rows with strictly increasing time are needed, found {len(data)}")
    check_increasing_time(path, col["time"], numbers[1:])
    loads = np.column_stack([col.get(c, np.zeros(len(data))) for c in LOAD_COLUMNS])
    psi, omega = _motion(col["time"], col.get("psi"), col.get("omega"), omega_default, path)
    return MotionSeries(col["time"].copy(), loads, psi, omega, _frame(path, stated, load_frame, default_frame), path,
                        tuple(numbers[1:]), "psi" in col or "omega" in col)


def write_csv(path: str, series: MotionSeries) -> None:
    """Write ``time,Fx,Fy,Fz,Mx,My,Mz,psi,omega`` (SI), readable by :func:`read_csv`."""
    table = np.column_stack([series.time, series.loads, series.psi, series.omega])
    np.savetxt(path, table, delimiter=",", fmt="%.10g", header="time,Fx,Fy,Fz,Mx,My,Mz,psi,omega", comments="")


def constant(loads, *, omega: float, duration: float, steps: int) -> MotionSeries:
    """Constant loads (6,) while the ring turns at ``omega`` (rad/s) for ``duration`` (s), ``steps`` samples."""
    time = np.linspace(0.0, duration, steps)
    return MotionSeries(time, np.tile(np.asarray(loads, float), (steps, 1)), omega * time, np.full(steps, float(omega)),
                        "fixed", "constant loads")


def from_openfast(path: str, *, bearing: str, blade: int = 1, mounting: str | None = None,
                  t_start: float | None = None, t_end: float | None = None, omega_default: float | None = None,
                  load_frame: str | None = None) -> MotionSeries:
    """Bearing loads and motion from an OpenFAST / FAST output file (``.out``, ``.outb``).

    Uses :func:`slewing_model.loads.openfast.read_output` and
    :func:`slewing_model.loads.aeroelastic.bearing_loads` (which turns the loads into the
    ``load_frame`` asked for, default ``"rotating"``: the blade's or the nacelle's frame);
    ``psi`` and ``omega`` are the recorded pitch (or yaw) angle and rate.
    """
    try:
        from ..loads import aeroelastic, openfast
    except ImportError as exc:
        raise ValueError(f"{path}: reading OpenFAST files needs slewing_model.loads.openfast and "
                         f"slewing_model.loads.aeroelastic ({exc})") from None
    output = openfast.read_output(path)
    options = {} if mounting is None else {"mounting": mounting}
    frame = load_frame or "rotating"
    series = aeroelastic.bearing_loads(output, bearing=bearing, blade=blade, t_start=t_start, t_end=t_end,
                                       frame=frame, **options)
    time = np.asarray(series.time, float)
    psi = getattr(series, "psi", None)
    omega = getattr(series, "omega", None)
    psi, omega = _motion(time, None if psi is None else np.asarray(psi, float),
                         None if omega is None else np.asarray(omega, float), omega_default, path)
    frame = _frame(path, getattr(series, "load_frame", None), frame, frame)
    return MotionSeries(time, np.asarray(series.loads, float), psi, omega, frame, path)


def window(series: MotionSeries, t_start: float | None, t_end: float | None, every: int = 1) -> MotionSeries:
    """The samples with ``t_start <= t <= t_end``, every ``every``-th one."""
    keep = np.ones(series.time.shape, bool)
    if t_start is not None:
        keep &= series.time >= t_start
    if t_end is not None:
        keep &= series.time <= t_end
    index = np.flatnonzero(keep)[::every]
    if index.size < 2:
        raise ValueError(f"{series.source}: fewer than two samples in the window "
                         f"[{t_start}, {t_end}] s (every {every}); the series spans "
                         f"{series.time[0]:g}..{series.time[-1]:g} s")
    return MotionSeries(series.time[index], series.loads[index], series.psi[index], series.omega[index],
                        series.load_frame, series.source)


def load_series(load: dict) -> MotionSeries:
    """The series of a study's ``[[loads]]`` entry (as :class:`~.definition.Case` ``.load``)."""
    kind = load["kind"]
    if kind == "constant":
        series = constant(load["loads"], omega=load["omega_rad_s"], duration=load["duration_s"], steps=load["steps"])
        series = MotionSeries(series.time, series.loads, series.psi, series.omega,
                              load["load_frame"] or load["default_frame"], load["name"])
    elif kind == "csv":
        series = read_csv(load["path"], omega_default=load["omega_rad_s"], load_frame=load["load_frame"],
                          default_frame=load["default_frame"])
    elif kind == "openfast":
        series = from_openfast(load["path"], bearing=load["bearing"], blade=load.get("blade", 1),
                               mounting=load.get("mounting"), t_start=load["t_start_s"], t_end=load["t_end_s"],
                               omega_default=load["omega_rad_s"], load_frame=load["load_frame"])
    else:  # pragma: no cover - the definition refuses it
        raise ValueError(f"unknown load kind {kind!r}")
    return window(series, load["t_start_s"], load["t_end_s"], load["every"])
