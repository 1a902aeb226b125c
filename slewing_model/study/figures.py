"""The figures a reviewer of a study looks at first (matplotlib, ``DIR/figures/``).

* ``overview.png`` -- every case's friction torque (mean, 99th percentile, max),
  largest ball load, smallest static safety factor and friction energy (bars per case
  up to 40 cases, histograms beyond); failed cases are counted in the title.
* ``friction_torque_vs_<parameter>.png`` -- for a bearing parameter the study varies
  over three values or more (``preload_um``, ``friction_coefficient``): the mean
  friction torque of each case against it, with the median and the 5-95 % band over
  the other axes of the product (error seeds, load series), per load series, bearing
  and ring model.
* ``life.png`` -- the raceway damage map of each track as steps, unrolled around its ring, with
  each track's damage and L10 and the ratio of DG03's life to ours; the cases of one bearing
  variant are parts of one duty (their load series, each run once: slice damages add up), while
  different variants are alternative designs, drawn side by side (or, beyond six, their median and
  range), never added; and ``x/2b`` of the rainflow cycles as shares of the cycles and of the
  damage (``slewing_model.life``; ``docs/guide/life-and-wear.md``).
* ``worst_case.png`` -- the time series of the case with the largest friction torque:
  ring angle and drive moment, friction torque, largest ball load.
"""
from __future__ import annotations

import os
import textwrap
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
    groups = life_groups(out_dir, ok)
    if groups:
        written.append(life_figure(os.path.join(folder, "life.png"), dict(groups) if len(groups) > 1
                                   else next(iter(groups.values()))))
    if ok:
        worst = max(ok, key=lambda r: _value(r, "friction_torque_max"))
        path = os.path.join(out_dir, "cases", worst["case"], "timeseries.csv")
        if os.path.exists(path):
            case = next((c for c in cases if c.key == worst["case"]), None)
            written.append(time_series(os.path.join(folder, "worst_case.png"), path, worst["name"],
                                       psi_note=psi_note(case.load if case is not None else {})))
    return written


def life_groups(out_dir: str, rows: list[dict]) -> dict:
    """The finished cases' folders by bearing variant: ``{variant name: [case folders]}``. A variant's
    cases are parts of one duty (its load series), whose damages add up; different variants (files,
    ring models, preloads, friction, error seeds: a Monte Carlo study's draws) are alternative designs
    and are never added together."""
    groups = defaultdict(list)
    for r in rows:
        folder = os.path.join(out_dir, "cases", r["case"])
        if r["status"] == "ok" and os.path.exists(os.path.join(folder, "raceway_damage.csv")):
            groups[case_name_parts(r["name"])[1]].append(folder)
    return dict(groups)


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
    """Why the ring angle has the sign it has, for an OpenFAST load series (docs/guide/openfast-loads.md):
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
    # constrained layout: the case labels (up to a whole case name) and the titles stay inside the
    # figure; tight_layout gave up on long labels and cut them at the left edge
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5 if len(ok) <= 40 else 6.5), layout="constrained")
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
            if len(keys) > 1:   # above the panel, not over its longest bars
                ax.legend(fontsize=8, ncols=len(keys), loc="lower left", bbox_to_anchor=(0.0, 1.0), frameon=False)
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
                from matplotlib.ticker import NullFormatter

                ax.set_xscale("log")
                ax.xaxis.set_minor_formatter(NullFormatter())   # decades only: minor labels ran together
            ax.set_xlabel(label + (" (log scale)" if log else ""))
            ax.grid(axis="x", alpha=0.3, which="both")
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


TRACK_LABELS = ("1 (outer ring)", "2 (inner ring)", "3 (inner ring)", "4 (outer ring)")
#: above this many groups of alternative designs, the map shows their median and range, not a line each
MAX_GROUP_LINES = 6


def _read_life(folder: str) -> dict:
    """A case's (or a `slewing life` run's) map, cycles and life summary."""
    import json

    d = np.loadtxt(os.path.join(folder, "raceway_damage.csv"), delimiter=",", skiprows=1, ndmin=2)
    path = os.path.join(folder, "life_cycles.csv")
    with open(path) as fh:
        header = fh.readline().strip().split(",")
        empty = not fh.readline().strip()                 # a ring that never moved: no cycles
    c = np.zeros((0, len(header))) if empty else np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    summary = {}
    if os.path.exists(os.path.join(folder, "life_summary.json")):
        with open(os.path.join(folder, "life_summary.json")) as fh:
            summary = json.load(fh)
    return {"angle": d[:, 0], "map": d[:, 1:].T, "cycles": {h: c[:, j] for j, h in enumerate(header)},
            "summary": summary}


def _number(x) -> float:
    """A number of a life summary (JSON: "inf" for infinity, null for none)."""
    return float("nan") if x is None else float(x)


def _duty(runs: list[dict]) -> dict:
    """One duty made of the runs (parts of it, each run once): maps and cycle damages add up; the
    tracks' damages by the weakest link (map) and Miner's rule (cycle rule); DG03 by Miner's rule."""
    from ..life.raceway_map import track_damage
    from ..life.rating import combined_damage

    damage_map = sum(r["map"] for r in runs)
    duration = sum(_number(r["summary"].get("duration_s", 0.0)) for r in runs)
    cycle = sum(np.asarray(r["summary"].get("track_damage", np.zeros(4)), float) for r in runs)
    dg03 = sum(duration_i / 3600.0 / h if h > 0 else 0.0 for duration_i, h in
               ((_number(r["summary"].get("duration_s", 0.0)), _number(r["summary"].get("life_dg03_L10_h", "inf")))
                for r in runs))
    hours = lambda d: duration / 3600.0 / d if d > 0 else float("inf")   # noqa: E731
    ours = hours(float(combined_damage(cycle)))
    return {"map": damage_map, "map_track": track_damage(damage_map), "cycle_track": cycle,
            "duration": duration, "ours_h": ours, "map_h": hours(float(combined_damage(track_damage(damage_map)))),
            "dg03_h": hours(dg03), "ratio": hours(dg03) / ours if np.isfinite(ours) and ours > 0 else float("nan")}


def _short(label: str, width: int = 48) -> str:
    return label if len(label) <= width else label[:width - 3] + "..."


def _distinct_labels(labels: list[str]) -> dict:
    """Each label without the comma-separated parts all labels share (``table3, rigid, preload 0 um,
    errors seed 3`` -> ``errors seed 3``), shortened: what sets the variants apart, where a cut
    label would lose it."""
    parts = [label.split(", ") for label in labels]
    common = set.intersection(*(set(p) for p in parts)) if len(labels) > 1 else set()
    return {label: _short(", ".join(x for x in p if x not in common) or label, 40) for label, p in zip(labels, parts)}


def _common_part(labels: list[str]) -> str:
    """The comma-separated parts all labels share, in the first label's order."""
    parts = [label.split(", ") for label in labels]
    common = set.intersection(*(set(p) for p in parts))
    return ", ".join(x for x in parts[0] if x in common)


def _fmt_h(h: float) -> str:
    return "inf" if not np.isfinite(h) else f"{h:.3g} h"


def _damage_scale(ax, drawn: np.ndarray) -> None:
    """A log y-axis for slice damages that span more than two decades (where a linear axis set by
    the largest shows the others as a line along zero)."""
    positive = drawn[np.isfinite(drawn) & (drawn > 0)]
    if positive.size and positive.max() / positive.min() > 100:
        top = 3 * float(positive.max())
        ax.set_yscale("log")      # at most seven decades: a slice far below the others leaves the axis at its foot
        ax.set_ylim(max(0.3 * positive.min(), 1e-7 * top), top)


def life_figure(path: str, case_dirs, title: str | None = None) -> str:
    """The raceway damage map of each track as steps (an empty slice shows as a gap), with each track's
    damage and life; and x/2b of the rainflow cycles, shares of the cycles and of the damage.

    ``case_dirs``: a list of folders that are parts of one duty (their maps add up: the cases of one
    bearing over several load series, or one `slewing life` run), or a dict ``{label: [folders]}`` of
    groups that are alternative designs (bearing variants): each group is one duty, and the groups are
    drawn side by side (up to :data:`MAX_GROUP_LINES`; beyond, their median and range), never added."""
    plt = _pyplot()
    groups = case_dirs if isinstance(case_dirs, dict) else {"": list(case_dirs)}
    runs = {label: [_read_life(f) for f in folders] for label, folders in groups.items()}
    duties = {label: _duty(r) for label, r in runs.items()}
    angle = next(iter(runs.values()))[0]["angle"]
    edges = np.linspace(0.0, 360.0, angle.size + 1)
    # constrained layout: the titles and the text panel keep their room (tight_layout let a map's title
    # run under the histogram and cut the last text line at the figure's edge)
    fig = plt.figure(figsize=(13, 9), layout="constrained")
    grid = fig.add_gridspec(1, 2, width_ratios=(1.6, 1.0))
    left, right = grid[0, 0].subgridspec(4, 1), grid[0, 1].subgridspec(2, 1, height_ratios=(1.3, 1.0))
    axes = [fig.add_subplot(left[k, 0]) for k in range(4)]
    one = len(duties) == 1
    short_labels = _distinct_labels(list(duties))
    for k, ax in enumerate(axes):
        if len(duties) <= MAX_GROUP_LINES:
            drawn = np.array([duty["map"][k] for duty in duties.values()])
            for j, (label, duty) in enumerate(duties.items()):
                ax.stairs(duty["map"][k], edges, lw=0.8, fill=one, alpha=0.8 if one else 1.0,
                          color=f"C{k if one else j}", label=None if one else short_labels[label])
        else:   # many variants: median and 5-95 % band, and the largest, dotted (on a log axis when far above)
            maps = np.array([duty["map"][k] for duty in duties.values()])
            lo, median, hi = np.percentile(maps, [5, 50, 95], axis=0)
            drawn = np.array([lo, median, hi, maps.max(axis=0)])
            ax.stairs(hi, edges, baseline=lo, fill=True, alpha=0.35, color=f"C{k}",
                      label=f"5-95 % of the {len(duties)} variants")
            ax.stairs(median, edges, color=f"C{k}", lw=1.2, label="median")
            ax.stairs(maps.max(axis=0), edges, color="k", lw=0.5, ls=":", label="largest")
        if not one:     # alternative designs can lie decades apart
            _damage_scale(ax, drawn)
        if one:
            d = next(iter(duties.values()))
            life_k = d["duration"] / 3600.0 / d["cycle_track"][k] if d["cycle_track"][k] > 0 else float("inf")
            ax.set_title(f"contact {TRACK_LABELS[k]}: D = {d['cycle_track'][k]:.3g} (cycle rule), "
                         f"{d['map_track'][k]:.3g} (map) in {d['duration']:.4g} s\nL10 of the track alone "
                         f"{_fmt_h(life_k)}", fontsize=9, loc="left")
        else:
            dk = np.array([d["map_track"][k] for d in duties.values()])
            ax.set_title(f"contact {TRACK_LABELS[k]}, map: D median {np.median(dk):.3g}, "
                         f"range {dk.min():.3g}..{dk.max():.3g}", fontsize=9, loc="left")
        ax.set_xlim(0, 360)
        ax.set_ylabel("slice damage d_j" + (" (log)" if ax.get_yscale() == "log" else ""), fontsize=8)
        ax.grid(alpha=0.3)
        if k < 3:
            ax.tick_params(labelbottom=False)
    axes[3].set_xlabel("slice, angle around its own ring [deg] (steps: a slice no ball rolled over is 0)")

    ax2 = fig.add_subplot(right[0, 0])
    ratios, counted, damage = [], [], []
    for r in (x for group in runs.values() for x in group):
        c = r["cycles"]
        if not c.get("count", np.zeros(0)).size:
            continue
        micro = _number(r["summary"].get("micro_swing_rad", 0.0))
        micro = 0.0 if np.isnan(micro) else micro
        worst = r["summary"].get("life_worst_track")
        ratios.append(c["travel_ratio"])
        counted.append(np.where(c["swing_rad"] >= micro, c["count"], 0.0))
        damage.append(c[f"damage_{worst}"] if worst and f"damage_{worst}" in c else np.zeros(c["count"].size))
    if ratios:
        r, wc, wd = np.concatenate(ratios), np.concatenate(counted), np.concatenate(damage)
        keep = np.isfinite(r) & (r > 0)
        r, wc, wd = r[keep], wc[keep], wd[keep]
        lo, hi = np.floor(np.log10(r.min())), np.ceil(np.log10(r.max()))
        bins = np.logspace(lo, max(hi, lo + 1), int(max(hi - lo, 1) * 4) + 1)
        shares, labels = [], []
        if wc.sum() > 0:
            shares.append(("cycles", wc / wc.sum(), "tab:blue"))
        if wd.sum() > 0:
            shares.append(("damage (worst track)", wd / wd.sum(), "tab:red"))
        if shares:
            ax2.hist([r] * len(shares), bins=bins, weights=[s[1] for s in shares], color=[s[2] for s in shares],
                     label=[f"share of the {s[0]}: {s[1][r < 1].sum():.0%} below 1" for s in shares])
            ax2.legend(fontsize=8, loc="upper left")
        ax2.axvline(1.0, color="k", ls="--", lw=1)
        ax2.set_xscale("log")
    ax2.set_title("x/2b of the rainflow cycles (micro-cycles left out of the count)", fontsize=9)
    ax2.set_xlabel("rolling travel over contact width, x/2b [-]")
    ax2.set_ylabel("share per bin")
    ax2.grid(alpha=0.3)

    ax3 = fig.add_subplot(right[1, 0])
    ax3.axis("off")
    lines = []       # (text, colour): a variant's line in its maps' colour, which makes it the maps' legend
    lines.append((f"L10 in hours of the duty ({next(iter(duties.values()))['duration']:.4g} s) repeated:" if one else
                  "L10 in hours of each variant's duty repeated" +
                  (" (colours as in the maps):" if len(duties) <= MAX_GROUP_LINES else ":"), "k"))
    if not one and len(duties) <= MAX_GROUP_LINES:
        lines.append(("ours = ISO/TS 16281 + oscillation rule; map = raceway map", "k"))
    for j, (label, d) in enumerate(duties.items() if len(duties) <= MAX_GROUP_LINES else []):
        track = int(np.argmax(d["cycle_track"])) + 1 if d["cycle_track"].max() > 0 else None
        ratio = ("" if np.isnan(d["ratio"]) else " (no damage)" if np.isinf(d["ratio"])
                 else f" = {d['ratio']:.2f} x ours")
        if label:      # one line a variant, named by what sets it apart
            lines.append((f"{short_labels[label]}: ours {_fmt_h(d['ours_h'])}"
                          f"{f' (track {track})' if track else ''}, map {_fmt_h(d['map_h'])}, "
                          f"DG03 {_fmt_h(d['dg03_h'])}{ratio}", f"C{j}"))
            continue
        worst = f"worst track {track}" if track else "no damage"
        lines.append((f"ISO/TS 16281 + oscillation rule {_fmt_h(d['ours_h'])} ({worst})", "k"))
        lines.append((f"raceway map {_fmt_h(d['map_h'])};  DG03 {_fmt_h(d['dg03_h'])}{ratio}", "k"))
    if len(duties) > MAX_GROUP_LINES:
        ours = np.array([d["ours_h"] for d in duties.values()])
        ratio = np.array([d["ratio"] for d in duties.values()])
        lines.append((f"ours: median {_fmt_h(float(np.median(ours)))}, range "
                      f"{_fmt_h(float(ours.min()))}..{_fmt_h(float(ours.max()))}", "k"))
        finite = ratio[np.isfinite(ratio)]
        no_damage = int(np.sum(np.isinf(ratio)))
        lines.append(("DG03 / ours: " + (f"median {np.median(finite):.2f}, range {finite.min():.2f}.."
                                         f"{finite.max():.2f}" if finite.size else "no finite ratio"), "k"))
        if no_damage:   # DG03's equivalent load is zero (an unloaded ring): its life is infinite, not a ratio
            lines.append((f"DG03 sees no damage (L10 inf) in {no_damage} of the {len(duties)} variants", "k"))
    cases = sum(len(v) for v in groups.values())
    lines.append((f"{cases} run(s)" + (" of one duty, added" if one and cases > 1 else "") + ("" if one else
                  f" in {len(duties)} variants: each variant's runs added, variants (alternative designs) "
                  f"never added"), "k"))
    if not one and len(duties) <= MAX_GROUP_LINES and any(short_labels[k] != k for k in short_labels):
        lines.append((f"all variants: {_common_part(list(duties))}", "k"))
    size = 9 if len(lines) <= 10 else 8      # wrapped to the panel's width (about 5 inches)
    anchor = None
    for text, colour in lines:
        for wrapped in textwrap.wrap(text, 60 if size == 9 else 66, subsequent_indent="    "):
            anchor = (ax3.text(0.0, 1.0, wrapped, va="top", fontsize=size, color=colour, transform=ax3.transAxes)
                      if anchor is None else       # each line under the one before
                      ax3.annotate(wrapped, xy=(0.0, 0.0), xycoords=anchor, xytext=(0.0, -0.3 * size),
                                   textcoords="offset points", va="top", fontsize=size, color=colour))
    if len(duties) > MAX_GROUP_LINES:     # the maps' legend at the panel's foot, not over a map's curves
        ax3.legend(*axes[0].get_legend_handles_labels(), title="the maps (left), in contact 1's colour",
                   fontsize=7, title_fontsize=7, loc="lower left", frameon=False)
    if title:
        fig.suptitle(title)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
