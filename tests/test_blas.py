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


@pytest.mark.skipif(not blas_thread_control(), reason="numpy's BLAS is not an OpenBLAS found in /proc/self/maps")
def test_a_steps_operator_work_runs_on_the_settings_threads_and_a_usual_step_leaves_them(monkeypatch):
    """The ring operator's work in a simulator step (here each new operator formed) runs numpy's BLAS on
    ``blas_threads`` threads, and the host's count is back after the step; a usual step (its solve the
    one compiled call, no BLAS) does not set them at all."""
    from slewing_model import Loads, load_bearing
    from slewing_model.distribution import bime
    from slewing_model.rings.superelement import build_superelement
    from slewing_model.simulation.simulator import BearingSimulator

    from conftest import BEARINGS

    bearing = load_bearing(BEARINGS / "table3.toml")
    sim = BearingSimulator(bearing, build_superelement(bearing, mesh="coarse", bc="free"),
                           SimulatorSettings(blas_threads=1))
    get, set_ = _openblas_threads()
    formed, entered = [], []
    original_start, original_threads = bime.start_operator, bime.blas_threads

    def start_operator(*args, **kwargs):
        formed.append(get())
        return original_start(*args, **kwargs)

    def threads(count):
        entered.append(count)
        return original_threads(count)
    monkeypatch.setattr(bime, "start_operator", start_operator)
    monkeypatch.setattr(bime, "blas_threads", threads)
    before = get()
    set_(2)
    try:
        untouched = 0
        for k in range(40):
            entries = len(entered)
            sim.step(Loads(Fz=8e4 + 2e3 * k, My=1e4 + 5e2 * k), 0.002 * k, 0.1)
            assert get() == 2
            untouched += len(entered) == entries
    finally:
        set_(before)
    assert formed and set(formed) == {1} and set(entered) == {1}
    assert 0 < untouched < 40


@pytest.mark.skipif(not blas_thread_control(), reason="numpy's BLAS is not an OpenBLAS found in /proc/self/maps")
def test_the_friction_of_numpys_loops_runs_on_the_settings_threads(monkeypatch):
    """With numpy's loops (the win64 FMU's, ``--no-numba``'s) the friction torque sums every contact's
    points by BLAS products: each step's friction runs on ``blas_threads`` threads, and the host's count
    is back after the step."""
    from slewing_model import Loads, load_bearing
    from slewing_model.friction import ball_kinematics
    from slewing_model.rings.superelement import build_superelement
    from slewing_model.simulation.simulator import BearingSimulator

    from conftest import BEARINGS

    bearing = load_bearing(BEARINGS / "table3.toml")
    sim = BearingSimulator(bearing, build_superelement(bearing, mesh="coarse", bc="free"),
                           SimulatorSettings(blas_threads=1, friction_kernel="numpy", contact_kernel="numpy"))
    get, set_ = _openblas_threads()
    seen = []
    original = ball_kinematics.ContactPoints.evaluate

    def evaluate(self, *args, **kwargs):
        seen.append(get())
        return original(self, *args, **kwargs)
    monkeypatch.setattr(ball_kinematics.ContactPoints, "evaluate", evaluate)
    before = get()
    set_(2)
    try:
        for k in range(5):
            sim.step(Loads(Fz=8e4 + 2e3 * k, My=1e4 + 5e2 * k), 0.002 * k, 0.1)
            assert get() == 2
    finally:
        set_(before)
    assert seen and set(seen) == {1}
