"""``slewing turbine FILE.toml -o DIR``: one closed-loop turbine case, or a turbine study on Dask.

A turbine file (:mod:`slewing_turbine.turbine_file`) runs its case and writes into ``DIR``:

* ``summary.json`` -- the case's settings and its figures (:func:`slewing_turbine.loop.summary`, the
  keys naming their units, and :func:`slewing_turbine.study.summary_row`'s columns);
* ``summary.csv`` -- the figures as one row (the columns of a study's ``summary.csv``);
* ``timeseries.csv`` -- :data:`slewing_turbine.study.TIMESERIES_COLUMNS` (SI);
* ``turbine.png`` -- :func:`plot_timeseries`.

A turbine study file (a ``[study]`` table: :mod:`slewing_turbine.study`) runs its cases on Dask
(:func:`slewing_turbine.study.run_turbine_study`), with ``slewing batch``'s output conventions.
"""
from __future__ import annotations

import csv
import json
import math
import os
import sys

import numpy as np


def plot_timeseries(result, path, title: str = "") -> str:
    """Five panels against time: the hub wind; the rotor speed (rated dashed); each blade's pitch demand
    (dashed) against its pitch; each blade's motor torque (one motor; the drive's limit dashed); each
    blade's bearing friction torque. Returns ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .loop import RATED_ROTOR_SPEED

    r = result
    t = r.time
    electric = r.drives == "electric"
    n = 5 if electric else 3
    fig, ax = plt.subplots(n, 1, figsize=(10, 2.2 * n + 0.6), sharex=True)
    ax[0].plot(t, r.wind, "k", lw=0.8)
    ax[0].set_ylabel("hub wind [m/s]")
    ax[1].plot(t, r.rotor_speed * 30.0 / math.pi, "k", lw=0.8)
    ax[1].axhline(RATED_ROTOR_SPEED * 30.0 / math.pi, color="r", ls="--", lw=0.8, label="rated")
    ax[1].set_ylabel("rotor speed [rpm]")
    ax[1].legend(loc="lower right", fontsize=7)
    for k in range(3):
        ax[2].plot(t, np.degrees(r.pitch_demand[:, k]), "--", color=f"C{k}", lw=0.8,
                   label=f"blade {k + 1} demand")
        ax[2].plot(t, np.degrees(r.pitch[:, k]), "-", color=f"C{k}", lw=1.0, label=f"blade {k + 1} pitch")
    ax[2].set_ylabel("pitch [deg]")
    ax[2].legend(loc="upper left", fontsize=7, ncol=3)
    if electric:
        for k in range(3):
            ax[3].plot(t, r.motor_torque[:, k], color=f"C{k}", lw=0.8, label=f"blade {k + 1}")
            ax[4].plot(t, r.friction_torque[:, k] / 1e3, color=f"C{k}", lw=0.8, label=f"blade {k + 1}")
        limit = r.drive_params.torque_limit
        for sign in (1, -1):
            ax[3].axhline(sign * limit, color="r", ls="--", lw=0.8, label="limit" if sign > 0 else None)
        ax[3].set_ylabel("motor torque [N m]")
        ax[3].legend(loc="upper left", fontsize=7, ncol=4)
        ax[4].set_ylabel("bearing friction\ntorque [kN m]")
        if not r.friction or r.bearings is None:
            ax[4].text(0.5, 0.5, "friction off" if not r.friction else "no bearing",
                       transform=ax[4].transAxes, ha="center", va="center", color="0.4")
    ax[-1].set_xlabel("time [s]")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title or "turbine loop", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return os.fspath(path)


def run_single(case, out_dir, *, figure: bool = True, progress: bool = False) -> dict:
    """Run a :class:`~slewing_turbine.turbine_file.TurbineCase` and write its files into ``out_dir``.

    Returns
    -------
    dict
        ``summary`` (the loop's figures), ``row`` (the summary's columns), ``files`` (written), ``result``.
    """
    from slewing_model.study.engine import write_json

    from .loop import summary
    from .study import summary_row, write_timeseries

    result = case.run(progress=progress)
    figures = summary(result)
    row = summary_row(result)
    os.makedirs(out_dir, exist_ok=True)
    files = [os.path.join(out_dir, name) for name in ("summary.json", "summary.csv", "timeseries.csv")]
    write_json(files[0], {"case": case.describe(), "summary": figures, "row": row})
    with open(files[1], "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["name"] + list(row))
        w.writeheader()
        w.writerow({"name": case.name, **{k: f"{v:.10g}" for k, v in row.items()}})
    write_timeseries(files[2], result)
    if figure:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            print("note: no figure: matplotlib is not installed (the 'plot' extra)", file=sys.stderr)
        else:
            title = f"{case.name}: {case.wind['kind']} wind, {case.drives} drives" + (
                f", {case.ring_model} bearings, friction {'on' if case.friction else 'off'}"
                if case.bearing_model else "") + f", IPC {'on' if case.ipc else 'off'}"
            files.append(plot_timeseries(result, os.path.join(out_dir, "turbine.png"), title))
    return {"summary": figures, "row": row, "files": files, "result": result}


def run(args) -> int:
    """The handler of ``slewing turbine`` (``args``: see :func:`slewing_model.cli`'s ``turbine`` parser)."""
    from .study import is_turbine_study

    if is_turbine_study(args.file):
        return _run_study(args)
    from .turbine_file import load_turbine

    overrides = {"simulation.t_end_s": args.t_end} if args.t_end is not None else None
    case = load_turbine(args.file, overrides=overrides)
    for option in ("workers", "scheduler"):
        if getattr(args, option) is not None:
            raise ValueError(f"--{option}: for a turbine study file (with a [study] table) only")
    out = run_single(case, args.output, figure=not args.no_figures, progress=not args.quiet)
    width = max(map(len, out["summary"]))
    print(f"{case.name}: {case.t_end:g} s at dt = {case.dt:g} s")
    for key, value in out["summary"].items():
        print(f"  {key:<{width}}  {value:.4g}")
    print("wrote " + ", ".join(out["files"]))
    return 0


def _run_study(args) -> int:
    from slewing_model.study.command import report_run

    from .study import load_turbine_study, markdown_table, run_turbine_study

    study = load_turbine_study(args.file)
    if args.t_end is not None:
        raise ValueError("--t-end: for a turbine file only (a study sets simulation.t_end_s in its [overrides])")

    def table(report):
        if not args.quiet:
            print(markdown_table(report.summary))

    return report_run("slewing turbine", args.file, lambda: run_turbine_study(
        study, args.output, workers=args.workers, scheduler=args.scheduler, progress=not args.quiet,
        retry_failed=args.retry_failed, figures=not args.no_figures, overwrite=args.overwrite), table)


def summary_json(path) -> dict:
    """Read a ``summary.json`` written by :func:`run_single`."""
    with open(path) as fh:
        return json.load(fh)
