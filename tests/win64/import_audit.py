"""What the win64 half of the FMUs imports under wine: the audit behind fmu_build/win64.py's STDLIB_KEPT,
EMBED_PYD_KEPT and NUMPY_UNUSED.

Each FMU given is unpacked; an audit hook (``sys.addaudithook``: every "import" event, and ``sys.modules`` when
the hook starts and at exit) is put at the top of its slave script; our C host (tests/c_host/host.c, built with
mingw-w64) runs it under wine: scenario basic (steps, state get/set and serialization, free, reload) and nan (a
refused step) for a bearing FMU, and for an FMI 2.0 one also bench with the parameter life = 1; basic for the
drive FMU. Prints the standard library's top-level modules that were imported (from python311.zip, its
extension modules, built in), the embeddable distribution's extension modules, numpy's subpackages, and the
imports that found no module. Run after a change of what the FMU imports, as root with wine and mingw-w64:

    .venv/bin/python tests/win64/import_audit.py bearing2=FMU2 bearing3=FMU3 drive=DRIVE_FMU

(the keys are tests/test_win64.py's CASES; build the FMUs with build_fmu.py and ``python -m fmu_build.drive``).
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
import test_win64 as t  # noqa: E402
import win64_tools as w  # noqa: E402

HOOK = r'''
import sys as _audit_sys
def _audit_write(lines, _path=r"{log}"):
    with open(_path, "a") as fh:
        fh.write("".join(line + "\n" for line in lines))
def _audit_modules(tag):
    _audit_write([tag + " " + name + "\t" + str(getattr(m, "__file__", None))
                  for name, m in list(_audit_sys.modules.items())])
_audit_modules("MOD")
_audit_sys.addaudithook(lambda event, args: event == "import" and _audit_write(["IMP " + str(args[0])]))
import atexit as _audit_atexit
_audit_atexit.register(_audit_modules, "END")
'''
SLAVES = ("SlewingBearing", "SlewingBearing3", "SlewingDrive", "TimeTable")


def audit(fmus: dict, folder: Path) -> Path:
    """Run the FMUs (case -> FMU file) with the hook; returns the log."""
    log = folder / "imports.txt"
    hosts = w.c_hosts(folder)
    hook = HOOK.format(log=w.windows_path(log))
    for case, fmu in fmus.items():
        version, identifier, inputs, outputs = t.CASES[case]
        unpacked = w.unpack(fmu, folder / case)
        for script in (unpacked / "resources").glob("*.py"):
            text = script.read_text()
            if script.stem in SLAVES and "from __future__ import annotations\n" in text:
                script.write_text(text.replace("from __future__ import annotations\n",
                                               "from __future__ import annotations\n" + hook, 1))
        token, refs = t.refs_of(fmu)
        vrs = [str(refs[n]) for n in inputs + outputs]
        runs = [("basic",)] + ([("nan",)] if case != "drive" else [])
        if case != "drive" and version == 2 and "life" in refs:
            rows = "".join(f"8000 -3000 {30000 + 1000 * k} 1500 -2500 {0.4 * (-1) ** k} 0.05\n" for k in range(8))
            (unpacked / "inputs.txt").write_text(rows)
            runs.append(("bench", "--inputs", w.windows_path(unpacked / "inputs.txt"), "--integer", str(refs["life"]),
                         "1"))
        for scenario, *extra in runs:
            run = w.wine(hosts[version], w.windows_path(unpacked), identifier, token, scenario, *vrs, *extra,
                         timeout=900)
            print(f"{case} {scenario}: exit {run.returncode}, {run.stdout.strip().splitlines()[-1:]}", flush=True)
    return log


def summary(log: Path) -> None:
    modules, attempts = {}, set()
    for line in log.read_text().splitlines():
        if line.startswith(("MOD ", "END ")):
            name, _, path = line[4:].partition("\t")
            modules[name] = path
        elif line.startswith("IMP "):
            attempts.add(line[4:])
    stdlib = sorted({n.split(".")[0] for n, p in modules.items() if "site-packages" not in p and "resources" not in p
                     and n.split(".")[0] in sys.stdlib_module_names})
    print(f"{len(modules)} modules")
    print("standard library:", " ".join(stdlib))
    extensions = {p.rsplit("\\", 1)[-1] for p in modules.values() if p.endswith(".pyd")}
    print("extension modules:", " ".join(sorted(extensions)))
    print("numpy:", " ".join(sorted({".".join(n.split(".")[:2]) for n in modules if n.startswith("numpy")})))
    print("imports that found no module:", " ".join(sorted(attempts - set(modules))))


if __name__ == "__main__":
    fmus = dict(argument.split("=", 1) for argument in sys.argv[1:])
    with tempfile.TemporaryDirectory(prefix="slewing_audit_") as tmp:
        summary(audit(fmus, Path(tmp)))
