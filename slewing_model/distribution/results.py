"""What a load distribution solve takes and gives: the loads on the moving ring and the
load on every ball (paper section 2: contact loads, contact angles, interference).

Run-time module: numpy and the standard library.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ..bearing.contact import ISO76_PRESSURE_LIMIT

LOAD_FIELDS = ("Fx", "Fy", "Fz", "Mx", "My")
#: largest contact pressure that still counts as an unloaded bearing, Pa: 1/1000 of the ISO 76 limit, a
#: ball load of 1e-9 of its static capacity. An unloaded bearing without preload keeps a round-off
#: interference (about 3e-17 m, 1.5 kPa), which would give a safety factor of 2e19.
NO_LOAD_PRESSURE = 1e-3 * ISO76_PRESSURE_LIMIT
DISPLACEMENT_FIELDS = ("x", "y", "z", "rx", "ry")


class NoEquilibriumError(RuntimeError):
    """No equilibrium exists for the load (or the solver could not find one).

    A :class:`RuntimeError`; :class:`LoadCapacityError` is the case of a load
    beyond the raceways' capacity.
    """


class LoadCapacityError(NoEquilibriumError):
    """The load is beyond what the raceways can carry (truncated contact ellipse)."""


@dataclass(frozen=True)
class Loads:
    """External load on the moving ring, fixed frame, SI units.

    Every component defaults to 0; each must be a finite number.

    Attributes
    ----------
    Fx, Fy, Fz : float, N
        Force; ``Fz > 0`` pushes the moving (inner) ring towards +z and loads
        diagonal 1 (contacts 1 and 3).
    Mx, My : float, N m
        Tilting moment about the x and y axes (right hand).

    Raises
    ------
    ValueError
        If a component is not a finite number.

    Examples
    --------
    >>> from slewing_model import Loads
    >>> print(Loads(Fz=800e3, My=1.2e6))
    Fz = 800 kN, My = 1200 kN m
    >>> Loads.from_paper(axial=800e3, tilting_moment=1.2e6).as_array()
    array([      0.,       0.,  800000.,      -0., 1200000.])
    """

    Fx: float = 0.0
    Fy: float = 0.0
    Fz: float = 0.0
    Mx: float = 0.0
    My: float = 0.0

    def __post_init__(self):
        for name in LOAD_FIELDS:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise ValueError(f"load {name} = {value!r}: must be a number")
            if not math.isfinite(value):
                raise ValueError(f"load {name} = {value!r}: must be finite (not NaN or infinite)")

    def __str__(self) -> str:
        """The load for a title or a message, in kN and kN m: the components that are not zero
        (``"Fz = 800 kN, My = 1200 kN m"``), or ``"no load"``."""
        parts = [f"{name} = {getattr(self, name) / 1e3:.4g} {'kN' if name[0] == 'F' else 'kN m'}"
                 for name in LOAD_FIELDS if getattr(self, name) != 0]
        return ", ".join(parts) or "no load"

    @classmethod
    def from_paper(cls, axial: float = 0.0, radial: float = 0.0, tilting_moment: float = 0.0,
                   direction: float = 0.0) -> "Loads":
        """The paper's load set (eqs 19, 22).

        Parameters
        ----------
        axial : float, optional
            Axial force ``Fa`` along +z, N. Default 0.
        radial : float, optional
            Radial force ``Fr``, N, in the direction ``direction``. Default 0.
        tilting_moment : float, optional
            Tilting moment ``Mt``, N m, about the axis perpendicular to the radial
            force, ``(-sin phi_r, cos phi_r)``. Default 0.
        direction : float, optional
            Direction ``phi_r`` of the radial force from the x axis, rad. Default 0.

        Returns
        -------
        Loads
            ``Fx = Fr cos phi_r``, ``Fy = Fr sin phi_r``, ``Fz = Fa``,
            ``Mx = -Mt sin phi_r``, ``My = Mt cos phi_r``.
        """
        c, s = math.cos(direction), math.sin(direction)
        return cls(radial * c, radial * s, axial, -tilting_moment * s, tilting_moment * c)

    @classmethod
    def from_array(cls, values) -> "Loads":
        """The load from its components ``(Fx, Fy, Fz, Mx, My)``, N and N m (inverse of :meth:`as_array`)."""
        return cls(*[float(v) for v in values])

    def as_array(self) -> np.ndarray:
        """The components ``(Fx, Fy, Fz, Mx, My)`` as an array of shape (5,), N and N m."""
        return np.array([self.Fx, self.Fy, self.Fz, self.Mx, self.My])

    def rotated(self, angle: float) -> "Loads":
        """The same load turned about z (e.g. from the moving ring's own frame to the fixed frame).

        Parameters
        ----------
        angle : float
            Rotation about +z, rad.

        Returns
        -------
        Loads
            Forces and moments turned by ``angle``; ``Fz`` unchanged.
        """
        c, s = math.cos(angle), math.sin(angle)
        return Loads(c * self.Fx - s * self.Fy, s * self.Fx + c * self.Fy, self.Fz,
                     c * self.Mx - s * self.My, s * self.Mx + c * self.My)


@dataclass(frozen=True)
class LoadDistribution:
    """Result of a BIME solve. Arrays are per ball (axis 0) and per contact 1..4
    or per diagonal 1, 2 (axis 1). SI units.

    Attributes
    ----------
    model : {"rigid", "flexible"}
        Ring model of the solve.
    loads : Loads
        The load solved for, fixed frame.
    displacement : ndarray (5,)
        Moving ring (X, Y, Z in m; rx, ry in rad).
    ball_angle : ndarray (B,), rad
        Angular position of every ball.
    contact_load : ndarray (B, 4), N
        ``Q`` of contacts 1..4 (``Q1 = Q3``, ``Q2 = Q4``).
    contact_angle : ndarray (B, 4), rad
        Loaded contact angle of each contact (that of its diagonal).
    interference : ndarray (B, 2), m
        ``delta_tot`` of diagonals 1 and 2 (negative: a gap).
    contact_deflection : ndarray (B, 4), m
        Share ``delta_i = (Q/K_i)^(2/3)`` of each contact.
    ring_displacement : ndarray (B, 4, 2) or None, m
        (R, z) displacement of the groove centre of contacts 1..4 by ring
        deformation (flexible model), computed from the forces on the rings when
        first asked for (a co-simulation step does not ask: it costs two products
        with the rings' compliance).
    semi_axis_a, semi_axis_b : ndarray (B, 4), m
        Hertz ellipse across the groove and along the rolling direction.
    contact_pressure : ndarray (B, 4), Pa
        Maximum Hertz pressure of each contact.
    truncated : ndarray (B, 4) of bool
        Edge loading: the contact ellipse runs over the groove edge (its
        pressure is then higher than Hertz's, which assumes an untruncated ellipse).
    energy : float, J
        Total potential energy (eq 20).
    iterations : int
        Newton iterations of the solve.
    residual : float
        Largest force residual at the end, relative to the load scale.
    state : ndarray
        Solver unknowns, for a warm start (:meth:`BimeSolver.solve` ``initial``).
    rings : dict, ndarray or None
        The rings' compliances at the groove centres (flexible model,
        :func:`slewing_model.rings.compliance.ring_compliances`), from which
        ``ring_displacement`` follows; or those displacements, (B, 4, 2), m.
    converged : bool
        True: ``residual`` is within the solver's tolerance. False only where a bounded solve
        (``step_work="bounded"`` of :class:`~slewing_model.distribution.bime.BimeSolver`) spent its
        work first: then the result is the last Newton iterate, not an equilibrium (its ball loads
        are the Hertz forces there; the load capacity is not checked), and the next warm solve goes
        on from it.
    """

    model: str
    loads: Loads
    displacement: np.ndarray
    ball_angle: np.ndarray
    contact_load: np.ndarray
    contact_angle: np.ndarray
    interference: np.ndarray
    contact_deflection: np.ndarray
    semi_axis_a: np.ndarray
    semi_axis_b: np.ndarray
    contact_pressure: np.ndarray
    truncated: np.ndarray
    energy: float
    iterations: int
    residual: float
    state: np.ndarray = field(repr=False)
    rings: dict | np.ndarray | None = field(default=None, repr=False, compare=False)
    converged: bool = True

    @functools.cached_property
    def ring_displacement(self) -> np.ndarray | None:
        """(B, 4, 2) groove-centre displacements by ring deformation, m (None for rigid rings)."""
        if self.rings is None or isinstance(self.rings, np.ndarray):
            return self.rings
        from ..rings.compliance import groove_displacement

        return groove_displacement(self.rings, self.state[5:])

    def __getstate__(self) -> dict:
        """Pickled (a study's worker, a copy) with the ring displacements in place of the rings'
        compliance matrices they come from (megabytes)."""
        state = dict(self.__dict__)
        state["rings"] = self.ring_displacement
        state.pop("ring_displacement", None)
        return state

    # the largest load and pressure are taken once (a co-simulation step reads the pressure's three
    # times: its own output, the safety factor's and the warnings'); the arrays are not changed in place
    @functools.cached_property
    def max_ball_load(self) -> float:
        """Largest contact load, N."""
        return float(self.contact_load.max())

    @functools.cached_property
    def max_contact_pressure(self) -> float:
        """Largest Hertz pressure, Pa."""
        return float(self.contact_pressure.max())

    @property
    def static_safety_factor(self) -> float:
        """ISO 76 static safety factor ``(4200 MPa / p_max)^3`` (load ratio, as
        ``C0 / P0``: Hertz pressure grows with the cube root of the load);
        infinite for an unloaded bearing (largest pressure below ``NO_LOAD_PRESSURE``, 4.2 MPa:
        1/1000 of the ISO 76 limit)."""
        p = self.max_contact_pressure
        return math.inf if p < NO_LOAD_PRESSURE else (ISO76_PRESSURE_LIMIT / p) ** 3

    def warnings(self) -> list[str]:
        """What a user must know about this result although it is a valid solution.

        Returns
        -------
        list of str
            One sentence each (empty when nothing): a bounded step that stopped short of
            equilibrium, a static safety factor below 1 (ISO 76: the raceways deform
            permanently) and contacts loaded over the groove edge.

        Examples
        --------
        >>> from slewing_model import load_bearing, solve, Loads
        >>> r = solve(load_bearing("examples/bearings/table1.toml"), Loads(Fz=3e7))
        >>> r.warnings()[0][:43]
        'static safety factor 0.269 is below 1: the '
        """
        out = []
        if not self.converged:
            out.append(f"not in equilibrium: a bounded step spent its work with a relative force residual of "
                       f"{self.residual:.2g}; the next steps go on from here (step_work = bounded)")
        s = self.static_safety_factor
        if s < 1.0:
            out.append(f"static safety factor {s:.3g} is below 1: the largest contact pressure "
                       f"{self.max_contact_pressure / 1e6:.0f} MPa exceeds ISO 76's {ISO76_PRESSURE_LIMIT / 1e6:.0f} MPa "
                       f"and the raceways deform permanently (the result assumes they do not)")
        if self.truncated_contacts:
            out.append(f"{self.truncated_contacts} contact ellipses run over the groove edge (edge loading: "
                       f"their pressure is higher than Hertz's)")
        return out

    @property
    def truncated_contacts(self) -> int:
        """Number of contacts whose ellipse runs over the groove edge (edge loading)."""
        return int(np.count_nonzero(self.truncated))

    @property
    def balls_in_four_point_contact(self) -> int:
        """Number of balls whose both diagonals carry load (a contact pressure of at least
        ``NO_LOAD_PRESSURE``, 4.2 MPa, on all four contacts: the round-off interference of an
        unloaded bearing is no contact)."""
        p = self.contact_pressure                  # column by column: np.all(axis=1) costs 5 us on (150, 4)
        least = np.minimum(np.minimum(p[:, 0], p[:, 1]), np.minimum(p[:, 2], p[:, 3]))
        return int(np.count_nonzero(least >= NO_LOAD_PRESSURE))

    def to_dict(self) -> dict:
        """Plain JSON-ready data (the ``slewing solve --json`` object).

        Returns
        -------
        dict
            Loads, displacement, contact loads ``Q`` (N), contact angles (rad),
            interference (m), ball angles (rad), pressures (Pa), the summary values
            (largest ball load and pressure, safety factor, counts), energy (J),
            iterations and, for flexible rings, ``ring_displacement`` (m).
        """
        d = {
            "model": self.model,
            "loads": {k: getattr(self.loads, k) for k in LOAD_FIELDS},
            "displacement": dict(zip(DISPLACEMENT_FIELDS, map(float, self.displacement))),
            "Q": self.contact_load.tolist(),
            "contact_angle": self.contact_angle.tolist(),
            "interference": self.interference.tolist(),
            "ball_angle": self.ball_angle.tolist(),
            "contact_pressure": self.contact_pressure.tolist(),
            "max_ball_load": self.max_ball_load,
            "max_contact_pressure": self.max_contact_pressure,
            "static_safety_factor": self.static_safety_factor,
            "balls_in_four_point_contact": self.balls_in_four_point_contact,
            "truncated_contacts": self.truncated_contacts,
            "energy": self.energy,
            "iterations": self.iterations,
        }
        if self.ring_displacement is not None:
            d["ring_displacement"] = self.ring_displacement.tolist()
        return d
