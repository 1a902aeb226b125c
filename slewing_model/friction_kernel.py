"""The per-point loop of the friction model, compiled with numba where it is installed.

:meth:`slewing_model.ball_kinematics.ContactPoints.evaluate` sums the regularised dissipated power
``D = sum w s``, ``s = sqrt(A^2 + t^2 S^2 + eps^2)``, its gradient and its Hessian (and the
Weiszfeld majorant ``M - H``) over the quadrature points of every loaded contact, per ball.
With numpy that is some sixty array operations per evaluation, each a few microseconds of
call overhead for a few thousand points: for a 150-ball bearing the overhead, not the
arithmetic, sets the time. :func:`_evaluate_points`, compiled, is the same sum as one loop
over contacts, across-groove nodes and folded along-groove nodes. :func:`_point_coefficients`
is, likewise, the set-up of the points' velocity coefficients (``ContactPoints``), some twenty
array operations done twice a step (the rule the balls are solved on and the torque's).

numba is optional (it is not part of the FMU's run-time requirements): without it
:data:`AVAILABLE` is False and the friction model uses its numpy code, which gives the same
results to round-off (``tests/test_friction_kernel.py``). The loops are compiled when first
asked for (:func:`compiled_evaluate_points`, :func:`compiled_point_coefficients`), which the
simulator does when it is built, so that the compile time lands in the FMU's instantiation,
never in a step.
"""
from __future__ import annotations

import functools
import importlib.util
import math

import numpy as np


def _numba_installed() -> bool:
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False


#: numba can be imported here (it is imported, and the loop compiled, only when first asked for:
#: importing numba also imports scipy, which the run-time part does not otherwise need)
AVAILABLE = _numba_installed()

_SIGNATURE = ("Tuple((f8[:], f8[:, :], f8[:, :, :], f8[:, :, :]))("
              "f8[:, :], i8[:], i8, f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :], f8[:, :, :], "
              "f8[:], f8[:], b1, b1)")


def _evaluate_points(u, owner, n_balls, g10, g12, h1, s0, s1, hs, weight, t2, eps2, derivatives, majorant):
    """Power (B,), gradient (B, 3), Hessian (B, 3, 3) and ``M - H`` (B, 3, 3) of the balls.

    ``u`` (B, 3) the balls' scaled unknowns; ``owner`` (C,) the ball of each contact; the
    coefficients (C, I) of the sliding velocity ``A = g10 u0 + g12 u1 + h1 - u2``,
    ``S = s0 u0 + s1 u1 + hs``; ``weight`` (K, C, I) the quadrature weights times ``mu Q``;
    ``t2`` (K,) the folded ``t^2``; ``eps2`` (C,) the squared regularisation. Without
    ``derivatives`` only the power is summed (the others come back zero), without
    ``majorant`` ``M - H`` comes back zero. The formulas are those of ``ContactPoints.evaluate``."""
    n_contacts, n_across = g10.shape
    n_along = t2.shape[0]
    power = np.zeros(n_balls)
    gradient = np.zeros((n_balls, 3))
    hessian = np.zeros((n_balls, 3, 3))
    extra = np.zeros((n_balls, 3, 3))
    for c in range(n_contacts):
        b = owner[c]
        u0, u1, u2 = u[b, 0], u[b, 1], u[b, 2]
        e2 = eps2[c]
        for i in range(n_across):
            a = g10[c, i] * u0 + g12[c, i] * u1 + (h1[c, i] - u2)
            s_ = s0[c, i] * u0 + s1[c, i] * u1 + hs[c, i]
            a2, s2 = a * a, s_ * s_
            total = 0.0
            alpha = beta = m0 = m1 = m2 = 0.0
            for k in range(n_along):
                speed = math.sqrt(a2 + t2[k] * s2 + e2)
                w = weight[k, c, i]
                total += w * speed
                if derivatives:
                    ws = w / speed                      # w / s
                    alpha += ws
                    beta += ws * t2[k]
                    ws3 = ws / speed / speed            # w / s^3
                    m0 += ws3
                    m1 += ws3 * t2[k]
                    m2 += ws3 * t2[k] * t2[k]
            power[b] += total
            if not derivatives:
                continue
            ga_0, ga_1 = g10[c, i], g12[c, i]           # GA = (g10, g12, -1), GS = (s0, s1, 0)
            gs_0, gs_1 = s0[c, i], s1[c, i]
            grad_a, grad_s = alpha * a, beta * s_       # dD/dA, dD/dS
            gradient[b, 0] += grad_a * ga_0 + grad_s * gs_0
            gradient[b, 1] += grad_a * ga_1 + grad_s * gs_1
            gradient[b, 2] -= grad_a
            e_aa, e_as, e_ss = m0 * a2, m1 * a * s_, m2 * s2
            h_aa, h_ss = alpha - e_aa, beta - e_ss
            # H = h_aa GA GA^T - e_as (GA GS^T + GS GA^T) + h_ss GS GS^T
            hessian[b, 0, 0] += h_aa * ga_0 * ga_0 - e_as * 2.0 * ga_0 * gs_0 + h_ss * gs_0 * gs_0
            hessian[b, 0, 1] += h_aa * ga_0 * ga_1 - e_as * (ga_0 * gs_1 + gs_0 * ga_1) + h_ss * gs_0 * gs_1
            hessian[b, 1, 1] += h_aa * ga_1 * ga_1 - e_as * 2.0 * ga_1 * gs_1 + h_ss * gs_1 * gs_1
            hessian[b, 0, 2] += e_as * gs_0 - h_aa * ga_0
            hessian[b, 1, 2] += e_as * gs_1 - h_aa * ga_1
            hessian[b, 2, 2] += h_aa
            if majorant:  # M - H = e_aa GA GA^T + e_as (GA GS^T + GS GA^T) + e_ss GS GS^T
                extra[b, 0, 0] += e_aa * ga_0 * ga_0 + e_as * 2.0 * ga_0 * gs_0 + e_ss * gs_0 * gs_0
                extra[b, 0, 1] += e_aa * ga_0 * ga_1 + e_as * (ga_0 * gs_1 + gs_0 * ga_1) + e_ss * gs_0 * gs_1
                extra[b, 1, 1] += e_aa * ga_1 * ga_1 + e_as * 2.0 * ga_1 * gs_1 + e_ss * gs_1 * gs_1
                extra[b, 0, 2] -= e_aa * ga_0 + e_as * gs_0
                extra[b, 1, 2] -= e_aa * ga_1 + e_as * gs_1
                extra[b, 2, 2] += e_aa
    for b in range(n_balls):                            # the lower triangles
        for r, c in ((1, 0), (2, 0), (2, 1)):
            hessian[b, r, c] = hessian[b, c, r]
            extra[b, r, c] = extra[b, c, r]
    return power, gradient, hessian, extra


@functools.lru_cache(maxsize=1)
def compiled_evaluate_points():
    """The compiled :func:`_evaluate_points` (numba, eager signature, numba's on-disk cache).

    The first call compiles (about a second) or loads it from the cache;
    :class:`slewing_model.simulator.BearingSimulator` makes that call when it is built, so
    that it lands in the FMU's instantiation and never in a step."""
    import numba

    return numba.njit(_SIGNATURE, cache=True, nogil=True)(_evaluate_points)


_COEFFICIENT_SIGNATURE = ("UniTuple(f8[:, :], 8)(f8[:], f8[:], f8[:], f8[:], f8[:], f8[:], f8[:], b1[:], f8[:], "
                          "f8, f8)")


def _point_coefficients(a, b, rb, rd, n_r, n_z, ring_speed, moving, u_nodes, length_scale, pitch_radius):
    """Velocity and lever-arm coefficients (C, I) of every contact (C,) at the across nodes
    ``u_nodes`` (I,, symmetric about 0): ``g10, g12, h1, s0, s1, hs, arm1, arm2``, the
    formulas of ``ContactPoints.__init__`` (:mod:`slewing_model.ball_kinematics`), which
    derives them, in the same order of operations."""
    n_contacts, n_across = a.size, u_nodes.size
    n_neg = n_across // 2
    out = [np.empty((n_contacts, n_across)) for _ in range(8)]
    g10, g12, h1, s0, s1, hs, arm1, arm2 = out
    root = np.sqrt(1.0 - u_nodes ** 2)
    for c in range(n_contacts):
        for i in range(n_neg, n_across):
            sin_pos = math.sin(a[c] * (u_nodes[i] / rd[c]))
            # sin is odd and the nodes symmetric: the node n_across - 1 - i has -sin_pos
            mirror = n_across - 1 - i
            for side in range(1 if mirror == i else 2):     # the middle node of an odd rule once
                k, sin_t = (i, sin_pos) if side == 0 else (mirror, -sin_pos)
                cos_t = math.sqrt(1.0 - sin_t * sin_t)
                rho = rb[c] - rd[c] + rd[c] * cos_t
                r_r = rho * n_r[c] - rd[c] * sin_t * n_z[c]
                r_z = rho * n_z[c] + rd[c] * sin_t * n_r[c]
                t2_r = -cos_t * n_z[c] - sin_t * n_r[c]
                t2_z = cos_t * n_r[c] - sin_t * n_z[c]
                half = b[c] * root[k]
                g10[c, k] = r_z / length_scale
                g12[c, k] = -r_r / length_scale
                h1[c, k] = ring_speed[c] * (pitch_radius + r_r)
                s0[c, k] = -half * t2_z / length_scale
                s1[c, k] = half * t2_r / length_scale
                hs[c, k] = -half * ring_speed[c] * t2_r
                arm1[c, k] = pitch_radius + r_r if moving[c] else 0.0
                arm2[c, k] = -t2_r * half if moving[c] else 0.0
    return g10, g12, h1, s0, s1, hs, arm1, arm2


@functools.lru_cache(maxsize=1)
def compiled_point_coefficients():
    """The compiled :func:`_point_coefficients` (as :func:`compiled_evaluate_points`)."""
    import numba

    return numba.njit(_COEFFICIENT_SIGNATURE, cache=True, nogil=True)(_point_coefficients)
