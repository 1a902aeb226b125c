"""The turbine loop's emergency stop (run_turbine(emergency_stop=...)): every blade's demand goes to feather and
the generator torque to zero; the drives pitch at their rate limit, the rotor slows down."""
import math
import sys

import numpy as np
import pytest

if sys.version_info < (3, 11):
    pytest.skip("the turbine loop needs rosco 2.10.6, which needs Python >= 3.11", allow_module_level=True)
pytest.importorskip("rosco", reason="the turbine loop needs ROSCO's library: pip install --no-deps rosco==2.10.6")

from slewing_turbine import loop  # noqa: E402
from slewing_turbine.wind import steady  # noqa: E402

DT = 0.01
RATED = 12.1 * math.pi / 30.0
WITHIN = math.radians(1.0)        # "at feather": every blade within 1 deg of it (emergency_stop_figures)


def test_emergency_stop_feathers_at_the_drives_rate_limit_and_the_rotor_slows_down():
    """No load moment (Cp table aero), no bearing: from rest at 60 deg the drives reach feather - 1 deg after
    the closed form ``dt + (90 - 60 - 1) deg / w_max`` (the demand acts from the step after the call; the
    speed loop's approach to the rate limit adds less than 0.15 s), cruising at the rate limit ``w_max``
    in between; the generator torque is zero from the stop on, so the rotor slows down."""
    config = loop.TurbineConfig(rotor_speed_init=RATED, pitch_init=math.radians(60.0))
    r = loop.run_turbine(config, steady(13.0, 5.0, DT), t_end=5.0, dt=DT, drives="electric", aero="cp_table",
                         emergency_stop=0.0)
    p = r.drive_params
    assert np.all(r.pitch_demand[1:] == loop.FEATHER) and np.all(r.generator_torque[1:] == 0.0)
    t_feather, rpm_stop, rpm_end = loop.emergency_stop_figures(r)
    closed = DT + (math.radians(90.0 - 60.0) - WITHIN) / p.rate_limit
    assert closed <= t_feather <= closed + 0.15
    cruise = (r.time > 1.0) & (r.time < closed - 0.5)          # before the position loop slows it to feather
    np.testing.assert_allclose(r.pitch_rate[cruise], p.rate_limit, rtol=1e-3)
    assert np.all(r.pitch_rate <= p.rate_limit * (1 + 1e-6))
    assert np.all(np.diff(r.rotor_speed) < 0.0)                # decelerating at every step
    assert rpm_end < 0.6 * rpm_stop
    s = loop.summary(r, settle=0.0)
    assert s["time to feather [s]"] == t_feather and s["rotor speed at end [rpm]"] == rpm_end


def test_friction_does_not_feather_faster():
    """BEM aero (the blades' pitching moments), rigid pitch bearings: with the bearings' friction the blades
    reach feather no sooner than without it, and the stop slows the rotor in both."""
    config = loop.TurbineConfig(rotor_speed_init=RATED, pitch_init=math.radians(70.0))
    wind = steady(13.0, 3.5, DT)
    times = {}
    for friction in (False, True):
        bearings = loop.make_bearings(config, "rigid", friction=friction)
        r = loop.run_turbine(config, wind, t_end=3.5, dt=DT, drives="electric", bearings="rigid",
                             friction=friction, aero="bem", bearing_simulators=bearings, emergency_stop=0.2)
        t_feather, rpm_stop, rpm_end = loop.emergency_stop_figures(r)
        assert math.isfinite(t_feather) and rpm_end < rpm_stop
        assert (np.max(r.friction_torque[1:]) > 1e3) == friction          # N m
        times[friction] = t_feather
    assert times[True] >= times[False]
    closed = DT + (math.radians(90.0 - 70.0) - WITHIN) / r.drive_params.rate_limit
    assert times[False] >= closed - 0.2        # the blades' moment may help at first, never beyond the rate limit
