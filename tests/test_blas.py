"""slewing_model.numerics.blas: the BLAS threads of a step are set for the step and restored after it."""
import numpy as np
import pytest

from slewing_model.numerics.blas import _openblas_threads, blas_thread_control, blas_threads
from slewing_model.simulation.simulator import SimulatorSettings


@pytest.mark.skipif(not blas_thread_control(), reason="numpy's BLAS is not an OpenBLAS found in /proc/self/maps")
def test_threads_are_set_inside_and_restored_after():
    get, set_ = _openblas_threads()
    before = get()
    set_(2)
    try:
        with blas_threads(1):
            assert get() == 1
            np.linalg.inv(np.eye(50) * 2.0)
        assert get() == 2
        with pytest.raises(ZeroDivisionError):   # restored on an exception too
            with blas_threads(1):
                raise ZeroDivisionError
        assert get() == 2
        with blas_threads(None):                  # None: left as it is
            assert get() == 2
    finally:
        set_(before)


@pytest.mark.parametrize("value", [0, -1, 1.5, True, "1"])
def test_bad_thread_count_is_refused(value):
    with pytest.raises(ValueError, match="blas_threads"):
        SimulatorSettings(blas_threads=value)
