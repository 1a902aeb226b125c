"""The compiled friction loop (numba) and its numpy fallback give the same results.

The compiled loop (:mod:`slewing_model.friction.kernel`) is optional: the FMU runs where
numba is not installed, with the numpy code. These tests compare both paths term by term
(the points' coefficients; power, gradient, Hessian, Weiszfeld majorant; each contact's power
and torque), on whole friction torques, cold and warm-started, and over co-simulation steps
(the compiled minimisation goes ball by ball, the numpy one batched: the same steps); they
run the library and the FMU in a Python where numba cannot be imported, and check that the
FMU loads its compiled loops from the cache it carries instead of compiling them.
"""
import json
import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from slewing_model import Loads, friction_torque, load_bearing, solve
from slewing_model.friction.ball_kinematics import ContactPoints, ContactSet
from slewing_model.friction.ellipse_quadrature import ellipse_quadrature
from slewing_model.friction.kernel import AVAILABLE, SINE_SERIES_LIMIT, _sine_series

from conftest import BEARINGS, ROOT, simulators_per_kernel

needs_numba = pytest.mark.skipif(not AVAILABLE, reason="numba is not installed: only the numpy path exists here")

#: a Python prelude that makes numba impossible to import, as on a host without it
NO_NUMBA = """
import sys
class _NoNumba:
    def find_spec(self, name, path=None, target=None):
        if name == "numba" or name.startswith("numba."):
            raise ImportError("numba is not installed (blocked by the test)")
sys.meta_path.insert(0, _NoNumba())
"""


def _distributions():
    """Load distributions of every kind: two-contact (axial), four-contact (idling with
    preload), mixed (combined load with errors)."""
    table3 = load_bearing(BEARINGS / "table3.toml")
    errors = load_bearing(BEARINGS / "table3_errors.toml").with_preload(10e-6)
    return [(table3, solve(table3, Loads(Fz=3e5))),
            (table3.with_preload(20e-6), solve(table3.with_preload(20e-6))),
            (errors, solve(errors, Loads(Fx=2e4, Fz=5e4, Mx=4e3), psi=0.3))]


def test_the_sine_series_is_the_sine_to_round_off():
    """The points' sines where a contact's angles are small (both paths take it): its Taylor series within
    two units of round-off of numpy's sin over its whole range, and odd."""
    sine_series = getattr(_sine_series, "py_func", _sine_series)   # the Python function, on arrays
    x = np.linspace(-SINE_SERIES_LIMIT, SINE_SERIES_LIMIT, 20001)
    series = sine_series(x)
    assert np.all(np.abs(series - np.sin(x)) <= 2.0 * np.spacing(np.abs(np.sin(x))))
    assert np.array_equal(series, -sine_series(-x))


@needs_numba
@pytest.mark.parametrize("quadrature", [(12, 2), (20, 4), (7, 3)])
def test_wide_and_narrow_contacts_take_the_same_sines_in_both_paths(quadrature):
    """Contacts whose angles ``a u / Rd`` reach past the series' limit take the C library's sine, the others the
    series, in the compiled loop and in numpy alike: the coefficients equal to round-off either side of it."""
    from types import SimpleNamespace

    from slewing_model.friction.kernel import compiled_point_coefficients

    ratio = np.linspace(0.05, 1.2, 24)                        # a / Rd, across SINE_SERIES_LIMIT
    rd = np.full(ratio.size, 0.02)
    angle = np.linspace(0.3, 1.2, ratio.size)
    geo = SimpleNamespace(a=(ratio * rd)[:, None], b=(0.2 * ratio * rd)[:, None], rb=np.full((ratio.size, 1), 0.019),
                          rd=rd[:, None], n_r=np.cos(angle)[:, None], n_z=np.sin(angle)[:, None],
                          ring_speed=np.where(np.arange(ratio.size) % 2, 0.3, 0.0)[:, None],
                          moving=(np.arange(ratio.size) % 2 == 1)[:, None], length_scale=0.019, pitch_radius=1.2)
    u_nodes = ellipse_quadrature(*quadrature).writable_arrays[0]
    assert np.any(ratio * np.abs(u_nodes).max() > SINE_SERIES_LIMIT)
    assert np.any(ratio * np.abs(u_nodes).max() <= SINE_SERIES_LIMIT)
    numpy_path = object.__new__(ContactPoints)
    numpy_path._coefficients(geo, u_nodes)
    columns = [np.ascontiguousarray(np.ravel(getattr(geo, name))) for name in ("a", "b", "rb", "rd", "n_r", "n_z",
                                                                              "ring_speed", "moving")]
    got = compiled_point_coefficients()(*columns, u_nodes, geo.length_scale, geo.pitch_radius)
    for name, a in zip(("g10", "g12", "h1", "s0", "s1", "hs", "arm1", "arm2"), got):
        b = getattr(numpy_path, name)
        assert np.allclose(a, b, rtol=1e-14, atol=1e-14 * np.abs(b).max()), name


@needs_numba
@pytest.mark.parametrize("case", range(3))
@pytest.mark.parametrize("quadrature", [(12, 2), (20, 4), (7, 3)])
def test_compiled_sums_equal_the_numpy_sums(case, quadrature):
    bearing, distribution = _distributions()[case]
    geometry = ContactSet(bearing, distribution, 0.1, 1.0, 1e-3)
    quad = ellipse_quadrature(*quadrature)
    numpy_path = ContactPoints(geometry, quad, workspace="kernel-test")
    compiled = ContactPoints(geometry, quad, workspace="kernel-test-compiled", compiled=True)
    # the points' velocity coefficients and lever arms, set up by the compiled loop too
    # (an odd rule has a middle node, u = 0, which the loop does not mirror)
    for name in ("g10", "g12", "h1", "s0", "s1", "hs", "arm1", "arm2"):
        a, b = getattr(compiled, name), getattr(numpy_path, name)
        assert a.shape == b.shape and np.allclose(a, b, rtol=1e-14, atol=1e-14 * np.abs(b).max()), name
    rng = np.random.default_rng(case)
    start = geometry.initial_guesses()[0]
    for u in (start, start * (1.0 + 0.3 * rng.standard_normal(start.shape))):
        want = numpy_path.evaluate(u, geometry.eps2, majorant=True)
        got = compiled.evaluate(u, geometry.eps2, majorant=True)
        nudged = numpy_path.evaluate(u * (1.0 + np.finfo(float).eps), geometry.eps2, majorant=True)
        for name, a, b, c in zip(("power", "gradient", "hessian", "majorant"), got, want, nudged):
            assert _within_round_off(a, b, c), name
        power_only = compiled.evaluate(u, geometry.eps2, derivatives=False)
        assert power_only[1] is None and np.allclose(power_only[0], want[0], rtol=1e-12)
        # each contact's power and torque on the moving ring (the torque's sign changes across the contacts)
        for name, a, b, c in zip(("power", "torque"), compiled.tractions(u), numpy_path.tractions(u),
                                 numpy_path.tractions(u * (1.0 + np.finfo(float).eps))):
            assert _within_round_off(a, b, c), name
    # a subset of the balls (the stragglers' path) keeps the compiled loop
    balls = np.arange(0, geometry.active.size, 3)
    sub_np, sub_c = numpy_path.subset(balls), compiled.subset(balls)
    eps2 = geometry.eps2[np.isin(geometry.owner, balls)]
    assert _within_round_off(sub_c.evaluate(start[balls], eps2)[2], sub_np.evaluate(start[balls], eps2)[2],
                             sub_np.evaluate(start[balls] * (1.0 + np.finfo(float).eps), eps2)[2])


def _within_round_off(got, want, nudged) -> bool:
    """``got`` equals ``want`` as far as the sums are defined: within 1e-12 of ``want`` (relative, and of its
    largest entry) and eight times what moves numpy's own sums (``nudged``: at motions one unit of round-off
    away). The Hessian's and the torques' terms cancel: on the distribution with errors a rounding of the
    motions moves the Hessian by 2e-12 of its largest entry, and the compiled loop rounds otherwise (fused
    multiply-adds, ``friction.kernel.FASTMATH``)."""
    bound = 1e-12 * np.abs(want).max() + 8.0 * np.abs(nudged - want).max()
    return want.shape == got.shape and bool(np.all(np.abs(got - want) <= bound + 1e-12 * np.abs(want)))


@needs_numba
@pytest.mark.parametrize("case", range(3))
def test_compiled_contact_set_equals_the_numpy_one(case):
    """The loaded contacts of a distribution (ContactSet) gathered by the compiled loop: the same
    contacts in the same order, the same geometry; and the same refusals of a distribution
    that cannot be (a value not finite, a negative load, a loaded contact without an ellipse)."""
    import dataclasses

    bearing, distribution = _distributions()[case]
    unloaded = np.arange(bearing.ball_count) % 7 == 0                 # and some balls without load
    distribution = dataclasses.replace(distribution, contact_load=np.where(unloaded[:, None], 0.0,
                                                                           distribution.contact_load))
    sets = {k: ContactSet(bearing, distribution, 0.1, 0.7, 1e-3, compiled=k) for k in (False, True)}
    names = ("ball_index", "contact_index", "owner", "active", "inactive", "loaded", "rb", "rd", "n_r", "n_z", "normal",
             "a", "b", "moving", "ring_speed", "mu_load", "eps2", "force_scale")
    for name in names:
        want, got = getattr(sets[False], name), getattr(sets[True], name)
        assert want.shape == got.shape and np.allclose(got, want, rtol=1e-15, atol=0.0), name
    assert np.array_equal(sets[True].inactive, np.flatnonzero(unloaded))
    # what the torque reports of the balls' motions, from the same motions and contact powers
    from slewing_model.friction.ball_kinematics import ball_results

    rng = np.random.default_rng(case)
    u = rng.standard_normal((sets[False].active.size, 3))
    power = rng.uniform(0.0, 1.0, sets[False].ball_index.size)
    results = [ball_results(sets[k], u, power, bearing.ball_count, 0.31, compiled=k) for k in (False, True)]
    names = ("contact_power", "power per ball", "omega_ball", "orbital", "state", "spin_roll", "count")
    for name, want, got in zip(names, *results):
        if name == "spin_roll":     # spin / roll: the compiled loop fuses multiply-adds (friction.kernel.FASTMATH)
            assert want.shape == got.shape and np.allclose(got, want, rtol=0.0, atol=1e-13 * np.abs(want).max())
        else:
            assert want.shape == got.shape and np.array_equal(want, got), name
    assert results[0][3][sets[False].inactive].tolist() == [0.31] * sets[False].inactive.size
    load = distribution.contact_load
    ball, contact = np.argwhere(load > 0)[1]                   # the second loaded contact
    first = np.arange(load.size).reshape(load.shape) == 4 * ball + contact
    for change, message in (
            ({"contact_angle": np.where(first, np.nan, distribution.contact_angle)},
             f"distribution.contact_angle of ball {ball + 1}, contact {contact + 1} = nan: must be finite"),
            ({"contact_load": np.where(first, -2.0, load)},
             f"distribution.contact_load of ball {ball + 1}, contact {contact + 1} = -2.0 N: must be >= 0"),
            ({"semi_axis_b": np.where(first, 0.0, distribution.semi_axis_b)},
             f"distribution.semi_axis_a/b of ball {ball + 1}, contact {contact + 1} = ")):
        bad = dataclasses.replace(distribution, **change)
        messages = []
        for compiled in (False, True):
            with pytest.raises(ValueError) as refused:
                ContactSet(bearing, bad, 0.1, 0.7, 1e-3, compiled=compiled)
            messages.append(str(refused.value))
        assert messages[0] == messages[1] and messages[0].startswith(message), messages
    # read-only arrays (a memory map, a view) are taken too, and a distribution without load
    frozen = dataclasses.replace(distribution, **{k: np.broadcast_to(getattr(distribution, k), load.shape)
                                                  for k in ("contact_load", "contact_angle")})
    assert np.array_equal(ContactSet(bearing, frozen, 0.1, 0.7, 1e-3, compiled=True).owner, sets[True].owner)
    idle = dataclasses.replace(distribution, contact_load=np.zeros_like(load))
    for compiled in (False, True):
        empty = ContactSet(bearing, idle, 0.1, 0.7, 1e-3, compiled=compiled)
        assert empty.ball_index.size == empty.active.size == empty.force_scale.size == 0
        assert empty.inactive.size == bearing.ball_count


@needs_numba
@pytest.mark.parametrize("case", range(3))
def test_compiled_torque_equals_the_numpy_torque(case):
    bearing, distribution = _distributions()[case]
    cold = {k: friction_torque(bearing, distribution, kernel=k) for k in ("numpy", "compiled")}
    assert cold["compiled"].magnitude == pytest.approx(cold["numpy"].magnitude, rel=1e-12)
    assert cold["compiled"].iterations == cold["numpy"].iterations
    assert np.allclose(cold["compiled"].state, cold["numpy"].state, rtol=1e-9, atol=1e-12)
    # warm-started from a slightly different state, as every co-simulation step is
    warm = {k: friction_torque(bearing, distribution, kernel=k, initial=cold["numpy"].state * 1.01)
            for k in ("numpy", "compiled")}
    assert warm["compiled"].magnitude == pytest.approx(warm["numpy"].magnitude, rel=1e-12)


@needs_numba
@pytest.mark.parametrize("name", ["pitch", "table3_heavy"])
def test_compiled_steps_equal_the_numpy_steps(name):
    # the co-simulation's steps, warm-started from each other: the compiled minimisation (ball by
    # ball) takes the steps the numpy loop (batched) takes, so the torques agree to round-off
    case, sims = simulators_per_kernel(name, 25, "friction_kernel")
    for k in range(case.steps):
        out = {kernel: sim.step(Loads(*case.loads[k]), case.psi[k], case.omega[k]) for kernel, sim in sims.items()}
        assert out["compiled"].friction_torque == pytest.approx(out["numpy"].friction_torque, rel=1e-10), k
        assert np.allclose(sims["compiled"]._friction_warm, sims["numpy"]._friction_warm, rtol=1e-8, atol=1e-12), k


@needs_numba
@pytest.mark.parametrize("case", range(4))
@pytest.mark.parametrize("solve_quadrature", [(12, 2), None])
def test_warm_torque_in_one_call_equals_the_loops_one_by_one(case, solve_quadrature, monkeypatch):
    """A warm-started torque (each co-simulation step's) runs its compiled loops in one call
    (``friction_kernel._friction_step``): bit for bit what the loops give called one by one from
    Python, also with unloaded balls (a bearing with clearance under a tilting moment); balls
    without a warm start (cold) are started in the call as the general path starts them (the same
    to round-off); no loaded contact takes the general path."""
    import slewing_model.friction.torque as friction

    if case < 3:
        bearing, distribution = _distributions()[case]
    else:
        bearing = load_bearing(BEARINGS / "table3.toml").with_preload(-50e-6)
        distribution = solve(bearing, Loads(Fz=2e4, Mx=2e4))
        assert np.any(distribution.contact_load.max(axis=1) == 0.0)          # unloaded balls
    start = friction_torque(bearing, distribution).state * 1.01
    calls = []
    one_call = friction.warm_friction_step

    def counted(*args):
        calls.append(one_call(*args))
        return calls[-1]

    def one_by_one(*args):
        return None

    monkeypatch.setattr(friction, "warm_friction_step", counted)
    fused = friction_torque(bearing, distribution, initial=start, solve_quadrature=solve_quadrature)
    assert calls[-1] is not None
    monkeypatch.setattr(friction, "warm_friction_step", one_by_one)
    loops = friction_torque(bearing, distribution, initial=start, solve_quadrature=solve_quadrature)
    for name in ("torque", "magnitude", "contact_part_moments", "power", "iterations", "residual", "converged"):
        assert getattr(fused, name) == getattr(loops, name), name
    for name in ("per_ball", "contact_power", "state", "ball_angular_velocity", "orbital_speed",
                 "spin_roll_ratio", "contact_count"):
        assert np.array_equal(getattr(fused, name), getattr(loops, name)), name
    # loaded balls without a warm start (contacts that changed): started in the one call as the
    # general path starts them, the same to round-off
    cold = start.copy()
    cold[np.flatnonzero(distribution.contact_load.max(axis=1) > 0)[::3]] = 0.0
    monkeypatch.setattr(friction, "warm_friction_step", counted)
    fused = friction_torque(bearing, distribution, initial=cold, solve_quadrature=solve_quadrature)
    assert calls[-1] is not None
    monkeypatch.setattr(friction, "warm_friction_step", one_by_one)
    loops = friction_torque(bearing, distribution, initial=cold, solve_quadrature=solve_quadrature)
    assert fused.iterations == loops.iterations and fused.converged == loops.converged
    for name in ("torque", "magnitude", "power"):
        assert getattr(fused, name) == pytest.approx(getattr(loops, name), rel=1e-12), name
    assert np.allclose(fused.state, loops.state, rtol=1e-9, atol=1e-12 * np.abs(loops.state).max())
    idle = replace(distribution, contact_load=np.zeros_like(distribution.contact_load))
    assert one_call(bearing, idle, 0.1, 1.0, 1e-3, ellipse_quadrature(20, 4), ellipse_quadrature(12, 2), start,
                    1e-5, 60, 0.5) is None


@needs_numba
@pytest.mark.parametrize("case", range(3))
def test_a_prepared_warm_torque_is_friction_torques_bit_for_bit(case):
    """What a co-simulation step takes of the friction torque (its magnitude with the seal torque,
    convergence, state and iterations), by the one compiled call with its operands prepared once
    (``warm_torque``), is ``friction_torque``'s bit for bit, also with another coefficient, a seal torque
    and the iterations capped; where ``friction_torque`` would take its general path (no warm start of
    the bearing's shape, no loaded contact) there is no answer."""
    from slewing_model.friction.torque import prepare_warm_torque, seal_torque_of, warm_torque

    bearing, distribution = _distributions()[case]
    start = friction_torque(bearing, distribution).state * 1.01
    for mu, seal, cap in ((0.1, 0.0, 60), (0.15, 12.5, 2)):
        step = prepare_warm_torque(bearing, mu=mu, omega=1.0, tol=1e-5)
        found = warm_torque(step, distribution, start, seal_torque_of(bearing, seal), max_iterations=cap)
        full = friction_torque(bearing, distribution, mu=mu, omega=1.0, seal_torque=seal, initial=start, tol=1e-5,
                               max_iterations=cap)
        assert found.magnitude == full.magnitude and found.magnitude > seal
        assert (found.converged, found.iterations) == (full.converged, full.iterations)
        assert np.array_equal(found.state, full.state)
    assert warm_torque(step, distribution, None, 0.0) is None
    assert warm_torque(step, distribution, start[:-1], 0.0) is None
    idle = replace(distribution, contact_load=np.zeros_like(distribution.contact_load))
    assert warm_torque(step, idle, start, 0.0) is None


@needs_numba
@pytest.mark.parametrize("case", range(3))
def test_both_paths_count_iterations_alike_when_they_run_out(case):
    # a few iterations allowed from a perturbed start: some balls converge, others run out;
    # both report max_iterations then (found by a review: the compiled loop reported one more)
    bearing, distribution = _distributions()[case]
    start = friction_torque(bearing, distribution).state * 1.3
    for most in (1, 2, 3):
        out = {k: friction_torque(bearing, distribution, kernel=k, initial=start, max_iterations=most)
               for k in ("numpy", "compiled")}
        assert out["compiled"].iterations == out["numpy"].iterations <= most + 1
        assert out["compiled"].converged == out["numpy"].converged
        if not out["numpy"].converged:
            assert out["numpy"].iterations == most
        assert out["compiled"].magnitude == pytest.approx(out["numpy"].magnitude, rel=1e-12)


def test_unknown_kernel_is_refused():
    bearing, distribution = _distributions()[0]
    with pytest.raises(ValueError, match="kernel = 'fortran'"):
        friction_torque(bearing, distribution, kernel="fortran")


def _run(code: str) -> dict:
    out = subprocess.run([sys.executable, "-c", NO_NUMBA + code], capture_output=True, text=True, cwd=ROOT,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_library_without_numba_gives_the_same_torque():
    bearing, distribution = _distributions()[2]
    here = friction_torque(bearing, distribution).magnitude          # compiled where numba is here
    there = _run("""
import json
from slewing_model import Loads, friction_torque, load_bearing, solve
from slewing_model.friction.kernel import AVAILABLE
b = load_bearing("examples/bearings/table3_errors.toml").with_preload(10e-6)
d = solve(b, Loads(Fx=2e4, Fz=5e4, Mx=4e3), psi=0.3)
try:
    friction_torque(b, d, kernel="compiled")
    refused = ""
except ValueError as exc:
    refused = str(exc)
print(json.dumps({"available": AVAILABLE, "torque": friction_torque(b, d).magnitude, "refused": refused}))
""")
    assert there["available"] is False
    assert "needs numba" in there["refused"]
    assert there["torque"] == pytest.approx(here, rel=1e-12)


@needs_numba
def test_fmu_ships_its_compiled_loops(table3_numba_fmu, tmp_path):
    table3_fmu = table3_numba_fmu
    # unpacked to a new folder, an instance loads the loops from the cache the FMU carries
    # (numba keys it by the source's content): no compilation at instantiation
    out = subprocess.run([sys.executable, "-c", f"""
import json, sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
md = read_model_description({str(table3_fmu)!r})
folder = extract({str(table3_fmu)!r}, unzipdir={str(tmp_path / "unzipped")!r})
fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="cache")
fmu.instantiate()
kernel = sys.modules["slewing_model.friction.kernel"]
stats = [f().stats for f, _ in kernel.all_kernels()]
print(json.dumps({{"inside": kernel.__file__.startswith(str(folder)), "hits": [sum(s.cache_hits.values()) for s in stats],
                   "misses": [sum(s.cache_misses.values()) for s in stats]}}))
fmu.freeInstance()  # (fmi2Terminate is for an initialized instance: refused in Instantiated)
"""], capture_output=True, text=True, cwd="/", timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["inside"]                             # the FMU's own copy of the library
    assert not any(result["misses"]) and all(h >= 1 for h in result["hits"]), result


def test_fmu_without_numba_gives_the_same_outputs(table3_numba_fmu):
    table3_fmu = table3_numba_fmu  # its compiled loops here, its numpy fallback where numba is missing
    from fmpy import simulate_fmu

    names = ["z", "rx", "friction_torque", "max_ball_load"]
    start = {"Fz": 4e4, "Mx": 2e3, "psi": 0.2, "omega": 0.5}
    here = simulate_fmu(str(table3_fmu), stop_time=0.05, step_size=0.01, start_values=start, output=names)
    there = _run(f"""
import json
from fmpy import simulate_fmu
r = simulate_fmu({str(table3_fmu)!r}, stop_time=0.05, step_size=0.01, start_values={start!r}, output={names!r})
import slewing_model.friction.kernel as k
print(json.dumps({{"available": k.AVAILABLE, **{{n: float(r[n][-1]) for n in {names!r}}}}}))
""")
    assert there.pop("available") is False
    for name in names:
        assert there[name] == pytest.approx(float(here[name][-1]), rel=1e-9, abs=1e-15), name


@pytest.mark.parametrize("owner, n_balls", [([0, 0, 1, 2, 2, 2, 3], 4),      # contacts in ball order
                                            ([0, 2, 2, 3], 4),               # ball 1 without a contact
                                            ([1, 0, 2, 2], 3)])              # not in ball order
def test_the_per_ball_sums_of_numpys_loops_add_each_balls_contacts(owner, n_balls):
    """``ContactPoints._per_ball``: every ball's sum of its contacts' values, as the product with the
    0/1 matrix ``sum_matrix`` gives it, whether the contacts follow one another (``np.add.reduceat``)
    or not (that product)."""
    from types import SimpleNamespace

    owner = np.array(owner)
    sum_matrix = np.zeros((n_balls, owner.size))
    sum_matrix[owner, np.arange(owner.size)] = 1.0
    points = SimpleNamespace(geometry=SimpleNamespace(owner=owner, active=np.arange(n_balls), sum_matrix=sum_matrix))
    values = np.random.default_rng(3).standard_normal((9, owner.size))
    want = np.array([[row[owner == b].sum() for b in range(n_balls)] for row in values])
    for _ in range(2):                              # the second call takes the kept starts
        got = ContactPoints._per_ball(points, values)
        assert got.shape == (9, n_balls) and np.allclose(got, want, rtol=1e-15, atol=1e-15)
    assert np.allclose(ContactPoints._per_ball(points, values[0]), want[0], rtol=1e-15, atol=1e-15)


@pytest.mark.parametrize("case", range(3))
def test_a_small_last_newton_step_taken_unchecked_changes_the_torque_by_round_off_only(case, monkeypatch):
    """A converged ball's last Newton step is taken without evaluating the power at it where it is small
    (``UNCHECKED_STEP``, which spares an evaluation of every ball a co-simulation step): cold, warm and
    perturbed starts, loose tolerances and balls that run out of iterations give the torque, power and ball
    states of the loop that checks every such step, to round-off. The check is not idle: taken unchecked
    whatever their size, the last steps from far starts at a loose tolerance raise the power (here by up to
    six times, table3 with errors), which the bound leaves to the check."""
    from slewing_model.friction import ball_kinematics

    bearing, distribution = _distributions()[case]
    cold = friction_torque(bearing, distribution, kernel="numpy")
    default = ball_kinematics.UNCHECKED_STEP
    raised = 0.0
    for start, most, tol in ((None, 60, 1e-5), (cold.state * 1.01, 60, 1e-5), (cold.state * 1.3, 60, 1e-5),
                             (cold.state * 1.3, 2, 1e-5), (cold.state * 0.5, 60, 1e-3), (cold.state * 2.0, 60, 0.1),
                             (-cold.state, 60, 1e-2)):
        found = {}
        for share in (default, 0.0, math.inf):              # 0: every last step checked; inf: none
            monkeypatch.setattr(ball_kinematics, "UNCHECKED_STEP", share)
            found[share] = friction_torque(bearing, distribution, kernel="numpy", initial=start,
                                           max_iterations=most, tol=tol)
        small, checked, unchecked = found.values()
        assert small.magnitude == pytest.approx(checked.magnitude, rel=1e-13)
        assert small.power == pytest.approx(checked.power, rel=1e-13)
        assert (small.iterations, small.converged) == (checked.iterations, checked.converged)
        assert np.allclose(small.state, checked.state, rtol=1e-12, atol=1e-15 * np.abs(checked.state).max())
        raised = max(raised, unchecked.power / checked.power - 1.0)
    if case == 2:
        assert raised > 1e-3


@needs_numba
def test_both_paths_take_the_last_newton_step_unchecked_alike():
    """``_step_unchecked`` (the compiled loop's test of a small last step) decides as ``minimise_power``'s
    numpy test does, also at its bound and with a NaN in the step or the unknowns."""
    from slewing_model.friction import kernel

    kernel.compile_all()                                 # the helper compiled in place
    rng = np.random.default_rng(5)
    x = rng.standard_normal((400, 3))
    step = x * np.exp(rng.uniform(-12.0, 2.0, (400, 1))) * rng.standard_normal((400, 3))
    step[0] = kernel.UNCHECKED_STEP * np.abs(x[0]).max()            # at the bound: unchecked
    step[1, 2], x[2, 0], x[3] = np.nan, np.nan, 0.0
    step[3] = 0.0
    numpy_test = np.abs(step).max(axis=1) <= kernel.UNCHECKED_STEP * np.abs(x).max(axis=1)
    compiled = np.array([kernel._step_unchecked(s, u) for s, u in zip(step, x)])
    assert np.array_equal(compiled, numpy_test)
    assert compiled[0] and not compiled[1] and not compiled[2] and compiled[3]
    assert 50 < compiled.sum() < 350                    # both outcomes met
