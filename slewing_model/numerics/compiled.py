"""The compile registry of the numba loops (the load distribution's and the friction's kernels).

numba is optional (it is not part of the FMU's run-time requirements): without it
:data:`AVAILABLE` is False and every model runs its numpy code, which gives the same results to
round-off. A kernel module enters each loop with :func:`loop_factory` in its own ``KERNELS`` list;
the loop is compiled when first asked for (or loaded from numba's on-disk cache, ``__pycache__``
beside the kernel's source, keyed by the source's content).
"""
from __future__ import annotations

import functools
import importlib.util


def _numba_installed() -> bool:
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False


#: numba can be imported here (it is imported, and the loop compiled, only when first asked for:
#: importing numba also imports scipy, which the run-time part does not otherwise need)
AVAILABLE = _numba_installed()

#: how the friction model may run its loops (``kernel`` of ``friction_torque``)
KERNEL_CHOICES = ("auto", "numpy", "compiled")


def use_compiled(kernel: str, name: str = "kernel") -> bool:
    """Whether ``kernel`` (one of :data:`KERNEL_CHOICES`) runs the compiled loops here:
    "compiled", or "auto" where numba is installed. ValueError naming ``name`` for another
    value, or for "compiled" where numba is not installed."""
    if kernel not in KERNEL_CHOICES:
        raise ValueError(f"{name} = {kernel!r}: must be 'auto', 'numpy' or 'compiled'")
    if kernel == "compiled" and not AVAILABLE:
        raise ValueError(f"{name} = 'compiled' needs numba, which is not installed in this Python "
                         "(pip install numba, or use 'auto' or 'numpy')")
    return AVAILABLE and kernel != "numpy"


def compile_loop(function, signature: str, helpers: tuple = (), error_model: str = "python"):
    """``function`` compiled by numba for ``signature`` (eager, numba's on-disk cache), after the
    ``helpers`` it calls (names in its module).

    numba takes the functions a compiled function calls from the module's globals when it
    compiles it: they must be compiled functions by then, so each helper is compiled in place
    of its Python definition, once. The Python definitions are used by nothing else (the numpy
    paths are the library's own code). ``error_model`` "numpy": a division by zero gives inf or
    NaN as numpy does, instead of raising."""
    import numba

    module = function.__globals__
    for name in helpers:
        if not hasattr(module[name], "py_func"):          # not compiled yet
            module[name] = numba.njit(cache=True, nogil=True, error_model=error_model)(module[name])
    return numba.njit(signature, cache=True, nogil=True, error_model=error_model)(function)


def loop_factory(registry: list, compile_function, function, signature: str):
    """The factory of ``function`` compiled by ``compile_function`` for ``signature``: its first call
    compiles the loop (or loads it from numba's on-disk cache), later calls return it. Entered in
    ``registry`` (a module's :data:`KERNELS`), from which :func:`compile_all` compiles them all
    when a simulator is built, so that compiling lands in an FMU's instantiation and never in a
    step, and ``build_fmu.py`` ships their cache."""
    @functools.lru_cache(maxsize=1)
    def factory():
        return compile_function(function, signature)

    factory.__doc__ = f"The compiled :func:`{function.__name__}` (numba, eager signature, numba's on-disk cache)."
    registry.append((factory, function))
    return factory
