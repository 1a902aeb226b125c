"""A ring model with a known block-circulant stiffness, independent of the finite
element superelement: each groove centre on an elastic foundation, tied to the same
groove centre of the neighbouring balls and to the ring's other groove centre."""
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SyntheticRing:
    ring: str
    ball_count: int
    first_row: np.ndarray

    def dense(self):
        n = self.ball_count
        k = (np.arange(n)[None, :] - np.arange(n)[:, None]) % n
        return self.first_row[k].transpose(0, 2, 1, 3).reshape(4 * n, 4 * n)


@dataclass(frozen=True)
class SyntheticSuperelement:
    outer: SyntheticRing
    inner: SyntheticRing

    def scaled(self, factor):
        return SyntheticSuperelement(*(SyntheticRing(r.ring, r.ball_count, r.first_row * factor)
                                       for r in (self.outer, self.inner)))


def ring_on_foundation(ring, n, k_ground, k_neighbour, k_pair):
    c = np.zeros((n, 4, 4))
    c[0] = np.eye(4) * (k_ground + 2 * k_neighbour + k_pair)
    c[0][0, 2] = c[0][2, 0] = c[0][1, 3] = c[0][3, 1] = -k_pair
    c[1] -= np.eye(4) * k_neighbour
    c[n - 1] -= np.eye(4) * k_neighbour
    return SyntheticRing(ring, n, c)


def synthetic_superelement(n, scale=1.0):
    return SyntheticSuperelement(ring_on_foundation("outer", n, 2e8 * scale, 5e8 * scale, 1e9 * scale),
                                 ring_on_foundation("inner", n, 3e8 * scale, 4e8 * scale, 1e9 * scale))
