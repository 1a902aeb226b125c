"""The loops of the load distribution, compiled with numba where it is installed.

A co-simulation step of :mod:`slewing_model.distribution.bime` assembles the bearing at the new rotation,
runs a few Newton iterations, each a step with the kept reduced ring operator
(:mod:`slewing_model.rings.reduced_operator`) and a trial point on the search line, sometimes forms,
borders or turns that operator, and reports the contacts of the solution. With numpy each of
these is some ten to fifty array operations on a few hundred entries, whose call overhead, not
their arithmetic, sets the time. The loops here are the same formulas, most in the same order
of operations, one loop each:

* a new rotation: the rings' error tables interpolated and added to the grooves
  (:func:`_add_groove_errors`), the Jacobian of eq 23
  (:func:`_jacobian`);
* an iteration: the trial point, its springs (eqs 1, 7, 8) and stop-rule terms
  (:func:`_trial_point`), the modified Newton step (:func:`_newton_step`); and the iterations
  that keep the reduced operator as they are, one after the other in one loop
  (:func:`_kept_iterations`, with the ring compliance's product :func:`_ring_times`: numba has
  no FFT, so by a real DFT with tables); the rigid model's iterations, which also start a
  flexible solve after a jump of the loads with the rings held (:func:`_rigid_solve`);
* the operator (:data:`COMPILED_ARITHMETIC`, numpy's :data:`slewing_model.rings.reduced_operator.NUMPY_ARITHMETIC`):
  formed (:func:`_operator_matrix`), coupled to the ring's motions (:func:`_operator_coupling`),
  turned with the ring (:func:`_column_turn`), bordered by contacts that close
  (:func:`_bordered_inverse`);
* the result: the contacts' loads, angles, Hertz ellipses and edge checks
  (:func:`_contact_results`).

Where a loop sums ``W^-1 v`` it does so column by column (``W^-1`` symmetric), which differs from
numpy's row sums by round-off; the Newton step's product with a single-precision ``W^-1`` is partly
summed in single precision, the same operations in both paths (:func:`_single_times`; why:
docs/design-decisions.md, "The kept operator in single precision, and what it means").

numba is optional, as for the friction's loops (:mod:`slewing_model.friction.kernel`, whose
:func:`~slewing_model.friction.kernel.compile_all` compiles these too, and whose
``use_compiled`` rule chooses): without it the numpy code runs, with the same results to
round-off (``tests/test_contact_kernel.py``).
"""
from __future__ import annotations

import functools
import math

import numpy as np

from ..bearing.contact import _E_TABLE, _F_TABLE, _LOG_KAPPA, effective_modulus
from ..numerics.compiled import compile_loop, loop_factory
from ..rings.reduced_operator import SINGLE_BLOCK, OperatorArithmetic
from ..rings.reduced_operator import bordered_inverse as _numpy_bordered_inverse

_TRIAL_SIGNATURE = ("Tuple((f8[:], f8[:], f8[:], f8[:, :, :], f8[:, :], f8[:, :], f8[:, :, :], f8[:, :, :], "
                    "f8[:, :], f8[:], f8[:], b1[:], f8[:]))(f8[:, :, :], f8[:, :], f8[:], f8[:], f8[:], f8[:], f8[:], "
                    "f8[:], f8, f8[:, :], f8[:, :], f8[:], f8)")


def _trial_point(separation, jacobian_rows, qs, dq, y, dy, ring_motion, ring_motion_step, t, natural_length,
                 stiffness, f_scaled, loaded_from):
    """The flexible model's springs at the trial point ``(qs + t dq, y + t dy)`` of a line search,
    with the ring motion ``M y`` there (``ring_motion + t ring_motion_step``, linear in ``t``), and
    what the solver's stop rule and line search ask of it: the formulas of
    ``BimeSolver._evaluate`` (:mod:`slewing_model.distribution.bime`).

    ``e = separation + J qs - M y`` (``jacobian_rows`` (4B, 5)), ``delta = |e| - l_N`` (eq 7),
    ``q = K max(delta, 0)^1.5`` (eq 8), the springs' energy ``sum 2/5 q max(delta, 0)`` (eq 1),
    the rings' ``1/2 y . M y`` (eq 15) and the load's work ``F . qs``; the gradient on the moving
    ring ``J^T f - F`` and the mismatch ``f - y`` of the Hertz forces and those the rings feel.

    Returns ``qs``, ``y``, ``M y`` at the trial point, ``e``, ``delta``, ``q``, the force vectors
    ``f`` and unit vectors ``n`` (B, 2, 2), the lengths ``|e|``, the gradient (5,), the mismatch
    (4B,), the loaded diagonals (2B,; ``delta > loaded_from``) and ``(springs' energy, rings'
    energy, work, largest force, largest residual, loaded diagonals)``, the largest force over
    ``q`` and ``|y|``, the largest residual over the gradient and mismatch.

    Three passes over the springs: ``e``; then each spring's length, direction and force; then the
    sums, in the order of one pass (so the same numbers bit for bit), the gradient's five in locals.
    Apart, the first two carry no chain of sums, whose latency held the one pass: 33 -> 26 us (pitch
    bearing, hot)."""
    n_balls = separation.shape[0]
    qs_t = qs + t * dq
    y_t = y + t * dy
    motion_t = ring_motion + t * ring_motion_step
    e = np.empty((n_balls, 2, 2))
    delta = np.empty((n_balls, 2))
    q = np.empty((n_balls, 2))
    force = np.empty((n_balls, 2, 2))
    n = np.empty((n_balls, 2, 2))
    length = np.empty((n_balls, 2))
    gradient = -f_scaled
    mismatch = np.empty(y.size)
    loaded = np.empty(2 * n_balls, np.bool_)
    x0, x1, x2, x3, x4 = qs_t[0], qs_t[1], qs_t[2], qs_t[3], qs_t[4]
    for b in range(n_balls):                        # e = separation + J qs - M y
        for d in range(2):
            row = 4 * b + 2 * d
            for c in range(2):
                motion = 0.0
                motion += jacobian_rows[row + c, 0] * x0
                motion += jacobian_rows[row + c, 1] * x1
                motion += jacobian_rows[row + c, 2] * x2
                motion += jacobian_rows[row + c, 3] * x3
                motion += jacobian_rows[row + c, 4] * x4
                e[b, d, c] = separation[b, d, c] + motion - motion_t[row + c]
    for b in range(n_balls):                        # |e|, n, delta (eq 7), q (eq 8), f = q n
        for d in range(2):
            e_r, e_z = e[b, d, 0], e[b, d, 1]
            size = math.sqrt(e_r ** 2 + e_z ** 2)
            length[b, d] = size
            n_r, n_z = e_r / size, e_z / size
            n[b, d, 0] = n_r
            n[b, d, 1] = n_z
            delta[b, d] = size - natural_length[b, d]
            closed = max(delta[b, d], 0.0)
            q[b, d] = stiffness[b, d] * (closed * math.sqrt(closed))
            force[b, d, 0] = q[b, d] * n_r
            force[b, d, 1] = q[b, d] * n_z
    g0, g1, g2, g3, g4 = gradient[0], gradient[1], gradient[2], gradient[3], gradient[4]
    n_loaded = 0
    energy = ring = 0.0
    peak_force = peak_residual = 0.0
    for b in range(n_balls):                        # the sums
        for d in range(2):
            row = 4 * b + 2 * d
            loaded[2 * b + d] = delta[b, d] > loaded_from
            n_loaded += loaded[2 * b + d]
            closed = max(delta[b, d], 0.0)
            energy += q[b, d] * closed
            peak_force = max(peak_force, q[b, d])
            for c in range(2):
                f = force[b, d, c]
                g0 += jacobian_rows[row + c, 0] * f
                g1 += jacobian_rows[row + c, 1] * f
                g2 += jacobian_rows[row + c, 2] * f
                g3 += jacobian_rows[row + c, 3] * f
                g4 += jacobian_rows[row + c, 4] * f
                mismatch[row + c] = f - y_t[row + c]
                ring += y_t[row + c] * motion_t[row + c]
                peak_force = max(peak_force, abs(y_t[row + c]))
                peak_residual = max(peak_residual, abs(mismatch[row + c]))
    gradient[0], gradient[1], gradient[2], gradient[3], gradient[4] = g0, g1, g2, g3, g4
    work = 0.0
    for k in range(5):
        work += f_scaled[k] * qs_t[k]
        peak_residual = max(peak_residual, abs(gradient[k]))
    if not math.isfinite(ring + work + gradient.sum() + mismatch.sum()):
        peak_residual = math.nan           # as numpy's max: a NaN is never converged
    return (qs_t, y_t, motion_t, e, delta, q, force, n, length, gradient, mismatch, loaded,
            np.array([0.4 * energy, 0.5 * ring, work, peak_force, peak_residual, n_loaded]))


def _symmetric_times(matrix, vectors):
    """``(M V)^T`` (k, n) for a symmetric ``M`` (n, n; double or single precision) and ``V^T = vectors``
    (k, n), summed in double column by column, ``sum_j v_j M_j`` with ``M``'s rows for its columns: a
    loop of vector operations, where a row's dot product is one chain of additions. ``M`` symmetric to round-off (a bordered
    ``W^-1``) gives ``M^T V``, which differs from ``M V`` by round-off.

    Four columns a pass, ``out += (M_j v_j + M_j+1 v_j+1) + (M_j+2 v_j+2 + M_j+3 v_j+3)``: ``out`` read and
    written once for four of ``M``'s rows, not for each (its passes, not ``M``'s, were the cost: 1.4 times
    faster for one vector of 370-460 rows, summed in double all the same)."""
    k, n = vectors.shape
    out = np.zeros((k, n))
    j = 0
    while j + 4 <= n:
        for m in range(k):
            v0, v1, v2, v3 = vectors[m, j], vectors[m, j + 1], vectors[m, j + 2], vectors[m, j + 3]
            for i in range(n):
                out[m, i] += (matrix[j, i] * v0 + matrix[j + 1, i] * v1) + (matrix[j + 2, i] * v2
                                                                            + matrix[j + 3, i] * v3)
        j += 4
    while j < n:                                   # the last rows, one by one
        for m in range(k):
            value = vectors[m, j]
            for i in range(n):
                out[m, i] += matrix[j, i] * value
        j += 1
    return out


def _single_times(matrix, vector):
    """``W^-1 v`` (n,) for a symmetric ``W^-1 = matrix`` kept in single precision (n, n) and ``v`` (n,):
    :func:`slewing_model.rings.reduced_operator.single_product`, the same operations in the same order.

    ``v`` rounded to single precision; per block of eight rows of ``W^-1`` (``SINGLE_BLOCK``; the last
    block what is left), ``s = M_j v_j + M_j+1 v_j+1 + ...``, each product and sum in single precision,
    added left to right; ``s`` added to the sum in double, block after block. Reading ``W^-1`` in its
    precision without converting each entry to double (``vcvtps2pd``, which set the product's time), eight
    single-precision lanes to a vector instead of four double ones, makes the product 0.45 as long
    (45 -> 21 us hot, 376 rows). The sum's rounding,
    about ``1e-7`` of ``|W^-1| |v|``, is of the size of the single-precision inverse's own error (about
    ``1e-7 cond(W)``): it changes the Newton direction, not the step's fixed point
    (:func:`_newton_step`, in increments)."""
    n = vector.size
    v = vector.astype(np.float32)
    out = np.zeros(n)
    j = 0
    while j < n:
        rows = min(SINGLE_BLOCK, n - j)
        if rows == SINGLE_BLOCK:                # a whole block: its pass written out for eight rows
            v0, v1, v2, v3 = v[j], v[j + 1], v[j + 2], v[j + 3]
            v4, v5, v6, v7 = v[j + 4], v[j + 5], v[j + 6], v[j + 7]
            for i in range(n):
                s = (matrix[j, i] * v0 + matrix[j + 1, i] * v1 + matrix[j + 2, i] * v2 + matrix[j + 3, i] * v3
                     + matrix[j + 4, i] * v4 + matrix[j + 5, i] * v5 + matrix[j + 6, i] * v6
                     + matrix[j + 7, i] * v7)
                out[i] += s
        else:                                  # the last rows
            for i in range(n):
                s = matrix[j, i] * v[j]
                for r in range(1, rows):
                    s += matrix[j + r, i] * v[j + r]
                out[i] += s
        j += rows
    return out



_NEWTON_SIGNATURE = ("Tuple((f8[:], f8[:]))(f8[:, ::1], f4[:, ::1], f8[:, :, :], i8[:], f8[:, :], f8[:, :], "
                     "f8[:, :], f8[:], f8[:], f8[:], f8[:])")


def _newton_step(inverse, single_inverse, contact_compliance, rows, jacobian, coupling, schur_inverse, force, y,
                 off_motion, f_scaled):
    """The modified Newton step with a kept reduced operator, in increments: ``dq`` (5,) and the
    contact forces after the step (``y.size``,), zero off the operator's ``rows``: the formulas of
    :func:`slewing_model.rings.reduced_operator.newton_step` (``force``, ``y`` and ``off_motion``, the
    ring motion of ``y`` off the rows or zeros, flat, (4B,)).

    ``W^-1`` is ``inverse`` (double) or, where that is empty, ``single_inverse``
    (:func:`slewing_model.rings.reduced_operator.kept_precision`; :func:`product_inverses`);
    ``W^-1 rhs`` is summed in double, column by column (:func:`_symmetric_times`), or for the single
    inverse partly in single precision (:func:`_single_times`)."""
    n = rows.size
    rhs = np.empty(n)
    for k in range(n // 2):                 # A^-1 (f - y) of each diagonal, + (M y_off) on its rows
        r0, r1 = rows[2 * k], rows[2 * k + 1]
        diagonal = r0 // 2
        m0, m1 = force[2 * diagonal] - y[r0], force[2 * diagonal + 1] - y[r1]
        for c in range(2):
            rhs[2 * k + c] = (contact_compliance[k, c, 0] * m0 + contact_compliance[k, c, 1] * m1
                              + off_motion[rows[2 * k + c]])
    if inverse.shape[0] == n:
        w = _symmetric_times(inverse, rhs.reshape(1, n))[0]
    else:
        w = _single_times(single_inverse, rhs)
    for i in range(n):
        w[i] += y[rows[i]]
    t = f_scaled.copy()                     # F - J_a^T w
    for i in range(n):
        for c in range(5):
            t[c] -= jacobian[i, c] * w[i]
    dq = np.zeros(5)
    for r in range(5):
        for c in range(5):
            dq[r] += schur_inverse[r, c] * t[c]
    y_new = np.zeros(y.size)
    for i in range(n):
        value = w[i]
        for c in range(5):
            value += coupling[i, c] * dq[c]
        y_new[rows[i]] = value
    return dq, y_new


def _off_motion(rows, op_active, y, cos_table, sin_table, harmonic_real, harmonic_imag):
    """The rings' motion ``M y_off`` (``y.size``,) under the forces ``y`` has off the operator's diagonals
    ``op_active`` (zeros where it has none): :func:`_newton_step`'s ``off_motion``."""
    y_off = np.zeros(y.size)
    found = False
    for i in range(y.size):
        if not op_active[i // 2] and y[i] != 0.0:
            y_off[i] = y[i]
            found = True
    if not found:
        return y_off
    return _ring_times(cos_table, sin_table, harmonic_real, harmonic_imag, y_off)


_TURN_SIGNATURE = "Tuple((b1, f8[:, :], f8[:, :], f8[:, :]))(f8[:, :], f8[:, :], f8[:, :], f8, f8)"


def _solve_small(a, b):
    """``a^-1 b`` for a small square ``a`` (m, m) and ``b`` (m, k): Gaussian elimination with
    partial pivoting (as LAPACK's ``gesv``); and False where ``a`` is singular. The friction's
    ``_solve3`` (:mod:`slewing_model.friction.kernel`) is the same elimination for 3 x 3, kept
    apart: on this general one the balls' minimisation took 17 % longer (measured)."""
    m, k = b.shape
    work = np.empty((m, m + k))
    work[:, :m] = a
    work[:, m:] = b
    for col in range(m):
        pivot = col
        for r in range(col + 1, m):
            if abs(work[r, col]) > abs(work[pivot, col]):
                pivot = r
        if work[pivot, col] == 0.0:
            return False, work[:, m:]
        if pivot != col:
            for c in range(col, m + k):
                work[col, c], work[pivot, c] = work[pivot, c], work[col, c]
        for r in range(col + 1, m):
            factor = work[r, col] / work[col, col]
            for c in range(col, m + k):
                work[r, c] -= factor * work[col, c]
    x = np.empty((m, k))
    for j in range(k):
        for r in range(m - 1, -1, -1):
            value = work[r, m + j]
            for c in range(r + 1, m):
                value -= work[r, c] * x[c, j]
            x[r, j] = value / work[r, r]
    return True, x


def _column_turn(old, new, coupling, mu, tolerance):
    """:func:`slewing_model.rings.reduced_operator.column_turn` as one compiled loop: whether a turn
    ``T`` (``old T`` fitted to ``new`` by least squares, to 1e-12, or to ``tolerance``) exists,
    the coupling ``coupling T``, ``(J^T coupling T + mu I)^-1`` and the Jacobian ``J`` they are
    for (``new``, or ``old T`` where the fit is not exact)."""
    n = old.shape[0]
    normal, right = np.zeros((5, 5)), np.zeros((5, 5))           # old^T old, old^T new
    for i in range(n):
        for r in range(5):
            for c in range(5):
                normal[r, c] += old[i, r] * old[i, c]
                right[r, c] += old[i, r] * new[i, c]
    found, turn = _solve_small(normal, right)
    empty = np.empty((0, 5))
    if not found:
        return False, empty, empty, empty
    fitted = np.empty((n, 5))                                     # old T
    worst = scale = total = 0.0
    for i in range(n):
        for c in range(5):
            value = 0.0
            for k in range(5):
                value += old[i, k] * turn[k, c]
            fitted[i, c] = value
            difference = abs(value - new[i, c])
            worst = max(worst, difference)
            total += difference                        # NaN or inf shows here, not in max
            scale = max(scale, abs(new[i, c]))
    if not (math.isfinite(total) and worst <= max(tolerance, 1e-12) * scale):   # NaN or inf: none, as numpy
        return False, empty, empty, empty
    jacobian = new if worst <= 1e-12 * scale else fitted
    turned = np.zeros((n, 5))
    for i in range(n):
        for k in range(5):
            value = coupling[i, k]
            for c in range(5):
                turned[i, c] += value * turn[k, c]
    found, schur_inverse = _schur_inverse(jacobian, turned, mu)
    if not found:
        return False, empty, empty, empty
    return True, turned, schur_inverse, jacobian


_JACOBIAN_SIGNATURE = "f8[:, :, :, :](f8[:], f8[:, :, :], f8, f8)"


def _jacobian(ball_angle, moving_centre, length, sign):
    """d(R, z of the moving groove centres)/d(X, Y, Z, L rx, L ry) (B, 2 diagonals, 2, 5) at the
    balls' angles, ``moving_centre`` (B, 2, 2) their (R, z), times the moving ring's ``sign``: the
    formulas of ``BimeSolver.set_rotation`` (eq 23), in the same order of operations."""
    n_balls = ball_angle.size
    jac = np.zeros((n_balls, 2, 2, 5))
    for b in range(n_balls):
        c, s = math.cos(ball_angle[b]), math.sin(ball_angle[b])
        for d in range(2):
            r, z = moving_centre[b, d, 0], moving_centre[b, d, 1]
            jac[b, d, 0, 0], jac[b, d, 0, 1] = sign * c, sign * s                        # R
            jac[b, d, 0, 3], jac[b, d, 0, 4] = sign * (-z * s / length), sign * (z * c / length)
            jac[b, d, 1, 2] = sign * 1.0                                                  # z
            jac[b, d, 1, 3], jac[b, d, 1, 4] = sign * (r * s / length), sign * (-r * c / length)
            jac[b, d, 0, 2] = jac[b, d, 1, 0] = jac[b, d, 1, 1] = sign * 0.0
    return jac


_BORDER_SIGNATURE = ("Tuple((b1, f8[:, :], f8[:, :]))(f8[:, ::1], f4[:, ::1], f8[:, :], f8[:, :], f8[:, :], "
                     "f8[:, :], f8[:, :], f8, f8[:, ::1], f4[:, ::1])")


def _bordered_inverse(inverse, single_inverse, b_mat, c_mat, jacobian, coupling, new_jacobian, mu, bordered,
                      single_bordered):
    """:func:`slewing_model.rings.reduced_operator.bordered_inverse` as one compiled loop: the same blocks,
    with ``W^-1 B`` summed column by column (:func:`_inverse_product`) and ``W^-1 + X S X^T``
    written in one pass over ``W^-1`` (numpy's product and sum take three, with a temporary the
    size of ``W^-1``).

    ``W^-1`` is ``inverse`` (double) or, where that is empty, ``single_inverse`` (:func:`_newton_step`);
    the new inverse is written into ``bordered``, or ``single_bordered`` (rounded), the one of the
    same precision ((n + r, n + r), the other empty). Returns whether the complements were regular,
    the new coupling and the new Schur complement's inverse."""
    n, r = b_mat.shape
    b_t = np.ascontiguousarray(b_mat.T)
    x_t = _inverse_product(inverse, single_inverse, b_t)                 # X^T = (W^-1 B)^T
    reduced = np.empty((r, r))                     # C - B^T X
    for k in range(r):
        for m in range(r):
            value = c_mat[k, m]
            for i in range(n):
                value -= b_mat[i, k] * x_t[m, i]
            reduced[k, m] = value
    found, schur = _solve_small(reduced, np.eye(r))
    empty = np.empty((0, 0))
    if not found:
        return False, empty, empty
    for k in range(r):                             # exactly symmetric
        for m in range(k + 1, r):
            schur[k, m] = schur[m, k] = 0.5 * (schur[k, m] + schur[m, k])
    xs = np.zeros((n, r))                          # X S
    for i in range(n):
        for k in range(r):
            for m in range(r):
                xs[i, k] += x_t[m, i] * schur[m, k]
    if inverse.shape[0] == n:
        _bordered_blocks(inverse, x_t, xs, schur, bordered)
    else:
        _bordered_blocks(single_inverse, x_t, xs, schur, single_bordered)
    d = np.empty((r, 5))                           # J_r - X^T J
    for k in range(r):
        for c in range(5):
            value = new_jacobian[k, c]
            for i in range(n):
                value -= x_t[k, i] * jacobian[i, c]
            d[k, c] = value
    new_coupling = np.zeros((n + r, 5))
    for i in range(n):
        for c in range(5):
            value = coupling[i, c]
            for k in range(r):
                value -= xs[i, k] * d[k, c]
            new_coupling[i, c] = value
    for k in range(r):
        for c in range(5):
            for m in range(r):
                new_coupling[n + k, c] += schur[k, m] * d[m, c]
    ja = np.empty((n + r, 5))                      # J_new
    ja[:n] = jacobian
    ja[n:] = new_jacobian
    found, schur_inverse = _schur_inverse(ja, new_coupling, mu)
    if not found:
        return False, empty, empty
    return True, new_coupling, schur_inverse


def _bordered_blocks(inverse, x_t, xs, schur, bordered):
    """``[[W^-1 + X S X^T, -X S], [-S X^T, S]]`` into ``bordered`` (of ``inverse``'s precision: each
    entry summed in double, then stored), :func:`_bordered_inverse`'s."""
    n, r = xs.shape
    row = np.empty(n)
    for i in range(n):
        for j in range(n):
            row[j] = inverse[i, j]
        for k in range(r):
            factor = xs[i, k]
            for j in range(n):
                row[j] += factor * x_t[k, j]
        for j in range(n):
            bordered[i, j] = row[j]
        for k in range(r):
            bordered[i, n + k] = -xs[i, k]
            bordered[n + k, i] = -xs[i, k]
    for k in range(r):
        for m in range(r):
            bordered[n + k, n + m] = schur[k, m]


_MATRIX_SIGNATURE = ("Tuple((f8[:, :, :], f8[:, :]))(f8[:, :, ::1], i8[:], f8[:, :], f8[:], f8[:], f8[:], f8[:])")


def _operator_matrix(blocks, rows, normal, delta, length, load, stiffness):
    """``A^-1`` (k, 2, 2) of the diagonals of ``rows`` (two a diagonal) and ``W = (A^-1 + M)_aa``:
    :func:`slewing_model.rings.reduced_operator.operator_matrix`'s formulas (``normal`` (2B, 2) and
    ``delta``, ``length``, ``load``, ``stiffness`` (2B,) of every diagonal), gathering ``M_aa``
    row by row from the block-circulant ``M``'s blocks (``blocks`` (B, m, m),
    :attr:`slewing_model.rings.compliance.BlockCirculant.blocks`: the same entries as the dense
    matrix's, read from 19 kB instead of 2.9 MB, which a step's other work has pushed out of the
    cache: a new operator's ``W`` was formed in 0.3-1.8 ms inside a step against 0.2 ms isolated)."""
    n = rows.size
    k = n // 2
    a_inv = np.empty((k, 2, 2))
    for j in range(k):
        d = rows[2 * j] // 2
        k_normal = 1.5 * stiffness[d] * math.sqrt(delta[d])
        across = length[d] / load[d]
        for r in range(2):
            for c in range(2):
                nn = normal[d, r] * normal[d, c]
                a_inv[j, r, c] = nn / k_normal + across * ((1.0 if r == c else 0.0) - nn)
    n_balls, m = blocks.shape[0], blocks.shape[1]
    ball = np.empty(n, np.int64)
    slot = np.empty(n, np.int64)
    for i in range(n):
        ball[i], slot[i] = rows[i] // m, rows[i] % m
    w = np.empty((n, n))
    for i in range(n):                                  # M[b m + r, c m + s] = C_((c - b) mod B)[r, s]
        for j in range(n):
            shift = ball[j] - ball[i]
            if shift < 0:
                shift += n_balls
            w[i, j] = blocks[shift, slot[i], slot[j]]
    for j in range(k):
        for r in range(2):
            for c in range(2):
                w[2 * j + r, 2 * j + c] += a_inv[j, r, c]
    return a_inv, w


_PRODUCT_SIGNATURE = "f8[:, :](f8[:, ::1], f4[:, ::1], f8[:, :])"


def _inverse_product(inverse, single_inverse, vectors):
    """``(W^-1 V)^T`` (k, n) for ``V^T = vectors`` (k, n), summed in double column by column
    (:func:`_symmetric_times`), ``W^-1`` ``inverse`` (double) or, where that is empty,
    ``single_inverse`` (:func:`product_inverses`): read in the precision it is kept in, not converted.
    The product of every loop with a kept operator's inverse (the Newton step, bordering, coupling)."""
    if inverse.shape[0] == vectors.shape[1]:
        return _symmetric_times(inverse, vectors)
    return _symmetric_times(single_inverse, vectors)


_COUPLING_SIGNATURE = "Tuple((f8[:, :], f8[:, :]))(f8[:, ::1], f4[:, ::1], f8[:, :], f8)"


def _operator_coupling(inverse, single_inverse, ja, mu):
    """:func:`slewing_model.rings.reduced_operator.operator_coupling` as one compiled loop: ``W^-1 J_a``
    (:func:`_inverse_product`; ``W^-1`` as there) and ``(J_a^T W^-1 J_a + mu I)^-1``, or an empty inverse
    where that is singular."""
    coupling = np.ascontiguousarray(_inverse_product(inverse, single_inverse, np.ascontiguousarray(ja.T)).T)
    found, schur_inverse = _schur_inverse(ja, coupling, mu)
    return coupling, schur_inverse if found else np.empty((0, 0))


def _schur_inverse(jacobian, coupling, mu):
    """``(J^T C + mu I)^-1`` for a Jacobian ``J`` and coupling ``C = W^-1 J`` (n, 5): the reduced
    operator's Schur complement, inverted by :func:`_solve_small` (False where singular)."""
    normal = mu * np.eye(5)
    for i in range(jacobian.shape[0]):
        for a in range(5):
            for c in range(5):
                normal[a, c] += jacobian[i, a] * coupling[i, c]
    return _solve_small(normal, np.eye(5))


def _segment(x, xp, guess):
    """The ``j`` with ``xp[j] <= x < xp[j + 1]`` for ``xp[0] <= x < xp[-1]`` (``guess`` first, then
    by bisection; one segment fits, so it is the one ``np.interp`` finds).

    The bisection halves the range ``[base, base + size)`` that holds ``j`` by moving its start or not:
    a choice LLVM makes without a branch, where ``lo, hi`` moved by an ``if`` mispredicted about half of
    its 13 steps in the 6001-row Hertz table (the contacts' results 114 -> 101 us hot, pitch
    bearing)."""
    last = xp.size - 1
    if 0 <= guess < last and xp[guess] <= x < xp[guess + 1]:
        return guess
    base, size = 0, last
    while size > 1:
        half = size // 2
        base = base + half if xp[base + half] <= x else base
        size -= half
    return base


def _interp(x, xp, fp, left, right, guess):
    """``np.interp(x, xp, fp, left, right)`` for one ``x``, in numpy's order of operations; the
    segment it fell in (``guess``: where to look first), or -1 outside the table."""
    last = xp.size - 1
    if x < xp[0]:
        return left, -1
    if x > xp[last]:
        return right, -1
    if x == xp[last]:
        return fp[last], -1
    j = _segment(x, xp, guess)
    if xp[j] == x:
        return fp[j], j
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    return slope * (x - xp[j]) + fp[j], j


#: the types of what :func:`_contact_results` takes of the bearing beside the springs' loads and vectors
#: (``BimeSolver._contact_arguments``): contact stiffness, ball diameters, groove radii, pitch diameter,
#: which contacts are inner, the modulus, the Hertz tables, the groove edges
_BEARING_CONTACT_TYPES = "f8[:, :], f8[:], f8[:, :], f8, b1[:], f8, f8[:], f8[:], f8[:], f8[:]"
_RESULTS_SIGNATURE = ("Tuple((f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], b1[:, :], i8))("
                      f"f8[:, :], f8[:, :, :], {_BEARING_CONTACT_TYPES})")


def _hertz_contact(q, dw, groove_radius, contact_angle, pitch_diameter, inner, modulus, f_table, log_kappa_table,
                   e_table):
    """Semi-axes ``a``, ``b`` and largest pressure of one loaded contact (``q > 0``): the formulas of
    :func:`slewing_model.bearing.contact.hertz_ellipse` (its tables of ``F(rho)``, ``log kappa`` and ``E``;
    ``modulus`` is ``E'``) with the curvatures of :func:`slewing_model.bearing.contact.raceway_curvatures`;
    ``inner``: the contact is on the inner ring."""
    last = e_table.size - 1
    gamma = dw * math.cos(contact_angle) / pitch_diameter
    if inner:
        rolling = 2.0 / dw * gamma / (1.0 - gamma)
    else:
        rolling = -2.0 / dw * gamma / (1.0 + gamma)
    transverse = -1.0 / groove_radius
    rho_ball = 2.0 / dw
    sum_rho = 2.0 * rho_ball + rolling + transverse
    f_rho = (rolling - transverse) / sum_rho
    # F(rho) -> log kappa, then E of it: the same segment of the tables but at its ends
    log_kappa, j = _interp(f_rho, f_table, log_kappa_table, 0.0, log_kappa_table[last], 0)
    kappa = math.exp(log_kappa)
    e_int, _ = _interp(log_kappa, log_kappa_table, e_table, e_table[0], e_table[last], j)
    base = 3.0 * q / (sum_rho * modulus)
    semi_a = (2.0 * (kappa * kappa) * e_int / math.pi * base) ** (1.0 / 3.0)
    semi_b = (2.0 * e_int / (math.pi * kappa) * base) ** (1.0 / 3.0)
    return semi_a, semi_b, 1.5 * q / (math.pi * semi_a * semi_b)


def _contact_results(load, e, contact_stiffness, ball_diameter, groove_radius, pitch_diameter, inner, modulus,
                     f_table, log_kappa_table, e_table, edge_angle):
    """What a load distribution reports of its contacts 1..4, from the diagonals' loads ``load``
    (B, 2) and relative vectors ``e`` (B, 2, 2): the formulas of ``BimeSolver._result``
    (:mod:`slewing_model.distribution.bime`) in the same order of operations.

    Contacts 1 and 3 carry diagonal 1's load at its angle ``atan2(e_z, e_r)``, contacts 2 and 4
    diagonal 2's at ``atan2(-e_z, e_r)``; the deflection ``(Q / K)^(2/3)``; the Hertz ellipse and
    pressure of the loaded ones (:func:`_hertz_contact`; zero where unloaded); whether the ellipse
    runs over the groove edge (``edge_angle`` (4,)). Returns those (B, 4) arrays and the first
    contact (``4 ball + contact``) whose angle is past its groove edge, or -1."""
    n_balls = load.shape[0]
    contact_load = np.empty((n_balls, 4))
    contact_angle = np.empty((n_balls, 4))
    deflection = np.empty((n_balls, 4))
    semi_a = np.zeros((n_balls, 4))
    semi_b = np.zeros((n_balls, 4))
    pressure = np.zeros((n_balls, 4))
    truncated = np.zeros((n_balls, 4), np.bool_)
    off = -1
    for b in range(n_balls):
        angle_1 = math.atan2(e[b, 0, 1], e[b, 0, 0])
        angle_2 = math.atan2(-e[b, 1, 1], e[b, 1, 0])
        for c in range(4):
            d = c % 2                                     # contacts (1, 3) <- diagonal 1, (2, 4) <- diagonal 2
            q = load[b, d]
            angle = angle_1 if d == 0 else angle_2
            contact_load[b, c] = q
            contact_angle[b, c] = angle
            deflection[b, c] = (max(q, 0.0) / contact_stiffness[b, c]) ** (2.0 / 3.0)
            if q > 0.0:
                semi_a[b, c], semi_b[b, c], pressure[b, c] = _hertz_contact(
                    q, ball_diameter[b], groove_radius[b, c], angle, pitch_diameter, inner[c], modulus, f_table,
                    log_kappa_table, e_table)
                if off < 0 and angle >= edge_angle[c]:
                    off = 4 * b + c
                truncated[b, c] = angle + semi_a[b, c] / groove_radius[b, c] >= edge_angle[c]
    return contact_load, contact_angle, deflection, semi_a, semi_b, pressure, truncated, off


def _periodic_interp(theta, angle, table):
    """The columns of ``table`` (K, N) at the angles ``theta`` (B,) taken modulo ``2 pi``:
    ``np.interp(theta % (2 pi), angle, column)`` of each column, in numpy's arithmetic
    (:meth:`slewing_model.bearing.manufacturing.RingErrorMap.at`), (B, K)."""
    n_columns = table.shape[0]
    out = np.empty((theta.size, n_columns))
    period = 2.0 * np.pi
    last = angle.size - 1
    segment = 0
    for b in range(theta.size):
        x = theta[b] % period
        for k in range(n_columns):
            out[b, k], j = _interp(x, angle, table[k], table[k, 0], table[k, last], segment)
            segment = max(j, 0)
    return out


_GROOVE_ERRORS_SIGNATURE = "f8[:, :](f8[:, :, :], f8[:], f8[:], f8[:, :], i8, i8)"


def _add_groove_errors(centre, theta, angle, table, contact_a, contact_b):
    """One ring's groove-centre deviations at its angles ``theta`` (B,) added to the groove centres
    ``centre`` (B, 4, 2) of its contacts ``contact_a``, ``contact_b`` (0-based), in place: the
    radial and axial columns of its periodic table (:attr:`slewing_model.bearing.manufacturing.RingErrorMap.table`)
    interpolated by :func:`_periodic_interp`, as :func:`slewing_model.distribution.assembly.assemble` adds
    them with numpy. Returns the interpolated columns (B, K) (a measured groove's radii last)."""
    values = _periodic_interp(theta, angle, table)
    for b in range(theta.size):
        centre[b, contact_a, 0] += values[b, 0]
        centre[b, contact_b, 0] += values[b, 1]
        centre[b, contact_a, 1] += values[b, 2]
        centre[b, contact_b, 1] += values[b, 3]
    return values


_RING_TIMES_SIGNATURE = "f8[::1](f8[:, ::1], f8[:, ::1], f8[:, :, ::1], f8[:, :, ::1], f8[::1])"


def _ring_times(cos_table, sin_table, harmonic_real, harmonic_imag, v):
    """The ring compliance's product ``M v`` (:class:`slewing_model.rings.compliance.BlockCirculant`,
    blocks of ``m``) through its harmonics, as numpy's FFT product does, ``R_j = conj(C^_j) V_j``:
    the real DFT ``V_j = sum_b v_b exp(-2 pi i j b / B)`` and its inverse by the tables ``cos``,
    ``sin`` (K, K) of ``2 pi j b / B`` for ``j, b < K = B // 2 + 1``, the harmonics ``conj(C^_j)``
    (K, m, m) by their real and imaginary parts. The balls ``b`` and ``B - b`` share their
    cosines and have opposite sines, so each sum runs over half the balls, and the tables, symmetric
    in ``j`` and ``b``, serve the DFT (read along ``j``) and its inverse (along ``b``) alike: 92 kB for
    the pitch bearing's 150 balls where the tables of every ball and their transposes were 365 kB,
    read at every product after the kept inverse's 540 kB have pushed them out of the cache. Differs
    from the FFT (and the dense product) by round-off; faster than the dense product from a few balls
    on (67 balls: 4.6 against 7.6 us).

    Both sums take four balls (four harmonics) a pass over a row of ``V`` (of the result): each entry
    read and written once for four terms, added one after the other in the order of a pass per ball,
    so the same numbers as that, bit for bit, in 26 instead of 32 us (pitch bearing, hot)."""
    n_harmonics = cos_table.shape[0]
    m = harmonic_real.shape[1]
    n_balls = v.size // m
    pairs = (n_balls - 1) // 2                     # b and B - b for b = 1 .. pairs; b = 0 (and B/2) alone
    v_real = np.zeros((m, n_harmonics))
    v_imag = np.zeros((m, n_harmonics))
    for single in range(2 if n_balls % 2 == 0 else 1):     # b = 0 and, for an even B, B/2: no sine, no pair
        b = single * (n_balls // 2)
        for a in range(m):
            value = v[b * m + a]
            for j in range(n_harmonics):
                v_real[a, j] += cos_table[b, j] * value
    ball = np.empty(pairs, np.int64)
    both = np.empty(pairs)
    apart = np.empty(pairs)
    for a in range(m):                             # V_j, the two balls' blocks added to every harmonic
        count = 0
        for b in range(1, pairs + 1):
            plus, minus = v[b * m + a] + v[(n_balls - b) * m + a], v[b * m + a] - v[(n_balls - b) * m + a]
            if plus != 0.0 or minus != 0.0:        # (not the rows off the reduced operator's)
                ball[count], both[count], apart[count] = b, plus, minus
                count += 1
        k = 0
        while k + 4 <= count:
            b0, b1, b2, b3 = ball[k], ball[k + 1], ball[k + 2], ball[k + 3]
            s0, s1, s2, s3 = both[k], both[k + 1], both[k + 2], both[k + 3]
            d0, d1, d2, d3 = apart[k], apart[k + 1], apart[k + 2], apart[k + 3]
            for j in range(n_harmonics):
                real = v_real[a, j] + cos_table[b0, j] * s0
                real += cos_table[b1, j] * s1
                real += cos_table[b2, j] * s2
                v_real[a, j] = real + cos_table[b3, j] * s3
                imag = v_imag[a, j] - sin_table[b0, j] * d0
                imag -= sin_table[b1, j] * d1
                imag -= sin_table[b2, j] * d2
                v_imag[a, j] = imag - sin_table[b3, j] * d3
            k += 4
        for k in range(k, count):
            for j in range(n_harmonics):
                v_real[a, j] += cos_table[ball[k], j] * both[k]
                v_imag[a, j] -= sin_table[ball[k], j] * apart[k]
    p_real = np.empty((m, n_harmonics))
    p_imag = np.empty((m, n_harmonics))
    for j in range(n_harmonics):                   # R_j; the inverse's weights (numpy's irfft: the
        weight = 1.0 if j == 0 or 2 * j == n_balls else 2.0      # imaginary part of j = 0 and B/2 drops)
        weight /= n_balls
        for a in range(m):
            real = imag = 0.0
            for c in range(m):
                real += harmonic_real[j, a, c] * v_real[c, j] - harmonic_imag[j, a, c] * v_imag[c, j]
                imag += harmonic_real[j, a, c] * v_imag[c, j] + harmonic_imag[j, a, c] * v_real[c, j]
            p_real[a, j] = weight * real
            p_imag[a, j] = weight * imag
    half = n_balls // 2 + 1
    cos_part = np.zeros((m, half))
    sin_part = np.zeros((m, half))
    for a in range(m):                             # the inverse DFT, each harmonic added to half the balls
        j = 0
        while j + 4 <= n_harmonics:
            r0, r1, r2, r3 = p_real[a, j], p_real[a, j + 1], p_real[a, j + 2], p_real[a, j + 3]
            i0, i1, i2, i3 = p_imag[a, j], p_imag[a, j + 1], p_imag[a, j + 2], p_imag[a, j + 3]
            for b in range(half):
                real = cos_part[a, b] + r0 * cos_table[j, b]
                real += r1 * cos_table[j + 1, b]
                real += r2 * cos_table[j + 2, b]
                cos_part[a, b] = real + r3 * cos_table[j + 3, b]
                imag = sin_part[a, b] + i0 * sin_table[j, b]
                imag += i1 * sin_table[j + 1, b]
                imag += i2 * sin_table[j + 2, b]
                sin_part[a, b] = imag + i3 * sin_table[j + 3, b]
            j += 4
        for j in range(j, n_harmonics):
            for b in range(half):
                cos_part[a, b] += p_real[a, j] * cos_table[j, b]
                sin_part[a, b] += p_imag[a, j] * sin_table[j, b]
    out = np.empty(v.size)
    for b in range(half):                          # ball b: cos - sin; ball B - b: cos + sin
        for a in range(m):
            out[b * m + a] = cos_part[a, b] - sin_part[a, b]
            if 0 < b < n_balls - b:
                out[(n_balls - b) * m + a] = cos_part[a, b] + sin_part[a, b]
    return out


#: the types of what the loops of the kept operator's iterations take first (``BimeSolver._kept_operands``):
#: the springs (separation, Jacobian rows, natural lengths, stiffness), the loads, the loaded threshold; the
#: operator (its inverse in double or single, compliance, rows, Jacobian, coupling, Schur complement's
#: inverse, diagonals); the ring product's tables (:func:`_ring_times`)
_KEPT_OPERAND_TYPES = ("f8[:, :, :], f8[:, :], f8[:, :], f8[:, :], f8[:], f8, "
                       "f8[:, ::1], f4[:, ::1], f8[:, :, :], i8[:], f8[:, :], f8[:, :], f8[:, :], b1[:], "
                       "f8[:, ::1], f8[:, ::1], f8[:, :, ::1], f8[:, :, ::1]")
_KEPT_SIGNATURE = (
    "Tuple((i8, f8, f8[::1], f8[::1], f8[::1], f8[:, :, ::1], f8[:, ::1], f8[:, ::1], f8[:, :, ::1], f8[:, :, ::1], "
    f"f8[:, ::1], f8[::1], f8[::1], b1[::1], f8[::1]))({_KEPT_OPERAND_TYPES}, "
    "f8[::1], f8[::1], f8[::1], f8[:, :, ::1], f8[:, ::1], f8[:, ::1], f8[:, :, ::1], f8[:, :, ::1], f8[:, ::1], "
    "f8[::1], f8[::1], b1[::1], f8[:], f8[:], i8, i8)")


def _kept_iterations(separation, jacobian_rows, natural_length, stiffness, f_scaled, loaded_from,
                     inverse, single_inverse, contact_compliance, rows, op_jacobian, coupling, schur_inverse, op_active,
                     cos_table, sin_table, harmonic_real, harmonic_imag,
                     qs, y, ring_motion, e, delta, q, force, n, length, gradient, mismatch, loaded, terms, rules,
                     iterations, max_iterations):
    """The flexible solver's iterations with a kept reduced operator, as ``BimeSolver.solve``
    (:mod:`slewing_model.distribution.bime`) runs them, one after the other in one loop, for as long as nothing
    but the operator's product is asked: each the modified Newton step (:func:`_newton_step`), the
    ring compliance's product with its ``dy`` (:func:`_ring_times`), the step limited to the trust
    length and the backtracking line search on the total energy (:func:`_trial_point`).

    The loop stops before an iteration that the solver must run itself: the stop rule met (or its
    residual not finite), ``max_iterations`` reached, a new operator asked for by the refresh rule,
    a diagonal loaded outside the operator's ``op_active`` (it borders them in), none loaded, a
    line search that fails or a moving ring beyond the ball diameter (it raises). Its decisions
    are the solver's; its sums (the slope, the step's length) run in another order than numpy's
    dot products, so a tie at round-off could fall the other way.

    ``qs`` ... ``loaded`` are the last point's (``BimeSolver``'s ``_Point``), ``terms`` its total
    energy, energy scale, largest force, largest residual and loaded diagonals; ``rules`` the stop
    rule's tolerance, the load scale, the trust length, the squared ball diameter, the refresh
    threshold, the finish iterations and the last iteration's residual. Returns the iterations
    done here, the last residual and the point reached, in the order given (the one given when
    none was done)."""
    rtol, load_scale, trust, dw2, refresh, finish = rules[0], rules[1], rules[2], rules[3], rules[4], rules[5]
    last_residual = rules[6]
    total, energy_scale, peak_force, peak_residual, n_loaded = terms[0], terms[1], terms[2], terms[3], terms[4]
    done = 0
    while True:
        scale = max(load_scale, peak_force, 1e-300)
        residual = peak_residual / scale
        if not math.isfinite(residual) or residual <= rtol or scale == 1e-300 or iterations >= max_iterations:
            break
        fresh = residual > refresh * last_residual
        if fresh and residual < last_residual:
            fresh = math.log(rtol / residual) < finish * math.log(residual / last_residual)
        if fresh or n_loaded == 0:
            break
        closed = False
        for i in range(loaded.size):
            if loaded[i] and not op_active[i]:
                closed = True
                break
        if closed:
            break
        off_motion = _off_motion(rows, op_active, y, cos_table, sin_table, harmonic_real,
                                 harmonic_imag)
        dq, y_new = _newton_step(inverse, single_inverse, contact_compliance, rows, op_jacobian, coupling,
                                 schur_inverse, force.reshape(-1), y, off_motion, f_scaled)
        dy = y_new - y
        m_dy = _ring_times(cos_table, sin_table, harmonic_real, harmonic_imag, dy)
        slope_q = slope_y = 0.0                    # g . dq - (f - y) . M dy, as two dot products
        for k in range(5):
            slope_q += gradient[k] * dq[k]
        for i in range(dy.size):
            slope_y += mismatch[i] * m_dy[i]
        slope = slope_q - slope_y
        norm = math.sqrt(dq[0] ** 2 + dq[1] ** 2 + dq[2] ** 2 + dq[3] ** 2 + dq[4] ** 2)
        if norm > trust:
            shrink = trust / norm
            dq, dy, m_dy, slope = dq * shrink, dy * shrink, m_dy * shrink, slope * shrink
        t = 1.0
        accepted = False
        for _ in range(60):
            (qs_t, y_t, motion_t, e_t, delta_t, q_t, force_t, n_t, length_t, gradient_t, mismatch_t, loaded_t,
             trial_terms) = _trial_point(separation, jacobian_rows, qs, dq, y, dy, ring_motion, m_dy, t,
                                         natural_length, stiffness, f_scaled, loaded_from)
            total_t = trial_terms[0] + trial_terms[1] - trial_terms[2]
            scale_t = trial_terms[0] + trial_terms[1] + abs(trial_terms[2])
            if total_t <= total + 1e-4 * t * min(slope, 0.0) + 1e-12 * max(energy_scale, scale_t):
                accepted = True
                break
            t *= 0.5
        if not accepted or qs_t[0] ** 2 + qs_t[1] ** 2 + qs_t[2] ** 2 + qs_t[3] ** 2 + qs_t[4] ** 2 > dw2:
            break
        qs, y, ring_motion, e, delta, q = qs_t, y_t, motion_t, e_t, delta_t, q_t
        force, n, length, gradient, mismatch, loaded = force_t, n_t, length_t, gradient_t, mismatch_t, loaded_t
        total, energy_scale = total_t, scale_t
        peak_force, peak_residual, n_loaded = trial_terms[3], trial_terms[4], trial_terms[5]
        iterations += 1
        last_residual = residual
        done += 1
    return (done, last_residual, qs, y, ring_motion, e, delta, q, force, n, length, gradient, mismatch, loaded,
            np.array([total, energy_scale, peak_force, peak_residual, n_loaded]))


#: what :func:`_warm_solve` reports: an equilibrium (its contacts' results too), the kept iterations
#: stopped short of it (the solver goes on from the point reached), a start far from it (the held-rings
#: start's), a kept operator that no column turn follows (its coupling is formed anew)
WARM_CONVERGED, WARM_STOPPED, WARM_FAR, WARM_NOT_TURNED = 0, 1, 2, 3

_WARM_SIGNATURE = (
    "Tuple((i8, i8, f8, b1, b1, f8[:], f8[:], f8[:], f8[:, :, :], f8[:, :], f8[:, :], f8[:, :, :], f8[:, :, :], "
    "f8[:, :], f8[:], f8[:], b1[:], f8[:], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], "
    f"f8[:, :], f8[:, :], b1[:, :], i8))({_KEPT_OPERAND_TYPES}, f8[::1], f8[::1], f8[:], i8, b1, "
    f"{_BEARING_CONTACT_TYPES})")


def _warm_solve(separation, jacobian_rows, natural_length, stiffness, f_scaled, loaded_from,
                inverse, single_inverse, contact_compliance, rows, op_jacobian, coupling, schur_inverse, op_active,
                cos_table, sin_table, harmonic_real, harmonic_imag, qs, y, rules, limit,
                turn, contact_stiffness, ball_diameter, groove_radius, pitch_diameter, inner, modulus, f_table,
                log_kappa_table, e_table, edge_angle):
    """The usual warm solve of ``BimeSolver.solve`` (:mod:`slewing_model.distribution.bime`) in one call,
    the loops it calls one by one, in its order and with its arguments: the start ``(qs, y)`` evaluated
    (the ring product :func:`_ring_times`, :func:`_trial_point`), the held-rings start's test, the stop
    rule, the kept operator turned with the ring (:func:`_column_turn`, where ``turn``), its iterations
    (:func:`_kept_iterations`, up to ``limit``) and the contacts' results at the equilibrium
    (:func:`_contact_results`).

    ``rules``: the tolerance, the load scale, the trust length, the squared ball diameter, the refresh
    threshold, the finish iterations, the held start's threshold, ``mu`` and the turn's tolerance. Returns a
    status (:data:`WARM_CONVERGED`, :data:`WARM_STOPPED`: the solver goes on from the point reached, the
    kept loop having stopped before that iteration; :data:`WARM_FAR`, :data:`WARM_NOT_TURNED`: at the
    start, which it returns), the iterations done, the last residual, whether the operator was turned
    (its Jacobian now this one's) and whether its coupling changed, the point (as :func:`_kept_iterations`
    returns it, and its total energy, energy scale, largest force, largest residual and loaded diagonals),
    the operator's coupling, Schur complement's inverse and Jacobian, and the contacts' results (empty
    unless converged)."""
    rtol, load_scale, held_start, mu, turn_tolerance = rules[0], rules[1], rules[6], rules[7], rules[8]
    still_q, still_y = np.zeros(5), np.zeros(y.size)
    motion = _ring_times(cos_table, sin_table, harmonic_real, harmonic_imag, y)
    (qs, y, motion, e, delta, q, force, n, length, gradient, mismatch, loaded, start) = _trial_point(
        separation, jacobian_rows, qs, still_q, y, still_y, motion, still_y, 0.0, natural_length, stiffness, f_scaled,
        loaded_from)
    energy, ring, work = start[0], start[1], start[2]
    terms = np.array([energy + ring - work, energy + ring + abs(work), start[3], start[4], start[5]])
    empty_2, empty_b = np.empty((0, 4)), np.empty((0, 4), np.bool_)
    no_results = (empty_2, empty_2, empty_2, empty_2, empty_2, empty_2, empty_b, -1)
    peak_force, peak_residual = terms[2], terms[3]
    status = WARM_STOPPED
    if terms[4] > 0 and not peak_residual <= held_start * max(load_scale, peak_force):
        status = WARM_FAR
    scale = max(load_scale, peak_force, 1e-300)
    converged = status == WARM_STOPPED and (peak_residual / scale <= rtol or scale == 1e-300)
    turned = changed = False
    if status == WARM_STOPPED and not converged and turn:          # the kept operator follows the ring
        new = np.empty((rows.size, 5))
        for i in range(rows.size):
            new[i] = jacobian_rows[rows[i]]
        if op_jacobian.shape[0] != rows.size:                    # (as numpy's turn: formed anew)
            status = WARM_NOT_TURNED
        elif not (op_jacobian == new).all():
            found, new_coupling, new_schur, new_jacobian = _column_turn(op_jacobian, new, coupling, mu,
                                                                       turn_tolerance)
            if not found:
                status = WARM_NOT_TURNED
            else:
                coupling, schur_inverse, op_jacobian, changed = new_coupling, new_schur, new_jacobian, True
        turned = status == WARM_STOPPED
    done, last_residual = 0, math.inf
    if status == WARM_STOPPED and not converged:
        kept_terms = np.array([terms[0], terms[1], peak_force, peak_residual, 1.0 if terms[4] > 0 else 0.0])
        kept_rules = np.array([rules[0], rules[1], rules[2], rules[3], rules[4], rules[5], math.inf])
        (done, last_residual, qs, y, motion, e, delta, q, force, n, length, gradient, mismatch, loaded,
         terms) = _kept_iterations(separation, jacobian_rows, natural_length, stiffness, f_scaled, loaded_from,
                                   inverse, single_inverse, contact_compliance, rows, op_jacobian, coupling,
                                   schur_inverse, op_active, cos_table, sin_table, harmonic_real,
                                   harmonic_imag, qs, y, motion, e, delta, q, force, n, length,
                                   gradient, mismatch, loaded, kept_terms, kept_rules, 0, limit)
        scale = max(load_scale, terms[2], 1e-300)
        converged = terms[3] / scale <= rtol or scale == 1e-300
    results = no_results
    if converged:
        status = WARM_CONVERGED
        results = _contact_results(q, e, contact_stiffness, ball_diameter, groove_radius, pitch_diameter, inner,
                                   modulus, f_table, log_kappa_table, e_table, edge_angle)
    return (status, done, last_residual, turned, changed, qs, y, motion, e, delta, q, force, n, length, gradient,
            mismatch, loaded, terms, coupling, schur_inverse, op_jacobian, results[0], results[1], results[2],
            results[3], results[4], results[5], results[6], results[7])


_RIGID_SIGNATURE = ("Tuple((f8[:], i8, b1, f8[:, :, :], f8[:, :], f8[:, :], f8[:]))(f8[:, :, :], f8[:, :], f8[:], f8[:], "
                    "f8[:], f8[:, :], f8[:, :], f8[:], f8, f8[:])")


def _rigid_solve(separation, jacobian_rows, qs, y, ring_motion, natural_length, stiffness, f_scaled, loaded_from,
                 rules):
    """The rigid model's solve of ``BimeSolver.solve`` (:mod:`slewing_model.distribution.bime`) from ``qs``,
    on grooves moved by a held ring motion ``M y`` (``ring_motion``, ``y`` the ring forces; zero for the
    rigid model itself): the moving ring's equilibrium with the rings held as they are deformed, the
    held-rings start of ``BimeSolver._held_rings_start``. Each iteration the Newton step of the rigid
    model (``BimeSolver._rigid_direction``: ``(sum J^T A J + mu I) dq = -(J^T f - F)``, ``A`` the
    springs' 2 x 2 stiffness, eqs 7-8), limited to the trust length, and the backtracking line search
    on the energy (eq 20, the rings' term held), at :func:`_trial_point`'s springs; the stop rule on
    the largest of ``|J^T f - F|`` over the largest of the loads and the springs' forces.

    ``rules``: the tolerance, the load scale, the trust length, the squared ball diameter, ``mu``
    and the iterations allowed. Returns ``qs`` reached, the iterations, whether it converged (False
    where the solver's loop raises NoEquilibriumError: no convergence, a line search that fails, a
    moving ring beyond the ball diameter, a residual not finite; or a singular step), and at ``qs``
    the springs' ``e``, ``delta``, ``q`` and ``(total energy, largest force, largest residual)``."""
    rtol, load_scale, trust, dw2, mu = rules[0], rules[1], rules[2], rules[3], rules[4]
    max_iterations = int(rules[5])
    n_balls = separation.shape[0]
    still, still_y = np.zeros(5), np.zeros(y.size)
    (qs, _, _, e, delta, q, _, n, length, gradient, _, _, terms) = _trial_point(
        separation, jacobian_rows, qs, still, y, still_y, ring_motion, still_y, 0.0, natural_length, stiffness,
        f_scaled, loaded_from)
    total, energy_scale = terms[0] - terms[2], terms[0] + abs(terms[2])
    hessian = np.empty((5, 5))
    block = np.empty((2, 2))
    iterations = 0
    while True:
        peak_force = peak_residual = 0.0
        for b in range(n_balls):
            for d in range(2):
                peak_force = max(peak_force, q[b, d])
        for k in range(5):
            peak_residual = max(peak_residual, abs(gradient[k]))
        if not math.isfinite(gradient.sum()):
            peak_residual = math.nan
        scale = max(load_scale, peak_force, 1e-300)
        residual = peak_residual / scale
        point = np.array([total, peak_force, peak_residual])
        if not math.isfinite(residual):
            return qs, iterations, False, e, delta, q, point
        if residual <= rtol or scale == 1e-300:
            return qs, iterations, True, e, delta, q, point
        if iterations >= max_iterations:
            return qs, iterations, False, e, delta, q, point
        iterations += 1
        hessian[:, :] = 0.0
        for b in range(n_balls):
            for d in range(2):
                closed = max(delta[b, d], 0.0)
                k_normal = 1.5 * stiffness[b, d] * math.sqrt(closed)         # d q / d delta (eq 8)
                across = q[b, d] / length[b, d]
                for r in range(2):
                    for c in range(2):
                        nn = n[b, d, r] * n[b, d, c]
                        block[r, c] = k_normal * nn + across * ((1.0 if r == c else 0.0) - nn)
                row = 4 * b + 2 * d
                for k in range(5):
                    for m in range(5):
                        value = 0.0
                        for r in range(2):
                            for c in range(2):
                                value += jacobian_rows[row + r, k] * block[r, c] * jacobian_rows[row + c, m]
                        hessian[k, m] += value
        for k in range(5):
            hessian[k, k] += mu
        ok, step = _solve_small(hessian, -gradient.reshape(5, 1))
        if not ok:
            return qs, iterations, False, e, delta, q, point
        dq = step[:, 0].copy()
        slope = 0.0
        for k in range(5):
            slope += gradient[k] * dq[k]
        norm = math.sqrt(dq[0] ** 2 + dq[1] ** 2 + dq[2] ** 2 + dq[3] ** 2 + dq[4] ** 2)
        if norm > trust:
            dq *= trust / norm
            slope *= trust / norm
        t = 1.0
        accepted = False
        for _ in range(60):
            (qs_t, _, _, e_t, delta_t, q_t, _, n_t, length_t, gradient_t, _, _, terms_t) = _trial_point(
                separation, jacobian_rows, qs, dq, y, still_y, ring_motion, still_y, t, natural_length, stiffness,
                f_scaled, loaded_from)
            total_t, scale_t = terms_t[0] - terms_t[2], terms_t[0] + abs(terms_t[2])
            if total_t <= total + 1e-4 * t * min(slope, 0.0) + 1e-12 * max(energy_scale, scale_t):
                accepted = True
                break
            t *= 0.5
        if not accepted:
            return qs, iterations, False, e, delta, q, point
        qs, e, delta, q, n, length, gradient = qs_t, e_t, delta_t, q_t, n_t, length_t, gradient_t
        total, energy_scale = total_t, scale_t
        if qs[0] ** 2 + qs[1] ** 2 + qs[2] ** 2 + qs[3] ** 2 + qs[4] ** 2 > dw2:
            return qs, iterations, False, e, delta, q, point


#: the helpers the load distribution's loops call
_HELPERS = ("_segment", "_interp", "_solve_small", "_hertz_contact", "_symmetric_times", "_bordered_blocks",
            "_periodic_interp", "_trial_point", "_newton_step", "_off_motion", "_ring_times", "_schur_inverse",
            "_column_turn", "_kept_iterations", "_contact_results", "_inverse_product", "_single_times")


#: numpy's floating-point semantics: a division by zero gives inf or NaN as the numpy code does,
#: instead of raising
ERROR_MODEL = "numpy"


#: LLVM's fast-math flags of these loops: none. ``contract`` (fused multiply-adds, as the friction's loops take,
#: :data:`slewing_model.friction.kernel.FASTMATH`) makes the usual solve's one call 0.94-0.97 as long (hot, call by
#: call), about 2 % of a step, but the Newton iterations' residuals then move by round-off, and where one sits at
#: the stop rule's tolerance the rounding decides an iteration: the answers would depend on whether the CPU the
#: loops are compiled for has fused multiply-adds (numba's loops for this CPU against the generic ones, or
#: numpy's), by more than round-off
FASTMATH = frozenset()


def _compile(function, signature):
    return compile_loop(function, signature, _HELPERS, error_model=ERROR_MODEL, fastmath=FASTMATH)


#: (factory, Python function) of each compiled loop of the load distribution
KERNELS: list = []
compiled_trial_point = loop_factory(KERNELS, _compile, _trial_point, _TRIAL_SIGNATURE)
compiled_newton_step = loop_factory(KERNELS, _compile, _newton_step, _NEWTON_SIGNATURE)
compiled_column_turn = loop_factory(KERNELS, _compile, _column_turn, _TURN_SIGNATURE)
compiled_jacobian = loop_factory(KERNELS, _compile, _jacobian, _JACOBIAN_SIGNATURE)
compiled_bordered_inverse = loop_factory(KERNELS, _compile, _bordered_inverse, _BORDER_SIGNATURE)
compiled_operator_matrix = loop_factory(KERNELS, _compile, _operator_matrix, _MATRIX_SIGNATURE)
compiled_operator_coupling = loop_factory(KERNELS, _compile, _operator_coupling, _COUPLING_SIGNATURE)
compiled_inverse_product = loop_factory(KERNELS, _compile, _inverse_product, _PRODUCT_SIGNATURE)
compiled_contact_results = loop_factory(KERNELS, _compile, _contact_results, _RESULTS_SIGNATURE)
compiled_add_groove_errors = loop_factory(KERNELS, _compile, _add_groove_errors, _GROOVE_ERRORS_SIGNATURE)
compiled_ring_times = loop_factory(KERNELS, _compile, _ring_times, _RING_TIMES_SIGNATURE)
compiled_kept_iterations = loop_factory(KERNELS, _compile, _kept_iterations, _KEPT_SIGNATURE)
compiled_rigid_solve = loop_factory(KERNELS, _compile, _rigid_solve, _RIGID_SIGNATURE)
compiled_warm_solve = loop_factory(KERNELS, _compile, _warm_solve, _WARM_SIGNATURE)


# ---- the loops with the interfaces of the numpy functions they stand for ----------------------

_NO_DOUBLE, _NO_SINGLE = np.zeros((0, 0)), np.zeros((0, 0), np.float32)


def product_inverses(inverse):
    """A kept operator's ``W^-1`` as the compiled Newton step takes it (:func:`_newton_step`): the pair
    (double, single), the one of its precision (:func:`slewing_model.rings.reduced_operator.kept_precision`)
    and an empty one."""
    if inverse.dtype == np.float32:
        return _NO_DOUBLE, np.ascontiguousarray(inverse)
    return np.ascontiguousarray(inverse, dtype=np.float64), _NO_SINGLE


def newton_step(op, point, f_scaled, off_motion=None):
    """:func:`slewing_model.rings.reduced_operator.newton_step` by the compiled loop."""
    y = point.y
    return compiled_newton_step()(*product_inverses(op.inverse), op.contact_compliance, op.rows, op.jacobian,
                                  op.coupling, op.schur_inverse, point.force.reshape(-1), y,
                                  np.zeros(y.size) if off_motion is None else off_motion, f_scaled)


def column_turn(old, new, coupling, mu, tolerance=0.0):
    """:func:`slewing_model.rings.reduced_operator.column_turn` by the compiled loop."""
    found, coupling, schur_inverse, jacobian = compiled_column_turn()(old, new, coupling, mu, tolerance)
    return (coupling, schur_inverse, jacobian) if found else None


#: from this many new rows on, bordering is numpy's (BLAS's products): the compiled loop sums
#: ``W^-1 B`` and ``X S X^T`` without blocking: 7.3 ms against 2.0 ms for 92 rows onto 368, 0.75
#: against 0.60 ms for 16, 0.52 against 0.58 for 12 (``python -m benchmarks operator --border``)
BORDER_BLAS_ROWS = 12


def bordered_inverse(inverse, b_mat, c_mat, jacobian, coupling, new_jacobian, mu):
    """:func:`slewing_model.rings.reduced_operator.bordered_inverse` by the compiled loop (a singular
    complement, not met, raises numpy's LinAlgError as the numpy one does); by numpy's from
    :data:`BORDER_BLAS_ROWS` new rows on."""
    if b_mat.shape[1] >= BORDER_BLAS_ROWS:
        return _numpy_bordered_inverse(inverse, b_mat, c_mat, jacobian, coupling, new_jacobian, mu)
    size = sum(b_mat.shape)
    bordered = np.empty((size, size), dtype=np.float32 if inverse.dtype == np.float32 else np.float64)
    both = (_NO_DOUBLE, bordered) if bordered.dtype == np.float32 else (bordered, _NO_SINGLE)
    found, new_coupling, schur_inverse = compiled_bordered_inverse()(
        *product_inverses(inverse), b_mat, c_mat, jacobian, coupling, new_jacobian, mu, *both)
    if not found:
        raise np.linalg.LinAlgError("singular matrix in bordering the reduced operator")
    return bordered, new_coupling, schur_inverse


def operator_matrix(point, compliance, stiffness, active):
    """:func:`slewing_model.rings.reduced_operator.operator_matrix` by the compiled loop."""
    rows = np.flatnonzero(np.repeat(active, 2))
    a_inv, w = compiled_operator_matrix()(compliance.blocks, rows, point.n.reshape(-1, 2),
                                         point.delta.reshape(-1), point.length.reshape(-1), point.q.reshape(-1),
                                         stiffness.reshape(-1))
    return rows, a_inv, w


def operator_coupling(inverse, ja, mu):
    """:func:`slewing_model.rings.reduced_operator.operator_coupling` by the compiled loop (a singular
    complement, not met, raises numpy's LinAlgError as the numpy one does)."""
    coupling, schur_inverse = compiled_operator_coupling()(*product_inverses(inverse), ja, mu)
    if schur_inverse.size == 0:
        raise np.linalg.LinAlgError("singular matrix: the Schur complement of the reduced operator")
    return coupling, schur_inverse


def inverse_product(inverse, vectors):
    """:func:`slewing_model.rings.reduced_operator.inverse_product` by the compiled loop."""
    return compiled_inverse_product()(*product_inverses(inverse), np.ascontiguousarray(vectors, dtype=np.float64))


def add_groove_errors(centre, theta, error_map, contacts):
    """:func:`_add_groove_errors` by the compiled loop, for a ring's ``error_map``
    (:class:`slewing_model.bearing.manufacturing.RingErrorMap`) and its two ``contacts`` (0-based): in place on
    ``centre``; returns the measured groove radii (B, 2), or None."""
    angle, table = error_map.table
    values = compiled_add_groove_errors()(centre, np.ascontiguousarray(theta, dtype=float), angle, table,
                                          contacts[0], contacts[1])
    return None if error_map.groove_radius is None else values[:, 4:6]


def contact_tables(youngs_modulus, poisson_ratio) -> tuple:
    """What :func:`_contact_results` takes of the Hertz contact: the modulus as
    :func:`slewing_model.bearing.contact.hertz_ellipse` takes it, and its tables."""
    return effective_modulus(youngs_modulus, poisson_ratio), _F_TABLE, _LOG_KAPPA, _E_TABLE


#: the reduced operator's arithmetic as compiled loops (:class:`slewing_model.rings.reduced_operator.OperatorArithmetic`)
COMPILED_ARITHMETIC = OperatorArithmetic(operator_matrix, operator_coupling, column_turn, bordered_inverse, newton_step,
                                         inverse_product)
