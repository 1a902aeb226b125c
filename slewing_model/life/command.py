"""``slewing life LOADS.csv BEARING.toml``: life and wear of one load series (table and figures).

Steps the bearing through the series (:class:`slewing_model.simulation.simulator.BearingSimulator`,
friction off: it does not change the load distribution), records the life accumulator, and
prints the ISO/TS 16281 life with the oscillation rule, the raceway map's life, DG03's life and
the wear indicators; with ``-o DIR`` it writes ``life_summary.json`` (strict JSON: an infinite
life is ``"inf"``, a value that does not exist ``null``), ``raceway_damage.csv``,
``life_cycles.csv`` and ``life.png`` there. A series without the ring angle (no ``psi`` nor
``omega`` column) is refused: it has no oscillation to count. Not a run-time module
(matplotlib for the figure).
"""
from __future__ import annotations

import math
import os
import sys


def add_arguments(p) -> None:
    p.add_argument("loads", help="load series CSV: time,Fx,Fy,Fz,Mx,My[,Mz],psi[,omega] (SI; the ring angle psi, "
                                 "or its speed omega, is required; `slewing loads` writes one from an OpenFAST file)")
    p.add_argument("bearing", help="bearing definition (TOML)")
    p.add_argument("-o", "--output", default=None, metavar="DIR",
                   help="write the table, maps and figure here (default: print only)")
    p.add_argument("--ring-model", choices=("rigid", "flexible"), default="rigid",
                   help="rigid rings (no build) or flexible (builds or reuses a coarse superelement)")
    p.add_argument("--load-frame", choices=("fixed", "rotating"), default=None,
                   help="frame of the loads (default: the file's '# load_frame =' comment, else fixed)")
    p.add_argument("--rating", type=float, default=None, metavar="N",
                   help="basic dynamic axial rating Ca of the bearing, N (default: from the raceway geometry)")
    p.add_argument("--slices", type=int, default=None, metavar="N",
                   help="slices of each track in the map, a whole number >= 4 (default: the first count from "
                        "1440 with no common divisor with the ball count, 1441 for 150 balls: no aliasing)")
    p.add_argument("--relubrication-swing", type=float, default=None, metavar="DEG",
                   help="ring movement that relubricates, deg, > 0 (default: the largest critical angle)")


def check_arguments(args) -> None:
    """Refuse what the options' rules forbid, naming the option, the value as given and the rule."""
    if args.slices is not None and args.slices < 4:
        raise ValueError(f"--slices {args.slices}: must be a whole number >= 4 (slices of each track in the map)")
    if args.relubrication_swing is not None and not (math.isfinite(args.relubrication_swing)
                                                     and args.relubrication_swing > 0):
        raise ValueError(f"--relubrication-swing {args.relubrication_swing:g} deg: must be finite and > 0 (deg)")
    if args.rating is not None and not (math.isfinite(args.rating) and args.rating > 0):
        raise ValueError(f"--rating {args.rating:g} N: must be finite and > 0 (N)")


def _share(x: float) -> str:
    return "-" if x is None or math.isnan(x) else f"{x:.1%}"


def _hours(x: float) -> str:
    return "infinite (no damage)" if math.isinf(x) else f"{x:.4g} h"


def run(args) -> int:
    from ..bearing.geometry import load_bearing
    from ..distribution.results import Loads, NoEquilibriumError
    from ..simulation.simulator import BearingSimulator, SimulatorSettings
    from ..study.series import read_csv
    from .duty import MICRO_CYCLE_STEPS, LifeAccumulator, LifeModel, LifeSettings, analyse_run, life_files

    check_arguments(args)
    bearing = load_bearing(args.bearing)
    series = read_csv(args.loads, load_frame=args.load_frame)
    if not series.recorded_motion:
        raise ValueError(f"{args.loads}: no column psi (nor omega): `slewing life` counts the oscillations of the "
                         f"ring angle psi (rad) and needs it on every row; this file has only the loads "
                         f"(`slewing loads` writes psi and omega from an OpenFAST file's pitch or yaw angle; "
                         f"examples/loads/blade_root_pitch_series.csv is a series with psi)")
    superelement = None
    if args.ring_model == "flexible":
        from ..rings.superelement import build_superelement

        superelement = build_superelement(bearing, mesh="coarse", bc="free")
    sim = BearingSimulator(bearing, superelement, SimulatorSettings(
        ring_model=args.ring_model, load_frame=series.load_frame, friction_coefficient=0.0))
    settings = LifeSettings(rating=args.rating, slices=args.slices,
                            relubrication_swing=None if args.relubrication_swing is None
                            else math.radians(args.relubrication_swing))
    model = LifeModel(sim.bearing, sim.settings.moving_ring, series.load_frame, settings)
    acc = LifeAccumulator(model, record=True)
    for k in range(series.time.size):
        try:
            r = sim.step(Loads.from_array(series.loads[k, :5]), float(series.psi[k]), float(series.omega[k]))
        except (NoEquilibriumError, ValueError) as exc:
            raise ValueError(f"{series.where(k)}: {exc}") from None
        acc.step(float(series.time[k]), float(series.psi[k]), r.distribution, series.loads[k, :5])
    res = analyse_run(acc)
    for text in res.warnings:
        print(f"slewing life: warning: {text}", file=sys.stderr)
    summary = res.summary()
    print(f"slewing life: {args.loads} on {bearing.name} ({args.ring_model} rings, loads in the "
          f"{series.load_frame} frame), {res.duration:g} s, {summary['life_cycles']:g} rainflow cycles, "
          f"{model.slices} slices a track")
    print(f"{'contact':>8} {'ring':>6} {'Qc [kN]':>9} {'crit [deg]':>10} {'D (ISO+osc.)':>13} {'D (map)':>11} "
          f"{'p_max [MPa]':>11}")
    for k in range(4):
        print(f"{k + 1:>8} {('outer', 'inner', 'inner', 'outer')[k]:>6} {model.capacity[k] / 1e3:9.2f} "
              f"{math.degrees(model.critical[k]):10.3f} {res.track_damage[k]:13.4e} {res.map_track_damage[k]:11.4e} "
              f"{res.peak_pressure[k] / 1e6:11.0f}")
    if res.worst_track is None:
        print("L10 (ISO/TS 16281 loads, oscillation rule): infinite: no damage (the ring never moved by more than "
              f"the reversal tolerance, {settings.reversal_tolerance:g} rad), no worst track")
    else:
        print(f"L10 (ISO/TS 16281 loads, oscillation rule): {res.life_hours:.4g} h of this duty, worst track "
              f"{res.worst_track}; damage {summary['life_damage_per_h']:.4g} per hour")
    print(f"L10 (raceway map):                          {_hours(res.map_life_hours)}")
    ratio = "no ratio: neither has damage" if summary["life_dg03_ratio"] is None \
        else f"{summary['life_dg03_ratio']:.3g} x ours"
    note = "; theta_e above the critical angle: DG03's factor used beyond its range" if res.dg03.above_critical else ""
    print(f"L10 (DG03, Pea_osc {res.dg03.pea_osc / 1e3:.4g} kN, theta_e {math.degrees(res.dg03.theta_e):.4g} deg, "
          f"Ca {model.rating / 1e3:.4g} kN): {_hours(res.dg03.hours)}, {ratio}{note}")
    if res.count.sum() > 0:
        print(f"x/2b < 1: {_share(res.share_below_one)} of the cycles, {_share(res.damage_share_below_one)} of the "
              f"damage; below the critical angle: {_share(res.below_critical)} of the cycles, "
              f"{_share(res.damage_share_below_critical)} of the damage ({res.micro_cycles:g} micro-cycles below "
              f"{math.degrees(res.micro_swing):.2g} deg = {MICRO_CYCLE_STEPS} steps of the angle's resolution "
              f"left out of the counts)")
    else:
        print("no rainflow cycles: no x/2b, no share below the critical angle")
    print(f"longest time without a {math.degrees(res.relubrication_swing):.3g} deg movement: "
          f"{res.relubrication_gap:.4g} s")
    if args.output:
        from ..study.engine import write_json, write_life
        from ..study.figures import life_figure

        os.makedirs(args.output, exist_ok=True)
        write_life(args.output, life_files(res, model))
        write_json(os.path.join(args.output, "life_summary.json"), {
            **summary, "track_damage": res.track_damage, "map_track_damage": res.map_track_damage,
            "capacity_N": model.capacity, "rating_N": model.rating, "dg03_pea_osc_N": res.dg03.pea_osc,
            "dg03_theta_e_rad": res.dg03.theta_e, "duration_s": res.duration, "slices": model.slices,
            "micro_swing_rad": res.micro_swing, "warnings": list(res.warnings)})
        if res.count.sum() == 0:
            print(f"wrote {args.output}/: life_summary.json, raceway_damage.csv, life_cycles.csv "
                  f"(no figure: no rainflow cycles, nothing to draw)")
            return 0
        try:
            figure = life_figure(os.path.join(args.output, "life.png"), [args.output],
                                 title=f"{os.path.basename(args.loads)} on {bearing.name}")
            print(f"wrote {args.output}/: life_summary.json, raceway_damage.csv, life_cycles.csv, {figure}")
        except ImportError:
            print(f"wrote {args.output}/: life_summary.json, raceway_damage.csv, life_cycles.csv "
                  f"(no figure: matplotlib is not installed)")
    return 0

