"""Speed and memory of the ring superelement build, and its convergence studies (their results:
docs/theory/superelement.md, Accuracy).

    .venv/bin/python -m benchmarks superelement             # benchmark table (~1.5 min)
    .venv/bin/python -m benchmarks superelement --study     # + convergence and patch tables (~4 min)

Benchmark: table1.toml (100 balls), both rings, free, no cache. Each build runs in a fresh
process (so that its peak resident memory, ru_maxrss, is its own); the table gives the median
of ``--runs`` runs and the ratio to the coarse build measured in the same run. Goals on a
2-core machine: fine < 60 s, coarse < 10 s, peak memory < 4 GB.
"""
from __future__ import annotations

import json
import os
import platform
import statistics
import subprocess
import time

import numpy as np

from .suite import ROOT, note, print_table, worker_command

RUNS = 3
TABLE1 = ROOT / "examples" / "bearings" / "table1.toml"
GOALS = {"coarse": 10.0, "fine": 60.0}
MEMORY_GOAL_GB = 4.0


def child(mesh: str) -> None:
    """One build in this process; prints JSON (time, peak memory, figures)."""
    import resource

    from slewing_model.bearing.geometry import load_bearing
    from slewing_model.rings.superelement import build_superelement

    bearing = load_bearing(TABLE1)
    t0 = time.perf_counter()
    se = build_superelement(bearing, mesh, "free", cache=False)
    seconds = time.perf_counter() - t0
    peak_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss        # KiB on Linux
    rings = se.metadata["rings"]
    print(json.dumps({"seconds": seconds, "peak_gb": peak_kib / 1024**2,
                      "dofs": [rings[r]["mesh"]["dofs"] for r in ("outer", "inner")],
                      "harmonics": [rings[r]["harmonics"] for r in ("outer", "inner")],
                      "diag": rings["outer"]["diagonal_N_per_m"][:2]}))


def run_child(mesh: str) -> dict:
    out = subprocess.run(worker_command("superelement", mesh), capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def cache_hit_seconds() -> float:
    import tempfile

    from slewing_model.bearing.geometry import load_bearing
    from slewing_model.rings.superelement import build_superelement

    bearing = load_bearing(TABLE1)
    with tempfile.TemporaryDirectory() as d:
        build_superelement(bearing, "coarse", "free", cache_dir=d)
        t0 = time.perf_counter()
        build_superelement(bearing, "coarse", "free", cache_dir=d)
        return time.perf_counter() - t0


def worker_main(argv: list[str]) -> None:
    """A worker process (:func:`run_child`): one build of mesh ``argv[0]``."""
    child(argv[0])


def benchmark(repeat: int) -> None:
    results = {}
    for mesh in ("coarse", "fine"):
        runs = [run_child(mesh) for _ in range(repeat)]
        results[mesh] = {"seconds": statistics.median(r["seconds"] for r in runs),
                         "peak_gb": max(r["peak_gb"] for r in runs), "dofs": runs[0]["dofs"],
                         "harmonics": runs[0]["harmonics"]}
    base = results["coarse"]["seconds"]
    rows = []
    for mesh, r in results.items():
        ok = r["seconds"] < GOALS[mesh] and r["peak_gb"] < MEMORY_GOAL_GB
        rows.append([mesh, f"{r['dofs'][0]}, {r['dofs'][1]}", f"{r['harmonics'][0]}, {r['harmonics'][1]}",
                     f"{r['seconds']:.2f}", f"{r['seconds'] / base:.2f}", f"{r['peak_gb']:.2f}",
                     f"< {GOALS[mesh]:.0f} s, < {MEMORY_GOAL_GB:.0f} GB: {'met' if ok else 'MISSED'}"])
    rows.append(["coarse, cache hit", "", "", f"{cache_hit_seconds():.3f}", "", "", ""])
    print_table(f"Superelement build, table1.toml (B = 100), both rings, free; median of {repeat} runs "
                f"({platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
                f"Python {platform.python_version()})",
                ["mesh", "DOFs per ring (outer, inner)", "harmonics", "median time [s]", "x coarse",
                 "peak memory [GB]", "goal"], rows)
    note("Paper (ANSYS, 14 cores): coarse 10 s, fine 5 min.")


# ---- studies -------------------------------------------------------------------------------------

def compliance_first_row(stiff, rcond=1e-10) -> np.ndarray:
    """First block row of the pseudo-inverse of K (the ring's compliance; rigid modes dropped), m/N."""
    blocks = stiff.harmonic_blocks().real
    top = max(np.abs(np.linalg.eigvalsh(b)).max() for b in blocks)
    inv = []
    for b in blocks:
        w, v = np.linalg.eigh(b)
        keep = np.abs(w) > rcond * top
        inv.append((v[:, keep] / w[keep]) @ v[:, keep].T)
    return np.real(np.fft.fft(np.array(inv), axis=0)) / len(blocks)


def _entries(stiff) -> dict:
    """A few condensed stiffness entries (GN/m) and compliance entries (um/kN = 1e-9 m/N) of the
    outer ring: along the contact-1 normal n1 and the groove tangent t1 at contact 1."""
    g = compliance_first_row(stiff)
    n1 = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])
    t1 = np.array([-np.sin(np.pi / 4), np.cos(np.pi / 4), 0.0, 0.0])
    g10 = np.linalg.pinv(stiff.harmonic_blocks()[10].real)
    c = stiff.first_row / 1e9
    return {"C0[R1,R1]": c[0][0, 0], "C0[z1,z1]": c[0][1, 1], "C0[R1,z1]": c[0][0, 1], "C1[R1,R1]": c[1][0, 0],
            "(G0-G1) n1n1": n1 @ (g[0] - g[1]) @ n1 * 1e9, "G0 t1t1": t1 @ g[0] @ t1 * 1e9,
            "g10 n1n1": n1 @ g10 @ n1 * 1e9}


def _cells(entries, ref, digits=2):
    return [f"{v:.4f} ({100 * (v / ref[k] - 1):+.{digits}f} %)" for k, v in entries.items()]


def study() -> None:
    from slewing_model.bearing.geometry import load_bearing
    from slewing_model.rings.superelement.build import DEFAULT_OPTIONS, auto_harmonics, condense_ring, ring_harmonics
    from slewing_model.rings.superelement.section import MESH_PRESETS

    bearing = load_bearing(TABLE1)
    ring, B = "outer", bearing.ball_count
    factors = (4, 8, 12, 16, 24)
    ns = [auto_harmonics(bearing, ring, f) for f in factors]
    note("\nConvergence, table1.toml, outer ring, free. "
         "C0, C1: blocks 0 and 1 of the first block row of K, GN/m. Compliance entries in um/kN (1e-9 m/N): "
         "G_k = block k of the first row of the ring's compliance (pseudo-inverse of K), along the contact-1 "
         "normal n1 or the groove tangent t1 at contact 1; G0 - G1: the part of a ball's own compliance not "
         "shared with its neighbour; g10: compliance of ball harmonic 10 (inverse of its 4x4 block) along n1.")
    harm = {}
    for mesh in ("coarse", "fine", "finer"):
        t0 = time.perf_counter()
        harm[mesh] = ring_harmonics(bearing, ring, MESH_PRESETS[mesh], "free", max(ns), dict(DEFAULT_OPTIONS))
        note(f"{mesh}: {harm[mesh].info['mesh']} solved {max(ns) + 1} harmonics in {time.perf_counter() - t0:.1f} s")
    ref = _entries(condense_ring(harm["finer"], B, max(ns))[0])
    keys = list(ref)
    rows = []
    for mesh in ("coarse", "fine", "finer"):
        for f, n in zip(factors, ns):
            label = f"{mesh}, N = {n} ({f} r/w)" + (" **default**" if f == 12 else "")
            rows.append([label, *_cells(_entries(condense_ring(harm[mesh], B, n)[0]), ref)])
    print_table(f"Convergence, table1.toml, outer ring, free (percentages: against finer, N = {max(ns)})",
                ["mesh, harmonics N", *keys], rows)

    rows, base = [], None
    for scale in (1.0, 0.5, 2.0):
        opts = dict(DEFAULT_OPTIONS, patch_scale=scale)
        h = ring_harmonics(bearing, ring, MESH_PRESETS["fine"], "free", 2 * ns[2], opts)
        for subtract in (True, False):
            for n in (ns[2], 2 * ns[2]):
                e = _entries(condense_ring(h, B, n, subtract_halfspace=subtract)[0])
                base = base or e
                rows.append([f"{scale}", "removed" if subtract else "kept", f"{n}", *_cells(e, base, 1)])
    print_table("Patch size and the Hertz part, table1.toml, outer ring, free, fine mesh (percentages: against "
                f"patch 1.0, half-space part removed, N = {ns[2]}, the default)",
                ["patch (x Hertz ellipse at 2.5 GPa)", "half-space part", "N", *keys], rows)

    rows, base = [], None
    for eps in (0.05, 0.02, 0.1, 0.2):
        h = ring_harmonics(bearing, ring, MESH_PRESETS["fine"], "free", ns[2],
                           dict(DEFAULT_OPTIONS, compliance_floor=eps))
        e = _entries(condense_ring(h, B)[0])
        base = base or e
        rows.append([f"{eps}", *_cells(e, base, 1)])
    print_table("Compliance floor, table1.toml, outer ring, free, fine mesh, N default",
                ["floor (x half-space compliance of the patch)", *keys], rows)


def add_arguments(parser) -> None:
    parser.add_argument("--study", action="store_true", help="also the convergence and patch-size tables")
    parser.add_argument("--no-bench", action="store_true", help="skip the timing table")


def main(args) -> None:
    if not args.no_bench:
        benchmark(args.runs)
    if args.study:
        study()
