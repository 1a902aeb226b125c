"""Friction torque of the bearing: an analytical model fed by the load distribution.

The paper (section 3 and its conclusion) computes the friction torque with a
finite element contact model (hours per case) and proposes to feed the
Flexible-BIME results to an analytical model instead. This module is that
model, in the line of Jones (paper ref. [19]), Leblanc & Nelias (refs. [17,
18]) and Joshi et al. (ref. [20]): slow speed, no inertia, full-sliding
Coulomb friction in every ball-raceway contact. ``docs/theory/friction.md`` gives the
derivation, the quadrature and the limits (full sliding, ref. [21]).

The model, one module per idea:

1. **Quadrature** (:mod:`slewing_model.friction.ellipse_quadrature`): a product rule over
   the Hertz ellipse, exact for the Hertz pressure weight.
2. **Contact** (:mod:`slewing_model.friction.contact`, :func:`ellipse_friction`):
   Hertz pressure ``p = p0 sqrt(1 - (eta/a)^2 - (xi/b)^2)`` over the contact
   ellipse (semi-axes from :func:`slewing_model.bearing.contact.hertz_ellipse`, carried by
   the :class:`~slewing_model.distribution.bime.LoadDistribution`), the contact surface bent
   across the groove with the radius ``R_d = 2 r_b R_c / (r_b + R_c)``
   (:func:`conformity_radius`), which gives the differential sliding. Coulomb
   traction ``mu p`` opposes the local sliding velocity (rolling, spin and
   differential sliding together).
3. **Ball kinematics** (:mod:`slewing_model.friction.ball_kinematics`): per ball the
   unknowns are its angular velocity and its orbital speed about the bearing
   axis; the equations are the three friction moments on the ball and its
   friction force along the rolling direction. For Coulomb friction at given
   normal loads these are the stationarity conditions of the dissipated power
   ``D = sum integral mu p |v_s| dA``, a convex function of the unknowns: the
   ball moves so as to dissipate the least power. All balls are solved at once;
   two and four loaded contacts are the same equations. Where numba is
   installed the points' set-up, the minimisation (ball by ball) and the
   torque's sums run as compiled loops (:mod:`slewing_model.friction.kernel`),
   with the same results.
4. **Bearing torque** (this module, :func:`friction_torque`): the dissipated
   power over the ring speed, plus a load-independent seal part. It equals the
   moment about z of the friction tractions on the moving ring's contacts at the
   ball equilibrium (reported too, and checked by the tests); the power is
   preferred because it is stationary there, hence insensitive to what remains
   of the ball residuals.
5. **Sign and slow speed**: :attr:`FrictionTorque.torque` acts on the moving
   ring about +z and opposes ``omega``: ``-magnitude * tanh(omega / omega_reg)``
   (:func:`regularised_torque`).
6. **Catalogue formula** (:mod:`slewing_model.friction.catalogue`) and **studies** over a
   turn and against preload (:mod:`slewing_model.friction.studies`); their
   functions are also importable from here.

Everything is SI. Run-time module: numpy and the standard library only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..distribution.assembly import cage_ratio
from .ball_kinematics import (
    SOLVED, ContactPoints, ContactSet, WarmFrictionStep, ball_results, cold_start, minimise_power, warm_friction_step,
)
from .catalogue import CATALOGUE_MU, catalogue_torque  # noqa: F401  (part of this module's interface)
from .contact import (  # noqa: F401
    DEFAULT_MU, DEFAULT_SLIDING_REGULARISATION, EllipseFriction, check_number, conformity_radius, ellipse_friction,
)
from .ellipse_quadrature import (  # noqa: F401
    DEFAULT_QUADRATURE, DEFAULT_SOLVE_QUADRATURE, EllipseQuadrature, as_quadrature, ellipse_quadrature,
)
from ..numerics.compiled import use_compiled
from ..bearing.geometry import Bearing

#: Default speed scale of the regularised Coulomb law near omega = 0, rad/s
DEFAULT_OMEGA_REGULARISATION = 1e-4
#: Default cap on the ball equilibrium's Newton iterations (``max_iterations`` of :func:`friction_torque`)
DEFAULT_MAX_ITERATIONS = 60


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
        Coulomb coefficient of the ball-raceway contacts used.
    iterations : int
        Iterations of the ball equilibrium.
    residual : float
        Largest friction force or moment (over ``Dw/2``) left on a ball at the
        last evaluated iterate, relative to ``mu`` times its largest contact load.
    converged : bool
        True when the ball equilibrium met its tolerance (else the torque is an upper bound).
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
        """Number of balls loaded on all four contacts."""
        return int(np.count_nonzero(self.contact_count == 4))

    def to_dict(self) -> dict:
        """Plain JSON-ready data (N m, rad/s).

        Returns
        -------
        dict
            ``torque``, ``magnitude``, ``contact_part``, ``seal_part`` (N m), ``per_ball``
            (list, N m), ``omega`` (rad/s), ``mu``, ``balls_in_four_point_contact`` and
            ``converged``.
        """
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


def friction_torque(bearing: Bearing, distribution, *, mu: float = DEFAULT_MU, omega: float = 1.0,
                    seal_torque: float = 0.0, seal_torque_per_length: float = 0.0, seal_length: float | None = None,
                    omega_regularisation: float = DEFAULT_OMEGA_REGULARISATION, quadrature=DEFAULT_QUADRATURE,
                    solve_quadrature=DEFAULT_SOLVE_QUADRATURE,
                    sliding_regularisation: float = DEFAULT_SLIDING_REGULARISATION, initial=None,
                    tol: float = 1e-5, max_iterations: int = DEFAULT_MAX_ITERATIONS, kernel: str = "auto"
                    ) -> FrictionTorque:
    """Friction torque of the bearing for a load distribution (full sliding, slow speed).

    Parameters
    ----------
    bearing : Bearing
        The bearing the distribution was solved for (ball and groove radii,
        preload, ball-diameter errors, moving ring).
    distribution : LoadDistribution
        Rigid or flexible BIME result: ``contact_load`` (B, 4) N,
        ``contact_angle`` (B, 4) rad, ``semi_axis_a``, ``semi_axis_b`` (B, 4) m.
    mu : float, optional
        Coulomb coefficient of the ball-raceway contacts (default 0.1, boundary lubrication).
    omega : float, optional
        Speed of the moving ring about +z relative to the fixed ring, rad/s. Default 1.
    seal_torque : float, optional
        Load-independent torque (seals, lubricant), N m. Default 0.
    seal_torque_per_length : float, optional
        Load-independent torque per length of seal, N m/m, added as
        ``seal_torque_per_length * seal_length``. Default 0.
    seal_length : float, optional
        Length of seal, m. Default: two seals on the pitch circle, ``2 pi dm``.
    omega_regularisation : float, optional
        Speed scale of :func:`regularised_torque`, rad/s (0: discontinuous Coulomb law).
        Default 1e-4.
    quadrature : int or (int, int), optional
        Rule (points across x along each ellipse) on which the power, hence
        the torque, is integrated. Default (20, 4).
    solve_quadrature : int, (int, int) or None, optional
        Rule on which the ball equilibrium is solved. Default (12, 2); None:
        ``quadrature`` itself.
    sliding_regularisation : float, optional
        ``|v_s|`` becomes ``sqrt(|v_s|^2 + eps^2)`` with
        ``eps = sliding_regularisation * |omega| * a`` per contact (``a`` the ellipse's
        semi-axis, m). Dimensionless, default 1e-3.
    initial : FrictionTorque or ndarray (B, 4), optional
        Warm start of the ball equilibrium: a previous result for this bearing.
    tol : float, optional
        Relative accuracy of the minimum dissipated power, hence of the torque
        (Newton decrement test): every ball's power is within ``tol`` of the
        mean of its own power and the average power per ball, so the total is
        within ``tol`` of its minimum. The torque error it leaves is one-sided
        (the torque is never below the converged one), below the quadrature
        error (~1e-3). Default 1e-5.
    max_iterations : int, optional
        Most iterations of the ball equilibrium. Default 60.
    kernel : {"auto", "numpy", "compiled"}, optional
        How the points are set up, the balls' equilibrium solved and the torque
        summed: numpy array operations, or compiled loops
        (:mod:`slewing_model.friction.kernel`, needs numba); "auto" takes the
        compiled loops where numba is installed. Both take the same steps and
        give the same results to round-off (torques to 1e-10 in the tests).
        Default "auto".

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
    mu = check_number("mu", mu, 0.0)
    omega = check_number("omega", omega)
    sliding_regularisation = check_number("sliding_regularisation", sliding_regularisation, 0.0, strict=True)
    tol = check_number("tol", tol, 0.0, strict=True)
    compiled = use_compiled(kernel)
    quad, solve_quad = _rules(quadrature, solve_quadrature)
    seal = seal_torque_of(bearing, seal_torque, seal_torque_per_length, seal_length)
    speed = _kinematics_speed(omega)
    n_balls = bearing.ball_count
    cage = cage_ratio(bearing) * speed
    warm = None
    if initial is not None:
        warm = initial.state if isinstance(initial, FrictionTorque) else np.asarray(initial, dtype=float)
    step = None
    if compiled and warm is not None and warm.shape == (n_balls, 4) and mu > 0.0:
        # the usual co-simulation step: the loops below in one compiled call, the same numbers
        step = warm_friction_step(bearing, distribution, mu, speed, sliding_regularisation, quad, solve_quad, warm,
                                  tol, max_iterations, cage)
    if step is not None:
        (iterations, residual, converged, power_c, torque_c, contact_power, per_ball, omega_ball, orbital, state,
         spin_roll, contact_count) = step
    else:
        geometry = ContactSet(bearing, distribution, mu, speed, sliding_regularisation, compiled=compiled)
        ls, big_r = geometry.length_scale, geometry.pitch_radius
        scale_u = np.array([ls, ls, big_r])                # solved: r w_r, r w_z, R w_c (w_t = 0)
        active = geometry.active
        iterations, residual, converged = 0, 0.0, True
        u = np.zeros((active.size, 3))
        if active.size and mu > 0.0:
            contacts = ContactPoints(geometry, quad, compiled=compiled)
            same = (solve_quad.n_across, solve_quad.n_along) == (quad.n_across, quad.n_along)
            solver = contacts if same else ContactPoints(geometry, solve_quad, workspace="solve", compiled=compiled)
            cold = np.ones(active.size, dtype=bool)
            if warm is not None:
                if warm.shape != (n_balls, 4):
                    raise ValueError(f"initial: state of shape {warm.shape}, expected ({n_balls}, 4) for this bearing")
                u = warm[active][:, SOLVED] * speed * scale_u
                cold = ~(np.all(np.isfinite(u), axis=1) & np.any(u != 0.0, axis=1))
                cold |= geometry.stale_warm_start(u)
            if np.any(cold):
                u = cold_start(geometry, solver, u, cold)
            u, iterations, residual, converged = minimise_power(solver, u, tol, max_iterations)
            power_c, torque_c = contacts.tractions(u)
        else:
            power_c = torque_c = np.zeros(geometry.ball_index.size)     # no loaded contact, or mu = 0
        contact_power, per_ball, omega_ball, orbital, state, spin_roll, contact_count = ball_results(
            geometry, u, power_c, n_balls, cage if geometry.inactive.size else 0.0, compiled)
    contact_part = _contact_part(per_ball)
    contact_part_moments = -math.copysign(1.0, speed) * float(np.sum(torque_c))
    magnitude = contact_part + seal

    return FrictionTorque(
        torque=regularised_torque(magnitude, omega, omega_regularisation),
        magnitude=magnitude, contact_part=contact_part, contact_part_moments=contact_part_moments,
        seal_part=seal, per_ball=per_ball, omega=omega, kinematics_speed=speed,
        ball_angular_velocity=omega_ball, orbital_speed=orbital, spin_roll_ratio=spin_roll, contact_power=contact_power,
        contact_count=contact_count, power=float(np.sum(power_c)), mu=mu,
        iterations=iterations, residual=residual, converged=converged, state=state,
    )


def _rules(quadrature, solve_quadrature) -> tuple[EllipseQuadrature, EllipseQuadrature]:
    """The rule the torque is integrated on and the one the balls are solved on (``quadrature`` and
    ``solve_quadrature`` of :func:`friction_torque`)."""
    quad = as_quadrature(quadrature)
    return quad, quad if solve_quadrature is None else as_quadrature(solve_quadrature)


def _kinematics_speed(omega: float) -> float:
    """The speed the balls' kinematics are solved at (``FrictionTorque.kinematics_speed``): ``omega``, or
    1 rad/s at rest (the torque of full sliding does not depend on it)."""
    return omega if omega != 0.0 else 1.0


def prepare_warm_torque(bearing: Bearing, *, mu: float = DEFAULT_MU, omega: float = 1.0,
                        quadrature=DEFAULT_QUADRATURE, solve_quadrature=DEFAULT_SOLVE_QUADRATURE,
                        sliding_regularisation: float = DEFAULT_SLIDING_REGULARISATION,
                        tol: float = 1e-5) -> WarmFrictionStep:
    """The operands of :func:`friction_torque`'s one compiled call for these arguments (its own, with
    the same defaults), prepared once for :func:`warm_torque` step after step."""
    mu = check_number("mu", mu, 0.0)
    omega = check_number("omega", omega)
    sliding_regularisation = check_number("sliding_regularisation", sliding_regularisation, 0.0, strict=True)
    tol = check_number("tol", tol, 0.0, strict=True)
    quad, solve_quad = _rules(quadrature, solve_quadrature)
    speed = _kinematics_speed(omega)
    return WarmFrictionStep.prepare(bearing, mu, speed, sliding_regularisation, quad, solve_quad, tol,
                                    cage_ratio(bearing) * speed)


def _contact_part(per_ball: np.ndarray) -> float:
    """The contacts' share of the torque magnitude, N m: the balls' (``FrictionTorque.per_ball``)."""
    return float(per_ball.sum())


@dataclass(frozen=True)
class WarmTorque:
    """What a co-simulation step takes of a warm-started friction torque (:func:`warm_torque`), as
    :class:`FrictionTorque` has it."""

    magnitude: float
    converged: bool
    state: np.ndarray
    iterations: int


def warm_torque(step: WarmFrictionStep, distribution, initial: np.ndarray, seal_torque: float,
                max_iterations: int = DEFAULT_MAX_ITERATIONS) -> WarmTorque | None:
    """:func:`friction_torque`'s magnitude, convergence and state from the warm start ``initial``
    (its ``state`` (B, 4)) by its one compiled call with operands prepared once (``step``, for the
    bearing, rules, ``mu``, ``omega``, tolerance and sliding regularisation of that call), bit for bit;
    ``seal_torque`` N m (``seal_torque_of``'s). None where :func:`friction_torque` must run instead
    (no warm start of this bearing's shape, a distribution to refuse, no loaded contact). A
    co-simulation step builds no :class:`FrictionTorque` then."""
    if initial is None or initial.shape != (step.bearing.ball_count, 4):
        return None
    found = step(distribution, initial, max_iterations)
    if found is None:
        return None
    iterations, converged, per_ball, state = found[0], found[2], found[6], found[9]
    return WarmTorque(_contact_part(per_ball) + seal_torque, converged, state, iterations)
