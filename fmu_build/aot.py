"""The loops compiled ahead of time (build time only; used by ``build_fmu.py``, whose default they are: ``--aot``).

The load distribution's, the friction's and the life map's loops (``slewing_model/distribution/kernel.py``,
``slewing_model/friction/kernel.py``, ``slewing_model/life/kernel.py``: every entry of their ``KERNELS``) are compiled once here, by
numba's ahead-of-time compiler (``numba.pycc``), into CPython extension modules, one for each target of
:data:`slewing_model.numerics.compiled.AOT_MODULES` (a CPU of the x86-64 psABI's level 3, AVX2 and FMA; any
x86-64 CPU), of which the FMU takes the first its CPU can run (``aot_kernels``). Each module needs
numpy only, not numba or llvmlite (LLVM, 179 of a numba FMU's 270 MB unpacked), and starts
without compiling or reading a cache. Each loop is exported under
:func:`~slewing_model.numerics.compiled.aot_name` with its eager signature and its module's
error model; ``source_hash()`` returns the hash of the sources it was compiled from, which the
registry checks before it takes the module (:func:`slewing_model.numerics.compiled.aot_kernels`).

The compilation (about a minute a target) runs in a child process, since it compiles the kernels'
helpers in place in their modules; its product is cached under ``<cache>/<key>/`` (:func:`aot_cache_dir`;
key: the sources' hash, numba's version, the Python ABI; the file name says the target). A process
that finds the module missing compiles it under a lock (a ``.lock`` file beside it): another one that needs it
meanwhile (two test workers, two builds) waits and takes it from the cache. ``make test`` compiles
them first (the Makefile's ``COMPILE_LOOPS``: :func:`prepare_cache`).

numba's ``pycc`` is pending deprecation ("replacement technology is being developed"); it is in
the pinned numba 0.68.1, and its modules give numba's JIT numbers on the benchmark cases (the generic
module to the last bit, the x86-64-v3 one to 1e-9: docs/fmu/hosts.md). The win64 half's module is made
from the same kernels by :func:`fmu_build.win64.aot_module` (pycc under wine, linked with mingw-w64).

Run: .venv/bin/python -m fmu_build.aot [-o FOLDER] [--target x86-64-v3|generic]    (prints the modules' paths)
"""
from __future__ import annotations

import argparse
import fcntl
import importlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the modules whose KERNELS are compiled
KERNEL_MODULES = ("slewing_model.distribution.kernel", "slewing_model.friction.kernel", "slewing_model.life.kernel")


def module_file_name(target: str = "generic") -> str:
    """The extension module's file name for ``target`` and this Python
    (``slewing_kernels.cpython-311-x86_64-linux-gnu.so``; :data:`~slewing_model.numerics.compiled.AOT_MODULES`)."""
    from slewing_model.numerics.compiled import AOT_MODULES

    return AOT_MODULES[target] + sysconfig.get_config_var("EXT_SUFFIX")


#: the modules' numba_unpickle, which keeps what it unpickled as numba's JIT does (compiled after pycc's C part:
#: :func:`memoised_mixin`)
UNPICKLE_SOURCE = Path(__file__).with_name("pycc_unpickle.c")


def memoised_mixin(modulemixin, folder) -> Path:
    """pycc's C part (``modulemixin``: numba's ``pycc/modulemixin.c``) with its ``numba_unpickle`` renamed
    ``numba_unpickle_each_time`` and :data:`UNPICKLE_SOURCE`'s in its place: a C file written into ``folder``,
    compiled in place of ``modulemixin`` (here by pycc, for win64 by mingw-w64)."""
    source = Path(folder) / "modulemixin_memoised.c"
    source.write_text(f"#define numba_unpickle numba_unpickle_each_time\n#include \"{Path(modulemixin).as_posix()}\"\n"
                      f"#undef numba_unpickle\n\n{UNPICKLE_SOURCE.read_text()}")
    return source


def c_part_digest() -> str:
    """8 hex digits of what the modules' C part adds to pycc's (:data:`UNPICKLE_SOURCE`): part of the cache keys."""
    import hashlib

    return hashlib.sha256(UNPICKLE_SOURCE.read_bytes()).hexdigest()[:8]


def cache_key() -> str:
    import numba

    from slewing_model.numerics.compiled import kernel_source_hash

    return (f"{kernel_source_hash():016x}-numba{numba.__version__}-{sysconfig.get_config_var('SOABI')}-"
            f"c{c_part_digest()}")


#: the environment variable that names the modules' cache (the tests set it to the user's, which ``make test``
#: fills before they start, while their other caches are private)
CACHE_VARIABLE = "SLEWING_AOT_CACHE_DIR"


def aot_cache_dir() -> Path:
    """``$SLEWING_AOT_CACHE_DIR``, else ``$SLEWING_CACHE_DIR/aot``, else ``~/.cache/slewing_model/aot``."""
    from slewing_model.rings.superelement.build import default_cache_dir

    return Path(os.environ.get(CACHE_VARIABLE) or Path(default_cache_dir()) / "aot")


def prepare_cache(stage=None) -> list:
    """Compile the modules of every target into the cache where they are missing, the targets side by side (one
    child process each; :func:`build_kernels`): what ``make test`` runs before the tests. Returns their paths."""
    import concurrent.futures

    from slewing_model.numerics.compiled import AOT_MODULES

    with concurrent.futures.ThreadPoolExecutor(len(AOT_MODULES)) as pool:
        return list(pool.map(lambda target: build_kernels(None, stage, target), AOT_MODULES))


def build_all_kernels(output_dir=None, stage=None) -> list:
    """:func:`build_kernels` for every target (:data:`~slewing_model.numerics.compiled.AOT_MODULES`), those
    missing from the cache compiled side by side (:func:`prepare_cache`): the modules an FMU with the loops
    compiled ahead of time carries. Returns their paths."""
    from slewing_model.numerics.compiled import AOT_MODULES

    prepare_cache(stage)
    return [build_kernels(output_dir, stage, target) for target in AOT_MODULES]


def build_kernels(output_dir=None, stage=None, target: str = "generic") -> Path:
    """The ahead-of-time module of this tree's loops for ``target`` (an LLVM CPU name of
    :data:`~slewing_model.numerics.compiled.AOT_MODULES`: the CPU's own features, none of the building
    machine's), compiled, or taken from the cache; copied into ``output_dir`` where given. Returns its path."""
    say = stage or (lambda line: None)
    cached = aot_cache_dir() / cache_key() / module_file_name(target)
    if not cached.exists():
        cached.parent.mkdir(parents=True, exist_ok=True)
        with open(cached.with_suffix(".lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)            # another process compiling it: wait for its module
            if not cached.exists():
                _compile_into(cached, target, say)
    if output_dir is None:
        return cached
    Path(output_dir).mkdir(parents=True, exist_ok=True)
    target = Path(output_dir) / cached.name
    shutil.copy2(cached, target)
    return target


def _compile_into(cached: Path, target: str, say) -> None:
    """Compile the module for ``target`` in a child process and put it at ``cached`` (whole: ``os.replace``)."""
    say(f"compiling the loops ahead of time for {target} with numba's pycc (about a minute, once per change "
        "of the kernels) ...")
    with tempfile.TemporaryDirectory(prefix="slewing_aot_") as tmp:
        # TMPDIR: numba's check of the C compiler leaves a folder in the temporary directory
        # (numba.pycc.platform._gentmpfile removes neither file nor folder); here it goes with ``tmp``
        run = subprocess.run([sys.executable, "-m", "fmu_build.aot", "--compile", tmp,
                              "--target", target], cwd=ROOT, capture_output=True, text=True,
                             env={**os.environ, "TMPDIR": tmp})
        built = Path(tmp) / module_file_name(target)
        if run.returncode != 0 or not built.exists():
            raise RuntimeError(f"compiling the loops ahead of time failed (exit {run.returncode}):\n"
                               f"{run.stdout[-3000:]}\n{run.stderr[-3000:]}")
        partial = cached.with_suffix(".partial")
        shutil.copy2(built, partial)
        os.replace(partial, cached)


def _compile(output_dir: str, target: str = "generic") -> None:
    """In the child process: export every loop of :data:`KERNEL_MODULES` and ``source_hash``, for ``target``."""
    warnings.simplefilter("ignore")                      # pycc's pending deprecation
    import numba
    import numba.pycc.compiler as pycc_compiler
    from numba.pycc import CC

    from slewing_model.numerics.compiled import AOT_MODULES, aot_name, compile_helpers, kernel_source_hash

    cc = CC(AOT_MODULES[target])
    cc.target_cpu = "" if target == "generic" else target       # pycc's default: a generic x86-64 CPU
    cc.output_dir = output_dir
    cc.verbose = False
    error_models, fastmath = {}, {}
    for name in KERNEL_MODULES:
        module = importlib.import_module(name)
        flags = getattr(module, "FASTMATH", frozenset())
        compile_helpers(vars(module), module._HELPERS, module.ERROR_MODEL, getattr(module, "_INLINE", ()), flags)
        for factory, function in module.KERNELS:
            cc.export(aot_name(function), factory.signature)(function)
            error_models[function], fastmath[function] = module.ERROR_MODEL, flags
    source_hash = kernel_source_hash()
    cc.export("source_hash", "i8()")(lambda: source_hash)

    # pycc compiles every export with one set of flags: give each loop its module's error model and fast-math
    # flags (a generic x86-64 CPU has no fused multiply-add: the friction's ``contract`` then changes nothing;
    # an x86-64-v3 CPU has, and fuses them as numba's JIT does on the building machine)
    original = pycc_compiler.compile_extra

    def compile_extra(typingctx, targetctx, func, args, return_type, flags, locals, **kwargs):
        flags.error_model = error_models.get(func, "python")
        flags.fastmath = set(fastmath.get(func, ()))
        return original(typingctx, targetctx, func, args, return_type, flags, locals, **kwargs)

    pycc_compiler.compile_extra = compile_extra
    # the C part with a numba_unpickle that keeps what it unpickled (pycc_unpickle.c); the paths normalised, since
    # distutils makes each object's folder from its source's path (numba's ../core/runtime/nrt.cpp)
    cc._get_mixin_sources = lambda: [str(memoised_mixin(source, output_dir)) if source.endswith("modulemixin.c")
                                     else os.path.normpath(source) for source in CC._get_mixin_sources(cc)]
    cc.compile()
    print(numba.__version__)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmu_build.aot", description=__doc__.split("\n\n")[0])
    parser.add_argument("-o", "--output", help="copy the module into this folder")
    parser.add_argument("--compile", help=argparse.SUPPRESS)
    parser.add_argument("--target", default=None, help="one target (x86-64-v3 or generic); default: both")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    if args.compile:
        _compile(args.compile, args.target or "generic")
        return 0
    paths = [build_kernels(args.output, print, args.target)] if args.target else build_all_kernels(args.output, print)
    print("\n".join(map(str, paths)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
