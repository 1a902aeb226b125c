"""The load distribution's compiled loops (:mod:`slewing_model.distribution.kernel`) against its numpy code.

Each compiled loop (a new rotation's grooves and Jacobian, a trial point and its springs, the
modified Newton step, the ring compliance's product, the reduced operator formed, coupled, turned
and bordered, a result's contacts and refusals) against the numpy code it stands for, at a
solver's iterates and off them: equal to round-off, most bit for bit; and a co-simulation stepped
with either (with the compiled loops, most iterations in one loop) takes the same iterations to
the same outputs, to round-off.
"""
import math

import numpy as np
import pytest

from slewing_model import BimeSolver, Loads, load_bearing
from slewing_model.distribution import LoadCapacityError
from slewing_model.friction.kernel import AVAILABLE
from slewing_model.rings.superelement import build_superelement

from conftest import BEARINGS, simulators_per_kernel, symmetric_block_circulant

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="numba is not installed: only the numpy path exists here")


@pytest.fixture(scope="module")
def pitch():
    bearing = load_bearing(BEARINGS / "pitch_bearing.toml")
    return bearing, build_superelement(bearing, mesh="coarse", bc="free")


def _table3_with_measured_radii(table3):
    """table3 whose balls each see other grooves, their radii measured too: every ball's and
    diagonal's stiffness and natural length differ."""
    from slewing_model import synthetic_errors
    from slewing_model.bearing.manufacturing import ManufacturingErrors, RingErrorMap

    synthetic = synthetic_errors(table3.ball_count, seed=7)
    outer = synthetic.outer
    radii = table3.groove_radius[[0, 3]] * (1.0 + 2e-3 * np.stack([np.sin(outer.angle), np.cos(3 * outer.angle)], 1))
    return table3.with_errors(ManufacturingErrors(outer=RingErrorMap(outer.angle, outer.radial, outer.axial, radii),
                                                  inner=synthetic.inner,
                                                  ball_diameter_deviation=synthetic.ball_diameter_deviation))


def _case(which: str, pitch, table3):
    """The bearing, its superelement and a combined load of the two cases these tests run: the pitch
    bearing, and table3 whose balls each see other grooves (every ball's and diagonal's stiffness
    and natural length differ)."""
    if which == "pitch":
        return (*pitch, Loads(Fx=2e5, Fz=-3e5, Mx=4e6, My=-1.5e6))
    bearing = _table3_with_measured_radii(table3)
    superelement = build_superelement(table3, mesh="coarse", bc="free")
    assert np.unique(BimeSolver(bearing, superelement).assembly.stiffness).size == bearing.ball_count * 2
    return bearing, superelement, Loads(Fx=2e4, Fz=1e5, Mx=3e4, My=-2e4)


@pytest.mark.parametrize("which", ["pitch", "table3 with errors"])
def test_compiled_trial_points_equal_the_numpy_ones(pitch, table3, which):
    bearing, superelement, loads = _case(which, pitch, table3)
    solvers = {k: BimeSolver(bearing, superelement, psi=0.3, kernel=k) for k in ("numpy", "compiled")}
    jacobian = solvers["numpy"].jacobian                                  # eq 23, set_rotation
    assert np.abs(solvers["compiled"].jacobian - jacobian).max() <= 1e-15 * np.abs(jacobian).max()
    state = solvers["numpy"].solve(loads).state
    rng = np.random.default_rng(5)
    f_scaled = solvers["numpy"].scaled_load(loads)
    compliance = solvers["numpy"].compliance
    for scale in (0.0, 1e-3, 2e-2):                      # the equilibrium, and points off it
        x = state * (1.0 + scale * rng.standard_normal(state.size))
        direction = (1e-3 * x[:5] * rng.standard_normal(5), 1e-2 * x[5:] * rng.standard_normal(state.size - 5))
        direction += (compliance @ direction[1],)
        # each path's own M y at x (numpy's FFT, the compiled DFT): equal to round-off, which the stiff
        # springs amplify in q past this test's 1e-13; the rest is compared with the same M y given
        own = {k: s._evaluate(x[:5], x[5:], f_scaled).ring_motion for k, s in solvers.items()}
        terms = (np.abs(np.asarray(compliance)) @ np.abs(x[5:])).max()        # the products' round-off scale
        assert np.abs(own["compiled"] - own["numpy"]).max() <= 1e-14 * terms
        # at x, and a trial point along a line
        for along in ((compliance @ x[5:],), (compliance @ x[5:], direction, 0.37)):
            points = {k: s._evaluate(x[:5], x[5:], f_scaled, *along) for k, s in solvers.items()}
            for name in ("qs", "y", "ring_motion", "e", "delta", "q", "force", "n", "length", "gradient", "mismatch"):
                ref, got = getattr(points["numpy"], name), getattr(points["compiled"], name)
                # the gradient and mismatch are differences of the forces: round-off on the forces' scale
                force_scale = points["numpy"].peak_force if name in ("gradient", "mismatch") else 0.0
                assert np.abs(got - ref).max() <= 1e-13 * max(np.abs(ref).max(), force_scale), name
            for name in ("total", "peak_force"):
                assert getattr(points["compiled"], name) == pytest.approx(getattr(points["numpy"], name), rel=1e-12)
            residuals = points["compiled"].peak_residual, points["numpy"].peak_residual
            assert abs(residuals[0] - residuals[1]) <= 1e-13 * points["numpy"].peak_force
            assert np.array_equal(points["compiled"].loaded, points["numpy"].loaded)
            assert points["compiled"].any_loaded == points["numpy"].any_loaded
            assert (points["numpy"].delta > 0).sum() < points["numpy"].delta.size    # some springs open


@pytest.mark.parametrize("which", ["pitch", "table3 with errors"])
def test_compiled_contact_results_equal_the_numpy_ones(pitch, table3, which):
    """What a result reports of its contacts (loads, angles, deflections, Hertz ellipses and pressures,
    edge loading) and its refusals of loads past the groove edge or the pressure limit, by the
    compiled loop and by numpy, at the same iterate: balls of other diameters and grooves of other
    measured radii too."""
    bearing, superelement, loads = _case(which, pitch, table3)
    solvers = {k: BimeSolver(bearing, superelement, psi=0.3, kernel=k) for k in ("numpy", "compiled")}
    state = solvers["numpy"].solve(loads).state
    f_scaled = solvers["numpy"].scaled_load(loads)
    point = solvers["numpy"]._evaluate(state[:5], state[5:], f_scaled)
    results = {k: s._result(loads, point, 3, 1e-9) for k, s in solvers.items()}
    for name in ("contact_load", "contact_angle", "contact_deflection", "semi_axis_a", "semi_axis_b",
                 "contact_pressure"):
        ref, got = getattr(results["numpy"], name), getattr(results["compiled"], name)
        assert np.array_equal(got == 0.0, ref == 0.0) and np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max(), name
    assert 0 < (results["numpy"].contact_load > 0).sum() < results["numpy"].contact_load.size   # some unloaded
    loaded_angle = results["numpy"].contact_angle[results["numpy"].contact_load > 0]

    def refusals(match, **settings):
        messages = []
        for s in solvers.values():
            for name, value in settings.items():
                setattr(s, name, value)
            with pytest.raises(LoadCapacityError, match=match) as refused:
                s._result(loads, point, 3, 1e-9)
            messages.append(str(refused.value))
        return messages

    # groove edges just past the largest contact angle: no contact off the raceway, some ellipses over the edge
    for s in solvers.values():
        s.edge_angle = np.full(4, loaded_angle.max() + 1e-9)
    truncated = {k: s._result(loads, point, 3, 1e-9).truncated for k, s in solvers.items()}
    assert np.array_equal(truncated["compiled"], truncated["numpy"])
    assert 0 < truncated["numpy"].sum() < loaded_angle.size
    first, second = refusals("past the groove edge", edge_angle=np.full(4, np.percentile(loaded_angle, 99)))
    assert first == second
    first, second = refusals("MPa, above the limit", edge_angle=np.full(4, 2.0),
                             pressure_limit=0.5 * results["numpy"].max_contact_pressure)
    assert first == second


@pytest.mark.parametrize("precision", ["double", "single"])
def test_compiled_newton_step_equals_the_numpy_step(pitch, precision, monkeypatch):
    """The modified Newton step with a kept operator, formed or bordered by contacts that closed (in
    double precision its inverse is symmetric to round-off only; in single, the operator's own
    precision, its inverse is kept in single, reduced_operator.kept_precision), at an iterate away
    from the operator's own; and the operator's matrix and coupling formed by the compiled loops."""
    from slewing_model.distribution.kernel import newton_step as compiled_step
    from slewing_model.rings import reduced_operator
    from slewing_model.rings.reduced_operator import assemble_operator, newton_step, update_operator

    if precision == "double":
        monkeypatch.setattr(reduced_operator, "OPERATOR_PRECISION", np.float64)
    assert reduced_operator.OPERATOR_PRECISION == (np.float64 if precision == "double" else np.float32)

    bearing, superelement = pitch
    loads = Loads(Fx=2e5, Fz=-3e5, Mx=4e6, My=-1.5e6)
    solver = BimeSolver(bearing, superelement)
    state = solver.solve(loads).state
    f_scaled = solver.scaled_load(loads)
    point = solver._evaluate(state[:5], state[5:], f_scaled)
    loaded = np.flatnonzero(point.delta.ravel() > 0.0)
    mu = 1e-12 * solver.reference_stiffness
    args = (point, solver.compliance, solver.assembly.stiffness)
    fewer = np.delete(loaded, np.s_[::8])                               # an operator some contacts close on
    masks = [np.isin(np.arange(point.delta.size), diagonals) for diagonals in (loaded, fewer, loaded)]
    formed = assemble_operator(*args, solver.jacobian, masks[1], mu)
    bordered = update_operator(formed, *args, solver.jacobian, masks[2], mu)
    assert bordered is not None and bordered.rows.size == 2 * loaded.size
    if precision == "double":
        assert not np.array_equal(bordered.inverse, bordered.inverse.T)      # symmetric to round-off only
    assert formed.inverse.dtype == bordered.inverse.dtype == reduced_operator.OPERATOR_PRECISION
    off = solver._evaluate(1.01 * state[:5], 0.98 * state[5:], f_scaled)
    # a new operator's W and springs' compliance, formed by the compiled loop: the same bit for bit
    from slewing_model.distribution.kernel import operator_matrix as compiled_matrix
    from slewing_model.rings.reduced_operator import operator_matrix

    for want, got in zip(operator_matrix(*args, masks[0]), compiled_matrix(*args, masks[0])):
        assert np.array_equal(want, got)
    # ... and its coupling to the ring's motions, W^-1 J_a and the Schur complement's inverse
    from slewing_model.distribution.kernel import operator_coupling as compiled_coupling
    from slewing_model.rings.reduced_operator import operator_coupling

    ja = solver.jacobian.reshape(-1, 5)[bordered.rows]
    for want, got in zip(operator_coupling(bordered.inverse, ja, mu), compiled_coupling(bordered.inverse, ja, mu)):
        assert np.abs(got - want).max() <= 1e-11 * np.abs(want).max()
    # the products with W^-1 (the coupling's, the inverse's check) read it as kept and sum in double: they are
    # BLAS's product with it converted, to double round-off (summed in single precision they would be 1e-7 off)
    from slewing_model.distribution.kernel import inverse_product as compiled_product
    from slewing_model.rings.reduced_operator import inverse_product

    vectors = np.vstack([ja.T, 1.0 + 0.125 * (np.arange(bordered.rows.size) % 7)])
    exact = bordered.inverse.astype(np.float64) @ vectors.T
    for product in (inverse_product, compiled_product):
        got = product(bordered.inverse, vectors).T
        assert np.abs(got - exact).max() <= 1e-13 * np.abs(exact).max()
    for op in (assemble_operator(*args, solver.jacobian, masks[0], mu), bordered):
        (dq, y), (dq_c, y_c) = newton_step(op, off, f_scaled), compiled_step(op, off, f_scaled)
        assert np.abs(dq_c - dq).max() <= 1e-11 * np.abs(dq).max()
        assert np.abs(y_c - y).max() <= 1e-11 * np.abs(y).max()
        assert np.array_equal(y_c == 0.0, y == 0.0)                          # zero off the operator's rows


def test_compiled_column_turn_equals_the_numpy_turn(pitch, table3):
    """After a turn of the ring the kept operator's coupling ``W^-1 J`` follows by a 5 x 5 column turn
    where one exists: the compiled turn gives the numpy one's coupling and Schur complement, and
    finds none where numpy finds none (grooves with errors turning with the ring), unless both are
    given a tolerance, within which they agree on the nearly turned operator."""
    from slewing_model import synthetic_errors
    from slewing_model.distribution.kernel import column_turn as compiled_turn
    from slewing_model.rings.reduced_operator import column_turn

    bearing, superelement = pitch
    solver = BimeSolver(bearing, superelement, psi=0.2)
    solver.solve(Loads(Fx=2e5, Fz=-3e5, Mx=4e6, My=-1.5e6))
    op, mu = solver.operator, 1e-12 * solver.reference_stiffness
    solver.set_rotation(0.23)
    new = solver.jacobian.reshape(-1, 5)[op.rows]
    want, got = column_turn(op.jacobian, new, op.coupling, mu), compiled_turn(op.jacobian, new, op.coupling, mu)
    assert want is not None and got is not None
    for a, b in zip(got, want):
        assert np.abs(a - b).max() <= 1e-11 * np.abs(b).max()
    # the turn reproduces the coupling formed from the new Jacobian
    assert np.abs(got[0] - op.inverse @ new).max() <= 1e-9 * np.abs(got[0]).max()
    errors = table3.with_errors(synthetic_errors(table3.ball_count, seed=3))
    moved = BimeSolver(errors, build_superelement(table3, mesh="coarse", bc="free"), psi=0.2)
    moved.solve(Loads(Fz=1e5, My=2e4))
    op_e = moved.operator
    moved.set_rotation(0.25)
    new_e = moved.jacobian.reshape(-1, 5)[op_e.rows]
    assert column_turn(op_e.jacobian, new_e, op_e.coupling, mu) is None
    assert compiled_turn(op_e.jacobian, new_e, op_e.coupling, mu) is None
    # with a tolerance, nearly a turn: both give the operator for the fitted old Jacobian
    want, got = (turn(op_e.jacobian, new_e, op_e.coupling, mu, 1e-4) for turn in (column_turn, compiled_turn))
    for a, b in zip(got, want):
        assert np.abs(a - b).max() <= 1e-11 * np.abs(b).max()
    assert not np.array_equal(want[2], new_e)
    broken = new.copy()
    broken[3, 1] = np.nan                              # a Jacobian that is not finite: no turn either
    assert column_turn(op.jacobian, broken, op.coupling, mu) is None
    assert compiled_turn(op.jacobian, broken, op.coupling, mu) is None


def test_compiled_error_tables_equal_numpy_interp(table3):
    """The grooves under the balls at a new rotation, from the rings' error tables interpolated by
    the compiled loop and added to the nominal grooves: numpy's values bit for bit, with measured
    groove radii and without, at angles past a turn and negative, assembled anew and from the last
    rotation (as a co-simulation step does)."""
    from slewing_model import synthetic_errors
    from slewing_model.distribution.assembly import assemble

    for bearing in (table3.with_errors(synthetic_errors(table3.ball_count, seed=3)),
                    _table3_with_measured_radii(table3)):
        last = assemble(bearing, 0.2)
        for psi in (0.0, 0.37, -2.5, 7.1):
            for previous in (None, last):
                want = assemble(bearing, psi, previous=previous)
                got = assemble(bearing, psi, previous=previous, compiled=True)
                assert np.array_equal(got.groove_centre, want.groove_centre)
                assert np.array_equal(got.groove_radius, want.groove_radius)
                assert np.array_equal(got.stiffness, want.stiffness)
                assert not np.array_equal(want.groove_centre, last.groove_centre)    # other grooves under the balls


@pytest.mark.parametrize("rows", [2, 6, 8, 14, 376])
def test_single_precision_sums_are_the_same_in_both_paths_and_within_their_rounding(rows):
    """The Newton step's product with a kept single-precision ``W^-1``, summed in single precision block
    by block (``kernel._single_times``, ``reduced_operator.single_product``): the compiled loop and
    numpy give the same bits (the same exactly rounded operations in the same order; numpy's reduction
    order included), for fewer rows than a block, whole blocks and a block left over. Each entry is
    within the rounding bound of its operations, ``v`` rounded (u), each product rounded (u) and a
    block's at most eight terms summed in single precision (7u): ``|p - W v| <= 10 u |W| |v|``
    entry by entry, ``u = 2^-24``; and not within double precision's (it is summed in single)."""
    from slewing_model.distribution import kernel
    from slewing_model.numerics.compiled import compile_helpers
    from slewing_model.rings.reduced_operator import single_product

    compile_helpers(vars(kernel), ("_single_times",), kernel.ERROR_MODEL, fastmath=kernel.FASTMATH)
    compiled = kernel._single_times                     # the helper the Newton step calls, compiled in place
    rng = np.random.default_rng(rows)
    a = rng.standard_normal((rows, rows)) * 10.0 ** rng.uniform(-2, 2, (rows, rows))
    inverse = (a + a.T).astype(np.float32)
    unit = 2.0 ** -24
    for v in (rng.standard_normal(rows) * 10.0 ** rng.uniform(-3, 3, rows), np.full(rows, 1.0 / 3.0)):
        got = single_product(inverse, v)
        assert np.array_equal(compiled(inverse, v), got)
        exact = inverse.astype(np.float64) @ v
        scale = np.abs(inverse.astype(np.float64)) @ np.abs(v)
        assert np.all(np.abs(got - exact) <= 10.0 * unit * scale)
        assert np.abs(got - exact).max() > 1e-12 * scale.max()


@pytest.mark.parametrize("balls", [2, 5, 67, 150, 151, 180])
def test_compiled_ring_product_equals_the_dense_product(balls):
    """The ring compliance's product in the compiled iterations (``contact_kernel._ring_times``), a
    real DFT by tables (even and odd numbers of balls: the harmonic B/2 is real or absent), against
    the dense product, also for a vector with the zero rows of those off the reduced operator."""
    from slewing_model.distribution.kernel import compiled_ring_times
    from slewing_model.rings.compliance import BlockCirculant, product_operands

    dense = symmetric_block_circulant(balls, seed=balls)
    operands = product_operands(BlockCirculant(dense, 4))
    rng = np.random.default_rng(balls + 1)
    for y in (rng.standard_normal(4 * balls), np.where(rng.random(4 * balls) < 0.4, 0.0, 1.0)):
        expected = np.array([math.fsum(dense[r] * y) for r in range(4 * balls)])
        got = compiled_ring_times()(*operands, y)
        assert np.abs(got - expected).max() <= 1e-14 * np.abs(expected).max()     # numpy's FFT: 5e-16


@pytest.mark.parametrize("name", ["pitch", "table3_heavy"])
def test_iterations_in_one_loop_equal_them_one_by_one(name, monkeypatch):
    """The compiled loop of the iterations that keep the operator (``_kept_iterations``) against the
    same iterations run one by one by ``BimeSolver.solve`` (the loop switched off): the same
    iterations and states to round-off over the steps of a case, and, where the solver runs out of
    iterations inside the loop, the same refusal."""
    from slewing_model.distribution.bime import BimeSolver
    from slewing_model.distribution import NoEquilibriumError
    from slewing_model.simulation.simulator import BearingSimulator

    case, sims = simulators_per_kernel(name, 20, "contact_kernel")
    looped = sims["compiled"]
    one_by_one = BearingSimulator(looped.bearing, looped.superelement, looped.settings)
    run_kept = BimeSolver._kept_iterations

    def switch(solver, *args):
        return run_kept(solver, *args) if solver is looped.solver else (0, args[0], args[4])

    monkeypatch.setattr(BimeSolver, "_kept_iterations", switch)
    for k in range(case.steps):
        a = looped.step(Loads(*case.loads[k]), case.psi[k], case.omega[k]).distribution
        b = one_by_one.step(Loads(*case.loads[k]), case.psi[k], case.omega[k]).distribution
        assert a.iterations == b.iterations, k
        assert np.abs(a.state - b.state).max() <= 1e-12 * np.abs(b.state).max(), k
    k = case.steps - 1
    for sim in (looped, one_by_one):
        sim.solver.max_iterations = 2
    messages = []
    for sim in (looped, one_by_one):
        with pytest.raises(NoEquilibriumError, match="no convergence after 2 Newton iterations") as refused:
            sim.step(Loads(*(1.5 * case.loads[k])), case.psi[k] + 0.01, case.omega[k])
        messages.append(str(refused.value).split(" (relative residual")[0])
    assert messages[0] == messages[1]


@pytest.mark.parametrize("name", ["pitch", "table3_heavy"])
def test_steps_with_compiled_contacts_equal_the_numpy_steps(name, monkeypatch, double_operator):
    """Whole steps with the compiled loops (most iterations in one loop with the kept operator,
    ``contact_kernel._kept_iterations``, most of those in the usual step's one call, ``_warm_solve``)
    against the numpy path: the same iterations, loads and
    torques to round-off. New operators in double precision: in single precision the round-off
    between the paths' iterates rounds ``W`` differently, and the answers differ by what the stop
    rule leaves (1.6e-8 of the largest ball load on the pitch case), which would hide a difference
    of the loops' formulas that size."""
    from slewing_model.distribution.bime import BimeSolver

    kept = []
    run_kept = BimeSolver._kept_iterations

    def counted(self, *args):
        done, point, last = run_kept(self, *args)
        kept.append(done)
        return done, point, last

    run_warm = BimeSolver._warm_solve

    def counted_warm(self, *args):
        found = run_warm(self, *args)
        kept.append(found[1])
        return found

    monkeypatch.setattr(BimeSolver, "_kept_iterations", counted)
    monkeypatch.setattr(BimeSolver, "_warm_solve", counted_warm)
    case, sims = simulators_per_kernel(name, 25, "contact_kernel")
    worst, total = 0.0, 0
    for k in range(case.steps):
        out = {kernel: sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k]) for kernel, sim in sims.items()}
        ref, got = out["numpy"].distribution, out["compiled"].distribution
        assert got.iterations == ref.iterations
        total += ref.iterations
        worst = max(worst, np.abs(got.contact_load - ref.contact_load).max() / ref.max_ball_load,
                    abs(out["compiled"].friction_torque - out["numpy"].friction_torque) / abs(out["numpy"].friction_torque))
    assert worst <= 1e-9, worst
    assert sum(kept) >= total // 2, (sum(kept), total)     # most iterations ran in the compiled loop


def test_rigid_solves_in_one_loop_equal_the_numpy_ones(pitch, rigid_loop_calls):
    """The rigid model's iterations in one compiled loop (``kernel._rigid_solve``) against the solver's
    numpy loop: cold and warm solves of the pitch bearing under loads that load one diagonal, both,
    and reverse the moment take the same iterations to the same displacement and contact loads to
    round-off; where the loop would run out of iterations, the numpy loop runs and refuses with its
    message."""
    from slewing_model.distribution import NoEquilibriumError

    bearing = pitch[0]
    solvers = {kernel: BimeSolver(bearing, None, psi=0.3, kernel=kernel) for kernel in ("numpy", "compiled")}
    sequence = [Loads(Fz=3e5), Loads(Fx=2e5, Fz=-3e5, Mx=4e6, My=-1.5e6), Loads(Fx=2e5, Fz=-3e5, Mx=-4e6, My=1.5e6),
                Loads(Fx=2.2e5, Fz=-3.1e5, Mx=-4.1e6, My=1.4e6)]
    last = {kernel: None for kernel in solvers}
    for loads in sequence:
        out = {}
        for kernel, solver in solvers.items():
            out[kernel] = solver.solve(loads, initial=last[kernel])
            last[kernel] = out[kernel]
        ref, got = out["numpy"], out["compiled"]
        assert got.iterations == ref.iterations > 0
        assert np.abs(got.displacement - ref.displacement).max() <= 1e-9 * np.abs(ref.displacement).max()
        assert np.abs(got.contact_load - ref.contact_load).max() <= 1e-9 * ref.max_ball_load
        assert got.residual <= solvers["compiled"].rtol
    assert len(rigid_loop_calls) == len(sequence)
    messages = []
    for solver in solvers.values():
        solver.max_iterations = 2
        with pytest.raises(NoEquilibriumError, match="no convergence after 2 Newton iterations") as refused:
            solver.solve(Loads(Fx=-2e5, Fz=3e5, Mx=4e6, My=-1.5e6))
        messages.append(str(refused.value).split(" (relative residual")[0])
    assert messages[0] == messages[1]
