"""Quadrature over a Hertz contact ellipse, exact for the Hertz pressure.

The friction model (:mod:`slewing_model.friction`) integrates the Coulomb traction
``mu p`` over every contact ellipse. The pressure ``p = p0 sqrt(1 - (eta/a)^2 - (xi/b)^2)``
is the weight of the rule: Gauss-Jacobi nodes across the groove and Gauss-Chebyshev nodes
of the second kind along the rolling direction integrate it exactly, so a rule of a few
points per direction carries the whole load (``docs/theory/friction.md``, Quadrature).

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

#: Default quadrature on which the power (torque) is integrated: points across
#: the groove x along the rolling direction (within 1e-3 of a 96 x 24 rule: docs/theory/friction.md)
DEFAULT_QUADRATURE = (20, 4)
#: Default rule on which the ball equilibrium is solved. The power is stationary
#: at the equilibrium: integrated on the fine rule at the equilibrium of this
#: cheaper one, it is within 1e-3 of the fully consistent value (docs/theory/friction.md).
#: ``solve_quadrature=None`` solves on the fine rule itself.
DEFAULT_SOLVE_QUADRATURE = (12, 2)


@dataclass(frozen=True)
class EllipseQuadrature:
    """Product rule over a Hertz contact ellipse, weights including the pressure.

    The ellipse is mapped to the square ``(u, t)`` in ``[-1, 1]^2`` by
    ``eta = a u`` (across the groove) and ``xi = b sqrt(1 - u^2) t`` (rolling
    direction), where ``p dA = 3 Q / (2 pi) (1 - u^2) sqrt(1 - t^2) du dt``:
    Gauss-Jacobi nodes ``u`` (weight ``1 - u^2``) and Gauss-Chebyshev nodes of
    the second kind ``t`` (weight ``sqrt(1 - t^2)``) integrate the Hertz weight
    exactly. Point ``k`` sits at ``eta = a * across[k]``, ``xi = b * along[k]``
    and carries the share ``weight[k]`` of the contact load (``sum = 1``):
    ``integral f p dA ~= Q * sum(weight * f(points))``.

    Attributes
    ----------
    n_across, n_along : int
    across, along : ndarray (n_across * n_along,)
        Point coordinates over the semi-axes (``along`` includes ``sqrt(1 - u^2)``).
    weight : ndarray (n_across * n_along,)
    across_nodes : ndarray (n_across,)
        ``u``.
    along_nodes : ndarray (n_along,)
        ``t``.
    along_squared : ndarray (K,)
        The distinct ``t^2``: the nodes ``+t`` and ``-t`` folded into one
        (the sliding speed over a contact depends on ``t^2`` only).
    folded_weight : ndarray (K, n_across)
        The weights summed over the nodes of each ``t^2``.
    """

    n_across: int
    n_along: int
    across: np.ndarray
    along: np.ndarray
    weight: np.ndarray
    across_nodes: np.ndarray
    along_nodes: np.ndarray
    along_squared: np.ndarray
    folded_weight: np.ndarray

    @property
    def size(self) -> int:
        return self.across.size

    @functools.cached_property
    def writable_arrays(self) -> tuple:
        """``across_nodes``, ``along_squared`` and ``folded_weight`` as writable copies, made once
        (the compiled friction loops take no read-only arrays; no code writes into them)."""
        return (np.array(self.across_nodes, dtype=float), np.array(self.along_squared, dtype=float),
                np.array(self.folded_weight, dtype=float))


def _gauss_jacobi_11(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss rule for the weight ``1 - x^2`` on [-1, 1] (Golub-Welsch): Gegenbauer
    ``lambda = 3/2``, monic recurrence ``beta_k = k (k + 2) / ((2k + 1)(2k + 3))``,
    ``integral (1 - x^2) dx = 4/3``."""
    k = np.arange(1, n, dtype=float)
    off = np.sqrt(k * (k + 2.0) / ((2.0 * k + 1.0) * (2.0 * k + 3.0)))
    nodes, vectors = np.linalg.eigh(np.diag(off, 1) + np.diag(off, -1))
    return nodes, 4.0 / 3.0 * vectors[0] ** 2


@functools.lru_cache(maxsize=32)
def ellipse_quadrature(n_across: int = DEFAULT_QUADRATURE[0], n_along: int = DEFAULT_QUADRATURE[1]
                       ) -> EllipseQuadrature:
    """The :class:`EllipseQuadrature` with ``n_across x n_along`` points (cached)."""
    n_across, n_along = int(n_across), int(n_along)
    if n_across < 1 or n_along < 1:
        raise ValueError(f"quadrature = ({n_across}, {n_along}): both sizes must be >= 1")
    u, wu = _gauss_jacobi_11(n_across)
    j = np.arange(1, n_along + 1)
    t = np.cos(j * np.pi / (n_along + 1))
    wt = np.pi / (n_along + 1) * np.sin(j * np.pi / (n_along + 1)) ** 2
    across = np.repeat(u, n_along)
    along = np.sqrt(1.0 - across**2) * np.tile(t, n_across)
    weight = 1.5 / np.pi * np.outer(wu, wt).ravel()
    along_squared, index = np.unique(np.round(t**2, 12), return_inverse=True)
    folded = np.zeros((along_squared.size, n_across))
    np.add.at(folded, index, weight.reshape(n_across, n_along).T)
    for arr in (across, along, weight, u, t, along_squared, folded):
        arr.setflags(write=False)
    return EllipseQuadrature(n_across, n_along, across, along, weight, u, t, along_squared, folded)


def as_quadrature(quadrature) -> EllipseQuadrature:
    if isinstance(quadrature, EllipseQuadrature):
        return quadrature
    if isinstance(quadrature, (int, np.integer)):
        return ellipse_quadrature(int(quadrature), int(quadrature))
    try:
        n_across, n_along = quadrature
    except (TypeError, ValueError):
        raise ValueError(f"quadrature = {quadrature!r}: an int or a pair (n_across, n_along)") from None
    return ellipse_quadrature(int(n_across), int(n_along))
