"""The same FMU on Linux and on win64 under wine: size of each half, instantiation, doStep.

Two builds of the pitch bearing FMU (150 balls, fine superelement, free rings, FMI 2.0), each carrying
both binaries (fmu_build/win64.py): the default (both halves run the loops compiled ahead of time),
``--numba`` (the Linux half with numba; the win64 half runs numpy's loops) and ``--no-numba`` (both halves
run numpy's loops). Each FMU
is unpacked once and run by our C host (``tests/c_host/host.c``, scenario ``bench``): the Linux build with
``PATH=/usr/bin:/bin``, the mingw build under wine 8 (``WINEDEBUG=-all``); a fresh process per run, the
Linux and the wine runs alternating so that both see the same machine load. A run is the pitch case of
``cases.py`` (the shipped blade-root series, pitching +-5 deg at 0.5 rad/s, flexible rings, friction on,
10 ms steps); a step is set the 7 inputs, ``fmi2DoStep``, get 5 outputs; the first ``WARM`` steps are left
out. Wine is not Windows: its timings say what the win64 half costs under wine on this machine, not on a
Windows desktop.

``--win64-numba``: a third build, the default with ``--win64-numba`` (its win64 half runs numba's loops,
compiled under wine at build time).

``--baseline VERSION``: instead of the builds, this tree's ``--no-numba`` FMU against that released
version's (built by its own build_fmu.py from a git worktree), both halves of each, alternating: what a change did to numpy's
loops, the win64 half's. ``--busy N``: N processes that only spin run beside the timed runs (and end with
them), as a user's pitch system shares the cores with its other FMUs.

Run (root, with wine and mingw-w64: ``make`` installs them):
    .venv/bin/python -m benchmarks win64 [--steps 1000] [--runs 3] [--win64-numba] [--baseline VERSION] [--busy 2]
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from .cases import CASES
from .fmu_variants import bench_output, compile_host  # our C host for Linux and its output
from .suite import ROOT, build_baseline, build_fmu_module, note, print_table, record, spread

if str(ROOT / "tests") not in sys.path:
    sys.path.append(str(ROOT / "tests"))
import win64_tools as w  # noqa: E402  (wine, mingw and the paths wine takes: tests/win64_tools.py)

RUNS = 3
#: no baseline unless --baseline names one (then the --no-numba FMUs of this tree and of that version)
BASELINE = None
INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
OUTPUTS = ("z", "rx", "ry", "friction_torque", "max_ball_load")
VARIANTS = {"default (loops compiled ahead of time)": {}, "--numba (numba on Linux)": {"numba": True},
            "--no-numba": {"numba": False}}
WARM = 20


def run_host(platform: str, host: Path, folder: Path, refs: dict, inputs: Path, parameters: dict):
    """One run of the C host: (instantiation s, step times s, final outputs); the resident set that
    :func:`benchmarks.fmu_variants.bench_output` also reads is left out (wine's is not the FMU's)."""
    integers = sum((["--integer", str(refs[k]), str(v)] for k, v in parameters.items()), [])
    if platform == "linux":
        arguments = [str(folder), "SlewingBearing", refs["guid"], "bench", *(str(refs[n]) for n in INPUTS + OUTPUTS),
                     "--inputs", str(inputs), *integers]
        out = subprocess.run([str(host), *arguments], env={"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root")},
                             capture_output=True, text=True, timeout=3600)
    else:
        arguments = [w.windows_path(folder), "SlewingBearing", refs["guid"], "bench",
                     *(str(refs[n]) for n in INPUTS + OUTPUTS), "--inputs", w.windows_path(inputs), *integers]
        out = w.wine(host, *arguments, timeout=3600)
    if out.returncode != 0 or "done" not in out.stdout:
        raise RuntimeError(f"the {platform} C host failed on {folder}:\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}")
    return bench_output(out.stdout)[:3]


def sizes(fmu: Path) -> dict:
    """Bytes per half of the FMU: zipped (compressed entries) and unpacked."""
    out = {"linux": [0, 0], "win64": [0, 0], "shared": [0, 0]}
    with zipfile.ZipFile(fmu) as z:
        for info in z.infolist():
            half = ("linux" if info.filename.startswith("binaries/linux64/") else
                    "win64" if info.filename.startswith("binaries/win64/") else "shared")
            out[half][0] += info.compress_size
            out[half][1] += info.file_size
    return out


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--busy", type=int, default=0, help="processes that spin beside the timed runs")
    parser.add_argument("--win64-numba", action="store_true", help="also the default FMU built with --win64-numba")


def main(args) -> None:
    if args.steps < WARM + 1 or args.busy < 0:
        sys.exit(f"--steps must be > {WARM}, --busy >= 0")
    if args.baseline_commit and args.win64_numba:
        sys.exit("--baseline compares the --no-numba FMUs: not with --win64-numba")
    if w.missing_tools():
        sys.exit(w.missing_tools())
    from fmpy import read_model_description

    build_fmu = build_fmu_module().build_fmu

    case = CASES["pitch"](args.steps)
    with tempfile.TemporaryDirectory(prefix="bench_win64_") as tmp:
        tmp = Path(tmp)
        hosts = {"linux": compile_host(tmp), "win64": w.mingw(tmp / "host.exe", [ROOT / "tests/c_host/host.c"], "-O2")}
        inputs = tmp / "inputs.txt"
        np.savetxt(inputs, np.column_stack([case.loads, case.psi, case.omega]), fmt="%.17g")
        built, size_rows = {}, []
        variants = dict(VARIANTS)
        if args.win64_numba:
            variants["--win64-numba (numba on both)"] = {"numba": True, "win64_numba": True}
        if args.baseline_commit:
            variants = {"--no-numba, this tree": {"numba": False}, f"--no-numba, version {args.baseline}": None}
            baseline_fmu = build_baseline(args.baseline_commit, tmp, ("pitch_bearing",), options=("--no-numba",))
        for index, (name, variant) in enumerate(variants.items()):
            fmu = tmp / f"pitch_{index}.fmu"             # (one folder each: unpacked below)
            if variant is None:
                baseline_fmu["pitch_bearing"].rename(fmu)
            else:
                build_fmu(ROOT / "examples/bearings/pitch_bearing.toml", fmu, **variant)
            folder = tmp / fmu.stem
            with zipfile.ZipFile(fmu) as z:
                z.extractall(folder)
            md = read_model_description(str(fmu))
            refs = {v.name: v.valueReference for v in md.modelVariables}
            refs["guid"] = md.guid
            built[name] = (folder, refs)
            s = sizes(fmu)
            size_rows.append([name, f"{fmu.stat().st_size / 1e6:.1f} MB",
                              f"{s['linux'][0] / 1e6:.1f} MB / {s['linux'][1] / 1e6:.0f} MB",
                              f"{s['win64'][0] / 1e6:.1f} MB / {s['win64'][1] / 1e6:.0f} MB",
                              f"{s['shared'][0] / 1e6:.1f} MB / {s['shared'][1] / 1e6:.0f} MB",
                              f"{(s['shared'][0] + s['linux'][0]) / 1e6:.1f} MB"])
        times = {(n, p): [] for n in variants for p in hosts}
        starts = {(n, p): [] for n in variants for p in hosts}
        finals = {}
        busy = [subprocess.Popen([sys.executable, "-c", "import time\nend = time.time() + 3600\n"
                                  "while time.time() < end: pass"]) for _ in range(args.busy)]
        try:
            for _ in range(args.runs):
                for name in variants:
                    for platform, host in hosts.items():          # interleaved: Linux, wine, Linux, wine...
                        folder, refs = built[name]
                        instantiation, steps, final = run_host(platform, host, folder, refs, inputs, case.parameters)
                        starts[name, platform].append(instantiation)
                        times[name, platform].append(steps[WARM:])
                        finals[name, platform] = final
        finally:
            for process in busy:
                process.kill()
                process.wait()
    note(f"pitch case: {case.description}; {args.steps} steps of 10 ms, {args.runs} runs per FMU and platform, "
          "our C host (Linux: PATH=/usr/bin:/bin; win64: mingw build under wine 8)"
          + (f"; {args.busy} spinning processes beside the runs" if args.busy else ""))
    print_table("The FMU's halves: zipped / unpacked", ["FMU", "zipped", "Linux half", "win64 half",
                                                       "model files", "zipped without win64"], size_rows)
    rows = []
    reference = list(variants)[-1] if args.baseline_commit else list(variants)[0]      # the ratios' baseline
    for name in variants:
        for platform in hosts:
            s = spread(np.concatenate(times[name, platform]) * 1e3)
            record(f"{name} {platform} [ms]", s)
            against = s["median"] / np.median(np.concatenate(times[reference, platform]) * 1e3)
            variant = variants[name] or {}
            numba = variant.get("win64_numba" if platform == "win64" else "numba")
            loops = "numba" if numba else "numpy" if numba is False or platform == "win64" and "numba" in variant \
                else "ahead of time"
            rows.append([name, "Linux" if platform == "linux" else "win64 under wine", loops,
                         f"{np.median(starts[name, platform]):.2f} s", f"{s['median']:.2f} ms",
                         f"{s['p95']:.2f} ms", f"{s['p99']:.2f} ms", f"{against:.2f}"])
    print_table("doStep in the C host (set inputs, doStep, get outputs)",
                ["FMU", "platform", "loops", "instantiation", "median", "95th pct", "99th pct",
                 f"median / {reference}'s on that platform"], rows)
    for name in variants:
        a, b = np.array(finals[name, "linux"]), np.array(finals[name, "win64"])
        note(f"{name}: final outputs, win64 under wine against Linux: largest relative difference "
              f"{np.max(np.abs(a - b) / np.maximum(np.abs(a), 1e-300)):.1e}")

