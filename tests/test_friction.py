"""Friction torque (slewing_model.friction) against closed forms, an independent
per-contact recomputation, and the physical behaviours the model must show.

Expected values come from closed forms (with their sources), from scipy
integrations written here independently of the module, or from relations the
model must satisfy (power balance, scaling, symmetry, periodicity); none is
copied from the module's own output.
"""
import math

import numpy as np
import pytest
from scipy import integrate, special

from slewing_model import Loads, solve, synthetic_errors
from slewing_model.friction import (
    CATALOGUE_MU, EllipseQuadrature, FrictionTorque, catalogue_torque, conformity_radius, ellipse_friction,
    ellipse_quadrature, friction_torque, omega_regularisation_for_step, preload_sweep, regularised_torque,
    stick_slip_torque, torque_ripple,
)
from slewing_model.friction import ball_kinematics
from slewing_model.friction.ball_kinematics import SOLVED, ContactSet
from slewing_model.numerics.compiled import AVAILABLE

SIGN_R = np.array([1.0, -1.0, -1.0, 1.0])   # contact normals of contacts 1..4 (geometry.Bearing.contact_normals)
SIGN_Z = np.array([1.0, 1.0, -1.0, -1.0])


@pytest.fixture(scope="module")
def axial(table3):
    """Table 3 bearing (67 balls) under a pure axial load: every ball on diagonal 1 only."""
    return table3, solve(table3, Loads(Fz=300e3))


@pytest.fixture(scope="module")
def preloaded(table3):
    """Table 3 bearing with 20 um ball preload, idling: every ball in four-point contact."""
    bearing = table3.with_preload(20e-6)
    return bearing, solve(bearing, None)


@pytest.fixture(scope="module")
def combined(table3):
    """Axial load and tilting moment: a mix of two- and four-contact balls."""
    return table3, solve(table3, Loads(Fz=100e3, Mx=50e3))


# ---- quadrature and one contact ---------------------------------------------------------

def test_quadrature_integrates_the_hertz_pressure_exactly():
    # semi-ellipsoidal pressure: integral p = Q, integral p eta^2 = Q a^2 / 5, integral p xi^2 = Q b^2 / 5,
    # integral p eta^2 xi^2 = Q a^2 b^2 / 35 (moments of the Hertz distribution, Johnson, Contact Mechanics 3.4)
    q = ellipse_quadrature(6, 4)
    assert isinstance(q, EllipseQuadrature)
    assert q.weight.sum() == pytest.approx(1.0, rel=1e-14)
    assert np.sum(q.weight * q.across**2) == pytest.approx(1 / 5, rel=1e-13)
    assert np.sum(q.weight * q.along**2) == pytest.approx(1 / 5, rel=1e-13)
    assert np.sum(q.weight * q.across**2 * q.along**2) == pytest.approx(1 / 35, rel=1e-13)
    assert np.sum(q.weight * q.across**4) == pytest.approx(3 / 35, rel=1e-13)


def test_uniform_sliding_gives_coulomb_force_and_no_moment():
    # rigid translation: every point slides at v0, the force is mu Q along v0 (Coulomb), no moment
    f = ellipse_friction(2000.0, 2e-3, 0.3e-3, 0.1, sliding_velocity=(0.3, 0.4))
    assert f.force[:2] == pytest.approx([0.1 * 2000 * 0.6, 0.1 * 2000 * 0.8], rel=1e-12)
    assert np.abs(f.moment).max() < 1e-12
    assert f.power == pytest.approx(0.1 * 2000 * 0.5, rel=1e-12)


def test_pure_spin_on_a_circle_gives_the_pivoting_moment_3pi_over_16():
    # Johnson, Contact Mechanics, section 5.6 (spin of a Hertz circle at full slip): M = 3 pi / 16 mu Q a
    load, a, mu = 1500.0, 1.2e-3, 0.1
    f = ellipse_friction(load, a, a, mu, relative_rotation=(0.0, 0.0, 2.0))
    exact = 3 * math.pi / 16 * mu * load * a
    assert f.moment[2] == pytest.approx(exact, rel=0.01)
    assert np.abs(f.force).max() < 1e-9 * mu * load         # a pure spin drags no net force


def _pivoting_factor_scipy(ratio):
    """f(a/b) in M = mu Q a f, by direct 2-D integration of p * distance over the ellipse (scipy).

    Independent of the module's quadrature: integral over the unit disk of
    sqrt(x^2 + (y/ratio)^2) * sqrt(1 - x^2 - y^2), times 3 / (2 pi) (pressure normalised to Q = 1)."""
    value, _ = integrate.dblquad(lambda y, x: math.hypot(x, y / ratio) * math.sqrt(max(1 - x * x - y * y, 0.0)),
                                 -1, 1, lambda x: -math.sqrt(1 - x * x), lambda x: math.sqrt(1 - x * x),
                                 epsabs=1e-11, epsrel=1e-10)
    return 1.5 / math.pi * value


@pytest.mark.parametrize("ratio", [2.0, 5.0, 10.0])
def test_pure_spin_on_a_slender_ellipse_matches_an_independent_integration(ratio):
    # closed form M = 3/8 mu Q a E(k), k^2 = 1 - (b/a)^2 (integrating in elliptic polar coordinates), checked
    # against a direct scipy integration; the module's default rule must be within 1 %
    f_scipy = _pivoting_factor_scipy(ratio)
    f_closed = 3 / 8 * special.ellipe(1 - 1 / ratio**2)
    assert f_scipy == pytest.approx(f_closed, rel=1e-7)
    load, a, mu = 1000.0, 3e-3, 0.1
    f = ellipse_friction(load, a, a / ratio, mu, relative_rotation=(0.0, 0.0, 1.0))
    assert f.moment[2] == pytest.approx(mu * load * a * f_closed, rel=0.01)


def test_pivoting_moment_converges_with_the_quadrature():
    exact = 3 / 8 * special.ellipe(1 - 1 / 6.0**2)
    errors = [abs(ellipse_friction(1.0, 1.0, 1 / 6.0, 1.0, relative_rotation=(0, 0, 1.0), quadrature=n).moment[2]
                  / exact - 1) for n in (4, 8, 16, 32)]
    assert all(e2 < e1 for e1, e2 in zip(errors, errors[1:]))
    assert errors[-1] < 1e-3


def test_bent_contact_surface_radius_is_the_harmonic_mean():
    # Harris & Kotzalas: R = 2 r D / (2 r + D) for groove radius r and ball diameter D
    r, dw = 13.25e-3, 25e-3
    assert conformity_radius(dw / 2, r) == pytest.approx(2 * r * dw / (2 * r + dw), rel=1e-14)


# ---- ball equilibrium and power balance ----------------------------------------------------

def _recompute_contacts(bearing, dist, result, quadrature, sliding_regularisation=1e-3):
    """Every loaded contact recomputed through ellipse_friction from the returned ball motion.

    Returns per contact: ball index, force and moment (about the ball centre) on the ball in the
    ball's (r, t, z) frame, position of the contact centre, raceway speed, dissipated power."""
    omega = result.kinematics_speed
    rb = 0.5 * (bearing.ball_diameter + bearing.preload)
    big_r = 0.5 * bearing.pitch_diameter
    moving = (1, 2) if bearing.moving_ring == "inner" else (0, 3)
    rows = []
    for b, c in zip(*np.nonzero(dist.contact_load > 0)):
        alpha = dist.contact_angle[b, c]
        n = np.array([SIGN_R[c] * math.cos(alpha), 0.0, SIGN_Z[c] * math.sin(alpha)])
        t = np.array([0.0, 1.0, 0.0])
        g = np.cross(n, t)
        centre = np.array([big_r, 0.0, 0.0])
        x0 = centre + rb * n
        ring = omega if c in moving else 0.0
        ez = np.array([0.0, 0.0, 1.0])
        w_ball = result.ball_angular_velocity[b]
        # raceway relative to ball: v(x) = W e_z x x - w_c e_z x c - w x (x - c) = v0 + w_rel x (x - x0)
        w_rel = ring * ez - w_ball
        v0 = ring * np.cross(ez, x0) - result.orbital_speed[b] * np.cross(ez, centre) - np.cross(w_ball, x0 - centre)
        assert abs(v0 @ n) < 1e-12 * big_r * abs(omega)      # no separation at the contact centre
        a, bb = dist.semi_axis_a[b, c], dist.semi_axis_b[b, c]
        f = ellipse_friction(dist.contact_load[b, c], a, bb, result.mu, sliding_velocity=(v0 @ t, v0 @ g),
                             relative_rotation=(w_rel @ t, w_rel @ g, w_rel @ n),
                             conformity_radius=conformity_radius(rb, bearing.groove_radius[c]),
                             quadrature=quadrature, regularisation=sliding_regularisation * abs(omega) * a)
        basis = np.stack([t, g, n])
        force = f.force @ basis
        moment = f.moment @ basis + np.cross(x0 - centre, force)
        rows.append((b, force, moment, x0, ring, float(f.power)))
    return rows


@pytest.mark.parametrize("case", ["axial", "preloaded", "combined"])
def test_power_balance_and_ball_equilibrium_from_an_independent_recomputation(case, request):
    """Sum over contacts of traction . sliding velocity = torque x omega, with the torque taken
    from the moments about z of the raceway tractions recomputed contact by contact; and every
    ball in equilibrium (friction moments and rolling-direction force vanish)."""
    bearing, dist = request.getfixturevalue(case)
    quad = (12, 4)
    omega = 0.7
    r = friction_torque(bearing, dist, omega=omega, quadrature=quad, solve_quadrature=None, tol=1e-13)
    assert r.converged
    rows = _recompute_contacts(bearing, dist, r, quad)
    power = sum(row[5] for row in rows)
    assert power == pytest.approx(r.power, rel=1e-10)              # same integration, two code paths
    ring_torque = sum(-(np.cross(x0, f) + (m - np.cross(x0 - np.array([bearing.pitch_diameter / 2, 0, 0]), f)))[2]
                      for _, f, m, x0, ring, _ in rows if ring != 0.0)
    assert ring_torque * omega == pytest.approx(-power, rel=1e-6)   # power balance
    assert r.contact_part * omega == pytest.approx(power, rel=1e-10)
    assert r.contact_part_moments == pytest.approx(-ring_torque, rel=1e-9)
    mu_q = r.mu * dist.contact_load.max()
    for b in np.unique([row[0] for row in rows]):
        f = sum(row[1] for row in rows if row[0] == b)
        m = sum(row[2] for row in rows if row[0] == b)
        assert abs(f[1]) < 1e-6 * mu_q                              # rolling-direction force
        assert np.abs(m).max() < 1e-6 * mu_q * bearing.ball_diameter  # friction moments


def test_power_is_the_minimum_over_ball_motions(preloaded):
    # the equilibrium minimises the dissipated power (convex): any other ball motion dissipates more
    bearing, dist = preloaded
    base = friction_torque(bearing, dist, solve_quadrature=None, tol=1e-12)
    rng = np.random.default_rng(3)
    for _ in range(3):
        state = base.state * (1 + 0.02 * rng.standard_normal(base.state.shape))
        other = friction_torque(bearing, dist, solve_quadrature=None, initial=state, max_iterations=0)
        assert other.power > base.power


def test_torque_is_proportional_to_mu(combined):
    bearing, dist = combined
    t = [friction_torque(bearing, dist, mu=mu).contact_part for mu in (0.05, 0.1, 0.15)]
    assert t[0] / 0.05 == pytest.approx(t[1] / 0.1, rel=1e-6)
    assert t[2] / 0.15 == pytest.approx(t[1] / 0.1, rel=1e-6)


def test_torque_is_odd_in_omega_and_independent_of_its_magnitude(combined):
    bearing, dist = combined
    slow = friction_torque(bearing, dist, omega=0.01)
    fast = friction_torque(bearing, dist, omega=2.0)
    back = friction_torque(bearing, dist, omega=-2.0)
    assert fast.magnitude == pytest.approx(slow.magnitude, rel=1e-6)
    assert back.magnitude == pytest.approx(fast.magnitude, rel=1e-6)
    assert fast.torque < 0 < back.torque
    assert back.torque == pytest.approx(-fast.torque, rel=1e-6)
    # the ball motion reverses and scales with the speed
    assert back.ball_angular_velocity == pytest.approx(-fast.ball_angular_velocity, rel=1e-5, abs=1e-9)
    assert slow.orbital_speed * 200 == pytest.approx(fast.orbital_speed, rel=1e-6)


def test_regularised_torque_near_zero_speed():
    m = 1234.0
    assert regularised_torque(m, 0.0, 1e-3) == 0.0
    assert regularised_torque(m, 1.0, 1e-3) == pytest.approx(-m, rel=1e-12)
    assert regularised_torque(m, -2.65e-3, 1e-3) == pytest.approx(m * math.tanh(2.65), rel=1e-12)
    speeds = np.linspace(-5e-3, 5e-3, 201)
    torques = np.array([regularised_torque(m, w, 1e-3) for w in speeds])
    assert np.all(np.diff(torques) < 0)                                    # opposes, monotonic
    assert np.max(np.abs(np.diff(torques) / np.diff(speeds))) <= m / 1e-3 * (1 + 1e-9)  # Lipschitz bound
    assert regularised_torque(m, 3.0, 0.0) == -m and regularised_torque(m, -3.0, 0.0) == m
    # stick-slip: below the break-away level the friction balances the drive; above, it slides
    assert stick_slip_torque(m, 0.0, 500.0, 1e-4) == -500.0
    assert stick_slip_torque(m, 0.0, 5000.0, 1e-4) == -m
    assert stick_slip_torque(m, 1e-3, 0.0, 1e-4) == -m
    assert omega_regularisation_for_step(m, inertia=1e4, step=1e-2) == pytest.approx(m * 1e-2 / 1e4)


def test_friction_torque_sign_convention_and_seal_part(axial):
    bearing, dist = axial
    plain = friction_torque(bearing, dist, omega=0.05)
    sealed = friction_torque(bearing, dist, omega=0.05, seal_torque=100.0, seal_torque_per_length=20.0)
    seal = 100.0 + 20.0 * 2 * math.pi * bearing.pitch_diameter     # two seals on the pitch circle
    assert sealed.seal_part == pytest.approx(seal, rel=1e-12)
    assert sealed.magnitude == pytest.approx(plain.magnitude + seal, rel=1e-9)
    assert sealed.torque == pytest.approx(-sealed.magnitude * math.tanh(0.05 / 1e-4), rel=1e-12)
    assert plain.per_ball.sum() == pytest.approx(plain.contact_part, rel=1e-12)
    assert np.all(plain.per_ball >= 0)
    at_rest = friction_torque(bearing, dist, omega=0.0, seal_torque=100.0)
    assert at_rest.torque == 0.0 and at_rest.magnitude == pytest.approx(plain.magnitude + 100.0, rel=1e-6)


def test_unloaded_bearing_has_only_the_seal_torque(table3):
    bearing = table3.with_preload(-20e-6)                  # clearance, idling: no contact loaded
    r = friction_torque(bearing, solve(bearing, None), seal_torque=50.0)
    assert r.contact_part == 0.0 and r.magnitude == 50.0 and r.balls_in_four_point_contact == 0


# ---- kinematics: two and four contacts ----------------------------------------------------

def test_two_contact_ball_rolls_about_an_axis_normal_to_the_loaded_diagonal(axial):
    # Leblanc & Nelias (paper ref. [17]), Joshi et al. (ref. [20]): with one loaded diagonal the ball's
    # rotation relative to the cage is normal to the contact line, and the ball set orbits at
    # (1 - Dw cos(alpha) / dm) / 2 of the ring speed (rolling at both contacts)
    bearing, dist = axial
    r = friction_torque(bearing, dist, omega=1.0, tol=1e-10)
    assert np.all(r.contact_count == 2)
    alpha = dist.contact_angle[:, 0]
    n = np.stack([np.cos(alpha), np.zeros_like(alpha), np.sin(alpha)], axis=1)
    relative = r.ball_angular_velocity - r.orbital_speed[:, None] * np.array([0.0, 0.0, 1.0])
    angle = np.degrees(np.arccos(np.einsum("bk,bk->b", relative, n) / np.linalg.norm(relative, axis=1)))
    assert np.all(np.abs(angle - 90.0) < 0.5)
    gamma = (bearing.ball_diameter + bearing.preload) * np.cos(alpha) / bearing.pitch_diameter
    assert r.orbital_speed == pytest.approx(0.5 * (1 - gamma), rel=2e-3)


def test_symmetric_four_contact_ball_turns_about_the_bearing_axis_with_spin_to_roll_tan_alpha(preloaded):
    # by the mirror symmetry z -> -z of a preloaded, unloaded, error-free bearing the ball turns about
    # the axial direction; relative to each raceway that rotation has spin / roll = tan(alpha)
    bearing, dist = preloaded
    r = friction_torque(bearing, dist, tol=1e-10)
    assert np.all(r.contact_count == 4)
    w = r.ball_angular_velocity
    assert np.abs(w[:, :2]).max() < 1e-6 * np.abs(w[:, 2]).max()
    assert np.abs(r.spin_roll_ratio) == pytest.approx(np.tan(dist.contact_angle), rel=1e-6)


def test_kinematic_conflict_of_four_contacts_multiplies_the_friction(axial, preloaded):
    # same equations, two regimes: normalised by mu, the contact loads and dm/2, the four-contact
    # friction is an order of magnitude above the rolling two-contact one (spin/roll ~1 against ~0.03)
    def normalised(case):
        bearing, dist = case
        r = friction_torque(bearing, dist)
        return r.contact_part / (r.mu * dist.contact_load.sum() * bearing.pitch_diameter / 2)

    assert normalised(preloaded) > 10 * normalised(axial)


def test_torque_grows_with_preload(table3):
    torques, results = preload_sweep(table3, [2e-6, 5e-6, 10e-6, 20e-6, 40e-6], details=True)
    assert np.all(np.diff(torques) > 0)
    assert all(r.balls_in_four_point_contact == table3.ball_count for r in results)


def test_torque_dips_where_balls_go_from_four_to_two_contacts(table3):
    bearing = table3.with_preload(10e-6)
    loads = np.linspace(0.0, 120e3, 25)
    torques, fours = [], []
    previous = None
    for fz in loads:
        # rtol 1e-8: at 45 kN the BIME Newton stalls at a 3e-10 residual floor (reported, bime.py)
        r = friction_torque(bearing, solve(bearing, Loads(Fz=fz), rtol=1e-8), initial=previous)
        previous = r
        torques.append(r.magnitude)
        fours.append(r.balls_in_four_point_contact)
    torques, fours = np.array(torques), np.array(fours)
    k = int(np.argmax(fours == 0))                  # first load with no ball in four-point contact
    assert fours[0] == bearing.ball_count and 0 < k < loads.size - 2
    assert torques[k] < 0.5 * torques[k - 1]        # the kinematic conflict ends: a drop
    assert np.all(np.diff(torques[k:]) > 0)         # then grows with the load on one diagonal


# ---- rotation -----------------------------------------------------------------------------

def test_pure_axial_torque_does_not_depend_on_psi_without_errors(table3):
    t = torque_ripple(table3, Loads(Fz=200e3), np.linspace(0.0, 2 * np.pi, 5))
    assert np.ptp(t) <= 1e-6 * t.mean()


@pytest.fixture(scope="module")
def with_errors(table3):
    errors = synthetic_errors(table3.ball_count, seed=7, ball_tolerance=0.0)
    return table3.with_preload(5e-6).with_errors(errors)


def test_torque_with_errors_varies_with_psi(with_errors):
    t = torque_ripple(with_errors, Loads(Fz=50e3), np.linspace(0.0, 2 * np.pi, 8, endpoint=False))
    assert np.ptp(t) > 0.01 * t.mean()


def test_torque_with_errors_repeats_with_the_relative_position_of_rings_and_cage(with_errors):
    loads = Loads(Fz=50e3)
    pitch = 2 * np.pi / with_errors.ball_count

    def torque(psi, cage):
        return friction_torque(with_errors, solve(with_errors, loads, psi=psi, cage_angle=cage)).magnitude

    base = torque(0.7, 0.3)
    assert torque(0.7 + 2 * np.pi, 0.3) == pytest.approx(base, rel=1e-6)   # moving ring back, cage unchanged
    assert torque(0.7, 0.3 + pitch) == pytest.approx(base, rel=1e-6)       # cage one ball pitch further
    assert abs(torque(0.7 + 0.5, 0.3) / base - 1) > 1e-4                    # but not any rotation


def test_torque_ripple_follows_loads_fixed_to_the_moving_ring(table3):
    # a radial load turning with the moving ring on an error-free bearing: the same load relative to the
    # moving ring and, with the cage moved by the same angle, the same ball positions: constant torque
    psi = np.array([0.0, 0.9, 2.1])
    t = torque_ripple(table3, Loads(Fx=80e3, Fz=50e3), psi, cage_angle=psi, loads_frame="moving")
    assert np.ptp(t) <= 1e-5 * t.mean()


# ---- numerics -------------------------------------------------------------------------------

def test_default_rules_are_converged(combined, preloaded):
    # the default (solve on 12x2, integrate on 20x4) against a fully consistent fine rule
    for bearing, dist in (combined, preloaded):
        fine = friction_torque(bearing, dist, quadrature=(48, 8), solve_quadrature=None).contact_part
        default = friction_torque(bearing, dist).contact_part
        assert default == pytest.approx(fine, rel=3e-3)


def test_sliding_regularisation_does_not_change_the_torque(axial):
    bearing, dist = axial
    t = [friction_torque(bearing, dist, sliding_regularisation=s).contact_part for s in (1e-3, 1e-4)]
    assert t[0] == pytest.approx(t[1], rel=2e-4)


def test_warm_start_gives_the_same_torque_in_fewer_iterations(combined):
    bearing, dist = combined
    cold = friction_torque(bearing, dist)
    nearby = solve(bearing, Loads(Fz=101e3, Mx=50e3))
    warm = friction_torque(bearing, nearby, initial=cold)
    again = friction_torque(bearing, nearby)
    assert warm.magnitude == pytest.approx(again.magnitude, rel=1e-5)
    assert warm.iterations < again.iterations


def _stale_balls(bearing, dist, warm):
    """``ContactSet.stale_warm_start`` of a warm state (B, 4), as ``friction_torque`` asks it."""
    geometry = ContactSet(bearing, dist, 0.1, 1.0, 1e-3)
    scale = np.array([geometry.length_scale, geometry.length_scale, geometry.pitch_radius])
    return geometry.active[geometry.stale_warm_start(warm[geometry.active][:, SOLVED] * scale)]


def test_a_warm_start_on_the_other_diagonal_starts_cold(table3, preloaded, monkeypatch):
    """A tilting moment reversed in one step: a ball's warm motion rolls on the diagonal it left.
    Such balls (and those that left a preload's four-point contact) start cold, in both kernels
    alike, and reach the torque of a cold start; a ball at its own equilibrium (a motion tilted as
    rolling on its heavier diagonal) is never one of them. Kept, the stale motions' power inflates
    the minimisation's floor (the mean power at the start), which loosens every ball's stop."""
    before = solve(table3, Loads(Fz=100e3, Mx=150e3))
    after = solve(table3, Loads(Fz=100e3, Mx=-150e3))
    q_before, q_after = before.contact_load, after.contact_load
    one_diagonal = (q_after[:, 0] > 0) != (q_after[:, 1] > 0)
    flipped = np.flatnonzero(((q_before[:, 0] >= q_before[:, 1]) != (q_after[:, 0] >= q_after[:, 1])) & one_diagonal)
    assert flipped.size > 10
    warm = friction_torque(table3, before)
    for bearing, dist, own in ((table3, before, warm), (table3, after, friction_torque(table3, after)),
                               (*preloaded, friction_torque(*preloaded))):
        assert _stale_balls(bearing, dist, own.state).size == 0
    assert set(flipped) <= set(_stale_balls(table3, after, warm.state))
    assert set(np.flatnonzero(one_diagonal)) <= set(_stale_balls(table3, after, friction_torque(*preloaded).state))
    cold = friction_torque(table3, after)
    restarted = {k: friction_torque(table3, after, initial=warm, kernel=k)
                 for k in (("numpy", "compiled") if AVAILABLE else ("numpy",))}
    for result in restarted.values():
        assert result.magnitude == pytest.approx(cold.magnitude, rel=1e-5)
        assert result.iterations == restarted["numpy"].iterations
        assert result.magnitude == pytest.approx(restarted["numpy"].magnitude, rel=1e-10)
    monkeypatch.setattr(ball_kinematics, "WARM_ROLLING", -np.inf)     # every warm motion kept (numpy path)
    kept = friction_torque(table3, after, initial=warm, kernel="numpy")
    assert kept.magnitude == pytest.approx(cold.magnitude, rel=1e-5)
    assert restarted["numpy"].residual < 0.25 * kept.residual


@pytest.mark.parametrize("tol", [1e-3, 1e-4])
def test_tolerance_bounds_the_torque_error_from_above(combined, preloaded, tol):
    # the solve stops when the power is within tol of its minimum: the torque (power / speed)
    # is then above the exact one by at most tol (the simulator uses 1e-4)
    bearing = combined[0].with_preload(10e-6).with_errors(synthetic_errors(combined[0].ball_count, seed=1))
    scattered = bearing, solve(bearing, Loads(Fz=50e3))      # errors: some balls carry a few newtons
    for bearing, dist in (combined, preloaded, scattered):
        exact = friction_torque(bearing, dist, solve_quadrature=None, tol=1e-12)
        loose = friction_torque(bearing, dist, solve_quadrature=None, tol=tol)
        assert exact.contact_part * (1 - 1e-12) <= loose.contact_part <= exact.contact_part * (1 + tol)
        # per ball: within tol of the mean of its own power and the average one (2x for the
        # quadratic model behind the Newton decrement test)
        mean = exact.per_ball[exact.per_ball > 0].mean()
        excess = loose.per_ball - exact.per_ball
        assert np.all(excess >= -1e-9 * exact.per_ball.max())      # round-off of the sums
        assert np.all(excess <= tol * (exact.per_ball + mean))


def test_bad_input_is_refused_naming_the_field(axial):
    bearing, dist = axial
    for kwargs, field in ((dict(mu=-0.1), "mu"), (dict(omega=float("nan")), "omega"),
                          (dict(seal_torque=-1.0), "seal_torque"), (dict(quadrature=(0, 4)), "quadrature"),
                          (dict(initial=np.zeros((3, 4))), "initial")):
        with pytest.raises(ValueError, match=field):
            friction_torque(bearing, dist, **kwargs)
    with pytest.raises(ValueError, match="omega_regularisation"):
        regularised_torque(1.0, 1.0, -1.0)


# ---- catalogue formula ------------------------------------------------------------------------

def test_catalogue_formula_in_si_equals_the_kn_form(table1):
    # M [kN m] = mu/2 (4.4 Mk [kN m] + Fa [kN] D + 2.2 Fr [kN] D 1.73), D [m]
    loads = Loads(Fx=30e3, Fy=-40e3, Fz=800e3, Mx=300e3, My=400e3)
    d = table1.pitch_diameter
    m_knm = CATALOGUE_MU / 2 * (4.4 * 500.0 + 800.0 * d + 2.2 * 50.0 * d * 1.73)
    assert catalogue_torque(table1, loads) == pytest.approx(m_knm * 1e3, rel=1e-12)
    assert catalogue_torque(table1, loads, mu=0.012) == pytest.approx(2 * m_knm * 1e3, rel=1e-12)


def test_result_serialises(axial):
    bearing, dist = axial
    d = friction_torque(bearing, dist).to_dict()
    assert isinstance(d["magnitude"], float) and len(d["per_ball"]) == bearing.ball_count
    assert isinstance(friction_torque(bearing, dist), FrictionTorque)


def test_solver_gradient_hessian_and_majorant_are_consistent(combined):
    # internals of the ball equilibrium: the analytic gradient and Hessian of the regularised power
    # match central differences, and M = H + (M - H) majorises the power (Weiszfeld step is safe)
    from slewing_model.friction.ball_kinematics import ContactPoints, ContactSet

    bearing, dist = combined
    geo = ContactSet(bearing, dist, 0.1, 1.0, 1e-3)
    contacts = ContactPoints(geo, ellipse_quadrature(12, 2), workspace="test")
    rng = np.random.default_rng(5)
    u = geo.initial_guesses()[0] * (1 + 0.01 * rng.standard_normal((geo.active.size, 3)))
    eps2 = geo.eps2 * 100
    f, g, h, extra = contacts.evaluate(u, eps2, majorant=True)
    plain = contacts.evaluate(u, eps2)                      # the same H, computed without M - H
    assert plain[3] is None and np.array_equal(plain[1], g)
    assert np.allclose(plain[2], h, rtol=1e-12, atol=1e-12 * np.abs(h).max())
    step = 1e-7 * np.abs(u).max()
    g_fd, h_fd = np.zeros_like(g), np.zeros_like(h)
    for k in range(3):
        du = np.zeros_like(u)
        du[:, k] = step
        fp, gp, _, _ = contacts.evaluate(u + du, eps2)
        fm, gm, _, _ = contacts.evaluate(u - du, eps2)
        g_fd[:, k], h_fd[:, :, k] = (fp - fm) / (2 * step), (gp - gm) / (2 * step)
    assert np.abs(g_fd - g).max() < 1e-6 * np.abs(g).max()
    assert np.abs(h_fd - h).max() < 1e-5 * np.abs(h).max()
    for _ in range(5):
        du = 1e-2 * np.abs(u).max() * rng.standard_normal(u.shape)
        bound = f + np.einsum("bk,bk->b", g, du) + 0.5 * np.einsum("bk,bkl,bl->b", du, h + extra, du)
        assert np.all(contacts.evaluate(u + du, eps2, derivatives=False)[0] <= bound * (1 + 1e-12))


def test_subset_of_balls_evaluates_as_the_whole(combined):
    # the last iterations of a few balls run on their own contacts: same power, gradient, Hessians
    from slewing_model.friction.ball_kinematics import ContactPoints, ContactSet

    bearing, dist = combined
    geo = ContactSet(bearing, dist, 0.1, 1.0, 1e-3)
    contacts = ContactPoints(geo, ellipse_quadrature(12, 2), workspace="test")
    u = geo.initial_guesses()[1]
    balls = np.array([0, 5, geo.active.size - 1])
    whole = contacts.evaluate(u, geo.eps2, majorant=True)
    part = contacts.subset(balls).evaluate(u[balls], geo.eps2[np.isin(geo.owner, balls)], majorant=True)
    for w, p in zip(whole, part):
        assert np.allclose(p, w[balls], rtol=1e-13, atol=0.0)
