"""The reduced Newton operator of the flexible model: the Newton system on the loaded contacts.

For flexible rings the rings are linear, so each Newton step of the energy (paper eq 20)
eliminates their displacements exactly through their compliance ``M`` at the contacts
(:mod:`slewing_model.rings.compliance`) and is solved on the *active* (loaded) diagonals
only (:mod:`slewing_model.distribution.bime` derives it):

    ``[(A^-1 + M)_aa  -S J_a] [y_a]   [A_a^-1 f_a + (M y)_a]``
    ``[-S J_a^T          0  ] [dq ] = [-F                  ]``

with ``A`` the 2x2 stiffness blocks of the Hertz springs (eqs 8-11) at an iterate, ``J``
the Jacobian of the contacts' relative vectors on the moving ring's five motions (eq 23)
and ``y`` the contact forces after the step. :class:`ReducedOperator` keeps
``W^-1 = (A^-1 + M)_aa^-1`` and what follows from it for the five motions (its Schur
complement). It is reused between iterations and between warm-started steps (a modified
Newton step, still a descent direction), bordered by the contacts that close
(:func:`update_operator`; contacts that open keep their rows until a fresh operator), and
rebuilt when convergence slows (:func:`assemble_operator`). A new one is inverted in single
precision (:data:`OPERATOR_PRECISION`): the step is solved in increments of ``y``
(:func:`newton_step`), so an approximate ``W^-1`` slows the iteration without moving its answer; for
the same reason the step's product with a single-precision ``W^-1`` is partly summed in single
precision (:func:`single_product`).

Run-time module: numpy.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np


@dataclass(frozen=True)
class ReducedOperator:
    """``W^-1`` of the active contacts and its coupling to the moving ring's motions.

    Attributes
    ----------
    rows : ndarray (n,) of int
        Rows of the operator's contacts among the 4B contact rows (ball, diagonal, (r, z)), two a
        diagonal, in the order they entered (:func:`update_operator`): the diagonals loaded when it
        was formed, then those that closed since.
    active : ndarray (2B,) of bool
        The operator's diagonals (``rows[::2] // 2``) as a mask.
    contact_compliance : ndarray (n/2, 2, 2)
        ``A^-1`` of the operator's diagonals, in its order, when each entered.
    inverse : ndarray (n, n)
        ``W^-1 = (A^-1 + M)_aa^-1``, computed in :data:`OPERATOR_PRECISION` (checked,
        :func:`checked_inverse`), so within about ``1e-7 cond(W)`` of the exact inverse; kept in
        the precision it was computed in (:func:`kept_precision`): single for an inverse by halves
        that passed the check, double for one made again, and for what bordering makes of either
        the precision it had. Its products sum in double.
    jacobian : ndarray (n, 5)
        ``J_a`` (scaled rotations) when the coupling was formed.
    coupling : ndarray (n, 5)
        ``W^-1 J_a``.
    schur_inverse : ndarray (5, 5)
        ``(J_a^T W^-1 J_a + mu I)^-1``.
    """

    rows: np.ndarray
    active: np.ndarray
    contact_compliance: np.ndarray
    inverse: np.ndarray
    jacobian: np.ndarray
    coupling: np.ndarray
    schur_inverse: np.ndarray

    def as_tuple(self) -> tuple:
        """The arrays, not copied (a solver state to keep or serialise)."""
        return tuple(getattr(self, f.name) for f in fields(self))

    @classmethod
    def from_tuple(cls, values) -> "ReducedOperator":
        return cls(*(np.asarray(v) for v in values))


def contact_compliance_blocks(point, stiffness: np.ndarray, active: np.ndarray) -> np.ndarray:
    """``A^-1`` (n_active, 2, 2): compliance of the active diagonals' Hertz springs at an iterate.

    ``point`` has per diagonal the unit vector ``n``, the elongation ``delta``, the length
    ``length`` and the load ``q`` of the spring (eqs 7-8); ``stiffness`` is ``K_tot`` (B, 2):
    normal compliance ``1 / (1.5 K sqrt(delta))``, and ``length / q`` across."""
    n = point.n.reshape(-1, 2)[active]
    nn = n[:, :, None] * n[:, None, :]
    delta = point.delta.ravel()[active]
    k_normal = 1.5 * stiffness.ravel()[active] * np.sqrt(delta)
    return nn / k_normal[:, None, None] + (point.length.ravel()[active] / point.q.ravel()[active])[:, None, None] * (
        np.eye(2) - nn)


def reduced_operator(rows, active, contact_compliance, inverse, jacobian: np.ndarray, mu: float,
                     arithmetic: "OperatorArithmetic | None" = None) -> ReducedOperator:
    """The operator from ``W^-1``: its coupling to the motions through the Jacobian (4B, 5) and the
    Schur complement's inverse (:func:`operator_coupling`)."""
    ja = jacobian.reshape(-1, 5)[rows]
    coupling, schur_inverse = _arithmetic(arithmetic).couple(inverse, ja, mu)
    return ReducedOperator(rows, active, contact_compliance, inverse, ja, coupling, schur_inverse)


def operator_coupling(inverse: np.ndarray, ja: np.ndarray, mu: float):
    """``W^-1 J_a`` and ``(J_a^T W^-1 J_a + mu I)^-1``."""
    coupling = inverse_product(inverse, ja.T).T
    return coupling, np.linalg.inv(ja.T @ coupling + mu * np.eye(5))


def inverse_product(inverse: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``(W^-1 V)^T`` (k, n) for ``V^T = vectors`` (k, n) and a symmetric ``W^-1 = inverse``, summed in
    double. An inverse kept in single precision (:func:`kept_precision`) is converted first: numpy's
    product of the two precisions as they are runs without BLAS (in a bounded step after a moment
    reversal, 74-628 us for one vector)."""
    return vectors @ inverse.astype(np.float64, copy=False)


#: rows of a single-precision ``W^-1`` whose products :func:`single_product` sums in single precision before
#: adding them to the sum in double: eight, one vector of single-precision lanes (the compiled loop,
#: :func:`slewing_model.distribution.kernel._single_times`, takes it from here and has its pass written out
#: for eight rows)
SINGLE_BLOCK = 8


def single_product(inverse: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """``W^-1 v`` (n,) for a symmetric ``W^-1 = inverse`` kept in single precision (n, n): the Newton
    step's product (:func:`newton_step`), partly summed in single precision.

    ``v`` is rounded to single precision; each block of :data:`SINGLE_BLOCK` rows of ``W^-1`` gives
    ``s = M_j v_j + M_j+1 v_j+1 + ...``, summed in single precision left to right, and the blocks' ``s``
    are added in double, one after the other (the last block what is left). These are the compiled
    loop's operations in its order (:func:`slewing_model.distribution.kernel._single_times`), each
    exactly rounded, so both give the same numbers. The rounding of ``s``, about ``1e-7`` of
    ``|W^-1| |v|``, is of the size of the single-precision inverse's own error: the step in increments
    takes it as it takes that, in its contraction, not in its fixed point."""
    n = vector.size
    v = vector.astype(np.float32)
    full = n - n % SINGLE_BLOCK
    out = np.zeros(n)
    for rows in (slice(0, full), slice(full, n)):
        terms = inverse[rows] * v[rows, None]
        if terms.size:
            # numpy reduces an axis that is not the innermost by adding its rows one after the other (left
            # to right, as the compiled loop; tests/test_contact_kernel.py checks the two bit for bit)
            s = np.add.reduce(terms.reshape(-1, min(SINGLE_BLOCK, terms.shape[0]), n), axis=1)
            out += np.add.reduce(s.astype(np.float64), axis=0)     # in double, block after block
    return out


#: how far a turned Jacobian may be off the ring's own where errors move the grooves with it
#: (relative to its largest entry): the kept operator then stands for ``J_old T`` instead of
#: ``J_new``, a modified Newton operator like any kept one (its springs' stiffnesses are those of
#: an earlier iterate, percents off before a refresh); table3 with errors: 4e-8 a step, at most
#: 2e-5 after a turn of one radian
APPROXIMATE_TURN = 1e-4


def turned_operator(op: ReducedOperator, jacobian: np.ndarray, mu, tolerance: float = 0.0,
                    arithmetic: "OperatorArithmetic | None" = None) -> ReducedOperator:
    """The kept operator after the ring turned (:meth:`slewing_model.distribution.bime.BimeSolver.set_rotation`).

    ``W^-1`` holds (the rings are axisymmetric and the balls keep their spacing); the coupling
    ``W^-1 J_a`` follows the Jacobian. Where every ball keeps its groove centres (no
    manufacturing errors) turning the balls by an angle only mixes the Jacobian's columns,
    ``J_new = J_old T`` (``T``: the turn in the X, Y and rx, ry pairs, eq 23), and then
    ``W^-1 J_new = (W^-1 J_old) T`` costs ``O(n)`` instead of a pass over ``W^-1``
    (:func:`column_turn`). Where errors move the groove centres with the ring, ``J_old T`` is
    off ``J_new`` by the errors' share: within ``tolerance`` (the caller's, e.g.
    :data:`APPROXIMATE_TURN`) the operator is turned all the same and stands for ``J_old T``;
    otherwise the coupling is formed anew. The operator itself when the Jacobian did not
    change."""
    ja = jacobian.reshape(-1, 5)[op.rows]
    if op.jacobian.shape == ja.shape and (op.jacobian == ja).all():
        return op
    arithmetic = _arithmetic(arithmetic)
    turned = None
    if op.jacobian.shape == ja.shape:
        turned = arithmetic.turn(op.jacobian, ja, op.coupling, mu, tolerance)
    if turned is None:
        return reduced_operator(op.rows, op.active, op.contact_compliance, op.inverse, jacobian, mu, arithmetic)
    coupling, schur_inverse, turned_jacobian = turned
    return ReducedOperator(op.rows, op.active, op.contact_compliance, op.inverse, turned_jacobian, coupling,
                           schur_inverse)


def column_turn(old: np.ndarray, new: np.ndarray, coupling: np.ndarray, mu: float, tolerance: float = 0.0):
    """The coupling ``coupling T``, the Schur complement's inverse ``(J^T coupling T + mu I)^-1`` and
    the Jacobian ``J`` they are for, where ``old T`` (``T`` fitted to ``new`` by least squares)
    reproduces ``new`` to 1e-12 (``J = new``: then ``coupling T = W^-1 old T = W^-1 new``) or to
    ``tolerance`` (``J = old T``); or None (no ``T`` does: errors move the grooves with the ring;
    or the fit's normal equations are singular)."""
    try:
        turn = np.linalg.solve(old.T @ old, old.T @ new)
    except np.linalg.LinAlgError:      # J_a of rank < 5 (fewer than three loaded diagonals)
        return None
    fitted = old @ turn
    misfit = np.abs(fitted - new).max()
    if not misfit <= max(tolerance, 1e-12) * np.abs(new).max():
        return None
    jacobian = new if misfit <= 1e-12 * np.abs(new).max() else fitted
    coupling = coupling @ turn
    return coupling, np.linalg.inv(jacobian.T @ coupling + mu * np.eye(5)), jacobian


def _add_blocks(matrix: np.ndarray, blocks: np.ndarray) -> None:
    """Add the 2x2 ``blocks`` (k, 2, 2) on the diagonal of ``matrix`` (2k, 2k), in place."""
    first = np.arange(0, 2 * blocks.shape[0], 2)
    for r in range(2):
        for c in range(2):
            matrix[first + r, first + c] += blocks[:, r, c]


#: the precision ``W``'s inverse is computed in (its stages, :data:`STAGES`; ``W`` is kept in double,
#: and so is the inverse once done). Single: 0.6 of double's time (one thread, the stages of 430 rows
#: 3.5 -> 2.2 ms) and an inverse within about ``1e-7 cond(W)`` of ``W``'s (the pitch bearing's ``W``,
#: condition 5.7e3: 4e-5), which the step in increments (:func:`newton_step`) takes as one more
#: approximation of its modified Newton operator: the equilibrium it converges to is the same. An
#: inverse too far off, or a ``W`` singular in single precision, is inverted again through its
#: Cholesky factor, in single precision and if need be in double (:func:`checked_inverse`; why:
#: docs/design-decisions.md, "The kept operator in single precision, and what it means")
OPERATOR_PRECISION = np.float32


def kept_precision(inverse: np.ndarray) -> np.ndarray:
    """``inverse`` as a :class:`ReducedOperator` keeps it: in single precision where it was computed
    so (an inverse by halves in :data:`OPERATOR_PRECISION`, which passed the check), else in double.

    The Newton iterations with a kept operator multiply by it 4-5 times a step, and the product
    reads all of it (the pitch bearing's 368 rows: 1.08 MB in double, from beyond the core's cache
    at a step's first iteration): kept in single precision it reads half, in products that still
    sum in double (the pitch bearing's complete steps 0.93-0.95 of the time). An inverse computed in single precision loses nothing so kept; one bordered
    in double from it (:func:`update_operator`) is rounded back, an error of ``6e-8`` relative per
    entry against the ``1e-7 cond(W)`` it already had. An inverse made in double
    (:func:`checked_inverse`: ``W`` too ill-conditioned for single precision) stays double."""
    return inverse if inverse.dtype == np.float32 else inverse.astype(np.float64, copy=False)


#: below this size :func:`spd_inverse` calls LAPACK's inverse
LEAF = 64


def spd_inverse(w: np.ndarray) -> np.ndarray:
    """Inverse of a symmetric positive definite matrix by its halves (Schur complement).

    With ``w = [[A, B], [B^T, D]]``, ``X = A^-1 B`` and ``S = D - B^T X`` (positive definite
    too, so no pivoting is needed),
    ``w^-1 = [[A^-1 + X S^-1 X^T, -X S^-1], [-S^-1 X^T, S^-1]]``, with ``A^-1`` and ``S^-1``
    by the same rule down to :data:`LEAF` rows, each made exactly symmetric: the formula takes
    ``(A^-1 B)^T`` for ``B^T A^-1``, and the round-off asymmetry of an inverse, multiplied by
    ``S^-1``, otherwise grows from level to level (measured: residual ``|w^-1 w - I|`` 1e-6
    instead of 1e-11 on the 592 rows of the pitch bearing's cold start; symmetric, as
    ``np.linalg.inv``'s). The flops are matrix products, which BLAS
    runs near the machine's peak; ``np.linalg.inv`` (LU, then ``n`` triangular solves) is
    twice as slow on one thread at 380 rows (``python -m benchmarks operator``).

    The top level is six stages (:data:`STAGES`), which :class:`PendingOperator` spreads over
    steps."""
    return _at_once(w, STAGES)


def _at_once(w: np.ndarray, stages: tuple) -> np.ndarray:
    """The inverse of ``w`` by ``stages`` (:data:`STAGES`, :data:`FACTOR_STAGES`) at once; LAPACK's at
    :data:`LEAF` rows or fewer."""
    if w.shape[0] <= LEAF:
        return _lapack_inverse(w)
    return _run_stages(w, stages)[0]


def _run_stages(w: np.ndarray, stages, parts: tuple = ()) -> tuple:
    """``stages`` run on ``w`` one after the other from ``parts`` (the results of the stage before
    the first): the last one's results."""
    for stage in stages:
        parts = stage(w, *parts)
    return parts


def _a_inverse(w):
    """``A^-1``."""
    h = w.shape[0] // 2
    return (spd_inverse(w[:h, :h]),)


def _x(w, a_inv):
    """... ``X = A^-1 B``."""
    h = w.shape[0] // 2
    return a_inv, a_inv @ w[:h, h:]


def _schur(w, a_inv, x):
    """... ``S = D - B^T X``, made exactly symmetric."""
    h = w.shape[0] // 2
    schur = w[h:, h:] - w[:h, h:].T @ x
    return a_inv, x, 0.5 * (schur + schur.T)


def _schur_inverse(w, a_inv, x, schur):
    """... ``S^-1``."""
    return a_inv, x, spd_inverse(schur)


def _y(w, a_inv, x, s_inv):
    """... ``Y = X S^-1``."""
    return a_inv, x, s_inv, x @ s_inv


def _joined(w, a_inv, x, s_inv, y):
    """... and ``w^-1`` from them."""
    h = w.shape[0] // 2
    out = np.empty_like(w)
    corner = a_inv + y @ x.T
    out[:h, :h] = 0.5 * (corner + corner.T)
    out[:h, h:] = -y
    out[h:, :h] = -y.T
    out[h:, h:] = s_inv
    return (out,)


#: the stages of :func:`spd_inverse`'s top level, each taking ``w`` and the last one's results
STAGES = (_a_inverse, _x, _schur, _schur_inverse, _y, _joined)
#: where the steps of a :class:`PendingOperator` end in a complete solve (one a step): ``A^-1`` and
#: ``A^-1 B`` on the step that forms ``W`` (with ``W``'s gathering, about half the work), the rest
#: on the next (measured against three steps and against the split 10/12 | 6/12). A
#: bounded solve runs as many stages as its work allows (:func:`stage_work`).
SPREAD_STAGES = (2, len(STAGES))


#: what a floating-point operation of each stage costs against one of a large product's in double
#: precision (one BLAS thread, measured: ``python -m benchmarks operator --stages``), in
#: :data:`OPERATOR_PRECISION`: an inverse of a half recurses down to LAPACK's leaves and runs at
#: about a third of a double product's rate (single: 1.3 times faster), ``S`` and the join add passes
#: over the matrix; single precision runs the products 2.2 times, the join 2 times faster than double
#: (whose weights are 3, 1, 1.5, 3, 1, 1.5). On operators of 356-424 rows (two runs) the stages run at
#: 39-49 million a millisecond, the join at 25-26, not 55: weights of (2.3, 0.45, 0.7, 2.3, 0.45, 0.75)
#: leave a bounded step's operator work at 1.3 times the time its bound says (the join twice)
STAGE_WEIGHT = (2.6, 0.63, 0.78, 2.6, 0.63, 1.6)


def inverse_work(n: int) -> float:
    """The work of :func:`spd_inverse` of ``n`` rows, its stages' (:func:`stage_work`): about
    ``2.25 n^3``."""
    return sum(stage_work(n, k) for k in range(len(STAGES)))


def stage_work(n: int, stage: int, method: int = 0) -> float:
    """The work of stage ``stage`` of :data:`STAGES` on ``n`` rows (``method`` 1 and 2:
    :data:`FACTOR_STAGES`', in :data:`OPERATOR_PRECISION` and in double): its floating-point operations
    (a product of ``(p, q)`` by ``(q, r)`` is ``2 p q r``, a symmetric one ``p q p``, an inverse of ``k``
    rows ``4 k^3 / 3``, an inverse Cholesky factor ``k^3``, LAPACK's ``2 k^3``; halves of ``h`` and
    ``m = n - h`` rows) times :data:`STAGE_WEIGHT` (:data:`FACTOR_WEIGHT`, :data:`FACTOR_WEIGHT_DOUBLE`),
    so that work is about time: some 55 million a millisecond on one core here. At :data:`LEAF` rows
    or fewer the first stage is the whole inverse."""
    weight = (STAGE_WEIGHT, FACTOR_WEIGHT, FACTOR_WEIGHT_DOUBLE)[method]
    if n <= LEAF:
        return weight[0] * 2.0 * n ** 3 if stage == 0 else 0.0
    h = n // 2
    m = n - h
    if method:
        flops = (h ** 3, 2.0 * h * h * m, m * m * h, m ** 3, 2.0 * m * h * (h + m),
                 h * h * (h + m) + m ** 3 + 2.0 * h * m * m)
    else:
        flops = (4.0 / 3.0 * h ** 3, 2.0 * h * h * m, 2.0 * m * m * h, 4.0 / 3.0 * m ** 3, 2.0 * h * m * m,
                 2.0 * h * h * m)
    return weight[stage] * flops[stage]


def cholesky_inverse(w_mat: np.ndarray, precision=np.float64) -> np.ndarray:
    """The inverse (double) of a symmetric positive definite ``W`` (double) through its Cholesky
    factor, computed in ``precision``: ``W`` scaled to a unit diagonal (:func:`scaled_matrix`), the
    inverse of that by :data:`FACTOR_STAGES` and scaled back. As accurate as LAPACK's Cholesky inverse
    (``potri``): about ``1e-7 cond(W)`` in single precision, where the inverse by halves
    (:func:`spd_inverse`, about half the time) can be 100 times farther off: the second way of
    :func:`checked_inverse`.

    Raises
    ------
    numpy.linalg.LinAlgError
        ``W`` is not positive definite in ``precision``."""
    scaled, scale = scaled_matrix(w_mat, precision)
    return _unscaled(_at_once(scaled, FACTOR_STAGES), scale)


def scaled_matrix(w_mat: np.ndarray, precision) -> tuple[np.ndarray, np.ndarray]:
    """``S W S`` in ``precision``, ``S = diag(W)^-1/2`` (a unit diagonal: Jacobi's scaling; a contact
    that just closed is soft, and the diagonal spans up to 1e6), and ``S_ii S_jj`` (double, exactly
    symmetric).

    Raises
    ------
    numpy.linalg.LinAlgError
        A diagonal entry of ``W`` is not positive: ``W`` is not positive definite."""
    diagonal = np.diagonal(w_mat)
    if not np.all(diagonal > 0.0):
        raise np.linalg.LinAlgError("W's diagonal is not positive")
    scale = 1.0 / np.sqrt(diagonal)
    scale = np.outer(scale, scale)
    return (w_mat * scale).astype(precision, copy=False), scale


def _unscaled(inverse: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """``S (S W S)^-1 S`` in double from the inverse of the scaled ``W`` (:func:`scaled_matrix`)."""
    out = inverse.astype(np.float64)
    out *= scale
    return out


def factor_inverse(w: np.ndarray) -> np.ndarray:
    """``X = L^-1`` (lower triangular) of the Cholesky factor ``L`` of ``w`` (symmetric positive
    definite), by halves as :data:`FACTOR_STAGES` form it: ``[[X11, 0], [-X22 L21 X11, X22]]``;
    LAPACK's factor and inverse at :data:`LEAF` rows or fewer."""
    n = w.shape[0]
    if n <= LEAF:
        return np.tril(np.linalg.inv(np.linalg.cholesky(w)))
    columns, x22 = _run_stages(w, FACTOR_STAGES[:-1])     # all but the join: X's blocks
    out = np.zeros_like(w)
    h = n // 2
    out[:, :h] = columns
    out[h:, h:] = x22
    return out


def _half_factor(w):
    """``X11``, the inverse Cholesky factor of ``A`` (``w = [[A, B^T], [B, D]]``) ..."""
    h = w.shape[0] // 2
    return (factor_inverse(w[:h, :h]),)


def _coupling_factor(w, x11):
    """... ``L21 = B X11^T`` ..."""
    h = w.shape[0] // 2
    return x11, w[h:, :h] @ x11.T


def _factor_schur(w, x11, l21):
    """... ``S = D - L21 L21^T`` (formed from ``L21``, whose error grows with the square root of
    ``A``'s condition, where :data:`STAGES` form it from ``A^-1``), exactly symmetric ..."""
    h = w.shape[0] // 2
    schur = w[h:, h:] - l21 @ l21.T
    return x11, l21, 0.5 * (schur + schur.T)


def _schur_factor(w, x11, l21, schur):
    """... ``X22``, the inverse Cholesky factor of ``S`` ..."""
    return x11, l21, factor_inverse(schur)


def _lower_columns(w, x11, l21, x22):
    """... ``X``'s first ``h`` columns ``[X11; X21]``, ``X21 = -X22 L21 X11`` ..."""
    h = w.shape[0] // 2
    columns = np.empty((w.shape[0], h), dtype=w.dtype)
    columns[:h] = x11
    columns[h:] = -(x22 @ (l21 @ x11))
    return columns, x22


def _factor_joined(w, columns, x22):
    """... and ``w^-1 = X^T X`` from them (its corners as symmetric products), exactly symmetric."""
    h = w.shape[0] // 2
    out = np.empty_like(w)
    corner = columns.T @ columns                 # X11^T X11 + X21^T X21
    out[:h, :h] = 0.5 * (corner + corner.T)
    out[:h, h:] = columns[h:].T @ x22            # X21^T X22
    out[h:, :h] = out[:h, h:].T
    corner = x22.T @ x22
    out[h:, h:] = 0.5 * (corner + corner.T)
    return (out,)


#: the stages of the inverse through the Cholesky factor (:func:`cholesky_inverse`), as :data:`STAGES`
#: are :func:`spd_inverse`'s: the way an inverse by halves that misses the check in single precision
#: is made again, spread over steps where the solve allows (:func:`advance_operator`)
FACTOR_STAGES = (_half_factor, _coupling_factor, _factor_schur, _schur_factor, _lower_columns, _factor_joined)
#: :data:`STAGE_WEIGHT` of :data:`FACTOR_STAGES` (in :data:`OPERATOR_PRECISION`; measured so,
#: ``python -m benchmarks operator --stages --method 1``): the inverse factors of the halves recurse down to
#: LAPACK's leaves (the first stage also scales ``W``), and the symmetric products run at about half a
#: general product's rate a counted flop
FACTOR_WEIGHT = (6.8, 0.43, 1.0, 3.6, 0.43, 1.1)
#: ... and in double precision (a pending operator of method 2; ``--method 2``)
FACTOR_WEIGHT_DOUBLE = (8.1, 0.97, 2.0, 5.0, 1.13, 2.2)
assert len(FACTOR_STAGES) == len(STAGES)                 # a pending operator is done after len(STAGES) of either


def method_precision(method: int):
    """The precision of the stages of a :class:`PendingOperator` of ``method``: :data:`OPERATOR_PRECISION`
    (0: by halves; 1: through the Cholesky factor), double (2: through the factor)."""
    return np.float64 if method == 2 else OPERATOR_PRECISION


def forming_work(rows: int) -> float:
    """The work of forming ``W`` on ``rows`` rows (gathering ``M_aa``, adding the springs'
    compliance), as :func:`stage_work` counts it: ``85 n^2`` (measured against the stages,
    ``python -m benchmarks operator --stages``)."""
    return 85.0 * rows * rows


@dataclass(frozen=True)
class PendingOperator:
    """A new reduced operator formed at an iterate and inverted over steps.

    Inverting ``W`` is about 1.5-2.5 ms on the pitch bearing (single or double precision,
    :data:`OPERATOR_PRECISION`), more than a whole step: made at
    once, it is what the slowest steps of a co-simulation spend (the 95th and 99th
    percentiles). :func:`start_operator` forms ``W`` and runs the first step's stages
    (:data:`SPREAD_STAGES`), :func:`advance_operator` the next; meanwhile the solver goes on
    with the operator it has (a modified Newton step: slower, as exact). ``stage``: the stages
    done, of :data:`STAGES` (``method`` 0: by halves) or of :data:`FACTOR_STAGES` (``method`` 1:
    through the Cholesky factor, ``W`` scaled: an inverse by halves that missed the check, made
    again; ``method`` 2: the same in double, where that missed it too), ``parts`` the last one's
    results (in :func:`method_precision`); ``scaled``: the matrix the stages take, ``matrix`` in
    :data:`OPERATOR_PRECISION` for method 0 (converted once, not at each step of stages: 0.1 ms a step
    of stages of the pitch bearing's operators), its
    :func:`scaled_matrix` for methods 1 and 2 (not part of the state: it follows from ``matrix``)."""

    rows: np.ndarray
    active: np.ndarray
    contact_compliance: np.ndarray
    matrix: np.ndarray
    stage: int
    parts: tuple
    method: int = 0
    scaled: tuple = ()

    def as_tuple(self) -> tuple:
        """The arrays (not copied), the stage and the method: a solver state to keep or serialise."""
        return (self.rows, self.active, self.contact_compliance, self.matrix, self.stage, self.method, *self.parts)

    @classmethod
    def from_tuple(cls, values) -> "PendingOperator":
        rows, active, a_inv, matrix, stage, method, *parts = values
        return cls(*(np.asarray(v) for v in (rows, active, a_inv, matrix)), int(stage),
                   tuple(np.asarray(v) for v in parts), int(method))


def start_operator(point, compliance, stiffness, active, arithmetic: "OperatorArithmetic | None" = None,
                   until: int | None = None) -> PendingOperator:
    """Form ``W = (A^-1 + M)_aa`` on the ``active`` diagonals at an iterate (:func:`operator_matrix`)
    and run the stages of its inverse up to ``until`` (default: the first step's, :func:`advance_operator`)."""
    rows, a_inv, w_mat = _arithmetic(arithmetic).form(point, compliance, stiffness, active)
    return advance_operator(PendingOperator(rows, active, a_inv, w_mat, 0, ()), None, None, arithmetic, until=until)


def operator_matrix(point, compliance, stiffness, active):
    """The rows of the ``active`` diagonals, the springs' compliance ``A^-1`` there (k, 2, 2) at an
    iterate (:func:`contact_compliance_blocks`) and ``W = (A^-1 + M)_aa`` (``M`` the rings';
    symmetric positive definite)."""
    rows = np.flatnonzero(np.repeat(active, 2))
    a_inv = contact_compliance_blocks(point, stiffness, active)
    w_mat = np.asarray(compliance).take(rows, axis=0).take(rows, axis=1)   # M_aa (3x faster than np.ix_)
    _add_blocks(w_mat, a_inv)
    return rows, a_inv, w_mat


def advance_operator(pending: PendingOperator, jacobian, mu, arithmetic: "OperatorArithmetic | None" = None,
                     until: int | None = None, again: bool = False) -> "PendingOperator | ReducedOperator":
    """The stages up to ``until`` (default: the end of this step's, :data:`SPREAD_STAGES`), of
    :data:`STAGES` (of :data:`FACTOR_STAGES` for ``pending.method`` 1 and 2); after the last, the operator
    with its coupling to the Jacobian (4B, 5) of now (``jacobian`` None: the pending operator,
    inverted). A ``W`` of :data:`LEAF` rows or fewer is inverted in one stage. The stages run in
    :func:`method_precision`; the inverse, once done, is checked (:func:`checked_inverse`) and
    kept as :func:`kept_precision` keeps it. An inverse that misses the check is made again through
    the Cholesky factor: with ``again``, as a pending operator of the next method at stage 0 (by
    halves: 1, in single precision; 1: 2, in double), whose stages the next calls run (a solve that
    can go on without it, or a bounded one: spread over steps as any new operator); else at once. A
    ``W`` singular in single precision (the preload's alone, condition 4e13 on the yaw bearing) is
    made again so in double (method 2): with ``again`` spread, else at once (:func:`checked_inverse`)."""
    if until is None:
        until = step_end(pending)
    if pending.stage < until:
        try:
            if not pending.scaled:           # the matrix the stages take, made on the first of them
                pending = replace(pending, scaled=scaled_matrix(pending.matrix, method_precision(pending.method))
                                  if pending.method else (pending.matrix.astype(OPERATOR_PRECISION, copy=False),))
            w_mat = pending.scaled[0]
            if pending.matrix.shape[0] <= LEAF:
                pending = replace(pending, stage=len(STAGES), parts=(spd_inverse(w_mat),))
            else:
                stages = (FACTOR_STAGES if pending.method else STAGES)[pending.stage:until]
                pending = replace(pending, stage=until, parts=_run_stages(w_mat, stages, pending.parts))
        except np.linalg.LinAlgError:        # singular in its precision (single): made again in double,
            if again and method_precision(pending.method) != np.float64:     # spread where it can be
                return replace(pending, stage=0, parts=(), method=2, scaled=())
            pending = replace(pending, stage=len(STAGES), parts=(None,))     # else at once
        if pending.stage == len(STAGES):
            inverse = pending.parts[0]
            if inverse is not None:          # as made (W^-1 = S (S W S)^-1 S in double for the factor's), checked
                inverse = _unscaled(inverse, pending.scaled[1]) if pending.method else kept_precision(inverse)
                if not passes_check(pending.matrix, inverse, arithmetic):
                    if again and method_precision(pending.method) != np.float64:
                        return replace(pending, stage=0, parts=(), method=pending.method + 1, scaled=())
                    inverse = None
            if inverse is None:
                inverse = checked_inverse(pending.matrix, pending.method, arithmetic)
            pending = replace(pending, parts=(inverse,), scaled=())
    if pending.stage < len(STAGES) or jacobian is None:
        return pending
    return reduced_operator(pending.rows, pending.active, pending.contact_compliance, pending.parts[0], jacobian, mu,
                            arithmetic)


#: how far ``W X v`` may be from ``v`` for a probe vector ``v`` (relative, largest entry) before an
#: inverse ``X`` computed in :data:`OPERATOR_PRECISION` is computed again, more exactly
#: (:func:`checked_inverse`): about the contraction an iteration of the step in increments keeps on
#: account of the inverse. Measured in single precision: a median of 2e-3 (pitch and yaw bearings
#: under load) up to 0.036 (pitch), with the same Newton iterations a step as in double (NREL 4.69
#: against 4.68); the yaw bearing's first operator after a start at zero loads 0.48
INVERSE_CHECK = 0.1


def checked_inverse(w_mat: np.ndarray, method: int = 0, arithmetic: "OperatorArithmetic | None" = None
                    ) -> np.ndarray:
    """The inverse of ``W`` (``w_mat``, double) in double precision, made again where the one
    :class:`PendingOperator`'s ``method`` made (by :func:`spd_inverse` in :data:`OPERATOR_PRECISION`, or
    through the Cholesky factor) missed the check (:func:`passes_check`) or ``W`` was singular in its
    precision: through the Cholesky factor (:func:`cholesky_inverse`) in single precision and then in
    double (the methods after ``method``), each checked, and last by LAPACK's ``inv`` in double.

    In single precision an inverse is within about ``1e-7 cond(W)`` of ``W``'s, and the operators
    under load are conditioned 4e3-1e8 here. By halves (:func:`spd_inverse`) the errors compound from
    level to level: after a moment reversal the pitch bearing's operators (condition 5e4-8e4) missed
    the check by far (probe residuals 0.24-1.5), a few times in a thousand steps, and each was inverted
    again by LAPACK in double, 4-19 ms, the slowest steps of the bounded scenarios. Through the factor,
    scaled to a unit diagonal, single precision gives 0.004-0.007 for them (one of condition 1e8:
    0.05) in about twice the time of an inverse by halves, a third to a half of LAPACK's in double;
    what it misses, double precision gives to about ``1e-16 cond(W)``. ``W`` of the preload alone (the yaw bearing at zero loads: condition 4e13) is
    singular in single precision; LAPACK's ``inv`` is the last resort for a ``W`` the Cholesky factor
    refuses in double too."""
    for precision in dict.fromkeys(method_precision(m) for m in range(method + 1, 3)):
        try:
            inverse = cholesky_inverse(w_mat, precision)
        except np.linalg.LinAlgError:       # not positive definite in this precision
            continue
        if passes_check(w_mat, inverse, arithmetic):
            return inverse
    return _lapack_inverse(w_mat)


def passes_check(w_mat: np.ndarray, inverse: np.ndarray, arithmetic: "OperatorArithmetic | None" = None) -> bool:
    """Whether ``W inverse v`` is within :data:`INVERSE_CHECK` of ``v`` for the probe
    ``v = (1, 1.125, ..., 1.75, 1, ...)`` (relative to its largest entry); ``inverse v`` summed in double
    (``arithmetic.product``, :func:`inverse_product`)."""
    probe = 1.0 + 0.125 * (np.arange(w_mat.shape[0]) % 7)
    product = _arithmetic(arithmetic).product(inverse, probe[None, :])[0]
    return float(np.abs(w_mat @ product - probe).max()) <= INVERSE_CHECK * float(probe.max())


def _lapack_inverse(w_mat: np.ndarray) -> np.ndarray:
    """LAPACK's inverse, made exactly symmetric."""
    inverse = np.linalg.inv(w_mat)
    return 0.5 * (inverse + inverse.T)


def step_end(pending: PendingOperator) -> int:
    """Where the pending operator's next step of stages ends (:data:`SPREAD_STAGES`)."""
    return next((end for end in SPREAD_STAGES if end > pending.stage), len(STAGES))


def complete_operator(pending: PendingOperator, jacobian, mu, arithmetic: "OperatorArithmetic | None" = None
                      ) -> ReducedOperator:
    """The remaining stages at once."""
    return advance_operator(pending, jacobian, mu, arithmetic, until=len(STAGES))


def assemble_operator(point, compliance, stiffness, jacobian, active, mu,
                      arithmetic: "OperatorArithmetic | None" = None) -> ReducedOperator:
    """Form and invert ``W = (A^-1 + M)_aa`` on the ``active`` diagonals at an iterate: O(n^3)."""
    return complete_operator(start_operator(point, compliance, stiffness, active, arithmetic), jacobian, mu,
                             arithmetic)


def update_operator(op: ReducedOperator, point, compliance, stiffness, jacobian, active, mu,
                    arithmetic: "OperatorArithmetic | None" = None) -> ReducedOperator | None:
    """Follow contacts that closed by bordering the kept ``W^-1``; contacts that opened stay.

    A diagonal that opened keeps its row in the operator with the stiffness it had when the
    operator was formed, until the next fresh one: a modified Newton step whose fixed point is
    the same, since the step's row of that contact, ``A^-1 (y_new - f) + (M dy) - J dq = 0``,
    holds at the equilibrium with ``y = f = 0``. Its stiffness is that of when the operator
    was formed, maybe some steps earlier: where it slows the iteration, the solve's refresh
    rule forms a new operator. Dropping it would cost a pass over ``W^-1`` that, as the ring
    turns, a contact closing again soon after would undo (measured on the pitch bearing's
    steps: updates 0.93 -> 0.28 a step).

    A diagonal that closed must enter: its force is zero outside the operator's rows. With
    ``B = M`` (kept rows, new rows), ``C = (A^-1 + M)`` on the new rows, ``X = W^-1 B`` and
    ``S = (C - B^T X)^-1``, ``W_new^-1 = [[W^-1 + X S X^T, -X S], [-S X^T, S]]``: O(n^2 r) for
    ``r`` new rows instead of O(n^3). The new rows come after the kept ones (the operator's
    rows are in the order they entered), and the coupling follows by the same blocks:
    ``W_new^-1 J_new = [W^-1 J - X S d, S d]``, ``d = J_r - X^T J``, with ``op`` turned to
    ``jacobian`` first (:func:`turned_operator`; where it was turned nearly, the kept rows keep the
    Jacobian their coupling is for). Returns None (form anew) when more than a quarter of the rows
    would be new. The blocks are :func:`bordered_inverse`'s."""
    closed = active & ~op.active
    new_rows = np.flatnonzero(np.repeat(closed, 2))
    if not borders(op, new_rows.size):
        return None
    rows = np.concatenate([op.rows, new_rows])
    new_a_inv = contact_compliance_blocks(point, stiffness, closed)
    b_mat = compliance.entries(op.rows, new_rows)            # M (kept rows, new rows), M (new, new):
    c_mat = compliance.entries(new_rows, new_rows)           # BlockCirculant.entries
    _add_blocks(c_mat, new_a_inv)
    new_jacobian = jacobian.reshape(-1, 5)[new_rows]
    inverse, coupling, schur_inverse = _arithmetic(arithmetic).border(
        op.inverse, b_mat, c_mat, op.jacobian, op.coupling, new_jacobian, mu)        # in the precision it had
    # the kept rows keep the Jacobian their coupling is for (a nearly turned one: turned_operator)
    return ReducedOperator(rows, op.active | closed, np.concatenate([op.contact_compliance, new_a_inv]), inverse,
                           np.concatenate([op.jacobian, new_jacobian]), coupling, schur_inverse)


#: bordering declines where more than this share of the kept rows would be new (a new operator is due)
BORDER_SHARE = 0.25


def borders(op: ReducedOperator, rows: int) -> bool:
    """Whether :func:`update_operator` borders ``rows`` new rows onto ``op`` (else it declines)."""
    return rows <= BORDER_SHARE * op.rows.size


def bordering_work(rows: int, kept_rows: int) -> float:
    """The work of bordering ``r = rows`` onto ``n = kept_rows`` (:func:`bordered_inverse`), as
    :func:`stage_work` counts it: ``X = W^-1 B`` and ``X S X^T``, ``2 n^2 r`` each, ``B^T X`` and ``X S``,
    ``2 n r^2`` each, ``S``'s inverse by LAPACK, ``6 r^3``, and the new matrix and coupling, ``120 (n + r)^2``
    (``python -m benchmarks operator --border``); the ``n^2 r`` products weighted 1.25 (``5 n^2 r``) for the
    passes of ``X S X^T``."""
    n, r = kept_rows, rows
    return 5.0 * n * n * r + 4.0 * n * r * r + 6.0 * r ** 3 + 120.0 * (n + r) ** 2


#: rows of ``W^-1`` :func:`bordered_inverse` converts to double at a time (a buffer of 64 x 400-480 doubles,
#: 0.2 MB). Inside the pitch bearing's NREL steps 3-6 from the start values (16-30 rows onto 402-476), a
#: bordering by numpy took 1.2-2.4 ms with the whole inverse converted and the product added whole, 1.1-1.3
#: ms by blocks (128 rows: no faster than whole)
BORDER_BLOCK = 64


def bordered_inverse(inverse, b_mat, c_mat, jacobian, coupling, new_jacobian, mu):
    """``W^-1`` (n, n) bordered by ``r`` rows (:func:`update_operator`): with ``X = W^-1 B`` (``b_mat``
    (n, r)) and ``S = (C - B^T X)^-1`` (``c_mat`` (r, r)), the new inverse
    ``[[W^-1 + X S X^T, -X S], [-S X^T, S]]``, its coupling ``[W^-1 J - X S d, S d]`` with
    ``d = J_r - X^T J`` (``coupling = W^-1 J`` (n, 5), ``jacobian = J``, ``new_jacobian = J_r``
    (r, 5)) and the new Schur complement's inverse ``(J_new^T W_new^-1 J_new + mu I)^-1``. The blocks
    are summed in double, the new inverse stored in ``W^-1``'s precision (:func:`kept_precision`).

    ``W^-1`` is read by blocks of :data:`BORDER_BLOCK` rows, each converted to double in one buffer, for
    ``X`` and again for ``W^-1 + X S X^T``: two reads of it and one write of the new inverse, where
    converting it whole and adding the product whole made several passes over newly allocated matrices
    of its size."""
    stored = inverse.dtype
    n, r = b_mat.shape
    x_mat = np.empty((n, r))
    buffer = np.empty((min(BORDER_BLOCK, n), n))
    for start in range(0, n, BORDER_BLOCK):
        rows = slice(start, min(start + BORDER_BLOCK, n))
        part = buffer[:rows.stop - start]
        part[...] = inverse[rows]
        np.matmul(part, b_mat, out=x_mat[rows])             # X = W^-1 B, by rows
    schur = np.linalg.inv(c_mat - b_mat.T @ x_mat)
    schur = 0.5 * (schur + schur.T)
    xs = x_mat @ schur
    bordered = np.empty((n + r, n + r), dtype=stored)
    x_t = np.ascontiguousarray(x_mat.T)
    for start in range(0, n, BORDER_BLOCK):
        rows = slice(start, min(start + BORDER_BLOCK, n))
        part = buffer[:rows.stop - start]
        np.matmul(xs[rows], x_t, out=part)
        part += inverse[rows]                                # W^-1 + X S X^T, summed in double
        bordered[rows, :n] = part
    bordered[:n, n:] = -xs
    bordered[n:, :n] = -xs.T
    bordered[n:, n:] = schur
    d = new_jacobian - x_mat.T @ jacobian
    new_coupling = np.concatenate([coupling - xs @ d, schur @ d])
    ja = np.concatenate([jacobian, new_jacobian])
    return bordered, new_coupling, np.linalg.inv(ja.T @ new_coupling + mu * np.eye(5))


def newton_step(op: ReducedOperator, point, f_scaled: np.ndarray, off_motion: np.ndarray | None = None):
    """The (modified) Newton step with the kept operator: ``dq`` (5,) and the contact forces
    after the step ``y`` (4B,), zero on the open contacts.

    ``point`` has the spring forces ``force`` (B, 2, 2) and the forces felt by the rings ``y``
    (4B,); ``off_motion`` is ``M y_off`` (4B,), the rings' motion under the forces ``y`` has off the
    operator's rows, where there are any (``None``: ``y`` is zero there).

    The step is solved in increments: with ``W = (A^-1 + M)_aa``, the system's first row
    ``W y_new = A^-1 f_a + (M y)_a`` is ``W (y_new - y)_a = A^-1 (f - y)_a + (M y_off)_a``, so
    ``y_new = y_a + W^-1 (A^-1 (f - y)_a + (M y_off)_a) + W^-1 J_a dq``. Equal in exact arithmetic,
    but the steps' fixed point, ``f = y`` on the operator's rows, no longer depends on ``W^-1``
    being ``W``'s inverse to round-off: an approximate one (single precision,
    :data:`OPERATOR_PRECISION`) costs a few iterations' contraction, not the answer's accuracy."""
    diagonals = op.rows[::2] // 2
    mismatch = point.force.reshape(-1, 2)[diagonals] - point.y.reshape(-1, 2)[diagonals]
    rhs = (op.contact_compliance @ mismatch[..., None]).ravel()
    if off_motion is not None:
        rhs = rhs + off_motion[op.rows]
    if op.inverse.dtype == np.float32:
        w_vec = point.y[op.rows] + single_product(op.inverse, rhs)
    else:
        w_vec = point.y[op.rows] + inverse_product(op.inverse, rhs[None, :])[0]
    dq = op.schur_inverse @ (f_scaled - op.jacobian.T @ w_vec)
    y_new = np.zeros_like(point.y)
    y_new[op.rows] = w_vec + op.coupling @ dq
    return dq, y_new


def off_rows(op: ReducedOperator, y: np.ndarray) -> np.ndarray | None:
    """``y`` (4B,) with the operator's rows zeroed, ``None`` where nothing is left (the forces a
    fresh operator's rows leave out: :func:`newton_step`'s ``off_motion`` is their ring motion)."""
    if not y.any():
        return None
    y_off = np.where(np.repeat(op.active, 2), 0.0, y)
    return y_off if y_off.any() else None


@dataclass(frozen=True)
class OperatorArithmetic:
    """Who does the reduced operator's arithmetic: this module's numpy functions
    (:data:`NUMPY_ARITHMETIC`), or the same as compiled loops
    (:data:`slewing_model.distribution.kernel.COMPILED_ARITHMETIC`); the functions above take it as
    ``arithmetic`` (default numpy)."""

    form: object        # operator_matrix
    couple: object      # operator_coupling
    turn: object        # column_turn
    border: object      # bordered_inverse
    step: object        # newton_step
    product: object     # inverse_product


#: this module's numpy functions
NUMPY_ARITHMETIC = OperatorArithmetic(operator_matrix, operator_coupling, column_turn, bordered_inverse, newton_step,
                                      inverse_product)


def _arithmetic(arithmetic: OperatorArithmetic | None) -> OperatorArithmetic:
    return NUMPY_ARITHMETIC if arithmetic is None else arithmetic
