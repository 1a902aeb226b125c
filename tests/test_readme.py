"""The commands of the README and of the documentation's pages run as written.

Every line of their ``sh`` blocks, and their ``python`` examples, is either run here or
skipped with the reason stated in :data:`SKIPPED` (FMU and SSP builds, full examples and
studies of minutes, cluster set-up, placeholders). The cheap ones run in a copy of the
repository (its tracked and new files, committed into a fresh git repository, and numba's cache of
the loops), with ``.venv/bin/`` pointing at this checkout's environment and ``../shared`` at the real one; each
must exit 0, and afterwards ``git status`` of the copy must show nothing: the commands write
only to ignored folders (``results/``), never into the repository. A command shown twice, or again with
only another ``-o``, runs once (:func:`_once`); the commands take the loops compiled ahead of time where
``make test`` compiled them (:func:`_aot_path`).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
VENV_BIN = Path(sys.executable).parent
OPENFAST = ROOT.parent / "shared" / "data" / "openfast"

#: (pattern at the start of a command, why it is not run here)
SKIPPED = (
    (r"make ", "installs the environment / runs the whole suite: what `make test` is"),
    (r"\.venv/bin/python build_fmu\.py", "builds an FMU (half a minute or more); tests/test_fmu*.py build and run it"),
    (r"\.venv/bin/python -m fmu_build\.drive", "builds an FMU; tests/test_drive_fmu.py runs it"),
    (r"bash tests/linux_floor/", "builds CPython in a Debian 11 chroot (minutes, as root); tests/linux_floor/run_all.sh "
                                 "runs it, tests/test_linux_floor.py uses what it built"),
    (r"\.venv/bin/python examples/ssp/", "builds and runs the SSP's four FMUs (minutes); tests/test_ssp.py runs it"),
    (r"\.venv/bin/python examples/", "a full example (seconds to a minute); examples/timings.py times each"),
    (r"\.venv/bin/python (-m )?benchmarks", "a benchmark (minutes)"),
    (r"\.venv/bin/slewing batch examples/studies/", "a study of minutes (2,000 or 10 long cases); tests/test_study.py"),
    (r"\.venv/bin/slewing turbine examples/studies/", "a turbine study of minutes (24 cases of 60 s); "
                                                     "tests/test_turbine_study.py"),
    (r"OMP_NUM_THREADS=1 nice ", "runs a CalculiX reference again (minutes, needs ccx); its results are stored in "
                                 "references/validation/data/, from which the redraw commands run here"),
    (r"ECOS=|chmod \+x \"\$ECOS\"|mkdir -p results && cd results", "ecos needs the SSP built (minutes)"),
    (r"export |dask ", "environment or cluster set-up for another machine"),
    (r".*\b(STUDY\.toml|DIR|HOST)\b", "a placeholder to fill in"),
)


#: the pages whose commands run: the README and the documentation site's Markdown pages
PAGES = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts)
#: the FMUs the examples step (`make demo`'s, and one a page builds), by the bearing file they are built from:
#: the test builds them quickly (coarse superelement, no win64 half; the loops compiled ahead of time, as by
#: default, taken from the cache `make test` fills: the examples' 1,600 steps take 12 s of CPU, 32 s with numpy's)
#: and steps them instead
EXAMPLE_FMUS = {"build/SlewingBearing_pitch_bearing.fmu": "examples/bearings/pitch_bearing.toml",
                "build/table1.fmu": "examples/bearings/table1.toml"}


def _blocks(kind: str) -> list[str]:
    return [block for page in PAGES
            for block in re.findall(rf"^```{kind}\n(.*?)^```", page.read_text(), flags=re.S | re.M)]


def _commands() -> list[str]:
    out = []
    for block in _blocks("sh"):
        for line in block.replace("\\\n", " ").splitlines():                # a command continued on the next line
            line = re.sub(r"\s+#\s.*$", "", line).strip()      # a trailing comment
            if line and not line.startswith("#"):
                out.append(line)
    return out


def _skip_reason(command: str):
    for pattern, reason in SKIPPED:
        if re.match(pattern, command):
            return reason
    return None


def test_every_documented_command_is_run_or_skipped_with_a_reason():
    commands = _commands()
    assert len(commands) > 15
    run = [c for c in commands if _skip_reason(c) is None]
    assert any(c.startswith(".venv/bin/slewing solve") for c in run)
    assert any(c.startswith(".venv/bin/slewing superelement") for c in run)


@pytest.fixture(scope="module")
def copy(tmp_path_factory):
    """A copy of the repository (tracked and new files) as a fresh git repository."""
    base = tmp_path_factory.mktemp("readme")
    repo = base / "repo"
    listed = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard", "-z"], cwd=ROOT,
                            capture_output=True, text=True, check=True).stdout.split("\0")
    for name in filter(None, listed):
        source = ROOT / name
        if source.is_file():
            (repo / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, repo / name)
    # numba's cache of the loops (ignored by git), as a checkout has it once its loops have run (`make test`
    # compiles them first): the scripts run from the copy import the copy's package, whose loops numba would
    # otherwise compile again (about a minute of CPU). numba uses an entry only where its source file has the
    # stamp (time, size) it was compiled from, which copy2 keeps; it compiles the others
    packages = ("slewing_model", "slewing_turbine")
    for cached in (path for package in packages for path in (ROOT / package).rglob("*.nb[ic]")):
        target = repo / cached.relative_to(ROOT)
        if target.parent.parent.is_dir():
            target.parent.mkdir(exist_ok=True)
            shutil.copy2(cached, target)
    if OPENFAST.is_dir():
        (base / "shared" / "data").mkdir(parents=True)
        (base / "shared" / "data" / "openfast").symlink_to(OPENFAST)
    git = ["git", "-c", "user.name=test", "-c", "user.email=test@example.com"]
    for args in (["init", "-q"], ["add", "-A"], ["commit", "-qm", "copy"]):
        subprocess.run(git + args, cwd=repo, check=True, capture_output=True)
    return repo


def _shared_outputs() -> set[str]:
    """The files the commands on ``../shared``'s files write (``-o results/fastv8.csv``)."""
    return {out for c in _commands() if "../shared/" in c for out in re.findall(r"(?:-o|--output)\s+(\S+)", c)}


def _needs_shared(command: str) -> bool:
    """A command that reads the public NREL OpenFAST outputs of ``../shared`` (not in a clone), or what such a
    command wrote."""
    return "../shared/" in command or any(out in command.split() for out in _shared_outputs())


_OUTPUT = re.compile(r"(?:^|\s)(?:-o|--output)\s+(\S+)")


def _once(commands) -> list[tuple[str | None, str | None, str | None]]:
    """``commands`` as (command to run, or None where its work is already done; its output path; the output
    path of the command that did that work).

    Two pages show the same command (``slewing solve`` of table1 in the README and the CLI guide), or the
    same command writing to another path (``slewing life ... -o results/life_pitch`` and ``-o
    results/life_pitch_series``): the second is the same work, with the same arguments, as the first, and
    exits as the first did, so it runs once (a command that differs in anything but its ``-o`` is run); the
    output of the first is copied to the second's path, where a later command may read it."""
    seen, out = {}, []
    for command in commands:
        output = (_OUTPUT.findall(command) or [None])[-1]
        key = _OUTPUT.sub(" -o OUTPUT", command)
        if key in seen:
            out.append((None, output, seen[key]))
        else:
            seen[key] = output
            out.append((command, output, None))
    return out


def test_a_command_differing_only_in_its_output_runs_once():
    once = _once(["a x -o r/1", "a x", "a x -o r/2", "a x --output r/3 --mu 1", "a x", "a y -o r/1"])
    assert [(c, o, first) for c, o, first in once] == [
        ("a x -o r/1", "r/1", None), ("a x", None, None), (None, "r/2", "r/1"),
        ("a x --output r/3 --mu 1", "r/3", None), (None, None, None), ("a y -o r/1", "r/1", None)]


def _aot_path() -> dict:
    """The environment that puts the loops compiled ahead of time on the commands' import path, where the
    cache `make test` fills (the Makefile's COMPILE_LOOPS_AOT; conftest's ``SLEWING_AOT_CACHE_DIR``) holds them
    for these sources: the library then takes its loops from them (numerics/compiled.py's ``aot_kernels``,
    which checks their sources' hash), as an FMU does, instead of loading each from numba's cache (1.5 s
    of CPU a command that solves; the answers are the same: tests/test_aot.py). Where they are not there:
    numba's cache."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    try:
        from fmu_build.aot import aot_cache_dir, cache_key, module_file_name
        from slewing_model.numerics.compiled import AOT_MODULES

        folder = aot_cache_dir() / cache_key()
        if not all((folder / module_file_name(target)).is_file() for target in AOT_MODULES):
            return {}
    except (ImportError, OSError):
        return {}
    return {"PYTHONPATH": os.pathsep.join(filter(None, (str(folder), os.environ.get("PYTHONPATH"))))}


def _run_commands(copy, commands) -> None:
    """Each command exits 0 in the copy, which is left as it was."""
    env = {**os.environ, **_aot_path()}
    for command, output, first in _once(commands):
        if command is None:
            if output is not None and first != output and (copy / first).exists():
                copy_output = shutil.copytree if (copy / first).is_dir() else shutil.copy2
                copy_output(copy / first, copy / output)
            continue
        line = command.replace(".venv/bin/", f"{VENV_BIN}/")
        done = subprocess.run(["bash", "-c", line], cwd=copy, capture_output=True, text=True, timeout=300, env=env)
        assert done.returncode == 0, f"{command}\n{done.stderr[-2000:]}"
    status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"], cwd=copy,
                            capture_output=True, text=True, check=True).stdout
    assert status == "", f"documented commands left files in the repository:\n{status}"


def test_documented_commands_exit_0_and_leave_nothing_in_the_repository(copy):
    commands = [c for c in _commands() if _skip_reason(c) is None and not _needs_shared(c)]
    assert any(c.startswith(".venv/bin/slewing solve") for c in commands)
    _run_commands(copy, commands)


@pytest.mark.skipif(not OPENFAST.is_dir(), reason=f"the README's `slewing loads` commands read the public NREL "
                    f"OpenFAST outputs in {OPENFAST}, which is absent (the README says what lives in ../shared)")
def test_documented_commands_on_the_openfast_files_exit_0(copy):
    commands = [c for c in _commands() if _skip_reason(c) is None and _needs_shared(c)]
    assert any(c.startswith(".venv/bin/slewing loads") for c in commands)
    _run_commands(copy, commands)


@pytest.fixture(scope="module")
def example_fmus(tmp_path_factory):
    """Builds an example FMU the first time a block names it; returns {path in the docs: built FMU}."""
    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu

    built = {}

    def build(name: str) -> Path:
        if name not in built:
            path = tmp_path_factory.mktemp("example_fmu") / Path(name).name
            built[name] = build_fmu(ROOT / EXAMPLE_FMUS[name], path, mesh="coarse", win64=False)
        return built[name]
    return build


def test_python_examples_run(copy, example_fmus):
    blocks = _blocks("python")
    assert any("solve(" in b for b in blocks) and any("simulate_fmu(" in b for b in blocks)
    for block in blocks:
        for name in EXAMPLE_FMUS:
            if name in block:
                block = block.replace(name, str(example_fmus(name)))
        done = subprocess.run([sys.executable, "-c", block], cwd=copy, capture_output=True, text=True, timeout=300,
                              env={**os.environ, **_aot_path()})
        assert done.returncode == 0, f"{block}\n{done.stderr[-2000:]}"
