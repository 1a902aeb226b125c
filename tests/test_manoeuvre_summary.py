"""The tracking figures of a manoeuvre's summary leave out the command steps themselves."""
import math

import numpy as np
import pytest

from slewing_drives.cosimulation import SETTLED_AFTER_S, SETTLED_DEG, settling


def _first_order(step_deg, tau, t_on=1.0, t_off=None, t_end=12.0, dt=0.001):
    """A drive that follows a step command as exp(-t/tau): the error after each step is known in closed form."""
    t = np.arange(0.0, t_end, dt)
    command = np.where((t >= t_on) & ((t < t_off) if t_off else True), step_deg, 0.0)
    angle = np.zeros_like(t)
    for k in range(1, t.size):
        angle[k] = command[k] + (angle[k - 1] - command[k]) * math.exp(-dt / tau)
    return t, command, command - angle


@pytest.mark.parametrize("step, tau", [(5.0, 0.3), (5.0, 0.1), (-2.0, 0.4)])
def test_settling_time_and_late_error_of_a_first_order_response(step, tau):
    t, command, error = _first_order(step, tau, t_off=6.0)
    settle, late = settling(t, command, error)
    assert settle == pytest.approx(tau * math.log(abs(step) / SETTLED_DEG), abs=2e-3)
    assert late == pytest.approx(abs(step) * math.exp(-SETTLED_AFTER_S / tau), rel=0.02)
    assert late < 0.5 * np.abs(error).max()                       # not the step itself


def test_a_response_too_slow_for_the_next_step_never_settles():
    t, command, error = _first_order(5.0, 2.0, t_off=3.0)
    assert settling(t, command, error)[0] == math.inf


def test_a_command_without_steps_reports_its_whole_error():
    t = np.linspace(0.0, 5.0, 501)
    error = 0.05 * np.sin(t)
    assert settling(t, 0.01 * t, error) == (0.0, pytest.approx(0.05, rel=1e-3))
