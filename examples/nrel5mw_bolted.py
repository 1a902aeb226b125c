"""NREL 5MW pitch bearing: free, clamped and bolted rings over the FAST v8 run.

The results: docs/guide/connected-structures.md ("What it changes").

    nice -n 10 .venv/bin/python examples/nrel5mw_bolted.py [-o results/nrel5mw_bolted] [--t-end 20] [--mesh-check]
        [--figure docs/figures/nrel5mw_bolted.png]

1. Derives the hub and blade-root tubes of ``examples/bearings/pitch_bearing_nrel5mw.toml`` from
   their published sources (printed) and checks the file against the derivation.
2. Steps the stand-in pitch bearing through blade 1 of the FAST v8 land-based run (60 s, turbulent
   12 m/s; loads in the blade-root frame, psi = the recorded pitch angle, as ``slewing life`` and the
   study read it: ``slewing_model.study.series.from_openfast``), with four ring models side by side:
   rigid rings; flexible free rings (the paper's idling model); flexible rings
   with clamped bolted faces; flexible rings bolted to the hub and blade-root tubes. Coarse
   superelements (cached). Friction coefficient 0.1 (the study's). Records at every step the peak
   ball load and the friction torque at full sliding (the torque the pitch drive must overcome),
   and the life accumulator (ISO/TS 16281 with the oscillation rule, raceway map, DG03).
3. The static sensitivity of the peak ball load at the run's largest moment to the assumed hub
   wall and blade-root length (builds of the coarse superelement for each variant).
4. ``--mesh-check``: the largest moment again with fine superelements (free, clamped, bolted).

Writes into ``-o``: ``summary.json`` (every number of the table), ``table.md``, ``series.csv``
(per step: time, |M|, psi, peak ball load and friction torque per ring model),
``largest_moment.csv`` (the contact loads around the bearing at the largest moment) and the
figure (``--figure``, default ``<out>/nrel5mw_bolted.png``).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
RUN = ROOT.parent / "shared/data/openfast/NREL5MW_Land_FASTv8_CertTest18_turb12mps_60s.outb"
PLAIN = ROOT / "examples/bearings/pitch_bearing.toml"
BOLTED = ROOT / "examples/bearings/pitch_bearing_nrel5mw.toml"

# ---- sources -----------------------------------------------------------------------------------
# Jonkman, Butterfield, Musial, Scott 2009, NREL/TP-500-38060 (NREL 5MW reference turbine)
# (checked in NREL's FAST input files of the turbine, github.com/old-NWTC/FAST CertTest/5MW_Baseline:
# NRELOffshrBsline5MW_Onshore_ElastoDyn.dat TipRad 63, HubRad 1.5, HubMass 56780; NRELOffshrBsline5MW_
# AeroDyn_blade.dat BlChord 3.542 at the root)
BLADE_LENGTH = 61.5               # m
ROOT_DIAMETER = 3.542             # m, chord at the blade root (a cylinder)
HUB_DIAMETER = 3.0                # m
HUB_MASS = 56_780.0               # kg
# WISDEM examples/02_reference_turbines/nrel5mw.yaml (windIO description of the NREL 5MW blade;
# github.com/WISDEM/WISDEM, commit 07df24f3680810cab6b2be1464cbde53e3e4cafa)
CYLINDER_END = 0.022222764        # span fraction where the "Cylinder" airfoil ends
ROOT_BUILDUP_GRID = [0.0, 0.012195122, 0.024390244]             # span fraction
ROOT_BUILDUP = [0.0517, 0.05143055156883146, 0.03168724979487978]  # m, glassTri "Root_build_up"
SKIN = 0.00282                    # m, glassTri "Shell_skin" and "Shell_skin_interior", each
GLASS_TRI = dict(axial=27.7, hoop=13.65, shear=7.2, nu=0.39)    # GPa, glassTri E1, E2, G, nu
CAST_IRON_DENSITY = 7200.0        # kg/m3, WISDEM cast_iron rho
# EN 1563 (spheroidal graphite cast iron), EN-GJS-400-18
CAST_IRON = dict(E=169.0, nu=0.275)  # GPa, -


def derive(bearing):
    """The two tubes from the sources above, scaled to the stand-in bearing (lengths in m)."""
    span = np.linspace(0.0, CYLINDER_END, 20001) * BLADE_LENGTH
    wall = np.interp(span, np.array(ROOT_BUILDUP_GRID) * BLADE_LENGTH, ROOT_BUILDUP) + 2 * SKIN
    wall_mean = float(np.trapezoid(wall, span) / span[-1])
    face = bearing.inner_section
    face_mid = face.inner_radius + face.outer_radius           # diameter of the face's middle
    scale = face_mid / (ROOT_DIAMETER - wall_mean)             # laminate mid-surface onto the face's middle
    root = dict(inner_diameter=face_mid - scale * wall_mean, outer_diameter=face_mid + scale * wall_mean,
                length=scale * span[-1], wall=scale * wall_mean)
    hub_wall = HUB_MASS / (CAST_IRON_DENSITY * math.pi * HUB_DIAMETER ** 2)   # a sphere's area pi D^2
    bore = 2 * bearing.outer_section.inner_radius
    hub = dict(inner_diameter=bore, outer_diameter=bore + 2 * scale * hub_wall, length=scale * HUB_DIAMETER / 2,
               wall=scale * hub_wall)
    return dict(root_cylinder_length_m=float(span[-1]), root_wall_at_root_m=float(wall[0]),
                root_wall_at_cylinder_end_m=float(wall[-1]), root_wall_mean_m=wall_mean,
                face_mid_diameter_m=face_mid, scale=scale, hub_wall_mass_equivalent_m=hub_wall,
                root=root, hub=hub)


def check_file(d):
    """The bearing file's tables against the derivation (0.1 mm: the file's rounding)."""
    table = tomllib.loads(BOLTED.read_text())["connection"]
    pairs = [(table["inner"], d["root"]), (table["outer"], d["hub"])]
    for t, ref in pairs:
        for key in ("inner_diameter", "outer_diameter", "length"):
            got, want = t[f"{key}_mm"], 1e3 * ref[key]
            if abs(got - want) > 0.051:
                raise SystemExit(f"{BOLTED.name}: {key}_mm = {got} but the derivation gives {want:.2f}")
    inner = table["inner"]
    assert (inner["axial_modulus_gpa"], inner["hoop_modulus_gpa"], inner["shear_modulus_gpa"],
            inner["poisson_ratio"]) == tuple(GLASS_TRI.values())
    assert (table["outer"]["youngs_modulus_gpa"], table["outer"]["poisson_ratio"]) == tuple(CAST_IRON.values())


def superelements(plain, bolted):
    from slewing_model.rings.superelement import build_superelement

    return {"rigid": None,
            "free": build_superelement(plain, "coarse", "free"),
            "clamped": build_superelement(plain, "coarse", "clamped"),
            "bolted": build_superelement(bolted, "coarse", "free")}


def run(series, plain, ses, mu):
    from slewing_model import Loads
    from slewing_model.life.duty import LifeAccumulator, LifeModel, LifeSettings, analyse_run
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    sims, accs = {}, {}
    for name, se in ses.items():
        sims[name] = BearingSimulator(plain, se, SimulatorSettings(
            ring_model="rigid" if se is None else "flexible", load_frame=series.load_frame, friction_coefficient=mu))
        model = LifeModel(sims[name].bearing, sims[name].settings.moving_ring, series.load_frame, LifeSettings())
        accs[name] = LifeAccumulator(model, record=True)
    n = series.time.size
    moment = np.hypot(series.loads[:, 3], series.loads[:, 4])
    k_max = int(np.argmax(moment))
    peak = {k: np.zeros(n) for k in sims}
    torque = {k: np.zeros(n) for k in sims}
    at_max = {}
    seconds = {k: 0.0 for k in sims}
    for i in range(n):
        loads = Loads.from_array(series.loads[i, :5])
        for name, sim in sims.items():
            t0 = time.perf_counter()
            r = sim.step(loads, float(series.psi[i]), float(series.omega[i]))
            seconds[name] += time.perf_counter() - t0
            peak[name][i] = r.distribution.max_ball_load
            torque[name][i] = r.friction_torque_magnitude
            accs[name].step(float(series.time[i]), float(series.psi[i]), r.distribution, series.loads[i, :5])
            if i == k_max:
                at_max[name] = (r.distribution.ball_angle.copy(), r.distribution.contact_load.copy())
        if i % 1000 == 0:
            print(f"  step {i}/{n}", flush=True)
    lives = {k: analyse_run(a) for k, a in accs.items()}
    return dict(k_max=k_max, moment=moment, peak=peak, torque=torque, at_max=at_max, lives=lives, seconds=seconds)


def sensitivity(plain, bolted, loads):
    """Peak ball load at the largest moment for other hub walls and blade-root lengths (coarse)."""
    from slewing_model.distribution.bime import solve
    from slewing_model.rings.superelement import build_superelement

    hub, root = bolted.connection["outer"], bolted.connection["inner"]

    def tube(a, **change):
        return dataclasses.replace(a, **change)

    wall = hub.outer_radius - hub.inner_radius
    rw = root.outer_radius - root.inner_radius
    variants = {
        "as derived": bolted.connection,
        "hub wall / 2": {"outer": tube(hub, outer_radius=hub.inner_radius + wall / 2), "inner": root},
        "hub wall / 4": {"outer": tube(hub, outer_radius=hub.inner_radius + wall / 4), "inner": root},
        "blade root 2 x long": {"outer": hub, "inner": tube(root, length=2 * root.length)},
        "blade root wall x 2": {"outer": hub, "inner": tube(root, inner_radius=root.inner_radius - rw / 2,
                                                             outer_radius=root.outer_radius + rw / 2)},
        "blade root wall / 2": {"outer": hub, "inner": tube(root, inner_radius=root.inner_radius + rw / 4,
                                                             outer_radius=root.outer_radius - rw / 4)},
        "hub clamped, blade root": {"inner": root},
        "blade root clamped, hub": {"outer": hub},
    }
    rows = []
    for name, conn in variants.items():
        b = plain.with_connection(conn)
        bc = "clamped"   # the ring without a connection (last two rows) is clamped
        se = build_superelement(b, "coarse", bc)
        r = solve(plain, loads, model="flexible", superelement=se)
        rows.append((name, r.max_ball_load))
        print(f"  sensitivity {name:24} peak ball load {r.max_ball_load / 1e3:7.2f} kN", flush=True)
    return rows


def mesh_check(plain, bolted, loads, mu):
    """Peak ball load and friction torque at the largest moment, coarse against fine superelements."""
    from slewing_model.distribution.bime import solve
    from slewing_model.friction.torque import friction_torque
    from slewing_model.rings.superelement import build_superelement

    rows = {}
    for mesh in ("coarse", "fine"):
        for name, b, bc in (("free", plain, "free"), ("clamped", plain, "clamped"), ("bolted", bolted, "free")):
            t0 = time.perf_counter()
            se = build_superelement(b, mesh, bc)
            r = solve(plain, loads, model="flexible", superelement=se)
            f = friction_torque(plain, r, omega=1.0, mu=mu)
            rows[f"{name} {mesh}"] = dict(peak_N=float(r.max_ball_load), friction_torque_Nm=float(f.magnitude))
            print(f"  mesh {mesh:6} {name:8} peak ball load {r.max_ball_load / 1e3:7.2f} kN, friction torque "
                  f"{f.magnitude / 1e3:6.2f} kN m ({time.perf_counter() - t0:.1f} s)", flush=True)
    return rows


def figure(path, res, series, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"rigid": "0.25", "free": "tab:blue", "clamped": "tab:red", "bolted": "tab:green"}
    labels = {"rigid": "rigid rings", "free": "free rings", "clamped": "clamped faces",
              "bolted": "bolted: hub + blade root"}
    fig, ax = plt.subplots(2, 2, figsize=(13, 8.5))
    a = ax[0, 0]
    for name, (angle, q) in res["at_max"].items():
        order = np.argsort(np.mod(angle, 2 * np.pi))
        deg = np.degrees(np.mod(angle, 2 * np.pi))[order]
        a.plot(deg, q[order, 0] / 1e3, "-", color=colours[name], label=f"{labels[name]}, diagonal 1")
        a.plot(deg, q[order, 1] / 1e3, "--", color=colours[name], label="diagonal 2" if name == "rigid" else None)
    k = res["k_max"]
    a.set(xlabel="ball angle [deg]", ylabel="contact load Q [kN]", xlim=(0, 360),
          title=f"ball loads at the largest moment, t = {series.time[k]:.2f} s, |M| = {res['moment'][k] / 1e6:.2f} MN m")
    a.set_ylim(0, 1.4 * max(q.max() for _, q in res["at_max"].values()) / 1e3)
    a.legend(fontsize=7, ncol=2, loc="upper center")
    a.grid(alpha=0.3)
    a = ax[0, 1]
    for name in res["peak"]:
        a.plot(series.time, res["peak"][name] / 1e3, color=colours[name], lw=0.8, label=labels[name],
               ls="--" if name == "rigid" else "-")
    a.set(xlabel="time [s]", ylabel="peak ball load [kN]", title="peak ball load over the FAST v8 run")
    a.legend(fontsize=7, loc="lower left")
    a.grid(alpha=0.3)
    a = ax[1, 0]
    for name in res["torque"]:
        a.plot(series.time, res["torque"][name] / 1e3, color=colours[name], lw=0.8, label=labels[name],
               ls="--" if name == "rigid" else "-")
    a3 = a.twinx()
    a3.plot(series.time, np.degrees(series.psi), color="tab:purple", lw=0.8, alpha=0.5)
    a3.set_ylabel("psi = -BldPitch1 [deg] (purple)")
    a.set(xlabel="time [s]", ylabel="friction torque at full sliding [kN m]",
          title="friction torque (mu = 0.1) over the run")
    a.legend(fontsize=7, loc="upper left")
    a.grid(alpha=0.3)
    a = ax[1, 1]
    names = list(summary["cases"])
    x = np.arange(len(names))
    ours = [_finite(summary["cases"][n]["L10_h"]) for n in names]
    dg03 = [_finite(summary["cases"][n]["L10_dg03_h"]) for n in names]
    a.bar(x - 0.2, ours, 0.4, color=[colours[n] for n in names], label="L10 ours (ISO/TS 16281 + oscillation)")
    a.bar(x + 0.2, dg03, 0.4, color="none", edgecolor="k", hatch="//", label="L10 DG03")
    for i, n in enumerate(names):
        a.text(i, max(ours[i], dg03[i]) * 1.02, f"DG03/ours {_g(summary['cases'][n]['dg03_ratio'], '.2f')}",
               ha="center", fontsize=8)
    a.set_xticks(x, [labels[n] for n in names], fontsize=8)
    a.set(ylabel="L10 [h of this duty repeated]", title="life of the FAST v8 run, blade 1")
    finite = [v for v in ours + dg03 if v is not None and math.isfinite(v)]
    if finite:
        a.set_ylim(0, 1.3 * max(finite))
    a.legend(fontsize=7, loc="upper center", ncol=2)
    fig.suptitle("NREL 5MW FAST v8 run (12 m/s, 60 s) on the 4.5 m stand-in pitch bearing: "
                 "free, clamped and bolted rings (coarse superelements)", fontsize=11)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def _finite(x):
    return 0.0 if x is None or not math.isfinite(x) else x


def _g(x, fmt=".3g"):
    return "-" if x is None else format(x, fmt)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", default=str(ROOT / "results/nrel5mw_bolted"))
    p.add_argument("--t-end", type=float, default=None, help="end of the window, s (default: the whole run)")
    p.add_argument("--figure", default=None)
    p.add_argument("--friction", type=float, default=0.1)
    p.add_argument("--no-sensitivity", action="store_true")
    p.add_argument("--mesh-check", action="store_true",
                   help="also the largest moment with fine superelements (builds of minutes)")
    args = p.parse_args()

    from slewing_model import Loads, load_bearing
    from slewing_model.study.series import from_openfast

    plain, bolted = load_bearing(PLAIN), load_bearing(BOLTED)
    d = derive(plain)
    check_file(d)
    print(f"blade root: cylinder {d['root_cylinder_length_m']:.3f} m, wall {1e3 * d['root_wall_at_root_m']:.1f} mm at "
          f"the root, {1e3 * d['root_wall_at_cylinder_end_m']:.1f} mm at the cylinder's end, mean "
          f"{1e3 * d['root_wall_mean_m']:.1f} mm; scale s = {d['face_mid_diameter_m']:.3f} / "
          f"({ROOT_DIAMETER} - {d['root_wall_mean_m']:.4f}) = {d['scale']:.4f}")
    print(f"  scaled tube: {1e3 * d['root']['inner_diameter']:.1f} x {1e3 * d['root']['outer_diameter']:.1f} mm, "
          f"wall {1e3 * d['root']['wall']:.1f} mm, length {1e3 * d['root']['length']:.1f} mm")
    print(f"hub: mass-equivalent wall {1e3 * d['hub_wall_mass_equivalent_m']:.1f} mm; scaled tube "
          f"{1e3 * d['hub']['inner_diameter']:.1f} x {1e3 * d['hub']['outer_diameter']:.1f} mm, wall "
          f"{1e3 * d['hub']['wall']:.1f} mm, length {1e3 * d['hub']['length']:.1f} mm")

    series = from_openfast(str(RUN), bearing="pitch", blade=1, t_end=args.t_end)
    print(f"run: {RUN.name}, blade 1, {series.time.size} steps, {series.time[0]:g}..{series.time[-1]:g} s, "
          f"loads in the {series.load_frame} frame", flush=True)
    t0 = time.perf_counter()
    ses = superelements(plain, bolted)
    print(f"superelements (coarse, cached): {time.perf_counter() - t0:.1f} s", flush=True)
    res = run(series, plain, ses, args.friction)
    k = res["k_max"]
    cases = {}
    for name in ses:
        life = res["lives"][name]
        s = life.summary()
        angle, q = res["at_max"][name]
        cases[name] = dict(
            peak_ball_load_max_N=float(res["peak"][name].max()),
            peak_ball_load_at_largest_moment_N=float(q.max()),
            balls_above_half_peak_at_largest_moment=int(np.sum(q.max(axis=1) > 0.5 * q.max())),
            friction_torque_mean_Nm=float(res["torque"][name].mean()),
            friction_torque_min_Nm=float(res["torque"][name].min()),
            friction_torque_max_Nm=float(res["torque"][name].max()),
            L10_h=s["life_L10_h"], L10_map_h=s["life_map_L10_h"], L10_dg03_h=s["life_dg03_L10_h"],
            dg03_ratio=s["life_dg03_ratio"], worst_track=s["life_worst_track"], cycles=s["life_cycles"],
            micro_cycles=s["life_micro_cycles"],
            track_damage=[float(x) for x in life.track_damage], step_time_s=res["seconds"][name])
    summary = dict(run=RUN.name, blade=1, steps=int(series.time.size), t_start_s=float(series.time[0]),
                   t_end_s=float(series.time[-1]), friction_coefficient=args.friction, mesh="coarse",
                   largest_moment=dict(time_s=float(series.time[k]), moment_Nm=float(res["moment"][k]),
                                       loads=[float(x) for x in series.loads[k, :5]]),
                   derivation=d, cases=cases)
    if not args.no_sensitivity:
        rows = sensitivity(plain, bolted, Loads.from_array(series.loads[k, :5]))
        summary["sensitivity_peak_at_largest_moment_N"] = {n: float(v) for n, v in rows}
    if args.mesh_check:
        summary["mesh_check_at_largest_moment"] = mesh_check(plain, bolted, Loads.from_array(series.loads[k, :5]),
                                                             args.friction)
    os.makedirs(args.output, exist_ok=True)
    with open(os.path.join(args.output, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1, default=lambda x: str(x))
    cols = ["time", "moment", "psi"] + [f"{w}_{n}" for n in ses for w in ("peak", "torque")]
    data = [series.time, res["moment"], series.psi] + [v for n in ses for v in (res["peak"][n], res["torque"][n])]
    np.savetxt(os.path.join(args.output, "series.csv"), np.column_stack(data), delimiter=",",
               header=",".join(cols), comments="")
    cols = ["ball_angle"] + [f"{n}_Q{c}" for n in ses for c in (1, 2, 3, 4)]
    data = [res["at_max"]["rigid"][0]] + [res["at_max"][n][1][:, c] for n in ses for c in range(4)]
    np.savetxt(os.path.join(args.output, "largest_moment.csv"), np.column_stack(data), delimiter=",",
               header=",".join(cols), comments="")
    lines = ["| rings | peak ball load, run max [kN] | at the largest moment [kN] | balls above half the peak | "
             "friction torque mean [kN m] | range [kN m] | L10 ours [h] | L10 map [h] | L10 DG03 [h] | DG03 / ours |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, c in cases.items():
        lines.append(f"| {name} | {c['peak_ball_load_max_N'] / 1e3:.1f} | {c['peak_ball_load_at_largest_moment_N'] / 1e3:.1f} | "
                     f"{c['balls_above_half_peak_at_largest_moment']} | {c['friction_torque_mean_Nm'] / 1e3:.2f} | "
                     f"{c['friction_torque_min_Nm'] / 1e3:.2f}..{c['friction_torque_max_Nm'] / 1e3:.2f} | "
                     f"{_g(c['L10_h'])} | {_g(c['L10_map_h'])} | {_g(c['L10_dg03_h'])} | {_g(c['dg03_ratio'], '.2f')} |")
    table = "\n".join(lines)
    with open(os.path.join(args.output, "table.md"), "w") as f:
        f.write(table + "\n")
    print(table)
    fig = figure(args.figure or os.path.join(args.output, "nrel5mw_bolted.png"), res, series, summary)
    print(f"wrote {args.output}/: summary.json, table.md, series.csv, largest_moment.csv; figure {fig}")


if __name__ == "__main__":
    main()
