"""Wall time of each example script.

Runs every example in a fresh process (``.venv/bin/python examples/NAME.py``), ``--runs``
times each, one after the other, and prints a markdown table: the median and the range of
the runs, in seconds. The first run of a script after the sources change includes Python's
and numba's compilation and any superelement build not yet in the cache; run it once before
measuring (``--warm-up``, on by default).

Run from the repository root::

    .venv/bin/python examples/timings.py [--runs 3] [--only friction_study load_cases]
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: the examples, with what each does
EXAMPLES = {
    "pitch_manoeuvre": "pitch step with the bearing in the loop (`make demo`)",
    "yaw_manoeuvre": "8 deg yaw move, 6 motors, yaw bearing 3.6 m",
    "load_distribution_study": "paper Figs 6, 8-11",
    "friction_study": "paper Fig. 14, torque over one turn, 4 -> 2 contacts",
    "load_cases": "load distributions of the paper's bearings",
}


def run_once(name: str) -> float:
    """Wall time of one run of ``examples/NAME.py``, s (its output discarded; a failure stops)."""
    start = time.perf_counter()
    done = subprocess.run([sys.executable, str(ROOT / "examples" / f"{name}.py")], cwd=ROOT,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"examples/{name}.py failed (rc {done.returncode}):\n{done.stderr[-2000:]}")
    return elapsed


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="timed runs of each example")
    parser.add_argument("--only", nargs="+", choices=list(EXAMPLES), default=list(EXAMPLES), help="examples to time")
    parser.add_argument("--no-warm-up", action="store_true", help="do not run each example once before timing it")
    args = parser.parse_args(argv)
    print("| example (each writes `results/`) | what | median [s] | runs [s] |")
    print("|---|---|---|---|")
    for name in args.only:
        if not args.no_warm_up:
            run_once(name)
        times = [run_once(name) for _ in range(args.runs)]
        print(f"| `examples/{name}.py` | {EXAMPLES[name]} | {statistics.median(times):.1f} | "
              f"{' / '.join(f'{t:.1f}' for t in times)} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
