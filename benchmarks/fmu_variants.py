"""The standalone FMU against the host FMU: zipped size, build time, instantiation, doStep.

Four builds of the pitch bearing FMU (150 balls, fine superelement, free rings, FMI 2.0),
all made in this run by this checkout's ``build_fmu.py``:

- ``host + numba``: ``--runtime host``, the FMU without a runtime of its own: it runs in this
  machine's Python and venv, with numba and its shipped cache. The baseline.
- ``standalone + aot``: the default (``--aot``); it carries its Python, numpy and the loops compiled ahead
  of time (``fmu_build/aot.py``), a module for an x86-64-v3 CPU and one for any x86-64, and takes the first
  this CPU runs: its cold build includes their compilation (the modules' cache emptied);
- ``standalone + aot, generic``: the same FMU without its x86-64-v3 module (removed from the unpacked
  folder), as a CPU without AVX2 or FMA runs it: the generic loops;
- ``standalone + numba``: ``--numba``; it carries numba and llvmlite instead, and the compiled loops' cache;
- ``standalone``: ``--no-numba``; it carries its Python and numpy, and runs the numpy loops.

Each FMU is run by our C host (``tests/c_host/host.c``, scenario ``bench``) in the environment of
a desktop session (``PATH=/usr/bin:/bin``, nothing else), as a user's C host would run it: a fresh
process per run, the variants' runs alternating so that all see the same machine load. A run is
the pitch case of ``cases.py``: the shipped blade-root series (1P-3P and turbulence) with the blade
pitching +-5 deg at 0.5 rad/s, flexible rings, friction on, 10 ms steps. A step is what a host does
each communication step: set the 7 inputs, ``fmi2DoStep``, get 5 outputs. The first ``WARM`` steps
(cold start of the solvers) are left out of the percentiles.

Build time: with the runtime staged anew (its cache emptied) and with the runtime cached; the
superelement is cached in both (built before the timing). Instantiation: loading the binary,
``fmi2Instantiate``, the parameters and initialisation, in the C host. Memory: the C host's resident set
(VmRSS) after the initialisation less before loading the FMU's binary.

``--pair``: the default and the ``--numba`` FMU only, with their builds cached (no cold build), the
``--numba`` FMU the baseline: the two alternating, as the instantiation and step goals compare them, and
the ``--numba`` FMU a second time (``standalone + numba, again``: the same unpacked folder, run as a third
variant): its ratio to the first is the run's noise floor, what a ratio of two identical FMUs scatters by.

Run: .venv/bin/python -m benchmarks fmu_variants [--steps 1000] [--runs 3] [--pair]
"""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from .cases import CASES
from .suite import ROOT, build_fmu_module, note, print_table, record, spread

RUNS = 3
INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
OUTPUTS = ("z", "rx", "ry", "friction_torque", "max_ball_load")
VARIANTS = {"host + numba": {"runtime": "host", "numba": True},
            "standalone + aot (default)": {"runtime": "standalone", "numba": False, "aot": True},
            "standalone + aot, generic": {"runtime": "standalone", "numba": False, "aot": True},
            "standalone + numba": {"runtime": "standalone", "numba": True},
            "standalone": {"runtime": "standalone", "numba": False}}
#: a variant's modules removed from its unpacked folder after the build
DROPPED = {"standalone + aot, generic": "resources/slewing_kernels_v3.*"}
REFERENCE = "host + numba"
WARM = 20


def compile_host(folder: Path) -> Path:
    binary = folder / "host"
    subprocess.run(["cc", "-O2", "-include", str(ROOT / "fmu_src/shim/glibc_compat.h"), "-nostartfiles", "-o",
                    str(binary), str(ROOT / "tests/c_host/start.c"), str(ROOT / "tests/c_host/host.c"),
                    "-Wl,--no-as-needed", "-l:libdl.so.2", "-lm"], check=True)
    return binary


def build(variant: dict, output: Path, cold: bool) -> float:
    """Build the pitch FMU of ``variant``; seconds. ``cold``: the runtime staged anew."""
    build_fmu = build_fmu_module()
    from fmu_build import runtime as build_runtime

    if cold and variant["runtime"] == "standalone":
        key = build_runtime.runtime_key(variant.get("numba", False), build_fmu.LINUX_BINARIES[2])
        for f in build_runtime.runtime_cache_dir().glob(f"runtime-{key}.*"):
            f.unlink()
    if cold and variant.get("aot"):
        from fmu_build import aot as build_aot

        shutil.rmtree(build_aot.aot_cache_dir() / build_aot.cache_key(), ignore_errors=True)
    start = time.perf_counter()
    build_fmu.build_fmu(ROOT / "examples/bearings/pitch_bearing.toml", output, **variant)
    return time.perf_counter() - start


def bench_output(stdout: str) -> tuple[float, np.ndarray, list, float]:
    """What the C host's ``bench`` scenario prints: (instantiation s, step times s, final outputs, resident set
    after the initialisation less before loading, MB)."""
    steps, instantiation, final, memory = [], None, None, float("nan")
    for line in stdout.splitlines():
        word, *rest = line.split() or [""]
        if word == "instantiate":
            instantiation = float(rest[0])
        elif word == "step":
            steps.append(float(rest[1]))
        elif word == "final":
            final = [float(x) for x in rest[1:]]
        elif word == "rss":
            memory = (int(rest[1]) - int(rest[0])) / 1024
    return instantiation, np.array(steps), final, memory


def run_host(host: Path, folder: Path, refs: dict, inputs: Path, parameters: dict) -> tuple:
    """One run of the C host: :func:`bench_output`."""
    integers = sum((["--integer", str(refs[k]), str(v)] for k, v in parameters.items()), [])
    command = [str(host), str(folder), "SlewingBearing", refs["guid"], "bench",
               *(str(refs[n]) for n in INPUTS + OUTPUTS), "--inputs", str(inputs), *integers]
    out = subprocess.run(command, env={"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root")},
                         capture_output=True, text=True, timeout=3600)
    if out.returncode != 0 or "done" not in out.stdout:
        raise RuntimeError(f"the C host failed on {folder}:\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}")
    return bench_output(out.stdout)


PAIR = ("standalone + aot (default)", "standalone + numba")
#: with --pair: the --numba FMU run again as a third variant (its own folder), the run's noise floor
AGAIN = "standalone + numba, again"


def add_arguments(parser) -> None:
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--pair", action="store_true",
                        help="the default and the --numba FMU only, builds cached, the --numba FMU the baseline")


def main(args) -> None:
    from fmpy import read_model_description

    from slewing_model import load_bearing
    from slewing_model.rings.superelement import build_superelement

    variants = {name: VARIANTS[name] for name in PAIR} if args.pair else VARIANTS
    reference = "standalone + numba" if args.pair else REFERENCE
    case = CASES["pitch"](args.steps)
    build_superelement(load_bearing(case.bearing), mesh="fine", bc="free")     # cached: not in the build times
    with tempfile.TemporaryDirectory(prefix="bench_runtime_") as tmp:
        tmp = Path(tmp)
        host = compile_host(tmp)
        inputs = tmp / "inputs.txt"
        np.savetxt(inputs, np.column_stack([case.loads, case.psi, case.omega]), fmt="%.17g")
        built, rows_build = {}, []
        for name, variant in variants.items():
            fmu = tmp / f"{name.replace(' + ', '_').replace(', ', '_')}.fmu"
            cold = build(variant, fmu, cold=name not in DROPPED and not args.pair)
            warm = build(variant, fmu, cold=False)
            folder = tmp / fmu.stem
            with zipfile.ZipFile(fmu) as z:
                z.extractall(folder)
                raw = sum(i.file_size for i in z.infolist())
            if name in DROPPED:
                for dropped in folder.glob(DROPPED[name]):
                    dropped.unlink()
            md = read_model_description(str(fmu))
            refs = {v.name: v.valueReference for v in md.modelVariables}
            refs["guid"] = md.guid
            built[name] = (folder, refs)
            rows_build.append([name, f"{fmu.stat().st_size / 1e6:.1f} MB", f"{raw / 1e6:.0f} MB",
                               f"{cold:.1f} s" if variant["runtime"] == "standalone" and name not in DROPPED
                               and not args.pair else "—",
                               f"{warm:.1f} s"])
        if args.pair:                   # the noise floor: the same FMU again (a copy of its unpacked folder)
            folder, refs = built["standalone + numba"]
            shutil.copytree(folder, folder.with_name(folder.name + "_again"))
            built[AGAIN] = (folder.with_name(folder.name + "_again"), refs)
            variants = {**variants, AGAIN: variants["standalone + numba"]}
        times = {name: [] for name in variants}
        starts = {name: [] for name in variants}
        memory = {name: [] for name in variants}
        finals = {}
        for r in range(args.runs):
            for name in variants:
                folder, refs = built[name]
                instantiation, steps, final, resident = run_host(host, folder, refs, inputs, case.parameters)
                starts[name].append(instantiation)
                memory[name].append(resident)
                times[name].append(steps[WARM:])
                finals[name] = final
    note(f"pitch case: {case.description}; {args.steps} steps of 10 ms, {args.runs} runs per FMU, "
          f"C host, PATH=/usr/bin:/bin")
    print_table("FMU variants: size and build", ["FMU", "zipped", "unpacked", "build, runtime staged",
                                                   "build, runtime cached"], rows_build)
    base = np.median(np.concatenate(times[reference]))
    rows = []
    for name in variants:
        s = spread(np.concatenate(times[name]) * 1e3)
        record(f"{name} [ms]", s)
        record(f"{name} instantiation [s]", float(np.median(starts[name])))
        record(f"{name} resident set after instantiation [MB]", float(np.median(memory[name])))
        rows.append([name, f"{np.median(starts[name]):.2f} s", f"{np.median(memory[name]):.0f} MB",
                     f"{s['median']:.2f} ms", f"{s['p95']:.2f} ms", f"{s['p99']:.2f} ms",
                     f"{s['median'] / (base * 1e3):.2f}"])
    print_table("doStep in the C host (set inputs, doStep, get outputs)",
                ["FMU", "instantiation", "memory after instantiation", "median", "95th pct", "99th pct",
                 f"median / {reference}"], rows)
    numba_median = np.median(np.concatenate(times["standalone + numba"]))
    for name in ("standalone + aot (default)", "standalone", AGAIN):
        if name not in times:
            continue
        note(f"median step of {name} / standalone + numba: "
             f"{np.median(np.concatenate(times[name])) / numba_median:.3f}")
    final_reference = np.array(finals[reference])
    for name, final in finals.items():
        deviation = np.max(np.abs(np.array(final) - final_reference) / np.maximum(np.abs(final_reference), 1e-300))
        note(f"final outputs of {name}: largest relative difference to {reference}: {deviation:.1e}")

