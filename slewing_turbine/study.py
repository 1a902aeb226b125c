"""Turbine studies: closed-loop cases (:func:`slewing_turbine.loop.run_turbine`) on Dask distributed.

A turbine study file (TOML) names a turbine file (:mod:`slewing_turbine.turbine_file`) and the axes whose
product makes the cases; each axis is a list of values of one key of the turbine file, and ``[overrides]``
sets keys for every case::

    [study]
    name = "turbine-nrel5mw"
    description = "..."                   # optional
    turbine = "../turbines/nrel5mw.toml"  # the base case, relative to this file

    [axes.wind]                           # every list is one axis of the product (in this order)
    speed_m_s = [8.0, 13.0, 18.0]
    seed = [1, 2]
    [axes.controller]
    ipc = [false, true]
    [axes.pitch]
    friction = [false, true]

    [overrides.simulation]                # optional: the same for every case
    t_end_s = 60.0

Each case is the turbine file with its axes' values, validated as a turbine file (a bad value is refused
before anything runs, naming the case). The output directory follows ``slewing batch``'s conventions
(:mod:`slewing_model.study.engine`)::

    DIR/study.json                     the study the folder holds (name, file)
    DIR/summary.csv                    one row per case: case, status, name, the axes' values, the figures of
                                       :func:`summary_row` (units in the column names), elapsed_s (wall),
                                       cpu_s (the worker's CPU time), worker
    DIR/cases/<key>/case.json          the case: every setting (:meth:`TurbineCase.describe`)
    DIR/cases/<key>/timeseries.csv     :data:`TIMESERIES_COLUMNS` (SI)
    DIR/cases/<key>/result.json        status, the summary row, wall and CPU time, worker, what ROSCO printed
                                       (its warnings; kept off the terminal) (written last)
    DIR/figures/turbine_study.png      :func:`study_figure`

A case's key is the SHA-256 of its settings with the files (DISCON.IN, Cp table, rotor, drive, bearings,
wind file) named by their content: a rerun skips the finished cases (failed ones too, unless
``retry_failed``), wherever the folder lives. A folder holding another study's results is refused
(``overwrite`` clears them).
"""
from __future__ import annotations

import csv
import dataclasses
import hashlib
import itertools
import json
import math
import os
import re
import tempfile
import time
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from slewing_model.bearing.conventions import definition_message

from .turbine_file import TABLES, TurbineCase, TurbineDefinitionError, load_turbine

#: bump when a case's numbers change for the same inputs (reruns then recompute)
CASE_FORMAT = 2
STUDY_RECORD = "study.json"
#: a case's time series (SI; per blade k = 1, 2, 3)
TIMESERIES_COLUMNS = (("time_s", "wind_m_s", "rotor_speed_rad_s", "generator_torque_Nm", "aero_torque_Nm")
                      + tuple(f"{q}_{k}" for q in ("pitch_demand_rad", "pitch_rad", "pitch_rate_rad_s",
                                                   "motor_torque_Nm", "friction_torque_Nm", "load_moment_Nm")
                              for k in (1, 2, 3)))


class TurbineStudyError(ValueError):
    """A turbine study file breaks a rule (the message names the file, the key, the value and the rule)."""


# ---- a case's figures --------------------------------------------------------------------------------

def column_name(key: str) -> str:
    """A column name from a :func:`slewing_turbine.loop.summary` key: ``"motor torque peak [N m]"`` ->
    ``"motor_torque_peak_Nm"``, ``"overspeed [%]"`` -> ``"overspeed_pct"``."""
    name, _, unit = key.partition("[")
    name = name.strip().lower().replace(" / ", " over ").replace("%", "pct")
    name = re.sub(r"[^0-9a-z]+", "_", name).strip("_")
    unit = unit.rstrip("]").strip().replace("%", "pct").replace("/", "_")
    unit = re.sub(r"\s+", "", unit)
    return f"{name}_{unit}" if unit else name


def summary_row(result, settle: float | None = None) -> dict:
    """The figures of a run as a row (column name -> number), over the window after the settle time
    (``settle``, None: the run's; :func:`slewing_turbine.loop.summary`): the summary, then per blade
    (``_1``, ``_2``, ``_3``) the pitch tracking error RMS, the motor torque peak and RMS, the drive energy,
    the friction torque mean and peak; with bearings, the pitch oscillations by ``x/2b``
    (:func:`slewing_turbine.loop.wear_shares`: the counted rainflow cycles and the shares with ``x/2b < 1``
    and ``>= 1``, %); with life, the bearing's largest raceway damage (whole run); and the wind's mean and
    standard deviation over the window."""
    from .loop import settle_index, summary, wear_shares, window_energies

    r = result
    i0 = settle_index(r, settle)
    row = {column_name(k): float(v) for k, v in summary(r, settle).items()}
    row["wind_mean_m_s"] = float(np.mean(r.wind[i0:]))
    row["wind_std_m_s"] = float(np.std(r.wind[i0:]))
    error = r.pitch_demand[i0:-1] - r.pitch[i0 + 1:]
    motor = window_energies(r, i0).get("motor")
    for k in range(3):
        b = k + 1
        row[f"pitch_tracking_error_rms_deg_{b}"] = float(np.degrees(np.sqrt(np.mean(error[:, k] ** 2))))
        if r.drives == "electric":
            torque = np.abs(r.motor_torque[i0 + 1:, k])
            row[f"motor_torque_peak_Nm_{b}"] = float(torque.max())
            row[f"motor_torque_rms_Nm_{b}"] = float(np.sqrt(np.mean(torque ** 2)))
            row[f"drive_energy_kJ_{b}"] = float(motor[k] / 1e3)
            row[f"friction_torque_mean_kNm_{b}"] = float(np.mean(r.friction_torque[i0 + 1:, k]) / 1e3)
            row[f"friction_torque_peak_kNm_{b}"] = float(np.max(r.friction_torque[i0 + 1:, k]) / 1e3)
        if r.contact_b is not None:
            w = wear_shares(r, k, i0)
            row[f"oscillations_{b}"] = w["cycles"]
            row[f"x2b_below_1_pct_{b}"] = 100.0 * w["below"]
            row[f"x2b_above_1_pct_{b}"] = 100.0 * w["above"]
        if r.life is not None:
            row[f"bearing_damage_{b}"] = float(r.life[k].worst_damage)
    return row


def timeseries_table(result) -> np.ndarray:
    """(n, len(TIMESERIES_COLUMNS)): the run's time series (SI)."""
    r = result
    columns = [r.time, r.wind, r.rotor_speed, r.generator_torque, r.aero_torque]
    for q in (r.pitch_demand, r.pitch, r.pitch_rate, r.motor_torque, r.friction_torque, r.load_moment):
        columns += [q[:, k] for k in range(3)]
    return np.column_stack(columns)


def write_timeseries(path: str, result) -> None:
    np.savetxt(path, timeseries_table(result), delimiter=",", fmt="%.10g", header=",".join(TIMESERIES_COLUMNS),
               comments="")


# ---- the study file ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class TurbineStudyCase:
    """One case: the turbine file with the axes' values.

    Attributes
    ----------
    index : int
        Its place in the product (the order of ``summary.csv``).
    key : str
        16 hex digits of the SHA-256 of its settings, files by content.
    name : str
        The axes' values, readable (``"speed_m_s=8, seed=1, ipc=off, friction=on"``).
    values : dict
        ``"table.key"`` -> the value of each axis.
    case : TurbineCase
    """

    index: int
    key: str
    name: str
    values: dict
    case: TurbineCase


@dataclass
class TurbineStudy:
    """A validated turbine study file."""

    name: str
    description: str
    path: str
    turbine: str
    axes: dict            # "table.key" -> list of values
    overrides: dict       # "table.key" -> value
    cases: list


def _flatten(table: Any, where: str, study_path: str) -> dict:
    """``[axes.wind] speed_m_s = [...]`` -> ``{"wind.speed_m_s": [...]}``; a key given as ``"wind.speed_m_s"``
    directly under the table is taken as well."""
    if not isinstance(table, Mapping):
        raise TurbineStudyError(f"{study_path}: {definition_message(where, table, 'must be a table')}")
    out = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            if key not in TABLES:
                raise TurbineStudyError(f"{study_path}: " + definition_message(
                    f"{where}.{key}", None, f"unknown table [{where}.{key}]: must name a table of the turbine "
                                            f"file ({', '.join(sorted(TABLES))})"))
            for k, v in value.items():
                out[f"{key}.{k}"] = v
        else:
            out[key] = value
    for dotted, value in out.items():
        table_name, _, key = dotted.partition(".")
        if table_name not in TABLES or key not in TABLES[table_name]:
            known = sorted(TABLES[table_name]) if table_name in TABLES else sorted(TABLES)
            raise TurbineStudyError(f"{study_path}: " + definition_message(
                f"{where}.{dotted}", value, f"not a key of the turbine file (known in "
                                            f"{'[' + table_name + ']' if table_name in TABLES else 'tables'}: "
                                            f"{', '.join(known)})"))
    return out


def _label(dotted: str, value) -> str:
    short = dotted.rpartition(".")[2]
    if isinstance(value, bool):
        return f"{short}={'on' if value else 'off'}"
    if isinstance(value, float):
        return f"{short}={value:g}"
    return f"{short}={value}"


def load_turbine_study(path) -> TurbineStudy:
    """Read a turbine study file, validate each of its cases (as a turbine file) and give each its key.

    Raises
    ------
    TurbineStudyError, TurbineDefinitionError
        Naming the file, the key (and the case), the value and the rule.
    """
    from slewing_model.study.definition import read_toml

    path = os.fspath(path)
    data = read_toml(path, TurbineStudyError, "study file")
    return turbine_study_from_dict(data, os.path.dirname(os.path.abspath(path)), path)


def is_turbine_study(path) -> bool:
    """True for a file with a ``[study]`` table (a turbine study file); False for a turbine file."""
    import tomllib

    try:
        with open(path, "rb") as fh:
            return "study" in tomllib.load(fh)
    except (OSError, ValueError):
        return False


def turbine_study_from_dict(data: Mapping, study_dir: str, path: str = "<dict>") -> TurbineStudy:
    """Validate a turbine study's layout (:func:`load_turbine_study`); relative paths against ``study_dir``."""
    def fail(key, value, rule):
        raise TurbineStudyError(f"{path}: {definition_message(key, value, rule)}")

    for key in data:
        if key not in ("study", "axes", "overrides"):
            fail(key, data[key] if not isinstance(data[key], Mapping) else None,
                 f"unknown table [{key}] (known tables: [axes], [overrides], [study]; names are case-sensitive)")
    head = data.get("study")
    if not isinstance(head, Mapping):
        fail("study", head, "missing table [study] (required)" if head is None else "must be a table")
    for key in head:
        if key not in ("name", "description", "turbine"):
            fail(f"study.{key}", head[key], "unknown key in table [study] (known: description, name, turbine)")
    name = head.get("name", os.path.splitext(os.path.basename(path))[0])
    if not isinstance(name, str) or not name:
        fail("study.name", name, "must be a non-empty string")
    description = head.get("description", "")
    if not isinstance(description, str):
        fail("study.description", description, "must be a string")
    turbine = head.get("turbine")
    if not isinstance(turbine, str) or not turbine:
        fail("study.turbine", turbine, "missing key (required): the turbine file of the cases"
             if turbine is None else "must be a turbine file (TOML)")
    turbine = os.path.normpath(os.path.join(study_dir, turbine))
    if not os.path.isfile(turbine):
        fail("study.turbine", head["turbine"], f"no such file: {turbine}")
    axes = _flatten(data.get("axes", {}), "axes", path)
    overrides = _flatten(data.get("overrides", {}), "overrides", path)
    for dotted, values in axes.items():
        if not isinstance(values, list) or not values:
            fail(f"axes.{dotted}", values, "must be a non-empty list (the axis' values)")
        if len(set(map(json.dumps, values))) != len(values):
            fail(f"axes.{dotted}", values, "values must be distinct")
        if dotted in overrides:
            fail(f"overrides.{dotted}", overrides[dotted], f"also an axis (axes.{dotted}): give it once")

    cases, digests, seen = [], {}, {}
    for index, combo in enumerate(itertools.product(*axes.values())):
        values = dict(zip(axes, combo))
        label = ", ".join(_label(k, v) for k, v in values.items()) or "base"
        try:
            case = load_turbine(turbine, overrides={**overrides, **values})
        except TurbineDefinitionError as exc:
            raise TurbineStudyError(f"{path}: case {label}: {exc}") from None
        case = dataclasses.replace(case, name=f"{case.name} | {label}" if values else case.name)
        key = case_key(case, digests)
        if key in seen:
            raise TurbineStudyError(f"{path}: cases {seen[key]!r} and {label!r} are the same case")
        seen[key] = label
        cases.append(TurbineStudyCase(index, key, label, values, case))
    return TurbineStudy(name, description, path, turbine, axes, overrides, cases)


def case_key(case: TurbineCase, digests: dict | None = None) -> str:
    """16 hex digits of the SHA-256 of the case's settings, its files by content (not by path)."""
    from slewing_model.study.definition import file_digest

    digests = {} if digests is None else digests

    def digest(p):
        if p not in digests:
            digests[p] = file_digest(p)
        return {"name": os.path.basename(p), "sha256": digests[p]}

    spec = case.describe()
    for k in ("name", "description", "path"):
        spec.pop(k)
    d = spec.pop("turbine_dir")
    for k in ("discon", "cp_table", "rotor"):
        spec[k] = digest(os.path.join(d, spec[k]))
    spec["drive"] = digest(spec["drive"])
    spec["bearings"] = [digest(b) for b in spec["bearings"]]
    if "file" in spec["wind"]:
        spec["wind"]["file"] = digest(spec["wind"]["file"])
    spec["format"] = CASE_FORMAT
    text = json.dumps(spec, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ---- one case, on a worker ---------------------------------------------------------------------------

def run_case(case: TurbineCase) -> dict:
    """Run one case: ``status`` ("ok" or the error), ``row`` (:func:`summary_row`), ``timeseries``
    (:func:`timeseries_table`), ``messages`` (what ROSCO printed: :func:`controller_messages`), ``elapsed``
    and ``cpu`` (s), ``worker``."""
    import socket

    from slewing_model.study.case import one_line

    from .controller import _StdoutToFile

    start, cpu = time.perf_counter(), time.process_time()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    with tempfile.TemporaryDirectory(prefix="slewing-turbine-case-") as folder:
        log = os.path.join(folder, "controller.txt")
        try:
            with _StdoutToFile(log):       # ROSCO's warnings: into the case's record, not the terminal
                result = case.run()
            out = {"status": "ok", "row": summary_row(result), "timeseries": timeseries_table(result)}
        except Exception as exc:  # noqa: BLE001 - a case's failure is its status, not the study's
            out = {"status": one_line(exc), "row": {}, "timeseries": None}
        out["messages"] = controller_messages(log)
    out.update(elapsed=time.perf_counter() - start, cpu=time.process_time() - cpu, worker=worker)
    return out


def controller_messages(path) -> list:
    """The distinct lines ROSCO printed (its frames of asterisks and blank lines left out), in order."""
    try:
        with open(path, errors="replace") as fh:
            lines = [line.strip() for line in fh]
    except OSError:
        return []
    return list(dict.fromkeys(line for line in lines if line and set(line) != {"*"}))


# ---- the output directory ----------------------------------------------------------------------------

def _write_case(out_dir: str, sc: TurbineStudyCase, result: dict) -> dict:
    from slewing_model.study.engine import case_dir, write_json

    folder = case_dir(out_dir, sc.key)
    os.makedirs(folder, exist_ok=True)
    write_json(os.path.join(folder, "case.json"), {"key": sc.key, "index": sc.index, "name": sc.name,
                                                   "values": sc.values, "case": sc.case.describe()})
    if result.get("timeseries") is not None:
        np.savetxt(os.path.join(folder, "timeseries.csv"), result["timeseries"], delimiter=",", fmt="%.10g",
                   header=",".join(TIMESERIES_COLUMNS), comments="")
    record = {"key": sc.key, "name": sc.name, "status": result["status"], "elapsed_s": result["elapsed"],
              "cpu_s": result.get("cpu"), "worker": result["worker"], "statistics": result["row"],
              "controller_messages": result.get("messages", [])}
    write_json(os.path.join(folder, "result.json"), record)
    return record


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    if isinstance(value, int):
        return str(value)
    return "" if math.isnan(value) else f"{value:.10g}"


def _rows(study: TurbineStudy, records: dict, lost: dict) -> tuple[list, list]:
    """The summary's columns and rows (as ``summary.csv`` reads back: strings)."""
    stats = list(dict.fromkeys(k for r in records.values() for k in (r.get("statistics") or {})))
    axes = [k.rpartition(".")[2] for k in study.axes]
    columns = ["case", "status", "name"] + axes + stats + ["elapsed_s", "cpu_s", "worker"]
    rows = []
    for sc in study.cases:
        row = {c: "" for c in columns}
        row.update(case=sc.key, name=sc.name)
        row.update({k.rpartition(".")[2]: _cell(v) for k, v in sc.values.items()})
        record = records.get(sc.key)
        if record is not None:
            row.update(status=" ".join(str(record["status"]).split()), elapsed_s=f"{record['elapsed_s']:.4g}",
                       cpu_s=_cell(record.get("cpu_s")), worker=record["worker"])
            row.update({k: _cell(v) for k, v in (record.get("statistics") or {}).items()})
        if sc.key in lost:
            row["status"] = lost[sc.key]
        rows.append(row)
    return columns, rows


def run_turbine_study(study, out_dir, *, workers: int | None = None, scheduler: str | None = None, client=None,
                      progress: bool = True, retry_failed: bool = False, figures: bool = True,
                      overwrite: bool = False):
    """Run every case of a turbine study that is not finished in ``out_dir`` on Dask.

    Parameters as :func:`slewing_model.study.run_study` (``workers``: the embedded ``LocalCluster``'s worker
    processes, default one per core; ``scheduler``: an existing cluster's address; ``client``: an existing
    client).

    Returns
    -------
    slewing_model.study.StudyReport

    Raises
    ------
    slewing_model.study.StudyInterrupted
        On Ctrl-C, after writing ``summary.csv`` for the cases finished so far.
    slewing_model.study.ForeignOutputError
        ``out_dir`` holds another study's results and ``overwrite`` is not set.
    """
    from slewing_model.study.engine import (StudyInterrupted, StudyReport, finished_cases, open_output_dir,
                                            run_on_dask, write_summary)

    if not isinstance(study, TurbineStudy):
        study = load_turbine_study(study)
    out_dir = os.fspath(out_dir)
    open_output_dir(out_dir, {"name": study.name, "path": study.path, "kind": "turbine"},
                    [c.key for c in study.cases], overwrite)
    report = StudyReport(len(study.cases), summary=os.path.join(out_dir, "summary.csv"))
    records, pending = finished_cases(out_dir, study.cases, report, retry_failed)
    lost = {}

    def finish():
        columns, report.rows = _rows(study, records, lost)
        report.failed = {r["case"]: r["status"] for r in report.rows if r["status"] != "ok"}
        write_summary(report.summary, report.rows, columns)

    def done(sc, result, client):
        records[sc.key] = _write_case(out_dir, sc, result)

    try:
        run_on_dask(run_case, [(sc, sc.case, f"slewing-turbine-case-{sc.key}") for sc in pending], report, lost,
                    done, workers=workers, scheduler=scheduler, client=client, progress=progress,
                    total=len(study.cases), title=study.name)
    except KeyboardInterrupt:
        for sc in pending:
            if sc.key not in records and sc.key not in lost:
                lost[sc.key] = "not finished: interrupted"
        finish()
        raise StudyInterrupted(report) from None
    finish()
    if figures:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            report.notes.append("no figures: matplotlib is not installed (the 'plot' extra)")
        else:
            figure = study_figure(report.summary, os.path.join(out_dir, "figures", "turbine_study.png"))
            if figure:
                report.figures = [figure]
    return report


# ---- the study's figure ------------------------------------------------------------------------------

#: the first column of :func:`summary_row` (the summary's columns: case, status, name, the axes, the figures)
FIRST_FIGURE = "settle_time_s"
#: the figures :func:`study_figure` shows (column, label)
FIGURE_COLUMNS = (("pitch_tracking_error_rms_deg", "pitch tracking error RMS [deg]"),
                  ("motor_torque_rms_Nm", "motor torque RMS [N m]"),
                  ("motor_torque_peak_Nm", "motor torque peak [N m]"),
                  ("drive_energy_kJ", "drive energy, 3 blades [kJ]"),
                  ("time_above_continuous_torque_pct", "time above continuous torque [%]"),
                  ("friction_torque_mean_kNm", "friction torque mean [kN m]"),
                  ("rotor_speed_std_rpm", "rotor speed std [rpm]"),
                  ("overspeed_pct", "overspeed [%]"),
                  ("x_2b_below_1_worst_blade_pct", "oscillations x/2b < 1, worst blade [%]"))


def read_summary(path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def study_figure(summary_csv, png) -> str | None:
    """Friction off against on and IPC off against on: each figure of :data:`FIGURE_COLUMNS` against the
    first numeric axis (the wind speed), one line per combination of the on/off axes, the mean over the
    other axes (seeds) with their range as a band. Returns the file written (None: no finished case)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in read_summary(summary_csv) if r["status"] == "ok"]
    if not rows:
        return None
    header = list(rows[0])
    axes = _axes(header)
    switches = [a for a in axes if {r[a] for r in rows} <= {"true", "false"}]
    numeric = [a for a in axes if a not in switches and _all_numbers(r[a] for r in rows)]
    x_axis = next((a for a in numeric if a == "speed_m_s"), numeric[0] if numeric else None)
    columns = [(c, label) for c, label in FIGURE_COLUMNS if c in header and any(r[c] for r in rows)]
    if not columns:
        return None
    n = len(columns)
    fig, panels = plt.subplots((n + 1) // 2, 2, figsize=(11, 2.6 * ((n + 1) // 2)), sharex=True, squeeze=False)
    combos = sorted({tuple(r[s] for s in switches) for r in rows})
    styles = ["-", "--", ":", "-."]
    for (column, label), ax in zip(columns, panels.flat):
        for j, combo in enumerate(combos):
            group = [r for r in rows if tuple(r[s] for s in switches) == combo]
            xs = sorted({float(r[x_axis]) for r in group}) if x_axis else [0.0]
            mean, low, high = [], [], []
            for x in xs:
                ys = [float(r[column]) for r in group if (x_axis is None or float(r[x_axis]) == x) and r[column]]
                mean.append(np.mean(ys) if ys else np.nan)
                low.append(min(ys) if ys else np.nan)
                high.append(max(ys) if ys else np.nan)
            name = ", ".join(f"{s} {'on' if v == 'true' else 'off'}" for s, v in zip(switches, combo)) or "cases"
            line, = ax.plot(xs, mean, styles[j % 4], marker="o", ms=3,
                            color=f"C{j}", label=name)
            ax.fill_between(xs, low, high, color=line.get_color(), alpha=0.15, lw=0)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(alpha=0.3)
    for ax in panels.flat[n:]:
        ax.set_visible(False)
    x_label = {"speed_m_s": "mean wind speed [m/s]"}.get(x_axis, x_axis)
    for ax in panels[-1]:
        ax.set_xlabel(f"{x_label} (mean over the other axes; band: their range)" if x_axis else "")
    panels.flat[0].legend(fontsize=7)
    try:
        with open(os.path.join(os.path.dirname(os.path.abspath(summary_csv)), STUDY_RECORD)) as fh:
            title = json.load(fh).get("name") or "turbine study"
    except (OSError, ValueError, AttributeError):
        title = "turbine study"
    fig.suptitle(title)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return os.fspath(png)


def _axes(header: list) -> list:
    """The axes' columns of a summary: between ``name`` and the first figure (:func:`summary_row`)."""
    first = next((c for c in (FIRST_FIGURE, "pitch_tracking_error_rms_deg") if c in header), "elapsed_s")
    return header[header.index("name") + 1:header.index(first)]


def _all_numbers(values) -> bool:
    try:
        for v in values:
            float(v)
    except ValueError:
        return False
    return True


def markdown_table(summary_csv, columns=None) -> str:
    """The summary's finished rows as a Markdown table (``columns``: default the axes and the figures of
    :data:`FIGURE_COLUMNS`)."""
    rows = [r for r in read_summary(summary_csv) if r["status"] == "ok"]
    if not rows:
        return "(no finished case)"
    header = list(rows[0])
    if columns is None:
        columns = _axes(header) + [c for c, _ in FIGURE_COLUMNS if c in header]
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        lines.append("| " + " | ".join(_short(r[c]) for c in columns) + " |")
    return "\n".join(lines)


def _short(text: str) -> str:
    try:
        value = float(text)
    except ValueError:
        return text
    return f"{value:.4g}"
