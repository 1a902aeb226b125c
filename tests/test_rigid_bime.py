"""Rigid-BIME (paper sections 2.1 and 2.3) against closed forms, symmetry and finite differences."""
import math

import numpy as np
import pytest

from slewing_model import BimeSolver, LoadCapacityError, Loads, NoEquilibriumError, solve


def _diagonal_stiffness_n_mm(dw_mm, rc_mm):
    # paper eqs 10-11 written out in N and mm, independent of slewing_model.bearing.contact
    s = dw_mm / (2 * rc_mm)
    k = 88220 * dw_mm**0.5 / (1 - s) ** 0.3621
    return (2 * k ** (-2 / 3)) ** -1.5 * 1e3**1.5  # two equal contacts in series, N/m^1.5


def _axial_closed_form(bearing, z):
    """Axial force of B equal balls for an axial displacement z (both diagonals, traction only)."""
    dw, rc, alpha = bearing.ball_diameter, bearing.groove_radius[0], bearing.contact_angle
    a = 2 * rc - dw                       # distance between the groove centres of a diagonal
    natural = a - bearing.preload         # eq 5 with the oversized ball
    ktot = _diagonal_stiffness_n_mm((dw + bearing.preload) * 1e3, rc * 1e3)
    force = 0.0
    angles = []
    for sign in (+1, -1):                 # diagonal 1 lengthens with +z, diagonal 2 shortens
        r, h = a * math.cos(alpha), a * math.sin(alpha) + sign * z
        length = math.hypot(r, h)
        delta = max(length - natural, 0.0)
        force += sign * bearing.ball_count * ktot * delta**1.5 * h / length
        angles.append(math.atan2(h, r))
    return force, angles


@pytest.mark.parametrize("preload", [-20e-6, 0.0, 10e-6])
@pytest.mark.parametrize("z", [40e-6, 100e-6, 200e-6])  # beyond the 20 um gap
def test_axial_load_matches_closed_form(table1, preload, z):
    bearing = table1.with_preload(preload)
    fz, (alpha1, _) = _axial_closed_form(bearing, z)
    result = solve(bearing, Loads(Fz=fz))
    assert result.displacement[2] == pytest.approx(z, rel=1e-6)
    assert np.allclose(result.displacement[[0, 1, 3, 4]], 0.0, atol=1e-12)
    # all balls equal, loaded contact angle of diagonal 1 from the closed form
    q1 = result.contact_load[:, 0]
    assert np.ptp(q1) <= 1e-9 * q1.max()
    assert result.contact_angle[:, 0] == pytest.approx(np.full(bearing.ball_count, alpha1), rel=1e-6)


def test_loaded_contact_angle_grows_with_axial_load(table1):
    angles = [solve(table1, Loads(Fz=f)).contact_angle[0, 0] for f in (1e5, 1e6, 3e6)]
    assert table1.contact_angle < angles[0] < angles[1] < angles[2]


def test_tilting_moment_matches_rumbarger(table1):
    # Rumbarger (NREL DG03 / Harris): Qmax = 4.37 M / (Z dm sin alpha) for a moment on a
    # four-point contact bearing with zero clearance
    moment = 200e3
    r = solve(table1, Loads(Mx=moment))
    b, c = np.unravel_index(np.argmax(r.contact_load), r.contact_load.shape)
    ratio = r.contact_load[b, c] * table1.ball_count * table1.pitch_diameter * math.sin(r.contact_angle[b, c]) / moment
    assert ratio == pytest.approx(4.37, rel=0.02)


def test_preload_alone_gives_preload_interference(table1):
    r = solve(table1.with_preload(15e-6))
    assert np.allclose(r.interference, 15e-6, rtol=1e-9)
    assert r.balls_in_four_point_contact == table1.ball_count


def test_balls_in_four_point_contact_are_those_loaded_on_all_four_contacts(table1):
    """Under an axial load and a tilting moment some balls carry both diagonals and others one: the
    count is that of the balls whose four contacts all press (a pressure of at least NO_LOAD_PRESSURE),
    counted ball by ball here."""
    from slewing_model.distribution.results import NO_LOAD_PRESSURE

    r = solve(table1, Loads(Fz=1e5, My=3e5))
    by_ball = sum(all(p >= NO_LOAD_PRESSURE for p in row) for row in r.contact_pressure.tolist())
    assert 0 < r.balls_in_four_point_contact == by_ball < table1.ball_count


def test_load_rotated_by_one_ball_pitch_shifts_loads_by_one_ball(table3):
    loads = Loads(Fx=20e3, Fy=-5e3, Fz=60e3, Mx=15e3, My=-30e3)
    a = solve(table3, loads)
    b = solve(table3, loads.rotated(2 * math.pi / table3.ball_count))
    assert np.allclose(b.contact_load, np.roll(a.contact_load, 1, axis=0), rtol=1e-7, atol=1e-9 * a.max_ball_load)


def test_paper_loads_are_the_general_set():
    # eq 22: the tilt axis is perpendicular to the radial load direction
    l = Loads.from_paper(axial=1.0, radial=2.0, tilting_moment=3.0, direction=math.pi / 2)
    assert np.allclose(l.as_array(), [0.0, 2.0, 1.0, -3.0, 0.0], atol=1e-15)


def test_equilibrium_of_contact_forces(table1):
    # forces and moments of the contacts on the moving ring, summed independently of the solver
    loads = Loads(Fx=80e3, Fy=30e3, Fz=400e3, Mx=-300e3, My=900e3)
    r = solve(table1, loads)
    solver = BimeSolver(table1)
    centres = solver.assembly.moving_centre      # (B, 2, 2) R, z of inner groove centres
    phi = r.ball_angle
    total = np.zeros(5)
    for k, (col, zsign) in enumerate(((0, 1.0), (1, -1.0))):
        q, alpha = r.contact_load[:, col], r.contact_angle[:, col]
        # force of the outer ring on the inner ring, along the diagonal towards the outer groove centre
        fr, fz = -q * np.cos(alpha), -q * zsign * np.sin(alpha)
        fx, fy = fr * np.cos(phi), fr * np.sin(phi)
        rr = centres[:, k, 0] + r.displacement[0] * np.cos(phi) + r.displacement[1] * np.sin(phi)
        zz = centres[:, k, 1] + r.displacement[2]
        px, py = rr * np.cos(phi), rr * np.sin(phi)
        total += [fx.sum(), fy.sum(), fz.sum(), (py * fz - zz * fy).sum(), (zz * fx - px * fz).sum()]
    # the contact forces balance the applied load (small-displacement statics)
    assert np.allclose(-total, loads.as_array(), rtol=1e-3, atol=1e-6 * 900e3)


def test_gradient_and_hessian_match_finite_differences(table3):
    solver = BimeSolver(table3.with_preload(5e-6))
    loads = Loads(Fx=1e4, Fz=5e4, My=2e4)
    x = np.array([3e-6, -2e-6, 10e-6, 2e-5, -1e-5])
    u, g, h = solver.energy_terms(x, loads)
    steps = np.array([1e-9, 1e-9, 1e-9, 1e-9 / 0.27, 1e-9 / 0.27])
    g_fd = np.empty(5)
    h_fd = np.empty((5, 5))
    for i in range(5):
        dx = np.zeros(5)
        dx[i] = steps[i]
        up, gp, _ = solver.energy_terms(x + dx, loads)
        um, gm, _ = solver.energy_terms(x - dx, loads)
        g_fd[i] = (up - um) / (2 * steps[i])
        h_fd[:, i] = (gp - gm) / (2 * steps[i])
    assert np.allclose(g, g_fd, rtol=1e-6, atol=1e-6 * np.abs(g).max())
    assert np.allclose(h, h_fd, rtol=1e-5, atol=1e-6 * np.abs(h).max())
    assert np.allclose(h, h.T)


def test_solution_is_the_energy_minimum(table3):
    solver = BimeSolver(table3)
    loads = Loads(Fx=1e4, Fz=5e4, My=2e4)
    r = solver.solve(loads)
    u0, g0, h0 = solver.energy_terms(r.displacement, loads)
    assert np.abs(g0[:3]).max() < 1e-8 * 5e4
    assert np.all(np.linalg.eigvalsh(h0) > 0)
    rng = np.random.default_rng(0)
    for _ in range(20):
        dx = rng.normal(size=5) * np.array([1e-6, 1e-6, 1e-6, 4e-6, 4e-6])
        assert solver.energy_terms(r.displacement + dx, loads)[0] > u0


def test_clearance_with_load_engages_contacts(table3):
    # 40 um clearance: the ring first crosses the gap, then the contacts carry the load
    r = solve(table3.with_preload(-40e-6), Loads(Fz=2e4))
    assert r.contact_load[:, 0].min() > 0 and np.all(r.contact_load[:, 1] == 0)
    assert r.displacement[2] > 40e-6 / (2 * math.sin(table3.contact_angle))


def test_idling_with_clearance_is_at_rest(table3):
    r = solve(table3.with_preload(-10e-6))
    assert r.max_ball_load == 0.0 and np.all(r.displacement == 0.0) and r.static_safety_factor == math.inf


def test_load_beyond_raceway_capacity_is_refused(table3):
    # gross overload: Hertz pressure above twice the ISO 76 limit
    with pytest.raises(LoadCapacityError, match=r"contact pressure .* above the limit of 8400 MPa"):
        solve(table3, Loads(Fz=5e7))
    with pytest.raises(LoadCapacityError, match=r"beyond what the bearing can carry"):
        solve(table3, Loads(Mx=2e7))


def test_contact_point_past_the_groove_edge_is_refused():
    # a wide gap between the rings leaves a shallow groove: its edge comes before the pressure limit
    from slewing_model import bearing_from_dict

    shallow = bearing_from_dict({"bearing": {"pitch_diameter_mm": 541.0, "ball_diameter_mm": 25.0,
                                             "groove_radius_mm": 13.25, "contact_angle_deg": 56.0, "ball_count": 67},
                                 "rings": {"gap_mm": 12.0}})
    edge = shallow.groove_edge_angle(1)
    assert math.radians(58) < edge < math.radians(62)
    assert solve(shallow, Loads(Fz=2e5)).contact_angle.max() < edge
    with pytest.raises(LoadCapacityError, match=r"past the groove edge"):
        solve(shallow, Loads(Fz=3e6))


def test_edge_loading_is_reported_before_the_load_is_refused(table1):
    # the ellipse reaches the groove edge (82.3 deg for the default rings) before its centre does
    moderate = solve(table1, Loads(Fz=2e6))
    high = solve(table1, Loads(Fz=2e7))
    assert moderate.truncated_contacts == 0 < high.truncated_contacts
    reach = high.contact_angle + high.semi_axis_a / table1.groove_radius[0]
    assert np.all(reach[high.truncated] >= table1.groove_edge_angle(1))


def test_solver_stops_with_a_clear_error_instead_of_looping(table3):
    solver = BimeSolver(table3, max_iterations=1)
    with pytest.raises(NoEquilibriumError, match=r"no convergence after 1 Newton iterations"):
        solver.solve(Loads(Fz=1e5, Mx=1e4))


def test_warm_start_needs_fewer_iterations(table1):
    solver = BimeSolver(table1)
    first = solver.solve(Loads(Fz=3e5, My=5e5))
    again = solver.solve(Loads(Fz=3.03e5, My=5.05e5), initial=first)
    assert again.iterations < first.iterations
    cold = solver.solve(Loads(Fz=3.03e5, My=5.05e5))
    assert np.allclose(again.contact_load, cold.contact_load, rtol=1e-8, atol=1e-8 * cold.max_ball_load)


@pytest.mark.parametrize("field", ["Fx", "Fz", "My"])
@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_non_finite_load_is_refused(field, value):
    with pytest.raises(ValueError, match=rf"load {field} = {value}: must be finite"):
        Loads(**{field: value})


def test_solver_converges_where_a_diagonal_just_unloads(table3):
    # with preload, an axial load that almost unloads diagonal 2 puts the energy near a kink;
    # the stopping rule must reach a tight tolerance there (the energy's roundoff is that of its terms)
    bearing = table3.with_preload(10e-6)
    for fz in np.linspace(1e3, 1.5e5, 60):
        r = solve(bearing, Loads(Fz=fz), rtol=1e-12)
        assert r.residual <= 1e-12
