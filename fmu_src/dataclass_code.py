"""The compiled methods of slewing_model's dataclasses, carried by the FMU (FMU run time).

A dataclass writes the source of its methods (``__init__``, ``__repr__``, ``__eq__``, ``__hash__``,
a frozen class's ``__setattr__`` and ``__delattr__``) when its class is created, and compiles it: for
the thirty-odd classes an instance imports (the bearing, the load distribution, the simulator, the
life accumulators), about 40 ms of its instantiation. ``build_fmu.py`` compiles those sources once
(:func:`fmu_build.bytecode.dataclass_code`) into ``dataclass_code.bin`` beside this module, and
within :func:`precompiled` a dataclass takes its code from there instead of compiling it: the same
code objects, compiled from the same source by the same Python version. A source the file lacks (an
edited module), or a file of another Python version, is compiled as before.

No ``from __future__`` import here: ``exec`` compiles a source with the future features of the module
that calls it, and a source this module hands on must be compiled as ``dataclasses`` would (which has none).
"""
import builtins
import contextlib
import dataclasses
import importlib.util
import marshal
import os

#: the file of the compiled methods, beside this module (written by build_fmu.py)
CODE_FILE = "dataclass_code.bin"

_codes = None


def codes() -> dict:
    """The compiled methods: source -> code object, read once; empty where the file is missing or of another
    Python version (its first bytes are :data:`importlib.util.MAGIC_NUMBER`)."""
    global _codes
    if _codes is None:
        _codes = {}
        try:
            with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), CODE_FILE), "rb") as fh:
                data = fh.read()
            if data.startswith(importlib.util.MAGIC_NUMBER):
                _codes = marshal.loads(data[len(importlib.util.MAGIC_NUMBER):])
        except (OSError, ValueError, EOFError, TypeError):
            pass
    return _codes


@contextlib.contextmanager
def precompiled():
    """Within it, the dataclasses created take their methods' code from :func:`codes` where it holds their
    source (``dataclasses`` executes each source it writes with ``exec``: here the code compiled from it)."""
    known = codes()
    if not known:
        yield
        return
    previous = dataclasses.__dict__.get("exec")

    def exec_(source, globals=None, locals=None, /):
        code = known.get(source) if isinstance(source, str) else None
        builtins.exec(source if code is None else code, globals, locals)

    dataclasses.exec = exec_
    try:
        yield
    finally:
        if previous is None:
            del dataclasses.exec
        else:
            dataclasses.exec = previous
