"""The package drawn by its imports: no import cycle, at most four modules of its own beside
the subpackages, the run-time part importing numpy only, and the code map (docs/theory/code-map.md) naming what
is there (and nothing that is not).

The import graph is read from the source with ast, lazy imports inside functions included, as
``../shared/tools/import_cycles.py`` reads it; an edge from a module to its own package's
``__init__`` does not count (Python runs that ``__init__`` first in any case)."""
import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "slewing_model"


def _modules() -> dict[str, Path]:
    modules = {}
    for path in PACKAGE.rglob("*.py"):
        name = ".".join(path.relative_to(ROOT).with_suffix("").parts)
        modules[name.removesuffix(".__init__")] = path
    return modules


def _edges(modules: dict[str, Path]) -> dict[str, set[str]]:
    edges = {}
    for name, path in modules.items():
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        targets = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package[:len(package) - node.level + 1] + ([node.module] if node.module else []))
                found = [base] + [f"{base}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                found = [a.name for a in node.names]
            else:
                continue
            targets.update(t for t in found if t in modules and t != name
                           and not (modules[t].name == "__init__.py" and name.startswith(t + ".")))
        edges[name] = targets
    return edges


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in edges:
        if v not in index:
            visit(v)
    return found


def test_the_cycle_finder_finds_a_planted_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_the_package_has_no_import_cycle():
    assert _cycles(_edges(_modules())) == []


def test_at_most_four_modules_of_its_own_beside_the_subpackages():
    own = sorted(p.name for p in PACKAGE.glob("*.py") if p.name != "__init__.py")
    assert len(own) <= 4, own


def test_the_run_time_part_imports_numpy_and_the_standard_library_only():
    """What the FMU carries (RUNTIME_MODULES): importing all of it loads no other package, and no
    module of slewing_model that the list leaves out (the FMU would not find it)."""
    code = ("import importlib, sys\n"
            "from slewing_model import RUNTIME_MODULES\n"
            "for m in RUNTIME_MODULES:\n"
            "    importlib.import_module(('slewing_model.' + m.replace('/', '.')).removesuffix('.__init__'))\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} - set(sys.stdlib_module_names)))\n"
            "print(sorted(m for m in sys.modules if m.startswith('slewing_model')))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    packages, loaded = map(ast.literal_eval, out.stdout.strip().splitlines())
    third_party = set(packages) - {"slewing_model", "__main__"}
    third_party = {m for m in third_party if not m.startswith(("_distutils_hack", "__editable__"))}
    assert third_party == {"numpy"}
    from slewing_model import RUNTIME_MODULES

    listed = {("slewing_model." + m.replace("/", ".")).removesuffix(".__init__") for m in RUNTIME_MODULES}
    assert set(loaded) - listed == set()


def test_the_runtime_list_names_every_run_time_module_that_exists():
    from slewing_model import RUNTIME_MODULES

    missing = [m for m in RUNTIME_MODULES if not (PACKAGE / f"{m}.py").exists()]
    assert missing == []
    # every subpackage the run-time modules live in carries its __init__
    folders = {m.rsplit("/", 1)[0] for m in RUNTIME_MODULES if "/" in m}
    assert {f"{f}/__init__" for f in folders} <= set(RUNTIME_MODULES)


def _code_map() -> str:
    text = (ROOT / "docs" / "theory" / "code-map.md").read_text()
    start = text.index("```\nslewing_model/")
    return text[start:text.index("```", start + 3)]


def test_the_code_map_names_every_subpackage_and_module_of_its_own():
    code_map = _code_map()
    for sub in sorted(p.parent.name for p in PACKAGE.glob("*/__init__.py")):
        assert re.search(rf"^\s+{sub}/", code_map, re.M), f"{sub}/ is not in the code map (docs/theory/code-map.md)"
    for own in sorted(p.name for p in PACKAGE.glob("*.py") if p.name != "__init__.py"):
        assert own in code_map, f"{own} is not in the code map (docs/theory/code-map.md)"


def test_every_file_the_code_map_names_exists():
    """Each ``name.py`` or ``name/`` indented under a folder of the map is there."""
    folders = [ROOT]
    for line in _code_map().splitlines()[1:]:
        entry = line.split()[0] if line.strip() else ""
        if not entry or not re.fullmatch(r"[\w./]+", entry) or not entry.endswith(("/", ".py,", ".py")):
            continue
        depth = (len(line) - len(line.lstrip())) // 4
        if line.startswith(" ") and depth == 0:
            continue
        parent = folders[depth] if depth < len(folders) else folders[-1]
        path = (ROOT if depth == 0 else parent) / entry.rstrip(",")
        assert path.exists(), f"the code map names {path.relative_to(ROOT)}, which is not there"
        if entry.endswith("/"):
            folders[depth + 1:] = [path]
