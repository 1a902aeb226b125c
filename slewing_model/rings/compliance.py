"""Compliance of the rings at the contacts, from their superelements (paper eqs 12-15).

Each ring's superelement (:mod:`slewing_model.rings.stiffness`) is its stiffness condensed to
the radial and axial displacement of its groove centres at every ball: a block-circulant
matrix (the ring is axisymmetric and the balls equally spaced). Its pseudo-inverse ``G`` is
the ring's compliance there (a free ring's rigid-body modes dropped), inverted harmonic by
harmonic; ``M`` combines both rings as the contacts feel them: the operator through which
the flexible solver (:mod:`slewing_model.distribution.bime`, :mod:`slewing_model.rings.reduced_operator`)
eliminates the ring displacements.

Both are kept as :class:`BlockCirculant`: their blocks (the entries the reduced operator takes of
``M``, :meth:`BlockCirculant.entries`), the dense matrix formed when first asked for (numpy's loops
take rows and columns of it), multiplied harmonic by harmonic (numpy's FFT) on large bearings, or
by a compiled real DFT (:func:`product_operands`, :mod:`slewing_model.distribution.kernel`) at any size.

Run-time module: numpy.
"""
from __future__ import annotations

import numpy as np

from ..bearing.conventions import INNER_SLOT, OUTER_SLOT, RING_CONTACTS

#: from this many balls on, products with a ring compliance go through the harmonics (FFT):
#: for a (4B, 4B) matrix 12 us against 34 us dense at B = 150, 13 us against 6 us at B = 67
#: (one thread, this machine); the dense product also pulls the 2.9 MB matrix through the cache
FFT_FROM_BALLS = 100


class BlockCirculant:
    """A block-circulant matrix (B blocks of m x m): block ``(b, c)`` is ``C_((c - b) mod B)``.

    The rings' compliances at the balls have this form (axisymmetric rings, equally spaced
    balls). Entries and slices come from the dense matrix (``matrix[rows, cols]``); a product
    ``matrix @ y`` is ``r_b = sum_k C_k y_(b+k)``, in the harmonic basis
    ``R_j = conj(C^_j) Y_j`` with ``C^ = DFT(C)`` (real ``C``): O(B m^2 + B log B m)
    instead of O(B^2 m^2), used from :data:`FFT_FROM_BALLS` balls on.

    :meth:`from_blocks` makes one from its blocks alone: the dense matrix (2.9 MB for the pitch
    bearing, about 8 ms to form in a fresh process) is then formed when first used (:attr:`dense`,
    an entry or slice, ``np.asarray``, a dense product below :data:`FFT_FROM_BALLS` balls), which
    the compiled loops never do.

    Parameters
    ----------
    dense : ndarray (B m, B m)
    block : int
        ``m``.
    """

    def __init__(self, dense: np.ndarray, block: int):
        self._dense = dense
        balls = dense.shape[0] // block
        first_row = dense[:block].reshape(block, balls, block).transpose(1, 0, 2)   # C_k, (B, m, m)
        self._set_blocks(np.ascontiguousarray(first_row))

    @classmethod
    def from_blocks(cls, blocks: np.ndarray) -> "BlockCirculant":
        """The matrix of the blocks ``C_k`` (B, m, m) (its first block row), its dense form not yet formed."""
        matrix = cls.__new__(cls)
        matrix._dense = None
        matrix._set_blocks(np.ascontiguousarray(blocks))
        return matrix

    def _set_blocks(self, blocks: np.ndarray) -> None:
        #: the blocks ``C_k`` (B, m, m), contiguous: ``dense[b m + r, c m + s] = blocks[(c - b) mod B, r, s]``,
        #: 19 kB for the pitch bearing against the dense matrix's 2.9 MB (entries gathered from it stay in cache)
        self.blocks = blocks
        self.balls, self.block = blocks.shape[0], blocks.shape[1]
        self.shape = (self.balls * self.block, self.balls * self.block)
        self.harmonics = np.conj(np.fft.rfft(blocks, axis=0))
        self.by_harmonics = self.balls >= FFT_FROM_BALLS

    @property
    def dense(self) -> np.ndarray:
        """The matrix (B m, B m), formed from :attr:`blocks` when first asked for."""
        if self._dense is None:
            n, m = self.balls, self.block
            k = (np.arange(n)[None, :] - np.arange(n)[:, None]) % n          # block (b, c) is C_(c - b)
            self._dense = self.blocks[k].transpose(0, 2, 1, 3).reshape(n * m, n * m)
        return self._dense

    def __matmul__(self, y: np.ndarray) -> np.ndarray:
        if not self.by_harmonics:
            return self.dense @ y
        harmonic = np.fft.rfft(y.reshape(self.balls, self.block), axis=0)
        product = np.matmul(self.harmonics, harmonic[..., None])[..., 0]
        return np.fft.irfft(product, n=self.balls, axis=0).reshape(y.shape)

    def __getitem__(self, index):
        return self.dense[index]

    def entries(self, rows: np.ndarray, columns: np.ndarray) -> np.ndarray:
        """``dense[rows][:, columns]`` (len(rows), len(columns)), the same numbers gathered from
        :attr:`blocks` (a few rows or columns: the dense matrix is then read at scattered places
        that a step's other work has pushed out of the cache)."""
        m = self.block
        shift = (columns[None, :] // m - rows[:, None] // m) % self.balls
        return self.blocks[shift, (rows % m)[:, None], (columns % m)[None, :]]

    def __array__(self, dtype=None, copy=None):
        return self.dense if dtype is None else self.dense.astype(dtype)


def product_operands(matrix: BlockCirculant) -> tuple:
    """What the compiled product ``M v`` (:func:`slewing_model.distribution.kernel._ring_times`) takes of a
    :class:`BlockCirculant`, always through its harmonics (compiled, that is faster than the dense
    product from a few balls on): the tables ``cos``, ``sin`` (K, K) of ``2 pi j b / B`` for the
    harmonics ``j < K = B // 2 + 1`` and the balls ``b < K`` (symmetric in ``j`` and ``b``; the DFT and its
    inverse need no other balls), with ``j b`` taken modulo ``B`` (the tables then as exact as numpy's
    FFT's twiddles: 6e-16, not 1e-13 at 180 balls), and the real and imaginary parts of its harmonics
    (K, m, m)."""
    n_harmonics, n_balls = matrix.harmonics.shape[0], matrix.balls
    turns = np.outer(np.arange(n_harmonics), np.arange(n_harmonics)) % n_balls  # j b mod B: angles below 2 pi
    angle = 2.0 * np.pi * turns / n_balls
    cos_table, sin_table = np.cos(angle), np.sin(angle)
    sin_table[2 * turns == n_balls] = 0.0                # the angle pi exactly (the harmonic B/2)
    return (cos_table, sin_table, np.ascontiguousarray(matrix.harmonics.real),
            np.ascontiguousarray(matrix.harmonics.imag))


def _pseudo_inverse_circulant(first_row: np.ndarray, rcond: float = 1e-10) -> np.ndarray:
    """Pseudo-inverse of a symmetric block-circulant matrix given by its first
    block row (B, m, m), returned dense (:func:`_pseudo_inverse_blocks`, the dense form
    :attr:`BlockCirculant.dense` makes of them)."""
    return BlockCirculant.from_blocks(_pseudo_inverse_blocks(first_row, rcond)).dense


def _pseudo_inverse_blocks(first_row: np.ndarray, rcond: float = 1e-10) -> np.ndarray:
    """First block row (B, m, m) of the pseudo-inverse of a symmetric block-circulant matrix given by
    its first block row (B, m, m). Inverts block by block in the harmonic (DFT) basis, dropping the
    null space (a free ring's rigid-body modes)."""
    blocks = np.fft.fft(first_row, axis=0)  # block j = sum_k C_k exp(-2 pi i j k / B)
    w, v = np.linalg.eigh(0.5 * (blocks + blocks.conj().transpose(0, 2, 1)))   # all blocks at once
    keep = np.abs(w) > rcond * np.abs(w).max()
    inverse_w = np.divide(1.0, w, out=np.zeros_like(w), where=keep)          # the null space dropped
    inv = (v * inverse_w[:, None, :]) @ v.conj().transpose(0, 2, 1)
    return np.fft.ifft(inv, axis=0).real  # first block row of the pseudo-inverse


def ring_compliances(superelement) -> dict[str, BlockCirculant]:
    """``G`` (4B, 4B) of each ring: its compliance at its groove centres, the
    pseudo-inverse of its superelement (a free ring's rigid modes dropped), from its blocks
    (:meth:`BlockCirculant.from_blocks`)."""
    return {name: BlockCirculant.from_blocks(_pseudo_inverse_blocks(np.asarray(getattr(superelement, name).first_row,
                                                                               dtype=float)))
            for name in ("outer", "inner")}


def contact_compliance(rings: dict[str, BlockCirculant]) -> BlockCirculant:
    """``M`` (4B, 4B): the combined compliance of both rings seen by the contacts,
    ordered like the relative vectors ``e`` (ball, diagonal, (r, z)).

    ``M = P_out G_out P_out^T + P_in G_in P_in^T`` with ``G`` from :func:`ring_compliances`: block-circulant
    too, each ``P`` ordering the DOFs within each ball (:func:`ring_index`), so formed block by block
    (the same sums as of the dense matrices)."""
    total = 0.0
    for name, slots in (("outer", OUTER_SLOT), ("inner", INNER_SLOT)):
        index = ring_index(1, slots)                           # the ball's 4 DOFs in the order of e
        total = total + rings[name].blocks[:, index[:, None], index[None, :]]
    return BlockCirculant.from_blocks(total)


def ring_index(n: int, slots: np.ndarray) -> np.ndarray:
    """Ring DOF (paper eq 14 order) of every entry of the relative vectors
    ``e`` in (ball, diagonal, (r, z)) order; ``slots`` is the ring's contact
    slot of diagonals 1 and 2."""
    return (4 * np.arange(n)[:, None, None] + 2 * slots[None, :, None] + np.arange(2)[None, None, :]).ravel()


def ring_selector(n: int, slots: np.ndarray) -> np.ndarray:
    """(4B, 4B) 0/1 matrix taking a ring's DOFs to the order of ``e``."""
    p = np.zeros((4 * n, 4 * n))
    p[np.arange(4 * n), ring_index(n, slots)] = 1.0
    return p


def groove_displacement(rings: dict[str, BlockCirculant], forces: np.ndarray) -> np.ndarray:
    """(B, 4, 2) displacements (R, z) of the groove centres of contacts 1..4 under the contact
    forces ``forces`` (4B,) that the rings feel, ordered like the relative vectors ``e``:
    ``D_in = -G_in P_in^T y``, ``D_out = G_out P_out^T y`` (paper eqs 14-15)."""
    n = rings["outer"].shape[0] // 4
    forces = forces.reshape(n, 2, 2)
    out = np.zeros((n, 4, 2))
    for ring, slots, sign in (("outer", OUTER_SLOT, 1.0), ("inner", INNER_SLOT, -1.0)):
        load = np.zeros((n, 2, 2))
        load[:, slots] = forces
        d = (rings[ring] @ load.ravel()).reshape(n, 2, 2) * sign
        out[:, [c - 1 for c in RING_CONTACTS[ring]]] = d
    return out
