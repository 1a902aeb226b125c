"""Bearing load time series: CSV files and a seeded synthetic generator.

CSV format (SI units, header required)::

    time,Fx,Fy,Fz,Mx,My[,Mz[,psi,omega]]

``Fx..My`` are the loads on the bearing's moving ring (N, N m) in the frame
the FMU's ``load_frame`` parameter says; ``Mz`` (optional) is the moment about
the bearing axis that the drive works against (aerodynamic and gravity
pitching moment of a blade, aerodynamic yaw moment), N m: positive when it
opposes a positive rotation, the sign :class:`slewing_drives.drive.ElectricDrive`
takes as ``load_torque``. ``psi`` (rad) and ``omega`` (rad/s), optional, are
the recorded motion of the moving ring (the pitch or yaw angle and its rate of
an aero-elastic run, :func:`slewing_model.loads.aeroelastic.bearing_loads`). Values
are interpolated linearly in time. Lines starting with ``#`` are comments; a
comment ``# load_frame = fixed`` (or ``rotating``) states the frame of the
loads and is read back into :attr:`LoadSeries.load_frame`.
"""
from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass

import numpy as np

COLUMNS = ("time", "Fx", "Fy", "Fz", "Mx", "My", "Mz")
#: the header with the recorded motion
MOTION_COLUMNS = COLUMNS + ("psi", "omega")
LOAD_FRAMES = ("fixed", "rotating")
_FRAME_COMMENT = re.compile(r"^#\s*load_frame\s*=\s*(\w+)\s*$")


@dataclass(frozen=True)
class LoadSeries:
    """Loads (and optionally the ring's motion) against time.

    Read and written as CSV by :meth:`read_csv` and :meth:`write_csv` (header
    ``time,Fx,Fy,Fz,Mx,My[,Mz[,psi,omega]]``, SI units).

    Attributes
    ----------
    time : ndarray (n,), s
        Sample times, strictly increasing.
    loads : ndarray (n, 6)
        Fx, Fy, Fz (N), Mx, My (N m) on the moving ring; Mz (N m), the moment
        the drive works against (positive when it opposes positive rotation).
    psi : ndarray (n,) or None, rad
        Recorded angle of the moving ring (None, default: not recorded).
    omega : ndarray (n,) or None, rad/s
        Recorded speed of the moving ring (given with ``psi`` or not at all).
    load_frame : {"fixed", "rotating"} or None
        Frame of ``Fx..My``: the fixed ring's, or the moving ring's (turned by
        ``psi``; the FMU's and :class:`slewing_model.simulation.simulator.SimulatorSettings`'
        ``load_frame``). None (default): not stated.

    Raises
    ------
    ValueError
        If the shapes do not match, only one of ``psi`` and ``omega`` is given or
        ``load_frame`` is unknown.

    Examples
    --------
    >>> from slewing_drives import LoadSeries
    >>> series = LoadSeries.read_csv("examples/loads/blade_root_loads.csv")
    >>> series.at(1.0).shape                # Fx, Fy, Fz (N), Mx, My, Mz (N m)
    (6,)
    """

    time: np.ndarray
    loads: np.ndarray
    psi: np.ndarray | None = None
    omega: np.ndarray | None = None
    load_frame: str | None = None

    def __post_init__(self):
        if (self.psi is None) != (self.omega is None):
            raise ValueError("psi and omega: give both or neither")
        if self.load_frame is not None and self.load_frame not in LOAD_FRAMES:
            raise ValueError(f"load_frame = {self.load_frame!r}: must be one of {', '.join(LOAD_FRAMES)} or None")
        n = np.shape(self.time)[0]
        if np.shape(self.loads) != (n, 6):
            raise ValueError(f"loads: shape {np.shape(self.loads)}, expected ({n}, 6) for {n} times")
        for name in ("psi", "omega"):
            value = getattr(self, name)
            if value is not None and np.shape(value) != (n,):
                raise ValueError(f"{name}: shape {np.shape(value)}, expected ({n},)")

    @property
    def has_motion(self) -> bool:
        """True when the series carries the recorded ``psi`` and ``omega``."""
        return self.psi is not None

    def at(self, t: float) -> np.ndarray:
        """Loads at a time, interpolated linearly.

        Parameters
        ----------
        t : float
            Time, s (the loads are held constant outside the series).

        Returns
        -------
        ndarray, shape (6,)
            Fx, Fy, Fz (N), Mx, My, Mz (N m).
        """
        return np.array([np.interp(t, self.time, self.loads[:, k]) for k in range(6)])

    def motion_at(self, t: float) -> tuple:
        """Recorded motion at a time, interpolated linearly.

        Parameters
        ----------
        t : float
            Time, s (the motion is held constant outside the series).

        Returns
        -------
        psi : float
            Angle of the moving ring, rad.
        omega : float
            Its speed, rad/s.

        Raises
        ------
        ValueError
            If the series has no recorded motion.
        """
        if not self.has_motion:
            raise ValueError("this load series has no recorded motion (psi, omega)")
        return float(np.interp(t, self.time, self.psi)), float(np.interp(t, self.time, self.omega))

    def write_csv(self, path, comments=()) -> None:
        """Write the series as CSV, SI units.

        Header ``time,Fx,Fy,Fz,Mx,My,Mz`` plus ``psi,omega`` when recorded, after the
        comments and the ``load_frame`` when it is stated.

        Parameters
        ----------
        path : str or path-like
            The file written.
        comments : sequence of str, optional
            Lines written at the top of the file, each as a comment (after a ``#`` and a space).
        """
        with open(path, "w", newline="") as fh:
            for line in comments:
                fh.write(f"# {line}\n")
            if self.load_frame is not None:
                fh.write(f"# load_frame = {self.load_frame}\n")
            w = csv.writer(fh)
            if self.has_motion:
                w.writerow(MOTION_COLUMNS)
                for t, row, p, o in zip(self.time, self.loads, self.psi, self.omega):
                    w.writerow([f"{t:.6f}"] + [f"{v:.6g}" for v in row] + [f"{p:.9g}", f"{o:.6g}"])
            else:
                w.writerow(COLUMNS)
                for t, row in zip(self.time, self.loads):
                    w.writerow([f"{t:.6f}"] + [f"{v:.6g}" for v in row])

    @classmethod
    def read_csv(cls, path) -> "LoadSeries":
        """Read a CSV of either header (``time,Fx,Fy,Fz,Mx,My[,Mz]`` or with ``psi,omega``).

        Parameters
        ----------
        path : str or path-like
            The CSV file, SI units; a missing ``Mz`` is 0.

        Returns
        -------
        LoadSeries
            With ``load_frame`` from a ``# load_frame = ...`` comment, if any.

        Raises
        ------
        ValueError
            Naming the file and line: a bad header, a value that is not a finite number,
            fewer than two rows or time not strictly increasing.
        """
        frame = None
        with open(path, newline="") as fh:
            rows, numbers = [], []            # the data rows and their line numbers in the file
            reader = csv.reader(fh)
            for r in reader:
                if r and r[0].startswith("#"):
                    m = _FRAME_COMMENT.match(",".join(r).strip())
                    if m:
                        frame = m.group(1)
                        if frame not in LOAD_FRAMES:
                            raise ValueError(f"{path}: load_frame = {frame!r}: must be one of {', '.join(LOAD_FRAMES)}")
                    continue
                if r:
                    rows.append(r)
                    numbers.append(reader.line_num)
        if not rows:
            raise ValueError(f"{path}: no header line")
        header = [h.strip() for h in rows[0]]
        allowed = (list(COLUMNS[:6]), list(COLUMNS), list(MOTION_COLUMNS))
        if header not in allowed:
            raise ValueError(f"{path}: header must be {','.join(COLUMNS[:6])}[,Mz] or {','.join(MOTION_COLUMNS)}, "
                             f"found {','.join(header)}")
        data = []
        for n, row in zip(numbers[1:], rows[1:]):
            try:
                values = [float(v) for v in row]
            except ValueError:
                raise ValueError(f"{path}, line {n}: {row!r}: every value must be a number") from None
            if len(values) != len(header) or not all(math.isfinite(v) for v in values):
                raise ValueError(f"{path}, line {n}: {len(header)} finite numbers expected")
            data.append(values)
        data = np.array(data)
        if len(data) < 2:
            raise ValueError(f"{path}: at least two rows with strictly increasing time are needed, found {len(data)}")
        stop = np.flatnonzero(np.diff(data[:, 0]) <= 0)
        if stop.size:        # the file's line where time stops increasing (comment and blank lines counted)
            k = int(stop[0]) + 1
            raise ValueError(f"{path}, line {numbers[k + 1]}: time = {data[k, 0]:.10g} s after {data[k - 1, 0]:.10g} s "
                             f"on line {numbers[k]}: time must be strictly increasing (rows out of order, or repeated?)")
        loads = np.zeros((len(data), 6))
        n_loads = min(len(header), 7) - 1                       # 5 without Mz, else 6
        loads[:, :n_loads] = data[:, 1:1 + n_loads]
        if len(header) == 9:
            return cls(data[:, 0], loads, data[:, 7].copy(), data[:, 8].copy(), frame)
        return cls(data[:, 0], loads, load_frame=frame)


def synthetic_blade_root_loads(duration: float, *, dt: float = 0.01, seed: int = 0,
                               rotor_speed_rpm: float = 9.0, blade_mass: float = 35e3,
                               blade_cg_radius: float = 25.0, mean_thrust_moment: float = 10e6,
                               mean_thrust_force: float = 4.5e5, turbulence_intensity: float = 0.12,
                               turbulence_time_scale: float = 3.0, mean_pitching_moment: float = 8e4,
                               pitching_moment_gravity: float = 4e4) -> LoadSeries:
    """Blade root loads of a multi-megawatt blade (blade frame: z along the blade).

    Mean thrust (flapwise) moment and shear, plus the rotor-periodic (1P)
    gravity moment and force of the blade, its centrifugal force, and
    turbulence as seeded first-order filtered noise on the thrust terms. The
    blade frame turns with the pitch angle: give these loads with the FMU's
    ``load_frame = rotating``.

    Parameters
    ----------
    duration : float
        Length of the series, s.
    dt : float, optional
        Time step, s. Default 0.01.
    seed : int, optional
        Seed of the turbulence; equal seeds give equal series. Default 0.
    rotor_speed_rpm : float, optional
        Rotor speed, rpm (1P period). Default 9.
    blade_mass : float, optional
        Blade mass, kg. Default 35e3.
    blade_cg_radius : float, optional
        Distance of the blade's centre of gravity from the blade root, m. Default 25.
    mean_thrust_moment : float, optional
        Mean flapwise (thrust) moment, N m. Default 10e6.
    mean_thrust_force : float, optional
        Mean flapwise shear, N. Default 4.5e5.
    turbulence_intensity : float, optional
        Standard deviation of the thrust terms over their mean. Default 0.12.
    turbulence_time_scale : float, optional
        Time constant of the turbulence filter, s. Default 3.
    mean_pitching_moment, pitching_moment_gravity : float, optional
        Mean and 1P amplitude of the moment about the pitch axis (on the drive), N m.
        Defaults 8e4 and 4e4.

    Returns
    -------
    LoadSeries
        Loads only (no recorded motion), ``load_frame = "rotating"``.

    Examples
    --------
    >>> from slewing_drives import synthetic_blade_root_loads
    >>> series = synthetic_blade_root_loads(60.0, seed=1)
    >>> series.time.size, series.load_frame
    (6001, 'rotating')
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration + dt / 2, dt)
    omega = rotor_speed_rpm * 2 * math.pi / 60
    azimuth = omega * t
    a = math.exp(-dt / turbulence_time_scale)
    noise = np.empty_like(t)
    x = 0.0
    for k in range(t.size):  # AR(1): first-order filtered white noise of unit variance
        x = a * x + math.sqrt(1 - a * a) * rng.standard_normal()
        noise[k] = x
    thrust = 1.0 + turbulence_intensity * noise
    g = 9.81
    gravity_moment = blade_mass * g * blade_cg_radius
    centrifugal = blade_mass * omega**2 * blade_cg_radius
    loads = np.column_stack([
        mean_thrust_force * thrust,                                  # Fx: flapwise shear
        blade_mass * g * np.sin(azimuth),                            # Fy: edgewise gravity shear
        centrifugal + blade_mass * g * np.cos(azimuth),              # Fz: along the blade (pulls the inner ring)
        gravity_moment * np.sin(azimuth),                            # Mx: edgewise gravity moment
        mean_thrust_moment * thrust,                                 # My: flapwise thrust moment
        mean_pitching_moment * thrust + pitching_moment_gravity * np.sin(azimuth),  # Mz: on the pitch drive
    ])
    return LoadSeries(t, loads, load_frame="rotating")                # the blade frame pitches with the blade


def synthetic_tower_top_loads(duration: float, *, dt: float = 0.05, seed: int = 0,
                              rotor_nacelle_mass: float = 350e3, thrust: float = 8e5, hub_height_offset: float = 3.0,
                              overhang_moment: float = 2.5e6, yaw_moment: float = 1.5e5,
                              turbulence_intensity: float = 0.1, turbulence_time_scale: float = 5.0) -> LoadSeries:
    """Yaw bearing loads of a multi-megawatt turbine.

    Weight of rotor and nacelle, rotor thrust and its tilting moment, overhang moment
    of the rotor weight, aerodynamic yaw moment (Mz) with seeded turbulence (first-order
    filtered noise on thrust and yaw moment). Nacelle frame (turns with the yaw angle).

    Parameters
    ----------
    duration : float
        Length of the series, s.
    dt : float, optional
        Time step, s. Default 0.05.
    seed : int, optional
        Seed of the turbulence. Default 0.
    rotor_nacelle_mass : float, optional
        Mass of rotor and nacelle, kg (``Fz = -m g``). Default 350e3.
    thrust : float, optional
        Mean rotor thrust, N (``Fx``). Default 8e5.
    hub_height_offset : float, optional
        Height of the hub above the yaw bearing, m (thrust's tilting moment). Default 3.
    overhang_moment : float, optional
        Tilting moment of the overhanging rotor weight, N m. Default 2.5e6.
    yaw_moment : float, optional
        Mean aerodynamic yaw moment, N m (``Mz``). Default 1.5e5.
    turbulence_intensity : float, optional
        Standard deviation of the gust factor. Default 0.1.
    turbulence_time_scale : float, optional
        Time constant of the turbulence filter, s. Default 5.

    Returns
    -------
    LoadSeries
        Loads only (no recorded motion); ``load_frame`` not stated (None).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration + dt / 2, dt)
    a = math.exp(-dt / turbulence_time_scale)
    x, noise = 0.0, np.empty_like(t)
    for k in range(t.size):
        x = a * x + math.sqrt(1 - a * a) * rng.standard_normal()
        noise[k] = x
    gust = 1.0 + turbulence_intensity * noise
    loads = np.column_stack([
        thrust * gust, np.zeros_like(t), np.full_like(t, -rotor_nacelle_mass * 9.81), np.zeros_like(t),
        overhang_moment + thrust * hub_height_offset * gust, yaw_moment * gust,
    ])
    return LoadSeries(t, loads)
