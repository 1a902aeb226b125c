"""Write the synthetic load series that ship with the examples (seeded, repeatable).

    .venv/bin/python examples/loads/make_load_series.py
"""
from pathlib import Path

from slewing_drives.load_series import synthetic_blade_root_loads, synthetic_tower_top_loads

HERE = Path(__file__).resolve().parent

#: the blade-root series of the pitch manoeuvre: a 7-10 MW class blade at rated wind (illustrative)
BLADE_ROOT = dict(duration=15.0, dt=0.01, seed=7, rotor_speed_rpm=9.0, blade_mass=35e3, blade_cg_radius=25.0,
                  mean_thrust_moment=10e6, mean_thrust_force=4.5e5, turbulence_intensity=0.12,
                  mean_pitching_moment=3e4, pitching_moment_gravity=2e4)
#: the tower-top series of the yaw manoeuvre: a 5-MW class nacelle (illustrative)
TOWER_TOP = dict(duration=40.0, dt=0.05, seed=11)


def main() -> None:
    synthetic_blade_root_loads(**BLADE_ROOT).write_csv(HERE / "blade_root_loads.csv")
    synthetic_tower_top_loads(**TOWER_TOP).write_csv(HERE / "tower_top_loads.csv")


if __name__ == "__main__":
    main()
