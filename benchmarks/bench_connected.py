"""Connected structures (issue 29): what they cost at build time, and that the step costs the same.

    .venv/bin/python benchmarks/bench_connected.py [--steps 400] [--meshes coarse fine]

1. Superelement build time (no cache) of the pitch bearing, free rings and bolted as in
   ``pitch_bearing_bolted.toml`` (hub flange on the outer ring, blade root on the inner one),
   per mesh, each build in this process one after the other.
2. ``--compare``: the pitch bearing at the two instants of the shipped blade-root series with the
   largest and the smallest moment, free / clamped / frictionless / bolted rings (coarse) and
   rigid rings: peak ball load and friction torque.
3. ``--tubes``: table1 (100 balls) with both rings bolted to steel tubes as wide as their faces,
   0.3 m and 1 m long, under a tilting moment of 1 MN m and an axial force of 1 MN: peak ball load
   against clamped, frictionless and free rings (coarse).
4. The step: the benchmark's pitch case (``cases.pitch``: blade-root series, pitching +-5 deg,
   flexible rings, friction on) through :class:`BearingSimulator` with the free and with the
   bolted superelement (coarse), interleaved step by step in one run: the median step time of each.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT))


def builds(meshes):
    from slewing_model import load_bearing
    from slewing_model.rings.superelement import build_superelement

    plain = load_bearing(ROOT / "examples/bearings/pitch_bearing.toml")
    bolted = load_bearing(ROOT / "examples/bearings/pitch_bearing_bolted.toml")
    rows = []
    for mesh in meshes:
        for name, bearing in (("free", plain), ("bolted", bolted)):
            t0 = time.perf_counter()
            se = build_superelement(bearing, mesh=mesh, bc="free", cache=False)
            seconds = time.perf_counter() - t0
            rings = se.metadata["rings"]
            extra = [rings[r].get("connection", {}).get("dofs", 0) for r in ("outer", "inner")]
            rows.append((mesh, name, seconds, [rings[r]["mesh"]["dofs"] for r in ("outer", "inner")], extra,
                         [rings[r]["harmonics"] for r in ("outer", "inner")]))
            print(f"build {mesh:6} {name:7} {seconds:7.2f} s  ring DOFs {rows[-1][3]}  adapter DOFs {extra}  "
                  f"harmonics {rows[-1][5]}", flush=True)
    return rows


def steps(n):
    import numpy as np

    from cases import pitch
    from slewing_model import Loads, load_bearing
    from slewing_model.rings.superelement import build_superelement
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    case = pitch(n)
    sims = {}
    for name, file in (("free", "pitch_bearing.toml"), ("bolted", "pitch_bearing_bolted.toml")):
        bearing = load_bearing(ROOT / "examples/bearings" / file)
        se = build_superelement(bearing, mesh="coarse", bc="free")
        sims[name] = BearingSimulator(bearing, se, SimulatorSettings(ring_model="flexible", load_frame="rotating"))
    times = {k: [] for k in sims}
    peaks = {k: [] for k in sims}
    iters = {k: [] for k in sims}
    for i in range(case.steps):
        loads = Loads(*case.loads[i])
        for name, sim in sims.items():
            t0 = time.perf_counter()
            r = sim.step(loads, float(case.psi[i]), float(case.omega[i]))
            times[name].append(time.perf_counter() - t0)
            peaks[name].append(r.distribution.max_ball_load)
            iters[name].append(r.distribution.iterations)
    for name in sims:
        t = np.array(times[name][10:])            # the first steps start cold
        print(f"step {name:7} median {1e3 * statistics.median(t):.2f} ms, mean {1e3 * t.mean():.2f} ms, "
              f"Newton iterations mean {np.mean(iters[name]):.2f}, peak ball load max "
              f"{max(peaks[name]) / 1e3:.1f} kN", flush=True)


def compare():
    import numpy as np

    from slewing_model import Loads, load_bearing
    from slewing_model.distribution.bime import solve
    from slewing_model.friction.torque import friction_torque
    from slewing_model.rings.superelement import build_superelement

    data = np.genfromtxt(ROOT / "examples/loads/blade_root_loads.csv", delimiter=",", names=True)
    moment = np.hypot(data["Mx"], data["My"])
    bolted = load_bearing(ROOT / "examples/bearings/pitch_bearing_bolted.toml")
    plain = bolted.with_connection(None)
    ses = {bc: build_superelement(plain, "coarse", bc) for bc in ("free", "clamped", "frictionless")}
    ses["bolted"] = build_superelement(bolted, "coarse", "free")
    ses["rigid"] = None
    for k in (int(np.argmax(moment)), int(np.argmin(moment))):
        loads = Loads(*(float(data[f][k]) for f in ("Fx", "Fy", "Fz", "Mx", "My")))
        print(f"t = {data['time'][k]:.2f} s: |M| = {moment[k] / 1e6:.2f} MN m, Fz = {data['Fz'][k] / 1e3:.0f} kN, "
              f"Fr = {np.hypot(data['Fx'][k], data['Fy'][k]) / 1e3:.0f} kN")
        for name, se in ses.items():
            r = solve(plain, loads, model="rigid" if se is None else "flexible", superelement=se)
            f = friction_torque(plain, r, omega=1.0)
            print(f"  {name:12} peak ball load {r.max_ball_load / 1e3:7.1f} kN, friction torque "
                  f"{f.magnitude / 1e3:6.2f} kN m", flush=True)


def tubes():
    from slewing_model import Loads, load_bearing
    from slewing_model.bearing.connection import Adapter
    from slewing_model.distribution.bime import solve
    from slewing_model.rings.superelement import build_superelement

    b = load_bearing(ROOT / "examples/bearings/table1.toml")

    def tube(ring, length):
        s = b.outer_section if ring == "outer" else b.inner_section
        return Adapter(ring, "tube", s.inner_radius, s.outer_radius, length, "far_end", 210e9, 210e9, 210e9,
                       210e9 / 2.6, 0.3)

    ses = {bc: build_superelement(b, "coarse", bc) for bc in ("clamped", "frictionless", "free")}
    for length in (0.3, 1.0):
        ses[f"tubes {length:g} m"] = build_superelement(
            b.with_connection({"outer": tube("outer", length), "inner": tube("inner", length)}), "coarse", "free")
    for loads in (Loads(0, 0, 0, 0, 1.0e6), Loads(0, 0, 1.0e6, 0, 0)):
        print(loads)
        q = {k: solve(b, loads, model="flexible", superelement=se).max_ball_load for k, se in ses.items()}
        for k, v in q.items():
            print(f"  {k:13} peak {v / 1e3:7.2f} kN, against clamped {100 * (v / q['clamped'] - 1):+6.1f} %, "
                  f"against frictionless {100 * (v / q['frictionless'] - 1):+6.1f} %", flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=400)
    p.add_argument("--meshes", nargs="*", default=["coarse", "fine"])
    p.add_argument("--no-builds", action="store_true")
    p.add_argument("--compare", action="store_true", help="the free / clamped / frictionless / bolted table")
    p.add_argument("--tubes", action="store_true", help="table1 on steel tubes against the idealisations")
    args = p.parse_args()
    if not args.no_builds:
        builds(args.meshes)
    if args.compare:
        compare()
    if args.tubes:
        tubes()
    if args.steps:
        steps(args.steps)


if __name__ == "__main__":
    main()
