"""The per-point loop of the friction model, compiled with numba where it is installed.

:meth:`slewing_model.friction.ball_kinematics.ContactPoints.evaluate` sums the regularised dissipated power
``D = sum w s``, ``s = sqrt(A^2 + t^2 S^2 + eps^2)``, its gradient and its Hessian (and the
Weiszfeld majorant ``M - H``) over the quadrature points of every loaded contact, per ball.
With numpy that is some sixty array operations per evaluation, each a few microseconds of
call overhead for a few thousand points: for a 150-ball bearing the overhead, not the
arithmetic, sets the time. :func:`_evaluate_points`, compiled, is the same sum as one loop
over contacts, across-groove nodes and folded along-groove nodes. The rest of a friction torque
is likewise compiled: the loaded contacts of the distribution (:func:`_contact_set`), the set-up
of the points' velocity coefficients, twice a step (:func:`_point_coefficients`, for the rule the
balls are solved on and the torque's), the balls' equilibrium ball by ball
(:func:`_minimise_balls`), the contacts' powers and torques (:func:`_tractions`) and what is
reported per ball (:func:`_ball_results`); a warm-started torque, each co-simulation step's,
runs them all in one call (:func:`_friction_step`).

numba is optional (it is not part of the FMU's run-time requirements): without it
:data:`AVAILABLE` is False and the friction model uses its numpy code, which gives the same
results to round-off (``tests/test_friction_kernel.py``). The loops are compiled when first
asked for (:func:`compile_all`), which the simulator does when it is built, so that the compile
time lands in the FMU's instantiation, never in a step. Compiling takes about half a minute;
numba's on-disk cache (``__pycache__`` beside this file, keyed by the source's content) makes it
a fraction of a second after the first time, and ``build_fmu.py`` ships that cache in the FMU.
"""
from __future__ import annotations

import math

import numpy as np

from ..distribution.kernel import KERNELS as CONTACT_KERNELS
from ..life.kernel import KERNELS as LIFE_KERNELS
from ..numerics.compiled import (  # noqa: F401
    AVAILABLE, KERNEL_CHOICES, c_order, compile_loop, loop_factory, use_compiled,
)


_SIGNATURE = c_order("Tuple((f8[:], f8[:, :], f8[:, :, :], f8[:, :, :]))("
                     "f8[:, :], i8[:], i8, f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :, :], "
                     "f8[:], f8[:], b1, b1)")


#: the rows of the scratch array a contact's points are summed through (``points``, (POINT_ROWS, I)):
#: :func:`_contact_sums` keeps eight per point, :func:`_contact_tractions` six
POINT_ROWS = 8


def _sliding(c, i, u0, u1, u2, g10, g12, h1, s0, s1, hs):
    """``A`` and ``S`` of point ``(c, i)`` for the ball unknowns ``(u0, u1, u2)``
    (``ContactPoints.velocity``)."""
    return g10[c, i] * u0 + g12[c, i] * u1 + (h1[c, i] - u2), s0[c, i] * u0 + s1[c, i] * u1 + hs[c, i]


def _contact_sums(c, u0, u1, u2, g10, g12, h1, s0, s1, hs, weight, t2, e2, derivatives, majorant,
                  gradient, hessian, extra, points):
    """Power of contact ``c`` at the ball unknowns ``(u0, u1, u2)``, returned; with
    ``derivatives`` its gradient (3,) and the upper triangle of its Hessian (3, 3) added to
    ``gradient`` and ``hessian``, with ``majorant`` that of ``M - H`` to ``extra``.
    The formulas are those of ``ContactPoints.evaluate`` (:mod:`slewing_model.friction.ball_kinematics`).

    First each point across the ellipse on its own (its sliding ``A``, ``S`` and sums along it, into
    ``points`` (:data:`POINT_ROWS`, I), the caller's): a loop with no chain of the ball's sums through it,
    so that the points' square roots and divisions overlap (scalar ones: the loop along the ellipse inside
    it keeps LLVM from making vector operations of it); then the points' terms summed into the ball's, in
    the order of one loop over the points, so the same numbers bit for bit as that loop."""
    n_across, n_along = g10.shape[1], t2.shape[0]
    for i in range(n_across):
        a, s_ = _sliding(c, i, u0, u1, u2, g10, g12, h1, s0, s1, hs)
        a2, s2 = a * a, s_ * s_
        total = 0.0
        alpha = beta = m0 = m1 = m2 = 0.0
        for k in range(n_along):
            speed = math.sqrt(a2 + t2[k] * s2 + e2)
            w = weight[k, c, i]
            total += w * speed
            if derivatives:
                inverse = 1.0 / speed               # one division, not three (measured 9 % of an evaluation)
                ws = w * inverse                    # w / s
                alpha += ws
                beta += ws * t2[k]
                ws3 = ws * (inverse * inverse)      # w / s^3
                m0 += ws3
                m1 += ws3 * t2[k]
                m2 += ws3 * t2[k] * t2[k]
        points[0, i], points[1, i], points[2, i] = a, s_, total
        points[3, i], points[4, i], points[5, i], points[6, i], points[7, i] = alpha, beta, m0, m1, m2
    power = 0.0
    for i in range(n_across):
        power += points[2, i]
        if not derivatives:
            continue
        a, s_, alpha, beta = points[0, i], points[1, i], points[3, i], points[4, i]
        a2, s2 = a * a, s_ * s_
        m0, m1, m2 = points[5, i], points[6, i], points[7, i]
        ga_0, ga_1 = g10[c, i], g12[c, i]           # GA = (g10, g12, -1), GS = (s0, s1, 0)
        gs_0, gs_1 = s0[c, i], s1[c, i]
        grad_a, grad_s = alpha * a, beta * s_       # dD/dA, dD/dS
        gradient[0] += grad_a * ga_0 + grad_s * gs_0
        gradient[1] += grad_a * ga_1 + grad_s * gs_1
        gradient[2] -= grad_a
        e_aa, e_as, e_ss = m0 * a2, m1 * a * s_, m2 * s2
        h_aa, h_ss = alpha - e_aa, beta - e_ss
        # H = h_aa GA GA^T - e_as (GA GS^T + GS GA^T) + h_ss GS GS^T
        hessian[0, 0] += h_aa * ga_0 * ga_0 - e_as * 2.0 * ga_0 * gs_0 + h_ss * gs_0 * gs_0
        hessian[0, 1] += h_aa * ga_0 * ga_1 - e_as * (ga_0 * gs_1 + gs_0 * ga_1) + h_ss * gs_0 * gs_1
        hessian[1, 1] += h_aa * ga_1 * ga_1 - e_as * 2.0 * ga_1 * gs_1 + h_ss * gs_1 * gs_1
        hessian[0, 2] += e_as * gs_0 - h_aa * ga_0
        hessian[1, 2] += e_as * gs_1 - h_aa * ga_1
        hessian[2, 2] += h_aa
        if majorant:  # M - H = e_aa GA GA^T + e_as (GA GS^T + GS GA^T) + e_ss GS GS^T
            extra[0, 0] += e_aa * ga_0 * ga_0 + e_as * 2.0 * ga_0 * gs_0 + e_ss * gs_0 * gs_0
            extra[0, 1] += e_aa * ga_0 * ga_1 + e_as * (ga_0 * gs_1 + gs_0 * ga_1) + e_ss * gs_0 * gs_1
            extra[1, 1] += e_aa * ga_1 * ga_1 + e_as * 2.0 * ga_1 * gs_1 + e_ss * gs_1 * gs_1
            extra[0, 2] -= e_aa * ga_0 + e_as * gs_0
            extra[1, 2] -= e_aa * ga_1 + e_as * gs_1
            extra[2, 2] += e_aa
    return power


def _symmetrise(matrix):
    """Copy the upper triangle of a (3, 3) matrix into its lower one."""
    for r, c in ((1, 0), (2, 0), (2, 1)):
        matrix[r, c] = matrix[c, r]


def _evaluate_points(u, owner, n_balls, g10, g12, h1, s0, s1, hs, weight, t2, eps2, derivatives, majorant):
    """Power (B,), gradient (B, 3), Hessian (B, 3, 3) and ``M - H`` (B, 3, 3) of the balls.

    ``u`` (B, 3) the balls' scaled unknowns; ``owner`` (C,) the ball of each contact; the
    coefficients (C, I) of the sliding velocity ``A = g10 u0 + g12 u1 + h1 - u2``,
    ``S = s0 u0 + s1 u1 + hs``; ``weight`` (K, C, I) the quadrature weights times ``mu Q``;
    ``t2`` (K,) the folded ``t^2``; ``eps2`` (C,) the squared regularisation. Without
    ``derivatives`` only the power is summed (the others come back zero), without
    ``majorant`` ``M - H`` comes back zero."""
    power = np.zeros(n_balls)
    gradient = np.zeros((n_balls, 3))
    hessian = np.zeros((n_balls, 3, 3))
    extra = np.zeros((n_balls, 3, 3))
    points = np.empty((POINT_ROWS, g10.shape[1]))
    for c in range(g10.shape[0]):
        b = owner[c]
        power[b] += _contact_sums(c, u[b, 0], u[b, 1], u[b, 2], g10, g12, h1, s0, s1, hs, weight, t2, eps2[c],
                                  derivatives, majorant, gradient[b], hessian[b], extra[b], points)
    for b in range(n_balls):                            # the lower triangles
        _symmetrise(hessian[b])
        _symmetrise(extra[b])
    return power, gradient, hessian, extra


def _solve3(a, rhs, out, m):
    """``out = a^-1 rhs`` for a symmetric (3, 3) ``a``, eliminated in ``m`` (3, 4), the caller's (an
    array made per call cost 37 of its 53 ns, measured; 300-450 calls a step): Gaussian elimination
    with partial pivoting (LAPACK's ``gesv``, which ``solve_per_ball`` calls, does the same; the contacts'
    general ``_solve_small`` is the same elimination, slower here by its sizes known late). A
    singular ``a`` (not met) is regularised as ``solve_per_ball`` does: ``a + 1e-13 mean(diag) I``;
    still singular, it raises ValueError (numpy's LinAlgError is one)."""
    shift = 0.0
    for attempt in range(2):
        for r in range(3):
            for c in range(3):
                m[r, c] = a[r, c]
            m[r, r] += shift
            m[r, 3] = rhs[r]
        singular = False
        for col in range(3):
            pivot = col
            for r in range(col + 1, 3):
                if abs(m[r, col]) > abs(m[pivot, col]):
                    pivot = r
            if m[pivot, col] == 0.0:
                singular = True
                break
            if pivot != col:
                for c in range(col, 4):
                    m[col, c], m[pivot, c] = m[pivot, c], m[col, c]
            for r in range(col + 1, 3):
                factor = m[r, col] / m[col, col]
                for c in range(col, 4):
                    m[r, c] -= factor * m[col, c]
        if not singular:
            break
        if attempt == 1:
            raise ValueError("singular ball Hessian in the friction's ball equilibrium")
        shift = 1e-13 * max((a[0, 0] + a[1, 1] + a[2, 2]) / 3.0, 1e-300)
    for r in range(2, -1, -1):
        value = m[r, 3]
        for c in range(r + 1, 3):
            value -= m[r, c] * out[c]
        out[r] = value / m[r, r]


def _ball_evaluate(u, c_first, c_last, g10, g12, h1, s0, s1, hs, weight, t2, eps2, derivatives, majorant,
                   gradient, hessian, extra, points):
    """Power of one ball (its contacts ``c_first .. c_last - 1``), its gradient, Hessian and
    ``M - H`` written into the given arrays (as :func:`_evaluate_points` for one ball)."""
    gradient[:] = 0.0
    hessian[:] = 0.0
    extra[:] = 0.0
    power = 0.0
    for c in range(c_first, c_last):
        power += _contact_sums(c, u[0], u[1], u[2], g10, g12, h1, s0, s1, hs, weight, t2, eps2[c],
                               derivatives, majorant, gradient, hessian, extra, points)
    _symmetrise(hessian)
    _symmetrise(extra)
    return power


def _quadratic(g, h, du):
    """``g . du`` and ``du . h . du``."""
    slope = curvature = 0.0
    for r in range(3):
        slope += g[r] * du[r]
        for c in range(3):
            curvature += du[r] * h[r, c] * du[c]
    return slope, curvature


def _damped_step(x, c_first, c_last, g10, g12, h1, s0, s1, hs, weight, t2, eps2, theta, has_extra, f, g, h, extra,
                 minus_g, damped, du, work, points):
    """The damped step ``du = -(H + theta (M - H))^-1 g`` of one ball at ``x`` into ``du``,
    after evaluating ``M - H`` there (into ``g``, ``h``, ``extra``) unless ``has_extra`` (``damped``,
    ``work`` and ``points`` the caller's scratch arrays); returns the power at ``x``, the slope ``g . du`` and
    the decrease the quadratic model predicts, ``-(g . du + du . H du / 2)``."""
    if not has_extra:
        f = _ball_evaluate(x, c_first, c_last, g10, g12, h1, s0, s1, hs, weight, t2, eps2, True, True, g, h, extra,
                           points)
    damped[:, :] = h + theta * extra
    _solve3(damped, minus_g, du, work)
    slope, curvature = _quadratic(g, h, du)
    return f, slope, -(slope + 0.5 * curvature)


#: a converged ball's last Newton step is taken without evaluating the power at it (the check that it lowers
#: the power: :func:`_minimise_balls`, ``minimise_power``) where its largest component is at most this share of the
#: ball's largest unknown: there the quadratic model the step minimises holds. Measured over 340 steps of each of
#: the pitch bearing's five scenarios of the ``realtime`` benchmark, table3 heavy and the yaw bearing: the check
#: refused a step only where it was round-off (at most 1e-16 of the unknowns; 1,259-2,859 balls of some 50,000
#: in the scenarios of held loads, none elsewhere), and the steps it accepted were at most 1.3e-3 of them. The
#: check was an evaluation of every ball's power each step: 0.86 of the friction's one call without it (hot)
UNCHECKED_STEP = 1e-2


def _step_unchecked(step, x):
    """Whether ``step`` (3,) is small enough beside the unknowns ``x`` (3,) to be taken unchecked
    (:data:`UNCHECKED_STEP`; a NaN in either: no, as numpy's comparisons in ``minimise_power``)."""
    largest = 0.0
    for k in range(3):
        if x[k] != x[k]:
            return False
        largest = max(largest, abs(x[k]))
    for k in range(3):
        if not abs(step[k]) <= UNCHECKED_STEP * largest:
            return False
    return True


def _minimise_balls(u, first, g10, g12, h1, s0, s1, hs, weight, t2, eps2, force_scale, tol, floor,
                    max_iterations, theta_down, theta_up, theta_min_up):
    """The minimisation of :func:`slewing_model.friction.ball_kinematics.minimise_power`, ball by ball.

    Ball ``b`` owns the contacts ``first[b] .. first[b + 1] - 1``; the other arguments are
    those of :func:`_evaluate_points` and of ``minimise_power`` (its damping schedule
    ``theta_down, theta_up, theta_min_up``). Every ball follows the steps the batched
    numpy loop takes for it: its iterates depend on its own contacts, ``tol`` and
    ``floor`` only (``floor < 0``: the mean power per ball at ``u``). Returns the unknowns (B, 3), and per ball the iterations, the force
    residual (relative to ``force_scale``) at its last evaluation and whether it converged."""
    n_balls = u.shape[0]
    out = u.copy()
    iterations = np.zeros(n_balls, dtype=np.int64)
    residual = np.zeros(n_balls)
    converged = np.zeros(n_balls, dtype=np.bool_)
    x = np.empty(3)
    g, h, e = np.empty(3), np.empty((3, 3)), np.empty((3, 3))          # at the iterate x
    g_t, h_t, e_t = np.empty(3), np.empty((3, 3)), np.empty((3, 3))    # at the trial point
    newton, du, trial, minus_g = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    damped, work = np.empty((3, 3)), np.empty((3, 4))
    points = np.empty((POINT_ROWS, g10.shape[1]))                     # a contact's points (_contact_sums)
    # every ball's power, gradient and Hessian at its start: they give the floor (the mean power) and
    # start each ball's loop, one evaluation a ball (the power is summed as without derivatives)
    start_f = np.empty(n_balls)
    start_g, start_h = np.empty((n_balls, 3)), np.empty((n_balls, 3, 3))
    total = 0.0
    for b in range(n_balls):
        start_f[b] = _ball_evaluate(out[b], first[b], first[b + 1], g10, g12, h1, s0, s1, hs, weight, t2, eps2,
                                    True, False, start_g[b], start_h[b], e, points)
        total += start_f[b]
    if floor < 0.0:
        floor = total / max(n_balls, 1)
    for b in range(n_balls):
        c0, c1 = first[b], first[b + 1]
        x[:] = out[b]
        theta = 0.0
        f = start_f[b]
        g[:], h[:, :] = start_g[b], start_h[b]
        has_extra = False
        count = 0
        while True:
            minus_g[:] = -g
            _solve3(h, minus_g, newton, work)
            slope = _quadratic(g, h, newton)[0]
            decrement = -slope
            if decrement <= tol * (f + floor):           # converged: the last Newton step where it lowers D
                trial[:] = x + newton
                if _step_unchecked(newton, x) or _ball_evaluate(trial, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2,
                                                                eps2, False, False, g_t, h_t, e_t, points) \
                        <= f * (1.0 + 1e-12):
                    x[:] = trial
                count += 1
                converged[b] = True
                break
            if count >= max_iterations:
                break
            count += 1
            if theta > 0.0:
                f, slope, predicted = _damped_step(x, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2, theta,
                                                   has_extra, f, g, h, e, minus_g, damped, du, work, points)
                has_extra = True
            else:
                du[:] = newton
                slope, predicted = -decrement, 0.5 * decrement
            trial[:] = x + du
            good = False
            for _attempt in range(12):
                with_extra = theta > 0.0
                f_t = _ball_evaluate(trial, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2, True, with_extra,
                                     g_t, h_t, e_t, points)
                actual = f - f_t
                good = actual >= -1e-4 * slope or abs(actual) <= 1e-13 * abs(f)
                if good:
                    if actual >= 0.5 * predicted:
                        theta = theta_down * theta if theta > 1e-3 else 0.0
                    break
                if theta >= 1.0:                          # Weiszfeld failed: round-off
                    break
                theta = min(1.0, max(theta_up * theta, theta_min_up))
                f, slope, predicted = _damped_step(x, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2, theta,
                                                   has_extra, f, g, h, e, minus_g, damped, du, work, points)
                has_extra = True
                trial[:] = x + du
            if good:                                      # else no step lowered its power: the ball stays
                x[:] = trial
                f = f_t
                g[:], h[:, :], e[:, :] = g_t, h_t, e_t
                has_extra = with_extra
        out[b] = x
        iterations[b] = count
        residual[b] = max(abs(g[0]), abs(g[1]), abs(g[2])) / force_scale[b]
    return out, iterations, residual, converged


def _contact_tractions(c, u0, u1, u2, g10, g12, h1, s0, s1, hs, weight, t2, e2, arm1, arm2, points):
    """Dissipated power and torque on the moving ring of contact ``c`` (its rows of the points'
    coefficients (C, I) and weights (K, C, I)) for its ball's unknowns ``(u0, u1, u2)``: the sums of
    ``ContactPoints.tractions`` (:mod:`slewing_model.friction.ball_kinematics`), whose formulas they are,
    in the same order, so the same numbers bit for bit.

    The points' sums along the ellipse are formed for all points across at once (into ``points``
    (:data:`POINT_ROWS`, I), the caller's scratch: ``A``, ``S``, ``A^2``, ``S^2``, ``sum w / s``,
    ``sum w t^2 / s``), each row of the rule along (``t2``) a pass over the points across: a loop without
    a chain of sums, whose square roots and divisions run four points at a time (vector operations,
    checked in the compiled code; the torque's rule of a pitch bearing's step, hot, 155 -> 123 us)."""
    n_across = g10.shape[1]
    for i in range(n_across):
        a, s_ = _sliding(c, i, u0, u1, u2, g10, g12, h1, s0, s1, hs)
        points[0, i], points[1, i], points[2, i], points[3, i] = a, s_, a * a, s_ * s_
        points[4, i] = points[5, i] = 0.0
    for k in range(t2.shape[0]):
        t2_k = t2[k]
        for i in range(n_across):
            ws = weight[k, c, i] / math.sqrt(points[2, i] + t2_k * points[3, i] + e2)
            points[4, i] += ws
            points[5, i] += ws * t2_k
    contact_power = contact_torque = 0.0
    for i in range(n_across):
        a, s_ = points[0, i], points[1, i]
        ga, gs = points[4, i] * a, points[5, i] * s_
        contact_power += ga * a + gs * s_
        contact_torque -= ga * arm1[c, i] + gs * arm2[c, i]   # the traction on the ring is minus that on the ball
    return contact_power, contact_torque


def _tractions(u, owner, g10, g12, h1, s0, s1, hs, weight, t2, eps2, arm1, arm2):
    """Dissipated power (C,) and torque on the moving ring (C,) of every contact
    (:func:`_contact_tractions`)."""
    n_contacts = g10.shape[0]
    power = np.zeros(n_contacts)
    torque = np.zeros(n_contacts)
    points = np.empty((POINT_ROWS, g10.shape[1]))
    for c in range(n_contacts):
        b = owner[c]
        power[c], torque[c] = _contact_tractions(c, u[b, 0], u[b, 1], u[b, 2], g10, g12, h1, s0, s1, hs, weight, t2,
                                                 eps2[c], arm1, arm2, points)
    return power, torque


_TRACTIONS_SIGNATURE = c_order("UniTuple(f8[:], 2)(f8[:, :], i8[:], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], "
                               "f8[:, :], f8[:, :, :], f8[:], f8[:], f8[:, :], f8[:, :])")


_MINIMISE_SIGNATURE = c_order("Tuple((f8[:, :], i8[:], f8[:], b1[:]))("
                              "f8[:, :], i8[:], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], "
                              "f8[:, :, :], f8[:], f8[:], f8[:], f8, f8, i8, f8, f8, f8)")


_FRICTION_STEP_SIGNATURE = c_order(
    "Tuple((i8, i8, f8, b1, f8[:], f8[:], f8[:, :], f8[:], f8[:, :], f8[:], f8[:, :], f8[:, :], i8[:]))("
    "f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:], f8[:], b1[:], f8[:], f8[:], f8, f8, f8, f8, f8, "
    "f8[:], f8[:], f8[:, :], f8[:], f8[:], f8[:, :], b1, f8[:, :], f8, i8, f8, f8, f8, f8)")

#: what :func:`_friction_step` answers where the friction torque must take its general path
GENERAL_PATH = -1


def _contact_weight(folded_weight, mu_load_c, weight, c):
    """Row ``c`` of the points' weights ``weight`` (K, C, I): a rule's folded weights (K, I) times a
    contact's ``mu Q``, as ``ContactPoints`` multiplies them."""
    for k in range(folded_weight.shape[0]):
        for i in range(folded_weight.shape[1]):
            weight[k, c, i] = folded_weight[k, i] * mu_load_c


def _rule_weight(folded_weight, mu_load):
    """The points' weights (K, C, I) of a rule's folded weights (K, I) for the contacts' ``mu Q``
    (C,) (:func:`_contact_weight`)."""
    n_fold, n_across = folded_weight.shape
    weight = np.empty((n_fold, mu_load.size, n_across))
    for c in range(mu_load.size):
        _contact_weight(folded_weight, mu_load[c], weight, c)
    return weight


#: step lengths along the first Newton direction of a cold start (``ball_kinematics.cold_start``)
COLD_STEPS = (0.25, 0.5)
#: a ball's warm start is kept where its spin axis tilts towards the normal of its heavier diagonal
#: at least this share of the way rolling on that diagonal does, for a ball loaded on one
#: diagonal, and away from it less than this share for a ball in four-point contact
#: (``ContactSet.stale_warm_start``). The shares at the equilibria of the pitch bearing's NREL series:
#: 1.009-1.014 on one diagonal, 0-1.014 in four-point contact; -1 after a moment reversal, 0 (the
#: axial rolling) after four-point contact
WARM_ROLLING = 0.5


def _diagonal_rolling(rb, alpha, sign, w_o, w_i, big_r, ls, out):
    """``ContactSet.heavier_rolling`` of one ball and diagonal (its outer contact's angle
    ``alpha``, ``sign`` 1 for diagonal 1, -1 for diagonal 2), into ``out`` (3,)."""
    n_r, n_z = math.cos(alpha), sign * math.sin(alpha)
    w_c = 0.5 * (w_o + w_i) + (w_o - w_i) * rb * n_r / (2.0 * big_r)
    w_g = ((w_o - w_c) * big_r + w_o * rb * n_r) / rb
    out[0], out[1], out[2] = -w_g * n_z * ls, w_g * n_r * ls, w_c * big_r


def _cold_start(u, cold, active, first, load, angle, ball_radius, inner_moves, speed, length_scale, pitch_radius,
                g10, g12, h1, s0, s1, hs, weight, t2, eps2):
    """The start of each ``cold`` row of ``u`` (active balls, scaled unknowns), in place:
    :func:`slewing_model.friction.ball_kinematics.cold_start`, ball by ball, with its candidates
    (``ContactSet.initial_guesses``: rolling about the normal of the heavier diagonal, and for a ball
    loaded on both about the axial direction), the one of least power, one Newton step from it and
    the length of least power among 0 and :data:`COLD_STEPS` of it. The other arguments are
    :func:`_minimise_balls`'s (the rule the balls are solved on)."""
    w_o, w_i = (0.0, speed) if inner_moves else (speed, 0.0)
    big_r, ls = pitch_radius, length_scale
    g, h, e = np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    best, other, du, minus_g, trial = np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    work, points = np.empty((3, 4)), np.empty((POINT_ROWS, g10.shape[1]))
    for row in range(active.size):
        if not cold[row]:
            continue
        ball, c0, c1 = active[row], first[row], first[row + 1]
        rb = ball_radius[ball]
        q1, q2 = load[ball, 0], load[ball, 1]
        outer, sign = (0, 1.0) if q1 >= q2 else (3, -1.0)       # the heavier diagonal: 1 (contacts 1, 3), 2 (4, 2)
        _diagonal_rolling(rb, angle[ball, outer], sign, w_o, w_i, big_r, ls, best)
        if q1 > 0.0 and q2 > 0.0:                               # four contacts: the axial rolling too
            r_o = rb * 0.5 * (math.cos(angle[ball, 0]) + math.cos(angle[ball, 3]))
            r_i = -rb * 0.5 * (math.cos(angle[ball, 1]) + math.cos(angle[ball, 2]))
            w_z = (w_i * (big_r + r_i) - w_o * (big_r + r_o)) / (r_i - r_o)
            w_c = (w_o * (big_r + r_o) - r_o * w_z) / big_r
            other[0], other[1], other[2] = 0.0, w_z * ls, w_c * big_r
            if _ball_evaluate(other, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2, False, False, g, h, e,
                              points) < _ball_evaluate(best, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2,
                                                       False, False, g, h, e, points):
                best[:] = other
        f = _ball_evaluate(best, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2, True, False, g, h, e, points)
        minus_g[:] = -g
        _solve3(h, minus_g, du, work)
        length, lowest = 0.0, f
        for t in COLD_STEPS:
            trial[:] = best + t * du
            power = _ball_evaluate(trial, c0, c1, g10, g12, h1, s0, s1, hs, weight, t2, eps2, False, False, g, h, e,
                                   points)
            if power < lowest:
                length, lowest = t, power
        u[row] = best + length * du


def _friction_step(load, angle, semi_a, semi_b, ball_radius, groove_radius, moving, sign_r, sign_z, mu, speed,
                   sliding_regularisation, length_scale, pitch_radius, fine_nodes, fine_t2, fine_weight,
                   solve_nodes, solve_t2, solve_weight, same_rule, warm, tol, max_iterations, theta_down, theta_up,
                   theta_min_up, cage_speed):
    """A warm-started friction torque (:func:`slewing_model.friction.friction_torque`) in one call: the
    loaded contacts (:func:`_contact_set`), the points of the rule the balls are solved on and of
    the torque's (:func:`_point_coefficients`), the balls' equilibrium from ``warm`` (the last
    state, (B, 4); :func:`_minimise_balls`), the contacts' powers and torques (:func:`_rule_tractions`,
    the torque rule's points formed where they are summed) and what is reported per ball
    (:func:`_ball_results`): the loops ``friction_torque`` calls one by one, with the same arguments, so
    the same numbers bit for bit.

    Returns a status (0; :data:`GENERAL_PATH` where the general path must run: a refused
    distribution, whose refusal it words, or no loaded contact),
    the iterations (as ``minimise_power`` counts them), the largest force residual, whether every
    ball converged, the contacts' powers and torques (C,), and :func:`_ball_results`'s.

    A ball without a warm start (newly loaded, or at rest), or with a stale one (its loaded diagonal
    flipped: ``ContactSet.stale_warm_start``), starts as ``friction_torque``'s general path starts it
    (:func:`_cold_start`), so that a step whose contacts changed stays one call."""
    n_balls = load.shape[0]
    (status, where, ball_index, contact_index, owner, active, inactive, rows, moving_c, force_scale) = _contact_set(
        load, angle, semi_a, semi_b, ball_radius, groove_radius, moving, sign_r, sign_z, mu, speed,
        sliding_regularisation)
    empty_i = np.zeros(0, np.int64)
    empty_2 = np.zeros((0, 0))
    empty_1 = np.zeros(0)
    refused = (GENERAL_PATH, 0, 0.0, False, empty_1, empty_1, empty_2, empty_1, empty_2, empty_1, empty_2, empty_2,
               empty_i)
    if status != 0 or active.size == 0 or mu <= 0.0:
        return refused
    scale = (length_scale, length_scale, pitch_radius)
    u = np.empty((active.size, 3))
    cold = np.zeros(active.size, np.bool_)
    w_o, w_i = (0.0, speed) if moving[1] else (speed, 0.0)         # moving[1]: contact 2's, the inner ring
    rolling = np.empty(3)
    for row in range(active.size):                  # the warm start (friction_torque's), or a cold one
        finite, moves = True, False
        for k, column in enumerate((0, 2, 3)):      # SOLVED
            value = warm[active[row], column] * speed * scale[k]
            u[row, k] = value
            finite = finite and math.isfinite(value)
            moves = moves or value != 0.0
        cold[row] = not (finite and moves)
        if not cold[row]:                           # a stale warm start (ContactSet.stale_warm_start): cold
            ball = active[row]
            q1, q2 = load[ball, 0], load[ball, 1]
            outer, sign = (0, 1.0) if q1 >= q2 else (3, -1.0)
            _diagonal_rolling(ball_radius[ball], angle[ball, outer], sign, w_o, w_i, pitch_radius, length_scale,
                              rolling)
            least = -WARM_ROLLING if q1 > 0.0 and q2 > 0.0 else WARM_ROLLING
            cold[row] = not u[row, 0] * rolling[0] >= least * rolling[0] * rolling[0]
    a, b, rb, rd, n_r, n_z, ring_speed = rows[4], rows[5], rows[0], rows[1], rows[2], rows[3], rows[6]
    mu_load, eps2 = rows[7], rows[8]
    first = np.zeros(active.size + 1, np.int64)     # the contacts of each active ball (ordered by ball)
    for j in range(owner.size):
        first[owner[j] + 1] = j + 1
    for row in range(active.size):
        first[row + 1] = max(first[row + 1], first[row])
    if same_rule:                                   # the rule the balls are solved on: the torque's, or its own
        nodes, folded_weight, rule_t2 = fine_nodes, fine_weight, fine_t2
    else:
        nodes, folded_weight, rule_t2 = solve_nodes, solve_weight, solve_t2
    # (each unused value named: numba, inlining the helpers, types every '_' as one variable)
    c10, c12, c1, c0, c1s, chs, _arm1, _arm2 = _point_coefficients(a, b, rb, rd, n_r, n_z, ring_speed, moving_c,
                                                                   nodes, length_scale, pitch_radius)
    rule_weight = _rule_weight(folded_weight, mu_load)
    if cold.any():
        _cold_start(u, cold, active, first, load, angle, ball_radius, moving[1], speed, length_scale,   # moving[1]:
                    pitch_radius, c10, c12, c1, c0, c1s, chs, rule_weight, rule_t2, eps2)  # contact 2's, inner ring
    u, iterations, residual, converged = _minimise_balls(
        u, first, c10, c12, c1, c0, c1s, chs, rule_weight, rule_t2, eps2, force_scale, tol, -1.0, max_iterations,
        theta_down, theta_up, theta_min_up)
    # the torque's rule: its points formed where they are summed (its arrays would be used for nothing else)
    power_c, torque_c = _rule_tractions(u, owner, a, b, rb, rd, n_r, n_z, ring_speed, moving_c, fine_nodes,
                                        length_scale, pitch_radius, fine_weight, mu_load, fine_t2, eps2)
    all_converged = True
    most, largest = 0, 0.0
    for row in range(active.size):                  # as numpy's max(initial=0): a NaN residual shows
        all_converged = all_converged and converged[row]
        most = max(most, iterations[row])
        if largest == largest and not residual[row] <= largest:
            largest = residual[row]
    results = _ball_results(ball_index, contact_index, owner, active, inactive, power_c, u, n_r, n_z, ring_speed,
                            length_scale, pitch_radius, speed, cage_speed if inactive.size else 0.0, n_balls)
    return (0, most if all_converged else max_iterations, largest, all_converged, power_c, torque_c, results[0],
            results[1], results[2], results[3], results[4], results[5], results[6])


#: the helpers the friction's loops call
_HELPERS = ("_sliding", "_contact_sums", "_symmetrise", "_solve3", "_ball_evaluate", "_quadratic", "_damped_step",
            "_step_unchecked", "_contact_set", "_node_sines", "_largest_node", "_contact_points", "_point_coefficients",
            "_contact_weight", "_rule_weight", "_minimise_balls", "_contact_tractions", "_tractions", "_rule_tractions",
            "_ball_results", "_cold_start", "_diagonal_rolling", "_sine_series")


#: numba's error model of these loops: numpy's, a division by zero gives inf or NaN (the divisors are lengths,
#: speeds and pivots that the inputs' checks and the regularisation keep from zero). Python's checks each
#: division and raises: a branch at every point of :func:`_contact_sums` and :func:`_contact_tractions`, which
#: would keep their divisions from overlapping and the tractions' from becoming vector operations
ERROR_MODEL = "numpy"


#: the helpers numba inlines into their callers (its own inlining, before LLVM's choices). Measured on a pitch
#: bearing's step, hot: the balls' equilibrium 360 -> 300 us (``_ball_evaluate``), an evaluation of every ball
#: 197 -> 172 us (``_contact_sums``)
_INLINE = ("_sliding", "_contact_sums", "_sine_series", "_ball_evaluate", "_contact_points", "_contact_tractions",
           "_contact_weight", "_step_unchecked")


#: LLVM's fast-math flags of these loops: ``contract``, a product and the sum it enters as one fused
#: multiply-add (rounded once instead of twice), where the CPU has them. Measured: the friction's one call of
#: the pitch bearing's NREL steps, hot, alternating with and without it call by call in one process, 0.88
#: (821 -> 724 us on a slow day; about 4 % of a step, below what the step's own A/B runs resolve here);
#: torques 3e-16 from the loops without it. Not ``reassoc``
#: (no faster) nor any flag that assumes no NaN or infinity (the loops look for them)
FASTMATH = frozenset({"contract"})


def _compile(function, signature):
    return compile_loop(function, signature, _HELPERS, error_model=ERROR_MODEL, inline=_INLINE, fastmath=FASTMATH)


_CONTACT_SET_SIGNATURE = c_order("Tuple((i8, i8, i8[:], i8[:], i8[:], i8[:], i8[:], f8[:, :], b1[:], f8[:]))("
                                 "f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:], f8[:], b1[:], f8[:], f8[:], "
                                 "f8, f8, f8)")

#: the rows of the per-contact array :func:`_contact_set` returns
CONTACT_ROWS = ("rb", "rd", "n_r", "n_z", "a", "b", "ring_speed", "mu_load", "eps2")
#: what :func:`_contact_set` refuses, after ``1 + k`` for a value of its field ``k`` that is not finite
NEGATIVE_LOAD, NO_ELLIPSE = 5, 6


def _contact_set(load, angle, semi_a, semi_b, ball_radius, groove_radius, moving, sign_r, sign_z, mu, speed,
                 sliding_regularisation):
    """The loaded contacts of a load distribution (``ContactSet``, :mod:`slewing_model.friction.ball_kinematics`,
    whose formulas, checks and order these are: ball by ball, contact by contact).

    ``load``, ``angle``, ``semi_a``, ``semi_b`` (B, 4) the distribution's; ``ball_radius`` (B,);
    ``groove_radius``, ``moving``, ``sign_r``, ``sign_z`` (4,) per contact 1..4. Returns a
    status (0, or what the numpy code refuses: ``1 + k`` the field ``k`` of the four has a
    value that is not finite, :data:`NEGATIVE_LOAD`, :data:`NO_ELLIPSE` a loaded contact
    without an ellipse) with the first contact it refuses (``4 ball + contact``), the ball and
    contact of every loaded contact (C,), the active-ball row of each, the active and inactive
    balls, the (9, C) rows of :data:`CONTACT_ROWS`, ``moving`` (C,) and the force scale
    (active balls,)."""
    n_balls = load.shape[0]
    status, where = 0, -1
    for k, field in enumerate((load, angle, semi_a, semi_b)):
        for b in range(n_balls):
            for c in range(4):
                if status == 0 and not math.isfinite(field[b, c]):
                    status, where = 1 + k, 4 * b + c
    n_contacts = n_active = 0
    for b in range(n_balls):
        loaded_ball = False
        for c in range(4):
            if load[b, c] < 0.0:
                if status == 0 or status == NO_ELLIPSE:
                    status, where = NEGATIVE_LOAD, 4 * b + c
            elif load[b, c] > 0.0:
                if status == 0 and (semi_a[b, c] <= 0.0 or semi_b[b, c] <= 0.0):
                    status, where = NO_ELLIPSE, 4 * b + c
                n_contacts += 1
                loaded_ball = True
        n_active += loaded_ball
    if status:
        none = np.empty(0, np.int64)
        return status, where, none, none, none, none, none, np.empty((9, 0)), np.empty(0, np.bool_), np.empty(0)
    ball_index, contact_index = np.empty(n_contacts, np.int64), np.empty(n_contacts, np.int64)
    owner, active = np.empty(n_contacts, np.int64), np.empty(n_active, np.int64)
    inactive = np.empty(n_balls - n_active, np.int64)
    rows = np.empty((9, n_contacts))
    moving_contact = np.empty(n_contacts, np.bool_)
    force_scale = np.empty(n_active)
    regularisation = sliding_regularisation * abs(speed)
    j = row = idle = 0
    for b in range(n_balls):
        largest = -1.0
        for c in range(4):
            q = load[b, c]
            if q <= 0.0:
                continue
            largest = max(largest, q)
            ball_index[j], contact_index[j], owner[j] = b, c, row
            rb = ball_radius[b]
            rc = groove_radius[c]
            rows[0, j] = rb
            rows[1, j] = 2.0 * rb * rc / (rb + rc)                      # conformity_radius
            rows[2, j] = sign_r[c] * math.cos(angle[b, c])
            rows[3, j] = sign_z[c] * math.sin(angle[b, c])
            rows[4, j] = semi_a[b, c]
            rows[5, j] = semi_b[b, c]
            rows[6, j] = speed if moving[c] else 0.0
            rows[7, j] = mu * q
            rows[8, j] = (regularisation * semi_a[b, c]) ** 2
            moving_contact[j] = moving[c]
            j += 1
        if largest > 0.0:
            active[row] = b
            force_scale[row] = mu * largest
            row += 1
        else:
            inactive[idle] = b
            idle += 1
    return status, where, ball_index, contact_index, owner, active, inactive, rows, moving_contact, force_scale


_BALL_RESULTS_SIGNATURE = c_order("Tuple((f8[:, :], f8[:], f8[:, :], f8[:], f8[:, :], f8[:, :], i8[:]))("
                                  "i8[:], i8[:], i8[:], i8[:], i8[:], f8[:], f8[:, :], f8[:], f8[:], f8[:], "
                                  "f8, f8, f8, f8, i8)")


def _ball_results(ball_index, contact_index, owner, active, inactive, contact_power_c, u, n_r, n_z, ring_speed,
                  length_scale, pitch_radius, speed, cage_speed, n_balls):
    """Per ball and contact, what the friction torque reports of the solved ball motions ``u``
    (active balls, 3) and the contacts' powers (C,): the formulas of
    ``ball_kinematics.ball_results``, in the same order of operations. Returns the contact powers
    (B, 4), the power per ball over ``|speed|`` (B,), the balls' angular velocities (B, 3), orbital
    speeds (B,), the state (B, 4), the spin-to-roll ratios (B, 4) and the loaded contacts' count (B,)."""
    contact_power = np.zeros((n_balls, 4))
    spin_roll = np.zeros((n_balls, 4))
    count = np.zeros(n_balls, np.int64)
    for j in range(ball_index.size):
        b, c, row = ball_index[j], contact_index[j], owner[j]
        contact_power[b, c] = contact_power_c[j]
        count[b] += 1
        # raceway minus ball, W e_z - w, and its components along the normal and about g = (-n_z, 0, n_r)
        rel_r = -u[row, 0] / length_scale
        rel_z = -u[row, 1] / length_scale + ring_speed[j]
        spin = rel_r * n_r[j] + rel_z * n_z[j]
        roll = -rel_r * n_z[j] + rel_z * n_r[j]
        spin_roll[b, c] = spin / roll if roll != 0.0 else 0.0
    per_ball = np.empty(n_balls)
    for b in range(n_balls):
        per_ball[b] = (((contact_power[b, 0] + contact_power[b, 1]) + contact_power[b, 2]) + contact_power[b, 3]) \
            / abs(speed)
    omega_ball = np.zeros((n_balls, 3))
    orbital = np.zeros(n_balls)
    state = np.zeros((n_balls, 4))
    for row in range(active.size):
        b = active[row]
        omega_ball[b, 0] = u[row, 0] / length_scale
        omega_ball[b, 2] = u[row, 1] / length_scale
        orbital[b] = u[row, 2] / pitch_radius
        state[b, 0] = u[row, 0] / (speed * length_scale)          # the solved columns (SOLVED)
        state[b, 2] = u[row, 1] / (speed * length_scale)
        state[b, 3] = u[row, 2] / (speed * pitch_radius)
    for b in inactive:
        orbital[b] = cage_speed
    return contact_power, per_ball, omega_ball, orbital, state, spin_roll, count


#: the largest angle whose sine :func:`_sine_series` gives (its last term's remainder is below
#: 5e-20 of the sine there: a rounding of the sum, no more)
SINE_SERIES_LIMIT = 0.5


def _sine_series(x):
    """``sin x`` for ``|x| <= SINE_SERIES_LIMIT``: its Taylor series to ``x^15 / 15!`` in Horner's form (the
    remainder, ``|x|^17 / 17!``, is below ``4.3e-20 |sin x|`` there). numba calls ``sin`` from the C library
    one angle at a time; a loop of this over the points runs as vector operations (measured: the points'
    coefficients of a pitch bearing's step, both rules, 168 -> 141 us; 97 us with :func:`c_order`).
    The numpy path (``ContactPoints``) takes it for the same contacts: the same numbers."""
    x2 = x * x
    return x * (1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (
        1.0 / 362880.0 + x2 * (-1.0 / 39916800.0 + x2 * (1.0 / 6227020800.0 + x2 * (-1.0 / 1307674368000.0))))))))


def _node_sines(a_c, rd_c, u_nodes, largest_node, sin_t):
    """``sin t_i`` of a contact's points across the groove into ``sin_t`` (I,): ``t_i = a u_i / Rd``, the
    angle of node ``u_i`` (symmetric about 0) on the groove, for the semi-axis ``a_c`` and groove radius
    ``rd_c`` (``ContactPoints.__init__``). Where every angle is within :data:`SINE_SERIES_LIMIT` (a
    contact's a / Rd is at most 0.25 on the pitch bearing), their series: a loop free of calls, which runs
    as vector operations (measured 1.6 times faster). Else the C library's sin, of the nodes u > 0: sin is
    odd and the nodes symmetric, the node I - 1 - i has -sin."""
    n_across = u_nodes.size
    if a_c * (largest_node / rd_c) <= SINE_SERIES_LIMIT:
        for i in range(n_across):
            sin_t[i] = _sine_series(a_c * (u_nodes[i] / rd_c))
    else:
        for i in range(n_across // 2, n_across):
            sin_pos = math.sin(a_c * (u_nodes[i] / rd_c))
            sin_t[n_across - 1 - i] = -sin_pos
            sin_t[i] = sin_pos                       # last: an odd rule's middle node (u = 0) is its own mirror


def _largest_node(u_nodes):
    largest = 0.0
    for i in range(u_nodes.size):
        largest = max(largest, abs(u_nodes[i]))
    return largest


def _contact_points(sin_t, root, rb_c, rd_c, nr, nz, speed, half_width, arm, length_scale, pitch_radius,
                    g10, g12, h1, s0, s1, hs, arm1, arm2):
    """The velocity and lever-arm coefficients ``g10, g12, h1, s0, s1, hs, arm1, arm2`` (I,) of one contact's
    points (their nodes' ``sin t`` and ``sqrt(1 - u^2)``; the contact's ball and groove radii, normal, ring
    speed, semi-axis ``b``, whether its ring is the moving one: the fixed ring's contacts take no torque arm)
    written into the given arrays: the formulas of ``ContactPoints.__init__``
    (:mod:`slewing_model.friction.ball_kinematics`), which derives them, in the same order of operations. A
    loop free of calls: it runs as vector operations."""
    for k in range(sin_t.size):
        sin_k = sin_t[k]
        cos_t = math.sqrt(1.0 - sin_k * sin_k)
        rho = rb_c - rd_c + rd_c * cos_t
        r_r = rho * nr - rd_c * sin_k * nz
        r_z = rho * nz + rd_c * sin_k * nr
        t2_r = -cos_t * nz - sin_k * nr
        t2_z = cos_t * nr - sin_k * nz
        half = half_width * root[k]
        g10[k] = r_z / length_scale
        g12[k] = -r_r / length_scale
        h1[k] = speed * (pitch_radius + r_r)
        s0[k] = -half * t2_z / length_scale
        s1[k] = half * t2_r / length_scale
        hs[k] = -half * speed * t2_r
        arm1[k] = pitch_radius + r_r if arm else 0.0
        arm2[k] = -t2_r * half if arm else 0.0


_COEFFICIENT_SIGNATURE = c_order("UniTuple(f8[:, :], 8)(f8[:], f8[:], f8[:], f8[:], f8[:], f8[:], f8[:], b1[:], f8[:], "
                                 "f8, f8)")


def _point_coefficients(a, b, rb, rd, n_r, n_z, ring_speed, moving, u_nodes, length_scale, pitch_radius):
    """Velocity and lever-arm coefficients (C, I) of every contact (C,) at the across nodes
    ``u_nodes`` (I,, symmetric about 0): ``g10, g12, h1, s0, s1, hs, arm1, arm2``
    (:func:`_node_sines`, :func:`_contact_points`)."""
    n_contacts, n_across = a.size, u_nodes.size
    shape = (n_contacts, n_across)     # eight arrays, each its own (not from a list: then they might alias)
    g10, g12, h1, s0, s1, hs = np.empty(shape), np.empty(shape), np.empty(shape), np.empty(shape), np.empty(shape), \
        np.empty(shape)
    arm1, arm2 = np.empty(shape), np.empty(shape)
    root = np.sqrt(1.0 - u_nodes ** 2)
    sin_t = np.empty(n_across)
    largest_node = _largest_node(u_nodes)
    for c in range(n_contacts):
        _node_sines(a[c], rd[c], u_nodes, largest_node, sin_t)
        _contact_points(sin_t, root, rb[c], rd[c], n_r[c], n_z[c], ring_speed[c], b[c], moving[c], length_scale,
                        pitch_radius, g10[c], g12[c], h1[c], s0[c], s1[c], hs[c], arm1[c], arm2[c])
    return g10, g12, h1, s0, s1, hs, arm1, arm2


def _rule_tractions(u, owner, a, b, rb, rd, n_r, n_z, ring_speed, moving, u_nodes, length_scale, pitch_radius,
                    folded_weight, mu_load, t2, eps2):
    """:func:`_tractions` on a rule whose points' coefficients are used for nothing else (the torque's
    rule where the balls are solved on another): each contact's points formed (:func:`_contact_points`,
    and :func:`_rule_weight`'s weights) where they are summed (:func:`_contact_tractions`), in arrays of
    one contact's size instead of the rule's arrays of every contact (:func:`_point_coefficients`): the
    same numbers, with the rule's ten arrays neither written nor read again."""
    n_contacts, n_across = a.size, u_nodes.size
    power = np.zeros(n_contacts)
    torque = np.zeros(n_contacts)
    root = np.sqrt(1.0 - u_nodes ** 2)
    sin_t = np.empty(n_across)
    shape = (1, n_across)              # one contact's rows, each array its own
    g10, g12, h1, s0, s1, hs = np.empty(shape), np.empty(shape), np.empty(shape), np.empty(shape), np.empty(shape), \
        np.empty(shape)
    arm1, arm2 = np.empty(shape), np.empty(shape)
    weight = np.empty((t2.size, 1, n_across))
    points = np.empty((POINT_ROWS, n_across))
    largest_node = _largest_node(u_nodes)
    for c in range(n_contacts):
        _node_sines(a[c], rd[c], u_nodes, largest_node, sin_t)
        _contact_points(sin_t, root, rb[c], rd[c], n_r[c], n_z[c], ring_speed[c], b[c], moving[c], length_scale,
                        pitch_radius, g10[0], g12[0], h1[0], s0[0], s1[0], hs[0], arm1[0], arm2[0])
        _contact_weight(folded_weight, mu_load[c], weight, 0)
        ball = owner[c]
        power[c], torque[c] = _contact_tractions(0, u[ball, 0], u[ball, 1], u[ball, 2], g10, g12, h1, s0, s1, hs,
                                                 weight, t2, eps2[c], arm1, arm2, points)
    return power, torque


#: (factory, Python function) of each compiled loop of the friction model
KERNELS: list = []
compiled_evaluate_points = loop_factory(KERNELS, _compile, _evaluate_points, _SIGNATURE)
compiled_tractions = loop_factory(KERNELS, _compile, _tractions, _TRACTIONS_SIGNATURE)
compiled_minimise_balls = loop_factory(KERNELS, _compile, _minimise_balls, _MINIMISE_SIGNATURE)
compiled_point_coefficients = loop_factory(KERNELS, _compile, _point_coefficients, _COEFFICIENT_SIGNATURE)
compiled_contact_set = loop_factory(KERNELS, _compile, _contact_set, _CONTACT_SET_SIGNATURE)
compiled_ball_results = loop_factory(KERNELS, _compile, _ball_results, _BALL_RESULTS_SIGNATURE)
compiled_friction_step = loop_factory(KERNELS, _compile, _friction_step, _FRICTION_STEP_SIGNATURE)


def all_kernels(friction: bool = True, contact: bool = True) -> tuple:
    """The compiled loops of a step, the friction's and the load distribution's
    (:mod:`slewing_model.distribution.kernel`) with the life map's (:mod:`slewing_model.life.kernel`):
    (factory, Python function) pairs."""
    return tuple(KERNELS if friction else ()) + tuple(CONTACT_KERNELS + LIFE_KERNELS if contact else ())


def compile_all(friction: bool = True, contact: bool = True) -> None:
    """Compile the loops (the friction's, the contacts'), or load them from numba's cache (what an
    FMU instance does when it starts)."""
    for factory, _ in all_kernels(friction, contact):
        factory()
