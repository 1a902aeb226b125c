"""The structured Flexible-BIME Newton solver (paper eq 20) on a ring model with a known
stiffness matrix: against the dense Newton on all 5 + 8B unknowns, statics, limits."""
import dataclasses
import math

import numpy as np
import pytest

from slewing_model import BimeSolver, Loads, solve
import slewing_model.distribution.bime as bime
from slewing_model.distribution.bime import solve_dense_newton
from slewing_model.numerics.compiled import AVAILABLE
from conftest import symmetric_block_circulant, through_json
from synthetic_rings import synthetic_superelement

LOADS = [Loads(), Loads(Fx=2e4, Fz=5e4, My=1e4), Loads(Fy=-3e4, Mx=-2e4, My=1.5e4)]


@pytest.fixture(scope="module")
def bearing(table3):
    return table3.with_preload(20e-6)


@pytest.mark.parametrize("loads", LOADS)
def test_structured_newton_equals_dense_newton(bearing, loads):
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    r = solver.solve(loads)
    x, _ = solve_dense_newton(solver, loads)
    n = bearing.ball_count
    assert np.allclose(r.displacement, x[:5], rtol=1e-8, atol=1e-12)
    d = r.ring_displacement
    assert np.allclose(d[:, [0, 3]].ravel(), x[5:5 + 4 * n], atol=1e-12)   # outer ring: contacts 1, 4
    assert np.allclose(d[:, [1, 2]].ravel(), x[5 + 4 * n:], atol=1e-12)   # inner ring: contacts 2, 3


def test_ring_displacement_is_formed_when_asked_for_and_pickled_without_the_rings(bearing):
    """The result keeps the rings' compliance, not their displacements, until asked (a co-simulation
    step does not ask); pickled, it carries the displacements (the dense-Newton test above checks
    their values), not the compliance matrices."""
    import pickle

    r = BimeSolver(bearing, synthetic_superelement(bearing.ball_count)).solve(LOADS[1])
    assert "ring_displacement" not in r.__dict__
    copy = pickle.loads(pickle.dumps(r))
    assert isinstance(copy.rings, np.ndarray) and np.array_equal(copy.ring_displacement, r.ring_displacement)
    again = dataclasses.replace(copy, iterations=0)                # a copy of the copy keeps them
    assert np.array_equal(again.ring_displacement, r.ring_displacement)
    assert len(pickle.dumps(r)) < 0.1 * len(pickle.dumps(r.rings))
    assert BimeSolver(bearing).solve(LOADS[1]).ring_displacement is None          # rigid rings


def _contact_force_vectors(r):
    """(B, 2, 2) force of the outer ring on the inner ring's groove centre, per diagonal, (r, z)."""
    alpha1, alpha2 = r.contact_angle[:, 0], r.contact_angle[:, 1]
    n1 = np.stack([np.cos(alpha1), np.sin(alpha1)], axis=1)
    n2 = np.stack([np.cos(alpha2), -np.sin(alpha2)], axis=1)
    return -np.stack([r.contact_load[:, 0:1] * n1, r.contact_load[:, 1:2] * n2], axis=1)


@pytest.mark.parametrize("loads", LOADS)
def test_each_ring_balances_its_contact_forces(bearing, loads):
    se = synthetic_superelement(bearing.ball_count)
    r = solve(bearing, loads, model="flexible", superelement=se)
    f = _contact_force_vectors(r)                      # on the inner ring; the outer ring gets -f
    d = r.ring_displacement
    on_inner = np.stack([f[:, 1], f[:, 0]], axis=1)    # inner DOF order: contact 2 (diag 2), 3 (diag 1)
    on_outer = -f                                      # outer DOF order: contact 1 (diag 1), 4 (diag 2)
    scale = r.max_ball_load
    assert np.allclose(se.inner.dense() @ d[:, [1, 2]].ravel(), on_inner.ravel(), atol=1e-7 * scale)
    assert np.allclose(se.outer.dense() @ d[:, [0, 3]].ravel(), on_outer.ravel(), atol=1e-7 * scale)


def test_very_stiff_rings_give_the_rigid_result(bearing):
    loads = LOADS[1]
    stiff = solve(bearing, loads, model="flexible", superelement=synthetic_superelement(bearing.ball_count, 1e6))
    rigid = solve(bearing, loads)
    assert np.allclose(stiff.contact_load, rigid.contact_load, rtol=1e-3, atol=1e-3 * rigid.max_ball_load)


def test_flexible_rings_lower_the_preload_interference(bearing):
    # the preload compresses the rings too, so the contacts keep less than the ball oversize
    r = solve(bearing, model="flexible", superelement=synthetic_superelement(bearing.ball_count))
    assert np.all(r.interference < 20e-6) and np.all(r.interference > 0)


def test_warm_start_reaches_the_cold_solution(bearing):
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    first = solver.solve(LOADS[1])
    changed = Loads(*(1.01 * LOADS[1].as_array()))
    warm = solver.solve(changed, initial=first)
    cold = solver.solve(changed)
    assert np.allclose(warm.contact_load, cold.contact_load, rtol=1e-8, atol=1e-8 * cold.max_ball_load)


def test_operator_reused_across_a_rotation_reaches_the_cold_solution(bearing):
    # after set_rotation the kept ring operator W^-1 is reused with the new Jacobian (the rings
    # are axisymmetric): the warm solve must land on the cold solution at the new angle
    from slewing_model import synthetic_errors

    with_errors = bearing.with_errors(synthetic_errors(bearing.ball_count, seed=4))
    solver = BimeSolver(with_errors, synthetic_superelement(bearing.ball_count), rtol=1e-10)
    previous = solver.solve(LOADS[1])
    for psi in (0.01, 0.02, 0.5):
        solver.set_rotation(psi)
        warm = solver.solve(LOADS[1], initial=previous)
        cold = BimeSolver(with_errors, synthetic_superelement(bearing.ball_count), psi=psi, rtol=1e-10).solve(LOADS[1])
        assert np.allclose(warm.contact_load, cold.contact_load, rtol=1e-8, atol=1e-8 * cold.max_ball_load)
        assert np.allclose(warm.displacement, cold.displacement, rtol=1e-8, atol=1e-14)
        previous = warm


def test_simulator_extrapolated_start_reaches_the_cold_solution(bearing):
    # the simulator starts each solve from the last two states extrapolated: every step must
    # still be the equilibrium of its own inputs, whatever the history
    from slewing_model import synthetic_errors
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    with_errors = bearing.with_errors(synthetic_errors(bearing.ball_count, seed=4))
    se = synthetic_superelement(bearing.ball_count)
    sim = BearingSimulator(with_errors, se, SimulatorSettings(ring_model="flexible", friction_coefficient=0.0,
                                                              tolerance=1e-10))
    steps = [(Loads(Fz=5e4 + 1e3 * k, Mx=2e3 * k), 0.01 * k) for k in range(6)]
    steps.append((Loads(Fx=-2e4, Fz=1e4, My=-1e4), 0.2))         # a jump: the extrapolation is poor here
    for loads, psi in steps:
        r = sim.step(loads, psi=psi, omega=0.1).distribution
        cold = BimeSolver(sim.bearing, se, psi=psi, rtol=1e-10).solve(loads)
        assert np.allclose(r.contact_load, cold.contact_load, rtol=1e-8, atol=1e-8 * cold.max_ball_load)


def test_extrapolated_start_goes_as_far_as_the_loads_go_on():
    # the start is the last state carried on along its last change by the share of their last
    # change that the loads repeat: the whole of it where they go on, none where they hold or go back
    from slewing_model.simulation.simulator import extrapolated_start, load_share

    def start(warm, previous, f, f1, f0):
        return extrapolated_start(warm, previous, load_share(f, f1, f0))

    rng = np.random.default_rng(7)
    warm, previous = rng.normal(size=9), rng.normal(size=9)
    f0, f1 = rng.normal(size=5), rng.normal(size=5)
    change = f1 - f0
    cases = {"go on": (f1 + change, 1.0), "hold": (f1, 0.0), "go back": (f0, 0.0), "half": (f1 + 0.5 * change, 0.5),
             "twice as fast": (f1 + 2.0 * change, 1.0)}
    for name, (f, share) in cases.items():
        assert np.allclose(start(warm, previous, f, f1, f0), warm + share * (warm - previous),
                           rtol=1e-12, atol=1e-12), name
    side = np.array([-change[1], change[0], 0.0, 0.0, 0.0])          # a change across the last: none of it
    assert np.array_equal(start(warm, previous, f1 + side - side @ change / (change @ change) * change, f1, f0), warm)
    # loads that held: the state moved with psi alone, carried on whole; no previous state: the last
    assert np.allclose(start(warm, previous, f1 + change, f1, f1.copy()), 2.0 * warm - previous)
    assert start(warm, None, f1, f1, f0) is warm


def test_a_step_that_holds_the_loads_after_a_jump_starts_at_its_equilibrium(bearing):
    # after a moment reversed in one step, the next step with the same inputs starts from the
    # reversed equilibrium itself (the extrapolation would repeat the reversal): no iteration,
    # the same state bit for bit. The simulator answers such a step at once (the last step's inputs,
    # an equilibrium); from its state through JSON, which leaves that answer out, the step is solved
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    sim = BearingSimulator(bearing, synthetic_superelement(bearing.ball_count),
                           SimulatorSettings(ring_model="flexible", friction_coefficient=0.0))
    for k in range(3):
        sim.step(Loads(Fz=5e4, Mx=2e3 + 1e2 * k), psi=0.01 * k, omega=0.1)
    reversed_ = sim.step(Loads(Fz=5e4, Mx=-2.2e3), psi=0.02, omega=0.1).distribution
    state = through_json(sim.get_state())
    repeated = sim.step(Loads(Fz=5e4, Mx=-2.2e3), psi=0.02, omega=0.1).distribution
    sim.set_state(state)
    held = sim.step(Loads(Fz=5e4, Mx=-2.2e3), psi=0.02, omega=0.1).distribution
    assert reversed_.iterations > 0 and held.iterations == 0 and repeated.iterations == 0
    assert np.array_equal(held.state, reversed_.state) and np.array_equal(repeated.state, reversed_.state)


REVERSALS = [(Loads(Fz=5e4, Mx=2e4), Loads(Fz=5e4, Mx=-2e4)),
             (Loads(Fx=2e4, Fz=5e4, My=1e4), Loads(Fx=-2e4, Fz=5e4, My=-1e4))]


def _far_start(bearing, before, after, kernel="numpy"):
    """A solver of ``bearing`` (synthetic rings; its loops ``kernel``) at the equilibrium of ``before``, that
    point under ``after`` (far from its equilibrium: residual above HELD_START) and the scaled loads of ``after``."""
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count), kernel=kernel)
    first = solver.solve(before)
    f_scaled = solver.scaled_load(after)
    start = solver._evaluate(first.state[:5], first.state[5:], f_scaled)
    assert start.peak_residual > bime.HELD_START * max(np.abs(f_scaled).max(), start.peak_force)
    return solver, start, f_scaled


@pytest.mark.parametrize("before, after", REVERSALS)
def test_held_rings_start_balances_the_moving_ring_and_lowers_the_energy(bearing, before, after):
    # a warm start far from its equilibrium (a moment reversed) first moves the moving ring to its
    # equilibrium under the new loads with the rings held: force balance on (X, Y, Z, rx, ry) there,
    # and a total energy (eq 20) below the start's; the ring forces are untouched
    solver, start, f_scaled = _far_start(bearing, before, after)
    held = solver._held_rings_start(start, after, f_scaled, np.abs(f_scaled).max())
    assert held.total < start.total
    assert np.array_equal(held.y, start.y)
    # the rigid solve stops at a relative residual of 1e-6 of the loads
    assert np.abs(held.gradient).max() <= 1e-5 * np.abs(f_scaled).max()


@pytest.mark.skipif(not AVAILABLE, reason="numba is not installed")
@pytest.mark.parametrize("before, after", REVERSALS)
def test_held_rings_start_compiled_is_the_rigid_solve(bearing, before, after, monkeypatch, rigid_loop_calls):
    # the compiled loop of the held-rings start (kernel._rigid_solve) takes the steps of the rigid
    # solver's numpy code on the held grooves (BimeSolver._rigid_solver): the same moving ring's
    # displacement to round-off, where both stop at the rigid tolerance of 1e-6
    solver, start, f_scaled = _far_start(bearing, before, after, kernel="compiled")
    cold_start_calls = len(rigid_loop_calls)          # the cold solve's rigid start ran it too
    compiled = solver._held_rings_start(start, after, f_scaled, np.abs(f_scaled).max())
    assert len(rigid_loop_calls) == cold_start_calls + 1
    monkeypatch.setattr(solver, "_compiled", False)
    numpy_ = solver._held_rings_start(start, after, f_scaled, np.abs(f_scaled).max())
    assert compiled is not start and numpy_ is not start
    np.testing.assert_allclose(compiled.qs, numpy_.qs, rtol=0, atol=1e-10 * np.abs(numpy_.qs).max())


def test_held_rings_start_is_not_taken_where_the_loads_grow_in_their_direction(bearing):
    # three times the load: far from its equilibrium, but the moving ring's equilibrium with the rings
    # held loads no contact that was open, and the Newton steps from the old equilibrium serve better
    before = Loads(Fx=2e4, Fz=5e4, My=1e4)
    after = Loads(*(3.0 * before.as_array()))
    solver, start, f_scaled = _far_start(bearing, before, after)
    assert solver._held_rings_start(start, after, f_scaled, np.abs(f_scaled).max()) is start


@pytest.mark.parametrize("before, after", REVERSALS)
def test_held_rings_start_reaches_the_cold_solution_in_fewer_iterations(bearing, before, after, monkeypatch):
    # the Newton steps from the old equilibrium overshoot after a reversal; from the held start
    # they reach the same equilibrium (the cold solve's) in fewer iterations
    se = synthetic_superelement(bearing.ball_count)
    cold = BimeSolver(bearing, se).solve(after)
    iterations = {}
    for held_start in (math.inf, bime.HELD_START):
        monkeypatch.setattr(bime, "HELD_START", held_start)
        solver = BimeSolver(bearing, se)
        warm = solver.solve(after, initial=solver.solve(before))
        assert np.allclose(warm.contact_load, cold.contact_load, rtol=1e-8, atol=1e-8 * cold.max_ball_load)
        iterations[held_start] = warm.iterations
    assert iterations[bime.HELD_START] < iterations[math.inf]


def test_refused_step_leaves_the_simulator_as_it_was(bearing):
    # an overload refused inside the solver (it had turned the rings and updated its kept
    # operator by then) must not change what the following steps answer: bit for bit the
    # steps of a simulator that never saw it
    from slewing_model import LoadCapacityError
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    se = synthetic_superelement(bearing.ball_count)
    settings = SimulatorSettings(ring_model="flexible", friction_coefficient=0.0)
    disturbed, clean = BearingSimulator(bearing, se, settings), BearingSimulator(bearing, se, settings)
    before = [(Loads(Fz=5e4, Mx=2e3), 0.0), (Loads(Fz=5.2e4, Mx=2.5e3), 0.01)]
    after = [(Loads(Fz=5.3e4, Mx=2.6e3), 0.01), (Loads(Fz=5.5e4, Mx=3e3), 0.02)]   # the first at the same psi
    for loads, psi in before:
        disturbed.step(loads, psi, 0.1)
        clean.step(loads, psi, 0.1)
    with pytest.raises(LoadCapacityError):
        disturbed.step(Loads(Fz=5e7), 0.3, 0.1)
    for loads, psi in after:
        a, b = disturbed.step(loads, psi, 0.1).distribution, clean.step(loads, psi, 0.1).distribution
        assert np.array_equal(a.contact_load, b.contact_load) and np.array_equal(a.displacement, b.displacement)


@pytest.mark.parametrize("balls", [67, 150])
def test_block_circulant_product_by_harmonics_equals_the_dense_product(balls):
    """The ring compliance's product by FFT (from FFT_FROM_BALLS balls on) against the
    dense matrix-vector product, on a random symmetric block-circulant matrix: block
    (b, c) = C_(c-b mod B), C_(-k) = C_k^T."""
    from slewing_model.rings.compliance import FFT_FROM_BALLS, BlockCirculant

    dense = symmetric_block_circulant(balls, seed=balls)
    assert np.array_equal(dense, dense.T)
    matrix = BlockCirculant(dense, 4)
    assert matrix.by_harmonics == (balls >= FFT_FROM_BALLS)
    y = np.random.default_rng(balls + 1).standard_normal(4 * balls)
    expected = np.array([sum(dense[r, c] * y[c] for c in range(4 * balls)) for r in range(4 * balls)])
    assert np.abs(matrix @ y - expected).max() <= 1e-13 * np.abs(expected).max()
    assert np.array_equal(matrix[np.ix_([0, 5], [3, 7])], dense[np.ix_([0, 5], [3, 7])])


def test_the_contacts_compliance_is_its_blocks_entry_for_entry():
    """The compiled operator gathers ``M_aa`` from the blocks of the contacts' compliance, bordering
    gathers ``M`` (kept rows, new rows) from them (``BlockCirculant.blocks``, ``entries``): the rings'
    compliances are block-circulant exactly (each built from its first block row), so are the
    contacts' (a selection of both, the same per ball, and their sum), and the blocks give the dense
    matrix's numbers bit for bit; on a random block-circulant matrix and the pitch bearing's."""
    from slewing_model import load_bearing
    from slewing_model.rings.compliance import BlockCirculant, contact_compliance, ring_compliances
    from slewing_model.rings.superelement import build_superelement

    from conftest import BEARINGS

    rings = ring_compliances(build_superelement(load_bearing(BEARINGS / "pitch_bearing.toml"), mesh="coarse",
                                                bc="free"))
    rng = np.random.default_rng(3)
    for matrix in (BlockCirculant(symmetric_block_circulant(67, seed=5), 4), *rings.values(),
                   contact_compliance(rings)):
        n, m = matrix.shape[0], matrix.block
        index = np.arange(n)
        shift = (index[None, :] // m - index[:, None] // m) % matrix.balls
        assert np.array_equal(matrix.blocks[shift, (index % m)[:, None], (index % m)[None, :]], matrix.dense)
        rows, columns = rng.choice(n, 40, replace=False), rng.choice(n, 9, replace=False)
        assert np.array_equal(matrix.entries(rows, columns), matrix.dense[np.ix_(rows, columns)])


def test_inverse_by_halves_is_as_exact_as_lapack():
    """The reduced operator's inverse by Schur complements (matrix products) against LAPACK's, on
    a matrix like the operator's: the pitch bearing's ring compliance (600 rows, singular: the
    free rings' rigid motions) plus small contact compliances on the diagonal. Without the
    symmetrisation at each level this one gives a residual of order 1e3, not 1e-10. The inverse
    through the Cholesky factor (the check's second try) too, in double precision, exactly
    symmetric."""
    from slewing_model import load_bearing
    from slewing_model.rings.reduced_operator import LEAF, cholesky_inverse, spd_inverse
    from slewing_model.rings.compliance import contact_compliance, ring_compliances
    from slewing_model.rings.superelement import build_superelement

    from conftest import BEARINGS

    bearing = load_bearing(BEARINGS / "pitch_bearing.toml")
    rings = np.asarray(contact_compliance(ring_compliances(build_superelement(bearing, mesh="coarse", bc="free"))))
    rng = np.random.default_rng(1)
    for rows in (LEAF - 1, 2 * LEAF + 3, rings.shape[0]):
        w = rings[:rows, :rows] + np.diag(rng.uniform(0.2, 2.0, rows) * 1e-3 * np.abs(rings).max())
        lapack, halves = np.linalg.inv(w), spd_inverse(w)
        eye = np.eye(rows)
        assert np.array_equal(halves, halves.T)
        assert np.abs(halves @ w - eye).max() <= 10.0 * max(np.abs(lapack @ w - eye).max(), 1e-12)
        assert np.abs(halves - lapack).max() <= 1e-8 * np.abs(lapack).max()
        factor = cholesky_inverse(w)
        assert np.array_equal(factor, factor.T)
        assert np.abs(factor @ w - eye).max() <= 10.0 * max(np.abs(lapack @ w - eye).max(), 1e-12)
        assert np.abs(factor - lapack).max() <= 1e-8 * np.abs(lapack).max()


def test_an_operator_the_inverse_by_halves_misses_in_single_precision_is_inverted_through_its_factor(
        monkeypatch):
    """The matrix of the test above with contact compliances of 1e-3 of the rings' largest (condition
    1.3e5, as the pitch bearing's operators after a moment reversal, 5e4-8e4): by halves in single
    precision the errors of ``A^-1`` compound from level to level and ``W X v`` misses the probe ``v``
    by 11 times ``v``. The check then inverts it through its Cholesky factor, still in single
    precision (within ``10 eps_single cond(W)``: the factor's error grows with the square root of the
    halves' conditions), and keeps that: no inverse in double, none by LAPACK (4-19 ms in the bounded
    scenarios' slowest steps when the check's second try was LAPACK's)."""
    from slewing_model import load_bearing
    from slewing_model.rings import reduced_operator
    from slewing_model.rings.reduced_operator import (
        INVERSE_CHECK, LEAF, STAGES, PendingOperator, advance_operator, spd_inverse,
    )
    from slewing_model.rings.compliance import contact_compliance, ring_compliances
    from slewing_model.rings.superelement import build_superelement

    from conftest import BEARINGS

    assert reduced_operator.OPERATOR_PRECISION == np.float32
    bearing = load_bearing(BEARINGS / "pitch_bearing.toml")
    rings = np.asarray(contact_compliance(ring_compliances(build_superelement(bearing, mesh="coarse", bc="free"))))
    rows = rings.shape[0]
    w = rings + np.diag(np.random.default_rng(1).uniform(0.2, 2.0, rows) * 1e-3 * np.abs(rings).max())
    probe = 1.0 + 0.125 * (np.arange(rows) % 7)                    # the check's probe
    halves = spd_inverse(w.astype(np.float32)).astype(float)
    assert np.abs(w @ (halves @ probe) - probe).max() > 1.0 * probe.max()
    tries = []
    cholesky, lapack = reduced_operator.cholesky_inverse, reduced_operator._lapack_inverse

    def by_factor(matrix, precision=np.float64):
        tries.append(precision)
        return cholesky(matrix, precision)

    def by_lapack(matrix):
        if matrix.shape[0] > LEAF:                                  # not a leaf of the halves
            tries.append("lapack")
        return lapack(matrix)

    monkeypatch.setattr(reduced_operator, "cholesky_inverse", by_factor)
    monkeypatch.setattr(reduced_operator, "_lapack_inverse", by_lapack)
    pending = PendingOperator(np.arange(rows), np.ones(rows // 2, bool), np.zeros((rows // 2, 2, 2)), w, 0, ())
    inverse = advance_operator(pending, None, None, until=len(STAGES)).parts[0]
    assert tries == [np.float32]
    assert inverse.dtype == np.float64 and np.array_equal(inverse, inverse.T)
    assert np.abs(w @ (inverse @ probe) - probe).max() <= INVERSE_CHECK * probe.max()
    exact = np.linalg.inv(w)
    error = np.abs(inverse - exact).max() / np.abs(exact).max()
    assert 1e-9 < error <= 10.0 * np.finfo(np.float32).eps * np.linalg.cond(w)     # single precision's


def test_operator_in_single_precision_reaches_the_double_precision_equilibrium(monkeypatch):
    """``W``'s inverse computed in single precision (``reduced_operator.OPERATOR_PRECISION``) is within
    a few ``eps cond(W)`` of the exact inverse, and the solver, whose step is in increments, reaches the
    equilibrium an operator in double precision gives, to its tolerance: the inverse's error (and the
    rounding of the Newton step's product with it, partly summed in single precision,
    ``reduced_operator.single_product``) slows its contraction, it does not stay in the answer (a step
    computing the forces themselves, not their increments, stalls at 1.5-3.7e-7). Its cost in Newton iterations is counted
    over this load and four others (single at most 1.25 times double; measured 143 against 127):
    one solve alone follows its own path of operators (this one: 33 against 22 iterations since its
    first operator, which the inverse by halves misses in single precision, is inverted through its
    factor in single precision, not exactly by LAPACK; over twelve other loads, at
    ``rtol`` 1e-10, single precision took 314 iterations and double 331)."""
    from slewing_model import load_bearing
    from slewing_model.rings import reduced_operator
    from slewing_model.rings.superelement import build_superelement

    from conftest import BEARINGS

    assert reduced_operator.OPERATOR_PRECISION == np.float32
    bearing = load_bearing(BEARINGS / "pitch_bearing.toml")
    superelement = build_superelement(bearing, mesh="coarse", bc="free")
    loads = Loads(Fx=3e5, Fz=-4e5, Mx=2.5e6, My=-1.5e6)
    forms = []
    original = reduced_operator.start_operator

    def kept(point, compliance, stiffness, active, arithmetic=None, until=None):
        forms.append((point, compliance, stiffness, active))
        return original(point, compliance, stiffness, active, arithmetic, until)

    monkeypatch.setattr("slewing_model.distribution.bime.start_operator", kept)
    single = BimeSolver(bearing, superelement).solve(loads)
    _, _, w = reduced_operator.operator_matrix(*forms[-1])
    exact = np.linalg.inv(w)
    approximate = reduced_operator.spd_inverse(w.astype(np.float32)).astype(float)
    bound = 10.0 * np.finfo(np.float32).eps * np.linalg.cond(w)
    assert np.abs(approximate - exact).max() <= bound * np.abs(exact).max()
    assert np.abs(approximate - exact).max() >= 1e-9 * np.abs(exact).max()        # single precision indeed
    monkeypatch.setattr(reduced_operator, "OPERATOR_PRECISION", np.float64)
    double = BimeSolver(bearing, superelement).solve(loads)
    assert single.converged and double.converged and single.residual <= 1e-10
    assert not np.array_equal(single.state, double.state)                       # two computations
    assert np.abs(single.displacement - double.displacement).max() <= 1e-9 * np.abs(double.displacement).max()
    assert np.abs(single.contact_load - double.contact_load).max() <= 1e-9 * double.max_ball_load
    others = [Loads(*f) for f in ((1e5, -2e5, -3e5, -1e6, 2e6), (-2e5, 1e5, -5e5, 2e6, 1e6),
                                  (0.0, 3e5, -2e5, 3e6, -2e6), (2e5, 2e5, -6e5, -2.5e6, -1e6))]
    iterations = {}
    for precision in (np.float32, np.float64):
        monkeypatch.setattr(reduced_operator, "OPERATOR_PRECISION", precision)
        solver = BimeSolver(bearing, superelement)
        iterations[precision] = sum(solver.solve(f).iterations for f in [loads, *others])
    assert iterations[np.float32] <= 1.25 * iterations[np.float64]


@pytest.mark.parametrize("condition", [1e4, 1e9, 1e13])
def test_an_operator_too_ill_conditioned_for_single_precision_is_inverted_in_double(condition):
    """A ``W`` of condition 1e4 keeps its single-precision inverse, in single precision
    (``kept_precision``); of 1e9 (an inverse far off in single precision) and 1e13 (singular there:
    the yaw bearing's preload alone, 4e13) it is inverted again in double, and kept in double: ``X W``
    is as close to the identity as LAPACK's double inverse gives, and the probe ``checked_inverse``
    uses passes."""
    from slewing_model.rings.reduced_operator import INVERSE_CHECK, STAGES, PendingOperator, advance_operator

    rows = 300
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.standard_normal((rows, rows)))
    w = (q * np.logspace(0.0, -np.log10(condition), rows)) @ q.T
    w = 0.5 * (w + w.T)
    pending = PendingOperator(np.arange(rows), np.ones(rows // 2, dtype=bool), np.zeros((rows // 2, 2, 2)), w, 0, ())
    inverse = advance_operator(pending, None, None, until=len(STAGES)).parts[0]
    assert inverse.dtype == (np.float32 if condition < 1e6 else np.float64)
    eye = np.eye(rows)
    lapack_error = np.abs(np.linalg.inv(w) @ w - eye).max()
    error = np.abs(inverse @ w - eye).max()
    single = np.abs(np.linalg.inv(w.astype(np.float32)).astype(float) @ w - eye).max() if condition < 1e12 else np.inf
    if condition < 1e6:                                            # kept: single precision's own
        assert 1e-6 < error < INVERSE_CHECK and error >= 100 * lapack_error
    else:                                                          # single far off: again in double
        assert single > 1.0 and error <= 100 * max(lapack_error, 1e-12)


def test_an_operator_singular_in_single_precision_is_made_again_in_double_over_the_next_steps():
    """Where the solve can wait (``again``: a bounded one), a ``W`` singular in single precision (here
    two of its rows equal there; the yaw bearing's preload alone, of condition 4e13) comes back as a
    pending operator through the factor in double (method 2) at stage 0, not inverted at once (32 ms
    on the yaw bearing's 720 rows, a bounded step's); its stages then give an inverse in double that
    passes the check."""
    from slewing_model.rings.reduced_operator import STAGES, PendingOperator, advance_operator, passes_check

    rows = 300
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.standard_normal((rows, rows)))
    w = (q * np.logspace(0.0, -3.0, rows)) @ q.T
    w = 0.5 * (w + w.T)
    w[:2, :2] = [[1.0, 1.0 - 1e-10], [1.0 - 1e-10, 1.0]]     # two rows equal in single precision
    w[:2, 2:] = w[2:, :2] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.inv(w[:4, :4].astype(np.float32))
    pending = PendingOperator(np.arange(rows), np.ones(rows // 2, dtype=bool), np.zeros((rows // 2, 2, 2)), w, 0, ())
    again = advance_operator(pending, None, None, until=len(STAGES), again=True)
    assert isinstance(again, PendingOperator) and (again.method, again.stage) == (2, 0)
    for stage in range(1, len(STAGES) + 1):                 # one stage a step
        again = advance_operator(again, None, None, until=stage, again=True)
    inverse = again.parts[0]
    assert inverse.dtype == np.float64 and passes_check(w, inverse)
    # double precision's: within a few round-offs times the condition (2e10; in single, singular)
    assert np.abs(inverse @ w - np.eye(rows)).max() <= 10 * np.finfo(float).eps * np.linalg.cond(w)


def test_a_start_at_zero_loads_forms_no_operator_of_the_preload_alone(monkeypatch):
    """The yaw bearing started at zero loads (an FMU's start values): its cold solve needs no operator,
    so the first step under load has none. Its operator is formed at the held-rings start (the moving
    ring's equilibrium under the loads, the rings held), on the contacts the loads close, not at the
    start values on every diagonal: the preload's alone, of condition 4e13, singular in single
    precision (it was inverted in double, 32-53 ms). The step reaches the equilibrium a simulator with
    double-precision operators gives (both to the simulator's tolerance, 1e-7: to 1e-6 of the tilts).
    Before the singular case was handled, it raised LinAlgError."""
    from slewing_model.rings import reduced_operator
    from slewing_model.simulation.simulator import BearingSimulator

    from conftest import benchmark_case

    case, bearing, superelement = benchmark_case("yaw", 1)
    formed = []
    start_operator = bime.start_operator

    def spied(point, compliance, stiffness, active, *rest, **options):
        formed.append(2 * int(np.count_nonzero(active)))
        return start_operator(point, compliance, stiffness, active, *rest, **options)

    monkeypatch.setattr(bime, "start_operator", spied)
    results = []
    for precision in (np.float32, np.float64):
        monkeypatch.setattr(reduced_operator, "OPERATOR_PRECISION", precision)
        sim = BearingSimulator(bearing, superelement)
        sim.step(Loads(), 0.0, 0.0)
        results.append(sim.step(Loads(*case.loads[0]), case.psi[0], case.omega[0]).distribution)
    single, double = results
    assert formed and max(formed) < 4 * bearing.ball_count     # none on every diagonal
    assert single.converged and double.converged
    assert np.abs(single.displacement - double.displacement).max() <= 1e-6 * np.abs(double.displacement).max()
    assert single.max_ball_load == pytest.approx(double.max_ball_load, rel=1e-6)


def test_inverse_spread_over_two_steps_equals_the_inverse_at_once(double_operator):
    """The new operator's inverse in the stages of two steps (a complete solve's) or one stage at a
    time (a bounded solve's), its state serialised between them (a co-simulation's rollback), is
    :func:`spd_inverse`'s bit for bit; through the Cholesky factor (a pending operator of method 1 or
    2), :func:`cholesky_inverse`'s."""
    from conftest import BEARINGS
    from slewing_model import load_bearing
    from slewing_model.rings.reduced_operator import (
        STAGES, PendingOperator, advance_operator, cholesky_inverse, method_precision, spd_inverse,
    )
    from slewing_model.rings.compliance import contact_compliance, ring_compliances
    from slewing_model.rings.superelement import build_superelement

    bearing = load_bearing(BEARINGS / "pitch_bearing.toml")
    rings = np.asarray(contact_compliance(ring_compliances(build_superelement(bearing, mesh="coarse", bc="free"))))
    rng = np.random.default_rng(2)
    for rows in (40, 377):
        w = rings[:rows, :rows] + np.diag(rng.uniform(0.2, 2.0, rows) * 1e-3 * np.abs(rings).max())
        pending = advance_operator(PendingOperator(np.arange(rows), np.ones(rows // 2, bool), np.zeros((rows // 2, 2, 2)),
                                                   w, 0, ()), None, None)
        pending = advance_operator(PendingOperator.from_tuple(through_json(pending.as_tuple())), None, None)
        assert pending.stage == len(STAGES)
        assert np.array_equal(pending.parts[0], spd_inverse(w))
        # a bounded step's way: one stage at a time, serialised after each
        pending = PendingOperator(np.arange(rows), np.ones(rows // 2, bool), np.zeros((rows // 2, 2, 2)), w, 0, ())
        while pending.stage < len(STAGES):
            pending = advance_operator(pending, None, None, until=pending.stage + 1)
            pending = PendingOperator.from_tuple(through_json(pending.as_tuple()))
        assert np.array_equal(pending.parts[0], spd_inverse(w))
        # the inverse through the Cholesky factor (methods 1 and 2: an inverse made again) the same way
        for method in (1, 2):
            pending = PendingOperator(np.arange(rows), np.ones(rows // 2, bool), np.zeros((rows // 2, 2, 2)), w, 0, (),
                                      method)
            while pending.stage < len(STAGES):
                pending = advance_operator(pending, None, None, until=pending.stage + 1)
                pending = PendingOperator.from_tuple(through_json(pending.as_tuple()))
            assert pending.method == method
            assert np.array_equal(pending.parts[0], cholesky_inverse(w, method_precision(method)))


def test_cold_solve_does_not_depend_on_the_solves_before(bearing):
    """A solve without a warm start is the same whatever the solver did before, a new operator
    left half inverted by a warm solve included (found by a review: it was completed later
    in the cold solve instead of one formed there)."""
    rings = synthetic_superelement(bearing.ball_count)
    solver = BimeSolver(bearing, rings, rtol=1e-10)
    result = solver.solve(Loads(Fz=5e4, My=1e4))
    k = 0
    while solver.pending_operator is None:              # warm solves of a growing moment, until one slows
        k += 1
        assert k < 40, "no new operator was left pending"
        result = solver.solve(Loads(Fz=5e4, My=1e4 * (1 + 0.15 * k)), initial=result)
    cold = solver.solve(Loads(Fz=5e4, My=1e4 * (1 + 0.15 * k)))
    fresh = BimeSolver(bearing, rings, rtol=1e-10).solve(Loads(Fz=5e4, My=1e4 * (1 + 0.15 * k)))
    assert solver.pending_operator is None
    assert np.array_equal(cold.state, fresh.state) and cold.iterations == fresh.iterations


@pytest.mark.parametrize("kernel", ["numpy", "compiled"])
def test_operator_bordered_by_closed_contacts_equals_a_fresh_one(bearing, kernel, double_operator):
    """Contacts closing (the kept inverse bordered by their rows; those that opened keep theirs)
    give the inverse, coupling and Schur complement that forming and inverting the operator on
    the same contacts gives, at the same iterate, with the rows in another order; the bordering's
    blocks by numpy or by the compiled loop (``contact_kernel.bordered_inverse``)."""
    from slewing_model.friction.kernel import AVAILABLE
    from slewing_model.rings.reduced_operator import assemble_operator, newton_step, update_operator

    if kernel == "compiled" and not AVAILABLE:
        pytest.skip("numba is not installed: only the numpy path exists here")
    arithmetic = None
    if kernel == "compiled":
        from slewing_model.distribution.kernel import COMPILED_ARITHMETIC as arithmetic

    loads = LOADS[1]
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    result = solver.solve(loads)
    point = solver._evaluate(result.state[:5], result.state[5:], solver.scaled_load(loads))
    loaded = np.flatnonzero((point.delta > 0.0).ravel())
    assert loaded.size > 12
    mu = 1e-12 * solver.reference_stiffness
    jacobian, stiffness = solver.jacobian, solver.assembly.stiffness

    def mask(diagonals):
        active = np.zeros(point.delta.size, dtype=bool)
        active[diagonals] = True
        return active

    def formed(active):
        return assemble_operator(point, solver.compliance, stiffness, jacobian, active, mu)

    for before, after in ((loaded[[0, 2] + list(range(5, loaded.size))], loaded),      # three close
                          (np.delete(loaded, [1, 7]), np.delete(loaded, [4, 9, 10]))):  # two close, three open
        kept = formed(mask(before))
        updated = update_operator(kept, point, solver.compliance, stiffness, jacobian, mask(after), mu, arithmetic)
        assert np.array_equal(updated.rows[:kept.rows.size], kept.rows)     # the kept rows stay, opened or not
        fresh = formed(mask(before) | mask(after))
        order = np.argsort(updated.rows)
        assert np.array_equal(updated.rows[order], fresh.rows)
        assert np.array_equal(updated.active, fresh.active)
        scale = np.abs(fresh.inverse).max()
        assert np.abs(updated.inverse[np.ix_(order, order)] - fresh.inverse).max() <= 1e-9 * scale
        assert np.abs(updated.coupling[order] - fresh.coupling).max() <= 1e-9 * np.abs(fresh.coupling).max()
        assert np.allclose(updated.schur_inverse, fresh.schur_inverse, rtol=1e-8)
        assert np.array_equal(updated.contact_compliance[order[::2] // 2], fresh.contact_compliance)
        # and the step it gives, away from the equilibrium (the forces picked in the operator's order)
        off = solver._evaluate(1.01 * result.state[:5], 0.98 * result.state[5:], solver.scaled_load(loads))
        (dq_u, y_u), (dq_f, y_f) = (newton_step(op, off, solver.scaled_load(loads)) for op in (updated, fresh))
        assert np.abs(dq_u - dq_f).max() <= 1e-9 * np.abs(dq_f).max()
        assert np.abs(y_u - y_f).max() <= 1e-9 * np.abs(y_f).max()


@pytest.mark.parametrize("kernel", ["numpy", "compiled"])
def test_newton_step_in_increments_solves_the_reduced_system(bearing, kernel, double_operator):
    """The modified Newton step, computed in increments (``reduced_operator.newton_step``), is the
    solution of the reduced system as the module states it, solved here densely from ``M``'s
    entries: ``[[W, -J_a], [J_a^T, mu I]] [y_a; dq] = [A^-1 f_a + (M y)_a; F]``, ``W = (A^-1 + M)_aa``;
    also at an iterate whose forces are not all on the operator's rows (a fresh operator on fewer
    contacts: the rings' motion under those forces enters as ``off_motion``), where leaving it out
    gives another step."""
    from slewing_model.rings.reduced_operator import assemble_operator, newton_step, off_rows

    step = newton_step
    if kernel == "compiled":
        from slewing_model.friction.kernel import AVAILABLE

        if not AVAILABLE:
            pytest.skip("numba is not installed: only the numpy path exists here")
        from slewing_model.distribution.kernel import newton_step as step
    loads = LOADS[1]
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    result = solver.solve(loads)
    f_scaled = solver.scaled_load(loads)
    converged = solver._evaluate(result.state[:5], result.state[5:], f_scaled)
    # forces 2 % below the equilibrium's, on its loaded diagonals only (which stay loaded: the rings give way less)
    y = np.where(np.repeat(converged.loaded, 2), 0.98 * converged.y, 0.0)
    point = solver._evaluate(result.state[:5], y, f_scaled)
    loaded = np.flatnonzero(point.loaded)
    assert not np.delete(point.y.reshape(-1, 2), loaded, axis=0).any()
    mu = 1e-12 * solver.reference_stiffness
    dense_m = np.column_stack([solver.compliance @ column for column in np.eye(point.y.size)])
    for diagonals in (loaded, np.delete(loaded, np.s_[::5])):
        active = np.isin(np.arange(point.loaded.size), diagonals)
        op = assemble_operator(point, solver.compliance, solver.assembly.stiffness, solver.jacobian, active, mu)
        rows = op.rows
        a_inv = np.zeros((rows.size, rows.size))
        for k in range(rows.size // 2):
            a_inv[2 * k:2 * k + 2, 2 * k:2 * k + 2] = op.contact_compliance[k]
        w = a_inv + dense_m[np.ix_(rows, rows)]
        ja = solver.jacobian.reshape(-1, 5)[rows]
        system = np.block([[w, -ja], [ja.T, mu * np.eye(5)]])
        rhs = np.concatenate([a_inv @ point.force.ravel()[rows] + (dense_m @ point.y)[rows], f_scaled])
        expected = np.linalg.solve(system, rhs)
        y_off = off_rows(op, point.y)
        assert (y_off is None) == (diagonals.size == loaded.size)
        off_motion = None if y_off is None else solver.compliance @ y_off
        dq, y_new = step(op, point, f_scaled, off_motion)
        x = np.concatenate([y_new[rows], dq])
        # the system's residual against its terms' size (backward error), and the forces against the dense solve's
        assert np.abs(system @ x - rhs).max() <= 1e-14 * (np.abs(system) @ np.abs(x) + np.abs(rhs)).max()
        assert np.abs(y_new[rows] - expected[:-5]).max() <= 1e-9 * np.abs(expected[:-5]).max()
        assert not np.delete(y_new, rows).any()                         # zero off the operator's rows
        if y_off is not None:                                           # the off-row forces' motion counts
            dq_without, _ = step(op, point, f_scaled)
            assert np.abs(dq_without - dq).max() > 1e-4 * np.abs(dq).max()


def test_operator_turned_then_bordered_follows_the_new_jacobian(bearing, double_operator):
    """A warm solve after the ring turned, with contacts closing: the kept operator is turned to the
    new Jacobian before it is bordered, so that its coupling is ``W^-1 J`` of the new angle (bordering
    the old coupling with new rows leaves it a few per cent off, and the turn then sees no change).
    In double precision, to round-off (a bordered inverse kept in single is rounded after its coupling
    was formed: 6e-8 off)."""
    rings = synthetic_superelement(bearing.ball_count)
    solver = BimeSolver(bearing, rings, rtol=1e-10)
    before = solver.solve(Loads(Fz=5e4, My=4.6e4))
    smaller = Loads(Fz=5e4, My=4.4e4)                                      # a smaller moment: contacts close
    start = BimeSolver(bearing, rings, rtol=1e-10).solve(smaller)           # ... at the first iterate already
    solver.set_rotation(0.05)
    after = solver.solve(smaller, initial=start)
    op = solver._reduced
    assert (after.interference > 0).sum() > (before.interference > 0).sum()
    assert np.any(np.diff(op.rows) < 0)                                     # bordered: rows appended
    formed = op.inverse @ solver.jacobian.reshape(-1, 5)[op.rows]
    assert np.abs(op.coupling - formed).max() <= 1e-9 * np.abs(formed).max()


def test_contacts_opening_under_the_kept_operator_reach_the_cold_solution(bearing):
    """Contacts that open keep their rows (and their earlier stiffness) in the operator until a
    fresh one: the iteration still ends at the equilibrium of the new load, where they carry
    nothing."""
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count), rtol=1e-10)
    before = solver.solve(Loads(Fz=5e4, My=4.4e4))
    tilted = Loads(Fz=5e4, My=4.6e4)         # a larger moment lifts the balls on one side
    warm = solver.solve(tilted, initial=before)
    opened = (before.interference > 0) & ~(warm.interference > 0)
    assert opened.any()                                          # the case does open contacts ...
    assert solver._reduced.active[opened.ravel()].any()          # ... that stayed in the operator
    cold = BimeSolver(bearing, synthetic_superelement(bearing.ball_count), rtol=1e-10).solve(tilted)
    assert np.allclose(warm.contact_load, cold.contact_load, rtol=1e-8, atol=1e-8 * cold.max_ball_load)
    assert np.allclose(warm.displacement, cold.displacement, rtol=1e-8, atol=1e-14)
    ring_forces = warm.state[5:].reshape(-1, 2, 2)                # y: the forces the rings feel, per diagonal
    assert np.abs(ring_forces[opened]).max() <= 1e-9 * cold.max_ball_load


@pytest.mark.parametrize("with_errors", [False, True])
def test_operator_after_a_turn_equals_one_formed_anew(bearing, with_errors):
    """After the ring turns, the kept operator's coupling to the ring's motions follows the
    Jacobian: for balls that keep their groove centres by a 5 x 5 column turn (eq 23), else
    (manufacturing errors move the groove centres with the ring) formed anew; either way as
    forming it from the new Jacobian. With errors and a tolerance, turned all the same: then an
    operator for the turned old Jacobian, which is that close to the new one."""
    from slewing_model.bearing.manufacturing import synthetic_errors
    from slewing_model.rings.reduced_operator import APPROXIMATE_TURN, reduced_operator, turned_operator

    if with_errors:
        bearing = bearing.with_errors(synthetic_errors(bearing.ball_count, seed=2))
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    solver.solve(LOADS[1])
    op, mu = solver._reduced, 1e-12 * solver.reference_stiffness
    solver.set_rotation(0.3)
    # which way: without errors the new Jacobian is the old one with its columns turned
    old, new = op.jacobian, solver.jacobian.reshape(-1, 5)[op.rows]
    fit = old @ np.linalg.lstsq(old, new, rcond=None)[0] - new
    assert (np.abs(fit).max() > 1e-9 * np.abs(new).max()) == with_errors
    turned = turned_operator(op, solver.jacobian, mu)
    formed = reduced_operator(op.rows, op.active, op.contact_compliance, op.inverse, solver.jacobian, mu)
    if with_errors:     # nearly a turn: an operator for J_old T, within the tolerance of the new Jacobian
        near = turned_operator(op, solver.jacobian, mu, APPROXIMATE_TURN)
        off = np.abs(near.jacobian - new).max() / np.abs(new).max()
        assert 1e-12 < off <= APPROXIMATE_TURN, off
        assert np.abs(near.coupling - op.inverse @ near.jacobian).max() <= 1e-9 * np.abs(near.coupling).max()
        schur = np.linalg.inv(near.jacobian.T @ near.coupling + mu * np.eye(5))
        assert np.abs(near.schur_inverse - schur).max() <= 1e-9 * np.abs(schur).max()
    assert np.array_equal(turned.jacobian, formed.jacobian)
    assert np.abs(turned.coupling - formed.coupling).max() <= 1e-12 * np.abs(formed.coupling).max()
    assert np.allclose(turned.schur_inverse, formed.schur_inverse, rtol=1e-9, atol=1e-12 * np.abs(formed.schur_inverse).max())


def test_nearly_turned_operator_bordered_stays_one_operator(bearing, double_operator):
    """A kept operator nearly turned (grooves with errors, :data:`APPROXIMATE_TURN`) stands for the
    turned old Jacobian; bordered by a contact that closes, its rows keep that Jacobian, so that
    its coupling is still ``W^-1 J`` of the Jacobian it holds (in double precision, to round-off)."""
    from slewing_model.bearing.manufacturing import synthetic_errors
    from slewing_model.rings.reduced_operator import APPROXIMATE_TURN, assemble_operator, turned_operator, update_operator

    bearing = bearing.with_errors(synthetic_errors(bearing.ball_count, seed=2))
    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    result = solver.solve(LOADS[1])
    f_scaled = solver.scaled_load(LOADS[1])
    point = solver._evaluate(result.state[:5], result.state[5:], f_scaled)
    mu, stiffness = 1e-12 * solver.reference_stiffness, solver.assembly.stiffness
    fewer = point.loaded.copy()
    fewer[np.flatnonzero(fewer)[0]] = False                   # one loaded diagonal left out, to border in
    op = assemble_operator(point, solver.compliance, stiffness, solver.jacobian, fewer, mu)
    solver.set_rotation(0.3)
    near = turned_operator(op, solver.jacobian, mu, APPROXIMATE_TURN)
    assert not np.array_equal(near.jacobian, solver.jacobian.reshape(-1, 5)[near.rows])      # nearly, not exactly
    bordered = update_operator(near, point, solver.compliance, stiffness, solver.jacobian, point.loaded, mu)
    assert bordered.rows.size == near.rows.size + 2
    assert np.array_equal(bordered.jacobian[:near.rows.size], near.jacobian)
    coupling = bordered.inverse @ bordered.jacobian
    assert np.abs(bordered.coupling - coupling).max() <= 1e-9 * np.abs(coupling).max()


def test_operator_on_few_contacts_after_a_turn_equals_one_formed_anew(bearing):
    """On one or two loaded diagonals the Jacobian has rank below 5 and no column turn can be
    fitted: the coupling is then formed anew, without error (found by a review: a singular solve)."""
    from slewing_model.rings.reduced_operator import assemble_operator, reduced_operator, turned_operator

    solver = BimeSolver(bearing, synthetic_superelement(bearing.ball_count))
    loads = LOADS[1]
    result = solver.solve(loads)
    point = solver._evaluate(result.state[:5], result.state[5:], solver.scaled_load(loads))
    loaded = np.flatnonzero((point.delta > 0.0).ravel())
    mu = 1e-12 * solver.reference_stiffness
    for count in (1, 2, 3):
        active = np.zeros(point.delta.size, dtype=bool)
        active[loaded[:count]] = True
        rows = np.flatnonzero(np.repeat(active, 2))
        op = assemble_operator(point, solver.compliance, solver.assembly.stiffness, solver.jacobian, active, mu)
        solver.set_rotation(0.3 * count)
        turned = turned_operator(op, solver.jacobian, mu)
        formed = reduced_operator(rows, active, op.contact_compliance, op.inverse, solver.jacobian, mu)
        assert np.abs(turned.coupling - formed.coupling).max() <= 1e-12 * np.abs(formed.coupling).max()
        solver.set_rotation(0.0)


@pytest.mark.parametrize("where", ["solver", "settings"])
def test_unknown_contact_kernel_is_refused(bearing, where):
    from slewing_model.simulation.simulator import SimulatorSettings

    with pytest.raises(ValueError, match="kernel = 'fortran': must be 'auto', 'numpy' or 'compiled'"):
        BimeSolver(bearing, kernel="fortran") if where == "solver" else SimulatorSettings(contact_kernel="fortran")
