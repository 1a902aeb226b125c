"""The CPUs an FMU's compiled loops are compiled for besides the building machine's
(:mod:`slewing_model.numerics.targets`): which one another machine takes, and how numba is told."""
import pytest

from slewing_model.numerics.targets import (
    CPUINFO_FLAGS, PORTABLE_TARGETS, X86_64_V3_FEATURES, cpuinfo_features, portable_target, target_environment,
)

from conftest import has_x86_64_v3


def test_a_cpu_with_every_x86_64_v3_feature_takes_those_loops_and_one_without_any_of_them_the_generic_ones():
    v3 = {name: True for name in X86_64_V3_FEATURES}
    assert portable_target({**v3, "avx512f": True, "sse2": True}) == "x86-64-v3"
    for missing in X86_64_V3_FEATURES:                       # one feature short: the generic loops
        assert portable_target({**v3, missing: False}) == "generic", missing
        assert portable_target({k: v for k, v in v3.items() if k != missing}) == "generic", missing
    assert portable_target({}) == "generic"
    assert [name for name, _ in PORTABLE_TARGETS][-1] == "generic"      # any x86-64 has somewhere to go


def test_this_cpu_takes_the_target_its_kernel_flags_say_it_can_run():
    # LLVM's view of this CPU (what the FMU asks) against the Linux kernel's /proc/cpuinfo flags (another reader)
    llvm = pytest.importorskip("llvmlite.binding")
    llvm.initialize_native_target()
    expected = "x86-64-v3" if has_x86_64_v3() else "generic"
    assert portable_target(llvm.get_host_cpu_features()) == expected


def test_numba_is_told_the_targets_cpu_and_none_of_the_hosts_features():
    for name, _ in PORTABLE_TARGETS:
        assert target_environment(name) == {"NUMBA_CPU_NAME": name, "NUMBA_CPU_FEATURES": ""}
    with pytest.raises(ValueError, match=r"target = 'skylake': must be one of x86-64-v3, generic"):
        target_environment("skylake")


def test_the_kernels_flags_name_every_x86_64_v3_feature_and_say_what_llvm_says_of_this_cpu():
    # the ahead-of-time FMU has no LLVM to ask: it reads /proc/cpuinfo (cpuinfo_features); here LLVM is the
    # other reader
    assert set(CPUINFO_FLAGS) == set(X86_64_V3_FEATURES)
    llvm = pytest.importorskip("llvmlite.binding")
    llvm.initialize_native_target()
    assert portable_target(cpuinfo_features()) == portable_target(llvm.get_host_cpu_features())
    assert cpuinfo_features("no flags here") == {name: False for name in X86_64_V3_FEATURES}
