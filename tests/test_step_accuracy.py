"""The co-simulation step answers as exactly as a tight solve: speed is not bought with accuracy.

Short versions of the benchmark cases (`benchmarks/cases.py`: the 150-ball pitch bearing pitching
under the blade-root series, the 180-ball yaw bearing yawing in bursts under the tower-top series,
table3 with errors under a heavy combined load, turning) are stepped with the simulator's default
settings, which are the FMU's, and every step is compared with a separate simulator solving the
same inputs to tolerances near the round-off floor (:data:`TIGHT`, :data:`TIGHT_FRICTION`).
The coarse superelement keeps the test short; the solver does not depend on the mesh.
"""
import sys

import numpy as np
import pytest

from slewing_model import Loads, load_bearing
from slewing_model.distribution.assembly import assemble
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings
from slewing_model.rings.superelement import build_superelement

from conftest import ROOT, benchmark_case
from statics import load_on_moving_ring

if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
from benchmarks.cases import CASES  # noqa: E402

#: relative accuracy asked of every output at every step, and the absolute floor of each output
#: where it passes through zero (the tilts change sign; the torque is 0 while a yaw drive rests).
#: The tilts' floor, 1e-7 rad, asks a tilt near zero to 1e-11 rad, 1e-7 of the cases' tilts (1e-4 to
#: 1e-3 rad), which is what the stop rule (residuals 1e-7 of the load) bounds; 1e-9 rad asked
#: 1e-13 rad, met only while the last Newton step with an inverse exact to round-off went far past the
#: tolerance (a single-precision inverse, reduced_operator.OPERATOR_PRECISION: 1.3e-12 rad on the
#: pitch case's first step, where its tilt rx is 2e-16 rad)
RTOL = 1e-4
FLOOR = {"z": 1e-9, "rx": 1e-7, "ry": 1e-7, "max_ball_load": 1e-3, "friction_torque": 1e-3}  # m, rad, N, N m
STEPS = 60
#: the reference: residuals near the round-off floor (~1e-12 of the load scale), ball equilibrium to 1e-9
TIGHT, TIGHT_FRICTION = 1e-11, 1e-9


def _settings(case, **options):
    return SimulatorSettings(ring_model="flexible" if case.parameters["ring_model"] == 2 else "rigid",
                             load_frame="rotating" if case.parameters["load_frame"] == 2 else "fixed", **options)


def _outputs(result):
    d = result.distribution
    return {"z": d.displacement[2], "rx": d.displacement[3], "ry": d.displacement[4],
            "max_ball_load": d.max_ball_load, "friction_torque": result.friction_torque}


@pytest.fixture(scope="module", params=["pitch", "yaw", "table3_heavy"])
def stepped(request):
    """(case, bearing, fast results, tight results, psi) over STEPS steps of a benchmark case."""
    case = CASES[request.param](STEPS)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="coarse", bc="free")
    fast = BearingSimulator(bearing, superelement, _settings(case))
    tight = BearingSimulator(bearing, superelement, _settings(case, tolerance=TIGHT, friction_tolerance=TIGHT_FRICTION))
    results = []
    for k in range(case.steps):
        loads = Loads(*case.loads[k])
        results.append((fast.step(loads, case.psi[k], case.omega[k]), tight.step(loads, case.psi[k], case.omega[k])))
    return case, fast.bearing, results


def test_every_step_matches_a_tight_solve(stepped):
    case, _, results = stepped
    for k, (fast, tight) in enumerate(results):
        got, want = _outputs(fast), _outputs(tight)
        for name, value in got.items():
            assert abs(value - want[name]) <= RTOL * max(abs(want[name]), FLOOR[name]), (
                f"{case.name}, step {k}: {name} = {value!r}, tight solve {want[name]!r}")


def test_balls_balance_the_applied_load_at_every_step(stepped):
    case, bearing, results = stepped
    lever = np.array([1.0, 1.0, 1.0, 2.0, 2.0]) / [1.0, 1.0, 1.0, bearing.pitch_diameter, bearing.pitch_diameter]
    for k, (fast, _) in enumerate(results):
        d = fast.distribution
        applied = d.loads.as_array() * lever                 # moments as forces at the pitch radius
        centres = assemble(bearing, case.psi[k]).groove_centre
        balance = load_on_moving_ring(bearing, d, centres) * lever
        scale = np.abs(applied).max()
        assert np.abs(balance - applied).max() <= 1e-6 * scale, (
            f"{case.name}, step {k}: contact forces {balance} against applied {applied} (scale {scale:.3g} N)")



def test_state_taken_while_a_new_operator_is_pending_repeats_the_steps():
    """A new ring operator is inverted over two steps (``reduced_operator.PendingOperator``): a state
    taken between them, kept in memory (so no array in it may be changed in place afterwards)
    or serialised as the FMU does, repeats the next steps to the last bit."""
    import json

    from slewing_model.simulation.simulator import decode_state, encode_state

    case = CASES["pitch"](STEPS)
    bearing = load_bearing(case.bearing)
    sim = BearingSimulator(bearing, build_superelement(bearing, mesh="coarse", bc="free"), _settings(case))

    def step(k):
        r = sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k])
        return r.distribution.contact_load, r.distribution.displacement, r.friction_torque

    k = 0
    while sim.solver.pending_operator is None:
        step(k)
        k += 1
        assert k < STEPS - 5, "no new operator was pending within the case"
    kept = sim.get_state()                       # in memory (fmi2GetFMUstate, a refused step's restore) ...
    saved = json.loads(json.dumps(encode_state(kept)))               # ... and serialised
    first = [step(j) for j in range(k, k + 5)]
    for state in (kept, decode_state(saved)):
        sim.set_state(state)
        assert sim.solver.pending_operator is not None
        again = [step(j) for j in range(k, k + 5)]
        for (q1, d1, t1), (q2, d2, t2) in zip(first, again):
            assert np.array_equal(q1, q2) and np.array_equal(d1, d2) and t1 == t2


def test_a_refused_step_leaves_the_simulator_as_it_was():
    """A step whose loads the bearing cannot carry raises, and the simulator restores itself
    (``BearingSimulator._checkpoint``): taken while a new operator is pending, with the life
    accumulator on, the steps after it equal to the last bit those of a twin that never saw it, the
    life outputs too."""
    from slewing_model import NoEquilibriumError

    case = CASES["pitch"](STEPS)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="coarse", bc="free")
    sims = [BearingSimulator(bearing, superelement, _settings(case, life=True)) for _ in range(2)]

    def step(sim, k):
        r = sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k])
        return (r.distribution.contact_load, r.distribution.displacement, r.friction_torque,
                sim.life.track_damage, sim.life.last_ratio)

    k = 0
    while sims[0].solver.pending_operator is None:
        for sim in sims:
            step(sim, k)
        k += 1
        assert k < STEPS - 5, "no new operator was pending within the case"
    with pytest.raises(NoEquilibriumError, match="beyond what the bearing can carry"):
        sims[0].step(Loads(*(50.0 * case.loads[k])), case.psi[k] + 0.3, case.omega[k])
    assert sims[0].solver.pending_operator is not None
    for j in range(k, k + 5):
        got, want = step(sims[0], j), step(sims[1], j)
        for a, b in zip(got, want):
            assert np.array_equal(a, b, equal_nan=True), (j, a, b)


def test_tuned_settings_take_effect_from_the_next_step():
    """The tunable settings (friction coefficient, seal torque, speed regularisation: the FMU's tunable
    parameters) changed between steps (``BearingSimulator.tune``) take effect from the next step: the
    steps after it equal, to the last bit, those of a simulator built with them and given the tuned one's
    state; and differ from those of the untuned one (the change discriminates)."""
    case = CASES["pitch"](STEPS)
    bearing = load_bearing(case.bearing)
    superelement = build_superelement(bearing, mesh="coarse", bc="free")
    tuned, kept = (BearingSimulator(bearing, superelement, _settings(case)) for _ in range(2))
    for k in range(8):
        for sim in (tuned, kept):
            sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k])
    changes = {"friction_coefficient": 0.15, "seal_torque": 40.0, "omega_regularisation": 2e-3}
    built = BearingSimulator(bearing, superelement, _settings(case, **changes))
    built.set_state(tuned.get_state())
    tuned.tune(**changes)
    for k in range(8, 12):
        got, want, old = (sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k]) for sim in (tuned, built, kept))
        assert (got.friction_torque, got.friction_torque_magnitude) == (want.friction_torque,
                                                                        want.friction_torque_magnitude), k
        assert got.friction_torque_magnitude > 1.2 * old.friction_torque_magnitude, k


def test_the_friction_start_carried_on_is_nearer_the_balls_motions_of_the_step():
    """The friction torque of a step starts from the last two steps' ball motions carried on as far as
    the loads go on (``simulator.extrapolated_motion``). For the pitch bearing's blade-root series it
    is about half as far from the step's ball motions as the last step's are (the median over the
    steps of the balls' median distance: 0.55; 1 where the loads turn back, share 0). Every step's
    torque is checked against a tight solve by :func:`test_every_step_matches_a_tight_solve`."""
    from slewing_model.simulation.simulator import ORBITAL, extrapolated_motion, load_share

    case, bearing, superelement = benchmark_case("pitch", STEPS)
    sim = BearingSimulator(bearing, superelement, _settings(case))
    states, loads, ratios = [], [], []
    for k in range(case.steps):
        f = Loads(*case.loads[k]).rotated(case.psi[k])
        loads.append(sim.solver.scaled_load(f))
        sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k])
        states.append(sim.get_state()["friction"])
        if k >= 2:
            start = extrapolated_motion(states[-2], states[-3], load_share(loads[-1], loads[-2], loads[-3]))
            rolled = np.all([state[:, ORBITAL] != 0 for state in states[-3:]], axis=0)     # loaded in all three
            carried = np.linalg.norm((start - states[-1])[rolled], axis=1)
            last = np.linalg.norm((states[-2] - states[-1])[rolled], axis=1)
            ratios.append(np.median(carried) / np.median(last))
    assert np.median(ratios) < 0.7


def test_a_ball_newly_loaded_or_unloaded_keeps_its_last_motion():
    """... a ball newly loaded keeps its last motion (none: it is started cold), a ball unloaded none."""
    from slewing_model.simulation.simulator import extrapolated_motion

    rng = np.random.default_rng(5)
    warm, previous = rng.normal(size=(6, 4)), rng.normal(size=(6, 4))
    warm[4], previous[5] = 0.0, 0.0              # ball 5 unloaded in the last step, ball 6 loaded in it
    start = extrapolated_motion(warm, previous, 0.5)
    assert np.allclose(start[:4], warm[:4] + 0.5 * (warm[:4] - previous[:4]), rtol=1e-14, atol=0)
    assert np.array_equal(start[4:], warm[4:])
    assert extrapolated_motion(warm, None, 0.5) is warm
