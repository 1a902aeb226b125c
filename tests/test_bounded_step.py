"""A bounded step (``step_work="bounded"``): a warm solve's work is capped, what it could
not do is flagged and carried over to the next solves, and where it arrives is the complete answer.

The case is the one that made the slowest steps: a tilting moment reversed in one step, which
flips the loaded diagonal of most balls (table1, 100 balls, rings of a known stiffness,
:mod:`synthetic_rings`; its reduced operator has about 240 rows, so its inverse is spread over
stages as on the pitch bearing)."""
import numpy as np
import pytest

from slewing_model import BimeSolver, Loads
from slewing_model.distribution import bime
from slewing_model.distribution.bime import BOUNDED_ITERATIONS, BOUNDED_WORK
from slewing_model.distribution.kernel import BORDER_BLAS_ROWS, bordered_inverse as compiled_bordered_inverse
from slewing_model.numerics.compiled import AVAILABLE
from slewing_model.rings.reduced_operator import (
    BORDER_BLOCK, LEAF, STAGES, bordered_inverse, bordering_work, stage_work,
)
from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings
from conftest import through_json
from statics import load_on_moving_ring
from synthetic_rings import synthetic_superelement

FORWARD = Loads(Fx=2e4, Fz=3e5, Mx=1e5, My=4e5)
REVERSED = Loads(Fx=2e4, Fz=3e5, Mx=-1e5, My=-4e5)
TOLERANCE = 1e-7


@pytest.fixture(scope="module")
def rings(table1):
    return synthetic_superelement(table1.ball_count)


class OperatorWork:
    """What each solve asked of the ring operator, counted at the calls the solver makes, as
    :data:`~slewing_model.distribution.bime.BOUNDED_WORK` counts work: forming ``W``
    (:func:`~slewing_model.rings.reduced_operator.forming_work`), the stages of its inverse each call ran
    (:func:`~slewing_model.rings.reduced_operator.stage_work`, from the stage before and after the
    call, of the pending operator's method), bordering (:func:`~slewing_model.rings.reduced_operator.bordering_work`). ``largest``: the
    largest stage run since the last :meth:`take`; ``pieces``: how many of these (forming, stages,
    borderings) were done since then (``taken_pieces``: up to the last :meth:`take`; ``pieces_taken``:
    at each :meth:`take`)."""

    def __init__(self, monkeypatch):
        self.work = self.largest = 0.0
        self.pieces = self.taken_pieces = 0
        self.pieces_taken = []

        def stages(n, first, last, method=0):
            for k in range(first, last):
                self.work += stage_work(n, k, method)
                self.largest = max(self.largest, stage_work(n, k, method))
                self.pieces += 1

        def done(result):
            return getattr(result, "stage", len(STAGES))         # an operator: all stages done

        def counted(name, cost):
            original = getattr(bime, name)

            def call(*args, **kwargs):
                result = original(*args, **kwargs)
                cost(result, *args)
                return result
            monkeypatch.setattr(bime, name, call)

        def started(result, point, compliance, stiffness, active, *rest):
            n = 2 * int(np.count_nonzero(active))
            self.work += bime.forming_work(n)
            self.pieces += 1
            stages(n, 0, done(result))

        def advanced(result, pending, *rest):
            # an inverse that missed the check comes back as a pending operator of the next method at stage 0
            again = getattr(result, "method", pending.method) != pending.method
            stages(pending.matrix.shape[0], pending.stage, len(STAGES) if again else done(result), pending.method)

        def bordered(result, op, point, compliance, stiffness, jacobian, active, *rest):
            new_rows = 2 * int(np.count_nonzero(active & ~op.active))
            if result is not None and new_rows:
                self.work += bordering_work(new_rows, op.rows.size)
                self.pieces += 1

        counted("start_operator", started)
        counted("advance_operator", advanced)
        counted("update_operator", bordered)

    def take(self) -> tuple[float, float]:
        work, largest = self.work, self.largest
        self.work = self.largest = 0.0
        self.taken_pieces, self.pieces = self.pieces, 0
        self.pieces_taken.append(self.taken_pieces)
        return work, largest


def reversal(table1, rings, step_work, work=None, steps=40):
    """Forward load solved (cold), then the moment reversed and held: the results and the ring
    operator's work of each warm solve."""
    sim = BearingSimulator(table1, rings, SimulatorSettings(tolerance=TOLERANCE, friction_coefficient=0.0,
                                                           step_work=step_work))
    sim.step(FORWARD, 0.0, 0.0)
    results, spent = [], []
    if work is not None:
        work.take()
    for _ in range(steps):
        results.append(sim.step(REVERSED, 0.0, 0.0).distribution)
        spent.append(None if work is None else work.take())
    return results, spent


def test_a_bounded_step_does_at_most_its_share_of_the_work(table1, rings, monkeypatch):
    work = OperatorWork(monkeypatch)
    held, held_work = reversal(table1, rings, "complete", work, steps=1)
    # started from the old equilibrium as it is (no held-rings start, bime.HELD_START), the
    # complete solve of the reversal does more than twice the bound: the case discriminates
    monkeypatch.setattr(bime, "HELD_START", np.inf)
    complete, complete_work = reversal(table1, rings, "complete", work, steps=2)
    assert complete_work[0][0] > 2 * BOUNDED_WORK and complete[0].iterations > BOUNDED_ITERATIONS
    # the held-rings start finds the new contact set with less of the operator's work
    assert held_work[0][0] < complete_work[0][0]
    results, spent = reversal(table1, rings, "bounded", work)
    # at most the bound, or one stage of an inverse on its way where the solve had done nothing else
    for work, largest in spent:
        assert work <= max(BOUNDED_WORK, largest) * (1 + 1e-12)
    assert max(r.iterations for r in results) <= BOUNDED_ITERATIONS
    assert not results[0].converged


def test_a_bounded_step_counts_the_held_rings_start_in_its_work(table1, rings, monkeypatch):
    # the reversal's first bounded step starts from the moving ring's equilibrium with the rings held
    # (BimeSolver._held_rings_start): its rigid solve takes HELD_WORK of the bound, the operator the rest
    work = OperatorWork(monkeypatch)
    held = []
    original = bime.BimeSolver._held_rings_start

    def spied(self, p, *rest):
        start = original(self, p, *rest)
        held.append(start is not p)
        return start

    monkeypatch.setattr(bime.BimeSolver, "_held_rings_start", spied)
    _, spent = reversal(table1, rings, "bounded", work, steps=1)
    assert held == [True]
    operator_work, largest = spent[0]
    # the rest of the bound, or the one piece a solve always does (that a run of bounded solves gets on)
    assert operator_work <= (BOUNDED_WORK - bime.HELD_WORK) * (1 + 1e-12) or work.taken_pieces == 1
    assert operator_work > 0


def test_a_bounded_step_flags_what_it_carries_over_and_arrives_at_the_complete_answer(table1, rings):
    results, _ = reversal(table1, rings, "bounded")
    for r in results:                       # the flag says what the residual says
        assert r.converged == (r.residual <= TOLERANCE)
        assert any("not in equilibrium" in w for w in r.warnings()) == (not r.converged)
    first = next(k for k, r in enumerate(results) if r.converged)
    assert 1 <= first < 20 and all(r.converged for r in results[first:])
    reference = BimeSolver(table1, rings, rtol=1e-11).solve(REVERSED)           # cold, to round-off
    arrived = results[-1]
    # both within 1e-7 of the load scale: the displacements agree to about 1e-6
    assert np.allclose(arrived.displacement, reference.displacement, rtol=2e-6, atol=1e-6 * np.abs(
        reference.displacement).max())
    assert arrived.max_ball_load == pytest.approx(reference.max_ball_load, rel=2e-6)
    # statics, independent of the solver: the contacts balance the applied load (ring deformation
    # moves the groove centres by micrometres: 1e-4 of the load)
    balance = load_on_moving_ring(table1, arrived)
    assert np.allclose(balance, REVERSED.as_array(), atol=1e-4 * 4e5)


def test_an_inverse_that_misses_the_check_is_made_again_over_the_next_steps(table1, rings, monkeypatch):
    """An inverse by halves that misses the check (``reduced_operator.checked_inverse``) is not made
    again at once in a bounded step (4-19 ms by LAPACK, the slowest steps of the bounded scenarios,
    before): it comes back as a pending operator through the Cholesky factor (method 1, single
    precision; where that misses too, method 2, double), whose stages the next steps run within
    their bound. Here every inverse in single precision misses: the check is made 1e-6, which only
    double precision meets. No inverse is made at once in a warm step, every step keeps to its
    bound, and the run arrives at the complete answer."""
    from slewing_model.rings import reduced_operator

    work = OperatorWork(monkeypatch)
    monkeypatch.setattr(reduced_operator, "INVERSE_CHECK", 1e-6)
    at_once, methods = [], set()
    cholesky, lapack, advance = (reduced_operator.cholesky_inverse, reduced_operator._lapack_inverse,
                                 reduced_operator.advance_operator)

    def by_factor(matrix, precision=np.float64):
        at_once.append("factor")
        return cholesky(matrix, precision)

    def by_lapack(matrix):
        if matrix.shape[0] > LEAF:
            at_once.append("lapack")
        return lapack(matrix)

    def advanced(pending, *args, **kwargs):
        methods.add(pending.method)
        return advance(pending, *args, **kwargs)

    monkeypatch.setattr(reduced_operator, "cholesky_inverse", by_factor)
    monkeypatch.setattr(reduced_operator, "_lapack_inverse", by_lapack)
    monkeypatch.setattr(bime, "advance_operator", advanced)
    sim = BearingSimulator(table1, rings, SimulatorSettings(tolerance=TOLERANCE, friction_coefficient=0.0,
                                                           step_work="bounded"))
    sim.step(FORWARD, 0.0, 0.0)                           # cold: complete, its inverses at once
    at_once.clear()
    work.take()
    results = []
    for _ in range(60):
        results.append(sim.step(REVERSED, 0.0, 0.0).distribution)
        spent, largest = work.take()
        assert spent <= max(BOUNDED_WORK, largest) * (1 + 1e-12)
    assert at_once == [] and methods == {0, 1, 2}
    assert results[-1].converged
    reference = BimeSolver(table1, rings, rtol=1e-11).solve(REVERSED)
    assert results[-1].max_ball_load == pytest.approx(reference.max_ball_load, rel=2e-6)


def test_the_step_after_a_bounded_solve_arrives_starts_at_its_equilibrium(table1, rings):
    """A flagged step's iterate is no point of the trajectory: the step after the first converged one,
    the loads held, starts at that equilibrium (0 iterations, the same state), not extrapolated along
    iterate -> equilibrium (which took it off again). Such a step is answered at once
    (BearingSimulator.step: the inputs of the last step, an equilibrium); its state through JSON leaves
    that answer out, so the same step from it is solved, and starts there too."""
    sim = BearingSimulator(table1, rings, SimulatorSettings(tolerance=TOLERANCE, friction_coefficient=0.0,
                                                           step_work="bounded"))
    sim.step(FORWARD, 0.0, 0.0)
    results = [sim.step(REVERSED, 0.0, 0.0).distribution]
    while not results[-1].converged and len(results) < 20:
        results.append(sim.step(REVERSED, 0.0, 0.0).distribution)
    assert len(results) >= 2 and results[-1].converged and not results[-2].converged
    arrived = results[-1]
    state = through_json(sim.get_state())
    repeated = sim.step(REVERSED, 0.0, 0.0).distribution
    assert repeated.iterations == 0 and np.array_equal(repeated.state, arrived.state)
    sim.set_state(state)
    solved = sim.step(REVERSED, 0.0, 0.0).distribution
    assert solved is not repeated and solved.iterations == 0 and np.array_equal(solved.state, arrived.state)


def test_an_iterate_on_its_way_is_not_refused_for_capacity(table1, rings):
    """Its contact angles are those of an iterate: the capacity check waits for the equilibrium."""
    results, _ = reversal(table1, rings, "bounded", steps=1)
    assert not results[0].converged and results[0].residual > 10 * TOLERANCE


def test_a_cold_solve_is_complete_whatever_the_step_work(table1, rings, monkeypatch):
    work = OperatorWork(monkeypatch)
    monkeypatch.setattr(bime, "BOUNDED_WORK", 0.2 * BOUNDED_WORK)   # below this cold solve's work
    bounded = BimeSolver(table1, rings, rtol=TOLERANCE, step_work="bounded").solve(REVERSED)
    assert bounded.converged and work.take()[0] > bime.BOUNDED_WORK
    complete = BimeSolver(table1, rings, rtol=TOLERANCE).solve(REVERSED)
    assert np.array_equal(bounded.state, complete.state)


def test_unknown_step_work_is_refused_with_its_name(table1):
    with pytest.raises(ValueError, match="step_work = 'fast': must be one of 'complete', 'bounded'"):
        SimulatorSettings(step_work="fast")
    with pytest.raises(ValueError, match="step_work = 'fast'"):
        BimeSolver(table1, step_work="fast")


@pytest.mark.skipif(not AVAILABLE, reason="numba is not installed")
@pytest.mark.parametrize("new_rows", [2, BORDER_BLAS_ROWS + 8])
def test_bordered_inverse_is_the_inverse_of_the_bordered_matrix(new_rows):
    """Compiled (few new rows) or by BLAS (many; ``W^-1`` read by blocks of BORDER_BLOCK rows, the last one
    short here): against LAPACK's inverse of the whole matrix."""
    rng = np.random.default_rng(new_rows)
    n = 3 * BORDER_BLOCK + 5
    a = rng.standard_normal((n + new_rows, n + new_rows))
    w = a @ a.T + (n + new_rows) * np.eye(n + new_rows)
    inverse = np.linalg.inv(w[:n, :n])
    jacobian, new_jacobian = rng.standard_normal((n, 5)), rng.standard_normal((new_rows, 5))
    args = (0.5 * (inverse + inverse.T), w[:n, n:], w[n:, n:], jacobian, inverse @ jacobian, new_jacobian, 1e-9)
    expected = np.linalg.inv(w)
    for bordering in (compiled_bordered_inverse, bordered_inverse):
        bordered, coupling, _ = bordering(*args)
        assert np.allclose(bordered, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
        assert np.allclose(coupling, expected @ np.vstack([jacobian, new_jacobian]), atol=1e-12)
    # an inverse kept in single precision (reduced_operator.kept_precision): bordered in double from its
    # entries, the same blocks as from the same entries in double, stored in single
    single = args[0].astype(np.float32)
    want = bordered_inverse(single.astype(np.float64), *args[1:])
    for bordering in (compiled_bordered_inverse, bordered_inverse):
        got = bordering(single, *args[1:])
        assert got[0].dtype == np.float32
        assert np.abs(got[0] - want[0].astype(np.float32)).max() <= 1e-6 * np.abs(want[0]).max()
        for a, b in zip(got[1:], want[1:]):
            assert np.allclose(a, b, rtol=0, atol=1e-11 * np.abs(b).max())


def test_a_flagged_step_caps_its_friction_and_the_steps_after_arrive_at_the_complete_torque(table1, rings,
                                                                                             monkeypatch):
    """The friction torque of an iterate on its way is an iterate too: at most
    BOUNDED_FRICTION_ITERATIONS of the ball equilibrium (a complete one after the reversal takes
    more), and once the distribution has arrived the torque is the complete solve's within the
    friction tolerance."""
    from slewing_model.simulation import simulator

    solved = []

    def recorded(original):                 # the step's one compiled call (warm_torque), or the general path
        def call(*args, **kwargs):
            found = original(*args, **kwargs)
            if found is not None:
                solved.append((kwargs.get("max_iterations"), found))
            return found
        return call
    monkeypatch.setattr(simulator, "friction_torque", recorded(simulator.friction_torque))
    monkeypatch.setattr(simulator, "warm_torque", recorded(simulator.warm_torque))
    steps = {}
    for work in ("complete", "bounded"):
        sim = BearingSimulator(table1, rings, SimulatorSettings(tolerance=TOLERANCE, step_work=work))
        sim.step(FORWARD, 0.0, 0.1)
        solved.clear()
        steps[work] = [(sim.step(REVERSED, 0.0, 0.1), solved[-1]) for _ in range(30)]
    complete_first = steps["complete"][0][1][1]
    assert complete_first.iterations > simulator.BOUNDED_FRICTION_ITERATIONS      # the case discriminates
    flagged = [(cap, torque) for result, (cap, torque) in steps["bounded"] if not result.distribution.converged]
    assert flagged and all(cap == simulator.BOUNDED_FRICTION_ITERATIONS for cap, _ in flagged)
    assert all(t.iterations <= simulator.BOUNDED_FRICTION_ITERATIONS for _, t in flagged)
    arrived, complete = steps["bounded"][-1][0], steps["complete"][-1][0]
    assert arrived.distribution.converged
    assert arrived.friction_torque_magnitude == pytest.approx(complete.friction_torque_magnitude, rel=1e-5)


def test_a_bounded_solve_of_small_operators_arrives_as_well(table1, rings, monkeypatch):
    """Operators of LEAF rows or fewer are inverted by LAPACK in their first stage (here every one:
    LEAF raised above the case's rows): a bounded run still arrives at the cold solution."""
    from slewing_model.rings import reduced_operator

    monkeypatch.setattr(reduced_operator, "LEAF", 10_000)
    results, _ = reversal(table1, rings, "bounded")
    assert results[-1].converged
    reference = BimeSolver(table1, rings, rtol=1e-11).solve(REVERSED)
    assert results[-1].max_ball_load == pytest.approx(reference.max_ball_load, rel=2e-6)


def test_a_bounded_run_gets_on_where_the_held_start_leaves_less_than_a_stage(table1, rings, monkeypatch):
    """Each bounded solve does at least one piece of the operator's work (forming ``W``, a stage of its
    inverse, a bordering), whatever the held-rings start took of its bound. Here the held start is
    tried in every solve and takes the whole bound. Before, such a run never formed or inverted an
    operator again: the yaw bearing (180 balls, the first stage of its 720-row operator 1.4e8)
    answered its start values in every step, all flagged. Now every solve does one such piece and
    no more, and the run arrives at the cold solution."""
    monkeypatch.setattr(bime, "HELD_START", 0.0)
    monkeypatch.setattr(bime, "HELD_WORK", BOUNDED_WORK)
    work = OperatorWork(monkeypatch)
    results, _ = reversal(table1, rings, "bounded", work, steps=60)
    pieces = work.pieces_taken[-60:]
    first = next(k for k, r in enumerate(results) if r.converged)
    assert first >= 2 and all(r.converged for r in results[first:])
    assert all(p == 1 for p in pieces[:first]) and sum(pieces[:first]) >= 2
    reference = BimeSolver(table1, rings, rtol=1e-11).solve(REVERSED)
    assert results[-1].max_ball_load == pytest.approx(reference.max_ball_load, rel=2e-6)


def test_a_bordering_larger_than_the_work_left_borders_the_most_stretched_contacts_first(table1, rings,
                                                                                        monkeypatch):
    """Contacts that closed are bordered in as the bounded solve's work allows (``_bordering_that_fits``):
    the most stretched first, the rest in the next solves. Before, a bordering was one piece whatever its
    size: on the pitch bearing 74 rows at once after its start values, the whole bound where the held-rings
    start had left half (NREL's slowest step). Here the bound and the first piece are made too small for
    the reversal's borderings: a solve borders only part of what closed, its work stays within the bound or
    the first piece (or one stage), and the run arrives at the cold solution."""
    piece = bordering_work(8, 3 * table1.ball_count)    # four diagonals onto more rows than the operator's
    monkeypatch.setattr(bime, "BOUNDED_WORK", piece)
    monkeypatch.setattr(bime, "BORDER_PIECE", piece)
    monkeypatch.setattr(bime, "HELD_START", np.inf)     # no held-rings start: the contacts close as they iterate
    borderings = []
    original = bime.update_operator

    def spied(op, point, compliance, stiffness, jacobian, active, *rest):
        entering, closed = active & ~op.active, point.loaded & ~op.active
        stretch = point.delta.ravel()
        if entering.any():
            borderings.append((int(np.count_nonzero(entering)), int(np.count_nonzero(closed)),
                               stretch[entering].min() >= stretch[closed & ~entering].max(initial=0.0),
                               bordering_work(2 * int(np.count_nonzero(entering)), op.rows.size)))
        return original(op, point, compliance, stiffness, jacobian, active, *rest)

    monkeypatch.setattr(bime, "update_operator", spied)
    work = OperatorWork(monkeypatch)
    results, spent = reversal(table1, rings, "bounded", work, steps=80)
    assert sum(entered < closed for entered, closed, _, _ in borderings) >= 2   # the case discriminates
    assert all(most_stretched for _, _, most_stretched, _ in borderings)
    # each bordering within the piece
    assert all(cost <= piece * (1 + 1e-12) for _, _, _, cost in borderings)
    for (operator_work, largest), pieces in zip(spent, work.pieces_taken[-len(spent):]):
        assert operator_work <= max(piece, largest) * (1 + 1e-12) or pieces == 1   # or its one piece
    first = next(k for k, r in enumerate(results) if r.converged)
    assert all(r.converged for r in results[first:])
    reference = BimeSolver(table1, rings, rtol=1e-11).solve(REVERSED)
    assert results[-1].max_ball_load == pytest.approx(reference.max_ball_load, rel=2e-6)


def test_the_yaw_bearing_bounded_from_zero_loads_arrives():
    """The 180-ball yaw bearing started at zero loads (an FMU's start values), then its tower-top loads
    held, bounded: the run arrives at the complete step's equilibrium and stays there. Its preload's
    operator has 720 rows, one stage of its inverse more than the bound leaves after the held-rings
    start: before, no operator was ever formed or inverted again, and every step answered the start
    values (residual 1), flagged."""
    from conftest import benchmark_case

    case, bearing, superelement = benchmark_case("yaw", 1)
    loads, psi, omega = Loads(*case.loads[0]), case.psi[0], case.omega[0]
    results = {}
    for step_work in ("bounded", "complete"):
        sim = BearingSimulator(bearing, superelement, SimulatorSettings(step_work=step_work))
        sim.step(Loads(), 0.0, 0.0)
        results[step_work] = [sim.step(loads, psi, omega).distribution for _ in range(30)]
    bounded, complete = results["bounded"], results["complete"][-1]
    assert not bounded[0].converged and complete.converged
    first = next(k for k, r in enumerate(bounded) if r.converged)
    assert all(r.converged for r in bounded[first:])
    assert bounded[-1].max_ball_load == pytest.approx(complete.max_ball_load, rel=1e-6)
    assert np.abs(bounded[-1].displacement - complete.displacement).max() <= 1e-6 * np.abs(complete.displacement).max()


def test_a_bounded_steps_newton_iterations_count_in_its_work(table1, rings, monkeypatch):
    """A bounded solve's Newton iterations take from its bound as its operator work does
    (``bime.ITERATION_WEIGHT``): once it has done its one piece of operator work, it starts an
    iteration only where the work left covers it. Here an iteration costs the whole bound: every step
    stops after the iteration that did its one piece, where with the iterations free some steps do
    several pieces; the run still arrives at the cold solution."""
    work = OperatorWork(monkeypatch)
    monkeypatch.setattr(bime, "ITERATION_WEIGHT", (0.0, 0.0))
    reversal(table1, rings, "bounded", work, steps=60)
    assert max(work.pieces_taken[-60:]) > 1                  # the case discriminates
    monkeypatch.setattr(bime, "ITERATION_WEIGHT", (0.0, BOUNDED_WORK / table1.ball_count))
    results, _ = reversal(table1, rings, "bounded", work, steps=60)
    assert max(work.pieces_taken[-60:]) == 1
    first = next(k for k, r in enumerate(results) if r.converged)
    assert all(r.converged for r in results[first:])
    reference = BimeSolver(table1, rings, rtol=1e-11).solve(REVERSED)
    assert results[-1].max_ball_load == pytest.approx(reference.max_ball_load, rel=2e-6)


@pytest.mark.skipif(not AVAILABLE, reason="numba is not installed")
def test_a_bounded_run_takes_the_same_steps_with_numpy_and_compiled_loops(table1, rings, monkeypatch):
    """The work a bounded solve counts, its iterations' and its operator's, is the same whichever runs
    left allows): the moment reversed and back twice, every step the same iterations, the same flag and
    the same state to 1e-7 of its largest entry. An iteration here costs a fifth of the bound, that the
    limit binds.

    Not to round-off: the Newton step rounds its right side to single precision for the kept inverse's
    product (``reduced_operator.single_product``, the same operations in both paths), so where the paths'
    right sides differ by double round-off, a rounding to single can differ by one unit (6e-8 relative);
    a flagged step's iterate, 1e-2 off its equilibrium here, carries that on. Measured: 1.5e-8."""
    monkeypatch.setattr(bime, "ITERATION_WEIGHT", (0.0, BOUNDED_WORK / 5 / table1.ball_count))
    runs = []
    for kernel in ("numpy", "auto"):
        sim = BearingSimulator(table1, rings, SimulatorSettings(tolerance=TOLERANCE, friction_coefficient=0.0,
                                                               step_work="bounded", contact_kernel=kernel))
        sim.step(FORWARD, 0.0, 0.0)
        runs.append([sim.step(REVERSED if (k // 10) % 2 == 0 else FORWARD, 0.0, 0.0).distribution
                     for k in range(40)])
    with_numpy, compiled = runs
    assert any(not r.converged for r in compiled)             # the bound was met
    assert [r.iterations for r in with_numpy] == [r.iterations for r in compiled]
    assert [r.converged for r in with_numpy] == [r.converged for r in compiled]
    for a, b in zip(with_numpy, compiled):
        assert np.allclose(a.state, b.state, rtol=0, atol=1e-7 * np.abs(b.state).max())


@pytest.mark.skipif(not AVAILABLE, reason="numba is not installed")
@pytest.mark.parametrize("step_work", ["complete", "bounded"])
def test_the_usual_step_in_one_compiled_call_takes_the_same_steps(table1, rings, step_work, monkeypatch):
    """A warm solve with a kept operator runs its loops in one compiled call (``bime.WARM_CALL``,
    ``kernel._warm_solve``): the same loops in the same order as one by one from Python, so the same
    numbers bit for bit, step after step. The steps go through every way the call ends: at an
    equilibrium, its kept iterations stopped short (a new operator due, contacts closing, the bound),
    a start far off (a reversal: the held-rings start), and a turn of the ring that the kept operator
    cannot follow by a column turn (grooves with errors turning with the ring)."""
    from slewing_model.bearing.manufacturing import synthetic_errors
    from slewing_model.distribution import kernel

    if step_work == "bounded":                 # an iteration costs a fifth of the bound: the limit binds
        monkeypatch.setattr(bime, "ITERATION_WEIGHT", (0.0, BOUNDED_WORK / 5 / table1.ball_count))
    # the errors move with the ring: a column turn fits them to about 4e-8 a step, above this tolerance
    monkeypatch.setattr(bime, "APPROXIMATE_TURN", 1e-9)
    bearing = table1.with_errors(synthetic_errors(table1.ball_count, seed=2))
    ended = []
    original = bime.compiled_warm_solve

    def recorded():
        call = original()

        def run(*args):
            out = call(*args)
            ended.append(out[0])
            return out
        return run
    monkeypatch.setattr(bime, "compiled_warm_solve", recorded)
    steps = np.arange(40)                      # the ring turns, holds (the moment reversed and back), turns
    angles = 0.005 * np.minimum(steps, 10) + 0.005 * np.maximum(steps - 30, 0)
    scale = 1.0 + 0.15 * np.sin(steps)
    loads = [Loads(**{k: v * s * (-1.0 if k[0] == "M" and 15 <= i < 25 else 1.0)
                      for k, v in vars(FORWARD).items()}) for i, s in zip(steps, scale)]
    runs = []
    for one_call in (False, True):
        sim = BearingSimulator(bearing, rings, SimulatorSettings(tolerance=TOLERANCE, friction_coefficient=0.0,
                                                                 step_work=step_work))
        sim.step(FORWARD, 0.0, 0.0)
        monkeypatch.setattr(bime, "WARM_CALL", one_call)
        # each step's result, and the work its solve had left (the iterations' and the operator's counted)
        runs.append([(sim.step(f, psi, 0.0).distribution, sim.solver._work_left) for f, psi in zip(loads, angles)])
    (one_by_one, left), (in_one_call, left_one_call) = (zip(*run) for run in runs)
    assert left == left_one_call
    assert set(ended) == {kernel.WARM_CONVERGED, kernel.WARM_STOPPED, kernel.WARM_FAR, kernel.WARM_NOT_TURNED}
    if step_work == "bounded":
        assert any(not r.converged for r in in_one_call)
    for a, b in zip(one_by_one, in_one_call):
        assert (a.iterations, a.converged) == (b.iterations, b.converged)
        assert np.array_equal(a.state, b.state) and np.array_equal(a.contact_pressure, b.contact_pressure)


# ---- life: a flagged step's iterate adds no damage ------------------------------------------------
#: the pitch bearing's blade-root loads (NREL 5MW, about the FAST v8 series' mean) with the tilting
#: moment My of 10 MN m reversed in one step (Mx with it) at :data:`LIFE_REVERSALS`; the blade swings
#: 0.02 rad at 0.5 Hz so that the balls roll (a bearing that stands takes no rolling damage)
LIFE_LOADS = Loads(Fx=2.36e5, Fy=-2.85e4, Fz=6.0e5, Mx=8.5e5, My=1.0e7)
LIFE_STEPS, LIFE_REVERSALS, LIFE_DT = 60, (20, 40), 0.01


@pytest.fixture(scope="module")
def life_runs():
    """The reversal case run complete and bounded side by side (flexible rings, coarse superelement of
    free rings, as ``conftest.benchmark_case``), life on: each run's distributions, worst-track damage
    after each step and simulator."""
    from slewing_model import load_bearing
    from slewing_model.rings.superelement import build_superelement

    bearing = load_bearing("examples/bearings/pitch_bearing.toml")
    superelement = build_superelement(bearing, mesh="coarse", bc="free", progress=False)
    t = np.arange(LIFE_STEPS) * LIFE_DT
    psi, omega = 0.02 * np.sin(np.pi * t), 0.02 * np.pi * np.cos(np.pi * t)
    sign = np.where(np.searchsorted(LIFE_REVERSALS, np.arange(LIFE_STEPS), side="right") % 2 == 1, -1.0, 1.0)
    runs = {}
    for work in ("complete", "bounded"):
        sim = BearingSimulator(bearing, superelement, SimulatorSettings(load_frame="rotating", life=True,
                                                                       step_work=work))
        distributions, damage = [], []
        for k in range(LIFE_STEPS):
            f = Loads(**{**vars(LIFE_LOADS), "Mx": sign[k] * LIFE_LOADS.Mx, "My": sign[k] * LIFE_LOADS.My})
            distributions.append(sim.step(f, float(psi[k]), float(omega[k])).distribution)
            damage.append(sim.life.worst_damage)
        runs[work] = (distributions, np.array(damage), sim)
    return psi, runs


def fed(sim, distributions, psi, as_converged=False, contact_load=None):
    """A fresh accumulator of ``sim``'s model fed ``distributions`` at ``psi``: every one counted as it is
    given where ``as_converged`` (``converged`` set True: an accumulator that counts every step's loads,
    iterates too), with ``contact_load(k, d)`` as step ``k``'s contact loads where given."""
    from dataclasses import replace

    from slewing_model.life import LifeAccumulator

    acc = LifeAccumulator(sim.life.model, kernel=sim.settings.contact_kernel)     # as the simulator adds
    for k, (d, angle) in enumerate(zip(distributions, psi)):
        loads = d.contact_load if contact_load is None else contact_load(k, d)
        acc.step(None, float(angle), replace(d, converged=as_converged or d.converged, contact_load=loads))
    return acc


def test_a_bounded_run_accumulates_the_complete_run_s_damage(life_runs):
    """After a moment reversed in one step the bounded steps answer with iterates whose largest ball load
    is several times the equilibrium's; the life accumulator counts none of them. The bounded run's
    damage equals the complete run's within 1e-4, track by track (measured: 5e-6): the equilibria both
    runs count agree to the solver's tolerance (ball loads to about 2e-5 at ``tolerance`` 1e-7, damage
    with Q^3: 6e-5), and the rolling of the flagged steps is counted with the next equilibrium's ball
    loads, which moved with their balls over those steps (at most 5 steps here). Slice by slice that
    shift shows: within 1e-3 of the largest slice's damage (measured: 5e-4). Counted as given, the
    iterates would put the bounded run's damage far off."""
    psi, runs = life_runs
    (complete, complete_damage, complete_sim), (bounded, bounded_damage, bounded_sim) = runs.values()
    flagged = [k for k, d in enumerate(bounded) if not d.converged]
    assert len(flagged) >= 3 and {LIFE_REVERSALS[0], LIFE_REVERSALS[1]} <= set(flagged)
    assert all(d.converged for d in complete)
    peak = max(bounded[k].contact_load.max() / complete[k].contact_load.max() for k in flagged)
    assert peak > 2.0                                   # the iterates are far off: the case discriminates
    assert bounded_damage[-1] == pytest.approx(complete_damage[-1], rel=1e-4)
    np.testing.assert_allclose(bounded_sim.life.track_damage, complete_sim.life.track_damage, rtol=1e-4)
    np.testing.assert_allclose(bounded_sim.life.map.damage_map, complete_sim.life.map.damage_map, rtol=0.0,
                               atol=1e-3 * complete_sim.life.map.damage_map.max())
    as_given = fed(bounded_sim, bounded, psi, as_converged=True).worst_damage
    assert as_given > 1.5 * complete_damage[-1]


def test_a_flagged_step_adds_no_damage_from_its_iterate(life_runs):
    """Independent of the accumulator's bookkeeping: the damage does not move over a flagged step; a
    plain raceway map fed each step's ball places with the loads of the bounded run's next converged step
    (its own where it converged) gives the bounded run's map; and the iterates' loads replaced by NaN
    give the same map bit for bit (they never enter it)."""
    from slewing_model.life import RacewayMap

    psi, runs = life_runs
    bounded, damage, sim = runs["bounded"]
    flagged = [k for k, d in enumerate(bounded) if not d.converged]
    for k in flagged:
        assert damage[k] == damage[k - 1]
    assert sim.life.pending_steps == 0 and bounded[-1].converged
    following = [next(j for j in range(k, LIFE_STEPS) if bounded[j].converged) for k in range(LIFE_STEPS)]
    model = sim.life.model
    plain = RacewayMap(model.capacity, model.passes, model.moving_ring, model.slices)
    for k, d in enumerate(bounded):
        plain.update(d.ball_angle, float(psi[k]), bounded[following[k]].contact_load)
    np.testing.assert_allclose(sim.life.map.damage_map, plain.damage_map, rtol=1e-12, atol=0.0)
    nan = fed(sim, bounded, psi, contact_load=lambda k, d: d.contact_load if d.converged
              else np.full_like(d.contact_load, np.nan))
    np.testing.assert_array_equal(nan.map.damage_map, sim.life.map.damage_map)
    assert np.isfinite(nan.worst_damage) and nan.worst_damage == sim.life.worst_damage


def test_the_rolled_angle_is_counted_in_both_modes(life_runs):
    """The balls roll over the raceway in the flagged steps too: both runs' maps count the whole rotation
    of the rings against each other, Σ|Δψ| of the inputs."""
    psi, runs = life_runs
    rolled = float(np.sum(np.abs(np.diff(psi))))
    for _, _, sim in runs.values():
        assert sim.life.map.rolled == pytest.approx(rolled, rel=1e-12)
