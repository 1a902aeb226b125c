"""The FMU Compliance Checker (modelica-tools/FMUComplianceChecker, with FMI Library 2.0.3) on our FMI 2.0 FMUs.

It checks the modelDescription against the standard's schema and rules, loads the binary and simulates
0-1 s with its own master; it reports its warnings and errors and the FMU's. It is not a Debian or PyPI
package: ``tests/fmu_check/build.sh`` builds it from clones of its two repositories (about 2 minutes). The
tests run where the binary is, named by SLEWING_FMUCHECK or in the cache folder's ``fmucheck/`` (``$SLEWING_CACHE_DIR``, else
``~/.cache/slewing_model``), and
are skipped elsewhere, saying so. The checker does not read FMI 3.0.
"""
import os
import re
import subprocess
import zipfile
from pathlib import Path

import pytest

from slewing_model.rings.superelement.build import default_cache_dir

CACHE = Path(default_cache_dir()) / "fmucheck"


def _checker() -> Path:
    named = os.environ.get("SLEWING_FMUCHECK")
    path = Path(named) if named else CACHE / "fmuCheck.linux64"
    if not path.is_file():
        pytest.skip(f"SKIPPED: the FMU Compliance Checker is not built ({path} is absent): "
                    f"bash tests/fmu_check/build.sh <FMUComplianceChecker clone> <fmi-library clone>")
    return path


def _check(fmu: Path, tmp_path: Path) -> tuple[int, str, tuple[int, int, int]]:
    """Runs the checker over 0-1 s at 10 ms; returns its exit code, its output and (FMU-reported,
    checker warnings, checker errors) from its summary."""
    done = subprocess.run([str(_checker()), "-h", "0.01", "-s", "1", "-l", "3", "-o", str(tmp_path / "out.csv"),
                           str(fmu)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    text = done.stdout + done.stderr
    counts = [re.search(pattern, text) for pattern in
              (r"(\d+) warning\(s\) and error\(s\)", r"(\d+) Warning\(s\)", r"(\d+) Error\(s\)")]
    assert all(counts), f"no summary in the checker's output:\n{text[-3000:]}"
    return done.returncode, text, tuple(int(m.group(1)) for m in counts)


@pytest.mark.parametrize("build", ["table3_aot_fmu", "table3_fmu"])
def test_the_compliance_checker_finds_nothing_in_our_fmi2_fmus(build, request, tmp_path):
    """The default build (loops compiled ahead of time) and the numpy-loops build: exit 0, and no warning
    or error from the checker or from the FMU, over a simulation of 100 steps."""
    _checker()
    fmu = request.getfixturevalue(build)
    code, text, counts = _check(fmu, tmp_path)
    assert code == 0 and counts == (0, 0, 0), text[-3000:]
    rows = (tmp_path / "out.csv").read_text().splitlines()
    assert len(rows) >= 101, f"{len(rows)} rows in the checker's output, not 1 s at 10 ms"


def test_the_compliance_checker_finds_a_broken_model_description(table3_fmu, tmp_path):
    """Control: a parameter made continuous (a combination FMI 2.0 forbids) is an error the checker reports."""
    _checker()
    broken = tmp_path / "broken.fmu"
    with zipfile.ZipFile(table3_fmu) as source, zipfile.ZipFile(broken, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "modelDescription.xml":
                text, n = re.subn(r'(name="preload"[^>]*?)variability="fixed"', r'\1variability="continuous"',
                                  data.decode())
                assert n == 1, "the modelDescription has no fixed parameter preload to break"
                data = text.encode()
            target.writestr(item, data)
    code, text, counts = _check(broken, tmp_path)
    assert counts[2] >= 1, text[-3000:]
