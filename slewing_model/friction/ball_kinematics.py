"""Ball kinematics: each ball's rotation and orbital speed from its own equilibrium.

For Coulomb friction at given normal loads the ball's friction moments and its friction
force along the rolling direction vanish where the dissipated power
``D = sum integral mu p |v_s| dA`` is least: a convex function of the ball's unknowns
(angular velocity, orbital speed), so the ball moves so as to dissipate the least power
(the Jones / Leblanc-Nelias line of models, paper refs [17-20]). :class:`ContactSet` holds
the loaded contacts of a load distribution, :class:`ContactPoints` the sliding velocities
at the points of one quadrature rule, and :func:`minimise_power` solves all balls at once
(batched Newton / Weiszfeld iterations; with numba, ball by ball in a compiled loop that
takes the same steps); two and four loaded contacts are the same
equations. :mod:`slewing_model.friction` turns the result into the bearing's torque.

Run-time module: numpy and the standard library (numba where installed, through
:mod:`slewing_model.friction.kernel`).
"""
from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass

import numpy as np

from ..distribution.assembly import ball_diameters
from .contact import conformity_radius
from .ellipse_quadrature import EllipseQuadrature
from .kernel import (
    COLD_STEPS, GENERAL_PATH, NEGATIVE_LOAD, NO_ELLIPSE, SINE_SERIES_LIMIT, UNCHECKED_STEP, WARM_ROLLING, _sine_series,
    compiled_ball_results, compiled_contact_set,
    compiled_evaluate_points, compiled_friction_step, compiled_minimise_balls, compiled_point_coefficients,
    compiled_tractions,
)
from ..bearing.geometry import RING_CONTACTS, Bearing

#: sign of the (r, z) components of the contact normals of contacts 1..4
#: (as :attr:`slewing_model.bearing.geometry.Bearing.contact_normals`)
_NORMAL_SIGN_R = np.array([1.0, -1.0, -1.0, 1.0])
_NORMAL_SIGN_Z = np.array([1.0, 1.0, -1.0, -1.0])
#: for each possible moving ring, which of contacts 1..4 turn with it
_IS_MOVING = {ring: np.isin(np.arange(4), [c - 1 for c in RING_CONTACTS[ring]]) for ring in ("inner", "outer")}
#: columns of the ball state (r w_r, r w_t, r w_z, R w_c) that are solved for (w_t = 0, see ContactPoints)
SOLVED = [0, 2, 3]
#: damping schedule of the Newton / Weiszfeld blend (see minimise_power)
_THETA_DOWN, _THETA_UP, _THETA_MIN_UP = 0.2, 10.0, 0.1
#: iterations after which at most a quarter of the balls left unconverged go on alone (see minimise_power):
#: the numpy loop's (the compiled one solves ball by ball). At once: a warm-started step leaves a few balls
#: unconverged at its start, and every batched evaluation costs all balls' points. Pitch bearing, NREL series,
#: numpy's loops: the step 0.955 of going alone after 1 iteration, the torques equal to 2e-16 (each ball's
#: iterates are its own); table3 heavy (67 balls, a batched evaluation cheaper than a subset's setup) 1.02, yaw
#: within 2 %; after 1 iteration 1.24 ms against 1.54 ms after 3 with an older compiled evaluation
_STRAGGLERS_AFTER = 0


class _Workspace:
    """Work arrays kept between calls, one set per thread and per name.

    The per-point arrays of 67 balls are 0.1-0.2 MB each: allocated afresh on
    every call, each is a new memory mapping whose page faults cost more than
    the arithmetic (measured: ~1000 faults and ~3 ms per call). Views into
    retained flat buffers avoid that; the buffers grow to the largest size
    asked for (a few MB for 67 balls) and are reused."""

    def __init__(self):
        self._arrays: dict[str, np.ndarray] = {}

    def get(self, name: str, shape: tuple) -> np.ndarray:
        size = math.prod(shape)
        flat = self._arrays.get(name)
        if flat is None or flat.size < size:
            flat = np.empty(size)
            self._arrays[name] = flat
        return flat[:size].reshape(shape)


_LOCAL = threading.local()


def _workspace(tag: str) -> _Workspace:
    spaces = getattr(_LOCAL, "spaces", None)
    if spaces is None:
        spaces = _LOCAL.spaces = {}
    if tag not in spaces:
        spaces[tag] = _Workspace()
    return spaces[tag]


#: what :class:`ContactSet` takes of a load distribution, each (B, 4)
_DISTRIBUTION_FIELDS = ("contact_load", "contact_angle", "semi_axis_a", "semi_axis_b")


def _refuse(status: int, where: int, arrays: dict) -> None:
    """ValueError for a load distribution :class:`ContactSet` cannot take, naming the field, the
    ball and contact (``where = 4 ball + contact``), the value and the rule: ``status`` as
    :func:`slewing_model.friction.kernel._contact_set` returns it."""
    ball, contact = divmod(where, 4)
    at = f"of ball {ball + 1}, contact {contact + 1}"
    if status == NEGATIVE_LOAD:
        raise ValueError(f"distribution.contact_load {at} = {float(arrays['contact_load'][ball, contact])!r} N: "
                         "must be >= 0")
    if status == NO_ELLIPSE:
        a, b, q = (float(arrays[name][ball, contact]) for name in ("semi_axis_a", "semi_axis_b", "contact_load"))
        raise ValueError(f"distribution.semi_axis_a/b {at} = {a!r} / {b!r} m: must be > 0 where the contact is "
                         f"loaded ({q!r} N)")
    name = _DISTRIBUTION_FIELDS[status - 1]
    raise ValueError(f"distribution.{name} {at} = {float(arrays[name][ball, contact])!r}: must be finite "
                     "(not NaN or infinite)")


def _first(mask: np.ndarray) -> int:
    """``4 ball + contact`` of the first True of a (B, 4) mask, ball by ball."""
    return int(np.flatnonzero(mask)[0])


def distribution_arrays(bearing: Bearing, distribution, writable: bool = False) -> dict:
    """The contact loads, angles and semi-axes (B, 4) of a load distribution for this bearing (a
    ValueError naming a field of another shape); ``writable`` copies where read-only or not in C order
    (the compiled loops take writable arrays in C order)."""
    n_balls = bearing.ball_count
    arrays = {}
    for name in _DISTRIBUTION_FIELDS:
        value = np.asarray(getattr(distribution, name), dtype=float)
        if writable and not (value.flags.writeable and value.flags.c_contiguous):
            value = np.array(value, order="C")
        if value.shape != (n_balls, 4):
            raise ValueError(f"distribution.{name} has shape {value.shape}, expected ({n_balls}, 4) "
                             f"for this bearing ({bearing.name})")
        arrays[name] = value
    return arrays


def ball_radii(bearing: Bearing) -> np.ndarray:
    """Radius of every ball (B,), m (:func:`slewing_model.distribution.assembly.ball_diameters`)."""
    return 0.5 * ball_diameters(bearing)


class ContactSet:
    """The loaded contacts of a load distribution, and what does not depend on
    the quadrature rule: ball of each contact, normal, ellipse, ring speed."""

    def __init__(self, bearing: Bearing, distribution, mu: float, speed: float, sliding_regularisation: float,
                 compiled: bool = False):
        arrays = distribution_arrays(bearing, distribution, writable=compiled)
        self.ball_radius = ball_radii(bearing)
        self.pitch_radius = 0.5 * bearing.pitch_diameter
        self.length_scale = 0.5 * bearing.ball_diameter
        self.speed = speed
        self.contact_load = q = arrays["contact_load"]
        self.contact_angle = arrays["contact_angle"]
        self.moving_ring = bearing.moving_ring
        if compiled:            # the same, one compiled loop (friction_kernel)
            (status, where, self.ball_index, self.contact_index, self.owner, self.active, self.inactive, rows,
             moving, self.force_scale) = compiled_contact_set()(
                q, self.contact_angle, arrays["semi_axis_a"], arrays["semi_axis_b"], self.ball_radius,
                np.asarray(bearing.groove_radius, dtype=float), _IS_MOVING[bearing.moving_ring], _NORMAL_SIGN_R,
                _NORMAL_SIGN_Z, mu, speed, sliding_regularisation)
            if status:
                _refuse(status, where, arrays)
            self.loaded = q > 0.0
            self.rb, self.rd, self.n_r, self.n_z, self.a, self.b, self.ring_speed = (row[:, None] for row in rows[:7])
            self.mu_load, eps2 = rows[7], rows[8]
            self.eps2 = eps2[:, None]
            self.moving = moving[:, None]
            self.normal = rows[2:4].T
            return
        for k, value in enumerate(arrays.values()):
            if not np.all(np.isfinite(value)):
                _refuse(1 + k, _first(~np.isfinite(value)), arrays)
        if np.any(q < 0.0):
            _refuse(NEGATIVE_LOAD, _first(q < 0.0), arrays)
        loaded = q > 0.0
        no_ellipse = loaded & ((arrays["semi_axis_a"] <= 0.0) | (arrays["semi_axis_b"] <= 0.0))
        if np.any(no_ellipse):
            _refuse(NO_ELLIPSE, _first(no_ellipse), arrays)
        self.loaded = loaded
        self.ball_index, self.contact_index = np.nonzero(loaded)
        active_mask = loaded.any(axis=1)
        self.active = active = np.flatnonzero(active_mask)
        self.inactive = np.flatnonzero(~active_mask)
        position = np.full(bearing.ball_count, -1)
        position[active] = np.arange(active.size)
        self.owner = position[self.ball_index]                # active-ball row of every contact
        b_i, c_i = self.ball_index, self.contact_index
        self.rb = self.ball_radius[b_i][:, None]
        alpha = arrays["contact_angle"][b_i, c_i]
        n_r = _NORMAL_SIGN_R[c_i] * np.cos(alpha)
        n_z = _NORMAL_SIGN_Z[c_i] * np.sin(alpha)
        self.normal = np.stack([n_r, n_z], axis=-1)
        self.n_r, self.n_z = n_r[:, None], n_z[:, None]
        self.rd = conformity_radius(self.rb, bearing.groove_radius[c_i][:, None])
        self.a = arrays["semi_axis_a"][b_i, c_i][:, None]
        self.b = arrays["semi_axis_b"][b_i, c_i][:, None]
        self.moving = _IS_MOVING[bearing.moving_ring][c_i][:, None]
        self.ring_speed = np.where(self.moving, speed, 0.0)
        self.mu_load = mu * q[b_i, c_i]
        self.eps2 = ((sliding_regularisation * abs(speed)) * self.a) ** 2
        self.force_scale = mu * q[active].max(axis=1) if active.size else np.zeros(0)

    @functools.cached_property
    def columns(self) -> tuple:
        """``a, b, rb, rd, n_r, n_z, ring_speed, moving`` as flat (C,) arrays, what the compiled loop
        sets the points of each rule up from (:mod:`slewing_model.friction.kernel`)."""
        return tuple(np.ascontiguousarray(x[:, 0]) for x in (self.a, self.b, self.rb, self.rd, self.n_r, self.n_z,
                                                             self.ring_speed, self.moving))

    @functools.cached_property
    def sum_matrix(self) -> np.ndarray:
        """(B_active, C): per-contact -> per-ball sums of the numpy path (the compiled loops
        sum by ``owner``), made when first asked for."""
        out = np.zeros((self.active.size, self.ball_index.size))
        out[self.owner, np.arange(self.ball_index.size)] = 1.0
        return out

    @functools.cached_property
    def heavier_rolling(self) -> np.ndarray:
        """The rolling motions (B_active, 3), scaled unknowns, about the axis normal to each ball's
        more loaded diagonal (1: contacts 1, 3, where it carries at least diagonal 2's load; else
        2: contacts 4, 2), rolling without sliding at the diagonal's two contact centres (the
        classical two-contact kinematics); made when first asked for (by :meth:`stale_warm_start`
        and :meth:`initial_guesses` of one step)."""
        q = self.contact_load[self.active]
        alpha = self.contact_angle[self.active]
        rb = self.ball_radius[self.active]
        big_r, ls = self.pitch_radius, self.length_scale
        w_o, w_i = (0.0, self.speed) if self.moving_ring == "inner" else (self.speed, 0.0)
        diagonals = []
        for outer, sign in ((0, 1.0), (3, -1.0)):          # diagonal 1 (contacts 1, 3), diagonal 2 (4, 2)
            n_r, n_z = np.cos(alpha[:, outer]), sign * np.sin(alpha[:, outer])
            # v . t = 0 at the outer contact (normal n) and at the inner one (-n), w = w_g g, g = (-n_z, 0, n_r)
            w_c = 0.5 * (w_o + w_i) + (w_o - w_i) * rb * n_r / (2.0 * big_r)
            w_g = ((w_o - w_c) * big_r + w_o * rb * n_r) / rb
            diagonals.append(np.stack([-w_g * n_z * ls, w_g * n_r * ls, w_c * big_r], axis=-1))
        return np.where((q[:, 0] >= q[:, 1])[:, None], diagonals[0], diagonals[1])

    def initial_guesses(self) -> np.ndarray:
        """Candidate scaled unknowns (2, B_active, 3) for a cold start, each a
        rolling motion without sliding at contact centres:

        0. about an axis normal to the more loaded diagonal (:attr:`heavier_rolling`);
        1. about the axial direction (``w_r = 0``), rolling at the centres of
           the outer and of the inner contacts (the motion of a symmetric
           four-contact ball; measured, it stays near the equilibrium until one
           diagonal carries about ten times the other).

        For a ball with one loaded diagonal both are the first. (A blend of
        the two diagonals' motions in proportion to their loads, tried too,
        was slower overall.)"""
        q = self.contact_load[self.active]
        alpha = self.contact_angle[self.active]
        rb = self.ball_radius[self.active]
        big_r, ls = self.pitch_radius, self.length_scale
        w_o, w_i = (0.0, self.speed) if self.moving_ring == "inner" else (self.speed, 0.0)
        heavier = self.heavier_rolling
        q1, q2 = q[:, 0], q[:, 1]
        # v . t = -r_r w_z - R w_c + W (R + r_r) = 0 at the outer (r_r > 0) and inner (r_r < 0) centres
        r_o = rb * 0.5 * (np.cos(alpha[:, 0]) + np.cos(alpha[:, 3]))
        r_i = -rb * 0.5 * (np.cos(alpha[:, 1]) + np.cos(alpha[:, 2]))
        w_z = (w_i * (big_r + r_i) - w_o * (big_r + r_o)) / (r_i - r_o)
        w_c = (w_o * (big_r + r_o) - r_o * w_z) / big_r
        axial = np.stack([np.zeros_like(w_z), w_z * ls, w_c * big_r], axis=-1)
        four = ((q1 > 0.0) & (q2 > 0.0))[:, None]
        return np.stack([heavier, np.where(four, axial, heavier)])

    def stale_warm_start(self, u: np.ndarray) -> np.ndarray:
        """The balls (B_active,) whose motion ``u`` (a warm start, scaled unknowns) belongs to
        another contact set: its spin axis tilts towards the normal of the heavier diagonal less
        than :data:`~slewing_model.friction.kernel.WARM_ROLLING` of the way rolling on it does
        (:attr:`heavier_rolling`'s radial component), for a ball loaded on one diagonal, or away
        from it by more than that share, for a ball in four-point contact (whose equilibria lie
        between the axial rolling, 0, and the diagonal's, 1). A ball whose heavier diagonal flipped
        (a moment reversed) or that left four-point contact (the first load after a preload)
        then starts cold (measured, compiled: the pitch bearing's friction after a reversal of its
        mean load 0.70 ms instead of 1.04; rigid reversals of table1 and table3 0.6 and 0.3 ms
        instead of 0.9 and 0.4)."""
        q = self.contact_load[self.active]
        tilt = self.heavier_rolling[:, 0]
        least = np.where((q[:, 0] > 0.0) & (q[:, 1] > 0.0), -WARM_ROLLING, WARM_ROLLING)
        return ~(u[:, 0] * tilt >= least * tilt * tilt)


@dataclass(frozen=True)
class ContactSubset:
    """What :class:`ContactPoints` and :func:`minimise_power` use of a :class:`ContactSet`,
    for some of its balls (:meth:`ContactPoints.subset`)."""

    owner: np.ndarray
    sum_matrix: np.ndarray
    eps2: np.ndarray
    force_scale: np.ndarray
    active: np.ndarray


class ContactPoints:
    """Sliding velocities of the loaded contacts at the points of one rule.

    The unknowns of active ball ``b`` are ``u = (r w_r, r w_z, R w_c)`` (m/s;
    ``r = Dw/2``, ``R = dm/2``; ``w_r``, ``w_z`` the ball's angular velocity
    along its radial and axial directions, ``w_c`` its orbital speed). Its
    tangential component ``w_t`` is zero at the equilibrium and is not solved
    for: the rule is symmetric in ``xi``, the mirror ``xi -> -xi`` maps the
    power at ``w_t`` onto the power at ``-w_t``, and a convex function even in
    ``w_t`` has its minimum at ``w_t = 0``.

    For contact ``c`` (of active ball ``owner[c]``) and point ``(t, i)``
    (``t`` along the rolling direction, ``i`` across the groove), the
    tangential sliding velocity, raceway minus ball, is

    ``v1 = A_ci = g10 u0 + g12 u1 - u2 + h1``     along the rolling direction,
    ``v2 = t S_ci,  S_ci = s0 u0 + s1 u1 + hs``   across the (bent) groove

    (coefficients (C, I)): the contact surface is flat along the rolling
    direction, so ``v1`` depends on the across position only and ``v2`` is
    linear in ``xi = t b sqrt(1 - u_i^2)``. ``|v|^2 = A^2 + t^2 S^2``
    depends on ``t^2`` only: the along nodes ``+t`` and ``-t`` fold into one,
    and the per-point arrays are (K, C, I) with K the distinct ``t^2``.

    Derivation: ``v = W e_z x (c + r) - w_c e_z x c - w x r`` with ``W`` the
    raceway's speed (``omega`` or 0), ``c = R e_r`` the ball centre and ``r``
    the point on the bent surface relative to it."""

    def __init__(self, geometry: ContactSet, quad: EllipseQuadrature, workspace: str = "fine",
                 compiled: bool = False):
        geo = self.geometry = geometry
        self.compiled = compiled           # evaluate with the compiled loop (friction_kernel)
        u_nodes, self.t2, weight = quad.writable_arrays   # (the compiled loops take no read-only arrays)
        if compiled:                       # the same formulas, one compiled loop (friction_kernel)
            (self.g10, self.g12, self.h1, self.s0, self.s1, self.hs, self.arm1,
             self.arm2) = compiled_point_coefficients()(*geo.columns, u_nodes, geo.length_scale, geo.pitch_radius)
        else:
            self._coefficients(geo, u_nodes)
        space = self._space = _workspace(workspace)
        shape = (self.t2.size, geo.ball_index.size, quad.n_across)
        self.weight = np.multiply(weight[:, None, :], geo.mu_load[:, None], out=space.get("weight", shape))
        if not compiled:                   # the numpy path's work arrays
            self._s, self._k, self._k3 = (space.get(name, shape) for name in ("s", "k", "k3"))
        self._ones = np.ones(quad.n_across)
        self._products = None

    def _coefficients(self, geo: ContactSet, u_nodes: np.ndarray) -> None:
        """The velocity coefficients ``g10 .. hs`` and lever arms ``arm1, arm2`` (C, I), numpy."""
        ls, big_r = geo.length_scale, geo.pitch_radius
        rb, rd, n_r, n_z, ring_speed = geo.rb, geo.rd, geo.n_r, geo.n_z, geo.ring_speed
        # sin of the angle a u / Rd (C, I), |angle| < pi/2: a contact whose angles are all within
        # SINE_SERIES_LIMIT takes the sine's series, as the compiled loop does (the same numbers); the others
        # np.sin, of the nodes u > 0 (the nodes are symmetric and sin is odd)
        n_i, n_neg = u_nodes.size, u_nodes.size // 2
        series = geo.a * (np.abs(u_nodes).max() / rd) <= SINE_SERIES_LIMIT
        if not np.all(series):
            sin_pos = np.sin(geo.a * (u_nodes[n_neg:] / rd))
            sin_t = np.concatenate([-sin_pos[:, n_i - n_neg - 1::-1][:, :n_neg], sin_pos], axis=1)
        if np.any(series):          # (all of them, as a rule: a pitch bearing's contacts are narrow)
            angle = geo.a * (u_nodes / rd)
            sine = getattr(_sine_series, "py_func", _sine_series)(angle)
            sin_t = sine if np.all(series) else np.where(series, sine, sin_t)
        cos_t = np.sqrt(1.0 - sin_t * sin_t)
        # point relative to the ball centre in the ball frame (r, t, z):
        # (rb - Rd + Rd cos) n + Rd sin g + xi t,  g = n x t = (-n_z, 0, n_r)
        rho = rb - rd + rd * cos_t
        r_r = rho * n_r - rd * sin_t * n_z
        r_z = rho * n_z + rd * sin_t * n_r
        t2_r = -cos_t * n_z - sin_t * n_r                                # second tangent cos g - sin n
        t2_z = cos_t * n_r - sin_t * n_z
        #   v . t  = r_z w_r - r_r w_z - R w_c + W (R + r_r)
        #   v . T2 = xi (-T2_z w_r + T2_r w_z - W T2_r)       (w_t = 0)
        half = geo.b * np.sqrt(1.0 - u_nodes**2)                        # xi = half * t
        self.g10, self.g12 = r_z / ls, -r_r / ls
        self.h1 = ring_speed * (big_r + r_r)
        self.s0, self.s1, self.hs = -half * t2_z / ls, half * t2_r / ls, -half * ring_speed * t2_r
        # lever arm of the moving ring's torque: e_z x (c + r) . v = arm1 v1 + arm2 t^2 S
        self.arm1 = np.where(geo.moving, big_r + r_r, 0.0)
        self.arm2 = np.where(geo.moving, -t2_r * half, 0.0)

    def _prepare_derivatives(self) -> None:
        """Coefficient products of the Hessian (derivatives only)."""
        g10, g12, s0, s1 = self.g10, self.g12, self.s0, self.s1
        self._products = (g10 * g10, g10 * g12, g12 * g12, s0 * s0, s0 * s1, s1 * s1,
                          2.0 * g10 * s0, g10 * s1 + s0 * g12, 2.0 * g12 * s1)
        self._rows = self._space.get("rows", (15,) + g10.shape)

    def subset(self, balls: np.ndarray) -> "ContactPoints":
        """The same rule restricted to the contacts of some active balls
        (their rows, in order): for the last iterations of a few balls."""
        geo = self.geometry
        rows = np.flatnonzero(np.isin(geo.owner, balls))
        position = np.full(geo.active.size, -1)
        position[balls] = np.arange(balls.size)
        owner = position[geo.owner[rows]]
        sum_matrix = np.zeros((balls.size, rows.size))
        sum_matrix[owner, np.arange(rows.size)] = 1.0
        sub = object.__new__(ContactPoints)
        sub.geometry = ContactSubset(owner=owner, sum_matrix=sum_matrix, eps2=geo.eps2[rows],
                               force_scale=geo.force_scale[balls], active=geo.active[balls])
        for name in ("g10", "g12", "h1", "s0", "s1", "hs", "arm1", "arm2"):
            setattr(sub, name, getattr(self, name)[rows])
        sub.t2, sub.weight = self.t2, np.ascontiguousarray(self.weight[:, rows])   # (the compiled loops take C order)
        sub._s, sub._k, sub._k3 = (np.empty_like(sub.weight) for _ in range(3))
        sub._products = None
        sub._ones = self._ones
        sub.compiled = self.compiled
        sub._space = _Workspace()
        return sub

    def velocity(self, u: np.ndarray):
        """``A`` and ``S`` (C, I) for the scaled unknowns ``u`` (B_active, 3)."""
        uc = u[self.geometry.owner]
        u0, u1, u2 = uc[:, 0, None], uc[:, 1, None], uc[:, 2, None]
        return self.g10 * u0 + self.g12 * u1 + (self.h1 - u2), self.s0 * u0 + self.s1 * u1 + self.hs

    def _speed(self, a2, s2, eps2):
        """``s = sqrt(A^2 + t^2 S^2 + eps^2)`` (K, C, I), in a work buffer."""
        s = self._s
        for k, t2 in enumerate(self.t2):
            np.multiply(s2, t2, out=s[k])
            s[k] += a2
        s += self._points_eps2(eps2, a2.shape)
        np.sqrt(s, out=s)
        return s

    def _points_eps2(self, eps2, shape):
        """``eps2`` (C, 1) spread over the points (C, I), kept while ``eps2`` is the same array: added to
        the (K, C, I) speeds it is one pass over them, where the column took an inner loop of I points per
        contact (arrays of (5, 372, 20): 47-60 us a pass with the column, 24 us spread)."""
        kept = getattr(self, "_eps2", None)
        if kept is None or kept[0] is not eps2 or kept[1].shape != shape:
            kept = self._eps2 = (eps2, np.ascontiguousarray(np.broadcast_to(eps2, shape)))
        return kept[1]

    def _moment(self, x, power):
        """``sum_K x t^(2 power)`` (C, I); with one ``t^2`` and ``power = 0``, a view of ``x[0]``."""
        if self.t2.size == 1:
            return x[0] * self.t2[0] ** power if power else x[0]
        out = x[0] * self.t2[0] ** power
        for k in range(1, self.t2.size):
            out += x[k] * self.t2[k] ** power
        return out

    def evaluate(self, u: np.ndarray, eps2: np.ndarray, derivatives: bool = True, majorant: bool = False):
        """Regularised dissipated power ``D = sum w s``, ``s = sqrt(A^2 + t^2 S^2 + eps^2)``,
        of every active ball (W); with ``derivatives`` also its gradient
        (B, 3) and its Hessian ``H`` (B, 3, 3); with ``majorant`` also ``M - H``
        where ``M = sum (w/s) G^T G >= H`` is the Hessian of the quadratic
        majorant of ``D`` at ``u`` (Weiszfeld), ``G`` the rows ``(GA, t GS)``,
        ``GA = (g10, g12, -1)``, ``GS = (s0, s1, 0)`` (None without it).

        In ``(A, S)``: ``ds = (A, t^2 S) / s``, and the Hessian of ``s`` is
        ``diag(1, t^2) / s - (A, t^2 S)(A, t^2 S)^T / s^3``, whose first part is
        the majorant's. Summed over the points, per (C, I):
        ``M = alpha GA GA^T + beta GS GS^T`` and
        ``M - H = e_aa GA GA^T + e_as (GA GS^T + GS GA^T) + e_ss GS GS^T``
        with ``alpha = sum w/s``, ``beta = sum w t^2/s``, ``e_aa = A^2 sum w/s^3``,
        ``e_as = A S sum w t^2/s^3``, ``e_ss = S^2 sum w t^4/s^3``.

        With ``compiled`` the same sums come from one compiled loop
        (:func:`slewing_model.friction.kernel.compiled_evaluate_points`)."""
        geo = self.geometry
        if self.compiled:
            kernel = compiled_evaluate_points()
            f, g, h, x = kernel(np.ascontiguousarray(u, dtype=float), geo.owner, geo.active.size,
                                self.g10, self.g12, self.h1, self.s0, self.s1, self.hs, self.weight, self.t2,
                                np.ravel(eps2), derivatives, majorant)
            return (f, g, h, x if majorant else None) if derivatives else (f, None, None, None)
        a, s_ = self.velocity(u)
        a2, s2 = a * a, s_ * s_
        s = self._speed(a2, s2, eps2)
        k = self._k
        np.multiply(self.weight, s, out=k)
        n_i = k.shape[2]
        ones = self._ones
        f_c = (k.reshape(-1, n_i) @ ones).reshape(k.shape[:2]).sum(axis=0)   # BLAS: short axis
        if not derivatives:
            return self._per_ball(f_c), None, None, None
        if self._products is None:
            self._prepare_derivatives()
        p00, p01, p11, q00, q01, q11, x00, x01, x11 = self._products
        g10, g12, s0, s1 = self.g10, self.g12, self.s0, self.s1
        k3 = self._k3
        np.divide(self.weight, s, out=k)                                 # w / s
        alpha, beta = self._moment(k, 0), self._moment(k, 1)
        rows = self._rows
        # gradient: dD/dA = alpha A, dD/dS = beta S
        ga, gs = alpha * a, beta * s_
        np.multiply(ga, g10, out=rows[0])
        rows[0] += gs * s0
        np.multiply(ga, g12, out=rows[1])
        rows[1] += gs * s1
        np.negative(ga, out=rows[2])
        np.divide(k, s, out=k3)
        k3 /= s                                                          # w / s^3
        e_aa = self._moment(k3, 0) * a2
        e_as = self._moment(k3, 1) * a
        e_as *= s_
        e_ss = self._moment(k3, 2) * s2
        # H = M - (M - H) per (C, I): h_aa GA GA^T + h_as (GA GS^T + GS GA^T) + h_ss GS GS^T
        h_aa = alpha - e_aa
        h_ss = beta - e_ss
        # rows 3..8: entries 00, 01, 02, 11, 12, 22 of H; rows 9..14: the same of M - H
        for row, paa, pas, pss in ((3, p00, x00, q00), (4, p01, x01, q01), (6, p11, x11, q11)):
            np.multiply(h_aa, paa, out=rows[row])
            rows[row] -= e_as * pas
            rows[row] += h_ss * pss
        for row, ga_k, gs_k in ((5, g10, s0), (7, g12, s1)):            # GA_2 = -1, GS_2 = 0
            np.multiply(e_as, gs_k, out=rows[row])
            rows[row] -= h_aa * ga_k
        rows[8] = h_aa
        n_rows = 9
        if majorant:
            n_rows = 15
            for row, paa, pas, pss in ((9, p00, x00, q00), (10, p01, x01, q01), (12, p11, x11, q11)):
                np.multiply(e_aa, paa, out=rows[row])
                rows[row] += e_as * pas
                rows[row] += e_ss * pss
            for row, ga_k, gs_k in ((11, g10, s0), (13, g12, s1)):
                np.multiply(e_aa, ga_k, out=rows[row])
                rows[row] += e_as * gs_k
                np.negative(rows[row], out=rows[row])
            rows[14] = e_aa
        sums = self._per_ball((rows[:n_rows].reshape(-1, n_i) @ ones).reshape(n_rows, -1))   # (rows, B)
        sym = [0, 1, 2, 1, 3, 4, 2, 4, 5]
        hessian = sums[3:9].T[:, sym].reshape(-1, 3, 3)
        extra = sums[9:15].T[:, sym].reshape(-1, 3, 3) if majorant else None
        return self._per_ball(f_c), sums[:3].T, hessian, extra

    def _per_ball(self, per_contact: np.ndarray) -> np.ndarray:
        """Per-contact values (..., C) summed per active ball (..., B): each ball's contacts, which follow
        one another (``owner`` is sorted), added in their order (``np.add.reduceat``), where the product
        with ``sum_matrix`` (B, C) took 80 of a 500-us evaluation (pitch bearing, 370 contacts); that
        product where a ball has no contact or ``owner`` is not sorted."""
        starts = getattr(self, "_ball_starts", None)
        if starts is None:
            owner, n_balls = self.geometry.owner, self.geometry.active.size
            starts = np.searchsorted(owner, np.arange(n_balls))
            ordered = owner.size > 0 and bool(np.all(np.diff(owner) >= 0)) and bool(
                np.all(np.diff(np.append(starts, owner.size)) > 0))
            self._ball_starts = starts = starts if ordered else False
        if starts is False:
            return per_contact @ self.geometry.sum_matrix.T
        return np.add.reduceat(per_contact, starts, axis=-1)

    def tractions(self, u: np.ndarray):
        """Dissipated power (W) and torque on the moving ring about +z (N m) of
        every contact, at the final regularisation (with ``compiled``: one compiled loop,
        :func:`slewing_model.friction.kernel.compiled_tractions`)."""
        geo = self.geometry
        if self.compiled:
            return compiled_tractions()(np.ascontiguousarray(u, dtype=float), geo.owner, self.g10, self.g12, self.h1,
                                        self.s0, self.s1, self.hs, self.weight, self.t2, np.ravel(geo.eps2),
                                        self.arm1, self.arm2)
        a, s_ = self.velocity(u)
        a2, s2 = a * a, s_ * s_
        s = self._speed(a2, s2, self.geometry.eps2)
        k = np.divide(self.weight, s, out=self._k)                       # |traction on the ball| / |v|
        ga, gs = self._moment(k, 0) * a, self._moment(k, 1) * s_         # tractions . (A, S) directions
        power = np.einsum("ci,ci->c", ga, a) + np.einsum("ci,ci->c", gs, s_)
        # the traction on the ring is minus that on the ball
        torque = -(np.einsum("ci,ci->c", ga, self.arm1) + np.einsum("ci,ci->c", gs, self.arm2))
        return power, torque


def solve_per_ball(a: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``a^-1 rhs`` for a stack of small symmetric systems (B, m, m), (B, m)."""
    try:
        return np.linalg.solve(a, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:                           # a singular H (not met): regularise
        m = a.shape[-1]
        d = np.maximum(np.einsum("bii->b", a) / m, 1e-300)
        return np.linalg.solve(a + 1e-13 * d[:, None, None] * np.eye(m), rhs[..., None])[..., 0]


def cold_start(geometry: ContactSet, contacts: ContactPoints, u: np.ndarray, cold: np.ndarray) -> np.ndarray:
    """Starting ball motions (scaled unknowns) for the balls marked ``cold``.

    Per ball the candidate of least power (:meth:`ContactSet.initial_guesses`),
    then one Newton step from it, line-searched on the power over the lengths
    ``0, 1/4, 1/2`` (:data:`~slewing_model.friction.kernel.COLD_STEPS`): from a rolling motion the Newton
    direction points at the minimum (measured on table3's two-contact balls:
    cosine 1.00 with the direction to it) but the full step overshoots it
    about three times, because the power curves less there than at the
    minimum. A ball near the 4 -> 2 contact transition keeps length 0. Costs four evaluations of the power and one of its
    derivatives; the minimisation then starts with Newton steps."""
    eps2 = geometry.eps2
    candidates = geometry.initial_guesses()
    power = np.stack([contacts.evaluate(c, eps2, derivatives=False)[0] for c in candidates])
    best = np.take_along_axis(candidates, np.argmin(power, axis=0)[None, :, None], axis=0)[0]
    start = np.where(cold[:, None], best, u)
    f, g, h, _ = contacts.evaluate(start, eps2)
    du = np.where(cold[:, None], solve_per_ball(h, -g), 0.0)
    lengths = np.array((0.0,) + COLD_STEPS)
    power = np.stack([f] + [contacts.evaluate(start + t * du, eps2, derivatives=False)[0] for t in COLD_STEPS])
    return start + lengths[np.argmin(power, axis=0)][:, None] * du


def minimise_power(contacts: ContactPoints, u: np.ndarray, tol: float, max_iterations: int,
              theta: np.ndarray | None = None, floor: float | None = None):
    """Minimise the regularised dissipated power of every active ball (batched).

    Step ``du = -(H + theta (M - H))^-1 g`` per ball: ``theta = 1`` is the
    Weiszfeld (iteratively reweighted least squares) step, which lowers the
    power however far from the minimum, where Newton's step (``theta = 0``)
    can overshoot by orders of magnitude (the power is nearly linear in some
    directions when every point slides); ``theta = 0`` converges
    quadratically near the minimum. ``theta`` (B,) starts as given (default
    0: Newton), shrinks after each step that lowers the power by at least
    half the predicted amount, and grows for a ball whose step fails (the
    step is then retried at once). Every trial point is evaluated with its
    derivatives, so an accepted step costs one evaluation; ``M - H`` is
    computed only while some ball has ``theta > 0``.

    Stopping rule: the Newton decrement ``g . H^-1 g`` of every ball is at
    most ``tol (D_b + floor)``, ``D_b`` its power and ``floor`` the mean
    power per ball at the start (unless given): each ball's power is within
    ``tol`` of the mean of its own power and the average one, so the total is
    within ``tol`` of its minimum (the start is above it: the test is a
    little looser than at the minimum, by the warm start's excess power), and
    a ball that carries almost nothing is not iterated to a relative accuracy
    that cannot show in the torque. That last Newton step is taken where it
    lowers the power (also by the converged balls when others run out of
    iterations), unchecked where it is small
    (:data:`~slewing_model.friction.kernel.UNCHECKED_STEP`). When at most a
    quarter of the balls are left after :data:`_STRAGGLERS_AFTER` iterations,
    they go on alone (:meth:`ContactPoints.subset`), the others take that last
    step.

    The floor fixed, every ball's iterates depend on its own contacts only: the
    compiled loop (``contacts.compiled``) solves ball after ball
    (:func:`slewing_model.friction.kernel.compiled_minimise_balls`), taking the
    same steps as this batched numpy loop.

    Returns ``(u, iterations, residual, converged)``; ``iterations``: the most
    a ball took; ``residual``: the largest force residual of a ball, relative
    to ``mu Q_max``, at its last evaluation."""
    eps2 = contacts.geometry.eps2
    n, m = u.shape
    scale = contacts.geometry.force_scale
    if contacts.compiled and theta is None:
        return _minimise_compiled(contacts, u, tol, max_iterations, -1.0 if floor is None else floor)
    theta = np.zeros(n) if theta is None else np.array(theta, dtype=float)
    f, g, h, extra = contacts.evaluate(u, eps2, majorant=bool(np.any(theta)))
    share = f.mean() if floor is None else floor            # fixed: each ball's iterates are its own
    iterations = 0

    def residual():
        return float(np.max(np.abs(g).max(axis=1) / scale))

    def last_newton_step(done):              # where it lowers the power, checked unless small (UNCHECKED_STEP)
        trial = np.where(done[:, None], u + newton, u)
        keep = done & (np.abs(newton).max(axis=1) <= UNCHECKED_STEP * np.abs(u).max(axis=1))
        if np.any(done & ~keep):
            keep |= done & (contacts.evaluate(trial, eps2, derivatives=False)[0] <= f * (1.0 + 1e-12))
        return np.where(keep[:, None], trial, u)

    while True:
        newton = solve_per_ball(h, -g)
        decrement = -np.einsum("bk,bk->b", g, newton)
        done = decrement <= tol * (f + share)
        if np.all(done):
            return last_newton_step(done), iterations + 1, residual(), True
        if iterations >= max_iterations:
            return last_newton_step(done), iterations, residual(), False
        left = np.flatnonzero(~done)
        if iterations >= _STRAGGLERS_AFTER and n >= 8 and 4 * left.size <= n:   # a long tail: the stragglers alone
            res_done = float(np.max(np.abs(g[done]).max(axis=1) / scale[done]))
            u = last_newton_step(done)
            u[left], more, res_left, converged = minimise_power(contacts.subset(left), u[left], tol,
                                                           max_iterations - iterations, theta[left], share)
            return u, iterations + more, max(res_done, res_left), converged
        iterations += 1
        if np.any(theta):
            if extra is None:                                       # theta rose after a Newton step
                f, g, h, extra = contacts.evaluate(u, eps2, majorant=True)
            du = solve_per_ball(h + theta[:, None, None] * extra, -g)
            slope = np.einsum("bk,bk->b", g, du)
            predicted = -(slope + 0.5 * np.einsum("bk,bkl,bl->b", du, h, du))
        else:
            du, slope = newton, -decrement
            predicted = 0.5 * decrement
        du[done] = 0.0                                              # converged balls wait
        slope[done] = predicted[done] = 0.0
        trial = u + du
        pending = np.ones(n, dtype=bool)
        for _ in range(12):
            f_t, g_t, h_t, x_t = contacts.evaluate(trial, eps2, majorant=bool(np.any(theta)))
            actual = f - f_t
            good = pending & ((actual >= -1e-4 * slope) | (np.abs(actual) <= 1e-13 * np.abs(f)))
            very = good & (actual >= 0.5 * predicted)
            theta = np.where(very, np.where(theta > 1e-3, _THETA_DOWN * theta, 0.0), theta)
            pending &= ~good
            if not np.any(pending) or np.all(theta[pending] >= 1.0):   # done, or Weiszfeld failed: round-off
                break
            theta[pending] = np.minimum(1.0, np.maximum(_THETA_UP * theta[pending], _THETA_MIN_UP))
            if extra is None:
                f, g, h, extra = contacts.evaluate(u, eps2, majorant=True)
            du[pending] = solve_per_ball(h[pending] + theta[pending, None, None] * extra[pending], -g[pending])
            slope = np.einsum("bk,bk->b", g, du)
            predicted = -(slope + 0.5 * np.einsum("bk,bkl,bl->b", du, h, du))
            trial[pending] = u[pending] + du[pending]
        if np.any(pending):                       # no step lowered their power: those balls stay
            trial[pending] = u[pending]
            f_t[pending], g_t[pending], h_t[pending] = f[pending], g[pending], h[pending]
            if x_t is not None and extra is not None:
                x_t[pending] = extra[pending]
            else:
                x_t = None                                          # recomputed if a ball needs it
        u, f, g, h, extra = trial, f_t, g_t, h_t, x_t


def _minimise_compiled(contacts: ContactPoints, u: np.ndarray, tol: float, max_iterations: int, floor: float):
    """:func:`minimise_power` ball by ball in one compiled loop
    (:func:`slewing_model.friction.kernel.compiled_minimise_balls`): the same steps
    (``floor < 0``: the mean power at ``u``, as the numpy loop takes it)."""
    geo = contacts.geometry
    first = np.searchsorted(geo.owner, np.arange(u.shape[0] + 1))      # contacts are ordered by ball
    u, iterations, residual, converged = compiled_minimise_balls()(
        np.ascontiguousarray(u, dtype=float), first, contacts.g10, contacts.g12, contacts.h1, contacts.s0,
        contacts.s1, contacts.hs, contacts.weight, contacts.t2, np.ravel(geo.eps2), geo.force_scale, tol, floor,
        max_iterations, _THETA_DOWN, _THETA_UP, _THETA_MIN_UP)
    # as the numpy loop counts: the most a ball took, or max_iterations when some ball ran out
    done = bool(converged.all())
    return u, int(iterations.max(initial=0)) if done else max_iterations, float(residual.max(initial=0.0)), done


def ball_results(geometry: ContactSet, u: np.ndarray, contact_power: np.ndarray, n_balls: int, cage_speed: float,
                 compiled: bool = False) -> tuple:
    """What the friction torque reports of the solved ball motions ``u`` (scaled unknowns of the
    active balls) and the contacts' dissipated powers (C,), per ball and contact 1..4:

    the contact powers (B, 4), the power per ball over ``|speed|`` (B,), the balls' angular
    velocities (B, 3: ``w_r, w_t, w_z``), their orbital speeds (B,; ``cage_speed``, rolling, for
    the unloaded), the state (B, 4) of a warm start, the spin-to-roll ratio of each loaded
    contact (B, 4) and the number of loaded contacts (B,). ``compiled``: one compiled loop
    (:func:`slewing_model.friction.kernel.compiled_ball_results`), the same arithmetic."""
    geo = geometry
    ls, big_r, speed = geo.length_scale, geo.pitch_radius, geo.speed
    if compiled:
        return compiled_ball_results()(geo.ball_index, geo.contact_index, geo.owner, geo.active, geo.inactive,
                                       contact_power, np.ascontiguousarray(u, dtype=float), np.ravel(geo.n_r),
                                       np.ravel(geo.n_z), np.ravel(geo.ring_speed), ls, big_r, speed,
                                       cage_speed, n_balls)
    power = np.zeros((n_balls, 4))
    power[geo.ball_index, geo.contact_index] = contact_power
    per_ball = power.sum(axis=1) / abs(speed)
    omega_ball = np.zeros((n_balls, 3))
    orbital = np.zeros(n_balls)
    state = np.zeros((n_balls, 4))
    active = geo.active
    if active.size:
        omega_ball[active[:, None], [0, 2]] = u[:, :2] / ls
        orbital[active] = u[:, 2] / big_r
        state[active[:, None], SOLVED] = u / (speed * np.array([ls, ls, big_r]))
    orbital[geo.inactive] = cage_speed          # unloaded balls: nominal rolling, for the record
    return (power, per_ball, omega_ball, orbital, state, spin_roll_ratio(geo, u, n_balls),
            np.count_nonzero(geo.loaded, axis=1))


@dataclass(frozen=True)
class WarmFrictionStep:
    """A warm-started friction torque's loops in one compiled call, its operands that stay from step to
    step prepared once (:func:`warm_friction_step`; a co-simulation keeps one:
    :class:`slewing_model.simulation.simulator.BearingSimulator`). Calling it with a load distribution
    for this bearing, the last state ``warm`` (B, 4) and the iterations allowed gives what
    :func:`warm_friction_step` gives.

    Preparing these operands every step (the bearing's ball radii, the rules' arrays, the distribution's
    arrays checked and copied) and building a :class:`~slewing_model.friction.FrictionTorque` would take
    35-55 us of the pitch bearing's 1 ms NREL step."""

    bearing: Bearing
    operands: tuple          # the bearing's, before mu
    rules: tuple             # mu ... the solve rule's arrays and whether it is the torque's
    tol: float
    cage_speed: float

    @classmethod
    def prepare(cls, bearing: Bearing, mu: float, speed: float, sliding_regularisation: float,
                quad: EllipseQuadrature, solve_quad: EllipseQuadrature, tol: float,
                cage_speed: float) -> "WarmFrictionStep":
        """The operands of :func:`warm_friction_step` but the distribution, the warm start and the
        iterations allowed."""
        same = (solve_quad.n_across, solve_quad.n_along) == (quad.n_across, quad.n_along)
        operands = (ball_radii(bearing), np.asarray(bearing.groove_radius, dtype=float), _IS_MOVING[bearing.moving_ring],
                    _NORMAL_SIGN_R, _NORMAL_SIGN_Z)
        rules = (mu, speed, sliding_regularisation, 0.5 * bearing.ball_diameter, 0.5 * bearing.pitch_diameter,
                 *quad.writable_arrays, *solve_quad.writable_arrays, same)
        return cls(bearing, operands, rules, tol, cage_speed)

    def __call__(self, distribution, warm: np.ndarray, max_iterations: int):
        arrays = distribution_arrays(self.bearing, distribution, writable=True)
        out = compiled_friction_step()(
            arrays["contact_load"], arrays["contact_angle"], arrays["semi_axis_a"], arrays["semi_axis_b"],
            *self.operands, *self.rules, np.array(warm, dtype=float), self.tol, max_iterations, _THETA_DOWN,
            _THETA_UP, _THETA_MIN_UP, self.cage_speed)
        return None if out[0] == GENERAL_PATH else out[1:]


def warm_friction_step(bearing: Bearing, distribution, mu: float, speed: float, sliding_regularisation: float,
                       quad: EllipseQuadrature, solve_quad: EllipseQuadrature, warm: np.ndarray, tol: float,
                       max_iterations: int, cage_speed: float):
    """A warm-started friction torque's loops in one compiled call
    (:func:`slewing_model.friction.kernel.compiled_friction_step`): the same loops, with the same
    arguments, as the steps of :func:`slewing_model.friction.friction_torque` (the same numbers
    bit for bit where every ball has a warm start; a ball without one is started as
    :func:`cold_start` starts it, the same to round-off). ``warm``: the last state (B, 4). None where
    the general path must run (a distribution to refuse, no loaded contact); else the
    iterations, largest residual, whether converged, the contacts' powers and torques (C,) and
    :func:`ball_results`'s arrays (:class:`WarmFrictionStep`, prepared for this call)."""
    return WarmFrictionStep.prepare(bearing, mu, speed, sliding_regularisation, quad, solve_quad, tol,
                                    cage_speed)(distribution, warm, max_iterations)


def spin_roll_ratio(geometry: ContactSet, u: np.ndarray, n_balls: int) -> np.ndarray:
    """Relative spin over relative rolling at each loaded contact centre."""
    out = np.zeros((n_balls, 4))
    if not geometry.active.size:
        return out
    rel = np.zeros((geometry.ball_index.size, 3))                 # raceway minus ball: W e_z - w
    rel[:, [0, 2]] = -u[geometry.owner, :2] / geometry.length_scale
    rel[:, 2] += geometry.ring_speed[:, 0]
    n_r, n_z = geometry.normal[:, 0], geometry.normal[:, 1]
    spin = rel[:, 0] * n_r + rel[:, 2] * n_z
    roll = -rel[:, 0] * n_z + rel[:, 2] * n_r                      # about g = (-n_z, 0, n_r)
    with np.errstate(divide="ignore", invalid="ignore"):
        out[geometry.ball_index, geometry.contact_index] = np.where(roll != 0.0, spin / roll, 0.0)
    return out
