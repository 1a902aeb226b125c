"""The library's simulator of this tree against a git revision's, with the life accumulator on or
off: where a step's time went between two versions (the FMU layer left out).

Each version runs in a worker process of its own, importing ``slewing_model`` from its own tree
(a git worktree for the revision; before the package was regrouped the simulator was
``slewing_model.simulator``), its numba loops loaded from its tree's cache (a first process
compiles them there); both step the same case of ``benchmarks/cases.py`` (fine superelement, free
rings), in alternating blocks, so that both see the same machine load.

``--kernels numpy`` runs both versions' numpy loops instead of numba's (``friction_kernel`` and
``contact_kernel``): the arithmetic of the standalone and win64 FMUs, which carry no numba.

Run: .venv/bin/python benchmarks/bench_simulator_ab.py [--baseline REV] [--cases pitch table3_heavy]
     [--steps 300] [--runs 3] [--life off|on|both] [--kernels auto|numpy]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import print_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
WARM = 20
WORKER = r'''
import json, sys, time
tree, case_name, steps, life = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4] == "on"
sys.path.insert(0, tree)
sys.path.insert(1, sys.argv[5])                                  # this tree's benchmarks/ (the cases)
from cases import CASES
from slewing_model import Loads, load_bearing
try:
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings
    from slewing_model.rings.superelement import build_superelement
except ImportError:                                              # before the regrouping
    from slewing_model.simulator import BearingSimulator, SimulatorSettings
    from slewing_model.superelement import build_superelement
case = CASES[case_name](steps)
bearing = load_bearing(case.bearing)
options = {"life": True} if life else {}
if sys.argv[6] != "auto":
    options.update(friction_kernel=sys.argv[6], contact_kernel=sys.argv[6])
frame = "rotating" if case.parameters["load_frame"] == 2 else "fixed"
ring_model = "rigid" if case.parameters["ring_model"] == 1 else "flexible"
superelement = build_superelement(bearing, mesh="fine", progress=False) if ring_model == "flexible" else None
sim = BearingSimulator(bearing, superelement, SimulatorSettings(ring_model=ring_model, load_frame=frame, **options))
print(json.dumps({"ready": True}), flush=True)
for line in sys.stdin:
    first, count = map(int, line.split())
    times = []
    for k in range(first, first + count):
        t0 = time.perf_counter()
        sim.step(Loads(*case.loads[k]), float(case.psi[k]), float(case.omega[k]))
        times.append(time.perf_counter() - t0)
    print(json.dumps({"times": times}), flush=True)
'''


class Worker:
    def __init__(self, tree: Path, case: str, steps: int, life: str, kernels: str = "auto"):
        self.process = subprocess.Popen([sys.executable, "-c", WORKER, str(tree), case, str(steps), life,
                                         str(ROOT / "benchmarks"), kernels], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, cwd=tempfile.gettempdir())
        self._answer()

    def _answer(self) -> dict:
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"worker ended (exit {self.process.wait()})")
        return json.loads(line)

    def run(self, first: int, count: int) -> list[float]:
        self.process.stdin.write(f"{first} {count}\n")
        self.process.stdin.flush()
        return self._answer()["times"]

    def close(self):
        self.process.stdin.close()
        self.process.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", default="e6a0774", help="git revision to compare with")
    parser.add_argument("--cases", nargs="*", default=["pitch", "table3_heavy"])
    parser.add_argument("--steps", type=int, default=300, help="steps of each block")
    parser.add_argument("--runs", type=int, default=3, help="blocks per version")
    parser.add_argument("--life", choices=("off", "on", "both"), default="both",
                        help="this tree's life accumulator (the baseline runs without: it may have none)")
    parser.add_argument("--kernels", choices=("auto", "numpy"), default="auto",
                        help="numpy: both versions run their numpy loops (the standalone and win64 FMUs')")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_ab_") as tmp:
        tree = Path(tmp) / "baseline"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), args.baseline], check=True,
                       capture_output=True)
        try:
            versions = {f"{args.baseline}": (tree, "off")}
            for life in (("off", "on") if args.life == "both" else (args.life,)):
                versions[f"this tree, life {life}"] = (ROOT, life)
            rows = []
            total = WARM + args.steps * args.runs
            # a first process of each version compiles its loops into its tree's numba cache, and the timed ones
            # load them from there: a process that compiled them itself ran 3 % slower at the median and up to
            # 30 % at the slowest steps (docs/speed.md, "Issue 31, sixteenth turn")
            for t, life in versions.values():
                Worker(t, args.cases[0], total, life, args.kernels).close()
            for case in args.cases:
                workers = {v: Worker(t, case, total, life, args.kernels) for v, (t, life) in versions.items()}
                for w in workers.values():
                    w.run(0, WARM)
                times = {v: [] for v in versions}
                for r in range(args.runs):
                    for v, w in workers.items():
                        times[v] += w.run(WARM + r * args.steps, args.steps)
                base = float(np.median(times[args.baseline]))
                for v, w in workers.items():
                    w.close()
                    t = np.array(times[v]) * 1e3
                    rows.append([case, v, f"{np.median(t):.3f}", f"{np.percentile(t, 99):.2f}", f"{t.max():.1f}",
                                 f"{np.median(t) / (base * 1e3):.2f}"])
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], capture_output=True)
    loops = "numpy's loops" if args.kernels == "numpy" else "numba's loops"
    print_table(f"The library's simulator step (ms, {loops}), {args.runs} alternating blocks of {args.steps} steps",
                ["case", "version", "median", "99th pct", "max", "median / baseline's"], rows)


if __name__ == "__main__":
    main()
