"""``slewing batch STUDY.toml -o DIR [--workers N] [--scheduler ADDRESS]``: run a study."""
from __future__ import annotations

import sys


def add_arguments(p) -> None:
    p.add_argument("study", help="study file (TOML): load series x bearing variants")
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output directory: summary.csv, cases/<key>/, figures/ (finished cases are skipped)")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="worker processes of the embedded Dask LocalCluster (not given: one per core)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="submit to an existing Dask cluster (e.g. tcp://host:8786) instead")
    p.add_argument("--retry-failed", action="store_true", help="run again the cases that finished with an error")
    p.add_argument("--no-figures", action="store_true", help="do not write figures/*.png")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--overwrite", action="store_true",
                   help="clear the results of another study found in the output directory (refused otherwise; "
                        "the same study's finished cases are always kept)")


def run(args) -> int:
    from .engine import run_study

    return report_run("slewing batch", args.study, lambda: run_study(
        args.study, args.output, workers=args.workers, scheduler=args.scheduler, progress=not args.quiet,
        retry_failed=args.retry_failed, figures=not args.no_figures, overwrite=args.overwrite))


def report_run(command: str, study_path, run, after_summary=None) -> int:
    """Run a study (``run()``: a :class:`~slewing_model.study.StudyReport`) and report it on the terminal; the
    command's exit status.

    A Ctrl-C (:class:`~slewing_model.study.StudyInterrupted`): one line on stderr, ``"<command>: interrupted;
    ..."``, and 130 (the status of a command ended by SIGINT). Otherwise the count line on stdout, then
    ``after_summary(report)`` (if given), the notes and each failure with its case and ``study_path`` on
    stderr; 0 when no case failed, 1 otherwise.
    """
    from .engine import StudyInterrupted

    try:
        report = run()
    except StudyInterrupted as stop:   # Ctrl-C: one line, the status of a command ended by SIGINT
        r = stop.report
        finished = sum(1 for row in r.rows if not row["status"].startswith("not finished"))
        print(f"\n{command}: interrupted; {finished} of {r.cases} cases finished, summary: {r.summary} "
              f"(the same command resumes)", file=sys.stderr)
        return 130
    ok = report.cases - len(report.failed)
    print(f"{report.cases} cases: {ok} ok, {len(report.failed)} failed; {len(report.ran)} run now "
          f"({report.wall_time:.1f} s{', ' + report.cluster if report.cluster else ''}), "
          f"{len(report.skipped)} already finished. Summary: {report.summary}")
    if after_summary is not None:
        after_summary(report)
    for note in report.notes:
        print(f"note: {note}", file=sys.stderr)
    names = {row["case"]: row["name"] for row in report.rows}
    for key, status in report.failed.items():   # each failure with its case and the study file
        print(f"  {study_path}: case {key} ({names.get(key, '?')}): {status}", file=sys.stderr)
    return 0 if not report.failed else 1
