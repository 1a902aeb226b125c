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
    """A number of a summary row; an empty cell (no value) is NaN."""
    return float(row[key]) if row[key] != "" else float("nan")


def study_figures(out_dir: str, cases, rows: list[dict]) -> list[str]:
    """Write the figures of a study's results; return their paths."""
    folder = os.path.join(out_dir, "figures")
    os.makedirs(folder, exist_ok=True)
    ok = [r for r in rows if r["status"] == "ok"]
    written = [overview(os.path.join(folder, "overview.png"), rows)]
    for key, (label, _) in SWEPT.items():
        values = {r[key] for r in ok if r[key] != ""}
        if len(values) >= 3:
            written.append(band_against(os.path.join(folder, f"friction_torque_vs_{key}.png"), ok, key, label,
                                        note=errors_note(cases)))
    maps = [os.path.join(out_dir, "cases", r["case"]) for r in ok]
    maps = [m for m in maps if os.path.exists(os.path.join(m, "raceway_damage.csv"))]
    if maps:
        written.append(life_figure(os.path.join(folder, "life.png"), maps))
    if ok:
        worst = max(ok, key=lambda r: _value(r, "friction_torque_max"))
        path = os.path.join(out_dir, "cases", worst["case"], "timeseries.csv")
        if os.path.exists(path):
            case = next((c for c in cases if c.key == worst["case"]), None)
            written.append(time_series(os.path.join(folder, "worst_case.png"), path, worst["name"],
                                       psi_note=psi_note(case.load if case is not None else {})))
    return written


def _amplitudes(values) -> str:
    values = values if isinstance(values, list) else [values]
    return "/".join(f"{v:g}" for v in values)


def errors_note(cases) -> str:
    """What manufacturing errors the cases carry, in one line for a figure's title: the seeded
    synthetic amplitudes (um) and the number of seeds, or the bearing files' own errors."""
    seeds = sorted({c.variant.get("error_seed") for c in cases if c.variant.get("error_seed") is not None})
    synthetic = next((c.variant.get("synthetic_errors") for c in cases if c.variant.get("synthetic_errors")), None)
    if not seeds:
        return "manufacturing errors: those of the bearing files"
    if not synthetic:
        return f"synthetic manufacturing errors of the bearing file's amplitudes, {len(seeds)} seeds"
    orders = synthetic.get("waviness_orders", [2, 3, 4, 5])
    parts = [f"waviness orders {_amplitudes(orders)}"]
    for key, what in (("radial_amplitude_um", "radial"), ("axial_amplitude_um", "axial")):
        if key in synthetic:
            parts.append(f"{what} {_amplitudes(synthetic[key])} um")
    if "ball_tolerance_um" in synthetic:
        parts.append(f"balls +-{synthetic['ball_tolerance_um']:g} um")
    return f"synthetic errors ({', '.join(parts)}), {len(seeds)} seeds"


def psi_note(load: dict) -> str:
    """Why the ring angle has the sign it has, for an OpenFAST load series (docs/openfast.md):
    psi is the blade pitch or nacelle yaw seen along the bearing's +z."""
    if load.get("kind") != "openfast":
        return ""
    if load.get("bearing") == "pitch":
        mounting = load.get("mounting", "tip")
        return ("psi = -BldPitch: +z points to the blade tip (mounting 'tip')" if mounting == "tip"
                else "psi = +BldPitch: +z points to the hub (mounting 'hub')")
    mounting = load.get("mounting", "up")
    return ("psi = +NacYaw: +z points up (mounting 'up')" if mounting == "up"
            else "psi = -NacYaw: +z points down (mounting 'down')")


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
                values = [_value(r, key) * scale for r in ok]
                ax.barh(y + (j - (len(keys) - 1) / 2) * height, values, height,
                        label=key.replace("friction_torque_", "") if len(keys) > 1 else None)
                if key == "friction_energy":      # a bar too short to see: say why it is empty
                    largest = max(values, default=0.0)
                    for k, v in enumerate(values):
                        if v <= 1e-3 * largest:
                            ax.text(0, y[k], f"  {v:.2g}: the ring hardly turned", va="center", fontsize=7)
            ax.set_yticks(y, labels if ax in axes[:, 0] else [""] * len(y), fontsize=7)
            ax.invert_yaxis()
            ax.set_xlabel(label)
            ax.grid(axis="x", alpha=0.3)
            if len(keys) > 1:
                ax.legend(fontsize=8)
    else:   # many cases: per group of cases (seeds, blades pooled) the median, quartiles and 5-95 % range
        groups = _groups(ok)
        fig.suptitle(title + f"\nper group of cases: median (line), quartiles (box), 5-95 % (whiskers); "
                     f"{len(ok) // max(len(groups), 1)} cases a group", fontsize=10)
        panels[0] = (("friction_torque_mean",), 1e-3, "friction torque, mean over the case [kN m]")
        names = list(groups)
        for ax, (keys, scale, label) in zip(axes.flat, panels):
            data = []
            for g in names:
                v = np.array([_value(r, keys[0]) * scale for r in groups[g]])
                data.append(v[np.isfinite(v)])
            ax.boxplot(data, orientation="horizontal", whis=(5, 95), showfliers=False, widths=0.6)
            ax.set_yticks(np.arange(1, len(names) + 1), names if ax in axes[:, 0] else [""] * len(names), fontsize=7)
            ax.invert_yaxis()
            everything = np.concatenate(data) if data else np.array([])
            log = everything.size > 0 and everything.min() > 0 and everything.max() / everything.min() > 100
            if log:
                ax.set_xscale("log")
            ax.set_xlabel(label + (" (log scale)" if log else ""))
            ax.grid(axis="x", alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _groups(ok: list[dict]) -> dict:
    """The cases by what sets them apart other than error seeds and blades: ring model, preload,
    friction coefficient, bearing file and load series; labelled by the parts that vary."""
    fields = ("ring_model", "preload_um", "friction_coefficient", "bearing", "load")
    varying = [f for f in fields if len({r[f] for r in ok}) > 1]
    groups = defaultdict(list)
    for r in ok:
        label = ", ".join(f"{float(r[f]):g} um" if f == "preload_um" else
                          (f"mu {r[f]}" if f == "friction_coefficient" else r[f]) for f in varying) or "all cases"
        groups[label].append(r)
    return dict(groups)


def band_against(path: str, ok: list[dict], key: str, label: str, note: str = "") -> str:
    """Mean friction torque against a swept parameter, per group (load series, bearing, ring model):
    every case, the median and the 5-95 % range of the cases (left, on a log axis when the torque
    spans decades); and the width of that range relative to the median (right: a band of a few
    per cent of 1000 N m cannot be seen on the left)."""
    plt = _pyplot()
    groups = defaultdict(list)
    for r in ok:
        groups[(r["load"], r["bearing"], r["ring_model"])].append(r)
    fig, (ax, rel) = plt.subplots(1, 2, figsize=(12, 4.8))
    for g, ((load, bearing, model), members) in enumerate(sorted(groups.items())):
        by_x = defaultdict(list)
        for r in members:
            by_x[float(r[key])].append(_value(r, "friction_torque_mean"))
        xs = np.array(sorted(by_x))
        samples = [np.array(by_x[x]) for x in xs]
        median = np.array([np.median(s) for s in samples])
        lo = np.array([np.percentile(s, 5) for s in samples])
        hi = np.array([np.percentile(s, 95) for s in samples])
        n = min(len(s) for s in samples)
        line, = ax.plot(xs, median, "o-", label=f"{bearing}, {model}, {load}: median of {n} cases per point")
        color = line.get_color()
        first = g == 0
        ax.errorbar(xs, median, yerr=[median - lo, hi - median], fmt="none", ecolor=color, capsize=7, lw=1.5,
                    label="5-95 % of the cases (bars)" if first else None)
        for i, (x, s) in enumerate(zip(xs, samples)):
            ax.plot(np.full(s.shape, x) + 0.25, s, "_", color=color, alpha=0.5, ms=8,
                    label="each case (its mean over the run), beside the bar" if first and i == 0 else None)
        with np.errstate(divide="ignore", invalid="ignore"):
            width = 100 * (hi - lo) / median
        rel.plot(xs, width, "o-", color=color, label=f"{bearing}, {model}")
        for x, w in zip(xs, width):
            if np.isfinite(w):
                rel.annotate(f"{w:.3g} %", (x, w), textcoords="offset points", xytext=(4, 4), fontsize=7,
                             color=color)
    values = np.array([_value(r, "friction_torque_mean") for r in ok])
    if values.size and values.min() > 0 and values.max() / values.min() > 20:
        ax.set_yscale("log")      # the torque spans decades: each point's spread stays visible
    ax.set_xlabel(label)
    ax.set_ylabel("mean friction torque [N m]" + (" (log scale)" if ax.get_yscale() == "log" else ""))
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title("mean friction torque of each case", fontsize=9)
    rel.set_yscale("log")
    rel.set_xlabel(label)
    rel.set_ylabel("5-95 % range / median [%] (log scale)")
    rel.set_title("spread of the cases: width of the 5-95 % range relative to the median", fontsize=9)
    rel.grid(alpha=0.3, which="both")
    rel.legend(fontsize=7)
    if note:
        fig.suptitle(note, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def time_series(path: str, csv_path: str, name: str, psi_note: str = "") -> str:
    """The ring angle (and the drive moment Mz, where there is one), the friction torque and the
    largest ball load over a case's run."""
    plt = _pyplot()
    data = np.loadtxt(csv_path, delimiter=",", skiprows=1, ndmin=2)
    c = {k: data[:, j] for j, k in enumerate(TIMESERIES_COLUMNS)}
    fig, axes = plt.subplots(3, 1, figsize=(10, 7), sharex=True)
    axes[0].plot(c["time"], np.degrees(c["psi"]), color="C0")
    axes[0].set_ylabel("ring angle psi [deg]", color="C0")
    if np.any(c["Mz"] != 0.0):       # no second axis for a series without a drive moment (idling)
        twin = axes[0].twinx()
        twin.plot(c["time"], c["Mz"] * 1e-3, color="C1", lw=0.8)
        twin.set_ylabel("drive moment Mz [kN m]", color="C1")
    else:
        axes[0].set_title("no drive moment Mz in this series", fontsize=8, loc="right")
    if psi_note:
        axes[0].set_title(psi_note, fontsize=8, loc="left")
    torque = c["friction_torque_magnitude"] * 1e-3
    axes[1].plot(c["time"], torque, lw=0.8)
    axes[1].set_ylabel("friction torque [kN m]")
    top = float(np.max(torque)) if torque.size else 0.0
    if top > 0:     # from zero, so that the ripple shows at its true size; its size in words
        axes[1].set_ylim(0, 1.15 * top)
        mean = float(np.mean(torque))
        axes[1].set_title(f"{float(np.min(torque)):.4g} to {top:.4g} kN m, mean {mean:.4g}: "
                          f"range {100 * (top - float(np.min(torque))) / mean:.2g} % of the mean", fontsize=8, loc="left")
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
