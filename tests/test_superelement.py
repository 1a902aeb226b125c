"""Ring superelement: the harmonic FE model against closed-form ring theory, the
coupling's treatment of the Hertz part, and the properties of the condensed matrix.

Closed forms used (sources in each test):
* Lame's thick cylinder with free ends (Timoshenko & Goodier, *Theory of Elasticity*, 3rd ed.,
  sec. 28): for uniform pressure on the bore of a ring with free end faces, sigma_z = 0 and the
  plane-stress Lame solution with a uniform axial strain is the exact 3-D solution.
* Curved beams (thin ring of radius R): the energy of extension (EA), shear (kappa G A) and
  bending (EI) for in-plane deformation, and of transverse shear, torsion (GJ) and bending for
  out-of-plane deformation, minimised per harmonic (Cook & Young, *Advanced Mechanics of
  Materials*, ch. 6; inextensional limit E I (n^2 - 1)^2 / R^4, Timoshenko, *Strength of
  Materials* II; out-of-plane n^2 (n^2 - 1)^2 E I G J / (R^4 (E I + n^2 G J)), same source).
  Saint-Venant torsion constant of a rectangle (Timoshenko & Goodier sec. 109).
* Boussinesq half-space in Fourier form, ``u_hat = 2 (1 - nu^2) / (E |k|) p_hat`` (Johnson,
  *Contact Mechanics*, ch. 3).
"""
import dataclasses
import importlib.util
import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from skfem import Basis, ElementTriP1, Functional, MeshTri, asm

from slewing_model.rings.stiffness import Superelement, SuperelementMismatchError
from slewing_model.rings.superelement import build_superelement
from slewing_model.rings.superelement import coupling as cp
from slewing_model.rings.superelement.command import main as command_main
from slewing_model.rings.superelement.harmonic import HarmonicRingModel
from slewing_model.rings.superelement.section import mesh_section, rectangle_mesh, ring_profile

E, NU = 200e9, 0.3
G = E / (2 * (1 + NU))


# ---- the harmonic model against closed forms -----------------------------------------------

def test_axisymmetric_pressure_matches_lame_open_cylinder():
    a, b, h, p = 0.9, 1.1, 0.1, 1e6
    m = rectangle_mesh(a, b, h, 8, 4)
    model = HarmonicRingModel(m, E, NU)
    bore = m.facets_satisfying(lambda x: np.isclose(x[0], a), boundaries_only=True)
    f = model.facet_load(bore, lambda r, z: (p + 0 * r, 0 * r, 0 * r))
    u = model.solver(0, constraints=model.rigid_modes(0))(f)
    r, z = model.doflocs
    big_a, big_b = p * a * a / (b * b - a * a), p * a * a * b * b / (b * b - a * a)
    u_r = ((1 - NU) * big_a * r + (1 + NU) * big_b / r) / E          # Lame, sigma_z = 0
    radial = model.component == 0
    assert np.max(np.abs(u[radial] - u_r[radial])) < 0.02 * np.max(np.abs(u_r))
    axial = model.component == 2
    eps_z = np.polyfit(z[axial], u[axial], 1)[0]
    assert eps_z == pytest.approx(-2 * NU * big_a / E, rel=0.02)      # uniform axial strain


def _torsion_constant_rectangle(w, t):
    """Saint-Venant J of a w x t rectangle (series of Timoshenko & Goodier sec. 109)."""
    a, b = max(w, t), min(w, t)
    s = sum(np.tanh(k * np.pi * a / (2 * b)) / k**5 for k in range(1, 400, 2))
    return a * b**3 / 3 * (1 - 192 / np.pi**5 * (b / a) * s)


#: thin-ish ring for the curved-beam checks: R / h = 20, square 50 mm section
R, HR, HZ = 1.0, 0.05, 0.05
A = HR * HZ
KAPPA = 10 * (1 + NU) / (12 + 11 * NU)     # Cowper's shear coefficient of a rectangle


def _beam_stiffness(rows):
    """Load per unit length q over the displacement W of the harmonic: minimise the curved-beam
    energy sum_i k_i (v_i . x)^2 over the other unknowns of x = (W, ...)."""
    s = sum(k * np.outer(v, v) for k, v in rows)
    return 1.0 / np.linalg.inv(s)[0, 0]


def in_plane_beam(n, shear=True):
    # x = (W radial, V tangential, Psi rotation): eps = (nV + W)/R, gam = (nW + V)/R + Psi, chi = n Psi / R
    i = HZ * HR**3 / 12
    rows = [(E * A / R**2, np.array([1.0, n, 0.0])), (E * i / R**2, np.array([0.0, 0.0, n]))]
    rows.append((KAPPA * G * A if shear else 1e6 * E * A, np.array([n / R, 1 / R, 1.0])))
    return _beam_stiffness(rows)


def out_of_plane_beam(n):
    # x = (W axial, Psi bending rotation, Phi twist): gam = nW/R + Psi, tau = (Psi - n Phi)/R,
    # kappa = (n Psi - Phi)/R
    i, j = HR * HZ**3 / 12, _torsion_constant_rectangle(HR, HZ)
    return _beam_stiffness([(KAPPA * G * A, np.array([n / R, 1.0, 0.0])),
                            (G * j / R**2, np.array([0.0, 1.0, -n])),
                            (E * i / R**2, np.array([0.0, n, -1.0]))])


@pytest.fixture(scope="module")
def thin_ring():
    model = HarmonicRingModel(rectangle_mesh(R - HR / 2, R + HR / 2, HZ, 6, 6), E, NU)
    # body force q R / (A r) per unit volume: force per radian q R, no moment about the centroid;
    # its work-conjugate is the area mean of the displacement (the centroid's, in beam theory)
    radial = model.body_load(lambda r, z: (R / (A * r), 0 * r, 0 * r))
    axial = model.body_load(lambda r, z: (0 * r, 0 * r, R / (A * r)))
    return model, radial, axial


@pytest.mark.parametrize("n", range(2, 11))
def test_in_plane_ring_bending_matches_curved_beam_with_shear(thin_ring, n):
    model, radial, _ = thin_ring
    u = model.solver(n)(radial)
    k_fe = R / (radial @ u)
    assert k_fe == pytest.approx(in_plane_beam(n), rel=0.02)


def test_shear_correction_matters_at_the_higher_harmonics(thin_ring):
    """The shear-free (Euler-Bernoulli) beam is off by more than the 2 % tolerance at n = 10,
    so the previous test does check the shear term."""
    model, radial, _ = thin_ring
    k_fe = R / (radial @ model.solver(10)(radial))
    assert abs(in_plane_beam(10, shear=False) / k_fe - 1) > 0.04
    i = HZ * HR**3 / 12
    assert in_plane_beam(10, shear=False) == pytest.approx(E * i * 99**2 / R**4, rel=0.01)


@pytest.mark.parametrize("n", range(2, 11))
def test_out_of_plane_ring_bending_and_torsion_matches_curved_beam(thin_ring, n):
    model, _, axial = thin_ring
    u = model.solver(n)(axial)
    k_fe = R / (axial @ u)
    assert k_fe == pytest.approx(out_of_plane_beam(n), rel=0.02)


def test_out_of_plane_beam_reduces_to_the_classic_formula():
    """Check of the beam energy used above: without shear it is the textbook formula."""
    i, j = HR * HZ**3 / 12, _torsion_constant_rectangle(HR, HZ)
    for n in (2, 5):
        classic = n**2 * (n**2 - 1) ** 2 * E * i * G * j / (R**4 * (E * i + n**2 * G * j))
        rows = [(1e6 * E * A, np.array([n / R, 1.0, 0.0])), (G * j / R**2, np.array([0.0, 1.0, -n])),
                (E * i / R**2, np.array([0.0, n, -1.0]))]
        assert _beam_stiffness(rows) == pytest.approx(classic, rel=1e-4)


# ---- the coupling and the Hertz (half-space) part -------------------------------------------

def _graded(x0, x1, c, h0, g):
    pts, x = [c], c
    while x < x1:
        x += h0 + g * (x - c)
        pts.append(min(x, x1))
    x = c
    while x > x0:
        x -= h0 + g * (c - x)
        pts.append(max(x, x0))
    return np.unique(pts)


def test_halfspace_harmonic_compliance_matches_fe_on_a_flat_face():
    """A patch on the flat upper face of a thick ring: at high harmonics the FE response is local
    and must equal the Boussinesq half-space value of coupling.halfspace_harmonic."""
    rm, w, h, a, b = 0.75, 0.07, 0.09, 0.005, 0.0008
    h0 = 0.5e-3
    xr = _graded(rm - w / 2, rm + w / 2, rm, h0, 0.15)
    xr = np.unique(np.concatenate([xr[abs(xr - rm) > 0.3 * h0], [rm - a, rm + a]]))
    mesh = MeshTri.init_tensor(xr, _graded(-h / 2, h / 2, h / 2, h0, 0.15))
    model = HarmonicRingModel(mesh, E, NU)
    flat = 1e3     # a "groove" of huge radius: the pressure direction is +z everywhere on the patch
    patch = cp.Patch(1, np.array([rm, h / 2 - flat]), flat, np.pi / 2, a, b, rm)
    facets = mesh.facets_satisfying(lambda x: np.isclose(x[1], h / 2) & (abs(x[0] - rm) < a + 1e-9),
                                    boundaries_only=True)
    g = cp.basis_loads(model, facets, patch)
    ns = [150, 300]
    hs = cp.halfspace_harmonic(patch, ns, E, NU)
    for n, ref in zip(ns, hs):
        c = g.T @ model.solver(n)(g)
        assert c[0, 0] == pytest.approx(ref[0], rel=0.01)
        assert c[1, 1] == pytest.approx(ref[1], rel=0.01)
        assert abs(c[0, 1]) < 1e-3 * c[0, 0]     # even and odd pressures do not couple


def test_harmonic_sum_of_the_halfspace_compliance_is_the_self_compliance(table1):
    """Two independent evaluations of the half-space compliance of a row of patches: the mean over
    the ball harmonics of the aliasing sums of coupling.halfspace_harmonic (1-D integrals per
    harmonic) is the ball's own compliance, the 2-D integral of coupling.halfspace_self. This
    checks the harmonic normalisation (1/(2 pi), B/(2 pi), h_n) of the condensation."""
    from slewing_model.rings.superelement import condense as cd

    patch = cp.ring_patches(table1, "outer", [cp.patch_size(table1, 1)] * 2)[0]
    rows = cd.halfspace_periodic(patch, table1.ball_count, E, NU)
    own = cp.halfspace_self(patch, E, NU)
    np.testing.assert_allclose(rows.mean(axis=0), own, rtol=0.01)
    assert rows[0, 0] > own[0] > rows[table1.ball_count // 2, 0]    # neighbours add up at long waves only


def _normal_compliance(bearing, scale, n, subtract):
    """Per-harmonic compliance of contact 1 along its contact normal, coarse mesh."""
    from slewing_model.rings.superelement import condense as cd
    from slewing_model.rings.superelement.supports import Support

    sizes = [tuple(scale * x for x in cp.patch_size(bearing, c)) for c in (1, 4)]
    sm = mesh_section(ring_profile(bearing, "outer"), [s[0] for s in sizes], "coarse")
    model = HarmonicRingModel(sm.mesh, bearing.youngs_modulus, bearing.poisson_ratio)
    patches = cp.ring_patches(bearing, "outer", sizes)
    loads, lams = cp.master_loads(model, sm.patch_facets, patches)
    c = cd.harmonic_compliances(model, loads, [n], Support("free", model, sm.bolted_facets))[0]
    if subtract:
        c = c - cd.halfspace_blocks(patches, lams, [n], bearing.youngs_modulus, bearing.poisson_ratio)[0]
    t = np.array([np.cos(patches[0].psi), np.sin(patches[0].psi)])
    return t @ c[:2, :2] @ t


def test_removing_the_halfspace_part_removes_the_patch_size_dependence(table1):
    """The ring model loaded over a patch holds the local (Hertz) indentation of the patch, which
    grows as the patch shrinks; with the half-space part removed the compliance no longer
    depends on the patch size (the Hertz springs hold that part). Harmonic 20 of table1."""
    raw = [_normal_compliance(table1, s, 20, False) for s in (0.5, 2.0)]
    ring = [_normal_compliance(table1, s, 20, True) for s in (0.5, 2.0)]
    assert raw[0] / raw[1] - 1 > 0.10
    assert abs(ring[0] / ring[1] - 1) < 0.03


# ---- the condensed matrix ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("superelement-cache")


@pytest.fixture(scope="module")
def free_se(table3, cache):
    return build_superelement(table3, "coarse", "free", cache_dir=cache)


@pytest.fixture(scope="module")
def supported_se(table3, cache):
    return build_superelement(table3, "coarse", {"outer": "clamped", "inner": "frictionless"}, cache_dir=cache)


def rigid_patterns(bearing, ring):
    """Groove-centre displacement patterns (4B,) of X, Y, Z, rx, ry (small rotations)."""
    ca, cb = (1, 4) if ring == "outer" else (2, 3)
    (ra, za), (rb, zb) = bearing.groove_centres[ca - 1], bearing.groove_centres[cb - 1]
    phi = bearing.ball_angles
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    t = np.array([1.0, 0.0, 1.0, 0.0])
    tilt = np.array([za, -ra, zb, -rb])          # rotation about y: u_r = z cos, u_z = -r cos
    return {"X": (c * t).ravel(), "Y": (s * t).ravel(), "Z": np.tile([0.0, 1.0, 0.0, 1.0], len(phi)),
            "rx": (-s * tilt).ravel(), "ry": (c * tilt).ravel()}


@pytest.mark.parametrize("ring", ["outer", "inner"])
def test_free_ring_is_symmetric_psd_with_exactly_the_rigid_body_null_space(free_se, table3, ring):
    k = free_se.ring(ring)
    assert k.removed_modes == ("X", "Y", "Z", "rx", "ry")
    kd = k.dense()
    assert np.abs(kd - kd.T).max() <= 1e-12 * np.abs(kd).max()
    w = np.linalg.eigvalsh(kd)
    top = w.max()
    assert np.sum(np.abs(w) < 1e-9 * top) == 5            # null space of dimension 5
    assert w.min() > -1e-9 * top                           # positive semi-definite
    assert np.sort(w)[5] > 1e-7 * top                      # and nothing else nearly singular
    for name, d in rigid_patterns(table3, ring).items():
        assert np.linalg.norm(kd @ d) < 1e-9 * top * np.linalg.norm(d), name


@pytest.mark.parametrize("ring", ["outer", "inner"])
def test_supported_rings_are_positive_definite(supported_se, ring):
    k = supported_se.ring(ring)
    assert k.removed_modes == ()
    w = np.linalg.eigvalsh(k.dense())
    assert w.min() > 1e-7 * w.max()
    meta = supported_se.metadata["rings"][ring]
    assert meta["boundary_condition"] == {"outer": "clamped", "inner": "frictionless"}[ring]
    assert "Z, rx, ry" in meta["support_removes"] or "X, Y, Z" in meta["support_removes"]


def test_support_stiffens_the_ring(free_se, supported_se, table3):
    """Clamping the bolted face raises the stiffness of the ovalisation pattern (harmonic 2)."""
    d = np.tile([1.0, 0.0, 1.0, 0.0], table3.ball_count) * np.repeat(np.cos(2 * table3.ball_angles), 4)
    assert supported_se.outer.energy(d) > 1.05 * free_se.outer.energy(d)


def test_matrix_is_block_circulant(free_se, table3):
    k = free_se.outer
    kd = k.dense()
    B = table3.ball_count
    shift = np.roll(np.eye(4 * B), 4, axis=0)           # moves every ball on by one
    np.testing.assert_allclose(shift @ kd @ shift.T, kd, atol=1e-9 * np.abs(kd).max())
    blocks = k.harmonic_blocks()
    assert np.abs(blocks.imag).max() < 1e-9 * np.abs(blocks.real).max()
    np.testing.assert_allclose(blocks[1:].real, blocks[1:][::-1].real, atol=1e-9 * np.abs(blocks).max())


def _section_properties(bearing, ring):
    prof = ring_profile(bearing, ring)
    sm = mesh_section(prof, [cp.patch_size(bearing, c)[0] for c in ((1, 4) if ring == "outer" else (2, 3))],
                      "fine")
    basis = Basis(sm.mesh, ElementTriP1(), intorder=4)
    area = asm(Functional(lambda w: 1.0 + 0 * w.x[0]), basis)
    rc = asm(Functional(lambda w: w.x[0]), basis) / area
    inertia = asm(Functional(lambda w: (w.x[0] - rc) ** 2), basis)
    return area, rc, inertia


@pytest.mark.parametrize("ring", ["outer", "inner"])
@pytest.mark.parametrize("n", [2, 3])
def test_condensed_ovalisation_matches_curved_beam_of_the_grooved_section(free_se, table3, ring, n):
    """End to end: radial forces f cos(n phi_b) on both groove centres of every ball; the
    condensed matrix gives the radial displacement of the groove centres, the curved beam
    (extension, shear, bending; section properties of the grooved section) the centroid's.
    At low n the ring bends as a beam (table3 is a thick ring, R/w = 6.6: from n = 4 on the
    section distorts and the beam no longer applies)."""
    area, rc, inertia = _section_properties(table3, ring)
    rows = [(E * area / rc**2, np.array([1.0, n, 0.0])), (5 / 6 * G * area, np.array([n / rc, 1 / rc, 1.0])),
            (E * inertia / rc**2, np.array([0.0, 0.0, n]))]
    k_beam = _beam_stiffness(rows)
    B = table3.ball_count
    per_radian = B * 2 / (2 * np.pi)                      # radial force per radian for f = 1 N
    w_beam = per_radian / rc / k_beam
    d = np.linalg.solve(free_se.ring(ring).harmonic_blocks()[n].real, [1.0, 0.0, 1.0, 0.0])
    assert d[0] == pytest.approx(w_beam, rel=0.02)
    assert d[2] == pytest.approx(d[0], rel=1e-6)


# ---- storage, cache, metadata, command ------------------------------------------------------

def test_metadata_states_the_inputs_and_the_removed_modes(free_se, table3):
    from slewing_model.rings.stiffness import bearing_hash

    m = free_se.metadata
    assert m["bearing_hash"] == bearing_hash(table3)
    assert m["mesh"]["name"] == "coarse" and m["boundary_conditions"] == {"outer": "free", "inner": "free"}
    assert m["rings"]["outer"]["removed_modes"] == ["X", "Y", "Z", "rx", "ry"]
    assert m["rings"]["outer"]["harmonics"] >= 2 * 2
    assert m["options"]["reference_pressure"] > 0 and "software_version" in m and "input_hash" in m
    assert m["rings"]["outer"]["truncation_change"] < 0.01


def test_second_build_comes_from_the_cache(table3, cache, free_se):
    t0 = time.perf_counter()
    again = build_superelement(table3, "coarse", "free", cache_dir=cache)
    assert time.perf_counter() - t0 < 0.5
    assert again.metadata["cache"]["hit"]
    np.testing.assert_array_equal(again.outer.first_row, free_se.outer.first_row)
    other = build_superelement(table3, "coarse", "free", cache_dir=cache, harmonics=20)
    assert not other.metadata["cache"]["hit"]


def test_a_file_is_refused_for_another_bearing(free_se, table3, tmp_path):
    path = tmp_path / "t3.npz"
    free_se.save(path)
    assert Superelement.load(path, table3.with_preload(10e-6)).outer.ball_count == table3.ball_count
    with pytest.raises(SuperelementMismatchError, match="ball_count"):
        Superelement.load(path, dataclasses.replace(table3, ball_count=60))


def test_bad_options_are_refused(table3, cache):
    with pytest.raises(ValueError, match="bc"):
        build_superelement(table3, "coarse", "glued", cache_dir=cache)
    with pytest.raises(ValueError, match="mesh"):
        build_superelement(table3, "medium", "free", cache_dir=cache)
    with pytest.raises(TypeError, match="patch_sclae"):
        build_superelement(table3, "coarse", "free", cache_dir=cache, patch_sclae=2)


def test_command_writes_the_file_and_prints_a_summary(tmp_path, cache, capsys):
    from conftest import BEARINGS

    out = tmp_path / "se.npz"
    status = command_main([str(BEARINGS / "table3.toml"), "--mesh", "coarse", "--bc", "free", "-o", str(out),
                           "--cache-dir", str(cache), "--quiet"])
    assert status == 0 and out.exists()
    text = capsys.readouterr().out
    assert "B = 67" in text and "X,Y,Z,rx,ry" in text and "time" in text
    assert Superelement.load(out).outer.ball_count == 67
    assert command_main([str(tmp_path / "missing.toml"), "-o", str(out), "--quiet"]) == 2


def test_fine_section_mesh_is_built_without_scikit_fem_warnings(caplog):
    """The yaw bearing's fine outer-ring mesh has over 1000 elements: scikit-fem logged
    "Transforming over 1000 elements to C_CONTIGUOUS." for it (a stray line in the yaw
    example's output) when given the element table transposed."""
    import logging

    from slewing_model import load_bearing

    from pathlib import Path

    bearing = load_bearing(Path(__file__).resolve().parents[1] / "examples" / "bearings" / "yaw_bearing.toml")
    with caplog.at_level(logging.DEBUG, logger="skfem"):
        meshes = [mesh_section(ring_profile(bearing, ring), [cp.patch_size(bearing, c)[0] for c in contacts], "fine")
                  for ring, contacts in (("outer", (1, 4)), ("inner", (2, 3)))]
    assert max(sm.mesh.t.shape[1] for sm in meshes) > 1000
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []
    assert all(sm.mesh.t.flags["C_CONTIGUOUS"] and sm.mesh.p.flags["C_CONTIGUOUS"] for sm in meshes)

# ---- the clamped face ------------------------------------------------------------------------

def test_long_wave_halfspace_subtraction_is_given_back_exactly_for_a_clamped_ring(table3, monkeypatch):
    """The 2-D half-space compliance of a row of patches diverges at n = 0; the condensation
    subtracts a stand-in there (the n = 1 value) and gives the row's excess over each ball's own
    compliance back per ball harmonic (condense.halfspace_addback). Whatever is subtracted at
    n = 0 and given back at j = 0 must cancel: the stand-in is a choice, not physics. Next to a
    clamped face the ring holds less than the row's long-wave half-space compliance, so
    ``c_0 - c_0^HS`` has negative directions; projecting them away per harmonic, before the
    give-back, gave that compliance back twice (the stiffness of ball harmonic 0 moved by 15 %
    of its largest entry when the stand-in was doubled). Here the stand-in is doubled and the
    same amount given back."""
    from slewing_model.rings.superelement import build as bd
    from slewing_model.rings.superelement import condense as cd
    from slewing_model.rings.superelement.section import MESH_PRESETS

    B = table3.ball_count
    h = bd.ring_harmonics(table3, "outer", MESH_PRESETS["coarse"], "clamped",
                          bd.auto_harmonics(table3, "outer", 12.0), bd.DEFAULT_OPTIONS)
    assert np.linalg.eigvalsh(h.c_fe[0] - h.c_hs[0]).min() < 0      # the case that matters is here
    ref = bd.condense_ring(h, B)[0].harmonic_blocks()[0].real
    extra = h.c_hs[0].copy()
    c_hs2 = h.c_hs.copy()
    c_hs2[0] += extra                                    # subtract the stand-in twice at n = 0 ...
    addback = cd.halfspace_addback

    def more_back(*args):                                # ... and give the same back at j = 0 (h_0 = 1)
        back = addback(*args).copy()
        back[0] += B / (2 * np.pi) * extra
        return back

    monkeypatch.setattr(cd, "halfspace_addback", more_back)
    other = bd.condense_ring(dataclasses.replace(h, c_hs=c_hs2), B)[0].harmonic_blocks()[0].real
    np.testing.assert_allclose(other, ref, rtol=0, atol=1e-9 * np.abs(ref).max())


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (Debian's calculix-ccx) is not installed")
@pytest.mark.parametrize("ring", ["outer", "inner"])
def test_clamped_face_matches_a_3d_calculix_solid(table3, ring, tmp_path):
    """The clamped ring's n = 0 compliance at the groove centres against an independent 3-D solid:
    the same section swept into quadratic wedges (C3D15) over a thin sector, the face found from
    the node coordinates with all three displacements fixed, CalculiX's solve
    (references/calculix/clamped_face/harmonic_vs_ccx.py; n = 1 on half a ring, slower, there)."""
    spec = importlib.util.spec_from_file_location(
        "harmonic_vs_ccx", Path(__file__).parents[1] / "references" / "calculix" / "clamped_face" / "harmonic_vs_ccx.py")
    ref = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ref)
    result, patches = ref.compare(table3, ring, "coarse", sector=0.5, work=str(tmp_path))
    c_harmonic, c_3d = result[0]
    np.testing.assert_allclose(c_3d, c_harmonic, rtol=0, atol=1e-4 * np.abs(c_harmonic).max())
    for k, patch in enumerate(patches):                  # along each contact normal, the smaller entries
        nrm = np.zeros(4)
        nrm[2 * k:2 * k + 2] = np.cos(patch.psi), np.sin(patch.psi)
        assert nrm @ c_3d @ nrm == pytest.approx(nrm @ c_harmonic @ nrm, rel=1e-3)
