"""Threads of the BLAS behind numpy, for the length of a computation.

A co-simulation step works on matrices of a few hundred rows (the reduced ring operator of
the flexible solver). OpenBLAS runs such products and inversions on all cores by default;
its threads spin while they wait, so when other processes or other FMUs share the cores,
a step takes several times longer and its tail far longer (measured on the 150-ball pitch
bearing with two busy cores: median 23 ms and 99th percentile 264 ms with two threads,
5.6 ms and 12.6 ms with one). :func:`blas_threads` sets the number of threads for a block
of code and restores it afterwards, so the host's own numpy work is not affected.

It talks to the OpenBLAS that numpy loaded (numpy's wheels bundle one, as
``scipy_openblas``) through ``ctypes``, found among the process's mapped libraries
(``/proc/self/maps``, Linux) or, on Windows, beside numpy's package (``numpy.libs``, the win64
FMU's numpy 1.26). Elsewhere, or with another BLAS, it does nothing. Run-time
module: the standard library only.
"""
from __future__ import annotations

import contextlib
import ctypes
import functools
import os

#: (get, set) function names of OpenBLAS builds: numpy's bundled scipy-openblas (64-bit
#: integers, suffixed), then a plain system OpenBLAS
_SYMBOLS = (("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
            ("scipy_openblas_get_num_threads", "scipy_openblas_set_num_threads"),
            ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
            ("openblas_get_num_threads", "openblas_set_num_threads"))


@functools.lru_cache(maxsize=1)
def _openblas_threads():
    """(get, set) of the thread count of the OpenBLAS loaded in this process, or None."""
    for path in _openblas_paths():
        try:
            library = ctypes.CDLL(path)
        except OSError:
            continue
        for get_name, set_name in _SYMBOLS:
            get, set_ = getattr(library, get_name, None), getattr(library, set_name, None)
            if get is not None and set_ is not None:
                get.restype, get.argtypes = ctypes.c_int, []
                set_.restype, set_.argtypes = None, [ctypes.c_int]
                return get, set_
    return None


def _openblas_paths() -> list:
    """The files of the OpenBLAS numpy loaded: among the process's mapped libraries (``/proc/self/maps``,
    Linux), else the DLLs beside numpy's package where its Windows wheel keeps them (``numpy.libs``,
    ``numpy/.libs``; loaded already, so that ``ctypes`` hands back numpy's own copy)."""
    import numpy  # (its BLAS must be loaded to be found)

    paths = set()
    if os.name == "nt":         # (under wine "/proc/self/maps" may be the Linux file of wine's process)
        package = os.path.dirname(numpy.__file__)
        for folder in (package + ".libs", os.path.join(package, ".libs")):
            if os.path.isdir(folder):
                paths.update(os.path.join(folder, name) for name in os.listdir(folder)
                             if "openblas" in name.lower() and name.lower().endswith(".dll"))
    else:
        try:
            with open("/proc/self/maps") as fh:
                paths = {line.split()[-1] for line in fh if "openblas" in line.lower()}
        except OSError:
            pass
    return sorted(p for p in paths if os.path.isfile(p))


def blas_thread_control() -> bool:
    """True when :func:`blas_threads` can set numpy's BLAS threads in this process."""
    return _openblas_threads() is not None


@contextlib.contextmanager
def blas_threads(count: int | None):
    """Run the block with ``count`` BLAS threads (None: leave them as they are).

    Examples
    --------
    >>> import numpy as np
    >>> with blas_threads(1):
    ...     x = np.linalg.inv(np.eye(3))
    """
    api = None if count is None else _openblas_threads()
    if api is None:
        yield
        return
    get, set_ = api
    before = get()
    if before == count:
        yield
        return
    set_(count)
    try:
        yield
    finally:
        set_(before)
