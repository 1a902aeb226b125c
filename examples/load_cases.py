"""Load distributions of the paper's example bearings.

Solves the example bearings of the paper (Tables 1 and 3) under idling, axial,
tilting and combined loads with rigid rings and prints their load distributions.
"""
from __future__ import annotations

import math
from pathlib import Path


from slewing_model import Loads, load_bearing, solve

ROOT = Path(__file__).resolve().parents[1]

CASES = {
    "table1.toml": [("idling, +20 um preload", None, 20e-6),
                    ("axial 1 MN", Loads(Fz=1e6), 0.0),
                    ("tilting moment 200 kNm", Loads(Mx=200e3), 0.0),
                    ("combined Fz 800 kN, Fr 150 kN, Mt 1.2 MNm", Loads.from_paper(800e3, 150e3, 1.2e6), 0.0)],
    "table3.toml": [("idling, +20 um preload", None, 20e-6),
                    ("radial 100 kN", Loads(Fx=100e3), 0.0)],
}


def main() -> None:
    for name, cases in CASES.items():
        bearing = load_bearing(ROOT / "examples" / "bearings" / name)
        print(f"\n== {bearing.name}: dm {bearing.pitch_diameter * 1e3:g} mm, Dw {bearing.ball_diameter * 1e3:g} mm, "
              f"{bearing.ball_count} balls, rigid rings")
        print(f"{'case':<44} {'Qmax kN':>8} {'alpha max':>9} {'p max MPa':>9} {'safety':>7} {'4-pt balls':>10} "
              f"{'z um':>8} {'tilt urad':>9}")
        for label, loads, preload in cases:
            r = solve(bearing.with_preload(preload), loads)
            tilt = math.hypot(r.displacement[3], r.displacement[4])
            print(f"{label:<44} {r.max_ball_load / 1e3:8.2f} {math.degrees(r.contact_angle.max()):9.2f} "
                  f"{r.max_contact_pressure / 1e6:9.0f} {r.static_safety_factor:7.2f} "
                  f"{r.balls_in_four_point_contact:10d} {r.displacement[2] * 1e6:8.2f} {tilt * 1e6:9.2f}")
        # one load distribution in full: ball loads around the bearing for the last case
        q = r.contact_load
        print(f"ball loads around the bearing, {label} (kN, every {max(1, bearing.ball_count // 12)}th ball):")
        for b in range(0, bearing.ball_count, max(1, bearing.ball_count // 12)):
            print(f"  ball {b + 1:3d} at {math.degrees(r.ball_angle[b]):6.1f} deg: diagonal 1-3 {q[b, 0] / 1e3:7.2f}, "
                  f"diagonal 2-4 {q[b, 1] / 1e3:7.2f}")


if __name__ == "__main__":
    main()
