"""The FMU carries the bytecode of its Python modules (fmu_build/bytecode.py), and instantiation imports
no more than a step needs.

Without bytecode, the first instantiation of a freshly unpacked FMU (fmpy unpacks one into a new folder at
every simulation) compiled every module it imports: about 1.2 s of CPU on the pitch bearing FMU, against
0.35 s for the rest of its instantiation.
"""
from __future__ import annotations

import importlib.util
import marshal
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HOST = ROOT / "tests" / "c_host"
INPUTS = ["Fx", "Fy", "Fz", "Mx", "My", "psi", "omega"]
OUTPUTS = ["z", "rx", "friction_torque", "max_ball_load", "static_safety_factor"]


def _sources_and_bytecode(fmu) -> tuple[dict, dict]:
    with zipfile.ZipFile(fmu) as z:
        names = z.namelist()
        sources = {n: z.read(n) for n in names if n.endswith(".py")}
        code = {n: z.read(n) for n in names if n.endswith(".pyc")}
    return sources, code


def test_every_module_of_the_fmu_has_checked_hash_bytecode_naming_no_building_path(table3_fmu):
    sys.path.insert(0, str(ROOT))
    from fmu_build.bytecode import bytecode_path

    sources, code = _sources_and_bytecode(table3_fmu)
    runtime = "binaries/linux64/python/"
    assert any(n.startswith("resources/slewing_model/") for n in sources)
    assert any(n.startswith(runtime) for n in sources)
    missing = []
    for name, source in sources.items():
        if not name.startswith(("resources/", runtime)):
            continue
        pyc = bytecode_path(name)
        if pyc not in code:
            missing.append(name)
            continue
        data = code[pyc]
        assert data[:4] == importlib.util.MAGIC_NUMBER, name
        # hash-based (PEP 552): the model's code checked against its source, the runtime's not
        assert int.from_bytes(data[4:8], "little") == (0b11 if name.startswith("resources/") else 0b01), name
        assert data[8:16] == importlib.util.source_hash(source), name
        filename = marshal.loads(data[16:]).co_filename
        assert not filename.startswith("/"), (name, filename)              # its path in the FMU, relative
        assert name.endswith(filename), (name, filename)
    # the standard library's modules the runtime keeps all compile; a few data files of packages need not
    assert not [n for n in missing if n.startswith("resources/")], missing
    assert len(missing) <= 0.02 * len(sources), missing


@pytest.fixture(scope="module")
def host(tmp_path_factory):
    binary = tmp_path_factory.mktemp("host") / "host2"
    run = subprocess.run(["cc", "-O1", "-include", str(ROOT / "fmu_src" / "shim" / "glibc_compat.h"),
                          "-nostartfiles", "-o", str(binary), str(HOST / "start.c"), str(HOST / "host.c"),
                          "-Wl,--no-as-needed", "-l:libdl.so.2", "-lm"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return binary


def _bytecode_files(folder: Path) -> dict:
    return {p: p.read_bytes() for p in folder.rglob("*.pyc")}


def test_a_freshly_unpacked_fmu_compiles_nothing_when_a_c_host_runs_it(table3_fmu, host, tmp_path):
    """Unpacked as fmpy does (the files dated now, not as the archive says), the FMU's instantiation and steps
    in a C host neither write a bytecode file (one was missing) nor rewrite one (one was stale)."""
    from fmpy import read_model_description

    folder = tmp_path / "fmu"
    with zipfile.ZipFile(table3_fmu) as z:
        z.extractall(folder)
    md = read_model_description(str(table3_fmu))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    before = _bytecode_files(folder)
    run = subprocess.run([str(host), str(folder), "SlewingBearing", md.guid, "basic",
                          *(str(refs[n]) for n in INPUTS + OUTPUTS)],
                         env={"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root")},
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0 and "done" in run.stdout, run.stdout[-2000:] + run.stderr[-2000:]
    after = _bytecode_files(folder)
    assert sorted(map(str, set(after) - set(before))) == []
    assert [str(p) for p in before if after[p] != before[p]] == []


def test_the_fmus_step_path_does_not_import_the_studies_or_the_life_modules_it_does_not_run(tmp_path):
    """Importing the simulator (what the FMU's slave imports) leaves out the friction studies and, until a
    run with the life accumulators asks for them, the life modules but the contact loops' kernel; the
    package's names are all there when asked for."""
    code = ("import sys; import slewing_model.simulation.simulator; "
            "print(sorted(m for m in sys.modules if m.startswith(('slewing_model.life', "
            "'slewing_model.friction.studies'))))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert run.stdout.split("\n")[0] == "['slewing_model.life', 'slewing_model.life.kernel']"
    code = ("from slewing_model.friction import torque_ripple, preload_sweep, studies; "
            "from slewing_model.life import LifeAccumulator, analyse_run, duty, rating; "
            "import slewing_model.friction as f, slewing_model.life as l; "
            "assert f.torque_ripple is studies.torque_ripple and l.LifeAccumulator is duty.LifeAccumulator; "
            "assert {'torque_ripple', 'studies'} <= set(dir(f)) and {'analyse_run', 'wear'} <= set(dir(l)); "
            "assert all(hasattr(f, n) for n in f.__all__) and all(hasattr(l, n) for n in l.__all__); "
            "from slewing_model.life import *")
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


#: run in a child Python with an unpacked FMU's resources (argv[1]) first on the path: imports every run-time
#: module of its slewing_model, each source dataclasses executes looked up in the FMU's dataclass_code.bin and
#: compared with the code compiled from it here; prints the numbers of sources, found, equal, and of those carried
_CHECK_DATACLASS_CODE = """
import builtins, dataclasses, importlib, sys
sys.path.insert(0, sys.argv[1])
import dataclass_code
carried = dataclass_code.codes()
seen = found = equal = 0
def exec_(source, globals=None, locals=None, /):
    global seen, found, equal
    code = compile(source, '<string>', 'exec', dont_inherit=True)
    seen += 1
    found += source in carried
    equal += carried.get(source) == code
    builtins.exec(code, globals, locals)
dataclasses.exec = exec_
import slewing_model
for name in slewing_model.RUNTIME_MODULES:
    parts = ['slewing_model', *name.split('/')]
    importlib.import_module('.'.join(parts[:-1] if parts[-1] == '__init__' else parts))
print(seen, found, equal, len(carried))
"""


def test_the_fmu_carries_its_dataclasses_methods_compiled_as_python_would_compile_them(table3_fmu, tmp_path):
    """Every dataclass of the run-time modules finds its methods' code in the FMU (fmu_src/dataclass_code.py),
    equal to the code Python compiles from their source: an instance creates its dataclasses without compiling,
    and with the same methods."""
    with zipfile.ZipFile(table3_fmu) as z:
        z.extractall(tmp_path, [n for n in z.namelist() if n.startswith("resources/")])
    run = subprocess.run([sys.executable, "-B", "-c", _CHECK_DATACLASS_CODE, str(tmp_path / "resources")],
                         capture_output=True, text=True, check=True)
    seen, found, equal, carried = map(int, run.stdout.split())
    assert seen > 100 and seen == found == equal == carried


def test_a_dataclass_whose_source_the_fmu_does_not_carry_is_compiled_as_before():
    """Within ``precompiled``, a dataclass whose methods' source is not in the file (an edited module) is
    compiled as without it: the same code, the same annotations (no future feature of dataclass_code.py
    leaks into its compilation); after it, dataclasses is as before."""
    import dataclasses

    sys.path.insert(0, str(ROOT / "fmu_src"))
    try:
        import dataclass_code
    finally:
        sys.path.remove(str(ROOT / "fmu_src"))

    def point():
        @dataclasses.dataclass(frozen=True)
        class Point:
            x: float
            y: int = 2
        return Point

    saved = dataclass_code._codes
    dataclass_code._codes = {"def __create_fn__(): pass": compile("", "<string>", "exec")}
    try:
        with dataclass_code.precompiled():
            assert "exec" in vars(dataclasses)
            made = point()
    finally:
        dataclass_code._codes = saved
    assert "exec" not in vars(dataclasses)
    assert made(1.0) == made(1.0, 2) and repr(made(1.0)).endswith("Point(x=1.0, y=2)")
    assert made.__init__.__annotations__ == point().__init__.__annotations__ == {"x": "float", "y": "int",
                                                                                 "return": None}
    for method in ("__init__", "__repr__", "__eq__", "__hash__", "__setattr__", "__delattr__"):
        assert getattr(made, method).__code__ == getattr(point(), method).__code__, method
