"""The bytecode an FMU carries beside its Python sources (build time only).

Python compiles a module's source the first time it imports it and writes the result to the
``__pycache__`` folder beside it, where later imports read it. An FMU is unpacked afresh by most
hosts (fmpy into a new temporary folder at every simulation, the C hosts once per installation),
sometimes into a read-only folder: without bytecode in it, every such instantiation compiles the
whole runtime it imports (the standard library's modules, numpy, slewing_model; about 1.2 s of CPU
on the pitch bearing FMU, three to four times the rest of its instantiation), and a read-only copy does so
at every instantiation. So the FMU carries the bytecode of every module (:func:`bytecode`), compiled
here for the Python it runs (same minor version: the runtime's, or for ``--runtime host`` the
building one's; another version's Python ignores the files and compiles as before).

The files are hash-based (PEP 552): valid whatever the files' times (unpacking sets them to the time
of unpacking, which would invalidate the usual time-stamped files). Those of the model's code in
``resources/`` (slewing_model, the slave) are checked: an import takes them where the source's hash
matches the one they record and compiles the source otherwise, so that an edited source is never run
stale. Those of the runtime (the standard library, numpy), which nobody edits in an FMU, are unchecked:
hashing their 5 MB of source would cost 2 % of every instantiation. They name their source by its path
inside the FMU (``slewing_model/rings/compliance.py``), not by the building machine's: Python replaces
that name by the file's path when it loads them.
"""
from __future__ import annotations

import importlib.util
import marshal
import subprocess
import sys
from pathlib import Path, PurePosixPath

#: PEP 552's flags of a hash-based file whose source is checked at import, and of one whose source is not
_CHECKED_HASH, _UNCHECKED_HASH = 0b11, 0b01


def bytecode_path(source: str) -> str:
    """The bytecode file of the source ``source`` (a path with ``/``): ``a/b/c.py`` ->
    ``a/b/__pycache__/c.cpython-311.pyc`` (this Python's cache tag)."""
    path = PurePosixPath(source)
    return str(path.parent / "__pycache__" / f"{path.stem}.{sys.implementation.cache_tag}.pyc")


def bytecode(source: bytes, name: str, checked: bool = True) -> bytes | None:
    """The hash-based bytecode file of ``source`` (what ``py_compile`` writes with ``invalidation_mode``
    ``CHECKED_HASH``, or ``UNCHECKED_HASH`` where not ``checked``), its code naming the file ``name``; None
    for a source this Python cannot compile (a template, another version's syntax), which the FMU then
    compiles or never imports as before."""
    try:
        code = compile(source, name, "exec", dont_inherit=True, optimize=0)
    except (SyntaxError, ValueError):
        return None
    flags = _CHECKED_HASH if checked else _UNCHECKED_HASH
    return (importlib.util.MAGIC_NUMBER + flags.to_bytes(4, "little")
            + importlib.util.source_hash(source) + marshal.dumps(code))


def compile_tree(root: Path, names_from: Path | None = None, checked: bool = False) -> int:
    """Write the bytecode of every ``.py`` below ``root`` beside it (:func:`bytecode_path`; unchecked
    unless ``checked``: a runtime's), each naming its source by its path relative to ``names_from``
    (default ``root``); returns the number written."""
    root = Path(root)
    base = Path(names_from) if names_from is not None else root
    written = 0
    for source in sorted(root.rglob("*.py")):
        if "__pycache__" in source.parts or not source.is_file():
            continue
        data = bytecode(source.read_bytes(), source.relative_to(base).as_posix(), checked)
        if data is None:
            continue
        target = root / bytecode_path(source.relative_to(root).as_posix())
        target.parent.mkdir(exist_ok=True)
        target.write_bytes(data)
        written += 1
    return written


#: run in a child Python: imports the modules named by argv[3:] from the folder argv[1] with every source
#: that ``dataclasses`` executes compiled on the way, and writes them to argv[2] (:func:`dataclass_code`)
_DATACLASS_RECORDER = """
import builtins, dataclasses, importlib, importlib.util, marshal, sys
codes = {}
def exec_(source, globals=None, locals=None, /):
    if isinstance(source, str):
        if source not in codes:
            codes[source] = compile(source, '<string>', 'exec', dont_inherit=True)
        source = codes[source]
    builtins.exec(source, globals, locals)
dataclasses.exec = exec_
sys.path.insert(0, sys.argv[1])
for name in sys.argv[3:]:
    importlib.import_module(name)
with open(sys.argv[2], 'wb') as fh:
    fh.write(importlib.util.MAGIC_NUMBER + marshal.dumps(codes))
"""


def dataclass_code(folder: Path, modules, output: Path) -> int:
    """Write to ``output`` the compiled methods of the dataclasses that importing ``modules`` (dotted names,
    found in ``folder`` first) creates, for ``fmu_src/dataclass_code.py``: :data:`importlib.util.MAGIC_NUMBER`,
    then the marshalled dict of the sources ``dataclasses`` executes to the code objects compiled from them
    (as ``exec`` compiles them: file name ``<string>``, no future features). Imported in a child of this
    Python, which writes no bytecode; returns the number of sources."""
    run = subprocess.run([sys.executable, "-B", "-c", _DATACLASS_RECORDER, str(folder), str(output), *modules],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"compiling the dataclasses' methods of {', '.join(modules)} failed:\n{run.stderr[-3000:]}")
    data = Path(output).read_bytes()
    return len(marshal.loads(data[len(importlib.util.MAGIC_NUMBER):]))
