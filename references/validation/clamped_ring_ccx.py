"""A clamped ring of table1 against a 3-D CalculiX solid: the groove-centre compliance, n = 0 and 1.

references/calculix/clamped_face/harmonic_vs_ccx.py sweeps the ring's cross-section mesh into
quadratic wedges (C3D15), fixes every node of the bolted face, applies the superelement's four
master loads (unit groove-centre forces R_a, z_a, R_b, z_b spread as the patch pressure) times
cos(n theta) and solves with CalculiX. n = 0 is the axisymmetric pattern of an axial load, n = 1
the pattern of a tilting moment. This script runs four cases of it and stores CalculiX's
compliances (slow, needs ccx), and draws them against the harmonic model computed live (fast):

* outer ring (lower face), n = 0, thin sector of 0.5 deg (one slab);
* inner ring (upper face), n = 0, thin sector of 0.5 deg;
* outer ring, half ring in 24 slabs, n = 0 and n = 1.

    OMP_NUM_THREADS=1 nice -n 10 .venv/bin/python references/validation/clamped_ring_ccx.py --rerun   # CalculiX, 4-6 min
    .venv/bin/python references/validation/clamped_ring_ccx.py -o docs/figures/val_calculix_axial.png  # redraw, 10 s

Stored: references/validation/data/clamped_ring_ccx.csv (case, ring, n, row, column, CalculiX's
compliance in m/N per unit of the theta integral; master DOFs R_a, z_a, R_b, z_b).
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from slewing_model import load_bearing  # noqa: E402
from references.validation.figure import pyplot, save  # noqa: E402

DATA = Path(__file__).resolve().parent / "data" / "clamped_ring_ccx.csv"
CASES = {  # name: (ring, sector in deg or None, slabs)
    "outer, sector 0.5 deg": ("outer", 0.5, 1),
    "inner, sector 0.5 deg": ("inner", 0.5, 1),
    "outer, half ring, 24 slabs": ("outer", None, 24),
}
DOFS = ("R_a", "z_a", "R_b", "z_b")


def harmonic_vs_ccx():
    spec = importlib.util.spec_from_file_location(
        "harmonic_vs_ccx", ROOT / "references" / "calculix" / "clamped_face" / "harmonic_vs_ccx.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def harmonic_side(bearing, ring, harmonics, mesh="coarse"):
    """The harmonic model's compliances L^T K(n)^-1 L of the clamped ring (as in harmonic_vs_ccx.compare)."""
    h = harmonic_vs_ccx()
    sizes = [h.cp.patch_size(bearing, c) for c in h.RING_CONTACTS[ring]]
    sm = h.mesh_section(h.ring_profile(bearing, ring), [a for a, _ in sizes], mesh)
    model = h.HarmonicRingModel(sm.mesh, bearing.youngs_modulus, bearing.poisson_ratio)
    patches = h.cp.ring_patches(bearing, ring, sizes)
    loads, _ = h.cp.master_loads(model, sm.patch_facets, patches)
    support = h.Support("clamped", model, sm.bolted_facets)
    return dict(zip(harmonics, h.cd.harmonic_compliances(model, loads, harmonics, support))), patches


def rerun(bearing, path=DATA):
    h = harmonic_vs_ccx()
    rows = []
    for name, (ring, sector, slabs) in CASES.items():
        t0 = time.perf_counter()
        result, _ = h.compare(bearing, ring, "coarse", sector=sector, slabs=slabs)
        print(f"{name}: {time.perf_counter() - t0:.0f} s", flush=True)
        for n, (_, c3) in result.items():
            for i in range(4):
                for j in range(4):
                    rows.append([name, ring, n, DOFS[i], DOFS[j], f"{c3[i, j]:.9e}"])
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "ring", "n", "row", "column", "calculix_m_per_n"])
        w.writerows(rows)
    print(f"wrote {path}")


def stored(path=DATA):
    out = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            key = (r["case"], int(r["n"]))
            out.setdefault(key, (r["ring"], np.zeros((4, 4))))[1][DOFS.index(r["row"]), DOFS.index(r["column"])] = \
                float(r["calculix_m_per_n"])
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rerun", action="store_true", help="run CalculiX and store its compliances")
    p.add_argument("-o", "--output", default="results/validation/val_calculix_axial.png")
    p.add_argument("--data", default=str(DATA), help="CalculiX's stored compliances (--rerun writes them here)")
    args = p.parse_args(argv)
    bearing = load_bearing(ROOT / "examples/bearings/table1.toml")
    if args.rerun:
        rerun(bearing, args.data)
    ref = stored(args.data)
    model = {ring: harmonic_side(bearing, ring, (0, 1)) for ring in ("outer", "inner")}
    print("| case | n | largest entry [um/MN] | largest entry difference / largest entry | "
          "along each contact normal, CalculiX / harmonic - 1 |")
    print("|---|---|---|---|---|")
    results = []
    for (name, n), (ring, c3) in ref.items():
        ch_all, patches = model[ring]
        ch = ch_all[n]
        rel = np.abs(c3 - ch).max() / np.abs(ch).max()
        normals = []
        for k, pt in enumerate(patches):
            nn = np.zeros(4)
            nn[2 * k:2 * k + 2] = np.cos(pt.psi), np.sin(pt.psi)
            normals.append((pt.contact, (nn @ c3 @ nn) / (nn @ ch @ nn) - 1))
        results.append((name, n, ch, c3, rel))
        print(f"| {name} | {n} | {np.abs(ch).max() * 1e12:.3f} | {rel:.1e} | "
              + ", ".join(f"contact {c}: {d:+.1e}" for c, d in normals) + " |")

    plt = pyplot()
    out = Path(args.output)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    iu = np.triu_indices(4)
    lim = 0.0
    for k, (name, n, ch, c3, rel) in enumerate(results):
        x, y = ch[iu] * 1e12, c3[iu] * 1e12
        lim = max(lim, np.abs(x).max(), np.abs(y).max())
        axes[0].plot(x, y, "os^v"[k % 4], ms=6, mfc="none", label=f"{name}, n = {n}")
    axes[0].plot([-lim, lim], [-lim, lim], "k-", lw=0.6)
    axes[0].set_xlabel("harmonic model (the superelement's) [um/MN]")
    axes[0].set_ylabel("3-D CalculiX solid [um/MN]")
    axes[0].set_title(f"{bearing.name}, clamped ring: the 10 groove-centre compliances", fontsize=10)
    axes[0].legend(fontsize=7)
    axes[0].grid(alpha=0.3)
    labels = [name.replace(", ", "\n") + f"\nn = {n}" for name, n, *_ in results]
    axes[1].bar(np.arange(len(results)), [r[4] for r in results], color=["C0" if r[1] == 0 else "C1" for r in results])
    axes[1].set_yscale("log")
    axes[1].set_xticks(np.arange(len(results)), labels, fontsize=7)
    axes[1].set_ylabel("largest entry difference / largest entry")
    axes[1].set_title("difference (n = 0: axial pattern, n = 1: tilting pattern)", fontsize=10)
    axes[1].grid(axis="y", alpha=0.3)
    return save(fig, out)


if __name__ == "__main__":
    sys.exit(main())
