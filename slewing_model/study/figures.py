"""The figures a reviewer of a study looks at first (matplotlib, ``DIR/figures/``).

* ``overview.png`` -- every case's friction torque (mean, 99th percentile, max),
  largest ball load, smallest static safety factor and friction energy (bars per case
  up to 40 cases, histograms beyond); failed cases are counted in the title.
* ``friction_torque_vs_<parameter>.png`` -- for a bearing parameter the study varies
  over three values or more (``preload_um``, ``friction_coefficient``): the mean
  friction torque of each case against it, with the median and the 5-95 % band over
  the other axes of the product (error seeds, load series), per load series, bearing
  and ring model.
* ``life.png`` -- the raceway damage map of each track, all cases together (each run once:
  their slice damages add up), unrolled around the ring, and the histogram of ``x/2b`` over
  all cases' rainflow cycles (``slewing_model.life``; ``docs/life.md``).
* ``worst_case.png`` -- the time series of the case with the largest friction torque:
  ring angle and drive moment, friction torque, largest ball load.
"""
from __future__ import annotations

import os
from collections import defaultdict

import numpy as np

from .case import TIMESERIES_COLUMNS
from .definition import case_name_parts

SWEPT = {"preload_um": ("ball preload [um]", 1.0), "friction_coefficient": ("friction coefficient mu [-]", 1.0)}


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _value(row, key):
    return float(row[key])


def study_figures(out_dir: str, cases, rows: list[dict]) -> list[str]:
    """Write the figures of a study's results; return their paths."""
    folder = os.path.join(out_dir, "figures")
    os.makedirs(folder, exist_ok=True)
    ok = [r for r in rows if r["status"] == "ok"]
    written = [overview(os.path.join(folder, "overview.png"), rows)]
    for key, (label, _) in SWEPT.items():
        values = {r[key] for r in ok if r[key] != ""}
        if len(values) >= 3:
            written.append(band_against(os.path.join(folder, f"friction_torque_vs_{key}.png"), ok, key, label))
    maps = [os.path.join(out_dir, "cases", r["case"]) for r in ok]
    maps = [m for m in maps if os.path.exists(os.path.join(m, "raceway_damage.csv"))]
    if maps:
        written.append(life_figure(os.path.join(folder, "life.png"), maps))
    if ok:
        worst = max(ok, key=lambda r: _value(r, "friction_torque_max"))
        path = os.path.join(out_dir, "cases", worst["case"], "timeseries.csv")
        if os.path.exists(path):
            written.append(time_series(os.path.join(folder, "worst_case.png"), path, worst["name"]))
    return written


def _labels(rows: list[dict]) -> list[str]:
    """Case labels without what all cases share (the bearing variant, or the load series)."""
    loads, variants = zip(*(case_name_parts(r["name"]) for r in rows))
    if len(set(variants)) == 1:
        return list(loads)
    if len(set(loads)) == 1:
        return list(variants)
    return [r["name"] for r in rows]


def overview(path: str, rows: list[dict]) -> str:
    plt = _pyplot()
    ok = [r for r in rows if r["status"] == "ok"]
    failed = len(rows) - len(ok)
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5 if len(ok) <= 40 else 6.5))
    title = f"{len(rows)} cases, {len(ok)} ok, {failed} failed (see summary.csv)"
    variants = {case_name_parts(r["name"])[1] for r in ok}
    if len(ok) <= 40 and len(variants) == 1:
        title += f"; bearing: {variants.pop()}"
    fig.suptitle(title)
    if not ok:
        for ax in axes.flat:
            ax.axis("off")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path
    panels = [
        (("friction_torque_mean", "friction_torque_p99", "friction_torque_max"), 1e-3, "friction torque [kN m]"),
        (("max_ball_load",), 1e-3, "largest ball load [kN]"),
        (("min_static_safety_factor",), 1.0, "smallest static safety factor [-]"),
        (("friction_energy",), 1e-3, "friction energy over the motion [kJ]"),
    ]
    if len(ok) <= 40:
        labels = _labels(ok)
        y = np.arange(len(ok))
        for ax, (keys, scale, label) in zip(axes.flat, panels):
            height = 0.8 / len(keys)
            for j, key in enumerate(keys):
                ax.barh(y + (j - (len(keys) - 1) / 2) * height, [_value(r, key) * scale for r in ok], height,
                        label=key.replace("friction_torque_", "") if len(keys) > 1 else None)
            ax.set_yticks(y, labels if ax in axes[:, 0] else [""] * len(y), fontsize=7)
            ax.invert_yaxis()
            ax.set_xlabel(label)
            ax.grid(axis="x", alpha=0.3)
            if len(keys) > 1:
                ax.legend(fontsize=8)
    else:
        for ax, (keys, scale, label) in zip(axes.flat, panels):
            for key in keys:
                ax.hist([_value(r, key) * scale for r in ok], bins=30, alpha=0.6,
                        label=key.replace("friction_torque_", "") if len(keys) > 1 else None)
            ax.set_xlabel(label)
            ax.set_ylabel("cases")
            if len(keys) > 1:
                ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def band_against(path: str, ok: list[dict], key: str, label: str) -> str:
    """Mean friction torque against a swept parameter: median and 5-95 % band per group (left),
    and the band relative to the median (right: narrow bands are invisible on the left)."""
    plt = _pyplot()
    groups = defaultdict(list)
    for r in ok:
        groups[(r["load"], r["bearing"], r["ring_model"])].append(r)
    fig, (ax, rel) = plt.subplots(1, 2, figsize=(12, 4.8))
    for (load, bearing, model), members in sorted(groups.items()):
        by_x = defaultdict(list)
        for r in members:
            by_x[float(r[key])].append(_value(r, "friction_torque_mean"))
        xs = np.array(sorted(by_x))
        samples = [np.array(by_x[x]) for x in xs]
        median = np.array([np.median(s) for s in samples])
        lo = np.array([np.percentile(s, 5) for s in samples])
        hi = np.array([np.percentile(s, 95) for s in samples])
        n = min(len(s) for s in samples)
        line, = ax.plot(xs, median, "o-", label=f"{bearing}, {model}, {load}: median ({n} cases per point)")
        color = line.get_color()
        ax.fill_between(xs, lo, hi, color=color, alpha=0.25, label="5-95 % band")
        for x, s in zip(xs, samples):
            ax.plot(np.full(s.shape, x), s, ".", color=color, alpha=0.15, ms=3)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel.fill_between(xs, 100 * (lo / median - 1), 100 * (hi / median - 1), color=color, alpha=0.3,
                             label=f"{bearing}, {model}: 5-95 % band")
            for x, s, m in zip(xs, samples, median):
                rel.plot(np.full(s.shape, x), 100 * (s / m - 1), ".", color=color, alpha=0.15, ms=3)
    ax.set_xlabel(label)
    ax.set_ylabel("mean friction torque [N m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    rel.set_xlabel(label)
    rel.set_ylabel("mean friction torque / median - 1 [%]")
    rel.grid(alpha=0.3)
    rel.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def time_series(path: str, csv_path: str, name: str) -> str:
    plt = _pyplot()
    data = np.loadtxt(csv_path, delimiter=",", skiprows=1, ndmin=2)
    c = {k: data[:, j] for j, k in enumerate(TIMESERIES_COLUMNS)}
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    axes[0].plot(c["time"], np.degrees(c["psi"]), color="C0")
    axes[0].set_ylabel("ring angle psi [deg]", color="C0")
    twin = axes[0].twinx()
    twin.plot(c["time"], c["Mz"] * 1e-3, color="C1", lw=0.8)
    twin.set_ylabel("drive moment Mz [kN m]", color="C1")
    axes[1].plot(c["time"], c["friction_torque_magnitude"] * 1e-3, lw=0.8)
    axes[1].set_ylabel("friction torque [kN m]")
    axes[2].plot(c["time"], c["max_ball_load"] * 1e-3, lw=0.8)
    axes[2].set_ylabel("largest ball load [kN]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"largest friction torque: {name}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def life_figure(path: str, case_dirs: list[str], title: str | None = None) -> str:
    """Raceway damage around each track (summed over the cases) and the histogram of x/2b."""
    plt = _pyplot()
    damage, ratios, counts = None, [], []
    for folder in case_dirs:
        d = np.loadtxt(os.path.join(folder, "raceway_damage.csv"), delimiter=",", skiprows=1, ndmin=2)
        damage = d if damage is None else np.column_stack([d[:, 0], damage[:, 1:] + d[:, 1:]])
        cycles = os.path.join(folder, "life_cycles.csv")
        with open(cycles) as fh:
            empty = len(fh.read().splitlines()) < 2          # a ring that never moved: no cycles
        c = np.zeros((0, 3)) if empty else np.loadtxt(cycles, delimiter=",", skiprows=1, ndmin=2)
        if c.size:
            ratios.append(c[:, 2])
            counts.append(c[:, 1])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    labels = ("1 (outer ring)", "2 (inner ring)", "3 (inner ring)", "4 (outer ring)")
    for k in range(4):
        ax1.plot(damage[:, 0], damage[:, k + 1], lw=1.0, label=f"contact {labels[k]}")
    ax1.set_xlabel("slice centre, angle around its own ring [deg]")
    ax1.set_ylabel("slice damage d_j [-]")
    ax1.set_xlim(0, 360)
    ax1.set_title(f"raceway damage map, {len(case_dirs)} case(s) each run once")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    if ratios:
        r, w = np.concatenate(ratios), np.concatenate(counts)
        keep = np.isfinite(r) & (r > 0)
        r, w = r[keep], w[keep]
        edges = np.logspace(np.floor(np.log10(r.min())), np.ceil(np.log10(r.max())), 41)
        ax2.hist(r, bins=edges, weights=w, color="tab:blue", alpha=0.8)
        ax2.axvline(1.0, color="k", ls="--", lw=1)
        below = w[r < 1].sum() / w.sum() if w.sum() else float("nan")
        ax2.set_xscale("log")
        ax2.set_title(f"x/2b of the rainflow cycles: {below:.0%} below 1 (patch never uncovered)")
    ax2.set_xlabel("rolling travel over contact width, x/2b [-]")
    ax2.set_ylabel("cycles")
    ax2.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
