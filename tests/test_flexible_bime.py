"""Flexible-BIME with finite element superelements (paper sections 2.2-2.4)."""

import dataclasses

import numpy as np
import pytest

from slewing_model import BimeSolver, Loads, load_bearing, solve
from slewing_model.rings.superelement import build_superelement

from conftest import BEARINGS
from statics import load_on_moving_ring


@pytest.fixture(scope="module")
def table3_errors():
    return load_bearing(BEARINGS / "table3_errors.toml")


@pytest.fixture(scope="module")
def table3_free(table3_errors):
    return build_superelement(table3_errors, mesh="coarse", bc="free")


@pytest.fixture(scope="module")
def table1_rings(table1):
    return {bc: build_superelement(table1, mesh="coarse", bc=bc) for bc in ("clamped", "free")}


def test_stiff_rings_give_the_rigid_result(table3_errors, table3_free):
    bearing = table3_errors.with_preload(10e-6)
    loads = Loads(Fx=1e4, Fz=4e4, My=2e3)
    stiff = solve(bearing, loads, model="flexible", superelement=table3_free.scaled(1e6))
    rigid = solve(bearing, loads)
    assert np.allclose(stiff.contact_load, rigid.contact_load, rtol=1e-3, atol=1e-3 * rigid.max_ball_load)


def test_ring_flexibility_lowers_and_smooths_the_preload_interference(table3_errors, table3_free):
    # paper section 4.1: +20 um preload, rigid 25 -> flexible 14 um mean, band 14 -> 12 um
    bearing = table3_errors.with_preload(20e-6)
    rigid = solve(bearing)
    flexible = solve(bearing, model="flexible", superelement=table3_free)
    assert flexible.interference.mean() < 0.85 * rigid.interference.mean()
    assert np.ptp(flexible.interference) < np.ptp(rigid.interference)


def test_axial_stiffness_clamped_near_rigid_free_softer(table1, table1_rings):
    # paper Fig. 6: rigid supports keep the rings near the rigid-ring curve, free rings are far softer
    for force in (1e6, 2e6, 4e6):
        z_rigid = solve(table1, Loads(Fz=force)).displacement[2]
        z_clamped = solve(table1, Loads(Fz=force), model="flexible", superelement=table1_rings["clamped"]).displacement[2]
        z_free = solve(table1, Loads(Fz=force), model="flexible", superelement=table1_rings["free"]).displacement[2]
        assert z_rigid < z_clamped and z_clamped - z_rigid < 0.5 * (z_free - z_rigid)  # nearer rigid than free
        assert z_free > 1.5 * z_rigid


@pytest.mark.parametrize("loads", [Loads(Fz=3e4), Loads(Fx=2e4, Fz=1e4, Mx=2e3, My=-1e3)])
def test_contact_forces_balance_the_applied_load(table3_errors, table3_free, loads):
    r = solve(table3_errors.with_preload(10e-6), loads, model="flexible", superelement=table3_free)
    got = load_on_moving_ring(table3_errors, r)
    scale = np.abs(loads.as_array() * [1, 1, 1, 2 / 0.541, 2 / 0.541]).max()
    assert np.allclose(got * [1, 1, 1, 2 / 0.541, 2 / 0.541], loads.as_array() * [1, 1, 1, 2 / 0.541, 2 / 0.541],
                       atol=1e-6 * scale)


def _ring_loads(result):
    """Contact forces on each ring's groove centres, in the superelement's DOF order."""
    a1, a2 = result.contact_angle[:, 0], result.contact_angle[:, 1]
    f1 = result.contact_load[:, 0:1] * np.stack([np.cos(a1), np.sin(a1)], axis=1)    # diagonal 1 direction
    f2 = result.contact_load[:, 1:2] * np.stack([np.cos(a2), -np.sin(a2)], axis=1)   # diagonal 2 direction
    on_inner = -np.stack([f2, f1], axis=1)   # contacts 2 (diag 2), 3 (diag 1)
    on_outer = np.stack([f1, f2], axis=1)    # contacts 1 (diag 1), 4 (diag 2)
    return on_outer.ravel(), on_inner.ravel()


@pytest.mark.parametrize("bc", ["clamped", "free"])
def test_each_ring_balances_its_strain_energy_gradient(table1, table1_rings, bc):
    se = table1_rings[bc]
    r = solve(table1.with_preload(10e-6), Loads(Fz=8e5, My=6e5), model="flexible", superelement=se)
    on_outer, on_inner = _ring_loads(r)
    d = r.ring_displacement
    scale = r.max_ball_load
    for ring, load, disp in ((se.outer, on_outer, d[:, [0, 3]].ravel()), (se.inner, on_inner, d[:, [1, 2]].ravel())):
        k = ring.dense()
        if bc == "free":  # a free ring is held against rigid motion: only the self-balanced part deforms it
            w, v = np.linalg.eigh(k)
            rigid = v[:, np.abs(w) < 1e-9 * np.abs(w).max()]
            assert rigid.shape[1] == 5
            load = load - rigid @ (rigid.T @ load)
        assert np.allclose(k @ disp, load, atol=1e-6 * scale)


def test_radial_load_has_no_spurious_circumferential_stiffness(table3_errors, table3_free):
    # paper Fig. 12: springs that stay in each ball's radial plane carry a radial load only
    # through their radial components; a load along x moves the ring along x only
    bearing = load_bearing(BEARINGS / "table3.toml")  # nominal: symmetric about the x axis
    se = build_superelement(bearing, mesh="coarse", bc="free")
    for fx in (2e4, 4e4):
        r = solve(bearing, Loads(Fx=fx), model="flexible", superelement=se)
        got = load_on_moving_ring(bearing, r)
        assert got[0] == pytest.approx(fx, rel=1e-6)
        assert abs(got[1]) < 1e-6 * fx and abs(r.displacement[1]) < 1e-9 * abs(r.displacement[0])
    # radial stiffness from two solutions equals the radial load over the displacement increment
    r1 = solve(bearing, Loads(Fx=2e4), model="flexible", superelement=se)
    r2 = solve(bearing, Loads(Fx=2.02e4), model="flexible", superelement=se)
    k_secant = (2.02e4 - 2e4) / (r2.displacement[0] - r1.displacement[0])
    f1, f2 = load_on_moving_ring(bearing, r1)[0], load_on_moving_ring(bearing, r2)[0]
    assert (f2 - f1) / (r2.displacement[0] - r1.displacement[0]) == pytest.approx(k_secant, rel=1e-5)


def test_warm_started_solver_follows_rotation(table3_errors, table3_free):
    solver = BimeSolver(table3_errors.with_preload(10e-6), table3_free)
    previous = solver.solve(Loads(Fz=3e4))
    for psi in np.linspace(0.0, 0.2, 5):
        solver.set_rotation(psi)
        warm = solver.solve(Loads(Fz=3e4), initial=previous)
        cold = BimeSolver(table3_errors.with_preload(10e-6), table3_free, psi=psi).solve(Loads(Fz=3e4))
        assert np.allclose(warm.contact_load, cold.contact_load, rtol=1e-7, atol=1e-7 * cold.max_ball_load)
        previous = warm


@pytest.mark.parametrize("bc", ["free", "clamped"])
def test_structured_solver_equals_dense_newton_on_fe_rings(table3_errors, bc):
    # the dense Newton on all 5 + 8B unknowns of eq 20 (free rings: deformation kept orthogonal to
    # the rigid-body modes, the ring's rigid motion being q) is an independent check of the reduction
    from slewing_model.distribution.bime import solve_dense_newton

    se = build_superelement(table3_errors, mesh="coarse", bc=bc)
    bearing = table3_errors.with_preload(10e-6)
    loads = Loads(Fx=1e4, Fz=5e4, Mx=3e3, My=-2e3)
    r = BimeSolver(bearing, se).solve(loads)
    x, _ = solve_dense_newton(BimeSolver(bearing, se), loads)
    n = bearing.ball_count
    assert np.allclose(r.displacement, x[:5], rtol=1e-8, atol=1e-14)
    assert np.allclose(r.ring_displacement[:, [0, 3]].ravel(), x[5:5 + 4 * n], atol=1e-13)
    assert np.allclose(r.ring_displacement[:, [1, 2]].ravel(), x[5 + 4 * n:], atol=1e-13)


def test_flexible_gradient_and_hessian_match_finite_differences(table3_errors, table3_free):
    # eq 20 with both rings: all 5 + 8B unknowns, at a point where contacts are loaded
    solver = BimeSolver(table3_errors.with_preload(10e-6), table3_free)
    loads = Loads(Fx=5e3, Fz=2e4, My=1e3)
    r = solver.solve(loads)
    n = table3_errors.ball_count
    rng = np.random.default_rng(3)
    x = np.concatenate([r.displacement, r.ring_displacement[:, [0, 3]].ravel(), r.ring_displacement[:, [1, 2]].ravel()])
    x = x + rng.normal(size=x.size) * np.r_[np.full(3, 1e-7), np.full(2, 1e-7), np.full(8 * n, 1e-7)]
    u, g, h = solver.energy_terms(x, loads)
    picks = [0, 2, 3, 5, 6, 5 + 4 * n + 7, 5 + 8 * n - 1]
    for i in picks:
        step = 1e-10
        dx = np.zeros_like(x)
        dx[i] = step
        up, gp, _ = solver.energy_terms(x + dx, loads)
        um, gm, _ = solver.energy_terms(x - dx, loads)
        assert (up - um) / (2 * step) == pytest.approx(g[i], rel=1e-5, abs=1e-6 * np.abs(g).max())
        assert np.allclose((gp - gm) / (2 * step), h[:, i], rtol=1e-4, atol=1e-6 * np.abs(h).max())
    assert np.allclose(h, h.T)


def test_clamped_faces_load_the_contacts_next_to_them_under_a_moment(table1, table1_rings):
    """Under a pure moment a rigid bearing loads both diagonals alike and does not
    lift. With the outer ring clamped on its lower face and the inner ring on its upper face,
    contacts 4 and 2 (diagonal 2) sit next to the fixed faces and contacts 1 and 3 (diagonal 1)
    far from them: diagonal 2 is the stiffer one, so it carries more than the rigid value,
    diagonal 1 less, and the moving ring rises (+z), towards the softer diagonal 1's side. The
    faces swapped, everything turns over (a check that the coupling sees which face is fixed)."""
    from slewing_model.bearing.geometry import RingSection

    rigid = solve(table1, Loads(My=1e6))
    assert abs(rigid.displacement[2]) < 1e-12
    flexible = solve(table1, Loads(My=1e6), model="flexible", superelement=table1_rings["clamped"])
    q1, q4 = flexible.contact_load[:, 0].max(), flexible.contact_load[:, 3].max()
    assert q4 > rigid.contact_load[:, 3].max() and q1 < rigid.contact_load[:, 0].max()
    assert flexible.displacement[2] > 1e-3 * rigid.displacement[4] * table1.pitch_diameter / 2

    def swapped(s):
        return RingSection(s.inner_radius, s.outer_radius, s.height, "upper" if s.bolted_face == "lower" else "lower")

    turned = dataclasses.replace(table1, outer_section=swapped(table1.outer_section),
                                 inner_section=swapped(table1.inner_section))
    other = solve(turned, Loads(My=1e6), model="flexible", superelement=build_superelement(turned, "coarse", "clamped"))
    assert other.contact_load[:, 0].max() == pytest.approx(q4, rel=1e-6)
    assert other.contact_load[:, 3].max() == pytest.approx(q1, rel=1e-6)
    assert other.displacement[2] == pytest.approx(-flexible.displacement[2], rel=1e-6)
