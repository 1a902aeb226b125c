"""Running a study on Dask distributed, and its output directory.

:func:`run_study` expands the study into cases, skips those already finished in
the output directory (keyed by the case hash), reads every load series and bearing
once, builds each flexible bearing's superelement once (on the client, through the
on-disk cache of :func:`slewing_model.rings.superelement.build_superelement`), and submits
one task per case to a Dask cluster: by default an embedded ``LocalCluster`` of
worker processes (one per core), or an existing cluster given by its scheduler
address. Each task carries its bearing, superelement and load series, so workers
need neither the files nor a superelement build. The client writes each result as
it arrives; a worker that dies mid-run has its tasks rescheduled by Dask on the
others.

Output directory::

    DIR/study.json                     the study the folder holds (name, file)
    DIR/summary.csv                    one row per case (case, status, statistics, parameters)
    DIR/cases/<key>/case.json          the case: name, load series, bearing variant, settings
    DIR/cases/<key>/timeseries.csv     see slewing_model.study.case.TIMESERIES_COLUMNS (SI)
    DIR/cases/<key>/timeseries.parquet the same columns as Parquet (when pyarrow is installed; pandas and
                                       Dask read it natively: ``pandas.read_parquet(DIR + "/cases")``
                                       reads each case's file)
    DIR/cases/<key>/raceway_damage.csv slice centre angle (deg, in its ring's frame) and the damage of
                                       contacts 1..4 in that slice (slewing_model.life.raceway_map)
    DIR/cases/<key>/life_cycles.csv    rainflow cycles of psi: swing (rad), count, x/2b (smallest over the
                                       loaded contacts), and per contact 1..4 x/2b, swing over its
                                       critical angle and peak Hertz pressure (Pa); then the cycle's
                                       damage of contacts 1..4 (damage_1..4)
    DIR/cases/<key>/life_summary.json  per track damage (cycle rule and map), the three lives, DG03's ratio
    DIR/cases/<key>/ball_load_histogram.csv   ball, diagonal, load bin, time, rotation
    DIR/cases/<key>/result.json        status, statistics, wall time, worker (written last)
    DIR/figures/*.png                  see slewing_model.study.figures

Every JSON file is strict JSON (:func:`json_ready`): an infinite value (a life without damage) is
the string ``"inf"``, a value that does not exist (NaN) is ``null``; in ``summary.csv`` ``inf`` and
an empty cell.

A folder holding another study's results is refused (``overwrite`` clears them).
A case whose ``result.json`` exists is finished: a rerun skips it (failed cases
too, unless ``retry_failed``). A case lost to the cluster itself (e.g. a task whose
workers died more than Dask's ``allowed-failures`` times) is listed in the summary
with that error but not marked finished, so a rerun tries it again.
"""
from __future__ import annotations

import contextlib
import csv
import json
import logging
import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from .case import HISTOGRAM_COLUMNS, STATISTICS, TIMESERIES_COLUMNS, CaseResult, CaseTask, json_ready, one_line, \
    run_case
from .definition import Case, Study, StudyDefinitionError, load_study
from .series import load_series

REQUIRED_COLUMNS = ("case", "status", "friction_torque_mean", "friction_torque_max", "max_ball_load",
                    "min_static_safety_factor")
SUMMARY_COLUMNS = REQUIRED_COLUMNS + tuple(s for s in STATISTICS if s not in REQUIRED_COLUMNS) + (
    "name", "load", "blade", "bearing", "ring_model", "preload_um", "friction_coefficient", "error_seed",
    "elapsed_s", "worker")


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) during :func:`run_study`, after ``summary.csv`` was written for the cases
    finished so far (the others: status ``not finished: interrupted``; a rerun resumes them).

    Attributes
    ----------
    report : StudyReport
        What the run did up to the interruption.
    """

    def __init__(self, report: "StudyReport"):
        super().__init__("interrupted")
        self.report = report


@dataclass
class StudyReport:
    """What :func:`run_study` did.

    Attributes
    ----------
    cases : int
        Number of cases of the study.
    skipped : list of str
        Keys of the cases found finished in the output directory.
    ran : list of str
        Keys of the cases computed now (ok or failed).
    failed : dict
        Key -> status of every case that is not ``ok`` (this run or before).
    summary : str
        Path of ``summary.csv``.
    rows : list of dict
        The rows of ``summary.csv``.
    wall_time : float, s
        From the first submission to the last result (0 when nothing was submitted).
    cluster : str
        What ran it.
    figures : list of str
        The figures written.
    notes : list of str
        What the run could not do (e.g. figures without matplotlib).
    """

    cases: int
    skipped: list = field(default_factory=list)
    ran: list = field(default_factory=list)
    failed: dict = field(default_factory=dict)
    summary: str = ""
    rows: list = field(default_factory=list)
    wall_time: float = 0.0
    cluster: str = ""
    figures: list = field(default_factory=list)
    notes: list = field(default_factory=list)


#: the record of which study an output directory holds
STUDY_RECORD = "study.json"


class ForeignOutputError(ValueError):
    """The output directory holds another study's results (``overwrite`` clears them); a :class:`ValueError`."""


def foreign_study(out_dir: str, name: str, keys) -> str | None:
    """The name of the other study whose results ``out_dir`` holds, or None (empty, or study ``name``'s).

    ``study.json`` names the study that wrote the folder; a folder written before that record
    existed is another study's when none of its cases is one of ``keys`` (this study's case keys)."""
    try:
        with open(os.path.join(out_dir, STUDY_RECORD)) as fh:
            other = json.load(fh).get("name")
    except (OSError, ValueError, AttributeError):
        other = None
    if other is not None:
        return None if other == name else other
    try:
        found = set(os.listdir(os.path.join(out_dir, "cases")))
    except OSError:
        found = set()
    if found and not found & set(keys):
        return "an unnamed study"
    return None


def clear_results(out_dir: str) -> None:
    """Remove what a study run writes (nothing else of the folder)."""
    import shutil

    for name in ("cases", "figures"):
        shutil.rmtree(os.path.join(out_dir, name), ignore_errors=True)
    for name in ("summary.csv", STUDY_RECORD):
        try:
            os.remove(os.path.join(out_dir, name))
        except FileNotFoundError:
            pass


def open_output_dir(out_dir: str, record: dict, keys, overwrite: bool = False) -> None:
    """Make ``out_dir`` the folder of the study ``record["name"]`` (case keys ``keys``): refuse it when it
    holds another study's results (:func:`foreign_study`), or clear them with ``overwrite``; then create
    ``cases/`` and write ``record`` as ``study.json``.

    Raises
    ------
    ForeignOutputError
        ``out_dir`` holds another study's results and ``overwrite`` is not set.
    """
    other = foreign_study(out_dir, record["name"], keys)
    if other is not None:
        if not overwrite:
            raise ForeignOutputError(
                f"output directory {out_dir} holds the results of {other!r}, not of study {record['name']!r}: "
                f"give another directory, or --overwrite to clear them")
        clear_results(out_dir)
    os.makedirs(os.path.join(out_dir, "cases"), exist_ok=True)
    write_json(os.path.join(out_dir, STUDY_RECORD), record)


def finished_cases(out_dir: str, cases, report: "StudyReport", retry_failed: bool = False) -> tuple[dict, list]:
    """The records of the ``cases`` (each with a ``key``) finished in ``out_dir`` (key -> ``result.json``;
    their keys appended to ``report.skipped``) and the list of the others, to run (a failed case is
    finished unless ``retry_failed``)."""
    records, pending = {}, []
    for case in cases:
        record = read_result(out_dir, case.key)
        if record is not None and (record["status"] == "ok" or not retry_failed):
            records[case.key] = record
            report.skipped.append(case.key)
        else:
            pending.append(case)
    return records, pending


def case_dir(out_dir: str, key: str) -> str:
    return os.path.join(out_dir, "cases", key)


def read_result(out_dir: str, key: str) -> dict | None:
    """The ``result.json`` of a finished case, or None."""
    path = os.path.join(case_dir(out_dir, key), "result.json")
    try:
        with open(path) as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None
    return data if data.get("key") == key else None


def write_json(path: str, data) -> None:
    """Write ``data`` as strict JSON (:func:`json_ready`; ``allow_nan=False`` refuses anything left),
    atomically (a temporary file, then renamed)."""
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        json.dump(json_ready(data), fh, indent=1, sort_keys=True, allow_nan=False)
    os.replace(tmp, path)


_write_json = write_json


def write_case(out_dir: str, case: Case, result: CaseResult) -> dict:
    """Write a case's files (``result.json`` last: the mark that it is finished); return the record."""
    folder = case_dir(out_dir, case.key)
    os.makedirs(folder, exist_ok=True)
    _write_json(os.path.join(folder, "case.json"), {"key": case.key, "index": case.index, "name": case.name,
                                                    "load": case.load, "variant": case.variant,
                                                    "simulation": case.simulation, "spec": case.spec})
    if result.timeseries is not None:
        np.savetxt(os.path.join(folder, "timeseries.csv"), result.timeseries, delimiter=",", fmt="%.10g",
                   header=",".join(TIMESERIES_COLUMNS), comments="")
        write_parquet(os.path.join(folder, "timeseries.parquet"), result.timeseries, TIMESERIES_COLUMNS)
    life = result.life or {}
    if "damage_map" in life:
        write_life(folder, life)
    if result.histogram is not None:
        np.savetxt(os.path.join(folder, "ball_load_histogram.csv"), result.histogram, delimiter=",",
                   fmt=["%d", "%d", "%.6g", "%.6g", "%.10g", "%.10g"], header=",".join(HISTOGRAM_COLUMNS),
                   comments="")
    record = {"key": case.key, "name": case.name, "status": result.status, "elapsed_s": result.elapsed,
              "worker": result.worker, "statistics": result.statistics}
    if "error" in life:
        record["life_error"] = life["error"]
    _write_json(os.path.join(folder, "result.json"), record)
    return record


def write_parquet(path: str, table: np.ndarray, columns) -> bool:
    """Write ``table`` (n, len(columns)) as Parquet with pyarrow; False (nothing written) without it."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return False
    pq.write_table(pa.table({c: np.ascontiguousarray(table[:, j]) for j, c in enumerate(columns)}), path)
    return True


def write_life(folder: str, life: dict) -> None:
    """A case's raceway damage map and rainflow cycles (see the module docstring)."""
    damage = np.asarray(life["damage_map"])
    slices = damage.shape[1]
    angle = (np.arange(slices) + 0.5) * 360.0 / slices
    np.savetxt(os.path.join(folder, "raceway_damage.csv"), np.column_stack([angle, damage.T]), delimiter=",",
               fmt="%.10g", header="angle_deg,contact1,contact2,contact3,contact4", comments="")
    columns = [life["swing"], life["count"], life["travel_ratio"]]
    header = ["swing_rad", "count", "travel_ratio"]
    if "track_travel_ratio" in life:
        swing = np.asarray(life["swing"])
        for k in range(4):
            columns += [np.asarray(life["track_travel_ratio"])[:, k], swing / life["critical_angle"][k],
                        np.asarray(life["cycle_peak_pressure"])[:, k]]
            header += [f"travel_ratio_{k + 1}", f"swing_over_critical_{k + 1}", f"peak_pressure_{k + 1}_Pa"]
    if "cycle_damage" in life:
        columns += [np.asarray(life["cycle_damage"])[:, k] for k in range(4)]
        header += [f"damage_{k + 1}" for k in range(4)]
    np.savetxt(os.path.join(folder, "life_cycles.csv"), np.column_stack(columns) if len(columns[0]) else
               np.zeros((0, len(header))), delimiter=",", fmt="%.10g", header=",".join(header), comments="")
    if "summary" in life:
        write_json(os.path.join(folder, "life_summary.json"), life["summary"])


def summary_row(case: Case, record: dict | None, status: str | None = None) -> dict:
    """One row of ``summary.csv``."""
    v, load = case.variant, case.load
    row = {c: "" for c in SUMMARY_COLUMNS}
    row.update(case=case.key, name=case.name, load=load["name"], blade=load.get("blade", ""),
               bearing=os.path.basename(v["file"]), ring_model=v["ring_model"],
               preload_um="" if v["preload_um"] is None else v["preload_um"],
               friction_coefficient=v["friction_coefficient"],
               error_seed="" if v["error_seed"] is None else v["error_seed"])
    if record is not None:
        row.update(status=record["status"], elapsed_s=f"{record['elapsed_s']:.4g}", worker=record["worker"])
        for k, value in (record.get("statistics") or {}).items():
            if k in row:    # None or NaN: no value, an empty cell; "inf" (JSON's infinity) stays "inf"
                if value is None or isinstance(value, str):
                    row[k] = "" if value is None else value
                elif isinstance(value, int):
                    row[k] = value
                else:
                    row[k] = "" if math.isnan(value) else f"{value:.10g}"
    if status is not None:
        row["status"] = status
    row["status"] = " ".join(str(row["status"]).split())   # one line
    return {k: str(v) for k, v in row.items()}             # as summary.csv reads back


def write_summary(path: str, rows: list[dict], columns=SUMMARY_COLUMNS) -> None:
    """Write ``summary.csv``: ``columns`` (default :data:`SUMMARY_COLUMNS`) and ``rows``, atomically."""
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=columns)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, path)


# ---- preparation on the client ---------------------------------------------------------------

class _Prepared:
    """Load series, bearings and superelements, each read or built once."""

    def __init__(self, simulation: dict):
        self.simulation = simulation
        self._series: dict = {}
        self._bearings: dict = {}
        self._superelements: dict = {}

    @staticmethod
    def _once(cache: dict, key, make):
        if key not in cache:
            try:
                cache[key] = (make(), None)
            except Exception as exc:  # noqa: BLE001 - becomes the failure of the cases that need it
                cache[key] = (None, exc)
        value, error = cache[key]
        if error is not None:
            raise error
        return value

    def series(self, load: dict):
        return self._once(self._series, json.dumps(load, sort_keys=True), lambda: load_series(load))

    def bearing(self, path: str):
        from ..bearing.geometry import load_bearing

        return self._once(self._bearings, path, lambda: load_bearing(path))

    def superelement(self, path: str):
        def build():
            try:
                from ..rings.superelement import build_superelement
            except ImportError as exc:
                raise ValueError(f"flexible rings need the superelement builder (scipy, scikit-fem): {exc}") from None
            return build_superelement(self.bearing(path), mesh=self.simulation["mesh"], bc=self.simulation["bc"])

        return self._once(self._superelements, path, build)

    def task(self, case: Case) -> CaseTask:
        v = case.variant
        try:
            bearing = self.bearing(v["file"])
        except Exception as exc:  # noqa: BLE001
            raise ValueError(f"bearing file: {exc}") from None
        try:
            series = self.series(case.load)
        except Exception as exc:  # noqa: BLE001
            raise ValueError(f"load series: {exc}") from None
        superelement = self.superelement(v["file"]) if v["ring_model"] == "flexible" else None
        return CaseTask(case.key, bearing, superelement, series, v, case.simulation)


# ---- the run ------------------------------------------------------------------------------------

def dask_client(workers: int | None, scheduler: str | None, owned: list):
    """A Dask client and what it runs on (a description); what the caller closes afterwards is appended to
    ``owned`` as it is made (the cluster before its client), so that a Ctrl-C pressed while the
    cluster starts, delivered as this returns, leaves nothing open."""
    from distributed import Client, LocalCluster

    if scheduler:
        if workers is not None:
            raise ValueError(f"--workers {workers}: applies to the embedded cluster only, not with --scheduler")
        owned.append(Client(scheduler))
        return owned[-1], f"Dask cluster at {scheduler}"
    n = (os.cpu_count() or 1) if workers is None else workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"--workers {workers!r}: must be a whole number >= 1")
    import dask

    # Dask starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which also fixes glibc's mmap
    # threshold: every temporary of 128 KiB or more (the ring operator's) is then mapped and
    # unmapped, and its page faults made each step 1.6 times slower (measured on the pitch
    # bearing: 12.3 ms against 8.1 ms per step). None unsets it for our workers.
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}), \
            _sigint_blocked():
        # no dashboard; the scheduler's HTTP server (health and metrics routes, always started)
        # on a free port of this machine, not Dask's default 8787, which another Dask may hold:
        # "Port 8787 is already in use" at every run otherwise
        owned.append(LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                  scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                                  silence_logs=logging.ERROR))
        owned.append(Client(owned[-1]))
        owned[-1].register_plugin(_quiet_close_plugin())
    return owned[-1], f"embedded LocalCluster, {n} worker process{'es' if n > 1 else ''}"


#: what a Dask worker logs (as an error, with a traceback) when its heartbeat meets a scheduler that
#: is closing (dask/distributed issues 7105, 9032): the embedded cluster's scheduler is this run's
#: and closes at its end or on Ctrl-C, so there it is no error (seen once in a Ctrl-C test)
HEARTBEAT_AT_CLOSE = "Failed to communicate with scheduler during heartbeat"


def _not_heartbeat_at_close(record: logging.LogRecord) -> bool:
    """A logging filter: False for :data:`HEARTBEAT_AT_CLOSE`, True for every other record."""
    return not record.getMessage().startswith(HEARTBEAT_AT_CLOSE)


def _quiet_close_plugin():
    """A Dask worker plugin that adds :func:`_not_heartbeat_at_close` to each worker's
    ``distributed.worker`` logger (also a worker restarted later): for the embedded cluster only. A
    cluster at ``--scheduler`` outlives the run, and a failed heartbeat there is an error."""
    from distributed import WorkerPlugin

    class QuietClose(WorkerPlugin):
        name = "slewing-quiet-close"

        def setup(self, worker):
            logging.getLogger("distributed.worker").addFilter(_not_heartbeat_at_close)

    return QuietClose()


#: what the client's event loop logs (as an error, with a traceback) when a Ctrl-C lands in
#: ``distributed.utils.sync`` before the coroutine it runs has made its future: the cancel callback it
#: schedules then reads that future unassigned, a NameError (distributed 2026.8.0 declares it without a
#: value; dask/distributed PR 5758 had set it to None). The interrupt stops the run as it should; seen once
#: in the Ctrl-C test
SYNC_CANCEL_CALLBACK = "sync.<locals>.cancel"


def _not_sync_cancel_error(record: logging.LogRecord) -> bool:
    """A logging filter: False for the NameError of :data:`SYNC_CANCEL_CALLBACK`, True for every other record."""
    error = record.exc_info[1] if record.exc_info else None
    return not (isinstance(error, NameError) and SYNC_CANCEL_CALLBACK in record.getMessage())


#: what the embedded cluster's scheduler (in this process) logs as an error when a Ctrl-C releases the run's
#: futures while it gathers one of their results for the client: every key it names is then "forgotten" (no
#: client wants it any more), and the run stops as it should (seen once in the Ctrl-C test). A key in
#: another state is a real failure and stays logged
FORGOTTEN_GATHER = "Couldn't gather keys"


def _not_forgotten_gather(record: logging.LogRecord) -> bool:
    """A logging filter: False for :data:`FORGOTTEN_GATHER` where every key it names was forgotten, True for
    every other record."""
    if not record.getMessage().startswith(FORGOTTEN_GATHER):
        return True
    states = record.args if isinstance(record.args, dict) else (record.args or (None,))[0]   # logging unpacks a dict
    return not (isinstance(states, dict) and states and set(states.values()) == {"forgotten"})


#: the known log records of a Ctrl-C during a run, dropped while it runs: (logger, filter). tornado's
#: ``tornado.application`` is where the event loop logs a callback's exception
_RUN_LOG_FILTERS = (("tornado.application", _not_sync_cancel_error), ("distributed.scheduler", _not_forgotten_gather))


@contextlib.contextmanager
def quiet_run_logs():
    """The filters of :data:`_RUN_LOG_FILTERS` on their loggers for the length of the block: the run's Dask
    client and embedded cluster, in this process."""
    for name, drop in _RUN_LOG_FILTERS:
        logging.getLogger(name).addFilter(drop)
    try:
        yield
    finally:
        for name, drop in _RUN_LOG_FILTERS:
            logging.getLogger(name).removeFilter(drop)


@contextlib.contextmanager
def _sigint_blocked():
    """SIGINT held back (blocked, not lost) in this thread while the embedded cluster starts.

    A terminal's Ctrl-C goes to the whole process group, Dask's worker processes included, and
    each of them then dies with a traceback. A blocked signal mask is inherited by new threads
    and, through fork and exec, by new processes: the cluster's event-loop thread, started in
    here, and every worker process it spawns (also one restarted later, after a worker died)
    keep SIGINT blocked for good, so Ctrl-C reaches the parent alone, which stops the run and
    closes the cluster. A Ctrl-C pressed while the cluster starts stays pending here and is
    delivered (KeyboardInterrupt) when the block is lifted. Where the platform has no signal
    masks (Windows), nothing changes."""
    import signal
    import threading

    block = getattr(signal, "pthread_sigmask", None)
    if block is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    # multiprocessing starts its resource tracker at the first spawn, with SIGINT blocked around
    # it and then unblocked (bpo-33613): that would lift this block in the event-loop thread
    # before the workers are spawned. Started here first, it is not started again.
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    previous = block(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        block(signal.SIG_SETMASK, previous)


def run_study(study: Study | str | os.PathLike, out_dir: str | os.PathLike, *, workers: int | None = None,
              scheduler: str | None = None, client=None, progress: bool = True, retry_failed: bool = False,
              figures: bool = True, on_result=None, overwrite: bool = False) -> StudyReport:
    """Run every case of a study that is not finished in ``out_dir``.

    Parameters
    ----------
    study : Study or path
        A :class:`Study` or a study file.
    out_dir : str or path-like
        Output directory (created): ``summary.csv``, ``cases/`` (one folder per case key)
        and ``figures/``.
    workers : int, optional
        Worker processes of the embedded ``LocalCluster`` (default: one per core).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``) to submit to instead.
    client : distributed.Client, optional
        An existing client (tests); neither ``workers`` nor ``scheduler`` then.
    progress : bool, optional
        Show a progress bar over the cases. Default True.
    retry_failed : bool, optional
        Run again the cases that finished with an error. Default False.
    figures : bool, optional
        Write ``figures/*.png`` (needs matplotlib). Default True.
    on_result : callable, optional
        ``on_result(case, record, client)`` after each result is written (tests, monitoring).
    overwrite : bool, optional
        Clear the results of another study found in ``out_dir`` (``cases/``, ``figures/``,
        ``summary.csv``) instead of refusing the folder. The same study's results are always
        kept and its finished cases skipped. Default False.

    Returns
    -------
    StudyReport
        Cases skipped, run and failed, the summary's rows, wall time (s) and figures.

    Raises
    ------
    StudyInterrupted
        On Ctrl-C (SIGINT), after writing ``summary.csv`` for the cases finished so far.
    ForeignOutputError
        ``out_dir`` holds another study's results and ``overwrite`` is not set.

    Examples
    --------
    >>> from slewing_model.study import run_study
    >>> report = run_study("examples/studies/nrel5mw_pitch.toml", "results/nrel5mw_pitch",
    ...                    workers=2)                                           # doctest: +SKIP
    >>> report.failed                                                           # doctest: +SKIP
    {}
    """
    if not isinstance(study, Study):
        study = load_study(study)
    out_dir = os.fspath(out_dir)
    check_files(study)
    cases = study.cases()
    open_output_dir(out_dir, {"name": study.name, "path": study.path}, [c.key for c in cases], overwrite)
    report = StudyReport(len(cases), summary=os.path.join(out_dir, "summary.csv"))
    records, pending = finished_cases(out_dir, cases, report, retry_failed)
    lost: dict[str, str] = {}

    try:
        _run_pending(out_dir, pending, study, records, lost, report, workers, scheduler, client, progress,
                     len(cases), on_result)
    except KeyboardInterrupt:   # Ctrl-C: a valid summary of the cases finished so far, then stop
        _finish(out_dir, cases, records, {**lost, **{c.key: "not finished: interrupted" for c in pending
                                                     if c.key not in records and c.key not in lost}}, report)
        raise StudyInterrupted(report) from None
    _finish(out_dir, cases, records, lost, report)
    if figures:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            report.notes.append("no figures: matplotlib is not installed (the 'plot' extra)")
        else:
            from .figures import study_figures

            report.figures = study_figures(out_dir, cases, report.rows)
    return report


def check_files(study: Study) -> None:
    """Every file the study names, checked before anything is run or written: each bearing file
    read and validated (:func:`~slewing_model.bearing.geometry.load_bearing`), each load file
    readable. A file that fails would fail every case that uses it, each with the same message.

    Raises
    ------
    StudyDefinitionError
        Naming the study file, the key, each file and what is wrong with it (all of them).
    """
    from ..bearing.geometry import BearingDefinitionError, load_bearing

    problems = []
    for path in dict.fromkeys(v["file"] for v in study.variants):
        try:
            load_bearing(path)
        except OSError as exc:
            problems.append(f"bearings.files = {path!r}: cannot read the bearing file: {exc.strerror}")
        except BearingDefinitionError as exc:   # names the file, the key, the value and the rule
            problems.append(f"bearings.files: {exc}")
    for kind, path in dict.fromkeys((load["kind"], load["path"]) for load in study.loads if "path" in load):
        try:
            with open(path, "rb"):
                pass
        except OSError as exc:
            problems.append(f"loads.{kind} = {path!r}: cannot read the load series: {exc.strerror}")
    if len(problems) == 1:
        raise StudyDefinitionError(f"{study.path}: {problems[0]} (nothing was run or written)")
    if problems:   # one message, a line per file
        raise StudyDefinitionError(f"{study.path}: {len(problems)} files cannot be used (nothing was run or "
                                   f"written):\n  " + "\n  ".join(problems))


def _finish(out_dir: str, cases: list, records: dict, lost: dict, report: StudyReport) -> None:
    """The report's rows and failures, and ``summary.csv``."""
    report.rows = [summary_row(c, records.get(c.key), lost.get(c.key)) for c in cases]
    report.failed = {r["case"]: r["status"] for r in report.rows if r["status"] != "ok"}
    write_summary(report.summary, report.rows)


def _run_pending(out_dir, pending, study, records, lost, report, workers, scheduler, client, progress,
                 total, on_result) -> None:
    """Run the cases not finished yet, writing each result as it arrives (into ``records``)."""
    prepared = _Prepared(study.simulation)
    tasks = []
    for case in pending:
        try:
            tasks.append((case, prepared.task(case)))
        except Exception as exc:  # noqa: BLE001 - a bad file fails its cases, not the study
            records[case.key] = write_case(out_dir, case, CaseResult(case.key, one_line(exc), 0.0, "client"))
            report.ran.append(case.key)

    def done(case, result, client):
        records[case.key] = write_case(out_dir, case, result)
        if on_result is not None:
            on_result(case, records[case.key], client)

    run_on_dask(run_case, [(case, task, f"slewing-case-{case.key}") for case, task in tasks], report, lost, done,
                workers=workers, scheduler=scheduler, client=client, progress=progress, total=total,
                title=study.name)


def run_on_dask(function, tasks: list, report: StudyReport, lost: dict, on_result, *, workers: int | None = None,
                scheduler: str | None = None, client=None, progress: bool = True, total: int | None = None,
                title: str = "") -> None:
    """Run ``function(argument)`` on Dask for each ``(case, argument, task_key)`` of ``tasks``, handing each
    result as it arrives to ``on_result(case, result, client)`` (which writes it).

    The client is ``client``, or one of :func:`dask_client` (``workers``, ``scheduler``), closed at the end;
    ``report.cluster`` says which, ``report.ran`` gets each case's ``key`` and ``report.wall_time`` the time
    from the first submission to the last result. A case lost to the cluster itself goes to ``lost``
    (key -> ``"not finished: <error>"``). ``progress``: a bar titled ``title`` over ``total`` cases (default
    ``len(tasks)``), those not in ``tasks`` counted as done. A Ctrl-C (KeyboardInterrupt) passes through,
    after the client and cluster this made are closed.
    """
    if not tasks:
        return
    from distributed import as_completed

    total = len(tasks) if total is None else total
    owned = []    # what this run started, closed last made first (the client, then its cluster)
    bar = None
    with quiet_run_logs():           # a Ctrl-C's known log lines of distributed, not shown
        try:
            if client is None:
                client, report.cluster = dask_client(workers, scheduler, owned)
            else:
                report.cluster = f"given client ({len(client.scheduler_info().get('workers', {}))} workers)"
            if progress:
                from ..progress import progress_bar     # a bar on a terminal, plain lines in a file

                bar = progress_bar(total, title, "case", initial=total - len(tasks))
            by_key = {}
            start = time.perf_counter()
            futures = []
            for case, argument, task_key in tasks:
                future = client.submit(function, argument, key=task_key, pure=False)
                by_key[future.key] = case
                futures.append(future)
            for future in as_completed(futures):
                case = by_key[future.key]
                try:
                    result = future.result()
                except Exception as exc:  # noqa: BLE001 - lost to the cluster: not marked finished
                    lost[case.key] = f"not finished: {one_line(exc)}"
                else:
                    on_result(case, result, client)
                report.ran.append(case.key)
                future.release()
                if bar is not None:
                    bar.update(1)
            report.wall_time = time.perf_counter() - start
        finally:
            if bar is not None:
                bar.close()
            for thing in reversed(owned):
                thing.close()
