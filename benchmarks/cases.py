"""The co-simulation cases users run, as plain input series: what the ``fmu`` benchmark times and
`tests/test_step_accuracy.py` checks step by step against tight-tolerance solves.

Each case is a bearing file, the FMU parameters (ring model, load frame) and, per step of
``dt``, the loads on the moving ring (Fx, Fy, Fz in N, Mx, My in N m), the ring's angle
``psi`` (rad) and speed ``omega`` (rad/s).

- ``pitch``: the 150-ball pitch bearing (`pitch_bearing.toml`) under the shipped blade-root
  series (turning with the blade: load frame "rotating"), the blade pitching +-5 deg at
  0.5 rad/s (a triangle wave), flexible rings, friction on.
- ``pitch_rigid``: the same with rigid rings.
- ``yaw``: the 180-ball yaw bearing (`yaw_bearing.toml`) under the shipped tower-top series
  (load frame "rotating", as `examples/yaw_manoeuvre.py`), yawing at 0.5 deg/s in bursts
  (10 s yawing, 5 s at rest, alternately in each direction).
- ``table3_heavy``: table3 with manufacturing errors, Fz 200 kN +- 5 %, Fx +-20 kN, Fy 10 kN,
  Mx +-50 kN m, My +-100 kN m, all varying, the ring turning at 0.1 rad/s.
- ``table3_light``: table3 with errors, Fz 10-30 kN with a 2 kN m moment, turning at
  0.5 rad/s (light: kept to compare with older figures).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DT = 0.01


@dataclass(frozen=True)
class Case:
    """Inputs of one benchmark case.

    Attributes
    ----------
    name, description : str
    bearing : Path
        Bearing definition (TOML).
    parameters : dict
        FMU start values (``ring_model`` 1 rigid / 2 flexible, ``load_frame`` 1 fixed / 2 rotating).
    loads : ndarray (n, 5)
        Fx, Fy, Fz (N), Mx, My (N m) per step.
    psi, omega : ndarray (n,)
        Ring angle (rad) and speed (rad/s) per step.
    """

    name: str
    description: str
    bearing: Path
    parameters: dict
    loads: np.ndarray
    psi: np.ndarray
    omega: np.ndarray

    @property
    def steps(self) -> int:
        return len(self.psi)


def _series(path, time: np.ndarray) -> np.ndarray:
    """Fx..My of a shipped load series CSV at ``time``, interpolated linearly."""
    from slewing_drives.load_series import LoadSeries   # numpy only: the FMU workers import no slewing_model

    series = LoadSeries.read_csv(path)
    return np.stack([np.interp(time, series.time, series.loads[:, k]) for k in range(5)], axis=1)


def _triangle(time: np.ndarray, amplitude: float, rate: float):
    """Angle and speed of a triangle wave between -amplitude and +amplitude at +-rate, starting at 0."""
    period = 4.0 * amplitude / rate
    phase = (time / period + 0.25) % 1.0
    rising = phase < 0.5
    psi = np.where(rising, amplitude * (4.0 * phase - 1.0), amplitude * (3.0 - 4.0 * phase))
    return psi, np.where(rising, rate, -rate)


def pitch(steps: int, *, rigid: bool = False) -> Case:
    time = np.arange(steps) * DT
    psi, omega = _triangle(time, math.radians(5.0), 0.5)
    return Case("pitch_rigid" if rigid else "pitch",
                f"pitch bearing, 150 balls, blade-root series, pitching +-5 deg at 0.5 rad/s, "
                f"{'rigid' if rigid else 'flexible'} rings",
                ROOT / "examples/bearings/pitch_bearing.toml", {"ring_model": 1 if rigid else 2, "load_frame": 2},
                _series(ROOT / "examples/loads/blade_root_loads.csv", time), psi, omega)


def yaw(steps: int) -> Case:
    time = np.arange(steps) * DT
    rate = math.radians(0.5)
    cycle = time % 30.0                    # 10 s yawing +, 5 s at rest, 10 s yawing -, 5 s at rest
    omega = np.where(cycle < 10.0, rate, np.where((cycle >= 15.0) & (cycle < 25.0), -rate, 0.0))
    psi = np.concatenate([[0.0], np.cumsum(omega[:-1]) * DT])
    return Case("yaw", "yaw bearing, 180 balls, tower-top series, yawing 0.5 deg/s in bursts, flexible rings",
                ROOT / "examples/bearings/yaw_bearing.toml", {"ring_model": 2, "load_frame": 2},
                _series(ROOT / "examples/loads/tower_top_loads.csv", time), psi, omega)


def table3_heavy(steps: int) -> Case:
    t = np.arange(steps) * DT
    loads = np.stack([2e4 * np.sin(0.7 * t), np.full_like(t, 1e4), 2e5 * (1.0 + 0.05 * np.sin(0.5 * t)),
                      5e4 * np.sin(0.3 * t + 1.0), 1e5 * np.cos(0.4 * t)], axis=1)
    return Case("table3_heavy", "table3 with errors (67 balls), Fz 200 kN +-5 %, Fx, Fy, Mx, My varying, "
                "turning at 0.1 rad/s, flexible rings", ROOT / "examples/bearings/table3_errors.toml",
                {"ring_model": 2, "load_frame": 1}, loads, 0.1 * t, np.full_like(t, 0.1))


def table3_light(steps: int) -> Case:
    t = np.arange(steps) * DT
    zero = np.zeros_like(t)
    loads = np.stack([zero, zero, 2e4 + 1e4 * np.sin(0.2 * t), 2e3 * np.cos(0.3 * t), zero], axis=1)
    return Case("table3_light", "table3 with errors, light load (Fz 10-30 kN, Mx 2 kN m), turning at 0.5 rad/s, "
                "flexible rings", ROOT / "examples/bearings/table3_errors.toml",
                {"ring_model": 2, "load_frame": 1}, loads, 0.5 * t, np.full_like(t, 0.5))


def saved(path, steps: int | None = None) -> Case:
    """A case written by :func:`save` (``.npz``): the FMU workers read scenarios made by a parent
    that may import ``slewing_model`` (an FMU's host process must not: the FMU brings its own)."""
    import json

    with np.load(path) as data:
        meta = json.loads(str(data["meta"]))
        n = len(data["psi"]) if steps is None else min(steps, len(data["psi"]))
        return Case(meta["name"], meta["description"], Path(meta["bearing"]), meta["parameters"],
                    data["loads"][:n], data["psi"][:n], data["omega"][:n])


def save(case: Case, path) -> Path:
    """Write ``case`` for :func:`saved`."""
    import json

    meta = {"name": case.name, "description": case.description, "bearing": str(case.bearing),
            "parameters": case.parameters}
    np.savez(path, meta=json.dumps(meta), loads=case.loads, psi=case.psi, omega=case.omega)
    return Path(path)


def load_case(name: str, steps: int) -> Case:
    """A case of :data:`CASES` by name, or one saved to ``name`` (``.npz``)."""
    return saved(name, steps) if name.endswith(".npz") else CASES[name](steps)


CASES = {"pitch": pitch, "pitch_rigid": lambda n: pitch(n, rigid=True), "yaw": yaw,
         "table3_heavy": table3_heavy, "table3_light": table3_light}
