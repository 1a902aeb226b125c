"""The loops compiled ahead of time (``fmu_build/aot.py``): modules that need numpy only, one for
an x86-64-v3 CPU and one for any x86-64, each equal to numba's JIT, the first the CPU runs taken, used only
where they were compiled from these sources, and an FMU that carries them instead of numba and runs in a C
host."""
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from slewing_model.numerics import compiled
from slewing_model.numerics.targets import CPUINFO_FLAGS, PORTABLE_TARGETS

from conftest import has_x86_64_v3

ROOT = Path(__file__).resolve().parents[1]
BEARING = ROOT / "examples" / "bearings" / "table3_errors.toml"
STEPS = 60

pytestmark = pytest.mark.skipif(not compiled._numba_installed(), reason="numba (its pycc) is not installed here")

#: a step series of table3 with errors, flexible rings, friction and life on, printed as JSON; with
#: "aot", numba and llvmlite cannot be imported and the modules' folder comes first on the path; with
#: "generic", the x86-64-v3 module cannot be imported either
SERIES = r'''
import json, sys
if sys.argv[1] in ("aot", "generic"):
    sys.modules["numba"] = sys.modules["llvmlite"] = None
    sys.path.insert(0, sys.argv[2])
if sys.argv[1] == "generic":
    sys.modules["slewing_kernels_v3"] = None
sys.path.insert(0, sys.argv[3])
from slewing_model import Loads, load_bearing
from slewing_model.numerics import compiled
from slewing_model.rings.superelement import build_superelement
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings
bearing = load_bearing(sys.argv[4])
settings = SimulatorSettings(life=True, contact_kernel="compiled", friction_kernel="compiled")
sim = BearingSimulator(bearing, build_superelement(bearing, mesh="coarse", bc="free"), settings)
out = []
for k in range(int(sys.argv[5])):
    r = sim.step(Loads(8e3, -3e3, 3e4 + 1e3 * k, 1.5e3 * (-1) ** (k // 20), -2.5e3), 0.4 + 0.01 * k, 0.05)
    d = r.distribution
    out.append([*d.displacement, d.max_ball_load, r.friction_torque, d.contact_load[19, 1], sim.life.worst_damage])
print(json.dumps({"aot": compiled.aot_kernels() is not None, "numba": sys.modules.get("numba") is not None,
                  "target": compiled.aot_target(), "out": out}))
'''


@pytest.fixture(scope="module")
def aot_folder(tmp_path_factory):
    sys.path.insert(0, str(ROOT))
    import fmu_build.aot

    folder = tmp_path_factory.mktemp("aot")
    fmu_build.aot.build_all_kernels(folder)
    return folder


def _series(mode, folder):
    run = subprocess.run([sys.executable, "-c", SERIES, mode, str(folder), str(ROOT), str(BEARING), str(STEPS)],
                         capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.splitlines()[-1])


def test_loops_compiled_ahead_of_time_equal_numbas_without_numba(aot_folder):
    jit, aot, generic = (_series(mode, aot_folder) for mode in ("jit", "aot", "generic"))
    assert not jit["aot"] and jit["numba"] and jit["target"] is None
    for found in (aot, generic):
        assert found["aot"] and not found["numba"]       # numba could not be imported, nor was it needed
    # the module this CPU runs (its features read by the kernel's flags here, by another reader than the FMU's),
    # and the generic one where that cannot be imported
    assert aot["target"] == ("x86-64-v3" if has_x86_64_v3() else "generic")
    assert generic["target"] == "generic"
    # the same LLVM code for other CPU targets: equal, observed bit for bit
    for found in (aot, generic):
        assert np.allclose(found["out"], jit["out"], rtol=1e-12, atol=0)


def test_a_cpu_takes_the_first_module_its_features_allow():
    v3 = "flags : fpu sse2 " + " ".join(CPUINFO_FLAGS.values())
    assert compiled.aot_targets(v3) == ["x86-64-v3", "generic"]
    for missing in CPUINFO_FLAGS.values():            # one flag short: the generic module only
        assert compiled.aot_targets(v3.replace(f" {missing}", "")) == ["generic"], missing
    assert compiled.aot_targets("") == ["generic"]    # no /proc/cpuinfo: another system
    assert set(compiled.AOT_MODULES) == {name for name, _ in PORTABLE_TARGETS}


def test_the_loops_compiled_ahead_of_time_are_the_default(monkeypatch, tmp_path, capsys):
    sys.path.insert(0, str(ROOT))
    import build_fmu

    for runtime in ("standalone", "host"):
        assert build_fmu.resolve_loops(runtime) == "aot"
    assert build_fmu.resolve_loops("standalone", numba=True) == "numba"
    assert build_fmu.resolve_loops("standalone", numba=False) == "numpy"
    assert build_fmu.resolve_loops("standalone", aot=False) == "numba"          # numba's JIT, as asked
    assert build_fmu.resolve_loops("standalone", numba=False, aot=True) == "aot"
    with pytest.raises(ValueError, match="not both"):
        build_fmu.resolve_loops("standalone", numba=True, aot=True)
    # the command: no option, --aot, --numba, --no-numba (one of them)
    asked = []
    built = tmp_path / "t.fmu"
    built.write_bytes(b"")
    monkeypatch.setattr(build_fmu, "build_fmu", lambda *a, **k: asked.append(k) or built)
    monkeypatch.setattr(build_fmu, "describe_fmu", lambda fmu: "")
    for options in ([], ["--aot"], ["--numba"], ["--no-numba"]):
        assert build_fmu.main(["b.toml", *options]) == 0
    assert [build_fmu.resolve_loops(k["runtime"], k["numba"], k["aot"]) for k in asked] == \
        ["aot", "aot", "numba", "numpy"]
    with pytest.raises(SystemExit):
        build_fmu.main(["b.toml", "--aot", "--numba"])
    capsys.readouterr()


def test_a_module_of_other_sources_is_not_used(aot_folder, monkeypatch):
    monkeypatch.syspath_prepend(str(aot_folder))
    compiled.aot_kernels.cache_clear()
    try:
        assert compiled.aot_kernels() is not None
        monkeypatch.setattr(compiled, "kernel_source_hash", lambda: 12345)
        compiled.aot_kernels.cache_clear()
        assert compiled.aot_kernels() is None
    finally:                                              # the other tests run numba's loops
        monkeypatch.undo()
        for module in compiled.AOT_MODULES.values():
            sys.modules.pop(module, None)
        compiled.aot_kernels.cache_clear()
    assert compiled.aot_kernels() is None                 # the tests' own path has no such module


def test_fmu_with_loops_compiled_ahead_of_time_runs_in_a_c_host_without_numba(aot_folder, tmp_path, table3_fmu):
    """The FMU built with aot=True carries the module and no numba; in our C host (no Python of
    this machine, a bare environment) it says so and answers as the numpy FMU does."""
    from fmpy import read_model_description

    from build_fmu import build_fmu
    from host_output import parse_host_output

    fmu = build_fmu(BEARING, tmp_path / "aot.fmu", mesh="coarse", bc="free", aot=True, win64=False)
    names = zipfile.ZipFile(fmu).namelist()
    for module in compiled.AOT_MODULES.values():      # a module for each target
        assert any(n.startswith(f"resources/{module}.") for n in names), module
    assert not any("/site-packages/numba/" in n or "/site-packages/llvmlite/" in n for n in names)
    assert fmu.stat().st_size < 1.15 * table3_fmu.stat().st_size     # numpy's FMU and a 1.5 MB module
    host = tmp_path / "host"
    subprocess.run(["cc", "-O1", "-o", str(host), str(ROOT / "tests/c_host/host.c"), "-ldl", "-lm"], check=True)
    values, logs = {}, {}
    for name, path in (("aot", fmu), ("numpy", table3_fmu)):
        folder = tmp_path / name
        with zipfile.ZipFile(path) as z:
            z.extractall(folder)
        md = read_model_description(str(path))
        refs = {v.name: v.valueReference for v in md.modelVariables}
        vrs = [str(refs[n]) for n in ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega", "z", "rx", "friction_torque",
                                      "max_ball_load")]
        run = subprocess.run([str(host), str(folder), "SlewingBearing", md.guid, "basic", *vrs], capture_output=True,
                             text=True, timeout=600, env={"PATH": "/usr/bin:/bin"})
        assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
        values[name], _, log_lines, errors = parse_host_output(run.stdout)
        assert not errors, errors
        logs[name] = " ".join(message for _, _, message in log_lines)
    target = "x86-64-v3" if has_x86_64_v3() else "generic"
    assert f"loops compiled ahead of time for {target}" in logs["aot"] and "run by numpy" in logs["numpy"]
    assert values["aot"].keys() == values["numpy"].keys() and values["aot"]
    for label, steps in values["aot"].items():           # compiled loops against numpy's: round-off
        for k, outputs in steps.items():
            assert np.allclose(outputs, values["numpy"][label][k], rtol=1e-9, atol=1e-15), (label, k)


def test_the_compiled_modules_key_covers_every_module_the_loops_take_code_from():
    """A compiled module is used only where its key, the hash of KERNEL_SOURCES, is the sources' now: so every
    module of slewing_model that a kernel module imports from (constants and functions the loops compile in)
    must be one of KERNEL_SOURCES, or an edit there would leave a stale module in use."""
    import ast

    package = Path(compiled.__file__).resolve().parents[1]
    listed = set(compiled.KERNEL_SOURCES)
    kernels = [name for name in listed if name.endswith("kernel.py")]
    assert kernels, listed
    for name in kernels:
        tree = ast.parse((package / name).read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level > 0:
                base = Path(name).parent
                for _ in range(node.level - 1):
                    base = base.parent
                target = base.joinpath(*node.module.split(".")) if node.module else base
                source = f"{target.as_posix()}.py"
                if not (package / source).exists():
                    source = f"{target.as_posix()}/__init__.py"
                assert source in listed, f"{name} imports from {source}, which KERNEL_SOURCES leaves out"


#: calls a compiled loop that returns arrays (the life map's widest contacts) ``sys.argv[2]`` times in a process
#: without numba, and prints how many pickles the module's numba_unpickle loaded (pickle.loads counted before
#: the module's first call, which takes the function once)
UNPICKLES = r'''
import pickle, sys
import numpy as np
sys.modules["numba"] = sys.modules["llvmlite"] = None
sys.path.insert(0, sys.argv[1])
loads, count = pickle.loads, [0]
def counted(*args, **kwargs):
    count[0] += 1
    return loads(*args, **kwargs)
pickle.loads = counted
import slewing_kernels
semi = np.ascontiguousarray(np.arange(12.0).reshape(3, 4))
for _ in range(int(sys.argv[2])):
    first, second = slewing_kernels.life__widest_contacts(semi, semi + 1.0)
assert first.dtype == np.float64 and first.shape == (4,), (first.dtype, first.shape)
print(count[0])
'''


def test_a_compiled_loop_unpickles_its_constants_once(aot_folder):
    """Returning an array, a loop compiled ahead of time boxes it with its dtype, a pickled constant: the
    module's numba_unpickle (fmu_build/pycc_unpickle.c) loads each constant once and keeps it, as numba's JIT
    does (pycc's own loads it on every call). 1 call and 50 calls load the same number of pickles."""
    def unpickles(calls):
        run = subprocess.run([sys.executable, "-c", UNPICKLES, str(aot_folder), str(calls)], capture_output=True,
                             text=True, timeout=300)
        assert run.returncode == 0, run.stderr[-3000:]
        return int(run.stdout.split()[-1])

    once, many = unpickles(1), unpickles(50)
    assert 1 <= once == many, (once, many)
