"""Connected structures condensed into the superelement (docs/guide/connected-structures.md).

The limits are checked against the superelement's own idealisations, which were built and
verified independently (tests/test_superelement.py): a very stiff adapter must give the clamped
face, a vanishing one the free ring, a steel tube something in between. The imported matrix is
checked by a round trip through files (the parametric adapter's face stiffness exported as a
Cartesian matrix on face nodes, written, read, projected back) and by refusals of bad input.

Every build here uses few harmonics (``N``): the limits hold at any N and the builds stay quick.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from slewing_model import BearingDefinitionError, Bearing, load_bearing
from slewing_model.bearing.connection import Adapter
from slewing_model.distribution.bime import Loads, solve
from slewing_model.rings.stiffness import Superelement, SuperelementMismatchError, bearing_hash
from slewing_model.rings.superelement import build_superelement

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = (ROOT / "examples" / "bearings" / "table1.toml").read_text()
N = 24
STEEL = 210e9


def _tube(bearing, ring="outer", modulus=STEEL, length=0.3, radii=None):
    s = bearing.outer_section if ring == "outer" else bearing.inner_section
    ri, ro = radii or (s.inner_radius, s.outer_radius)
    return Adapter(ring, "tube", ri, ro, length, "far_end", modulus, modulus, modulus, modulus / 2.6, 0.3)


def _build(bearing, bc, harmonics=N):
    return build_superelement(bearing, mesh="coarse", bc=bc, cache=False, harmonics=harmonics)


@pytest.fixture(scope="module")
def builds(table1):
    return {
        "free": _build(table1, "free"),
        "clamped": _build(table1, "clamped"),
        # outer ring bolted to a tube 1e4 times stiffer than steel, the inner ring clamped
        "stiff": _build(table1.with_connection({"outer": _tube(table1, modulus=1e4 * STEEL)}), "clamped"),
        # outer ring bolted to a tube 1e-6 times as stiff as steel, the inner ring free
        "soft": _build(table1.with_connection({"outer": _tube(table1, modulus=1e-6 * STEEL)}), "free"),
        # a steel tube, 300 mm long, on the outer ring, and the inner ring clamped
        "steel": _build(table1.with_connection({"outer": _tube(table1)}), "clamped"),
    }


def _rigid_patterns(bearing, j):
    """Rigid-body patterns of the outer ring's (R1, z1, R4, z4) in ball harmonic j, from the
    groove-centre coordinates: Z at j = 0; X and the tilt at j = 1."""
    (r1, z1), (r4, z4) = bearing.groove_centres[0], bearing.groove_centres[3]
    if j == 0:
        return np.array([[0.0, 1.0, 0.0, 1.0]]).T
    if j == 1:
        return np.array([[1.0, 0.0, 1.0, 0.0], [z1, -r1, z4, -r4]]).T
    return np.zeros((4, 0))


def _complement(r):
    if r.shape[1] == 0:
        return np.eye(4)
    return np.linalg.qr(r, mode="complete")[0][:, r.shape[1]:]


def test_a_very_stiff_tube_reproduces_the_clamped_face(builds):
    """Compliance of every ball harmonic of the outer ring, stiff tube against clamped face."""
    stiff = builds["stiff"].outer.harmonic_blocks().real
    clamped = builds["clamped"].outer.harmonic_blocks().real
    worst = max(np.linalg.norm(np.linalg.inv(s) - np.linalg.inv(c)) / np.linalg.norm(np.linalg.inv(c))
                for s, c in zip(stiff, clamped))
    assert worst < 0.01, worst
    assert builds["stiff"].outer.removed_modes == ()
    assert builds["stiff"].metadata["boundary_conditions"] == {"outer": "connected", "inner": "clamped"}
    # the inner ring, not connected, is the clamped ring itself
    np.testing.assert_allclose(builds["stiff"].inner.first_row, builds["clamped"].inner.first_row, rtol=1e-9,
                               atol=1e-9 * np.abs(builds["clamped"].inner.first_row).max())


def test_a_vanishing_tube_gives_back_the_free_ring(table1, builds):
    """On the complement of the rigid-body modes (which the free ring does not resist and the
    vanishing tube barely does) the stiffness blocks agree with the free ring's."""
    soft = builds["soft"].outer.harmonic_blocks().real
    free = builds["free"].outer.harmonic_blocks().real
    B = table1.ball_count
    worst = 0.0
    for j in range(B):
        q = _complement(_rigid_patterns(table1, min(j, B - j)))
        a, b = q.T @ soft[j] @ q, q.T @ free[j] @ q
        worst = max(worst, np.linalg.norm(a - b) / np.linalg.norm(b))
    assert worst < 0.01, worst
    # and the rigid-body modes carry (almost) no stiffness
    for j in (0, 1):
        r = _rigid_patterns(table1, j)
        r = r / np.linalg.norm(r, axis=0)
        assert np.abs(r.T @ soft[j] @ r).max() < 1e-4 * np.abs(free[2]).max()


def test_a_steel_tube_lies_between_free_and_clamped(builds):
    """Ball harmonic 2 (ovalisation), compliance along the R1 + R4 pattern: free > steel tube > clamped,
    and the tube is not a negligible change from the clamped face (> 10 %)."""
    d = np.array([1.0, 0.0, 1.0, 0.0])

    def compliance(se, j=2):
        block = se.outer.harmonic_blocks().real[j]
        return d @ np.linalg.solve(block, d)

    clamped, steel = compliance(builds["clamped"]), compliance(builds["steel"])
    q = _complement(np.zeros((4, 0)))
    free = d @ np.linalg.pinv(q.T @ builds["free"].outer.harmonic_blocks().real[2] @ q) @ d
    assert clamped * 1.1 < steel < free


def test_load_distribution_limits(table1, builds):
    """Peak ball load under a tilting moment: the stiff tube gives the clamped value within 0.5 %, a
    steel tube a value between the free and the clamped rings'. (The vanishing tube is not solved:
    it leaves the fixed ring floating, held by almost nothing; the free ring's model instead takes
    its rigid-body motion out exactly. Its limit is the superelement test above.)"""
    loads = Loads(0.0, 0.0, 300e3, 0.0, 400e3)
    q = {k: solve(table1.with_connection(None), loads, model="flexible", superelement=builds[k]).max_ball_load
         for k in ("free", "clamped", "stiff", "steel")}
    assert abs(q["stiff"] / q["clamped"] - 1) < 0.005, q
    assert abs(q["free"] / q["clamped"] - 1) > 0.02, q          # the limits are apart: the test can fail
    assert min(q["free"], q["clamped"]) < q["steel"] < max(q["free"], q["clamped"]), q


# ---- the bearing file table ---------------------------------------------------------------------

TUBE = """
[connection.outer]
type = "tube"
inner_diameter_mm = 1510.0
outer_diameter_mm = 1630.0
length_mm = 500.0
axial_modulus_gpa = 40.0
hoop_modulus_gpa = 15.0
shear_modulus_gpa = 5.0
poisson_ratio = 0.3
"""


def _load(tmp_path, text):
    path = tmp_path / "b.toml"
    path.write_text(TABLE1 + text)
    return load_bearing(path)


def test_tube_table_is_read_in_si(tmp_path):
    b = _load(tmp_path, TUBE)
    a = b.connection["outer"]
    assert (a.kind, a.clamped_edge) == ("tube", "far_end")
    assert a.inner_radius == pytest.approx(0.755) and a.outer_radius == pytest.approx(0.815)
    assert a.length == pytest.approx(0.5)
    assert (a.axial_modulus, a.hoop_modulus, a.radial_modulus, a.shear_modulus) == pytest.approx(
        (40e9, 15e9, 15e9, 5e9))
    # its D: the inverse of the stated compliance (axial strain of an axial stress 1/Ez, hoop -nu/Ez)
    s = np.linalg.inv(a.elasticity()[:3, :3])
    assert s[2, 2] == pytest.approx(1 / 40e9) and s[1, 2] == pytest.approx(-0.3 / 40e9)
    # the SI form round-trips, and so does the superelement key
    back = Bearing.from_si_dict(b.to_dict())
    assert back.connection == b.connection
    assert bearing_hash(back) == bearing_hash(b)


def test_isotropic_material_reduces_to_lame(tmp_path):
    b = _load(tmp_path, """
[connection.inner]
type = "plate"
inner_diameter_mm = 1300.0
outer_diameter_mm = 1480.0
thickness_mm = 60.0
clamped_edge = "inner"
youngs_modulus_gpa = 170.0
poisson_ratio = 0.25
""")
    p = b.connection["inner"]
    e, nu = 170e9, 0.25
    lam, mu = e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))
    d = p.elasticity()
    np.testing.assert_allclose(d[:3, :3], lam + 2 * mu * np.eye(3), rtol=1e-12)
    np.testing.assert_allclose(np.diag(d)[3:], mu, rtol=1e-12)


@pytest.mark.parametrize("text, key, rule", [
    (TUBE + "length = 3.0\n", "connection.outer.length", "unknown key in table [connection.outer]"),
    (TUBE.replace('type = "tube"', 'type = "pipe"'), "connection.outer.type", "must be one of 'tube', 'plate'"),
    (TUBE.replace("length_mm = 500.0\n", ""), "[connection.outer]", "missing key `length_mm`"),
    (TUBE.replace("length_mm = 500.0", "length_mm = -5.0"), "connection.outer.length_mm", "must be > 0"),
    (TUBE.replace("inner_diameter_mm = 1510.0", "inner_diameter_mm = 1700.0").replace("1630.0", "1800.0"),
     "connection.outer.inner_diameter_mm", "must overlap the outer ring's bolted face"),
    (TUBE + "youngs_modulus_gpa = 200.0\n", "connection.outer.axial_modulus_gpa", "not both"),
    (TUBE.replace("poisson_ratio = 0.3", "poisson_ratio = 0.9"), "connection.outer.poisson_ratio",
     "not positive definite"),
    ("\n[connection]\nouter_ring = 1\n", "connection.outer_ring", "unknown key in table [connection]"),
    ("\n[connection.outer]\ntype = \"plate\"\ninner_diameter_mm = 1510.0\nouter_diameter_mm = 1700.0\n"
     "thickness_mm = 50.0\nyoungs_modulus_gpa = 200.0\npoisson_ratio = 0.3\n",
     "[connection.outer]", "missing key `clamped_edge`"),
    ("\n[connection.outer]\ntype = \"matrix\"\nformat = \"calculix\"\nfile = \"nothere.mtx\"\n"
     "nodes_csv = \"n.csv\"\nstiffness_unit = \"N/mm\"\n", "connection.outer.file", "no such file"),
    ("\n[connection.outer]\ntype = \"matrix\"\nformat = \"abaqus\"\n", "connection.outer.format",
     "must be one of 'calculix', 'matrix_market'"),
])
def test_connection_table_refuses_bad_input_naming_key_and_rule(tmp_path, text, key, rule):
    with pytest.raises(BearingDefinitionError) as info:
        _load(tmp_path, text)
    message = str(info.value)
    assert key in message and rule in message, message


def test_unknown_key_message_lists_the_known_keys(tmp_path):
    with pytest.raises(BearingDefinitionError) as info:
        _load(tmp_path, TUBE + "wall_mm = 3\n")
    for known in ("inner_diameter_mm", "outer_diameter_mm", "length_mm", "axial_modulus_gpa", "hoop_modulus_gpa",
                  "shear_modulus_gpa", "poisson_ratio", "youngs_modulus_gpa"):
        assert known in str(info.value)


# ---- cache key ----------------------------------------------------------------------------------

def test_the_superelement_key_holds_the_connection(table1, builds):
    plain = table1.with_connection(None)
    tube = table1.with_connection({"outer": _tube(table1)})
    longer = table1.with_connection({"outer": _tube(table1, length=0.6)})
    assert "connection" not in plain.to_dict()          # unconnected bearings keep their hash
    assert len({bearing_hash(plain), bearing_hash(tube), bearing_hash(longer)}) == 3
    with pytest.raises(SuperelementMismatchError, match="connection"):
        builds["free"].check(tube)
    builds["steel"].check(tube)                          # built for it
    with pytest.raises(SuperelementMismatchError, match="connection"):
        builds["steel"].check(longer)


def test_cache_hit_and_miss_follow_the_connection(table1, tmp_path):
    tube = table1.with_connection({"outer": _tube(table1, modulus=STEEL)})
    first = build_superelement(tube, mesh="coarse", bc="free", harmonics=8, cache_dir=tmp_path)
    again = build_superelement(tube, mesh="coarse", bc="free", harmonics=8, cache_dir=tmp_path)
    assert again.metadata["cache"]["hit"] and not first.metadata["cache"]["hit"]
    np.testing.assert_array_equal(first.outer.first_row, again.outer.first_row)
    other = table1.with_connection({"outer": _tube(table1, modulus=2 * STEEL)})
    assert not build_superelement(other, mesh="coarse", bc="free", harmonics=8, cache_dir=tmp_path).metadata[
        "cache"]["hit"]
    path = tmp_path / "se.npz"
    first.save(path)
    Superelement.load(path, tube)
    with pytest.raises(SuperelementMismatchError):
        Superelement.load(path, other)


# ---- imported matrices --------------------------------------------------------------------------

NI = 12          # harmonics of the round trip: its nodes sit at 2 NI + 2 angles


def _matrix_table(fmt, unit="N/m", file="k.mtx", nodes="nodes.csv"):
    return (f'\n[connection.outer]\ntype = "matrix"\nformat = "{fmt}"\nfile = "{file}"\nnodes_csv = "{nodes}"\n'
            f'stiffness_unit = "{unit}"\n')


@pytest.mark.parametrize("fmt", ["calculix", "matrix_market"])
def test_imported_matrix_of_an_adapter_gives_the_parametric_superelement(table1, tmp_path, fmt):
    """A steel tube narrower than the face (the bolted annulus is part of the face): its face
    stiffness exported as a Cartesian matrix on face nodes, written (CalculiX in N/mm, Matrix Market
    in N/m), read back through a bearing file and projected onto the harmonics gives the
    parametric superelement within 1 % (compliance of every ball harmonic)."""
    from slewing_model.rings.superelement.adapters import ring_face_stiffness
    from slewing_model.rings.superelement.imported import (export_face_stiffness, write_calculix,
                                                           write_matrix_market, write_nodes)

    tube = _tube(table1, radii=(0.760, 0.805))
    parametric = _build(table1.with_connection({"outer": tube}), "free", harmonics=NI)
    ids, xyz, k = export_face_stiffness(ring_face_stiffness(table1, "outer", tube, mesh="coarse"), NI)
    write_nodes(tmp_path / "nodes.csv", ids, xyz)
    if fmt == "calculix":
        write_calculix(tmp_path / "k.mtx", ids, k / 1e3)
        unit = "N/mm"
    else:
        write_matrix_market(tmp_path / "k.mtx", k)
        unit = "N/m"
    bearing = _load(tmp_path, _matrix_table(fmt, unit))
    imported = _build(bearing, "free", harmonics=NI)
    a = parametric.outer.harmonic_blocks().real
    b = imported.outer.harmonic_blocks().real
    worst = max(np.linalg.norm(np.linalg.inv(x) - np.linalg.inv(y)) / np.linalg.norm(np.linalg.inv(x))
                for x, y in zip(a, b))
    assert worst < 0.01, worst
    assert imported.metadata["boundary_conditions"]["outer"] == "connected"


def _small_face_set(table1, tmp_path, dz=0.0):
    """Four nodes on the outer ring's lower face (r = 790 mm, every 90 deg), one of them ``dz`` off it."""
    z = -table1.outer_section.height / 2
    xyz = np.array([[0.79, 0, z + dz], [0, 0.79, z], [-0.79, 0, z], [0, -0.79, z]])
    from slewing_model.rings.superelement.imported import write_nodes

    write_nodes(tmp_path / "nodes.csv", np.arange(1, 5), xyz)


def _write_lines(path, k, both=False):
    with open(path, "w") as fh:
        for i in range(len(k)):
            for j in range(len(k)) if both else range(i, len(k)):
                if k[i, j] != 0:
                    fh.write(f"{i // 3 + 1},{i % 3 + 1},{j // 3 + 1},{j % 3 + 1},{float(k[i, j])!r}\n")


@pytest.mark.parametrize("case, message", [
    ("asymmetric", "the matrix is not symmetric: entry (node 1 dof 1, node 2 dof 3)"),
    ("indefinite", "the matrix is not positive semi-definite: smallest eigenvalue -2e+08"),
    ("off_face", "node 1 at (x, y, z) = (790.000, 0.000, -38.750) mm (r = 790.000 mm) does not lie on the outer "
                 "ring's bolted face (lower face, z = -43.750 mm"),
    ("coarse_nodes", "its 4 nodes resolve harmonics up to 1"),
])
def test_a_bad_imported_matrix_is_refused_with_its_message(table1, tmp_path, case, message):
    from slewing_model.rings.superelement.imported import ImportedMatrixError

    _small_face_set(table1, tmp_path, dz=5e-3 if case == "off_face" else 0.0)
    k = 1e9 * np.eye(12)
    if case == "asymmetric":
        k[0, 5], k[5, 0] = 1e8, 3e8
    if case == "indefinite":
        k[0, 0], k[0, 3], k[3, 0], k[3, 3] = 1e8, 3e8, 3e8, 1e8       # eigenvalues 4e8 and -2e8
    _write_lines(tmp_path / "k.mtx", k, both=case == "asymmetric")
    bearing = _load(tmp_path, _matrix_table("calculix"))
    with pytest.raises(ImportedMatrixError) as info:
        _build(bearing, "free", harmonics=8)
    assert message in str(info.value), str(info.value)
    assert "k.mtx" in str(info.value) or "nodes.csv" in str(info.value)


def test_a_matrix_market_file_of_the_wrong_size_is_refused(table1, tmp_path):
    from slewing_model.rings.superelement.imported import ImportedMatrixError, write_matrix_market

    _small_face_set(table1, tmp_path)
    write_matrix_market(tmp_path / "k.mtx", np.eye(9))
    with pytest.raises(ImportedMatrixError, match="a 9 x 9 matrix: the nodes file has 4 nodes, so it must be 12 x 12"):
        _build(_load(tmp_path, _matrix_table("matrix_market")), "free", harmonics=8)


# ---- where the user says it: the CLI and the FMU read the connection through the bearing file ----

def test_superelement_and_solve_commands_read_the_connection(tmp_path):
    """``slewing superelement`` builds the connected superelement from the file alone; ``slewing
    solve --superelement`` accepts it for that file and refuses it for the unconnected one."""
    path = tmp_path / "tube.toml"
    path.write_text(TABLE1 + TUBE)
    out = tmp_path / "se.npz"
    cmd = [sys.executable, "-m", "slewing_model.cli"]
    run = subprocess.run(cmd + ["superelement", str(path), "--harmonics", "8", "--quiet", "-o", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    assert "connected" in run.stdout
    se = Superelement.load(out, load_bearing(path))
    assert se.outer.boundary_condition == "connected" and se.inner.boundary_condition == "free"
    assert se.metadata["rings"]["outer"]["connection"]["kind"] == "tube"
    run = subprocess.run(cmd + ["solve", str(path), "--fz", "200000", "--superelement", str(out), "--json"],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    plain = tmp_path / "plain.toml"
    plain.write_text(TABLE1)
    run = subprocess.run(cmd + ["solve", str(plain), "--fz", "200000", "--superelement", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode != 0 and "connection" in run.stderr


def test_the_fmu_reads_the_connection_back_from_its_bearing_json(tmp_path, builds, table1):
    """build_fmu.py packs ``bearing.to_dict()`` as JSON and the superelement; the FMU restores the
    bearing with ``Bearing.from_si_dict`` and loads the superelement against it: a connected
    bearing survives that trip (also with an imported matrix, whose files the FMU does not need)."""
    import json

    tube = table1.with_connection({"outer": _tube(table1)})
    back = Bearing.from_si_dict(json.loads(json.dumps(tube.to_dict())))
    assert back.connection == tube.connection
    builds["steel"].save(tmp_path / "se.npz")
    Superelement.load(tmp_path / "se.npz", back)
    _small_face_set(table1, tmp_path)
    _write_lines(tmp_path / "k.mtx", 1e9 * np.eye(12))
    imported = _load(tmp_path, _matrix_table("calculix"))
    (tmp_path / "k.mtx").unlink()
    again = Bearing.from_si_dict(json.loads(json.dumps(imported.to_dict())))
    assert again.connection == imported.connection and bearing_hash(again) == bearing_hash(imported)


# ---- the adapter's own model against closed forms -----------------------------------------------

def test_orthotropic_model_with_isotropic_constants_is_the_ring_model():
    """The general-D assembly against the ring model's own (Lame) assembly, same mesh: K0, K1, K2 equal."""
    from slewing_model.bearing.connection import elasticity
    from slewing_model.rings.superelement.adapters import OrthotropicHarmonicModel
    from slewing_model.rings.superelement.harmonic import HarmonicRingModel
    from slewing_model.rings.superelement.section import rectangle_mesh

    mesh = rectangle_mesh(0.9, 1.1, 0.2, 3, 3)
    e, nu = 200e9, 0.3
    a = HarmonicRingModel(mesh, e, nu)
    b = OrthotropicHarmonicModel(mesh, elasticity(e, e, e, e / (2 * (1 + nu)), nu))
    for ka, kb in ((a.K0, b.K0), (a.K1, b.K1), (a.K2, b.K2)):
        assert abs(ka - kb).max() < 1e-10 * abs(ka).max()


@pytest.mark.parametrize("field, expected", [
    # uniform axial displacement of the face: E_z pi (ro^2 - ri^2) / L (nu = 0: no end effect)
    ("axial", lambda ri, ro, L, ez, g: ez * np.pi * (ro**2 - ri**2) / L),
    # rotation of the face about the axis (V = r): torque per radian G J / L, J = pi (ro^4 - ri^4) / 2
    ("torsion", lambda ri, ro, L, ez, g: g * np.pi * (ro**4 - ri**4) / 2 / L),
])
def test_tube_face_stiffness_against_closed_forms(table1, field, expected):
    """An orthotropic tube (axial 40 GPa, hoop 12 GPa, shear 4 GPa, nu = 0) on the outer ring's
    face, harmonic 0: the face stiffness of a rigid axial pull and of a rigid twist of the face is
    the bar's and the shaft's closed form (both fields are exact in the quadratic elements)."""
    from slewing_model.rings.superelement.adapters import ring_face_stiffness

    s = table1.outer_section
    ri, ro, L, ez, g = s.inner_radius, s.outer_radius, 0.4, 40e9, 4e9
    tube = Adapter("outer", "tube", ri, ro, L, "far_end", ez, 12e9, 12e9, g, 0.0)
    fs = ring_face_stiffness(table1, "outer", tube, mesh="coarse")
    q = np.zeros(fs.face.size)
    if field == "axial":
        q[2::3] = 1.0
    else:
        q[1::3] = fs.face.r
    stiffness = 2 * np.pi * q @ fs.matrix(0) @ q          # c_0 = 2 pi: the whole circumference
    assert stiffness == pytest.approx(expected(ri, ro, L, ez, g), rel=1e-6)


def test_a_calculix_written_substructure_file_is_read_node_by_node():
    """tests/data/calculix/blocksub.mtx, written by CalculiX 2.20 (*SUBSTRUCTURE GENERATE of
    block_substructure.inp: its user-element layout, lower triangle row by row, one retained DOF
    per element "node"), read with the nodes in another order, equals the retained block of the
    block's stiffness assembled here from the C3D8 element matrix (what that CalculiX version
    writes: see check_substructure.py there)."""
    sys.path.insert(0, str(ROOT / "tests" / "data" / "calculix"))
    from check_substructure import block_matrices

    from slewing_model.rings.superelement.imported import read_calculix

    top, k_tt, _ = block_matrices()
    order = np.random.default_rng(3).permutation(len(top))
    k = read_calculix(str(ROOT / "tests" / "data" / "calculix" / "blocksub.mtx"), top[order])
    dofs = (3 * order[:, None] + np.arange(3)).ravel()
    assert np.abs(k - k_tt[np.ix_(dofs, dofs)]).max() < 1e-10 * np.abs(k_tt).max()


def test_a_very_stiff_plate_on_the_upper_face_reproduces_the_clamped_face(table1, builds):
    """The inner ring (bolted on its upper face) on a plate 1e4 times stiffer than steel, wider
    than the face and clamped along its inner edge: the clamped inner ring within 1 %."""
    s = table1.inner_section
    plate = Adapter("inner", "plate", s.inner_radius - 0.05, s.outer_radius, 0.04, "inner",
                    *(1e4 * STEEL,) * 3, 1e4 * STEEL / 2.6, 0.3)
    se = _build(table1.with_connection({"inner": plate}), "clamped")
    a = se.inner.harmonic_blocks().real
    c = builds["clamped"].inner.harmonic_blocks().real
    worst = max(np.linalg.norm(np.linalg.inv(x) - np.linalg.inv(y)) / np.linalg.norm(np.linalg.inv(y))
                for x, y in zip(a, c))
    assert worst < 0.01, worst
    assert se.metadata["rings"]["inner"]["connection"]["bolted_annulus_m"] == pytest.approx(
        [s.inner_radius, s.outer_radius])


def test_with_connection_refuses_a_connection_for_the_other_ring(table1):
    with pytest.raises(BearingDefinitionError, match="connection.outer"):
        table1.with_connection({"outer": _tube(table1, ring="inner")})
