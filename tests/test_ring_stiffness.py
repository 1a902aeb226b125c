"""Run-time superelement container (slewing_model.rings.stiffness): numpy only, block-circulant
algebra, storage, and the check that a file belongs to the bearing it is used with."""
import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest

from slewing_model.bearing.geometry import RingSection
from slewing_model.rings.stiffness import (RingStiffness, Superelement, SuperelementMismatchError, bearing_hash,
                                          ring_fields)


def random_first_row(B, seed=0, free=False):
    """First block row of a random symmetric positive (semi-)definite block-circulant matrix:
    built from Hermitian positive blocks in the harmonic domain (the defining property)."""
    rng = np.random.default_rng(seed)
    blocks = np.zeros((B, 4, 4))
    for j in range(B // 2 + 1):
        a = rng.normal(size=(4, 4))
        blocks[j] = a @ a.T + 0.1 * np.eye(4)
        blocks[(-j) % B] = blocks[j]
    if free:
        blocks[0][:, 1] = blocks[0][1, :] = 0.0      # a zero mode in harmonic 0
    return np.real(np.fft.fft(blocks, axis=0)) / B * 1e9


def test_runtime_module_imports_numpy_only():
    code = ("import sys; import slewing_model.rings.stiffness; "
            "bad = [m for m in ('scipy', 'skfem', 'tqdm') if m in sys.modules]; print(bad); assert not bad")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


def test_dense_is_the_block_circulant_of_the_first_row():
    B = 7
    row = random_first_row(B)
    k = RingStiffness("outer", B, row, (), "clamped").dense()
    assert k.shape == (4 * B, 4 * B)
    for b in range(B):
        for kk in range(B):
            c = (b + kk) % B
            np.testing.assert_array_equal(k[4 * b:4 * b + 4, 4 * c:4 * c + 4], row[kk])
    np.testing.assert_allclose(k, k.T, rtol=0, atol=1e-12 * abs(k).max())


def test_harmonic_blocks_follow_the_stated_convention_and_diagonalise_dense():
    B = 9
    row = random_first_row(B, seed=1)
    ring = RingStiffness("inner", B, row)
    blocks = ring.harmonic_blocks()
    for j in range(B):   # definition in the docstring: block j = sum_k C_k exp(+2 pi i j k / B)
        ref = sum(row[k] * np.exp(2j * np.pi * j * k / B) for k in range(B))
        np.testing.assert_allclose(blocks[j], ref, atol=1e-6 * abs(ref).max())
        np.testing.assert_allclose(blocks[j], blocks[j].conj().T, atol=1e-6 * abs(ref).max())
    # the pattern D_b = d exp(2 pi i j b / B) is scaled by block j
    j, d = 2, np.array([1.0, -2.0, 0.5, 3.0])
    pattern = np.concatenate([d * np.exp(2j * np.pi * j * b / B) for b in range(B)])
    np.testing.assert_allclose(ring.dense() @ pattern,
                               np.concatenate([(blocks[j] @ d) * np.exp(2j * np.pi * j * b / B) for b in range(B)]),
                               rtol=1e-9, atol=1e-6)
    eig_dense = np.sort(np.linalg.eigvalsh(ring.dense()))
    eig_blocks = np.sort(np.concatenate([np.linalg.eigvalsh(b) for b in blocks]))
    np.testing.assert_allclose(eig_dense, eig_blocks, rtol=1e-9, atol=1e-6 * eig_dense.max())


def test_apply_and_energy_match_the_dense_matrix():
    B = 12
    ring = RingStiffness("outer", B, random_first_row(B, seed=2))
    d = np.random.default_rng(3).normal(size=4 * B) * 1e-6
    np.testing.assert_allclose(ring.apply(d), ring.dense() @ d, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(ring.apply(d.reshape(B, 4)).ravel(), ring.dense() @ d, rtol=1e-10, atol=1e-12)
    assert ring.energy(d) == pytest.approx(0.5 * d @ ring.dense() @ d, rel=1e-10)


def test_a_first_row_that_is_not_symmetric_is_refused():
    row = random_first_row(6)
    row[1, 0, 1] += 1e8
    with pytest.raises(ValueError, match="symmetric"):
        RingStiffness("outer", 6, row)
    with pytest.raises(ValueError, match="shape"):
        RingStiffness("outer", 5, random_first_row(6))
    with pytest.raises(ValueError, match="ring"):
        RingStiffness("middle", 6, random_first_row(6))


def _superelement(bearing, seed=0):
    B = bearing.ball_count
    return Superelement(RingStiffness("outer", B, random_first_row(B, seed, free=True), ("X", "Y", "Z", "rx", "ry"), "free"),
                        RingStiffness("inner", B, random_first_row(B, seed + 1), (), "clamped"),
                        {"bearing": ring_fields(bearing), "bearing_hash": bearing_hash(bearing),
                         "bearing_name": bearing.name, "mesh": {"name": "coarse"}})


def test_save_and_load_round_trip(table3, tmp_path):
    se = _superelement(table3)
    path = tmp_path / "se.npz"
    se.save(path)
    back = Superelement.load(path, table3)
    for r in ("outer", "inner"):
        a, b = se.ring(r), back.ring(r)
        np.testing.assert_array_equal(a.first_row, b.first_row)
        assert (a.removed_modes, a.boundary_condition, a.ball_count) == (b.removed_modes, b.boundary_condition,
                                                                         b.ball_count)
    assert back.metadata["bearing_hash"] == bearing_hash(table3)
    json.dumps(back.metadata)   # JSON-serialisable


def test_a_folder_holds_the_same_superelement_as_a_file_bit_for_bit(table3, tmp_path):
    """The FMU's form (:meth:`Superelement.save_folder`: .npy files and a JSON text, read without zipfile) and the
    file's give the same arrays, bit for bit, and the same metadata; the folder is checked against the bearing
    and refused where it is not a superelement, as a file is."""
    se = _superelement(table3)
    se.save(tmp_path / "se.npz")
    se.save_folder(tmp_path / "se")
    assert sorted(p.name for p in (tmp_path / "se").iterdir()) == ["inner_first_row.npy", "metadata.json",
                                                                   "outer_first_row.npy"]
    a, b = Superelement.load(tmp_path / "se.npz", table3), Superelement.load(tmp_path / "se", table3)
    assert a.metadata == b.metadata
    for r in ("outer", "inner"):
        x, y = a.ring(r), b.ring(r)
        assert (x.first_row.dtype, x.first_row.shape, x.first_row.tobytes()) == (y.first_row.dtype, y.first_row.shape,
                                                                                 y.first_row.tobytes())
        assert (x.removed_modes, x.boundary_condition, x.ball_count) == (y.removed_modes, y.boundary_condition,
                                                                         y.ball_count)
    with pytest.raises(SuperelementMismatchError, match="youngs_modulus"):
        Superelement.load(tmp_path / "se", dataclasses.replace(table3, youngs_modulus=210e9))
    (tmp_path / "se" / "metadata.json").unlink()
    with pytest.raises(ValueError, match="not a superelement"):
        Superelement.load(tmp_path / "se")


def test_load_refuses_another_bearing_naming_the_field(table3, tmp_path):
    path = tmp_path / "se.npz"
    _superelement(table3).save(path)
    other = dataclasses.replace(table3, youngs_modulus=210e9)
    with pytest.raises(SuperelementMismatchError, match="youngs_modulus"):
        Superelement.load(path, other)
    section = table3.inner_section
    thicker = dataclasses.replace(table3, inner_section=RingSection(section.inner_radius - 0.01, section.outer_radius,
                                                                    section.height, section.bolted_face))
    with pytest.raises(SuperelementMismatchError, match="inner_section.inner_radius"):
        Superelement.load(path, thicker)
    assert issubclass(SuperelementMismatchError, ValueError)


def test_preload_errors_and_moving_ring_do_not_change_the_hash(table3):
    h = bearing_hash(table3)
    assert bearing_hash(table3.with_preload(20e-6)) == h
    assert bearing_hash(dataclasses.replace(table3, moving_ring="outer", name="renamed")) == h
    assert bearing_hash(dataclasses.replace(table3, first_ball_angle=0.1)) != h
    assert bearing_hash(dataclasses.replace(table3, contact_angle=table3.contact_angle + 1e-3)) != h


def test_scaled_multiplies_both_rings(table3):
    se = _superelement(table3)
    big = se.scaled(1e6)
    np.testing.assert_allclose(big.outer.first_row, 1e6 * se.outer.first_row)
    np.testing.assert_allclose(big.inner.dense(), 1e6 * se.inner.dense())
    assert big.metadata["scale"] == 1e6
    assert big.outer.removed_modes == se.outer.removed_modes


def test_a_file_that_is_not_a_superelement_is_refused(tmp_path):
    path = tmp_path / "x.npz"
    np.savez(path, something=np.zeros(3))
    with pytest.raises(ValueError, match="not a superelement"):
        Superelement.load(path)
