"""A step whose inputs are the last step's (``BearingSimulator.step``): it answers the last equilibrium at
once. Checked against the same steps solved (the simulator's state through JSON before each step, which
leaves the held answer out), on the paper's Table 1 bearing with rings of a known stiffness
(:mod:`synthetic_rings`), friction and life on: a load held, switched, held again, the ring turning and
stopping, and the speed changing while the rest holds."""
import math

import numpy as np
import pytest

from slewing_model import Loads
from slewing_model.friction import regularised_torque
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings
from conftest import through_json
from synthetic_rings import synthetic_superelement

LOW = Loads(Fx=2e4, Fz=3e5, Mx=1e5, My=4e5)
HIGH = Loads(Fx=3e4, Fz=4.5e5, Mx=1.5e5, My=6e5)
#: (loads, psi, omega) per step: held, switched and held, turning, stopped (held), the speed alone changing
STEPS = ([(LOW, 0.0, 0.1)] * 3 + [(HIGH, 0.0, 0.1)] * 3 + [(HIGH, 0.002 * k, 0.2) for k in range(1, 4)]
         + [(HIGH, 0.006, 0.0)] * 2 + [(HIGH, 0.006, -2e-5), (HIGH, 0.006, 3e-4), (LOW, 0.006, 3e-4)])


def settings(step_work="complete"):
    return SimulatorSettings(ring_model="flexible", friction_coefficient=0.1, life=True, step_work=step_work)


def solved_again(sim):
    """The simulator's state through JSON, as a master's serialised FMU state: the held answer is left out."""
    sim.set_state(through_json(sim.get_state()))


@pytest.fixture(scope="module")
def rings(table1):
    return synthetic_superelement(table1.ball_count)


def test_a_step_with_the_last_inputs_answers_its_equilibrium(table1, rings):
    held, solved = BearingSimulator(table1, rings, settings()), BearingSimulator(table1, rings, settings())
    repeats = 0
    for k, (loads, psi, omega) in enumerate(STEPS):
        same = k > 0 and STEPS[k - 1][:2] == (loads, psi)
        maps = held.life.map.damage_map.copy(), solved.life.map.damage_map.copy()
        last = held.last
        a = held.step(loads, psi, omega)
        solved_again(solved)
        b = solved.step(loads, psi, omega)
        da, db = a.distribution, b.distribution
        if same:                    # answered at once: the last equilibrium, its torque at this speed
            repeats += 1
            assert da.iterations == 0 and np.array_equal(da.state, last.distribution.state)
            assert np.array_equal(da.contact_load, last.distribution.contact_load)
            assert a.friction_torque_magnitude == last.friction_torque_magnitude
            assert a.friction_torque == regularised_torque(a.friction_torque_magnitude, omega, 1e-4)
        # the same equilibrium as the step solved, within what the solver's tolerance leaves (2e-5 of the
        # displacements and ball loads, SimulatorSettings.tolerance) and the friction's
        for got, expected in ((da.displacement[:3], db.displacement[:3]), (da.displacement[3:], db.displacement[3:]),
                              (da.contact_load, db.contact_load)):
            assert np.abs(got - expected).max() <= 2e-5 * np.abs(expected).max()
        assert a.friction_torque_magnitude == pytest.approx(b.friction_torque_magnitude, rel=1e-5)
        assert math.copysign(1.0, a.friction_torque) == math.copysign(1.0, b.friction_torque) or omega == 0.0
        # life: a held step crosses no slice and adds nothing, solved or not; the two accumulators agree
        # (their load distributions within the solver's tolerance, Q^3 within three times it)
        if same:
            assert np.array_equal(held.life.map.damage_map, maps[0])
            assert np.array_equal(solved.life.map.damage_map, maps[1])
        np.testing.assert_allclose(held.life.track_damage, solved.life.track_damage, rtol=1e-5, atol=0.0)
        assert held.life.half.completed == solved.life.half.completed
    assert repeats == 8          # the steps whose loads and psi are the last step's


def test_the_held_answer_goes_with_the_settings_and_the_state(table1, rings):
    sim = BearingSimulator(table1, rings, settings())
    first = sim.step(HIGH, 0.0, 0.1)
    state = sim.get_state()
    assert sim.step(HIGH, 0.0, 0.1).distribution.iterations == 0
    # another friction coefficient: solved again, the torque in proportion (the same load distribution)
    sim.tune(friction_coefficient=0.2)
    tuned = sim.step(HIGH, 0.0, 0.1)
    assert tuned.friction_torque_magnitude != first.friction_torque_magnitude
    reference = BearingSimulator(table1, rings, SimulatorSettings(ring_model="flexible", friction_coefficient=0.2))
    assert tuned.friction_torque_magnitude == pytest.approx(
        reference.step(HIGH, 0.0, 0.1).friction_torque_magnitude, rel=1e-5)
    # a state in memory (an FMU's fmi2GetFMUstate) keeps it: the step repeated from it repeats exactly
    sim.set_state(state)
    sim.tune(friction_coefficient=0.1)           # back to the state's settings: the held answer is dropped
    again = sim.step(HIGH, 0.0, 0.1)
    sim.set_state(state)
    repeated = sim.step(HIGH, 0.0, 0.1)
    assert repeated.distribution.iterations == 0 and repeated.friction_torque == first.friction_torque
    assert again.friction_torque == pytest.approx(first.friction_torque, rel=1e-5)


def test_a_flagged_step_is_not_repeated(table1, rings):
    """A bounded step that stopped short is an iterate, not an equilibrium: the same inputs go on from it."""
    sim = BearingSimulator(table1, rings, settings("bounded"))
    sim.step(LOW, 0.0, 0.1)
    reversed_ = Loads(Fx=2e4, Fz=3e5, Mx=-1e5, My=-4e5)
    results = [sim.step(reversed_, 0.0, 0.1).distribution]
    while not results[-1].converged and len(results) < 30:
        results.append(sim.step(reversed_, 0.0, 0.1).distribution)
    assert len(results) >= 2 and results[-1].converged
    assert all(r.iterations > 0 for r in results[1:])
    residuals = [r.residual for r in results]
    assert residuals[-1] < residuals[0]
