"""The rings' compliances formed block by block (slewing_model/rings/compliance.py): the numbers of the dense
construction bit for bit, without forming a dense (4B, 4B) matrix until one is asked for (the pitch bearing's
two rings and the contacts' cost about 25 ms of an FMU's instantiation as dense matrices)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from conftest import symmetric_block_circulant


def _dense_construction(superelement):
    """The rings' and the contacts' compliance as dense matrices: the pseudo-inverse's first block row made
    dense, ``M = P_out G_out P_out^T + P_in G_in P_in^T`` by its rows and columns (np.ix_)."""
    from slewing_model.bearing.conventions import INNER_SLOT, OUTER_SLOT
    from slewing_model.rings.compliance import _pseudo_inverse_blocks, ring_index

    rings = {}
    for name in ("outer", "inner"):
        row = _pseudo_inverse_blocks(np.asarray(getattr(superelement, name).first_row, dtype=float))
        n, m, _ = row.shape
        k = (np.arange(n)[None, :] - np.arange(n)[:, None]) % n
        rings[name] = row[k].transpose(0, 2, 1, 3).reshape(n * m, n * m)
    n = rings["outer"].shape[0] // 4
    total = 0.0
    for name, slots in (("outer", OUTER_SLOT), ("inner", INNER_SLOT)):
        index = ring_index(n, slots)
        total = total + rings[name][np.ix_(index, index)]
    return rings, total


@pytest.mark.parametrize("balls", [12, 67, 150])
def test_the_compliances_from_their_blocks_are_the_dense_constructions_bit_for_bit(balls):
    from slewing_model.rings.compliance import BlockCirculant, contact_compliance, product_operands, ring_compliances

    first_rows = {}
    for seed, name in enumerate(("outer", "inner")):
        dense = symmetric_block_circulant(balls, seed=balls + seed)
        dense = dense @ dense.T                      # symmetric positive semi-definite, as a ring's stiffness
        first_rows[name] = SimpleNamespace(first_row=dense[:4].reshape(4, balls, 4).transpose(1, 0, 2))
    superelement = SimpleNamespace(**first_rows)
    rings = ring_compliances(superelement)
    contacts = contact_compliance(rings)
    operands = product_operands(contacts)
    assert all(m._dense is None for m in (*rings.values(), contacts))          # nothing dense formed yet
    expected_rings, expected_contacts = _dense_construction(superelement)
    for name in ("outer", "inner"):
        assert np.array_equal(np.asarray(rings[name]), expected_rings[name])
    assert np.array_equal(np.asarray(contacts), expected_contacts)
    from_dense = BlockCirculant(expected_contacts, 4)         # as made from its dense matrix
    assert np.array_equal(contacts.blocks, from_dense.blocks)
    assert np.array_equal(contacts.harmonics, from_dense.harmonics)
    for a, b in zip(operands, product_operands(from_dense)):
        assert np.array_equal(a, b)
    y = np.random.default_rng(balls).standard_normal(4 * balls)
    assert np.array_equal(contacts @ y, from_dense @ y)
    assert contacts.shape == (4 * balls, 4 * balls) and contacts.balls == balls and contacts.block == 4
