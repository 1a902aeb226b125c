"""Connected structures: what they cost at build time, and that the step costs the same.

    .venv/bin/python -m benchmarks connected [--steps 400] [--meshes coarse fine] [--compare] [--tubes]

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

import statistics
import time

from .suite import ROOT, print_table


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
            dofs = [rings[r]["mesh"]["dofs"] for r in ("outer", "inner")]
            harmonics = [rings[r]["harmonics"] for r in ("outer", "inner")]
            rows.append([mesh, name, f"{seconds:.2f} s", f"{dofs[0]}, {dofs[1]}", f"{extra[0]}, {extra[1]}",
                         f"{harmonics[0]}, {harmonics[1]}"])
            print(f"  built {mesh} {name}: {seconds:.1f} s", flush=True)
    print_table("Superelement build of the pitch bearing, no cache, free and bolted rings (pitch_bearing_bolted.toml)",
                ["mesh", "rings", "build time", "ring DOFs (outer, inner)", "adapter DOFs (outer, inner)",
                 "harmonics (outer, inner)"], rows)
    return rows


def steps(n):
    import numpy as np

    from slewing_model import Loads, load_bearing
    from slewing_model.rings.superelement import build_superelement
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    from .cases import pitch

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
    rows = []
    for name in sims:
        t = np.array(times[name][10:])            # the first steps start cold
        rows.append([name, f"{1e3 * statistics.median(t):.2f} ms", f"{1e3 * np.percentile(t, 95):.2f} ms",
                     f"{1e3 * t.mean():.2f} ms", f"{np.mean(iters[name]):.2f}", f"{max(peaks[name]) / 1e3:.1f} kN"])
    print_table(f"The pitch case ({n} steps, the first 10 left out), free and bolted rings (coarse), interleaved step "
                "by step", ["rings", "median step", "95th pct", "mean step", "Newton iterations (mean)",
                            "largest peak ball load"], rows)


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
        rows = []
        for name, se in ses.items():
            r = solve(plain, loads, model="rigid" if se is None else "flexible", superelement=se)
            f = friction_torque(plain, r, omega=1.0)
            rows.append([name, f"{r.max_ball_load / 1e3:.1f} kN", f"{f.magnitude / 1e3:.2f} kN m"])
        print_table(f"Pitch bearing at t = {data['time'][k]:.2f} s of the blade-root series: |M| = "
                    f"{moment[k] / 1e6:.2f} MN m, Fz = {data['Fz'][k] / 1e3:.0f} kN, "
                    f"Fr = {np.hypot(data['Fx'][k], data['Fy'][k]) / 1e3:.0f} kN",
                    ["rings", "peak ball load", "friction torque"], rows)


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
        q = {k: solve(b, loads, model="flexible", superelement=se).max_ball_load for k, se in ses.items()}
        print_table(f"table1 on steel tubes, {loads}",
                    ["rings", "peak ball load", "against clamped", "against frictionless"],
                    [[k, f"{v / 1e3:.2f} kN", f"{100 * (v / q['clamped'] - 1):+.1f} %",
                      f"{100 * (v / q['frictionless'] - 1):+.1f} %"] for k, v in q.items()])


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=400, help="steps of the pitch case (0: no step timing)")
    parser.add_argument("--meshes", nargs="*", default=["coarse", "fine"])
    parser.add_argument("--no-builds", action="store_true")
    parser.add_argument("--compare", action="store_true", help="the free / clamped / frictionless / bolted table")
    parser.add_argument("--tubes", action="store_true", help="table1 on steel tubes against the idealisations")


def main(args) -> None:
    if not args.no_builds:
        builds(args.meshes)
    if args.compare:
        compare()
    if args.tubes:
        tubes()
    if args.steps:
        steps(args.steps)
