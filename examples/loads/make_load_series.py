"""Write the synthetic load series that ship with the examples (seeded, repeatable).

    .venv/bin/python examples/loads/make_load_series.py

* ``blade_root_loads.csv``: blade-root loads of the pitch manoeuvre (no ring angle: the drive
  sets it).
* ``tower_top_loads.csv``: tower-top loads of the yaw manoeuvre.
* ``blade_root_pitch_series.csv``: blade-root loads with the pitch bearing's angle ``psi`` and
  speed ``omega`` of a pitch schedule, for ``slewing life`` (which counts the oscillations of
  ``psi``)::

      .venv/bin/slewing life examples/loads/blade_root_pitch_series.csv examples/bearings/pitch_bearing.toml
"""
import dataclasses
import math
from pathlib import Path

import numpy as np

from slewing_drives.load_series import synthetic_blade_root_loads, synthetic_tower_top_loads

HERE = Path(__file__).resolve().parent

#: the blade-root series of the pitch manoeuvre: a 7-10 MW class blade at rated wind (illustrative)
BLADE_ROOT = dict(duration=15.0, dt=0.01, seed=7, rotor_speed_rpm=9.0, blade_mass=35e3, blade_cg_radius=25.0,
                  mean_thrust_moment=10e6, mean_thrust_force=4.5e5, turbulence_intensity=0.12,
                  mean_pitching_moment=3e4, pitching_moment_gravity=2e4)
#: the tower-top series of the yaw manoeuvre: a 5-MW class nacelle (illustrative)
TOWER_TOP = dict(duration=40.0, dt=0.05, seed=11)
#: the pitch series: the blade-root loads of BLADE_ROOT's blade over 60 s, sampled every 0.05 s
PITCH_LOADS = {**BLADE_ROOT, "duration": 60.0, "dt": 0.05, "seed": 5}
#: its pitch schedule: mean pitch angle (deg); the pitch controller's answer to the turbulence (deg per
#: standard deviation of the thrust) and its time constant (s); a gust met by pitching to feather at 40 s
PITCH_SCHEDULE = dict(mean_deg=3.0, turbulence_deg=1.5, time_constant_s=1.5, gust_at_s=40.0, gust_deg=4.0,
                      rate_deg_s=4.0)


def pitch_series(loads=PITCH_LOADS, schedule=PITCH_SCHEDULE):
    """The blade-root loads with the pitch bearing's motion: the pitch angle beta follows the thrust's
    turbulence through a first-order lag (more thrust, more pitch to feather), plus a gust step at the
    drive's rate; psi = -beta (the bearing's +z towards the blade tip, docs/guide/openfast-loads.md) and omega its
    time derivative."""
    series = synthetic_blade_root_loads(**loads)
    t = series.time
    turbulence = (series.loads[:, 0] / loads["mean_thrust_force"] - 1.0) / loads["turbulence_intensity"]
    a = math.exp(-loads["dt"] / schedule["time_constant_s"])
    lagged = np.empty_like(t)
    x = 0.0
    for k, u in enumerate(turbulence):      # the controller's lag
        x = a * x + (1.0 - a) * u
        lagged[k] = x
    gust = np.clip((t - schedule["gust_at_s"]) * schedule["rate_deg_s"], 0.0, schedule["gust_deg"])
    beta = np.radians(schedule["mean_deg"] + schedule["turbulence_deg"] * lagged + gust)
    psi = -beta
    return dataclasses.replace(series, psi=psi, omega=np.gradient(psi, t))


def main() -> None:
    synthetic_blade_root_loads(**BLADE_ROOT).write_csv(HERE / "blade_root_loads.csv")
    synthetic_tower_top_loads(**TOWER_TOP).write_csv(HERE / "tower_top_loads.csv")
    pitch_series().write_csv(HERE / "blade_root_pitch_series.csv", comments=(
        "synthetic blade-root loads (slewing_drives.synthetic_blade_root_loads, seed 5, 60 s, dt 0.05 s)",
        "with a pitch schedule (3 deg, the controller's answer to the turbulence, a 4 deg gust step at 40 s);",
        "psi = -pitch angle (+z towards the blade tip), omega = dpsi/dt; written by",
        ".venv/bin/python examples/loads/make_load_series.py (PITCH_LOADS, PITCH_SCHEDULE there)",
    ))


if __name__ == "__main__":
    main()
