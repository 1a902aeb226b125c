"""The compile registry of the numba loops (the load distribution's and the friction's kernels).

numba is optional (it is not part of the FMU's run-time requirements): without it
:data:`AVAILABLE` is False and every model runs its numpy code, which gives the same results to
round-off. A kernel module enters each loop with :func:`loop_factory` in its own ``KERNELS`` list;
the loop is compiled when first asked for (or loaded from numba's on-disk cache, ``__pycache__``
beside the kernel's source, keyed by the source's content).

The same loops compiled ahead of time (``fmu_build/aot.py``: numba's ``pycc``, an extension module
named :data:`AOT_MODULE` that needs numpy only) take the place of numba where that module can be
imported and was compiled from these sources (:func:`kernel_source_hash`): an FMU built with
``--aot`` carries it instead of numba and llvmlite. A module of other sources is not used.
"""
from __future__ import annotations

import functools
import hashlib
import importlib
import importlib.util
import os

#: the extension module of the loops compiled ahead of time (fmu_build/aot.py) for any x86-64 CPU
AOT_MODULE = "slewing_kernels"
#: ... and the modules by target (:data:`slewing_model.numerics.targets.PORTABLE_TARGETS`): an ``--aot`` FMU
#: carries one for each and takes the first its CPU can run (:func:`aot_targets`)
AOT_MODULES = {"x86-64-v3": "slewing_kernels_v3", "generic": AOT_MODULE}
#: the sources the loops are compiled from: the kernels, what they take from other modules, this registry
KERNEL_SOURCES = ("distribution/kernel.py", "friction/kernel.py", "life/kernel.py", "bearing/contact.py",
                  "rings/reduced_operator.py", "numerics/compiled.py")


def kernel_source_hash() -> int:
    """A 62-bit hash of :data:`KERNEL_SOURCES`: what an ahead-of-time module was compiled from."""
    digest = hashlib.sha256()
    package = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))      # slewing_model/
    for name in KERNEL_SOURCES:
        with open(os.path.join(package, name), "rb") as fh:
            digest.update(fh.read().replace(b"\r\n", b"\n"))
    return int.from_bytes(digest.digest()[:8], "little") >> 2


def aot_name(function) -> str:
    """The name of ``function``'s loop in the ahead-of-time module: ``<subpackage>_<name>``
    (``distribution__trial_point``)."""
    return f"{function.__module__.split('.')[-2]}_{function.__name__}"


def aot_targets(cpuinfo: str | None = None) -> list:
    """The targets (:data:`AOT_MODULES`) whose ahead-of-time module this CPU may run, the fastest first: from
    the one its features allow (:func:`~slewing_model.numerics.targets.portable_target` of
    :func:`~slewing_model.numerics.targets.cpuinfo_features`, ``cpuinfo`` the text of ``/proc/cpuinfo``, read
    by default) down to the generic one."""
    from .targets import PORTABLE_TARGETS, cpuinfo_features, portable_target

    names = [name for name, _ in PORTABLE_TARGETS]
    return names[names.index(portable_target(cpuinfo_features(cpuinfo))):]


@functools.lru_cache(maxsize=1)
def aot_kernels():
    """The ahead-of-time module of the first of :func:`aot_targets` that can be imported and whose
    ``source_hash()`` is :func:`kernel_source_hash`; None where there is none (its target: :func:`aot_target`)."""
    for target in aot_targets():
        try:
            module = importlib.import_module(AOT_MODULES[target])
            if module.source_hash() == kernel_source_hash():
                return module
        except (ImportError, AttributeError, OSError):
            continue
    return None


def aot_target() -> str | None:
    """The target (:data:`AOT_MODULES`) of the ahead-of-time module in use (:func:`aot_kernels`), or None."""
    module = aot_kernels()
    return None if module is None else {v: k for k, v in AOT_MODULES.items()}.get(module.__name__)


def _numba_installed() -> bool:
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False


#: numba can be imported here (it is imported, and the loop compiled, only when first asked for:
#: importing numba also imports scipy, which the run-time part does not otherwise need)
AVAILABLE = aot_kernels() is not None or _numba_installed()

#: how the friction model may run its loops (``kernel`` of ``friction_torque``)
KERNEL_CHOICES = ("auto", "numpy", "compiled")


def use_compiled(kernel: str, name: str = "kernel") -> bool:
    """Whether ``kernel`` (one of :data:`KERNEL_CHOICES`) runs the compiled loops here:
    "compiled", or "auto" where numba is installed. ValueError naming ``name`` for another
    value, or for "compiled" where numba is not installed."""
    if kernel not in KERNEL_CHOICES:
        raise ValueError(f"{name} = {kernel!r}: must be 'auto', 'numpy' or 'compiled'")
    if kernel == "compiled" and not AVAILABLE:
        raise ValueError(f"{name} = 'compiled' needs numba, which is not installed in this Python, or the "
                         f"loops compiled ahead of time ({AOT_MODULE}, fmu_build/aot.py) "
                         "(pip install numba, or use 'auto' or 'numpy')")
    return AVAILABLE and kernel != "numpy"


def c_order(signature: str) -> str:
    """``signature`` (``returns(arguments)``) with every array argument in C order (``f8[:, :]`` ->
    ``f8[:, ::1]``; what it returns is left as it is). numba types an array of
    ``f8[:, :]`` as of any layout: its strides are known only at run time and LLVM does not turn the loops
    over its last axis into vector operations. In C order it does (measured: the friction's points'
    coefficients of a pitch bearing's step 100 -> 58 us). The caller must then pass arrays in C order:
    numba refuses others (TypeError: no matching definition)."""
    depth, start = 0, len(signature)
    for start in range(len(signature) - 1, -1, -1):         # the arguments: from the '(' matching the last ')'
        depth += {")": 1, "(": -1}.get(signature[start], 0)
        if depth == 0:
            break
    arguments = signature[start:].replace("[:, :, :]", "[:, :, ::1]").replace("[:, :]", "[:, ::1]")
    return signature[:start] + arguments.replace("[:]", "[::1]")


def compile_loop(function, signature: str, helpers: tuple = (), error_model: str = "python", inline: tuple = (),
                 fastmath: frozenset = frozenset()):
    """``function`` compiled by numba for ``signature`` (eager, numba's on-disk cache), after the
    ``helpers`` it calls (names in its module).

    numba takes the functions a compiled function calls from the module's globals when it
    compiles it: they must be compiled functions by then, so each helper is compiled in place
    of its Python definition, once. The Python definitions are used by nothing else (the numpy
    paths are the library's own code). ``error_model`` "numpy": a division by zero gives inf or
    NaN as numpy does, instead of raising. ``inline``: the helpers numba inlines into their callers.
    ``fastmath``: LLVM's fast-math flags for the loop and its helpers (numba's ``fastmath``; a module's
    ``FASTMATH``); none of those that assume no NaN or infinity, which the loops' checks look for."""
    import numba

    compile_helpers(function.__globals__, helpers, error_model, inline, fastmath)
    return numba.njit(signature, cache=True, nogil=True, error_model=error_model,
                      fastmath=set(fastmath))(function)


def compile_helpers(module: dict, helpers: tuple, error_model: str = "python", inline: tuple = (),
                    fastmath: frozenset = frozenset()) -> None:
    """Each of ``helpers`` (names in the globals ``module``) compiled in place of its Python
    definition, once (:func:`compile_loop`; ``fmu_build/aot.py`` before it exports the loops)."""
    import numba

    for name in helpers:
        if not hasattr(module[name], "py_func"):          # not compiled yet
            module[name] = numba.njit(cache=True, nogil=True, error_model=error_model, fastmath=set(fastmath),
                                      inline="always" if name in inline else "never")(module[name])


def loop_factory(registry: list, compile_function, function, signature: str):
    """The factory of ``function`` compiled by ``compile_function`` for ``signature``: its first call
    compiles the loop (or loads it from numba's on-disk cache), later calls return it. Entered in
    ``registry`` (a module's :data:`KERNELS`), from which :func:`compile_all` compiles them all
    when a simulator is built, so that compiling lands in an FMU's instantiation and never in a
    step, and ``build_fmu.py`` ships their cache."""
    @functools.lru_cache(maxsize=1)
    def factory():
        aot = aot_kernels()
        if aot is not None:
            return getattr(aot, aot_name(function))
        return compile_function(function, signature)

    factory.__doc__ = (f"The compiled :func:`{function.__name__}` (ahead of time where its module is here; else "
                       f"numba, eager signature, numba's on-disk cache).")
    factory.signature = signature
    registry.append((factory, function))
    return factory
