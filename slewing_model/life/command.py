"""``slewing life LOADS.csv BEARING.toml``: life and wear of one load series (table and figures).

Steps the bearing through the series (:class:`slewing_model.simulation.simulator.BearingSimulator`,
friction off: it does not change the load distribution), records the life accumulator, and
prints the ISO/TS 16281 life with the oscillation rule, the raceway map's life, DG03's life and
the wear indicators; with ``-o DIR`` it writes ``life_summary.json``, ``raceway_damage.csv``,
``life_cycles.csv`` and ``life.png`` there. Not a run-time module (matplotlib for the figure).
"""
from __future__ import annotations

import json
import math
import os


def add_arguments(p) -> None:
    p.add_argument("loads", help="load series CSV: time,Fx,Fy,Fz,Mx,My[,Mz][,psi][,omega] (SI; `slewing loads` "
                                 "writes one from an OpenFAST file)")
    p.add_argument("bearing", help="bearing definition (TOML)")
    p.add_argument("-o", "--output", default=None, metavar="DIR", help="write the table, maps and figure here")
    p.add_argument("--ring-model", choices=("rigid", "flexible"), default="rigid",
                   help="rigid rings (default, no build) or flexible (builds or reuses a coarse superelement)")
    p.add_argument("--load-frame", choices=("fixed", "rotating"), default=None,
                   help="frame of the loads (default: the file's '# load_frame =' comment, else fixed)")
    p.add_argument("--rating", type=float, default=None, metavar="N",
                   help="basic dynamic axial rating Ca of the bearing, N (default: from the raceway geometry)")
    p.add_argument("--slices", type=int, default=None, metavar="N", help="slices of each track in the map (720)")
    p.add_argument("--relubrication-swing", type=float, default=None, metavar="DEG",
                   help="ring movement that relubricates, deg (default: the largest critical angle)")


def run(args) -> int:
    from ..bearing.geometry import load_bearing
    from ..distribution.results import Loads
    from ..simulation.simulator import BearingSimulator, SimulatorSettings
    from ..study.series import read_csv
    from .duty import LifeAccumulator, LifeModel, LifeSettings, analyse_run
    from .raceway_map import DEFAULT_SLICES

    bearing = load_bearing(args.bearing)
    series = read_csv(args.loads, load_frame=args.load_frame)
    superelement = None
    if args.ring_model == "flexible":
        from ..rings.superelement import build_superelement

        superelement = build_superelement(bearing, mesh="coarse", bc="free")
    sim = BearingSimulator(bearing, superelement, SimulatorSettings(
        ring_model=args.ring_model, load_frame=series.load_frame, friction_coefficient=0.0))
    settings = LifeSettings(rating=args.rating, slices=args.slices or DEFAULT_SLICES,
                            relubrication_swing=None if args.relubrication_swing is None
                            else math.radians(args.relubrication_swing))
    model = LifeModel(sim.bearing, sim.settings.moving_ring, series.load_frame, settings)
    acc = LifeAccumulator(model, record=True)
    for k in range(series.time.size):
        r = sim.step(Loads.from_array(series.loads[k, :5]), float(series.psi[k]), float(series.omega[k]))
        acc.step(float(series.time[k]), float(series.psi[k]), r.distribution, series.loads[k, :5])
    res = analyse_run(acc)
    summary = res.summary()
    print(f"slewing life: {args.loads} on {bearing.name} ({args.ring_model} rings, loads in the "
          f"{series.load_frame} frame), {res.duration:g} s, {summary['life_cycles']:g} rainflow cycles")
    print(f"{'contact':>8} {'ring':>6} {'Qc [kN]':>9} {'crit [deg]':>10} {'D (ISO+osc.)':>13} {'D (map)':>11} "
          f"{'p_max [MPa]':>11}")
    for k in range(4):
        print(f"{k + 1:>8} {('outer', 'inner', 'inner', 'outer')[k]:>6} {model.capacity[k] / 1e3:9.2f} "
              f"{math.degrees(model.critical[k]):10.3f} {res.track_damage[k]:13.4e} {res.map_track_damage[k]:11.4e} "
              f"{res.peak_pressure[k] / 1e6:11.0f}")
    print(f"L10 (ISO/TS 16281 loads, oscillation rule): {res.life_hours:.4g} h of this duty, worst track "
          f"{res.worst_track}; damage {summary['life_damage_per_h']:.4g} per hour")
    print(f"L10 (raceway map):                          {res.map_life_hours:.4g} h")
    print(f"L10 (DG03, Pea_osc {res.dg03.pea_osc / 1e3:.4g} kN, theta_e {math.degrees(res.dg03.theta_e):.4g} deg, "
          f"Ca {model.rating / 1e3:.4g} kN): {res.dg03.hours:.4g} h, {summary['life_dg03_ratio']:.3g} x ours")
    print(f"cycles with x/2b < 1: {res.share_below_one:.1%}; below the critical angle: {res.below_critical:.1%}; "
          f"longest time without a {math.degrees(res.relubrication_swing):.3g} deg movement: "
          f"{res.relubrication_gap:.4g} s")
    if args.output:
        from ..study.engine import write_life
        from ..study.figures import life_figure

        os.makedirs(args.output, exist_ok=True)
        write_life(args.output, {"damage_map": res.damage_map, "swing": res.swing, "count": res.count,
                                 "travel_ratio": res.travel_ratio, "track_travel_ratio": res.track_travel_ratio,
                                 "cycle_peak_pressure": res.cycle_peak_pressure, "critical_angle": model.critical})
        with open(os.path.join(args.output, "life_summary.json"), "w") as fh:
            json.dump({**summary, "track_damage": res.track_damage.tolist(),
                       "map_track_damage": res.map_track_damage.tolist(), "capacity_N": model.capacity.tolist(),
                       "rating_N": model.rating, "dg03_pea_osc_N": res.dg03.pea_osc,
                       "dg03_theta_e_rad": res.dg03.theta_e, "duration_s": res.duration}, fh, indent=1)
        try:
            figure = life_figure(os.path.join(args.output, "life.png"), [args.output],
                                 title=f"{os.path.basename(args.loads)} on {bearing.name}")
            print(f"wrote {args.output}/: life_summary.json, raceway_damage.csv, life_cycles.csv, {figure}")
        except ImportError:
            print(f"wrote {args.output}/: life_summary.json, raceway_damage.csv, life_cycles.csv "
                  f"(no figure: matplotlib is not installed)")
    return 0
