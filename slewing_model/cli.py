"""The ``slewing`` command line.

``slewing solve BEARING.toml [--fx N] [--fy N] [--fz N] [--mx Nm] [--my Nm] [--model rigid|flexible] [--json]``
``slewing superelement BEARING.toml [--mesh coarse|fine] [--bc free|clamped|frictionless] -o FILE``
``slewing loads FILE.outb --bearing pitch|yaw [--blade K] [--mounting M] [--start s] [--end s] -o LOADS.csv``
``slewing turbine TURBINE.toml -o DIR`` (the turbine loop: slewing_turbine, imported when it runs)
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import select
import sys

import numpy as np

from . import __version__
from .distribution.bime import LOAD_FIELDS, Loads, NoEquilibriumError, solve
from .friction.torque import catalogue_torque, friction_torque
from .bearing.geometry import BearingDefinitionError, load_bearing
from .rings.stiffness import DEFAULT_MESH, MESH_HELP


def _finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} must be finite")
    return value




class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """``--help`` shows each option's default, except where there is none (None, a flag's False)."""

    def _get_help_string(self, action):
        if action.default is None or action.default is False or "%(default)" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def _add_parser(sub, name: str, **kw):
    return sub.add_parser(name, formatter_class=_HelpFormatter, **kw)


def _add_superelement_file(p) -> None:
    p.add_argument("--superelement", default=None, metavar="FILE.npz",
                   help="a superelement built by `slewing superelement` for this bearing: flexible rings with it "
                        "(its mesh and ring supports; --mesh and --bc are then not used)")


def _add_solve(sub) -> None:
    p = _add_parser(sub, "solve", help="load distribution of a bearing under a load")
    p.add_argument("bearing", help="bearing definition (TOML)")
    for name, unit in zip(LOAD_FIELDS, ("N", "N", "N", "Nm", "Nm")):
        p.add_argument(f"--{name.lower()}", type=_finite_float, default=0.0, metavar=unit,
                       help=f"{name} on the moving ring, {unit} (fixed frame)")
    p.add_argument("--model", choices=("rigid", "flexible"), default="rigid", help="ring model")
    p.add_argument("--bc", choices=("free", "clamped", "frictionless"), default="free",
                   help="ring support of the flexible model's superelement (a ring the bearing file connects, "
                        "[connection.<ring>], is held by that instead)")
    p.add_argument("--mesh", choices=("coarse", "fine", "finer"), default=DEFAULT_MESH, help=MESH_HELP)
    _add_superelement_file(p)
    p.add_argument("--preload", type=_finite_float, default=None, metavar="m",
                   help="ball preload (oversize), m, overriding the bearing file")
    p.add_argument("--psi", type=_finite_float, default=0.0, metavar="rad",
                   help="rotation of the moving ring (turns its manufacturing errors with it)")
    p.add_argument("--mu", type=_finite_float, default=None, metavar="-",
                   help="Coulomb friction coefficient of the raceway contacts (default: the friction model's)")
    p.add_argument("--seal-torque", type=_finite_float, default=0.0, metavar="Nm",
                   help="load-independent friction torque (seals, grease)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run_solve)


def _bearing_and_loads(args):
    """The bearing (with ``--preload`` applied) and the loads of the command line."""
    bearing = load_bearing(args.bearing)
    if args.preload is not None:
        bearing = bearing.with_preload(args.preload)
    return bearing, Loads(args.fx, args.fy, args.fz, args.mx, args.my)


def _superelement(args, bearing):
    """The superelement of ``--superelement`` (checked against the bearing), or None."""
    if args.superelement is None:
        return None
    from .rings.stiffness import Superelement

    return Superelement.load(args.superelement, bearing)


def _run_solve(args) -> int:
    bearing, loads = _bearing_and_loads(args)
    se = _superelement(args, bearing)
    model = "flexible" if se is not None else args.model
    result = solve(bearing, loads, model=model, superelement=se, bc=args.bc, mesh=args.mesh, psi=args.psi)
    options = {} if args.mu is None else {"mu": args.mu}
    friction = friction_torque(bearing, result, omega=1.0, seal_torque=args.seal_torque, **options)
    catalogue = catalogue_torque(bearing, loads)
    for warning in result.warnings():      # a valid answer the user must not take at face value
        print(f"slewing solve: warning: {warning}", file=sys.stderr)
    if args.json:
        data = result.to_dict()
        data["friction_torque"] = friction.magnitude              # N m, for a positive omega
        data["friction_torque_catalogue"] = catalogue              # N m, maker's start-up formula
        data["warnings"] = result.warnings()
        if not math.isfinite(data["static_safety_factor"]):      # unloaded: JSON has no infinity
            data["static_safety_factor"] = None
        print(json.dumps(data))
        return 0
    print(f"{bearing.name}: {model} rings, {bearing.ball_count} balls, {result.iterations} Newton iterations")
    d = result.displacement
    print(f"displacement  x {d[0] * 1e6:9.3f} um  y {d[1] * 1e6:9.3f} um  z {d[2] * 1e6:9.3f} um  "
          f"rx {d[3] * 1e6:9.3f} urad  ry {d[4] * 1e6:9.3f} urad")
    safety = result.static_safety_factor
    print(f"max ball load {result.max_ball_load / 1e3:.3f} kN, max contact pressure "
          f"{result.max_contact_pressure / 1e6:.0f} MPa, static safety factor "
          f"{'- (unloaded)' if math.isinf(safety) else f'{safety:.3g}'}, "
          f"{result.balls_in_four_point_contact} balls in four-point contact")
    print(f"friction torque {friction.magnitude:.4g} N m (analytical, full sliding), catalogue formula "
          f"{catalogue:.4g} N m")
    print(f"{'ball':>4} {'phi deg':>8} {'Q1 kN':>8} {'Q2 kN':>8} {'Q3 kN':>8} {'Q4 kN':>8} "
          f"{'a13 deg':>8} {'a24 deg':>8} {'d13 um':>8} {'d24 um':>8}")
    for b in range(bearing.ball_count):
        q = result.contact_load[b] / 1e3
        a = np.degrees(result.contact_angle[b])
        i = result.interference[b] * 1e6
        print(f"{b + 1:4d} {math.degrees(result.ball_angle[b]):8.2f} {q[0]:8.3f} {q[1]:8.3f} {q[2]:8.3f} {q[3]:8.3f} "
              f"{a[0]:8.3f} {a[1]:8.3f} {i[0]:8.3f} {i[1]:8.3f}")
    return 0


def _add_plot(sub) -> None:
    p = _add_parser(sub, "plot", help="per-ball interference or load, rigid and flexible rings side by side (PNG)")
    p.add_argument("bearing", help="bearing definition (TOML)")
    for name, unit in zip(LOAD_FIELDS, ("N", "N", "N", "Nm", "Nm")):
        p.add_argument(f"--{name.lower()}", type=_finite_float, default=0.0, metavar=unit, help=f"{name}, {unit}")
    p.add_argument("--preload", type=_finite_float, default=None, metavar="m", help="ball preload, m")
    p.add_argument("--quantity", choices=("interference", "load"), default="interference", help="what to plot")
    p.add_argument("--bc", choices=("free", "clamped", "frictionless"), default="free",
                   help="ring support of the flexible rings' superelement (a ring the bearing file connects, "
                        "[connection.<ring>], is held by that instead)")
    p.add_argument("--mesh", choices=("coarse", "fine", "finer"), default=DEFAULT_MESH, help=MESH_HELP)
    _add_superelement_file(p)
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.set_defaults(func=_run_plot)


def _run_plot(args) -> int:
    from .plots import plot_distribution

    bearing, loads = _bearing_and_loads(args)
    se = _superelement(args, bearing)
    label = f"flexible rings ({args.bc})" if se is None else f"flexible rings ({args.superelement})"
    results = {"rigid rings": solve(bearing, loads),
               label: solve(bearing, loads, model="flexible", superelement=se, bc=args.bc, mesh=args.mesh)}
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)   # results/ on a fresh clone
    plot_distribution(results, args.output, quantity=args.quantity,
                      title=f"{bearing.name}, preload {bearing.preload * 1e6:g} um, {loads}")
    print(f"wrote {args.output}")
    return 0


def _add_superelement(sub, wanted: bool) -> None:
    """The build-time subcommand; its module (scipy, scikit-fem) is imported only when asked for."""
    help_text = "build a ring superelement (scikit-fem; `slewing superelement -h` for its options)"
    if not wanted:
        sub.add_parser("superelement", help=help_text, add_help=False)
        return
    try:
        from .rings.superelement import command
    except ImportError as exc:  # build-time dependencies missing
        reason = f"slewing superelement needs scipy and scikit-fem: {exc}"
        p = sub.add_parser("superelement", help=help_text)
        p.set_defaults(func=lambda args: (print(reason, file=sys.stderr), 2)[1])
        return
    p = _add_parser(sub, "superelement", help=help_text)
    command.add_arguments(p)
    p.set_defaults(func=command.run)


def _add_loads(sub) -> None:
    p = _add_parser(sub, "loads", help="pitch or yaw bearing loads from an OpenFAST/FAST output file (.out, .outb) "
                                     "as a CSV load series (SI)")
    p.add_argument("file", help="OpenFAST / FAST output file: .out text or .outb binary (FileID 1-4)")
    p.add_argument("--bearing", choices=("pitch", "yaw"), required=True)
    p.add_argument("--blade", type=int, default=1, metavar="K", help="blade whose pitch bearing")
    p.add_argument("--mounting", default=None,
                   help="which way the bearing's +z axis points: pitch 'tip' (default) or 'hub', yaw 'up' (default) "
                        "or 'down' (docs/guide/openfast-loads.md)")
    p.add_argument("--frame", choices=("rotating", "fixed"), default="rotating",
                   help="frame of Fx..My: the moving ring's (blade, nacelle) or the fixed ring's (hub, tower)")
    p.add_argument("--source", default="auto",
                   help="channels to use: pitch 'b' or 'c', yaw 'p' or 'n'; auto: the first complete set")
    p.add_argument("--start", type=_finite_float, default=None, metavar="s", help="start of the time window")
    p.add_argument("--end", type=_finite_float, default=None, metavar="s", help="end of the time window")
    p.add_argument("-o", "--output", required=True, help="CSV to write: time,Fx,Fy,Fz,Mx,My,Mz,psi,omega (SI)")
    p.set_defaults(func=_run_loads)


def _run_loads(args) -> int:
    from .loads.aeroelastic import bearing_channels, bearing_loads
    from .loads.openfast import read_output

    output = read_output(args.file)
    series = bearing_loads(output, args.bearing, args.blade, args.mounting, args.start, args.end,
                           frame=args.frame, source=args.source)
    used = bearing_channels(output, args.bearing, args.blade, args.source)
    what = f"pitch bearing of blade {args.blade}" if args.bearing == "pitch" else "yaw bearing"
    mounting = args.mounting or ("tip" if args.bearing == "pitch" else "up")
    rate = used["rate"] or f"the rate of {used['angle']}"
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)   # results/ on a fresh clone
    series.write_csv(args.output, comments=(
        f"slewing loads: {what} from {args.file}",
        f"channels: {', '.join(used['loads'])} ({used['frame']} frame), psi from {used['angle']}, omega from {rate}",
        f"mounting = {mounting} (docs/guide/openfast-loads.md); SI units: N, N m, rad, rad/s; Mz opposes positive psi",
    ))
    print(f"wrote {args.output}: {what}, {series.time.size} rows, t = {series.time[0]:g} .. {series.time[-1]:g} s, "
          f"{args.frame} frame, from {', '.join(used['loads'])} and {used['angle']}")
    return 0


#: a negative number argparse would take for an option (it only knows ``-5`` and ``-.5``, not ``-1e5``)
_NEGATIVE_NUMBER = re.compile(r"^-((\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|inf|infinity|nan)$", re.IGNORECASE)


def _attach_negative_numbers(argv: list) -> list:
    """``--fz -1e5`` -> ``--fz=-1e5``, so that every numeric option takes a negative value."""
    out = []
    for i, token in enumerate(argv):
        if token == "--":
            return out + argv[i:]
        previous = out[-1] if out else ""
        if _NEGATIVE_NUMBER.match(token) and previous.startswith("--") and previous != "--" and "=" not in previous:
            out[-1] = f"{previous}={token}"
        else:
            out.append(token)
    return out


def _stdout_is_broken() -> bool:
    """True when nobody reads our standard output any more (a closed pipe)."""
    try:
        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(event & select.POLLERR for _, event in poller.poll(0))
    except (AttributeError, OSError, ValueError):
        return False


def _add_batch(sub) -> None:
    """``slewing batch STUDY.toml -o DIR [--workers N] [--scheduler ADDRESS]`` (slewing_model.study; Dask)."""
    from .study import command

    p = _add_parser(sub, "batch", help="run a study of many cases (load series x bearing variants) on Dask")
    command.add_arguments(p)
    p.set_defaults(func=command.run)


def _add_turbine(sub) -> None:
    """``slewing turbine FILE.toml -o DIR``: a closed-loop turbine case or a turbine study (slewing_turbine,
    imported when the command runs: the bearing library does not depend on it)."""
    p = _add_parser(sub, "turbine", help="the wind turbine's closed loop (ROSCO, rotor, pitch drives on their "
                                         "bearings): a turbine file's case, or a turbine study's cases on Dask")
    p.add_argument("file", help="turbine file (TOML: examples/turbines/nrel5mw.toml) or turbine study file "
                                "(with a [study] table: examples/studies/turbine_nrel5mw.toml)")
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output directory: summary.csv, summary.json, timeseries.csv, turbine.png (a study: "
                        "summary.csv, cases/<key>/, figures/; finished cases are skipped)")
    p.add_argument("--t-end", type=_finite_float, default=None, metavar="S",
                   help="a turbine file's run length instead of its simulation.t_end_s, s")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="a study: worker processes of the embedded Dask LocalCluster (not given: one per core)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="a study: submit to this Dask cluster")
    p.add_argument("--retry-failed", action="store_true", help="a study: run again the cases that failed")
    p.add_argument("--overwrite", action="store_true",
                   help="a study: clear another study's results found in the output directory")
    p.add_argument("--no-figures", action="store_true", help="write no PNG")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_run_turbine)


def _run_turbine(args) -> int:
    import importlib.util

    if sys.version_info < (3, 11) or importlib.util.find_spec("rosco") is None:
        print("slewing turbine: error: the turbine loop needs ROSCO's controller library (Python >= 3.11): "
              "pip install --no-deps rosco==2.10.6", file=sys.stderr)
        return 2
    from slewing_turbine.cli import run

    return run(args)


def _add_life(sub) -> None:
    """``slewing life LOADS.csv BEARING.toml`` (slewing_model.life.command)."""
    from .life import command

    p = _add_parser(sub, "life", help="life and wear of one load series: ISO/TS 16281 with oscillations, raceway "
                                    "damage map, DG03, x/2b (docs/guide/life-and-wear.md)")
    command.add_arguments(p)
    p.set_defaults(func=command.run)


def main(argv=None) -> int:
    argv = _attach_negative_numbers(sys.argv[1:] if argv is None else list(argv))
    parser = argparse.ArgumentParser(prog="slewing", description="Four-point contact slewing bearing model",
                                     formatter_class=_HelpFormatter)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    _add_solve(sub)
    _add_plot(sub)
    _add_superelement(sub, wanted=bool(argv) and argv[0] == "superelement")
    _add_batch(sub)
    _add_loads(sub)
    _add_life(sub)
    _add_turbine(sub)
    args = parser.parse_args(argv)
    try:
        code = int(args.func(args) or 0)
        sys.stdout.flush()
        return code
    except KeyboardInterrupt:  # Ctrl-C: one line, not a traceback; the status of a command ended by SIGINT
        print(f"\nslewing {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        if not _stdout_is_broken():
            raise
        # the reader went away (`slewing solve ... | head`): stop quietly, with the status of a command
        # ended by SIGPIPE; stdout goes to /dev/null so that the interpreter's last flush does not fail
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except (BearingDefinitionError, NoEquilibriumError, ValueError) as exc:
        print(f"slewing {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # a file that cannot be read or written: one line naming it
        reason = f"{exc.filename}: {exc.strerror}" if exc.filename else str(exc)
        print(f"slewing {args.command}: error: {reason}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
