"""Friction torque of the bearing: an analytical model fed by the load distribution.

The paper (section 3 and its conclusion) computes the friction torque with a
finite element contact model (hours per case) and proposes to feed the
Flexible-BIME results to an analytical model instead. This module is that
model, in the line of Jones (paper ref. [19]), Leblanc & Nelias (refs. [17,
18]) and Joshi et al. (ref. [20]): slow speed, no inertia, full-sliding
Coulomb friction in every ball-raceway contact. ``docs/friction.md`` gives the
derivation, the convergence studies and the limits (full sliding, ref. [21]).

1. **Contact** (:func:`ellipse_friction`): Hertz pressure
   ``p = p0 sqrt(1 - (eta/a)^2 - (xi/b)^2)`` over the contact ellipse (semi-axes
   from :func:`slewing_model.contact.hertz_ellipse`, carried by the
   :class:`~slewing_model.bime.LoadDistribution`). The contact surface is bent
   across the groove with the radius ``R_d = 2 r_b R_c / (r_b + R_c)``
   (:func:`conformity_radius`), which gives the differential sliding across the
   ellipse. Coulomb traction ``mu p`` opposes the local sliding velocity
   (rolling, spin and differential sliding together), integrated with a product
   Gauss rule exact for the Hertz weight (:func:`ellipse_quadrature`).
2. **Ball kinematics** (:func:`friction_torque`): per ball the unknowns are its
   angular velocity (3 components) and its orbital speed about the bearing
   axis; the equations are the three friction moments on the ball and its
   friction force along the rolling direction. For Coulomb friction at given
   normal loads these are the stationarity conditions of the dissipated power
   ``D = sum integral mu p |v_s| dA``, a convex function of the unknowns: the
   ball moves so as to dissipate the least power. All balls are solved at once
   (batched Newton / Weiszfeld iterations on ``D``); two and four loaded
   contacts are the same equations.
3. **Bearing torque**: the dissipated power over the ring speed, plus a
   load-independent seal part. It equals the moment about z of the friction
   tractions on the moving ring's contacts at the ball equilibrium (reported
   too, and checked by the tests); the power is preferred because it is
   stationary there, hence insensitive to what remains of the ball residuals.
4. **Sign and slow speed**: :attr:`FrictionTorque.torque` acts on the moving
   ring about +z and opposes ``omega``: ``-magnitude * tanh(omega / omega_reg)``
   (:func:`regularised_torque`).
5. **Catalogue formula** (:func:`catalogue_torque`) and **rotation**
   (:func:`torque_ripple`, :func:`preload_sweep`).

Everything is SI. Run-time module: numpy and the standard library only.
"""
from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass, field

import numpy as np

from .friction_kernel import AVAILABLE as COMPILED_AVAILABLE, evaluate_points
from .geometry import RING_CONTACTS, Bearing

#: Default Coulomb coefficient of the ball-raceway contacts. Slewing bearings
#: turn so slowly (entrainment speeds of mm/s) that no lubricant film separates
#: the surfaces: grease-lubricated steel on steel is in boundary lubrication,
#: where friction coefficients of about 0.08-0.12 are usual. 0.1 is the middle
#: of that range; calibrate it against a measured running torque where one exists.
DEFAULT_MU = 0.1
#: Catalogue start-up friction coefficient of four-point contact slewing bearings
CATALOGUE_MU = 0.006
#: Default quadrature on which the power (torque) is integrated: points across
#: the groove x along the rolling direction (convergence table in docs/friction.md)
DEFAULT_QUADRATURE = (20, 4)
#: Default rule on which the ball equilibrium is solved. The power is stationary
#: at the equilibrium: integrated on the fine rule at the equilibrium of this
#: cheaper one, it is within 1e-3 of the fully consistent value (docs/friction.md).
#: ``solve_quadrature=None`` solves on the fine rule itself.
DEFAULT_SOLVE_QUADRATURE = (12, 2)
#: Sliding-velocity regularisation ``eps``, as a fraction of ``|omega| a`` (the
#: sliding speed at the ellipse edge of a spin as fast as the ring); the
#: spin of a two-contact ball is about ``0.35 |omega|``, so eps is ~0.3 % of it
DEFAULT_SLIDING_REGULARISATION = 1e-3
#: Default speed scale of the regularised Coulomb law near omega = 0, rad/s
DEFAULT_OMEGA_REGULARISATION = 1e-4

#: sign of the (r, z) components of the contact normals of contacts 1..4
#: (as :attr:`slewing_model.geometry.Bearing.contact_normals`)
_NORMAL_SIGN_R = np.array([1.0, -1.0, -1.0, 1.0])
_NORMAL_SIGN_Z = np.array([1.0, 1.0, -1.0, -1.0])
#: for each possible moving ring, which of contacts 1..4 turn with it
_IS_MOVING = {ring: np.isin(np.arange(4), [c - 1 for c in RING_CONTACTS[ring]]) for ring in ("inner", "outer")}
#: columns of the ball state (r w_r, r w_t, r w_z, R w_c) that are solved for (w_t = 0, see _Contacts)
_SOLVED = [0, 2, 3]
#: damping schedule of the Newton / Weiszfeld blend (see _minimise)
_THETA_DOWN, _THETA_UP, _THETA_MIN_UP = 0.2, 10.0, 0.1
#: step lengths along the first Newton direction of a cold start (see _cold_start)
_COLD_STEPS = (0.25, 0.5)


# ---- quadrature over the Hertz ellipse -------------------------------------------------

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


def _quadrature(quadrature) -> EllipseQuadrature:
    if isinstance(quadrature, EllipseQuadrature):
        return quadrature
    if isinstance(quadrature, (int, np.integer)):
        return ellipse_quadrature(int(quadrature), int(quadrature))
    try:
        n_across, n_along = quadrature
    except (TypeError, ValueError):
        raise ValueError(f"quadrature = {quadrature!r}: an int or a pair (n_across, n_along)") from None
    return ellipse_quadrature(int(n_across), int(n_along))


def conformity_radius(ball_radius, groove_radius):
    """Radius ``R_d`` of the deformed contact surface across the groove, m.

    Harmonic mean of the ball and groove radii, ``2 r_b R_c / (r_b + R_c)``
    (Harris & Kotzalas, *Rolling Bearing Analysis*: the pressure surface of a
    ball in a conforming groove lies between the two)."""
    rb = np.asarray(ball_radius, dtype=float)
    rc = np.asarray(groove_radius, dtype=float)
    return 2.0 * rb * rc / (rb + rc)


# ---- one contact ------------------------------------------------------------------------

@dataclass(frozen=True)
class EllipseFriction:
    """Friction integrated over one contact ellipse, in the contact's frame
    (t: rolling direction, g: across the groove, n: normal out of the ball).

    Attributes
    ----------
    force : ndarray (..., 3), N
        Friction force on the ball, components along (t, g, n).
    moment : ndarray (..., 3), N m
        Its moment about the centre of the ellipse.
    power : ndarray (...), W
        Dissipated power ``integral tau . v_s dA`` (>= 0).
    """

    force: np.ndarray
    moment: np.ndarray
    power: np.ndarray


def ellipse_friction(load, a, b, mu, *, sliding_velocity=(0.0, 0.0), relative_rotation=(0.0, 0.0, 0.0),
                     conformity_radius=np.inf, quadrature=None, regularisation=0.0) -> EllipseFriction:
    """Coulomb friction on one Hertz contact ellipse for a rigid relative motion.

    The raceway moves relative to the ball with the velocity ``v0 + w x (x - x0)``
    (``x0`` the centre of the ellipse). The friction traction on the ball is
    ``mu p v_s / |v_s|``, ``v_s`` the tangential part of that velocity on the
    contact surface: it drags the ball along with the raceway. This is the
    integration used by :func:`friction_torque`, for one contact.

    Parameters
    ----------
    load : float or array, N
        Contact load ``Q``.
    a, b : float or array, m
        Semi-axes across the groove (``g``) and along the rolling direction (``t``).
    mu : float
        Coulomb coefficient.
    sliding_velocity : (..., 2) array_like, m/s
        ``v0`` along (t, g).
    relative_rotation : (..., 3) array_like, rad/s
        ``w`` along (t, g, n); ``(0, 0, w_n)`` is a pure spin (pivoting).
    conformity_radius : float or array, m
        ``R_d`` of the contact surface across the groove; ``inf``: a flat ellipse.
    quadrature : int, (int, int), EllipseQuadrature or None
        None: ``DEFAULT_QUADRATURE[0]`` points across and as many along as
        keep the spacing (``>= n_across * b / a``, at least
        ``DEFAULT_QUADRATURE[1]``): the bearing default suits its slender
        ellipses (``a/b`` about 5-10), not a circle.
    regularisation : float or array, m/s
        ``|v_s|`` becomes ``sqrt(|v_s|^2 + regularisation^2)``.

    Returns
    -------
    EllipseFriction

    Examples
    --------
    Pivoting moment of a circular contact, ``3 pi / 16 mu Q a``:

    >>> f = ellipse_friction(1000.0, 1e-3, 1e-3, 0.1, relative_rotation=(0, 0, 1.0), quadrature=40)
    >>> round(float(f.moment[2] / (3 * math.pi / 16 * 0.1 * 1000.0 * 1e-3)), 3)
    1.0
    """
    if quadrature is None:
        n_across = DEFAULT_QUADRATURE[0]
        ratio = float(np.max(np.asarray(b, dtype=float) / np.asarray(a, dtype=float)))
        quadrature = (n_across, max(DEFAULT_QUADRATURE[1], math.ceil(n_across * ratio)))
    quad = _quadrature(quadrature)
    q = np.asarray(load, dtype=float)
    a = np.asarray(a, dtype=float)[..., None]
    b = np.asarray(b, dtype=float)[..., None]
    radius = np.asarray(conformity_radius, dtype=float)[..., None]
    eta, xi = a * quad.across, b * quad.along
    flat = np.isinf(radius)
    finite = np.where(flat, 1.0, radius)
    theta = np.where(flat, 0.0, eta / finite)
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    rg = np.where(flat, eta, finite * sin_t)                  # bent surface, centre of curvature on -n
    rn = np.where(flat, 0.0, finite * (cos_t - 1.0))
    rt = xi
    v0 = np.asarray(sliding_velocity, dtype=float)
    w = np.asarray(relative_rotation, dtype=float)
    vt = v0[..., 0, None] + w[..., 1, None] * rn - w[..., 2, None] * rg     # v = v0 + w x r
    vg = v0[..., 1, None] + w[..., 2, None] * rt - w[..., 0, None] * rn
    vn = w[..., 0, None] * rg - w[..., 1, None] * rt
    s1, s2 = vt, cos_t * vg - sin_t * vn                      # along t and along the bent g
    speed = np.sqrt(s1**2 + s2**2 + np.asarray(regularisation, dtype=float)[..., None] ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(speed > 0.0, (mu * q)[..., None] * quad.weight / speed, 0.0)
    ft, fb = scale * s1, scale * s2
    fg, fn = fb * cos_t, -fb * sin_t
    force = np.stack([ft.sum(-1), fg.sum(-1), fn.sum(-1)], axis=-1)
    moment = np.stack([(rg * fn - rn * fg).sum(-1), (rn * ft - rt * fn).sum(-1), (rt * fg - rg * ft).sum(-1)],
                      axis=-1)
    power = (scale * (s1**2 + s2**2)).sum(-1)
    return EllipseFriction(force, moment, power)


# ---- result and slow-speed laws -----------------------------------------------------------

@dataclass(frozen=True)
class FrictionTorque:
    """Friction torque of the bearing, SI units.

    Sign convention: ``torque`` is the friction torque **acting on the moving
    ring**, about the bearing axis +z, when the moving ring turns at ``omega``
    (rad/s, about +z) relative to the fixed ring. It opposes ``omega``:
    negative for ``omega > 0``. The actuator must supply ``-torque`` to keep
    the speed; the fixed ring feels ``-torque``.

    Attributes
    ----------
    torque : float, N m
        ``-magnitude * tanh(omega / omega_regularisation)``
        (:func:`regularised_torque`), or ``-magnitude * sign(omega)`` when
        ``omega_regularisation = 0``.
    magnitude : float, N m
        ``contact_part + seal_part``, at full sliding (>= 0); also the
        break-away level of a stick-slip law (:func:`stick_slip_torque`).
    contact_part : float, N m
        From the ball-raceway contacts: dissipated power over ``|kinematics_speed|``.
    contact_part_moments : float, N m
        The same from the moments about z of the friction tractions on the
        moving ring's contacts. Equal to ``contact_part`` at the ball
        equilibrium on one rule (``solve_quadrature=None``); with the default
        split rules it differs by the fine rule's residual (< 1e-2).
    seal_part : float, N m
        Load-independent part (seals, lubricant).
    per_ball : ndarray (B,), N m
        Contribution of each ball to ``contact_part``.
    omega : float, rad/s
        The speed asked for.
    kinematics_speed : float, rad/s
        Speed at which the ball motion below is given: ``omega``, or 1 rad/s when
        ``omega = 0`` (at full sliding the motion is proportional to the speed).
    ball_angular_velocity : ndarray (B, 3), rad/s
        Angular velocity of each ball (absolute), along its (radial,
        tangential, axial) directions.
    orbital_speed : ndarray (B,), rad/s
        Speed of each ball's centre about the bearing axis.
    spin_roll_ratio : ndarray (B, 4)
        At the centre of each contact, relative rotation (raceway minus ball)
        about the contact normal over that about the across-groove axis; 0 for
        unloaded contacts.
    contact_power : ndarray (B, 4), W
        Power dissipated in each contact at ``kinematics_speed``.
    contact_count : ndarray (B,)
        Loaded contacts of each ball (0, 2 or 4).
    power : float, W
        Total dissipated power at ``kinematics_speed``.
    mu : float
    iterations : int
        Iterations of the ball equilibrium.
    residual : float
        Largest friction force or moment (over ``Dw/2``) left on a ball at the
        last evaluated iterate, relative to ``mu`` times its largest contact load.
    converged : bool
    state : ndarray (B, 4)
        Ball unknowns per unit of speed: pass as ``initial`` for a warm start.
    """

    torque: float
    magnitude: float
    contact_part: float
    contact_part_moments: float
    seal_part: float
    per_ball: np.ndarray
    omega: float
    kinematics_speed: float
    ball_angular_velocity: np.ndarray
    orbital_speed: np.ndarray
    spin_roll_ratio: np.ndarray
    contact_power: np.ndarray
    contact_count: np.ndarray
    power: float
    mu: float
    iterations: int
    residual: float
    converged: bool
    state: np.ndarray = field(repr=False)

    @property
    def balls_in_four_point_contact(self) -> int:
        return int(np.count_nonzero(self.contact_count == 4))

    def to_dict(self) -> dict:
        """Plain JSON-ready data (N m, rad/s)."""
        return {
            "torque": self.torque,
            "magnitude": self.magnitude,
            "contact_part": self.contact_part,
            "seal_part": self.seal_part,
            "per_ball": self.per_ball.tolist(),
            "omega": self.omega,
            "mu": self.mu,
            "balls_in_four_point_contact": self.balls_in_four_point_contact,
            "converged": self.converged,
        }


def regularised_torque(magnitude: float, omega: float,
                       omega_regularisation: float = DEFAULT_OMEGA_REGULARISATION) -> float:
    """Friction torque on the moving ring for a full-sliding level ``magnitude``, N m.

    ``-magnitude * tanh(omega / omega_regularisation)``: the Coulomb law made
    continuous near ``omega = 0``. Odd, bounded by ``magnitude``, slope
    ``magnitude / omega_regularisation`` at rest, within 1 % of the
    full-sliding level for ``|omega| > 2.65 omega_regularisation``. It needs
    only the speed, which is what a co-simulation step hands over; with an
    explicit coupling the step stays stable when
    ``omega_regularisation >= magnitude * step / inertia``
    (:func:`omega_regularisation_for_step`). ``omega_regularisation = 0`` gives
    the discontinuous ``-magnitude * sign(omega)``.
    """
    if not math.isfinite(omega_regularisation) or omega_regularisation < 0.0:
        raise ValueError(f"omega_regularisation = {omega_regularisation!r}: must be finite and >= 0 (rad/s)")
    if omega_regularisation == 0.0:
        return -magnitude * float(np.sign(omega))
    return -magnitude * math.tanh(omega / omega_regularisation)


def omega_regularisation_for_step(magnitude: float, inertia: float, step: float) -> float:
    """Smallest regularisation speed (rad/s) an explicit co-simulation step resolves.

    Near rest the regularised law acts on the driven inertia (kg m^2, all that
    the actuator drives, seen at the bearing) as a damper
    ``magnitude / omega_regularisation``; a forward-Euler (explicit) coupling
    with step ``step`` (s) is stable and does not chatter in sign when
    ``step * magnitude / (omega_regularisation * inertia) <= 1``."""
    if inertia <= 0.0 or step <= 0.0:
        raise ValueError(f"inertia = {inertia!r}, step = {step!r}: both must be > 0")
    return magnitude * step / inertia


def stick_slip_torque(magnitude: float, omega: float, driving_torque: float, omega_stick: float) -> float:
    """Karnopp's stick-slip friction, for a model that knows its net driving torque, N m.

    Below ``omega_stick`` (rad/s) the bearing sticks: the friction balances the
    driving torque (N m, about +z on the moving ring) up to the break-away
    level ``magnitude``; above, full sliding ``-magnitude sign(omega)``. It
    needs the driving torque as an input, so it belongs inside the actuator's
    own model (with ``FrictionTorque.magnitude`` as its parameter)."""
    if abs(omega) > omega_stick:
        return -magnitude * math.copysign(1.0, omega)
    return -max(-magnitude, min(magnitude, driving_torque))


def seal_torque_of(bearing: Bearing, seal_torque: float = 0.0, seal_torque_per_length: float = 0.0,
                   seal_length: float | None = None) -> float:
    """Load-independent torque ``seal_torque + seal_torque_per_length * seal_length``, N m.

    ``seal_torque_per_length`` in N m per m of seal; ``seal_length`` (m)
    defaults to two seals (upper and lower) on the pitch circle, ``2 pi dm``."""
    for name, value in (("seal_torque", seal_torque), ("seal_torque_per_length", seal_torque_per_length)):
        if not isinstance(value, (int, float, np.floating)) or not math.isfinite(value) or value < 0.0:
            raise ValueError(f"{name} = {value!r}: must be a finite number >= 0")
    length = 2.0 * math.pi * bearing.pitch_diameter if seal_length is None else float(seal_length)
    if not math.isfinite(length) or length < 0.0:
        raise ValueError(f"seal_length = {seal_length!r}: must be finite and >= 0 (m)")
    return float(seal_torque + seal_torque_per_length * length)


# ---- all contacts of the bearing ------------------------------------------------------------

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


class _ContactSet:
    """The loaded contacts of a load distribution, and what does not depend on
    the quadrature rule: ball of each contact, normal, ellipse, ring speed."""

    def __init__(self, bearing: Bearing, distribution, mu: float, speed: float, sliding_regularisation: float):
        n_balls = bearing.ball_count
        arrays = {}
        for name in ("contact_load", "contact_angle", "semi_axis_a", "semi_axis_b"):
            value = np.asarray(getattr(distribution, name), dtype=float)
            if value.shape != (n_balls, 4):
                raise ValueError(f"distribution.{name} has shape {value.shape}, expected ({n_balls}, 4) "
                                 f"for this bearing ({bearing.name})")
            if not np.all(np.isfinite(value)):
                raise ValueError(f"distribution.{name}: must be finite (not NaN or infinite)")
            arrays[name] = value
        q = arrays["contact_load"]
        if np.any(q < 0.0):
            raise ValueError("distribution.contact_load: must be >= 0 (N)")
        loaded = q > 0.0
        if np.any(loaded & ((arrays["semi_axis_a"] <= 0.0) | (arrays["semi_axis_b"] <= 0.0))):
            raise ValueError("distribution.semi_axis_a/b: must be > 0 (m) where the contact is loaded")
        self.contact_load = q
        self.loaded = loaded
        self.ball_index, self.contact_index = np.nonzero(loaded)
        active_mask = loaded.any(axis=1)
        self.active = active = np.flatnonzero(active_mask)
        self.inactive = np.flatnonzero(~active_mask)
        position = np.full(n_balls, -1)
        position[active] = np.arange(active.size)
        self.owner = position[self.ball_index]                # active-ball row of every contact
        n_c = self.ball_index.size
        self.sum_matrix = np.zeros((active.size, n_c))        # per-contact -> per-ball sums
        self.sum_matrix[self.owner, np.arange(n_c)] = 1.0
        dw = np.full(n_balls, bearing.ball_diameter + bearing.preload)
        if bearing.errors is not None and bearing.errors.ball_diameter_deviation is not None:
            dw = dw + bearing.errors.ball_diameter_deviation
        self.ball_radius = 0.5 * dw
        self.pitch_radius = 0.5 * bearing.pitch_diameter
        self.length_scale = 0.5 * bearing.ball_diameter
        self.speed = speed
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
        self.contact_angle = arrays["contact_angle"]
        self.moving_ring = bearing.moving_ring

    def initial_guesses(self) -> np.ndarray:
        """Candidate scaled unknowns (2, B_active, 3) for a cold start, each a
        rolling motion without sliding at contact centres:

        0. about an axis normal to the more loaded diagonal, rolling at its two
           contact centres (the classical two-contact kinematics);
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
        diagonals = []
        for outer, sign in ((0, 1.0), (3, -1.0)):          # diagonal 1 (contacts 1, 3), diagonal 2 (4, 2)
            n_r, n_z = np.cos(alpha[:, outer]), sign * np.sin(alpha[:, outer])
            # v . t = 0 at the outer contact (normal n) and at the inner one (-n), w = w_g g, g = (-n_z, 0, n_r)
            w_c = 0.5 * (w_o + w_i) + (w_o - w_i) * rb * n_r / (2.0 * big_r)
            w_g = ((w_o - w_c) * big_r + w_o * rb * n_r) / rb
            diagonals.append(np.stack([-w_g * n_z * ls, w_g * n_r * ls, w_c * big_r], axis=-1))
        q1, q2 = q[:, 0], q[:, 1]
        heavier = np.where((q1 >= q2)[:, None], diagonals[0], diagonals[1])
        # v . t = -r_r w_z - R w_c + W (R + r_r) = 0 at the outer (r_r > 0) and inner (r_r < 0) centres
        r_o = rb * 0.5 * (np.cos(alpha[:, 0]) + np.cos(alpha[:, 3]))
        r_i = -rb * 0.5 * (np.cos(alpha[:, 1]) + np.cos(alpha[:, 2]))
        w_z = (w_i * (big_r + r_i) - w_o * (big_r + r_o)) / (r_i - r_o)
        w_c = (w_o * (big_r + r_o) - r_o * w_z) / big_r
        axial = np.stack([np.zeros_like(w_z), w_z * ls, w_c * big_r], axis=-1)
        four = ((q1 > 0.0) & (q2 > 0.0))[:, None]
        return np.stack([heavier, np.where(four, axial, heavier)])


@dataclass(frozen=True)
class _SubSet:
    """What :class:`_Contacts` and :func:`_minimise` use of a :class:`_ContactSet`,
    for some of its balls (:meth:`_Contacts.subset`)."""

    owner: np.ndarray
    sum_matrix: np.ndarray
    eps2: np.ndarray
    force_scale: np.ndarray
    active: np.ndarray


class _Contacts:
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

    def __init__(self, geometry: _ContactSet, quad: EllipseQuadrature, workspace: str = "fine",
                 compiled: bool = False):
        geo = self.geometry = geometry
        self.compiled = compiled           # evaluate with the compiled loop (friction_kernel)
        ls, big_r = geo.length_scale, geo.pitch_radius
        rb, rd, n_r, n_z, ring_speed = geo.rb, geo.rd, geo.n_r, geo.n_z, geo.ring_speed
        u_nodes, t2, weight = quad.across_nodes, quad.along_squared, quad.folded_weight
        # sin of the angle a u / Rd (C, I), |angle| < pi/2; the nodes u are symmetric and sin is odd
        n_i, n_neg = u_nodes.size, u_nodes.size // 2
        sin_pos = np.sin(geo.a * (u_nodes[n_neg:] / rd))
        sin_t = np.concatenate([-sin_pos[:, n_i - n_neg - 1::-1][:, :n_neg], sin_pos], axis=1)
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
        self.t2 = np.array(t2, dtype=float)          # writable (the compiled loop takes no read-only arrays)
        space = self._space = _workspace(workspace)
        shape = (self.t2.size, geo.ball_index.size, quad.n_across)
        self.weight = np.multiply(weight[:, None, :], geo.mu_load[:, None], out=space.get("weight", shape))
        self._s, self._k, self._k3 = (space.get(name, shape) for name in ("s", "k", "k3"))
        self._ones = np.ones(quad.n_across)
        self._products = None

    def _prepare_derivatives(self) -> None:
        """Coefficient products of the Hessian (derivatives only)."""
        g10, g12, s0, s1 = self.g10, self.g12, self.s0, self.s1
        self._products = (g10 * g10, g10 * g12, g12 * g12, s0 * s0, s0 * s1, s1 * s1,
                          2.0 * g10 * s0, g10 * s1 + s0 * g12, 2.0 * g12 * s1)
        self._rows = self._space.get("rows", (15,) + g10.shape)

    def subset(self, balls: np.ndarray) -> "_Contacts":
        """The same rule restricted to the contacts of some active balls
        (their rows, in order): for the last iterations of a few balls."""
        geo = self.geometry
        rows = np.flatnonzero(np.isin(geo.owner, balls))
        position = np.full(geo.active.size, -1)
        position[balls] = np.arange(balls.size)
        owner = position[geo.owner[rows]]
        sum_matrix = np.zeros((balls.size, rows.size))
        sum_matrix[owner, np.arange(rows.size)] = 1.0
        sub = object.__new__(_Contacts)
        sub.geometry = _SubSet(owner=owner, sum_matrix=sum_matrix, eps2=geo.eps2[rows],
                               force_scale=geo.force_scale[balls], active=geo.active[balls])
        for name in ("g10", "g12", "h1", "s0", "s1", "hs", "arm1", "arm2"):
            setattr(sub, name, getattr(self, name)[rows])
        sub.t2, sub.weight = self.t2, self.weight[:, rows]
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
        s += eps2
        np.sqrt(s, out=s)
        return s

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
        (:func:`slewing_model.friction_kernel.evaluate_points`)."""
        geo = self.geometry
        if self.compiled:
            f, g, h, x = evaluate_points(np.ascontiguousarray(u, dtype=float), geo.owner, geo.sum_matrix.shape[0],
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
            return geo.sum_matrix @ f_c, None, None, None
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
        sums = (rows[:n_rows].reshape(-1, n_i) @ ones).reshape(n_rows, -1) @ geo.sum_matrix.T   # (rows, B)
        sym = [0, 1, 2, 1, 3, 4, 2, 4, 5]
        hessian = sums[3:9].T[:, sym].reshape(-1, 3, 3)
        extra = sums[9:15].T[:, sym].reshape(-1, 3, 3) if majorant else None
        return geo.sum_matrix @ f_c, sums[:3].T, hessian, extra

    def tractions(self, u: np.ndarray):
        """Dissipated power (W) and torque on the moving ring about +z (N m) of
        every contact, at the final regularisation."""
        a, s_ = self.velocity(u)
        a2, s2 = a * a, s_ * s_
        s = self._speed(a2, s2, self.geometry.eps2)
        k = np.divide(self.weight, s, out=self._k)                       # |traction on the ball| / |v|
        ga, gs = self._moment(k, 0) * a, self._moment(k, 1) * s_         # tractions . (A, S) directions
        power = np.einsum("ci,ci->c", ga, a) + np.einsum("ci,ci->c", gs, s_)
        # the traction on the ring is minus that on the ball
        torque = -(np.einsum("ci,ci->c", ga, self.arm1) + np.einsum("ci,ci->c", gs, self.arm2))
        return power, torque


def _solve(a: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``a^-1 rhs`` for a stack of small symmetric systems (B, m, m), (B, m)."""
    try:
        return np.linalg.solve(a, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:                           # a singular H (not met): regularise
        m = a.shape[-1]
        d = np.maximum(np.einsum("bii->b", a) / m, 1e-300)
        return np.linalg.solve(a + 1e-13 * d[:, None, None] * np.eye(m), rhs[..., None])[..., 0]


def _cold_start(geometry: _ContactSet, contacts: _Contacts, u: np.ndarray, cold: np.ndarray) -> np.ndarray:
    """Starting ball motions (scaled unknowns) for the balls marked ``cold``.

    Per ball the candidate of least power (:meth:`_ContactSet.initial_guesses`),
    then one Newton step from it, line-searched on the power over the lengths
    ``0, 1/4, 1/2`` (:data:`_COLD_STEPS`): from a rolling motion the Newton
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
    du = np.where(cold[:, None], _solve(h, -g), 0.0)
    lengths = np.array((0.0,) + _COLD_STEPS)
    power = np.stack([f] + [contacts.evaluate(start + t * du, eps2, derivatives=False)[0] for t in _COLD_STEPS])
    return start + lengths[np.argmin(power, axis=0)][:, None] * du


def _minimise(contacts: _Contacts, u: np.ndarray, tol: float, max_iterations: int,
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
    power per ball (of this call, unless given): each ball's power is within
    ``tol`` of the mean of its own power and the average one, so the total is
    within ``tol`` of its minimum, and a ball that carries almost nothing is
    not iterated to a relative accuracy that cannot show in the torque. That
    last Newton step is taken where it lowers the power. When at most a
    quarter of the balls are left after three iterations, they go on alone
    (:meth:`_Contacts.subset`), the others take that last step.

    Returns ``(u, iterations, residual, converged)``; ``residual``: the largest
    force residual of a ball, relative to ``mu Q_max``, at the last evaluation."""
    eps2 = contacts.geometry.eps2
    n, m = u.shape
    theta = np.zeros(n) if theta is None else np.array(theta, dtype=float)
    f, g, h, extra = contacts.evaluate(u, eps2, majorant=bool(np.any(theta)))
    scale = contacts.geometry.force_scale
    iterations = 0

    def residual():
        return float(np.max(np.abs(g).max(axis=1) / scale))

    while True:
        newton = _solve(h, -g)
        decrement = -np.einsum("bk,bk->b", g, newton)
        share = f.mean() if floor is None else floor
        done = decrement <= tol * (f + share)
        if np.all(done):
            trial = u + newton
            keep = contacts.evaluate(trial, eps2, derivatives=False)[0] <= f * (1.0 + 1e-12)
            return np.where(keep[:, None], trial, u), iterations + 1, residual(), True
        if iterations >= max_iterations:
            return u, iterations, residual(), False
        left = np.flatnonzero(~done)
        if iterations >= 3 and n >= 8 and 4 * left.size <= n:   # a long tail: the stragglers alone
            res_done = float(np.max(np.abs(g[done]).max(axis=1) / scale[done]))
            trial = np.where(done[:, None], u + newton, u)          # the last Newton step of the others
            keep = done & (contacts.evaluate(trial, eps2, derivatives=False)[0] <= f * (1.0 + 1e-12))
            u = np.where(keep[:, None], trial, u)
            u[left], more, res_left, converged = _minimise(contacts.subset(left), u[left], tol,
                                                           max_iterations - iterations, theta[left], share)
            return u, iterations + more, max(res_done, res_left), converged
        iterations += 1
        if np.any(theta):
            if extra is None:                                       # theta rose after a Newton step
                f, g, h, extra = contacts.evaluate(u, eps2, majorant=True)
            du = _solve(h + theta[:, None, None] * extra, -g)
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
            du[pending] = _solve(h[pending] + theta[pending, None, None] * extra[pending], -g[pending])
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


def _check_number(name: str, value, minimum: float | None = None, strict: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} = {value!r}: must be a number")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} = {value!r}: must be finite (not NaN or infinite)")
    if minimum is not None and (value < minimum or (strict and value == minimum)):
        raise ValueError(f"{name} = {value!r}: must be {'>' if strict else '>='} {minimum:g}")
    return value


def friction_torque(bearing: Bearing, distribution, *, mu: float = DEFAULT_MU, omega: float = 1.0,
                    seal_torque: float = 0.0, seal_torque_per_length: float = 0.0, seal_length: float | None = None,
                    omega_regularisation: float = DEFAULT_OMEGA_REGULARISATION, quadrature=DEFAULT_QUADRATURE,
                    solve_quadrature=DEFAULT_SOLVE_QUADRATURE,
                    sliding_regularisation: float = DEFAULT_SLIDING_REGULARISATION, initial=None,
                    tol: float = 1e-5, max_iterations: int = 60, kernel: str = "auto") -> FrictionTorque:
    """Friction torque of the bearing for a load distribution (full sliding, slow speed).

    Parameters
    ----------
    bearing : Bearing
        The bearing the distribution was solved for (ball and groove radii,
        preload, ball-diameter errors, moving ring).
    distribution : LoadDistribution
        Rigid or flexible BIME result: ``contact_load`` (B, 4) N,
        ``contact_angle`` (B, 4) rad, ``semi_axis_a``, ``semi_axis_b`` (B, 4) m.
    mu : float
        Coulomb coefficient of the ball-raceway contacts (default
        :data:`DEFAULT_MU` = 0.1, boundary lubrication).
    omega : float, rad/s
        Speed of the moving ring about +z relative to the fixed ring.
    seal_torque : float, N m
        Load-independent torque (seals, lubricant).
    seal_torque_per_length : float, N m per m of seal
        Added as ``seal_torque_per_length * seal_length``.
    seal_length : float, m, optional
        Default: two seals on the pitch circle, ``2 pi dm``.
    omega_regularisation : float, rad/s
        Speed scale of :func:`regularised_torque` (0: discontinuous Coulomb law).
    quadrature : int or (int, int)
        Rule (points across x along each ellipse) on which the power, hence
        the torque, is integrated (default :data:`DEFAULT_QUADRATURE`).
    solve_quadrature : int, (int, int) or None
        Rule on which the ball equilibrium is solved (default
        :data:`DEFAULT_SOLVE_QUADRATURE`); None: ``quadrature`` itself.
    sliding_regularisation : float
        ``|v_s|`` becomes ``sqrt(|v_s|^2 + eps^2)`` with
        ``eps = sliding_regularisation * |omega| * a`` per contact.
    initial : FrictionTorque or ndarray (B, 4), optional
        Warm start of the ball equilibrium: a previous result for this bearing.
    tol : float
        Relative accuracy of the minimum dissipated power, hence of the torque
        (Newton decrement test): every ball's power is within ``tol`` of the
        mean of its own power and the average power per ball, so the total is
        within ``tol`` of its minimum. The torque error it leaves is one-sided
        (the torque is never below the converged one), below the quadrature
        error (~1e-3).
    max_iterations : int
    kernel : {"auto", "numpy", "compiled"}
        How the power and its derivatives are summed over the quadrature points:
        numpy array operations, or one compiled loop
        (:mod:`slewing_model.friction_kernel`, needs numba); "auto" takes the
        compiled loop where numba is installed. Both give the same results to
        round-off.

    Returns
    -------
    FrictionTorque
        ``converged`` is False if the ball equilibrium did not meet ``tol``
        within ``max_iterations`` (the torque is then an upper bound).

    Examples
    --------
    >>> from slewing_model import load_bearing, solve, Loads
    >>> b = load_bearing("examples/bearings/table1.toml")
    >>> t = friction_torque(b, solve(b, Loads(Fz=500e3)), mu=0.1, omega=0.05)
    >>> t.torque < 0 < t.magnitude
    True
    """
    mu = _check_number("mu", mu, 0.0)
    omega = _check_number("omega", omega)
    sliding_regularisation = _check_number("sliding_regularisation", sliding_regularisation, 0.0, strict=True)
    tol = _check_number("tol", tol, 0.0, strict=True)
    if kernel not in ("auto", "numpy", "compiled"):
        raise ValueError(f"kernel = {kernel!r}: must be 'auto', 'numpy' or 'compiled'")
    if kernel == "compiled" and not COMPILED_AVAILABLE:
        raise ValueError("kernel = 'compiled' needs numba, which is not installed in this Python")
    compiled = kernel == "compiled" or (kernel == "auto" and COMPILED_AVAILABLE)
    quad = _quadrature(quadrature)
    solve_quad = quad if solve_quadrature is None else _quadrature(solve_quadrature)
    seal = seal_torque_of(bearing, seal_torque, seal_torque_per_length, seal_length)
    speed = omega if omega != 0.0 else 1.0
    geometry = _ContactSet(bearing, distribution, mu, speed, sliding_regularisation)
    n_balls = bearing.ball_count
    ls, big_r = geometry.length_scale, geometry.pitch_radius
    scale_u = np.array([ls, ls, big_r])                # solved: r w_r, r w_z, R w_c (w_t = 0)
    active = geometry.active

    iterations, residual, converged = 0, 0.0, True
    u = np.zeros((active.size, 3))
    if active.size and mu > 0.0:
        contacts = _Contacts(geometry, quad, compiled=compiled)
        same = (solve_quad.n_across, solve_quad.n_along) == (quad.n_across, quad.n_along)
        solver = contacts if same else _Contacts(geometry, solve_quad, workspace="solve", compiled=compiled)
        cold = np.ones(active.size, dtype=bool)
        if initial is not None:
            state = initial.state if isinstance(initial, FrictionTorque) else np.asarray(initial, dtype=float)
            if state.shape != (n_balls, 4):
                raise ValueError(f"initial: state of shape {state.shape}, expected ({n_balls}, 4) for this bearing")
            u = state[active][:, _SOLVED] * speed * scale_u
            cold = ~(np.all(np.isfinite(u), axis=1) & np.any(u != 0.0, axis=1))
        if np.any(cold):
            u = _cold_start(geometry, solver, u, cold)
        u, iterations, residual, converged = _minimise(solver, u, tol, max_iterations)
        power_c, torque_c = contacts.tractions(u)
    else:
        power_c = torque_c = np.zeros(geometry.ball_index.size)     # no loaded contact, or mu = 0

    contact_power = np.zeros((n_balls, 4))
    contact_power[geometry.ball_index, geometry.contact_index] = power_c
    per_ball = contact_power.sum(axis=1) / abs(speed)
    contact_part = float(per_ball.sum())
    contact_part_moments = -math.copysign(1.0, speed) * float(np.sum(torque_c))
    magnitude = contact_part + seal

    omega_ball = np.zeros((n_balls, 3))
    orbital = np.zeros(n_balls)
    state = np.zeros((n_balls, 4))
    if active.size:
        omega_ball[active[:, None], [0, 2]] = u[:, :2] / ls
        orbital[active] = u[:, 2] / big_r
        state[active[:, None], _SOLVED] = u / (speed * scale_u)
    if geometry.inactive.size:       # unloaded balls: nominal rolling, for the record
        from .assembly import cage_ratio
        orbital[geometry.inactive] = cage_ratio(bearing) * speed
    return FrictionTorque(
        torque=regularised_torque(magnitude, omega, omega_regularisation),
        magnitude=magnitude, contact_part=contact_part, contact_part_moments=contact_part_moments,
        seal_part=seal, per_ball=per_ball, omega=omega, kinematics_speed=speed,
        ball_angular_velocity=omega_ball, orbital_speed=orbital,
        spin_roll_ratio=_spin_roll_ratio(geometry, u, n_balls), contact_power=contact_power,
        contact_count=np.count_nonzero(geometry.loaded, axis=1), power=float(np.sum(power_c)), mu=mu,
        iterations=iterations, residual=residual, converged=converged, state=state,
    )


def _spin_roll_ratio(geometry: _ContactSet, u: np.ndarray, n_balls: int) -> np.ndarray:
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


# ---- catalogue formula --------------------------------------------------------------------

def catalogue_torque(bearing: Bearing, loads, mu: float = CATALOGUE_MU) -> float:
    """Start-up friction torque of slewing bearing catalogues, N m.

    ``M = mu / 2 (4.4 M_k + F_a D + 2.2 F_r D 1.73)``. The makers write it with
    ``M`` and ``M_k`` in kN m, forces in kN and ``D`` (raceway, i.e. pitch,
    diameter) in m; every term is a force times a length, so the same
    expression holds in N, N m and m (both sides scale by 1000) and no
    numerical conversion factor is needed.

    Parameters
    ----------
    bearing : Bearing
    loads : Loads or None
        ``F_a = |Fz|``, ``F_r = hypot(Fx, Fy)``, ``M_k = hypot(Mx, My)``.
    mu : float
        About 0.006 for four-point contact bearings (scatter about +-25 %).

    Examples
    --------
    >>> from slewing_model import load_bearing, Loads
    >>> b = load_bearing("examples/bearings/table1.toml")
    >>> round(catalogue_torque(b, Loads(Fz=1e6)))   # 0.003 * 1e6 N * 1.5 m
    4500
    """
    mu = _check_number("mu", mu, 0.0)
    if loads is None:
        return 0.0
    d = bearing.pitch_diameter
    f_a = abs(loads.Fz)
    f_r = math.hypot(loads.Fx, loads.Fy)
    m_k = math.hypot(loads.Mx, loads.My)
    return 0.5 * mu * (4.4 * m_k + f_a * d + 2.2 * f_r * d * 1.73)


# ---- rotation and studies -----------------------------------------------------------------

def torque_ripple(bearing: Bearing, loads, psi, *, model: str = "rigid", superelement=None, mu: float = DEFAULT_MU,
                  cage_angle=None, loads_frame: str = "fixed", seal_torque: float = 0.0,
                  seal_torque_per_length: float = 0.0, quadrature=DEFAULT_QUADRATURE, bc: str = "free",
                  mesh: str = "coarse", rtol: float = 1e-8, details: bool = False):
    """Friction torque magnitude (N m) at each rotation ``psi`` of the moving ring.

    At every ``psi`` the bearing is re-assembled (each ring's errors read under
    the balls at that rotation, :mod:`slewing_model.assembly`), the load
    distribution solved with a warm-started :class:`~slewing_model.bime.BimeSolver`
    (``set_rotation``) and the friction computed with a warm-started ball
    equilibrium. The configuration repeats when ``psi`` changes by ``2 pi`` at
    the same cage angle and, without ball-diameter errors, when the cage angle
    changes by one ball pitch ``2 pi / B``.

    Parameters
    ----------
    bearing : Bearing
    loads : Loads or None
        On the moving ring.
    psi : array_like, rad
        Rotations of the moving ring.
    model : {"rigid", "flexible"}
    superelement : Superelement, optional
        For ``model="flexible"`` (built with ``bc`` and ``mesh`` when not given).
    mu : float
    cage_angle : array_like, rad, optional
        Rotation of the ball set at each ``psi``; default: rolling without slip
        (:func:`slewing_model.assembly.cage_ratio`).
    loads_frame : {"fixed", "moving"}
        Frame in which ``loads`` stays constant: ``"moving"`` turns it with the
        moving ring (e.g. the blade loads on a pitch bearing).
    seal_torque, seal_torque_per_length : float
        As in :func:`friction_torque`.
    quadrature : int or (int, int)
    bc, mesh : str
        Superelement options when it is built here.
    rtol : float
        Force tolerance of the BIME solves (1e-8 is ample for the torque; the
        BIME default 1e-10 sits at the round-off floor of some cases).
    details : bool
        Also return the lists of load distributions and :class:`FrictionTorque`.

    Returns
    -------
    ndarray, N m, shape of ``psi``
        (and, with ``details``, the distributions and friction results).
    """
    from .bime import BimeSolver, Loads

    if model not in ("rigid", "flexible"):
        raise ValueError(f"model = {model!r}: must be 'rigid' or 'flexible'")
    if loads_frame not in ("fixed", "moving"):
        raise ValueError(f"loads_frame = {loads_frame!r}: must be 'fixed' or 'moving'")
    loads = Loads() if loads is None else loads
    psi = np.asarray(psi, dtype=float)
    flat = psi.ravel()
    cages = None if cage_angle is None else np.broadcast_to(np.asarray(cage_angle, dtype=float), psi.shape).ravel()
    if model == "flexible" and superelement is None:
        from .superelement import build_superelement

        superelement = build_superelement(bearing, mesh=mesh, bc=bc)
    solver = BimeSolver(bearing, superelement if model == "flexible" else None,
                        psi=float(flat[0]) if flat.size else 0.0,
                        cage_angle=None if cages is None else float(cages[0]), rtol=rtol)
    out = np.empty(flat.size)
    distributions, frictions = [], []
    distribution = friction = None
    for k, angle in enumerate(flat):
        solver.set_rotation(float(angle), None if cages is None else float(cages[k]))
        load_k = loads.rotated(float(angle)) if loads_frame == "moving" else loads
        distribution = solver.solve(load_k, initial=distribution)
        friction = friction_torque(bearing, distribution, mu=mu, seal_torque=seal_torque,
                                   seal_torque_per_length=seal_torque_per_length, quadrature=quadrature,
                                   initial=friction)
        out[k] = friction.magnitude
        if details:
            distributions.append(distribution)
            frictions.append(friction)
    out = out.reshape(psi.shape)
    return (out, distributions, frictions) if details else out


def preload_sweep(bearing: Bearing, preloads, loads=None, *, model: str = "rigid", superelement=None,
                  mu: float = DEFAULT_MU, psi: float = 0.0, quadrature=DEFAULT_QUADRATURE, rtol: float = 1e-8,
                  details: bool = False):
    """Friction torque magnitude (N m) against ball preload (m), as the paper's Figure 14.

    Parameters
    ----------
    bearing : Bearing
    preloads : array_like, m
        Ball oversize values (``Bearing.with_preload``).
    loads : Loads, optional
        External load (None: idling, as Figure 14).
    model : {"rigid", "flexible"}
    superelement : Superelement, optional
        For the flexible model; the ring matrices do not depend on the preload.
    mu, psi, quadrature, rtol
        As in :func:`friction_torque` and :func:`slewing_model.bime.solve`.
    details : bool
        Also return the list of :class:`FrictionTorque` (contact counts etc.).
    """
    from .bime import solve

    preloads = np.asarray(preloads, dtype=float)
    out = np.empty(preloads.size)
    results = []
    friction = None
    for k, preload in enumerate(preloads.ravel()):
        b = bearing.with_preload(float(preload))
        distribution = solve(b, loads, model=model, superelement=superelement, psi=psi, rtol=rtol)
        friction = friction_torque(b, distribution, mu=mu, quadrature=quadrature, initial=friction)
        out[k] = friction.magnitude
        results.append(friction)
    out = out.reshape(preloads.shape)
    return (out, results) if details else out
