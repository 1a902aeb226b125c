"""``slewing superelement BEARING.toml [--mesh coarse|fine|finer] [--bc free|clamped|frictionless] -o FILE``.

Builds the condensed ring stiffness of both rings (with a
progress bar over the harmonic solves), writes it to one ``.npz`` and prints a
summary: matrix size, time, and the convergence figures of the build.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from ..stiffness import DEFAULT_MESH, MESH_HELP
from .section import MESH_PRESETS
from .supports import BOUNDARY_CONDITIONS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of the ``superelement`` sub-command."""
    parser.add_argument("bearing", help="bearing definition (TOML, see examples/bearings)")
    parser.add_argument("-o", "--output", required=True, help="output file (.npz)")
    parser.add_argument("--mesh", choices=list(MESH_PRESETS), default=DEFAULT_MESH, help=MESH_HELP)
    parser.add_argument("--bc", choices=BOUNDARY_CONDITIONS, default="free",
                        help="boundary condition of both rings (free: the paper's idling model); a ring the "
                             "bearing file connects ([connection.<ring>]) is held by its connected structure instead")
    parser.add_argument("--bc-outer", choices=BOUNDARY_CONDITIONS, help="boundary condition of the outer ring only")
    parser.add_argument("--bc-inner", choices=BOUNDARY_CONDITIONS, help="boundary condition of the inner ring only")
    parser.add_argument("--harmonics", type=int, help="highest Fourier harmonic (not given: from the section)")
    parser.add_argument("--no-cache", action="store_true", help="neither read nor write the cache")
    parser.add_argument("--cache-dir", help="cache folder (not given: $SLEWING_CACHE_DIR, else ~/.cache/slewing_model)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    """Run the command; returns the exit status (0 ok, 2 bad input)."""
    from ...bearing.geometry import BearingDefinitionError, load_bearing
    from .build import build_superelement

    try:
        bearing = load_bearing(args.bearing)
    except (BearingDefinitionError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    bc = {"outer": args.bc_outer or args.bc, "inner": args.bc_inner or args.bc}
    expert = {} if args.harmonics is None else {"harmonics": args.harmonics}
    if args.harmonics is not None and args.harmonics < 2:
        print(f"error: --harmonics = {args.harmonics}: must be at least 2", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    se = build_superelement(bearing, mesh=args.mesh, bc=bc, cache=not args.no_cache,
                            cache_dir=args.cache_dir, progress=not args.quiet, **expert)
    elapsed = time.perf_counter() - t0
    out = args.output
    directory = os.path.dirname(os.path.abspath(out))
    os.makedirs(directory, exist_ok=True)
    se.save(out)
    print(summary(se, elapsed, out))
    return 0


def summary(se, elapsed: float, path: str | None = None) -> str:
    """Human-readable summary of a built superelement."""
    m = se.metadata
    B = se.outer.ball_count
    lines = [f"superelement of {m.get('bearing_name', '?')}: B = {B} balls, two {4 * B} x {4 * B} matrices "
             f"stored as first block rows ({B} x 4 x 4 each)"]
    if path:
        lines.append(f"  file: {path} ({os.path.getsize(path) / 1024:.0f} KiB)")
    hit = m.get("cache", {}).get("hit")
    lines.append(f"  time: {elapsed:.2f} s" + (" (cache hit)" if hit else
                                                f" (build {m.get('build_seconds', elapsed):.2f} s)"))
    lines.append(f"  mesh: {m['mesh']['name']}, harmonics per ring: "
                 + ", ".join(f"{r} {m['rings'][r]['harmonics']}" for r in ("outer", "inner")))
    lines.append(f"  {'ring':6} {'bc':13} {'null space':18} {'elements':>8} {'DOFs':>7} {'trunc.':>8} "
                 f"{'clipped':>8} {'K diag R, z [GN/m]':>20}")
    for r in ("outer", "inner"):
        rm = m["rings"][r]
        ph = rm["projection"]["per_harmonic"]
        diag = np.array(rm["diagonal_N_per_m"]) / 1e9
        null = ",".join(rm["removed_modes"]) or "none (PD)"
        lines.append(f"  {r:6} {rm['boundary_condition']:13} {null:18} {rm['mesh']['elements']:>8} "
                     f"{rm['mesh']['dofs']:>7} {100 * rm['truncation_change']:>7.2f}% "
                     f"{ph['clipped']:>4}/{ph['directions']:<4} {diag[0]:>9.3f} {diag[1]:>9.3f}")
    for r in ("outer", "inner"):
        conn = m["rings"][r].get("connection")
        if conn:
            lines.append(f"  {r} ring: {conn['support']}")
    lines.append("  trunc.: largest change of a diagonal entry when only 3/4 of the harmonics are kept; "
                 "clipped: harmonic directions with no compliance beyond Hertz's (floor applies)")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m slewing_model.rings.superelement",
                                     description="Build the ring superelement of a bearing (paper eqs 12-15).")
    add_arguments(parser)
    return run(parser.parse_args(argv))
