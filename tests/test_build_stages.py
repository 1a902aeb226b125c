"""`make demo` and build_fmu.py say what they are doing: without it `make demo` would be silent
for about 11 minutes on a loaded machine before its first progress bar (the superelement, the
FMU's packaging and Linux binary, its Python runtime, the compilation of the loops)."""
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

pytest.importorskip("pythonfmu")


def _stages(lines):
    """The stage each line names, by its first words."""
    names = {"building the ring superelement": "superelement", "packaging the FMU": "package",
             "compiling the FMU's Linux binary": "binary", "staging the FMU's Python runtime": "runtime",
             "compiling the loops with numba": "numba", "compiling the loops ahead of time": "aot",
             "adding the Windows (win64) binary": "win64"}
    return [next((v for k, v in names.items() if line.startswith(k)), line) for line in lines]


@pytest.mark.parametrize("runtime, expected", [
    ("host", ["superelement", "package", "binary"]),
    ("standalone", ["superelement", "package", "binary", "runtime", "win64"]),
])
def test_build_names_each_stage_as_it_begins(tmp_path, runtime, expected):
    from build_fmu import build_fmu

    lines = []
    fmu = build_fmu(ROOT / "examples/bearings/table3.toml", tmp_path / "t.fmu", mesh="coarse", runtime=runtime,
                    numba=False, stage=lines.append)
    assert _stages(lines) == expected, lines
    assert all(line.endswith("...") and "\n" not in line for line in lines)
    assert "table3.toml (coarse mesh, free rings" in lines[0]
    with zipfile.ZipFile(fmu) as z:                                # and the FMU was built
        assert "modelDescription.xml" in z.namelist()


def test_build_fmu_command_prints_the_stages(tmp_path):
    import subprocess

    out = subprocess.run([sys.executable, "build_fmu.py", "examples/bearings/table3.toml", "-o", str(tmp_path / "t.fmu"),
                          "--mesh", "coarse", "--runtime", "host", "--no-numba"], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    printed = out.stdout.splitlines()
    assert _stages(printed[:3]) == ["superelement", "package", "binary"], printed
    assert printed[3].startswith("wrote ")
