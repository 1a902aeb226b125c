"""Which files of a standalone FMU's Linux runtime the FMUs open: the audit behind the keep lists of
:mod:`fmu_build.runtime` (build time only; run by hand).

The FMUs this project builds on the runtime without numba (the bearing FMU with its loops compiled ahead
of time or numpy's, FMI 2.0 and 3.0; the drive FMU; the time-table FMU) are built with the runtime
*untrimmed* (every module of the standard library and of numpy that was staged before the audit's lists
existed: :func:`fmu_build.runtime.runtime` with ``trim=False``), unpacked, and run by C hosts under
``strace -f`` (``openat``, successful calls), through all their paths:

* the bearing FMU in our C host (``tests/c_host/host.c``), FMI 2.0 and 3.0: ``basic`` (steps, the state
  got, set, serialized and deserialized, the instance freed, the binary unloaded and loaded again),
  ``nan`` (a refused step), ``stress`` (two instances, a refused step, unloads); FMI 2.0 ``bench`` with
  the life accumulators on, the rotating load frame and bounded steps, with the rigid rings, and with a
  bad parameter (``ring_model = 9``: the instance refuses to initialise, with its message);
* the drive FMU and the time-table FMU in fmusim (``../shared/vendor``), their FMU state
  serialized at the end (``--final-fmu-state-file``).

Every regular file opened below the runtime's folder is recorded. The result: per part of the runtime
(the standard library's modules by top-level name, its extension modules, numpy's subpackages, the
shared libraries), what was opened, and whether :func:`fmu_build.runtime.kept` keeps it: a file opened
that the trimmed runtime leaves out fails the audit (exit status 1). Its lists are what
``STDLIB_IMPORTED``, ``DYNLOAD_IMPORTED`` and ``NUMPY_IMPORTED`` in ``fmu_build/runtime.py`` hold.

Needs strace (``apt-get install strace``), a C compiler, and fmusim's build dependencies for the
drive and table FMUs (else they are skipped, saying so).

Run: .venv/bin/python -m fmu_build.import_audit [--bearing TOML] [--work DIR] [--json FILE]
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HOST = ROOT / "tests" / "c_host"
FMUSIM = ROOT.parent / "shared" / "vendor" / "fmusim-v0.0.39" / "build.sh"
INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
OUTPUTS = ("z", "rx", "friction_torque", "max_ball_load", "life_damage")
#: the FMI 2.0 bench runs: (name, integer parameters, whether the run must succeed)
BENCH_RUNS = (("life, rotating frame, bounded steps", {"life": 1, "load_frame": 2, "step_work": 2}, True),
              ("rigid rings", {"ring_model": 1}, True),
              ("a bad parameter", {"ring_model": 9}, False))
OPENED = re.compile(r'open(?:at)?\((?:[^,]+, )?"((?:[^"\\]|\\.)*)"')


def compile_hosts(folder: Path) -> dict:
    """Our C host for FMI 2.0 and 3.0."""
    hosts = {}
    for version, flags in ((2, []), (3, ["-DFMI3"])):
        hosts[version] = folder / f"host{version}"
        subprocess.run(["cc", "-O1", *flags, "-o", str(hosts[version]), str(HOST / "host.c"), "-ldl", "-lm"],
                       check=True)
    return hosts


def untrimmed(fmu: Path, folder: Path, platform: str) -> Path:
    """``fmu`` unpacked into ``folder`` with its Linux runtime replaced by the untrimmed one."""
    from fmu_build import runtime

    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    shutil.rmtree(folder / platform / runtime.RUNTIME_FOLDER)
    with zipfile.ZipFile(runtime.runtime(platform, numba=False, trim=False).archive) as z:
        z.extractall(folder)
    for f in (folder / platform).rglob("*"):             # zip entries lose their modes
        if f.is_file() and f.read_bytes()[:4] == b"\x7fELF":
            f.chmod(0o755)
    return folder


def traced(command, log: Path, expect_success=True, env=None) -> str:
    """Run ``command`` under ``strace -f`` (successful opens into ``log``); its output. ``expect_success``:
    True, the run must exit 0; False, it must fail (a bad parameter); None, either (what it opened counts)."""
    run = subprocess.run(["strace", "-f", "-qq", "-e", "trace=open,openat", "-e", "status=successful", "-o",
                          str(log), *map(str, command)], capture_output=True, text=True, timeout=1800,
                         env=env or {"PATH": "/usr/bin:/bin"})
    if expect_success and run.returncode != 0:
        raise RuntimeError(f"{command[0]} failed ({run.returncode}):\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}")
    if expect_success is False and run.returncode == 0:
        raise RuntimeError(f"{command} was to fail (a bad parameter) and did not:\n{run.stdout[-2000:]}")
    return run.stdout


def opened_files(log: Path, prefix: Path) -> set:
    """The regular files below ``prefix`` that the strace log names as opened, relative to it."""
    found = set()
    for line in log.read_text(errors="replace").splitlines():
        match = OPENED.search(line)
        if not match:
            continue
        path = Path(match.group(1))
        try:
            relative = path.resolve().relative_to(prefix.resolve())
        except ValueError:
            continue
        if (prefix / relative).is_file():
            found.add(relative.as_posix())
    return found


def run_bearing(fmu: Path, version: int, work: Path, hosts: dict, say) -> set:
    """The bearing FMU's runs (module docstring); the files of its runtime opened."""
    from fmpy import read_model_description

    from fmu_build.shim import LINUX_BINARIES

    platform = LINUX_BINARIES[version]
    folder = untrimmed(fmu, work / f"bearing{version}", platform)
    md = read_model_description(str(fmu))
    refs = {v.name: str(v.valueReference) for v in md.modelVariables}
    token = md.guid if version == 2 else md.instantiationToken
    model = "SlewingBearing" if version == 2 else "SlewingBearing3"
    vrs = [refs[n] for n in INPUTS + OUTPUTS]
    opened = set()
    # basic must pass; nan and stress count for what they open whatever the host makes of the statuses
    runs = [("basic", [], True), ("nan", [], None), ("stress", ["--cycles", "1"], None)]
    if version == 2:
        inputs = work / "inputs.txt"
        inputs.write_text("".join(f"{8e3} {-3e3} {3e4 + 1e3 * k} {1.5e3} {-2.5e3} {0.4 + 0.01 * k} 0.05\n"
                                  for k in range(25)))
        for name, parameters, succeeds in BENCH_RUNS:
            integers = sum((["--integer", refs[k], str(v)] for k, v in parameters.items()), [])
            runs.append((f"bench: {name}", ["--inputs", str(inputs), *integers], succeeds))
    for index, (name, extra, succeed) in enumerate(runs):
        scenario = name.split(":")[0]
        say(f"FMI {version}.0 bearing FMU, our C host, {name} ...")
        log = work / f"strace_{version}_{index}_{scenario}.log"
        out = traced([hosts[version], folder, model, token, scenario, *vrs, *extra], log, succeed)
        if succeed is False and "ring_model" not in out:
            raise RuntimeError(f"the bad parameter's message is missing:\n{out[-2000:]}")
        opened |= opened_files(log, folder / platform / "python")
    return opened


def run_in_fmusim(fmu: Path, name: str, work: Path, fmusim: Path, say) -> set:
    """``fmu`` (FMI 2.0) in fmusim with its runtime untrimmed, its state serialized at the end."""
    from fmu_build.shim import LINUX_BINARIES

    platform = LINUX_BINARIES[2]
    folder = untrimmed(fmu, work / name, platform)
    repacked = work / f"{name}_untrimmed.fmu"
    with zipfile.ZipFile(repacked, "w", zipfile.ZIP_STORED) as z:
        for f in sorted(folder.rglob("*")):
            if f.is_file():
                z.write(f, f.relative_to(folder).as_posix())
    found = set()
    # a plain run must pass; the run that serializes the state at the end counts for what it opens
    for label, extra, succeed in (("", [], True), ("_state", ["--final-fmu-state-file", work / f"{name}.state"], None)):
        say(f"{name} FMU, fmusim{', its state serialized' if extra else ''} ...")
        log = work / f"strace_{name}{label}.log"
        traced([fmusim, "--interface-type", "cs", "--stop-time", "0.2", "--output-interval", "0.01", *extra,
                "--output-file", work / f"{name}.csv", repacked], log, succeed,
               env={"PATH": "/usr/bin:/bin", "TMPDIR": str(work)})
        # fmusim unpacks the FMU into a folder of its own (removed when it ends): the runtime's files are found
        # by their path below ``binaries/linux64/python/`` in whatever folder it chose
        marker = f"/{platform}/python/"
        for line in log.read_text(errors="replace").splitlines():
            match = OPENED.search(line)
            if match and marker in match.group(1):
                relative = match.group(1).split(marker, 1)[1]
                if (folder / platform / "python" / relative).is_file():
                    found.add(relative)
    return found


def build_fmus(bearing: Path, work: Path, say) -> dict:
    """The FMUs audited (their Linux halves; the win64 half is built by fmu_build/win64.py)."""
    from build_fmu import build_fmu
    from fmu_build.drive import build_drive_fmu, build_table_fmu

    say("building the FMUs (FMI 2.0 and 3.0 bearing, drive, time table; no win64 half) ...")
    return {"bearing2": build_fmu(bearing, work / "bearing2.fmu", mesh="coarse", win64=False, stage=say),
            "bearing3": build_fmu(bearing, work / "bearing3.fmu", mesh="coarse", fmi_version=3, win64=False, stage=say),
            "drive": build_drive_fmu(ROOT / "examples/drives/pitch_drive.toml", work / "drive.fmu", win64=False),
            "table": build_table_fmu(work / "table.fmu", "a command", [0.0, 0.1, 0.2],
                                     [("command", "rad", "pitch angle command")], [[0.0], [0.1], [0.0]],
                                     win64=False)}


def summary(opened: set, minor: str) -> dict:
    """``opened`` (paths relative to the runtime's prefix) by part: stdlib, dynload, numpy, libraries, other."""
    parts = defaultdict(set)
    stdlib = f"lib/python{minor}/"
    for path in sorted(opened):
        if path.startswith(stdlib + "lib-dynload/"):
            parts["dynload"].add(Path(path).name.split(".")[0])
        elif path.startswith(stdlib + "site-packages/numpy/"):
            inside = path[len(stdlib + "site-packages/numpy/"):].split("/")
            if len(inside) > 1 and inside[0] != "__pycache__":
                parts["numpy"].add(inside[0])
        elif path.startswith(stdlib + "site-packages/"):
            parts["site-packages"].add(path[len(stdlib + "site-packages/"):])
        elif path.startswith(stdlib):
            inside = path[len(stdlib):].split("/")        # a module's bytecode, written by a run: its module
            parts["stdlib"].add((inside[-1] if inside[0] == "__pycache__" else inside[0]).split(".")[0])
        else:
            parts["libraries"].add(path)
    return {k: sorted(v) for k, v in parts.items()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmu_build.import_audit", description=__doc__.splitlines()[0])
    parser.add_argument("--bearing", default=str(ROOT / "examples/bearings/table3_errors.toml"))
    parser.add_argument("--work", help="keep the FMUs, logs and unpacked folders here (default: a temporary folder)")
    parser.add_argument("--json", help="write the result (opened files, summary, dropped) to this file")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from fmu_build import runtime

    if shutil.which("strace") is None:
        parser.error("strace is not installed (apt-get install strace)")

    def say(line):
        print(line, flush=True)

    with tempfile.TemporaryDirectory(prefix="slewing_audit_") as tmp:
        work = Path(args.work) if args.work else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        fmus = build_fmus(Path(args.bearing), work, say)
        hosts = compile_hosts(work)
        opened = run_bearing(fmus["bearing2"], 2, work, hosts, say)
        opened |= run_bearing(fmus["bearing3"], 3, work, hosts, say)
        fmusim = work / "fmusim"
        built = FMUSIM.exists() and subprocess.run(["bash", str(FMUSIM), str(fmusim)],
                                                   capture_output=True).returncode == 0
        if built:
            for name in ("drive", "table"):
                opened |= run_in_fmusim(fmus[name], name, work, fmusim, say)
        else:
            say(f"SKIPPED the drive and table FMUs: fmusim is not built from {FMUSIM} (its libraries missing?)")
        minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
        parts = summary(opened, minor)
        dropped = sorted(p for p in opened if not runtime.kept(p, minor))
    for part, names in parts.items():
        print(f"{part} ({len(names)}): {' '.join(names)}")
    if args.json:
        Path(args.json).write_text(json.dumps({"opened": sorted(opened), "summary": parts, "dropped": dropped},
                                              indent=1))
    if dropped:
        print(f"FAILED: {len(dropped)} files opened that the trimmed runtime leaves out: {' '.join(dropped)}")
        return 1
    print(f"{len(opened)} files of the runtime opened; the trimmed runtime keeps them all")
    return 0


if __name__ == "__main__":
    sys.exit(main())
