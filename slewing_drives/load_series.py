"""Bearing load time series: CSV files and a seeded synthetic generator.

CSV format (SI units, header required)::

    time,Fx,Fy,Fz,Mx,My[,Mz]

``Fx..My`` are the loads on the bearing's moving ring (N, N m) in the frame
the FMU's ``load_frame`` parameter says; ``Mz`` (optional) is the moment about
the bearing axis that the drive works against (aerodynamic and gravity
pitching moment of a blade, aerodynamic yaw moment), N m. Values are
interpolated linearly in time.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass

import numpy as np

COLUMNS = ("time", "Fx", "Fy", "Fz", "Mx", "My", "Mz")


@dataclass(frozen=True)
class LoadSeries:
    """Loads against time.

    Attributes
    ----------
    time : ndarray (n,), s, strictly increasing
    loads : ndarray (n, 6)
        Fx, Fy, Fz (N), Mx, My, Mz (N m).
    """

    time: np.ndarray
    loads: np.ndarray

    def at(self, t: float) -> np.ndarray:
        """Loads (6,) at time ``t`` (held constant outside the series)."""
        return np.array([np.interp(t, self.time, self.loads[:, k]) for k in range(6)])

    def write_csv(self, path) -> None:
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            for t, row in zip(self.time, self.loads):
                w.writerow([f"{t:.6f}"] + [f"{v:.6g}" for v in row])

    @classmethod
    def read_csv(cls, path) -> "LoadSeries":
        with open(path, newline="") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].startswith("#")]
        header = [h.strip() for h in rows[0]]
        if header[:6] != list(COLUMNS[:6]):
            raise ValueError(f"{path}: header must start with {','.join(COLUMNS[:6])}, found {','.join(header)}")
        data = []
        for n, row in enumerate(rows[1:], start=2):
            try:
                values = [float(v) for v in row]
            except ValueError:
                raise ValueError(f"{path}, line {n}: {row!r}: every value must be a number") from None
            if len(values) != len(header) or not all(math.isfinite(v) for v in values):
                raise ValueError(f"{path}, line {n}: {len(header)} finite numbers expected")
            data.append(values + [0.0] * (7 - len(values)))
        data = np.array(data)
        if len(data) < 2 or np.any(np.diff(data[:, 0]) <= 0):
            raise ValueError(f"{path}: at least two rows with strictly increasing time are needed")
        return cls(data[:, 0], data[:, 1:7])


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
    duration, dt : float, s
    seed : int
    rotor_speed_rpm : float
    blade_mass : float, kg
    blade_cg_radius : float, m
        Distance of the blade's centre of gravity from the blade root.
    mean_thrust_moment, mean_thrust_force : float, N m and N
    turbulence_intensity : float
        Standard deviation of the thrust terms over their mean.
    turbulence_time_scale : float, s
    mean_pitching_moment, pitching_moment_gravity : float, N m
        Mean and 1P amplitude of the moment about the pitch axis (on the drive).

    Returns
    -------
    LoadSeries
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
    return LoadSeries(t, loads)


def synthetic_tower_top_loads(duration: float, *, dt: float = 0.05, seed: int = 0,
                              rotor_nacelle_mass: float = 350e3, thrust: float = 8e5, hub_height_offset: float = 3.0,
                              overhang_moment: float = 2.5e6, yaw_moment: float = 1.5e5,
                              turbulence_intensity: float = 0.1, turbulence_time_scale: float = 5.0) -> LoadSeries:
    """Yaw bearing loads: weight of rotor and nacelle, rotor thrust and its tilting
    moment, overhang moment of the rotor weight, aerodynamic yaw moment (Mz) with
    seeded turbulence. Nacelle frame (turns with the yaw angle)."""
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
