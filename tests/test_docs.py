"""What users read holds together: links and named files exist, versions agree, no work log.

The Sphinx build itself (``make docs``, warnings as errors) checks the site's cross-references and
its API pages; these tests check what Sphinx does not: the README's links (GitHub renders it, not
Sphinx), every repository file a page names in backticks, the version in its three places, the
shape of the validation pages, and the repository's root.
"""
import re
import subprocess
import tomllib
from pathlib import Path

import pytest

import slewing_model

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SHARED = ROOT.parent / "shared"
#: the pages users read: the README, the changelog and the site's Markdown pages
PAGES = sorted([ROOT / "README.md", ROOT / "CHANGELOG.md"]
               + [p for p in DOCS.rglob("*.md") if "_build" not in p.parts])
#: top-level folders and files whose paths a page may name in backticks
TOP = ("examples", "docs", "slewing_model", "slewing_drives", "slewing_turbine", "tests", "benchmarks", "references", "fmu_src",
       "fmu_build", "build_fmu.py", "pyproject.toml", "Makefile", "LICENSE", "CHANGELOG.md", "README.md")
#: outputs of commands, not files of the repository
OUTPUTS = ("results/", "build/", "docs/_build")


def _text(page: Path) -> str:
    """The page without its fenced code blocks (commands may name files they create)."""
    return re.sub(r"^(```|~~~).*?^\1", "", page.read_text(), flags=re.S | re.M)


def _links(page: Path):
    """Relative Markdown links of a page: (target without its #anchor, as written)."""
    for target in re.findall(r"\]\(([^)\s]+)\)", _text(page)):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue                                    # another site, or an anchor of this page
        yield target.split("#")[0], target


def _named_paths(page: Path):
    """Repository paths a page names in backticks (``examples/bearings/table1.toml``)."""
    for quoted in re.findall(r"`([^`\s]+)`", _text(page)):
        if quoted.startswith(OUTPUTS) or re.search(r"[<>*{}$]|NAME|\.\.\.", quoted):
            continue                                    # an output, or a pattern with a placeholder
        if quoted.startswith("../shared/") or quoted.split("/")[0] in TOP and ("/" in quoted or "." in quoted):
            yield quoted


def test_pages_are_found():
    names = {p.relative_to(ROOT).as_posix() for p in PAGES}
    assert {"README.md", "CHANGELOG.md", "docs/index.md", "docs/getting-started.md"} <= names


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_internal_link_exists(page):
    missing = [written for target, written in _links(page) if target and not (page.parent / target).exists()]
    assert not missing, f"{page.relative_to(ROOT)} links to files that do not exist: {missing}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_file_named_exists(page):
    missing = []
    for path in _named_paths(page):
        if path.startswith("../shared/"):
            if not SHARED.is_dir():
                continue                                # beside a clone, not in it: README says so
            found = (ROOT / path).exists()
        else:
            found = (ROOT / path.rstrip("/")).exists()
        if not found:
            missing.append(path)
    assert not missing, f"{page.relative_to(ROOT)} names files that do not exist: {missing}"


def test_the_version_is_the_same_in_pyproject_the_package_and_the_changelog():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    released = re.findall(r"^## \[(\d+\.\d+\.\d+)\]", (ROOT / "CHANGELOG.md").read_text(), flags=re.M)
    assert released, "CHANGELOG.md has no '## [X.Y.Z]' version heading"
    assert pyproject == slewing_model.__version__ == released[0]


def test_the_changelog_keeps_a_changelog_form():
    text = (ROOT / "CHANGELOG.md").read_text()
    assert text.startswith("# Changelog")
    versions = re.findall(r"^## \[(\d+)\.(\d+)\.(\d+)\] - (\d{4}-\d{2}-\d{2})$", text, flags=re.M)
    assert versions, "every released version is '## [X.Y.Z] - YYYY-MM-DD'"
    numbers = [tuple(map(int, v[:3])) for v in versions]
    assert numbers == sorted(numbers, reverse=True), "newest version first"
    for heading in re.findall(r"^### (.+)$", text, flags=re.M):
        assert heading in ("Added", "Changed", "Deprecated", "Removed", "Fixed", "Security")


HISTORY = re.compile(r"([a-z]+th|first|second|third) turn|issue [0-9]+|this session|between sessions|this week",
                     re.I)


@pytest.mark.parametrize("page", [p for p in PAGES if p.name != "CHANGELOG.md"],
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_development_history_in_what_users_read(page):
    lines = [line for line in page.read_text().splitlines() if HISTORY.search(line) and "github.com" not in line]
    assert not lines, f"{page.relative_to(ROOT)} tells how the work went:\n" + "\n".join(lines[:5])


def test_no_commit_hash_names_a_baseline():
    for page in PAGES:
        hits = re.findall(r"--baseline\s+([0-9a-f]{7,40})\b", page.read_text())
        assert not hits, f"{page.relative_to(ROOT)} names a baseline by its hash: {hits}"


def test_the_readme_is_for_a_first_hour():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 200
    for command in ("make demo", "make test"):
        assert command in text


VALIDATION = sorted(p for p in (DOCS / "validation").glob("*.md") if p.name != "index.md")


def test_there_is_a_validation_page_per_reference():
    assert len(VALIDATION) >= 6, [p.name for p in VALIDATION]


@pytest.mark.parametrize("page", VALIDATION, ids=lambda p: p.name)
def test_every_validation_page_has_its_figure_its_table_and_their_command(page):
    text = page.read_text()
    figures = re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", text)
    assert figures, f"{page.name} shows no figure"
    for figure in figures:
        assert (page.parent / figure).is_file(), figure
    assert re.search(r"^\|.*\|\s*\n\|[-:| ]+\|\s*$", text, flags=re.M), f"{page.name} has no table"
    assert re.search(r"^```sh\n.*?\S.*?^```", text, flags=re.S | re.M), f"{page.name} names no command"


def test_the_repository_root_holds_what_the_design_names():
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    top = {line.split("/")[0] for line in tracked.splitlines()}
    allowed = {"pyproject.toml", "fmu_src", "slewing_model", "slewing_drives", "slewing_turbine", "build_fmu.py", "fmu_build", "tests",
               "examples", "benchmarks", "references", "docs", "README.md", "LICENSE", "CHANGELOG.md", "Makefile",
               ".gitignore", ".ci"}
    assert top <= allowed, sorted(top - allowed)


def test_the_fmu_variables_page_says_what_the_fmu_says():
    """Every variable of the FMU stands on the variables page with its unit and its description as the
    FMU's modelDescription.xml gives them (fmu_src/bearing_variables.py writes both)."""
    import sys

    sys.path.insert(0, str(ROOT / "fmu_src"))
    import bearing_variables as variables

    rows = {}
    for line in (DOCS / "fmu" / "variables.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) > 2 and re.fullmatch(r"`[^`]+`", cells[0]):
            rows[cells[0].strip("`")] = cells
    named = [(name, unit, text) for name, unit, text in variables.INPUTS + variables.OUTPUTS]
    named += [(name, unit, text) for name, unit, text, *_ in variables.REAL_PARAMETERS]
    assert named and all(name in rows for name, _, _ in named), sorted({n for n, _, _ in named} - set(rows))
    for name, unit, text in named:
        assert unit in rows[name], (name, unit)
        assert any(cell.startswith(text) for cell in rows[name]), (name, text)
    for name, choices, text in variables.INTEGER_PARAMETERS:
        assert any(cell.startswith(text) for cell in rows[name]), (name, text)
