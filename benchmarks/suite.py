"""The benchmark suite's common code: the runner, the tables and their JSON, the baseline version.

Run: .venv/bin/python -m benchmarks [NAME ...] [--baseline VERSION|none] [--runs N] [--output DIR]
     [the benchmarks' own options]

NAME is a benchmark (--list lists them with a line each, NAME --help gives its own options) or
"main", the main set (what runs without a name, and what make bench runs). Each benchmark prints its
tables (medians and tails of several runs, ratios to a baseline measured in the same run) and writes
them, with the machine, the versions and the date, to results/bench/NAME.json (--output DIR).

A baseline is a released version of this package (--baseline 1.0.0): its commit is the git tag
vVERSION or VERSION, else the newest commit whose pyproject.toml has version = "VERSION"; a git
commit-ish is taken too (--baseline HEAD~3), for comparing with a commit that is no release.
The baseline's FMUs are built in the same run from a git worktree of that commit by its own
build_fmu.py, and stepped alternately with this tree's, so that both see the same machine load.

This module imports neither ``slewing_model`` nor numba: the FMU workers (``benchmarks.fmu``) import
it, and an FMU's host process must not import the package the FMU brings.
"""
from __future__ import annotations

import argparse
import ast
import contextlib
import datetime
import importlib
import json
import os
import platform
import re
import subprocess
import sys
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(__file__).resolve().parent
RESULTS = ROOT / "results" / "bench"

#: benchmark name -> module of this package (``operator`` is not a module name: it is the standard library's)
BENCHMARKS = {
    "rigid": "rigid", "superelement": "superelement", "flexible": "flexible", "operator": "ring_operator",
    "friction": "friction", "fmu": "fmu", "batch": "batch", "realtime": "realtime", "flagged": "flagged",
    "fmu_variants": "fmu_variants", "win64": "win64", "fmi3": "fmi3", "life": "life", "connected": "connected",
    "step_parts": "step_parts", "slowest": "slowest", "machine_noise": "machine_noise", "turbine": "turbine",
}
#: the main set: what ``make bench`` runs (the figures of docs/performance.md; several minutes)
MAIN = ("rigid", "superelement", "flexible", "operator", "friction", "fmu", "batch", "realtime", "flagged")
#: the baseline of the benchmarks that measure one (``fmu``, ``realtime``) unless ``--baseline`` is given
DEFAULT_BASELINE = "1.0.0"


# ---- tables, notes and the JSON of a run ---------------------------------------------------------

class Report:
    """What one benchmark printed: its tables and notes, and any figures it adds to :attr:`data`."""

    def __init__(self, name: str):
        self.name = name
        self.started = datetime.datetime.now(datetime.timezone.utc)
        self.versions = versions()                  # at the start: the tree measured
        self.tables: list[dict] = []
        self.notes: list[str] = []
        self.data: dict = {}


_report: Report | None = None


def print_table(title: str, header: list[str], rows: list[list[str]]) -> None:
    """Print a table (Markdown) and keep it, with its cells' numbers, for the run's JSON."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)] if rows else \
        [len(h) for h in header]
    print(f"\n{title}")
    print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for r in rows:
        print("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |")
    sys.stdout.flush()
    if _report is not None:
        _report.tables.append({"title": title, "header": list(header),
                               "rows": [{h: parse_cell(c) for h, c in zip(header, r)} for r in rows]})


def note(text: str) -> None:
    """Print a line of the benchmark's results (not a table) and keep it for the run's JSON."""
    print(text, flush=True)
    if _report is not None:
        _report.notes.append(text)


def record(key: str, value) -> None:
    """Keep a figure (numbers, lists, dicts of them) in the run's JSON under ``data``."""
    if _report is not None:
        _report.data[key] = value


_NUMBER = re.compile(r"^([-+]?(?:\d[\d,]*\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(?:\s*([^\d\s()/][^\s()]*))?$")


def parse_cell(cell: str):
    """A table cell as JSON: a number (``"1.25"``), a number and its unit (``"3.1 ms"``:
    ``{"value": 3.1, "unit": "ms"}``), else the text as printed."""
    match = _NUMBER.match(cell.strip())
    if not match:
        return cell
    try:
        value = float(match.group(1).replace(",", ""))
    except ValueError:
        return cell
    return value if match.group(2) is None else {"value": value, "unit": match.group(2)}


def spread(values) -> dict:
    """Median and tail of ``values`` (e.g. step times): ``median``, ``p95``, ``p99``, ``max``."""
    import numpy as np

    values = np.asarray(values, dtype=float)
    return {"median": float(np.median(values)), "p95": float(np.percentile(values, 95)),
            "p99": float(np.percentile(values, 99)), "max": float(values.max())}


def median_time(func, repeat: int = 7, number: int = 1) -> float:
    """Median wall time of ``func()`` over ``repeat`` runs of ``number`` calls, seconds per call."""
    import statistics
    import time

    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            func()
        times.append((time.perf_counter() - start) / number)
    return statistics.median(times)


def machine() -> dict:
    """The CPU model, its cores (all and this process's) and the system."""
    model = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    cores = os.cpu_count()
    with contextlib.suppress(AttributeError):
        cores = len(os.sched_getaffinity(0))
    return {"cpu": model, "cores": cores, "cpus_on_machine": os.cpu_count(), "system": platform.platform(),
            "machine": platform.machine(), "hostname": platform.node()}


def package_version(tree: Path = ROOT) -> str | None:
    """The ``version`` of ``tree``'s ``pyproject.toml``."""
    try:
        return _project_version((tree / "pyproject.toml").read_text())
    except OSError:
        return None


def _project_version(text: str) -> str | None:
    try:
        import tomllib
    except ImportError:             # Python < 3.11
        import tomli as tomllib
    try:
        return tomllib.loads(text).get("project", {}).get("version")
    except tomllib.TOMLDecodeError:
        return None


def _git(*args: str, check: bool = True) -> str:
    out = subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True)
    if check and out.returncode != 0:
        raise RuntimeError(f"git {' '.join(args)}: {out.stderr.strip()}")
    return out.stdout.strip() if out.returncode == 0 else ""


def versions() -> dict:
    """This tree's package version and commit (``dirty``: files changed since), Python's and the libraries'."""
    from importlib import metadata

    found = {"slewing_model": package_version(), "commit": _git("rev-parse", "HEAD", check=False) or None,
             "dirty": bool(_git("status", "--porcelain", "--untracked-files=no", check=False)),
             "python": platform.python_version()}
    for name in ("numpy", "scipy", "numba", "fmpy", "dask"):
        with contextlib.suppress(metadata.PackageNotFoundError):
            found[name] = metadata.version(name)
    return found


def write_json(report: Report, args: argparse.Namespace, folder: Path) -> Path:
    """``folder/NAME.json``: the report's tables, notes and data, the options, machine, versions and date."""
    baseline = None
    if getattr(args, "baseline_commit", None):
        baseline = {"version": args.baseline, "commit": args.baseline_commit}
    options = {k: v for k, v in vars(args).items() if k not in ("baseline_commit",)}
    seconds = (datetime.datetime.now(datetime.timezone.utc) - report.started).total_seconds()
    document = {"benchmark": report.name, "description": describe(report.name),
                "date": report.started.isoformat(timespec="seconds"), "seconds": round(seconds, 1),
                "machine": machine(), "versions": report.versions, "baseline": baseline, "options": options,
                "tables": report.tables, "notes": report.notes, "data": report.data}
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{report.name}.json"
    path.write_text(json.dumps(document, indent=1, default=str) + "\n")
    return path


# ---- the baseline: a released version, its commit, its FMUs ---------------------------------------

def resolve_baseline(version: str) -> str:
    """The commit (full hash) of the released ``version`` of this package.

    The git tag ``vVERSION`` or ``VERSION`` where one exists; else the newest commit whose
    ``pyproject.toml`` has ``version = "VERSION"`` (the newest such commit is ``HEAD`` or the parent of a
    commit that changed the version line: ``git log -G'^version = '``); else, for a baseline that is no
    release, ``version`` read as a git commit-ish (``HEAD~2``, a hash). Raises ``ValueError`` if none."""
    for tag in (f"v{version}", version):
        commit = _git("rev-parse", "--verify", "--quiet", f"refs/tags/{tag}^{{commit}}", check=False)
        if commit:
            return commit
    if _project_version(_git("show", "HEAD:pyproject.toml", check=False)) == version:
        return _git("rev-parse", "HEAD")
    changes = _git("log", "--first-parent", "--format=%H", "-G", r"^version = ", "--", "pyproject.toml",
                   check=False).split()
    for change in changes:                     # newest first: the version before each change
        before = _git("show", f"{change}^:pyproject.toml", check=False)
        if before and _project_version(before) == version:
            return _git("rev-parse", f"{change}^")
    commit = _git("rev-parse", "--verify", "--quiet", f"{version}^{{commit}}", check=False)
    if commit:
        return commit
    raise ValueError(f"baseline {version!r}: no tag v{version} or {version}, no commit whose pyproject.toml has "
                     f'version = "{version}", and not a git commit')


@contextlib.contextmanager
def baseline_tree(commit: str, folder: Path):
    """A git worktree of ``commit`` at ``folder/baseline_tree``, removed afterwards."""
    tree = Path(folder) / "baseline_tree"
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), commit], check=True,
                   capture_output=True)
    try:
        yield tree
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], capture_output=True)


def build_baseline(commit: str, out: Path, bearings, options=()) -> dict[str, Path]:
    """The FMUs of ``commit`` (one per bearing of examples/bearings, by stem), each built by that commit's own
    ``build_fmu.py`` run as a script in a worktree (with its command-line ``options``, e.g. ``("--no-numba",)``):
    the entry point of every version, whatever modules it builds with."""
    with baseline_tree(commit, out) as tree:
        fmus = {}
        for name in bearings:
            fmus[name] = Path(out) / f"baseline_{name}.fmu"
            subprocess.run([sys.executable, "build_fmu.py", f"examples/bearings/{name}.toml", "-o", str(fmus[name]),
                            *options], cwd=tree, check=True, capture_output=True)
        return fmus


def build_fmu_module():
    """This tree's ``build_fmu`` module (the FMU's build entry point, at the repository's root)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    import build_fmu

    return build_fmu


def worker_command(module: str, *args: str) -> list[str]:
    """The command of a worker process running ``benchmarks.<module>.worker_main(args)``: the repository is
    appended to ``sys.path`` (not put first: an FMU's own ``slewing_model`` must win) and the working folder
    left out of it."""
    code = ("import os, sys\n"
            "sys.path[:] = [p for p in sys.path if p not in ('', os.getcwd())]\n"
            f"sys.path.append({str(ROOT)!r})\n"
            f"from benchmarks.{module} import worker_main\n"
            "worker_main(sys.argv[1:])\n")
    return [sys.executable, "-c", code, *args]


# ---- the runner -----------------------------------------------------------------------------------

def describe(name: str) -> str:
    """The first paragraph of the benchmark's module docstring, on one line (read without importing it)."""
    path = HERE / f"{BENCHMARKS[name]}.py"
    doc = ast.get_docstring(ast.parse(path.read_text())) or ""
    return " ".join(doc.split("\n\n")[0].split())


def _module(name: str):
    return importlib.import_module(f"benchmarks.{BENCHMARKS[name]}")


def _parser(name: str | None, module=None) -> argparse.ArgumentParser:
    if name is None:
        parser = argparse.ArgumentParser(
            prog="python -m benchmarks", formatter_class=argparse.RawDescriptionHelpFormatter,
            description=__doc__.split("\n\n", 1)[1].split("\nThis module")[0],
            epilog="benchmarks (main set marked *):\n" + "\n".join(
                f"  {n:<14}{'*' if n in MAIN else ' '} {describe(n)[:100]}" for n in BENCHMARKS)
            + "\n\n'python -m benchmarks NAME --help' gives a benchmark's own options.")
        parser.add_argument("names", nargs="*", metavar="NAME", help="benchmarks to run, or 'main' (the default)")
        parser.add_argument("--list", action="store_true", help="list the benchmarks with a line each")
    else:
        parser = argparse.ArgumentParser(prog=f"python -m benchmarks {name}", description=module.__doc__,
                                         formatter_class=argparse.RawDescriptionHelpFormatter)
    common = parser.add_argument_group("common options")
    runs = getattr(module, "RUNS", None) if module else None
    common.add_argument("--runs", type=int, default=None,
                        help="repeated runs (their median and tail are tabulated)"
                             + (f"; default {runs}" if runs else ""))
    if module is None or hasattr(module, "BASELINE"):
        default = getattr(module, "BASELINE", DEFAULT_BASELINE) if module else DEFAULT_BASELINE
        common.add_argument("--baseline", default=None, metavar="VERSION",
                            help="released version of this package measured in the same run (its git tag or the "
                                 "newest commit with that version in pyproject.toml), a git commit-ish, or 'none'; "
                                 f"default {default or 'none'}")
    else:
        common.add_argument("--baseline", default=None, metavar="VERSION", help="(this benchmark measures none)")
    common.add_argument("--output", type=Path, default=RESULTS, help=f"folder of the JSON results (default {RESULTS})")
    if module is not None and hasattr(module, "add_arguments"):
        module.add_arguments(parser)
    return parser


def _options(parser: argparse.ArgumentParser) -> set[str]:
    return {s for action in parser._actions for s in action.option_strings}


def main(argv: list[str] | None = None) -> int:
    """``python -m benchmarks``: run the named benchmarks (the main set without a name) one after the other."""
    argv = list(sys.argv[1:] if argv is None else argv)
    split = next((i for i, a in enumerate(argv) if a.startswith("-")), len(argv))
    names, options = argv[:split], []      # the names first; a name after the options is taken too
    for a in argv[split:]:
        (names if a in BENCHMARKS or a == "main" else options).append(a)
    if "--list" in options:
        for n in BENCHMARKS:
            print(f"{n:<14}{'*' if n in MAIN else ' '} {describe(n)}")
        print("\n* the main set: 'python -m benchmarks' or 'python -m benchmarks main' (make bench)")
        return 0
    unknown = [n for n in names if n not in BENCHMARKS and n != "main"]
    if unknown or (not names and {"-h", "--help"} & set(options)):
        parser = _parser(None)
        if unknown:
            parser.error(f"unknown benchmark {', '.join(unknown)} (--list lists them)")
        parser.print_help()
        return 0
    names = list(dict.fromkeys(n for name in (names or ["main"]) for n in (MAIN if name == "main" else [name])))
    modules = {n: _module(n) for n in names}
    parsers = {n: _parser(n, modules[n]) for n in names}
    if {"-h", "--help"} & set(options):
        for n in names:
            parsers[n].print_help()
            print()
        return 0
    known = set().union(*map(_options, parsers.values()))
    stray = [o.split("=")[0] for o in options if o.startswith("-") and o.split("=")[0] not in known]
    if stray:
        parsers[names[0]].error(f"option {', '.join(stray)} is not one of {', '.join(names)}'s")

    parsed, resolved = {}, {}
    for n in names:
        args, _ = parsers[n].parse_known_args(options)
        if args.runs is not None and args.runs < 1:
            parsers[n].error("--runs must be at least 1")
        if args.runs is None:
            args.runs = getattr(modules[n], "RUNS", None)
        elif not hasattr(modules[n], "RUNS"):
            print(f"note: {n} takes no --runs (ignored)", file=sys.stderr)
        if not hasattr(modules[n], "BASELINE"):
            if args.baseline is not None:
                print(f"note: {n} measures no baseline: --baseline ignored", file=sys.stderr)
            args.baseline = args.baseline_commit = None
        else:
            if args.baseline is None:
                args.baseline = getattr(modules[n], "BASELINE", None)
            if args.baseline in (None, "none"):
                args.baseline, args.baseline_commit = None, None
            else:
                if args.baseline not in resolved:
                    try:
                        resolved[args.baseline] = resolve_baseline(args.baseline)
                    except (ValueError, RuntimeError) as error:
                        parsers[n].error(str(error))
                args.baseline_commit = resolved[args.baseline]
        parsed[n] = args
    for version, commit in resolved.items():
        print(f"baseline {version}: commit {commit[:12]}", flush=True)

    global _report
    failed = []
    for n in names:
        print(f"\n=== {n}: {describe(n)}", flush=True)
        _report = Report(n)
        try:
            modules[n].main(parsed[n])
        except (Exception, SystemExit) as error:        # a benchmark that fails does not stop the others
            if isinstance(error, SystemExit) and error.code in (None, 0):
                pass
            else:
                traceback.print_exc()
                failed.append(n)
                continue
        finally:
            report, _report = _report, None
        print(f"\n{n}: {write_json(report, parsed[n], parsed[n].output)}", flush=True)
    if failed:
        print(f"\nfailed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0

