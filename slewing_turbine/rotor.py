"""The rotor and drivetrain as one rotating inertia, and ROSCO's simulator loop.

The drivetrain is rigid: rotor, shaft, gearbox and generator turn together, seen
from the low-speed shaft as one inertia ``J``::

    J d(Omega)/dt = T_aero - N T_gen / eta_gb

with the aerodynamic torque from the rotor's power coefficient table
``Cp(pitch, lambda)``, ``lambda = Omega R / U``::

    T_aero = 1/2 rho pi R^3 (Cp / lambda) U^2          (P = 1/2 rho pi R^2 Cp U^3 = T_aero Omega)

This is the model of ROSCO's simulator (``rosco.toolbox.sim.Sim.sim_ws_series``), and
:func:`simulate_like_rosco_sim` is its loop with ideal pitch drives (each blade's pitch
is the previous command): explicit Euler, one step per wind sample, the table
interpolated by a bicubic ``scipy.interpolate.RectBivariateSpline`` as ROSCO does.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["CpTable", "Drivetrain", "RotorSimResult", "aerodynamic_torque", "euler_step",
           "simulate_like_rosco_sim"]

_DEG = np.deg2rad(1.0)  # the factor ROSCO's table reader multiplies degrees by


@dataclass(frozen=True)
class Drivetrain:
    """Rigid drivetrain and rotor constants (SI units).

    Attributes
    ----------
    rotor_inertia : float, kg m^2
        Total inertia about the shaft seen from the low-speed side: rotor (hub and
        blades) plus the generator's inertia times the gear ratio squared.
    gear_ratio : float
        Generator turns per rotor turn.
    generator_efficiency : float
        Electrical over mechanical generator power, in (0, 1].
    gearbox_efficiency : float
        In (0, 1]: the rotor sees ``gear_ratio * T_gen / gearbox_efficiency``.
    rotor_radius : float, m
        Tip radius (rotor apex to blade tip).
    air_density : float, kg/m^3
        Air density.
    """

    rotor_inertia: float
    gear_ratio: float
    generator_efficiency: float = 0.944
    gearbox_efficiency: float = 1.0
    rotor_radius: float = 63.0
    air_density: float = 1.225

    @classmethod
    def from_nrel5mw(cls) -> "Drivetrain":
        """NREL's 5 MW reference turbine, the values ROSCO's simulator reads for it.

        Returns
        -------
        Drivetrain
            ``rotor_inertia`` 43,702,538.057 kg m^2, ``gear_ratio`` 97, generator efficiency
            0.944, gearbox 1.0, radius 63 m, air 1.225 kg/m^3.

        Notes
        -----
        From ROSCO's NREL-5MW case (``Examples/Test_Cases/NREL-5MW``, ROSCO 2.10.6):

        * ``rotor_inertia`` 38,677,040.613 kg m^2 (ROSCO's ``Tune_Cases/NREL5MW.yaml``, from
          ElastoDyn's summary: ``HubIner`` 115,926 kg m^2 plus the three blades' second
          moment of mass about the shaft), plus ``GenIner`` 534.116 kg m^2 (ElastoDyn,
          about the high-speed shaft) times ``GBRatio``^2 = 97^2:
          38,677,040.613 + 534.116 x 9,409 = 38,677,040.613 + 5,025,497.444
          = 43,702,538.057 kg m^2 (ROSCO's ``Turbine.J``, and ``WE_Jtot`` in DISCON.IN);
        * ``GenEff`` 94.4 % (ServoDyn), ``GBoxEff`` 100 % (ElastoDyn), ``TipRad`` 63 m
          (ElastoDyn), ``AirDens`` 1.225 kg/m^3 (AeroDyn).
        """
        return cls(rotor_inertia=38_677_040.613 + 534.116 * 97.0**2, gear_ratio=97.0, generator_efficiency=0.944,
                   gearbox_efficiency=1.0, rotor_radius=63.0, air_density=1.225)


@dataclass(frozen=True)
class CpTable:
    """Rotor performance tables over blade pitch and tip speed ratio.

    Attributes
    ----------
    pitch : (n_pitch,) ndarray, rad
        Blade pitch angles of the table's columns.
    tip_speed_ratio : (n_tsr,) ndarray
        Tip speed ratios of its rows.
    cp, ct, cq : (n_tsr, n_pitch) ndarray
        Power, thrust and torque coefficients.
    """

    pitch: np.ndarray
    tip_speed_ratio: np.ndarray
    cp: np.ndarray
    ct: np.ndarray
    cq: np.ndarray
    _spline: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        from scipy.interpolate import RectBivariateSpline

        # bicubic, interpolating (s = 0), as ROSCO's RotorPerformance.interp_surface; built once here
        # (ROSCO builds it at every call: same knots, same values)
        object.__setattr__(self, "_spline", RectBivariateSpline(self.pitch, self.tip_speed_ratio, self.cp.T))

    @classmethod
    def read(cls, path) -> "CpTable":
        """Read ROSCO's rotor performance file (e.g. ``Cp_Ct_Cq.NREL5MW.txt``).

        The file: a pitch angle vector (deg) and a tip speed ratio vector, each on the line
        after its ``# Pitch angle vector`` / ``# TSR vector`` heading, then the power, thrust
        and torque coefficient matrices (one row per tip speed ratio), each starting two
        lines after its heading (``# Power coefficient``, ``Thrust``, ``Torque``).

        Parameters
        ----------
        path : str or path-like
            The file.

        Returns
        -------
        CpTable
            Pitch converted to rad.

        Raises
        ------
        ValueError
            If a vector or a matrix is missing or has the wrong size.
        """
        lines = Path(path).read_text().splitlines()

        def heading(word: str) -> int:
            for k, line in enumerate(lines):
                if line.lstrip().startswith("#") and word in line:
                    return k
            raise ValueError(f"{path}: no '# ... {word} ...' heading")

        def vector(word: str) -> np.ndarray:
            return np.array(lines[heading(word) + 1].split(), dtype=float)

        pitch_deg = vector("Pitch angle")
        tsr = vector("TSR")

        def matrix(word: str) -> np.ndarray:
            start = heading(word) + 2
            rows = [line.split() for line in lines[start:start + tsr.size]]
            try:
                table = np.array(rows, dtype=float)
            except ValueError:
                raise ValueError(f"{path}: the {word} coefficient table is not {tsr.size} rows of "
                                 f"{pitch_deg.size} numbers") from None
            if table.shape != (tsr.size, pitch_deg.size):
                raise ValueError(f"{path}: the {word} coefficient table is {table.shape}, expected "
                                 f"({tsr.size}, {pitch_deg.size}) (tip speed ratios x pitch angles)")
            return table

        return cls(pitch=pitch_deg * _DEG, tip_speed_ratio=tsr, cp=matrix("Power"), ct=matrix("Thrust"),
                   cq=matrix("Torque"))

    def power_coefficient(self, pitch: float, tip_speed_ratio: float) -> float:
        """Power coefficient at one point (bicubic spline through the table).

        Parameters
        ----------
        pitch : float, rad
            Blade pitch.
        tip_speed_ratio : float
            ``Omega R / U``.

        Returns
        -------
        float
            ``Cp``; outside the table the spline's end polynomials extend it.
        """
        return float(self._spline(pitch, tip_speed_ratio)[0, 0])


def aerodynamic_torque(power_coefficient: float, tip_speed_ratio: float, wind_speed: float,
                       drivetrain: Drivetrain) -> float:
    """Rotor torque from the power coefficient.

    ``T = 1/2 rho pi R^3 (Cp / lambda) U^2`` (power ``1/2 rho pi R^2 Cp U^3`` over ``Omega = lambda U / R``),
    evaluated in the order of ROSCO's simulator.

    Parameters
    ----------
    power_coefficient : float
        ``Cp``.
    tip_speed_ratio : float
        ``lambda``.
    wind_speed : float, m/s
        ``U``.
    drivetrain : Drivetrain
        Radius and air density.

    Returns
    -------
    float
        Torque on the low-speed shaft, N m.
    """
    d = drivetrain
    return 0.5 * d.air_density * (np.pi * d.rotor_radius**3) * (power_coefficient / tip_speed_ratio) * wind_speed**2


def euler_step(rotor_speed: float, aero_torque: float, generator_torque: float, dt: float,
               drivetrain: Drivetrain) -> float:
    """One explicit Euler step of ``J dOmega/dt = T_aero - N T_gen / eta_gb``.

    Parameters
    ----------
    rotor_speed : float, rad/s
        Speed at the start of the step.
    aero_torque : float, N m
        Aerodynamic torque over the step (low-speed shaft).
    generator_torque : float, N m
        Generator torque over the step (high-speed shaft).
    dt : float, s
        Step.
    drivetrain : Drivetrain
        Inertia, gear ratio, gearbox efficiency.

    Returns
    -------
    float
        Speed at the end of the step, rad/s.
    """
    d = drivetrain
    return rotor_speed + (dt / d.rotor_inertia) * (aero_torque - d.gear_ratio * generator_torque / d.gearbox_efficiency)


@dataclass
class RotorSimResult:
    """Time series of :func:`simulate_like_rosco_sim` (SI units, one value per time sample).

    Attributes
    ----------
    time : ndarray, s
    wind_speed : ndarray, m/s
    rotor_speed : ndarray, rad/s
    generator_speed : ndarray, rad/s
    pitch : ndarray, rad
        Collective pitch (the command of blade 1; ideal drives: also the blades' pitch
        at the next sample).
    generator_torque : ndarray, N m
        Generator torque command.
    aero_torque : ndarray, N m
        Aerodynamic torque over the step ending at the sample.
    """

    time: np.ndarray
    wind_speed: np.ndarray
    rotor_speed: np.ndarray
    generator_speed: np.ndarray
    pitch: np.ndarray
    generator_torque: np.ndarray
    aero_torque: np.ndarray


def simulate_like_rosco_sim(time, wind_speed, *, discon_in, cp_table: CpTable, drivetrain: Drivetrain | None = None,
                            rotor_speed_init: float = 10.0 * (2.0 * np.pi / 60.0), initial_pitch: float = 0.0,
                            library=None) -> RotorSimResult:
    """ROSCO's simulator (``Sim.sim_ws_series``) with ideal pitch drives, sample for sample.

    At each sample ``i >= 1`` (``dt = time[1] - time[0]``):

    1. ``lambda = Omega[i-1] R / U[i]``, ``Cp`` at (``pitch[i-1]``, ``lambda``), ``T_aero[i]``
       (:func:`aerodynamic_torque`);
    2. ``Omega[i]`` by :func:`euler_step` with ``T_gen[i-1]``; generator speed ``N Omega[i]``;
    3. the controller (:class:`~slewing_turbine.controller.RoscoController`) gets ``Omega[i]``,
       the wind ``U[i]``, the measured pitch ``pitch[i-1]`` on all three blades and the
       torque ``T_gen[i-1]``; the last sample is its last call;
    4. its commands are ``T_gen[i]`` and ``pitch[i]`` (blade 1).

    At ``i = 0``: ``Omega = rotor_speed_init``, pitch ``initial_pitch``, ``T_gen`` = 1 N m,
    ``T_aero`` = 1000 N m (ROSCO's simulator's start values).

    Parameters
    ----------
    time : (n,) array_like, s
        Equally spaced sample times.
    wind_speed : (n,) array_like, m/s
        Hub-height wind speed at each sample.
    discon_in : str or path-like
        ROSCO's parameter file.
    cp_table : CpTable
        The rotor's performance table.
    drivetrain : Drivetrain, optional
        Default :meth:`Drivetrain.from_nrel5mw`.
    rotor_speed_init : float, rad/s
        Default 10 rpm (ROSCO's simulator's default).
    initial_pitch : float, rad
        Pitch at the first sample (the controller's initialising call gets 0, as in ROSCO's
        simulator).
    library : str or path-like, optional
        ROSCO's library (default: the ``rosco`` wheel's).

    Returns
    -------
    RotorSimResult

    Raises
    ------
    ValueError
        If the arrays differ in length, have fewer than 2 samples, or the time step is not > 0.
    """
    from .controller import Measurements, RoscoController

    t = np.asarray(time, dtype=float)
    ws = np.asarray(wind_speed, dtype=float)
    if t.ndim != 1 or ws.shape != t.shape or t.size < 2:
        raise ValueError(f"time and wind_speed: shapes {t.shape} and {ws.shape}: must be equal 1-D arrays of "
                         f">= 2 samples")
    dt = t[1] - t[0]
    if not dt > 0:
        raise ValueError(f"time[1] - time[0] = {dt!r}: must be > 0 (s)")
    if not np.all(np.isfinite(ws)):
        raise ValueError("wind_speed: must be finite (m/s)")
    d = drivetrain or Drivetrain.from_nrel5mw()
    n = t.size
    pitch = np.full(n, float(initial_pitch))
    rot = np.full(n, float(rotor_speed_init))
    gen = rot * d.gear_ratio
    aero = np.full(n, 1000.0)
    torque = np.ones(n)
    spline = cp_table._spline
    radius, ratio, eff = d.rotor_radius, d.gear_ratio, d.generator_efficiency
    blades = np.zeros(3)
    with RoscoController(discon_in, dt, library=library) as controller:
        for i in range(1, n):
            u = ws[i]
            tsr = rot[i - 1] * radius / u
            cp = spline(pitch[i - 1], tsr)[0, 0]
            aero[i] = aerodynamic_torque(cp, tsr, u, d)
            rot[i] = euler_step(rot[i - 1], aero[i], torque[i - 1], dt, d)
            gen[i] = rot[i] * ratio
            blades[:] = pitch[i - 1]
            cmd = controller.step(Measurements(time=t[i], rotor_speed=rot[i], generator_speed=gen[i],
                                               generator_torque=torque[i - 1], blade_pitch=blades, wind_speed=u,
                                               generator_efficiency=eff), last=i == n - 1)
            torque[i] = cmd.generator_torque
            pitch[i] = cmd.pitch[0]
    return RotorSimResult(time=t, wind_speed=ws, rotor_speed=rot, generator_speed=gen, pitch=pitch,
                          generator_torque=torque, aero_torque=aero)
