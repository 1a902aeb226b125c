"""The CPUs numba's loops are compiled for, besides the building machine's: what an FMU runs on another machine.

numba compiles a loop for the CPU it runs on (its name and every feature LLVM finds there) and keys the
entries of its on-disk cache by both, so the loops an FMU carries for its building machine serve no other
CPU model. The FMU carries them also for each of :data:`PORTABLE_TARGETS`, compiled with
:func:`target_environment` (an LLVM CPU name and no feature of the host's), and on another machine takes the
first whose features that CPU has (:func:`portable_target`):

- ``x86-64-v3``, the x86-64 psABI's third level (AVX2, FMA, BMI2, ...: Intel's CPUs since Haswell, 2013,
  AMD's since Excavator, 2015): the loops' fused multiply-adds and four-wide vector operations. Measured on
  this machine (an AMD EPYC, znver4), the library's pitch bearing NREL step, three runs of 3-5 alternating
  processes each: 0.90-0.94 of the building CPU's loops' median, the
  generic ones 1.07-1.25 (the x86-64-v3 loops' answers are those of the building CPU's loops bit for bit:
  both fuse multiply-adds);
- ``generic``: any x86-64 CPU (SSE2 only).

The loops compiled ahead of time (``fmu_build/aot.py``, an FMU built with ``--aot``) are compiled for the same
targets, one extension module each; that FMU has no LLVM to ask, so it reads the CPU's features from the
Linux kernel (:func:`cpuinfo_features`).

Run-time module: the standard library only (it runs before numba is imported).
"""
from __future__ import annotations

#: what the x86-64 psABI's level 3 adds to level 1 (every x86-64 CPU's), by LLVM's names: level 2's CMPXCHG16B,
#: LAHF/SAHF, POPCNT, SSE3, SSE4.1, SSE4.2, SSSE3, and level 3's AVX, AVX2, BMI1, BMI2, F16C, FMA, LZCNT, MOVBE,
#: XSAVE
X86_64_V3_FEATURES = ("cx16", "sahf", "popcnt", "sse3", "sse4.1", "sse4.2", "ssse3",
                      "avx", "avx2", "bmi", "bmi2", "f16c", "fma", "lzcnt", "movbe", "xsave")

#: the CPUs an FMU's loops are compiled for besides the building machine's, the fastest first: (LLVM CPU
#: name, the host features it needs)
PORTABLE_TARGETS = (("x86-64-v3", X86_64_V3_FEATURES), ("generic", ()))


def portable_target(host_features) -> str:
    """The first of :data:`PORTABLE_TARGETS` whose features the host has.

    Parameters
    ----------
    host_features : mapping of str to bool
        The host CPU's features by LLVM's names, as ``llvmlite.binding.get_host_cpu_features()`` gives
        them (a feature missing from it counts as absent).

    Returns
    -------
    str
        The target's LLVM CPU name (``generic`` where the host lacks the others' features).

    Examples
    --------
    >>> portable_target({name: True for name in X86_64_V3_FEATURES})
    'x86-64-v3'
    >>> portable_target({"sse2": True, "avx": True})
    'generic'
    """
    for name, needs in PORTABLE_TARGETS:
        if all(host_features.get(feature, False) for feature in needs):
            return name
    return PORTABLE_TARGETS[-1][0]


def target_environment(name: str) -> dict:
    """The environment (``NUMBA_CPU_NAME``, ``NUMBA_CPU_FEATURES``) under which numba compiles, and finds in
    its cache, the loops for the target ``name`` (:data:`PORTABLE_TARGETS`): that CPU's own features, none of
    the host's added (numba adds the host's unless told otherwise: its cache entries would then be this
    machine's). ValueError for another name."""
    names = [target for target, _ in PORTABLE_TARGETS]
    if name not in names:
        raise ValueError(f"target = {name!r}: must be one of {', '.join(names)}")
    return {"NUMBA_CPU_NAME": name, "NUMBA_CPU_FEATURES": ""}


#: the Linux kernel's names (``/proc/cpuinfo``'s flags) of :data:`X86_64_V3_FEATURES`, by LLVM's names
CPUINFO_FLAGS = {"cx16": "cx16", "sahf": "lahf_lm", "popcnt": "popcnt", "sse3": "pni", "sse4.1": "sse4_1",
                 "sse4.2": "sse4_2", "ssse3": "ssse3", "avx": "avx", "avx2": "avx2", "bmi": "bmi1", "bmi2": "bmi2",
                 "f16c": "f16c", "fma": "fma", "lzcnt": "abm", "movbe": "movbe", "xsave": "xsave"}


def cpuinfo_features(cpuinfo: str | None = None) -> dict:
    """The CPU's features among :data:`X86_64_V3_FEATURES`, by LLVM's names (as :func:`portable_target`
    takes them), from the Linux kernel's flags of its first processor.

    Parameters
    ----------
    cpuinfo : str, optional
        The text of ``/proc/cpuinfo``; read from there by default. Where it cannot be read (another system),
        no feature: the generic loops.

    Examples
    --------
    >>> cpuinfo_features("flags : fpu sse2 avx avx2 fma")["avx2"], cpuinfo_features("flags : fpu sse2")["avx2"]
    (True, False)
    """
    if cpuinfo is None:
        try:
            with open("/proc/cpuinfo") as fh:
                cpuinfo = fh.read()
        except OSError:
            cpuinfo = ""
    flags = next((set(line.split(":", 1)[1].split()) for line in cpuinfo.splitlines()
                  if line.startswith("flags") and ":" in line), set())
    return {name: flag in flags for name, flag in CPUINFO_FLAGS.items()}
