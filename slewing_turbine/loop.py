"""The closed turbine loop: wind, rotor, ROSCO, and three pitch drives on their pitch bearings.

Every step ``dt`` (10 ms by default), in the order of ROSCO's ``Sim`` (so that ideal drives reproduce it):

1. **aero**: the rotor torque from the rotor speed and the blades' pitch at the start of the step and the
   wind at its end (as ``Sim``): either from the Cp table (``aero="cp_table"``, collective, ``Sim``'s
   formula) or from the blade-element momentum model of each blade (``aero="bem"``) at *its own* pitch and
   azimuth, in the wind sheared over its span; with ``"bem"`` each blade's root loads add gravity and the
   centrifugal load (:func:`slewing_turbine.blade_loads.root_loads`, the blade frame ``b`` that pitches);
2. **rotor**: one explicit Euler step of the 1-DOF drivetrain (:func:`slewing_turbine.rotor.euler_step`), the
   azimuth advanced by the step's start speed;
3. **pitch axes** (``drives="electric"``): each blade's pitch bearing (an in-process
   :class:`~slewing_model.simulation.BearingSimulator`, ``bearings="flexible"`` or ``"rigid"``; or a bearing FMU,
   :mod:`slewing_turbine.fmu_bearing`) steps under the
   blade's root loads ``Fx, Fy, Fz, Mx, My`` (the blade frame is the moving ring's frame: ``load_frame``
   ``"rotating"``, the bearing's +z towards the tip) at the ring angle ``psi = -pitch`` and speed
   ``omega = -pitch rate`` (the blade turns by minus its pitch about the tip-wards axis, as
   :func:`slewing_model.loads.aeroelastic.bearing_loads` reads OpenFAST's runs); its friction torque at full
   sliding goes, with the blade's pitching moment ``Mz`` as load torque, to the blade's
   :class:`~slewing_drives.ElectricDrive`, which follows the last pitch demand for one step (the sequential
   coupling of :func:`slewing_drives.cosimulation.run_manoeuvre`). ``drives="ideal"``: the blades are at the
   last demand (no drive, no bearing), as in ``Sim``;
4. **controller**: ROSCO (:class:`slewing_turbine.controller.RoscoController`) with the new rotor and generator
   speed, the last generator torque, the wind, the measured pitch of each blade (the drives' angles; ideal:
   the last demand), the rotor azimuth and the blades' out-of-plane root moments (IPC); its generator torque
   and pitch demands act from the next step on.

The drives run in pitch coordinates: angle = blade pitch (rad), positive speed = pitching towards feather;
their load torque is the moment about the pitch axis that opposes a positive pitch, which is the blade's
``Mz`` about the tip-wards axis ``zb`` (a blade pitches by turning about ``-zb``). Motor torques are those of
one motor (each blade's drive has ``motor_count`` of them).

:func:`run_turbine` returns a :class:`TurbineResult` (arrays, SI units), :func:`summary` the figures a pitch
system engineer reads first, :func:`summary_table` them side by side for several runs.
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: the NREL 5MW turbine's files (copies of ROSCO 2.10.6's case, Apache-2.0: their README)
NREL5MW = ROOT / "examples" / "turbines" / "nrel5mw"
#: the pitch drive and pitch bearing of the examples
PITCH_DRIVE = ROOT / "examples" / "drives" / "pitch_drive_nrel5mw.toml"
PITCH_BEARING = ROOT / "examples" / "bearings" / "pitch_bearing.toml"
#: rated rotor speed of the NREL 5MW turbine, rad/s (12.1 rpm)
RATED_ROTOR_SPEED = 12.1 * math.pi / 30.0
#: the settle time the figures leave out by default, s (a run shorter than twice this: its first half): from
#: ROSCO's ``Sim`` start (10 rpm, 0 deg) the NREL 5MW's start-up transient (overspeed, the blades pitching
#: at the drives' rate limit) dies down within 10 to 20 s of simulated time
SETTLE_DEFAULT = 20.0
#: the pitch an emergency stop demands, rad (ROSCO's ``PC_MaxPit`` of the NREL 5MW: feather, 90 deg)
FEATHER = math.pi / 2.0
DRIVES = ("ideal", "electric")
BEARINGS = (None, "flexible", "rigid")
AERO = ("cp_table", "bem")
#: the columns of ``TurbineResult.root_loads`` (the first five: what each pitch bearing gets)
ROOT_LOADS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")


@dataclass
class TurbineConfig:
    """What the loop runs (SI units, angles in rad).

    Attributes
    ----------
    turbine_dir : Path
        The turbine's files (default the NREL 5MW copies in ``examples/turbines/nrel5mw``).
    discon, cp_table, rotor : str
        File names in ``turbine_dir``: ROSCO's DISCON.IN, the Cp/Ct/Cq table, the rotor's geometry
        (:class:`slewing_turbine.bem.RotorGeometry`: it names the AeroDyn and ElastoDyn blade files).
    discon_overrides : dict or None
        ROSCO parameters replacing the DISCON file's (``overrides`` of
        :class:`~slewing_turbine.controller.RoscoController`, e.g. ``{"IPC_ControlMode": 1}``).
    drivetrain : Drivetrain or None
        The rotor's 1-DOF drivetrain; None: :meth:`Drivetrain.from_nrel5mw`.
    drive : DriveParameters or path
        Each blade's pitch drive (default ``examples/drives/pitch_drive_nrel5mw.toml``: two motors).
    drive_substeps : int
        Inner steps of a drive per loop step (:class:`~slewing_drives.ElectricDrive`).
    bearing : path
        Each blade's pitch bearing (default ``examples/bearings/pitch_bearing.toml``).
    mesh : {"fine", "coarse"}
        Superelement mesh of flexible bearings (the FMU's default: fine).
    friction_coefficient, seal_torque : float
        The bearings' friction (``friction=True``), -, N m.
    life : bool
        Accumulate each bearing's raceway life map (:class:`~slewing_model.life.LifeAccumulator`); the
        summary then gives the worst blade's map damage and life.
    step_work : {"complete", "bounded"}
        The bearings' step mode (:class:`~slewing_model.simulation.SimulatorSettings`): every step solved to
        the tolerance, or each step's work capped (real time; a step that would need more answers with its
        last iterate and goes on in the next steps).
    hub_height : float or None
        m; None: the turbine's (``rotor.toml``, 90 m for the NREL 5MW).
    shear_exponent : float
        The power-law wind shear over the rotor (``aero="bem"``), IEC's 0.2 by default.
    rotor_speed_init, pitch_init, azimuth_init : float
        The start, rad/s, rad, rad (``Sim``'s default start: 10 rpm, 0 deg).
    generator_torque_init : float
        The generator torque before the first controller call, N m (``Sim``: 1).
    continuous_torque_share : float
        A motor's continuous torque as a share of its peak (``torque_limit``), for the duty figure of
        :func:`summary`. Default 0.4 (ASSUMPTION: servo pitch motors carry 2-3 times their continuous torque
        for seconds; the drive file gives the peak only).
    settle : float or None
        s of simulated time :func:`summary` leaves out at the start (the start-up transient); None:
        :data:`SETTLE_DEFAULT` (20 s), or half the run when it is shorter than 40 s.
    """

    turbine_dir: Path = NREL5MW
    discon: str = "DISCON.IN"
    discon_overrides: dict | None = None
    cp_table: str = "Cp_Ct_Cq.NREL5MW.txt"
    rotor: str = "rotor.toml"
    drivetrain: object = None
    drive: object = PITCH_DRIVE
    drive_substeps: int = 10
    bearing: object = PITCH_BEARING
    mesh: str = "fine"
    friction_coefficient: float = 0.1
    seal_torque: float = 0.0
    life: bool = False
    step_work: str = "complete"
    hub_height: float | None = None
    shear_exponent: float = 0.2
    rotor_speed_init: float = 10.0 * math.pi / 30.0
    pitch_init: float = 0.0
    azimuth_init: float = 0.0
    generator_torque_init: float = 1.0
    continuous_torque_share: float = 0.4
    settle: float | None = None

    def path(self, name: str) -> Path:
        """A file of the turbine (``turbine_dir / name``)."""
        return Path(self.turbine_dir) / name

    def drive_parameters(self):
        from slewing_drives import DriveParameters

        return self.drive if isinstance(self.drive, DriveParameters) else DriveParameters.from_toml(self.drive)

    def bearing_definition(self):
        """The pitch bearing: ``bearing`` itself, or the bearing file it names read."""
        from slewing_model import load_bearing

        return self.bearing if not isinstance(self.bearing, (str, Path)) else load_bearing(self.bearing)

    def the_drivetrain(self):
        from .rotor import Drivetrain

        return self.drivetrain if self.drivetrain is not None else Drivetrain.from_nrel5mw()


@dataclass
class TurbineResult:
    """Time histories of a closed-loop run (SI units, angles in rad; ``(n, 3)``: per blade).

    Values at the sample times ``time[i]``: ``wind`` (the hub-height wind the step ending there saw),
    ``rotor_speed``, ``azimuth``, ``generator_torque`` (the command from the controller call at ``time[i]``),
    ``pitch_demand`` (from that call), ``pitch`` (the blades' angle the controller measured there),
    ``pitch_rate``. Values of the step ending at ``time[i]`` (NaN at ``i = 0``): ``aero_torque``,
    ``motor_torque`` (one motor's, averaged over the step), ``friction_torque`` (the bearing's at full
    sliding, held over the step), ``load_moment`` (the drive's load torque), ``root_loads`` (the blade-root
    loads ``Fx, Fy, Fz, Mx, My, Mz`` in the blade frame ``b`` at the step's start), ``bearing_loads`` (their
    first five: what each bearing got), ``root_moop`` (the out-of-plane root moments the controller got),
    ``step_seconds`` (wall time of the step), ``motor_energy`` (each drive's delivered motor energy so far,
    cumulative, J). With bearings: ``contact_b`` (n, 3, 4), the widest contact patch's semi-axis ``b`` of
    each contact 1..4 of each blade's bearing at the step (m; 0: unloaded), and ``contact_angle`` at it
    (rad), None where the bearings give no load distribution (bearing FMUs); ``bearing_geometry``
    ``(pitch_diameter, ball_diameter)`` (m). ``settle``: the s left out of the
    figures (:func:`summary`); ``emergency_stop``: the time of the emergency stop (None: none).
    """

    time: np.ndarray
    wind: np.ndarray
    rotor_speed: np.ndarray
    azimuth: np.ndarray
    generator_torque: np.ndarray
    aero_torque: np.ndarray
    pitch_demand: np.ndarray
    pitch: np.ndarray
    pitch_rate: np.ndarray
    motor_torque: np.ndarray
    friction_torque: np.ndarray
    load_moment: np.ndarray
    root_loads: np.ndarray
    root_moop: np.ndarray
    step_seconds: np.ndarray
    energies: dict
    drives: str
    bearings: str | None
    aero: str
    friction: bool
    drive_params: object = None
    drivetrain: object = None
    continuous_torque_share: float = 0.4
    life: list | None = None
    motor_energy: np.ndarray | None = None
    contact_b: np.ndarray | None = None
    contact_angle: np.ndarray | None = None
    bearing_geometry: tuple | None = None
    settle: float = 0.0
    emergency_stop: float | None = None

    @property
    def bearing_loads(self) -> np.ndarray:
        """(n, 3, 5): ``Fx, Fy, Fz, Mx, My`` of each blade's bearing (blade frame)."""
        return self.root_loads[:, :, :5]

    @property
    def dt(self) -> float:
        return float(self.time[1] - self.time[0])


class PitchAxis:
    """One blade's pitch drive on its pitch bearing, stepped together (the sequential coupling of
    :func:`slewing_drives.cosimulation.run_manoeuvre`, in pitch coordinates).

    Parameters
    ----------
    drive : DriveParameters
    bearing : BearingSimulator, FmuBearing or None
        The blade's pitch bearing (``load_frame`` "rotating"; a bearing FMU:
        :class:`slewing_turbine.fmu_bearing.FmuBearing`); None: no bearing, no friction.
    pitch : float
        The start angle, rad.
    substeps : int
        The drive's inner steps per step.
    """

    def __init__(self, drive, bearing=None, pitch: float = 0.0, substeps: int = 10):
        from slewing_drives import ElectricDrive

        self.drive = ElectricDrive(drive, substeps=substeps)
        self.drive.state.angle = pitch
        self.bearing = bearing
        self.friction = 0.0
        self.result = None          # the bearing's last StepResult

    def hold(self, load_moment: float) -> None:
        """Start at rest holding ``load_moment`` (N m), as a drive that has held its angle."""
        self.drive.hold(load_moment)

    def step(self, demand: float, dt: float, loads, load_moment: float):
        """Advance one step: the bearing at the drive's angle and speed under ``loads`` (a
        :class:`~slewing_model.Loads` in the blade frame, or None without a bearing), then the drive
        towards ``demand`` (rad) against ``load_moment`` (N m) and the bearing's friction.

        Returns
        -------
        DriveState
            The drive's state at the end of the step (``angle`` = pitch, ``speed`` = pitch rate).
        """
        s = self.drive.state
        if self.bearing is not None:
            r = self.bearing.step(loads, psi=-s.angle, omega=-s.speed)
            self.friction = r.friction_torque_magnitude
            self.result = r
        return self.drive.step(demand, dt, load_torque=load_moment, friction_torque=self.friction)


def bearing_settings(config: TurbineConfig, ring_model: str, friction: bool):
    """The pitch bearings' :class:`~slewing_model.simulation.SimulatorSettings`: ``ring_model``, loads in the
    blade frame (``load_frame`` "rotating"), the config's friction (``friction``: its coefficient and seal
    torque, else both 0), ``life`` and ``step_work``; the rest the defaults."""
    from slewing_model.simulation.simulator import SimulatorSettings

    return SimulatorSettings(ring_model=ring_model, load_frame="rotating",
                             friction_coefficient=config.friction_coefficient if friction else 0.0,
                             seal_torque=config.seal_torque if friction else 0.0, life=config.life,
                             step_work=config.step_work)


def make_bearings(config: TurbineConfig, ring_model: str, friction: bool, count: int = 3) -> list:
    """``count`` pitch bearing simulators (:func:`bearing_settings`; loads in the blade frame). The same as
    FMUs: :func:`slewing_turbine.fmu_bearing.fmu_bearings`."""
    from slewing_model.simulation.simulator import BearingSimulator

    bearing = config.bearing_definition()
    superelement = None
    if ring_model == "flexible":
        from slewing_model.rings.superelement import build_superelement

        superelement = build_superelement(bearing, mesh=config.mesh, bc="free")
    settings = bearing_settings(config, ring_model, friction)
    return [BearingSimulator(bearing, superelement, settings) for _ in range(count)]


# ---- aerodynamics ----------------------------------------------------------------------------------

class _CpAero:
    """``Sim``'s rotor torque from the Cp table: collective (the blades' mean pitch; blade 1's when equal)."""

    def __init__(self, config: TurbineConfig, drivetrain):
        from .rotor import CpTable, aerodynamic_torque

        self.table = CpTable.read(config.path(config.cp_table))
        self.torque = aerodynamic_torque
        self.drivetrain = drivetrain

    def __call__(self, wind: float, rotor_speed: float, pitch: np.ndarray, azimuth: float):
        p = pitch[0] if pitch[1] == pitch[0] and pitch[2] == pitch[0] else float(np.mean(pitch))
        tsr = rotor_speed * self.drivetrain.rotor_radius / wind
        return float(self.torque(self.table.power_coefficient(p, tsr), tsr, wind, self.drivetrain)), None


class _BemAero:
    """Each blade's BEM loads at its pitch and azimuth in the sheared wind, plus gravity and centrifugal
    root loads: the rotor torque and the root loads (3, 6) in the blade frame."""

    def __init__(self, config: TurbineConfig, drivetrain):
        from . import bem, blade_loads, wind

        self.bem, self.blade_loads, self.wind = bem, blade_loads, wind
        self.geometry = bem.RotorGeometry.read_toml(config.path(config.rotor))
        self.blade = self.geometry.read_blade()
        self.mass = blade_loads.BladeMass.of_rotor(self.geometry)
        self.hub_height = self.geometry.hub_height if config.hub_height is None else float(config.hub_height)
        self.shear_exponent = config.shear_exponent

    def __call__(self, wind: float, rotor_speed: float, pitch: np.ndarray, azimuth: float):
        g, torque = self.geometry, 0.0
        loads = np.empty((3, 6))
        for k in range(3):
            az = azimuth + 2.0 * math.pi * k / 3.0
            u = self.wind.shear(wind, self.bem.node_heights(self.blade, az, self.hub_height), self.hub_height,
                                self.shear_exponent)
            aero = self.bem.bem_loads(self.blade, u, rotor_speed, float(pitch[k]), azimuth=az)
            torque += aero.torque_contribution
            r = self.blade_loads.root_loads(aero, self.mass, az, float(pitch[k]), rotor_speed,
                                            tilt=g.shaft_tilt, cone=g.precone)
            loads[k] = (r.Fx, r.Fy, r.Fz, r.Mx, r.My, r.Mz)
        return float(torque), loads


def out_of_plane(root_loads: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """Out-of-plane root moments (the coned frame's ``My``, what OpenFAST's ServoDyn gives ROSCO) from the
    blade-frame ``Mx, My``: ``Myc = -sin(pitch) Mxb + cos(pitch) Myb`` (ElastoDyn's ``b`` is ``c`` turned by
    the pitch)."""
    return -np.sin(pitch) * root_loads[:, 3] + np.cos(pitch) * root_loads[:, 4]


# ---- the loop ----------------------------------------------------------------------------------------

def run_turbine(config: TurbineConfig | None, wind, *, t_end: float | None = None, dt: float = 0.01,
                drives: str = "ideal", bearings: str | None = None, friction: bool = True,
                aero: str = "bem", bearing_simulators: list | None = None, progress: bool = False,
                emergency_stop: float | None = None) -> TurbineResult:
    """Run the closed loop over ``wind`` (module docstring: the order of a step).

    Parameters
    ----------
    config : TurbineConfig or None
        The turbine, its drives and bearings (None: the defaults).
    wind : WindSeries
        Hub-height wind (``time``, ``speed``, m/s); sampled at the loop's times (interpolated where its
        times differ).
    t_end : float, s
        The last sample's time (default: the wind's). The run has ``round(t_end / dt) + 1`` samples from the
        wind's first time.
    dt : float, s
        The step (the controller's ``DT``).
    drives : {"ideal", "electric"}
        Ideal: each blade is at its last demand (``Sim``'s actuator). Electric: a
        :class:`~slewing_drives.ElectricDrive` per blade, on its bearing where ``bearings`` is given.
    bearings : {None, "flexible", "rigid"}
        The pitch bearings' ring model (electric drives only); None: no bearing (no friction).
    friction : bool
        The bearings' friction on (``config.friction_coefficient``, ``seal_torque``) or off (both 0).
    aero : {"bem", "cp_table"}
        Each blade's BEM, with root loads; or ``Sim``'s Cp table (no root loads: no bearing, and the drives
        carry no load moment).
    bearing_simulators : list of 3 BearingSimulator, optional
        Use these (built by :func:`make_bearings` once for several runs) instead of building them; they must
        match ``bearings`` and ``friction``, and carry on from their last state. Bearing FMUs in their place
        (:class:`slewing_turbine.fmu_bearing.FmuBearing`, :func:`~slewing_turbine.fmu_bearing.fmu_bearings`)
        give no load distribution: the result then has no contact patches (``contact_b`` None, no ``x/2b``
        figure), and with ``config.life`` its ``life`` holds the FMUs' damage only
        (:class:`~slewing_turbine.fmu_bearing.FmuLife`).
    progress : bool
        A progress bar on stderr.
    emergency_stop : float or None, s
        From the first controller call at or after this time the pitch demand of every blade is feather
        (:data:`FEATHER`, 90 deg) and the generator torque is zero (the grid lost with the stop: the worst
        case for the rotor's speed); the drives pitch at their rate and torque limits against the
        bearings' friction and the blades' pitching moments. ROSCO is still called (its outputs are
        overridden). None: no stop.

    Returns
    -------
    TurbineResult
    """
    from slewing_model import Loads

    from .controller import Measurements, RoscoController
    from .rotor import euler_step

    config = config or TurbineConfig()
    if drives not in DRIVES:
        raise ValueError(f"drives = {drives!r}: must be one of {', '.join(map(repr, DRIVES))}")
    if bearings not in BEARINGS:
        raise ValueError(f"bearings = {bearings!r}: must be one of {', '.join(map(repr, BEARINGS))}")
    if aero not in AERO:
        raise ValueError(f"aero = {aero!r}: must be one of {', '.join(map(repr, AERO))}")
    if bearings is not None and drives == "ideal":
        raise ValueError("bearings need drives = 'electric' (an ideal drive has no bearing)")
    if bearings is not None and aero == "cp_table":
        raise ValueError("bearings need aero = 'bem' (the Cp table gives no blade-root loads)")
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt = {dt!r}: must be a finite number > 0")
    if emergency_stop is not None and not math.isfinite(emergency_stop):
        raise ValueError(f"emergency_stop = {emergency_stop!r}: must be a finite time, s")

    drivetrain = config.the_drivetrain()
    t0 = float(wind.time[0])
    t_end = float(wind.time[-1]) if t_end is None else float(t_end)
    n = int(round((t_end - t0) / dt)) + 1
    if n < 2:
        raise ValueError(f"t_end = {t_end!r}: the run needs at least one step of dt = {dt!r} after {t0!r}")
    time = t0 + np.arange(n) * dt
    settle = resolve_settle(config.settle, float(time[-1] - time[0]))
    wind_time, wind_speed = np.asarray(wind.time, float), np.asarray(wind.speed, float)
    if wind_time.size >= n and np.array_equal(wind_time[:n], time):
        ws = wind_speed[:n].copy()
    else:
        if time[-1] > wind_time[-1] + 1e-9 * max(1.0, abs(wind_time[-1])):
            raise ValueError(f"t_end = {t_end!r}: the wind ends at {wind_time[-1]!r} s")
        ws = np.interp(time, wind_time, wind_speed)

    aero_model = (_BemAero if aero == "bem" else _CpAero)(config, drivetrain)
    params = config.drive_parameters() if drives == "electric" else None
    if drives == "electric" and bearings is not None:
        sims = bearing_simulators or make_bearings(config, bearings, friction)
        if len(sims) != 3:
            raise ValueError(f"bearing_simulators: {len(sims)} given, 3 needed")
    else:
        sims = [None] * 3

    # ---- the arrays (module docstring of TurbineResult: what index i means) ----
    rot, azimuth, gen_torque, aero_torque = (np.full(n, np.nan) for _ in range(4))
    demand, pitch, rate, motor, fric, mz, moop = (np.full((n, 3), np.nan) for _ in range(7))
    roots = np.full((n, 3, 6), np.nan)
    step_seconds = np.zeros(n)
    motor_energy = np.zeros((n, 3)) if drives == "electric" else None
    stepped = sims[0] is not None
    patches = stepped              # the bearings give their load distribution (bearing FMUs do not)
    contact_b = np.zeros((n, 3, 4)) if stepped else None
    contact_angle = np.zeros((n, 3, 4)) if stepped else None
    rot[0], azimuth[0], gen_torque[0] = config.rotor_speed_init, config.azimuth_init, config.generator_torque_init
    demand[0] = pitch[0] = config.pitch_init
    rate[0] = 0.0
    moop[0] = 0.0

    axes = None
    if drives == "electric":
        axes = [PitchAxis(params, sims[k], config.pitch_init, config.drive_substeps) for k in range(3)]
        if aero == "bem":            # the drives start holding the blades' pitching moments
            _, first = aero_model(ws[0], rot[0], pitch[0], azimuth[0])
            for k in range(3):
                axes[k].hold(first[k, 5])
            moop[0] = out_of_plane(first, pitch[0])
    iterator = range(1, n)
    if progress:
        from slewing_model.progress import progress_bar

        iterator = progress_bar(desc=f"turbine ({drives} drives)", unit="step", leave=False, iterable=iterator)

    with RoscoController(config.path(config.discon), dt, overrides=config.discon_overrides) as controller:
        for i in iterator:
            start = _time.perf_counter()
            # 1. aero from the last speed and the blades' pitch over this step, the wind at its end (as Sim)
            blade_pitch = demand[i - 1] if drives == "ideal" else pitch[i - 1]
            aero_torque[i], root = aero_model(ws[i], rot[i - 1], blade_pitch, azimuth[i - 1])
            # 2. rotor
            rot[i] = euler_step(rot[i - 1], aero_torque[i], gen_torque[i - 1], dt, drivetrain)
            azimuth[i] = (azimuth[i - 1] + rot[i - 1] * dt) % (2.0 * math.pi)
            # 3. pitch axes over the step, towards the last demands
            if root is not None:
                roots[i] = root
                moop[i] = out_of_plane(root, blade_pitch)
            else:
                moop[i] = 0.0
            if axes is None:
                pitch[i] = demand[i - 1]
                rate[i] = (demand[i - 1] - pitch[i - 1]) / dt
            else:
                for k, axis in enumerate(axes):
                    load_moment = 0.0 if root is None else float(root[k, 5])
                    loads = None if root is None else Loads(*map(float, root[k, :5]))
                    s = axis.step(float(demand[i - 1, k]), dt, loads, load_moment)
                    pitch[i, k], rate[i, k], motor[i, k] = s.angle, s.speed, s.mean_motor_torque
                    fric[i, k], mz[i, k] = axis.friction, load_moment
                    motor_energy[i, k] = axis.drive.state.motor_energy
                    if patches and axis.result.distribution is not None:
                        contact_b[i, k], contact_angle[i, k] = widest_contacts(axis.result.distribution)
                    elif patches:
                        patches = False
            # 4. controller: the new speed, the measured pitch
            m = Measurements(time=time[i], rotor_speed=rot[i], generator_speed=rot[i] * drivetrain.gear_ratio,
                             generator_torque=gen_torque[i - 1], blade_pitch=pitch[i].copy(), wind_speed=ws[i],
                             azimuth=azimuth[i], root_moop=moop[i].copy(),
                             generator_efficiency=drivetrain.generator_efficiency)
            c = controller.step(m, last=i == n - 1)
            gen_torque[i] = c.generator_torque
            demand[i] = c.pitch
            if emergency_stop is not None and time[i] >= emergency_stop - 1e-9 * dt:
                gen_torque[i] = 0.0
                demand[i] = FEATHER
            step_seconds[i] = _time.perf_counter() - start

    energies = rotor_energies(time, rot, aero_torque, gen_torque, drivetrain)
    if axes is not None:
        energies.update(drive_energies(axes, pitch, rate, motor, fric, mz, params))
    life = None
    if sims[0] is not None and sims[0].life is not None:
        life = [s.life for s in sims]
    if not patches:
        contact_b = contact_angle = None
    geometry = None
    if stepped:
        b = sims[0].bearing
        geometry = (float(b.pitch_diameter), float(b.ball_diameter))
    return TurbineResult(time, ws, rot, azimuth, gen_torque, aero_torque, demand, pitch, rate, motor, fric, mz,
                         roots, moop, step_seconds, energies, drives, bearings, aero, friction, params, drivetrain,
                         config.continuous_torque_share, life, motor_energy, contact_b, contact_angle, geometry,
                         settle, emergency_stop)


def resolve_settle(settle: float | None, duration: float) -> float:
    """The settle time of a run of ``duration`` s: ``settle`` (it must leave a window: ``0 <= settle <
    duration``), or None: :data:`SETTLE_DEFAULT`, at most half the run."""
    if settle is None:
        return min(SETTLE_DEFAULT, 0.5 * duration)
    settle = float(settle)
    if not (math.isfinite(settle) and 0.0 <= settle < duration):
        raise ValueError(f"settle = {settle!r} s: must be >= 0 and shorter than the run ({duration:g} s)")
    return settle


def widest_contacts(distribution) -> tuple:
    """The widest patch's semi-axis ``b`` (m) of each contact 1..4 over the balls, and its contact angle
    (rad), as :class:`slewing_model.life.LifeAccumulator` takes them for ``x/2b``."""
    b = np.asarray(distribution.semi_axis_b, dtype=float)
    j = np.argmax(b, axis=0)
    cols = np.arange(b.shape[1])
    return b[j, cols], np.asarray(distribution.contact_angle, dtype=float)[j, cols]


# ---- energies ----------------------------------------------------------------------------------------

def rotor_energies(time, rotor_speed, aero_torque, generator_torque, drivetrain) -> dict:
    """The rotor's energy balance over a run, J: the work of the aero torque and of the generator's torque on
    the shaft at each step's mean speed (exact for the explicit Euler step: ``J (w1 - w0) = dt (Ta - Tg')``
    times ``(w1 + w0) / 2``), the electrical energy and the generator's and gearbox's losses, the change of
    kinetic energy and what is left of ``aero - shaft - kinetic``.

    ``Tg' = gear_ratio * Tg / gearbox_efficiency`` is the generator torque seen on the rotor; the gearbox
    loss is ``Tg' - gear_ratio * Tg`` times the speed, the generator's ``(1 - generator_efficiency)`` of the
    generator's mechanical power."""
    dt = np.diff(time)
    mean_speed = 0.5 * (rotor_speed[1:] + rotor_speed[:-1])
    ng, eta_gb = drivetrain.gear_ratio, drivetrain.gearbox_efficiency
    tg = generator_torque[:-1]                    # held over the step ending at i
    aero = float(np.sum(aero_torque[1:] * mean_speed * dt))
    shaft = float(np.sum(ng * tg / eta_gb * mean_speed * dt))
    generator_mech = float(np.sum(ng * tg * mean_speed * dt))
    electrical = drivetrain.generator_efficiency * generator_mech
    kinetic = 0.5 * drivetrain_inertia(drivetrain) * (rotor_speed[-1] ** 2 - rotor_speed[0] ** 2)
    return {"aero": aero, "shaft": shaft, "electrical": electrical, "generator_loss": generator_mech - electrical,
            "gearbox_loss": shaft - generator_mech, "kinetic_change": float(kinetic),
            "rotor_residual": aero - shaft - float(kinetic)}


def drivetrain_inertia(drivetrain) -> float:
    """The drivetrain's inertia on the rotor side, kg m^2 (``rotor_inertia``: the total)."""
    for name in ("rotor_inertia", "inertia", "J"):
        if hasattr(drivetrain, name):
            return float(getattr(drivetrain, name))
    raise AttributeError("the drivetrain has no rotor_inertia")


def drive_energies(axes, pitch, rate, motor_torque, friction, load_moment, params) -> dict:
    """Per blade, J: the motors' delivered (positive) work (``DriveState.motor_energy``: motoring only,
    energy fed back is not credited); the motors' work at the ring, signed (each step's mean ring torque
    times the step's pitch change); the work against the bearing's friction (its torque times the angle
    travelled, each step); the work against the load moment (signed: negative where the blade's pitching
    moment drives it); the change of the drive's kinetic energy (ring side); and what is left of
    ``ring work - friction - load - kinetic`` (the mean torque over a step stands for the inner steps'
    torques: a small residual)."""
    return drive_work(np.array([a.drive.state.motor_energy for a in axes]), pitch, rate, motor_torque, friction,
                      load_moment, params)


def drive_work(motor, pitch, rate, motor_torque, friction, load_moment, params) -> dict:
    """:func:`drive_energies`' terms over the samples given (``pitch`` ... from the window's first sample on,
    ``motor`` the motors' delivered energy over it)."""
    dpitch = np.diff(pitch, axis=0)
    ring_work = np.nansum(params.torque_gain * motor_torque[1:] * dpitch, axis=0)
    fric = np.nansum(friction[1:] * np.abs(dpitch), axis=0)
    load = np.nansum(load_moment[1:] * dpitch, axis=0)
    kinetic = 0.5 * params.inertia * (rate[-1] ** 2 - rate[0] ** 2)
    return {"motor": motor, "ring_work": ring_work, "friction": fric, "load_moment": load,
            "drive_kinetic_change": kinetic, "drive_residual": ring_work - fric - load - kinetic}


# ---- the figures -------------------------------------------------------------------------------------

def settle_index(result: TurbineResult, settle: float | None = None) -> int:
    """The first sample of the figures' window: the first at or after ``time[0] + settle`` (None: the run's
    ``result.settle``)."""
    r = result
    settle = resolve_settle(r.settle if settle is None else settle, float(r.time[-1] - r.time[0]))
    return int(np.searchsorted(r.time, r.time[0] + settle - 1e-9 * r.dt))


def window_energies(result: TurbineResult, i0: int) -> dict:
    """:func:`rotor_energies` and the drives' energies (:func:`drive_energies`' keys) over the samples
    ``i0 ...`` (the steps ending after ``time[i0]``); the motors' delivered energy from the cumulative
    ``motor_energy``."""
    r = result
    out = rotor_energies(r.time[i0:], r.rotor_speed[i0:], r.aero_torque[i0:], r.generator_torque[i0:],
                         r.drivetrain)
    if r.drives == "electric":
        motor = (r.motor_energy[-1] - r.motor_energy[i0] if r.motor_energy is not None
                 else np.asarray(r.energies["motor"]))
        w = slice(i0, None)
        out.update(drive_work(motor, r.pitch[w], r.pitch_rate[w], r.motor_torque[w], r.friction_torque[w],
                              r.load_moment[w], r.drive_params))
    return out


def wear_cycles(result: TurbineResult, blade: int, i0: int = 0) -> tuple:
    """The rainflow cycles of a blade's pitch over the samples ``i0 ...`` and each cycle's ``x/2b`` (the
    smallest over the loaded contacts), as :func:`slewing_model.life.analyse_run` takes them: the ring's
    swing (:func:`~slewing_model.life.oscillation.rainflow_cycles`, cycles not above the reversal
    tolerance left out), the rolling travel ``x`` of each contact
    (:func:`~slewing_model.life.wear.rolling_travel`) at its widest patch ``2b`` over the cycle.

    Returns
    -------
    swing (rad), count (1 or 0.5), ratio (x/2b; inf: no contact loaded), counted (bool: not a micro-cycle,
    :data:`slewing_model.life.duty.MICRO_CYCLE_STEPS` of the series' angle resolution)
    """
    from slewing_model.life.duty import DEFAULT_REVERSAL_TOLERANCE, MICRO_CYCLE_STEPS, angle_resolution
    from slewing_model.life.oscillation import rainflow_cycles
    from slewing_model.life.wear import rolling_travel

    r = result
    if r.contact_b is None:
        raise ValueError("x/2b needs the bearings' contact patches: a run with bearings that give their load "
                         "distribution (bearing FMUs do not)")
    psi = -r.pitch[i0:, blade]                       # the ring angle (the blade turns by minus its pitch)
    cyc = rainflow_cycles(psi, min_swing=DEFAULT_REVERSAL_TOLERANCE)
    b, angle = r.contact_b[i0:, blade], r.contact_angle[i0:, blade]
    dm, dw = r.bearing_geometry
    ratio = np.full(cyc.swing.size, np.inf)
    cols = np.arange(4)
    for j, (s, e) in enumerate(zip(cyc.start, cyc.end)):
        bb = b[s:e + 1]
        k = np.argmax(bb, axis=0)
        bmax, a = bb[k, cols], angle[s:e + 1][k, cols]
        loaded = bmax > 0
        if np.any(loaded):
            ratio[j] = float(np.min(rolling_travel(cyc.swing[j], dm, dw, a[loaded]) / (2.0 * bmax[loaded])))
    micro = max(DEFAULT_REVERSAL_TOLERANCE, MICRO_CYCLE_STEPS * angle_resolution(psi))
    return cyc.swing, cyc.count, ratio, cyc.swing >= micro


def wear_shares(result: TurbineResult, blade: int, i0: int = 0) -> dict:
    """A blade's pitch oscillations by their ``x/2b`` (:func:`wear_cycles`), shares of the counted cycles
    (by count, micro-cycles left out; NaN without cycles): ``x/2b < 1`` (part of the patch never uncovered:
    false brinelling, standstill marks) and ``x/2b >= 1`` (the ball rolls off its patch: wear from grease
    starvation is the risk); and the number of counted cycles."""
    swing, count, ratio, counted = wear_cycles(result, blade, i0)
    total = float(count[counted].sum())
    below = float(count[counted & (ratio < 1.0)].sum() / total) if total else math.nan
    return {"cycles": total, "below": below, "above": 1.0 - below if total else math.nan}


def summary(result: TurbineResult, settle: float | None = None) -> dict:
    """The figures of a run (the keys name their units), over the window after the settle time.

    ``settle`` (s, None: the run's ``result.settle``, :attr:`TurbineConfig.settle`) of simulated time is
    left out of every figure: the start-up transient from ``Sim``'s start. The window's energies are those
    of its steps (the motors' delivered energy from the cumulative ``motor_energy``). Whole-run figures:
    the bearing map damage and life (the accumulators run from the start) and the wall time per simulated
    second.

    * pitch tracking error: demand of the last call minus the blades' angle at the next sample, per blade
      (``demand[i-1] - pitch[i]``: what the drive did not reach in the step it had), RMS and largest over
      the blades;
    * motor torque (one motor, mean over each step): peak and RMS over the blades;
    * the motors' energy (all blades) and their **duty**: the share of the time a motor's torque exceeds its
      continuous torque (``continuous_torque_share`` of its peak, see :class:`TurbineConfig`), largest over
      the blades; the RMS torque over the peak torque; and the **actuator duty cycle** (ADC, as in pitch
      control studies): the pitch travel over the travel at the rate limit for the window;
    * rotor speed: standard deviation, and the overspeed: the largest speed above rated (12.1 rpm), %;
    * the bearing friction torque: mean and peak (largest over the blades);
    * with bearings: the share of the pitch oscillations with ``x/2b < 1`` (:func:`wear_shares`), largest
      over the blades;
    * with an emergency stop inside the window: the time from the stop until every blade is within 1 deg
      of feather (NaN: not reached), and the rotor's speed at the stop and at the end;
    * the rotor's energy balance residual over the aero energy.
    """
    r = result
    i0 = settle_index(r, settle)
    d = slice(i0 + 1, None)                  # the window's steps (ending after time[i0])
    out = {"settle time [s]": float(r.time[i0] - r.time[0])}
    error = r.pitch_demand[i0:-1] - r.pitch[i0 + 1:]
    out["pitch tracking error RMS [deg]"] = float(np.degrees(np.sqrt(np.mean(error**2))))
    out["pitch tracking error max [deg]"] = float(np.degrees(np.max(np.abs(error))))
    duration = float(r.time[-1] - r.time[i0])
    energies = window_energies(r, i0)
    travel = np.sum(np.abs(np.diff(r.pitch[i0:], axis=0)), axis=0)
    out["pitch travel [deg]"] = float(np.degrees(np.max(travel)))
    if r.drives == "electric":
        p = r.drive_params
        torque = np.abs(r.motor_torque[d])
        out["motor torque peak [N m]"] = float(torque.max())
        out["motor torque RMS [N m]"] = float(np.sqrt(np.mean(torque**2)))
        out["motor torque RMS / peak limit"] = out["motor torque RMS [N m]"] / p.torque_limit
        out["time above continuous torque [%]"] = float(
            100.0 * np.max(np.mean(torque > r.continuous_torque_share * p.torque_limit, axis=0)))
        out["time at torque limit [%]"] = float(
            100.0 * np.max(np.mean(torque >= (1.0 - 1e-6) * p.torque_limit, axis=0)))
        out["drive energy [kJ]"] = float(np.sum(energies["motor"]) / 1e3)
        out["load moment work [kJ]"] = float(np.sum(energies["load_moment"]) / 1e3)
        out["actuator duty cycle [%]"] = float(100.0 * np.max(travel) / (p.rate_limit * duration))
        out["friction torque mean [kN m]"] = float(np.mean(r.friction_torque[d]) / 1e3)
        out["friction torque peak [kN m]"] = float(np.max(r.friction_torque[d]) / 1e3)
        out["friction energy [kJ]"] = float(np.sum(energies["friction"]) / 1e3)
    if r.contact_b is not None:
        shares = [wear_shares(r, k, i0)["below"] for k in range(3)]
        finite = [x for x in shares if math.isfinite(x)]
        out["x/2b below 1, worst blade [%]"] = 100.0 * max(finite) if finite else math.nan
    rpm = r.rotor_speed[i0:] * 30.0 / math.pi
    out["rotor speed mean [rpm]"] = float(np.mean(rpm))
    out["rotor speed std [rpm]"] = float(np.std(rpm))
    out["overspeed [%]"] = float(max(0.0, 100.0 * (r.rotor_speed[i0:].max() / RATED_ROTOR_SPEED - 1.0)))
    out["electrical energy [kWh]"] = energies["electrical"] / 3.6e6
    out["rotor energy residual / aero energy"] = (energies["rotor_residual"] / energies["aero"]
                                                  if energies["aero"] != 0 else math.nan)
    if r.emergency_stop is not None and r.emergency_stop >= r.time[i0] and r.emergency_stop <= r.time[-1]:
        out.update({f"{k} [{u}]": v for (k, u), v in zip(
            (("time to feather", "s"), ("rotor speed at stop", "rpm"), ("rotor speed at end", "rpm")),
            emergency_stop_figures(r))})
    if r.life is not None:
        damage = [a.worst_damage for a in r.life]
        whole = float(r.time[-1] - r.time[0])
        out["bearing map damage, worst blade"] = float(max(damage))
        out["bearing map life, worst blade [h]"] = (whole / max(damage) / 3600.0 if max(damage) > 0
                                                    else math.inf)
    seconds = r.step_seconds[1:]
    out["seconds per simulated second"] = float(seconds.sum() / float(r.time[-1] - r.time[0]))
    return out


def emergency_stop_figures(result: TurbineResult, within: float = math.radians(1.0)) -> tuple:
    """After the emergency stop: the time (s) until every blade is within ``within`` (rad) of feather and
    stays there (NaN: not reached by the end), and the rotor speed (rpm) at the stop and at the end."""
    r = result
    i_stop = int(np.searchsorted(r.time, r.emergency_stop - 1e-9 * r.dt))
    near = np.all(r.pitch >= FEATHER - within, axis=1)
    later = near[i_stop:]
    if not later[-1]:
        t_feather = math.nan
    else:
        last_off = np.flatnonzero(~later)
        first = int(last_off[-1]) + 1 if last_off.size else 0
        t_feather = float(r.time[i_stop + first] - r.time[i_stop])
    rpm = r.rotor_speed * 30.0 / math.pi
    return t_feather, float(rpm[i_stop]), float(rpm[-1])


def summary_table(results: dict, settle: float | None = None) -> str:
    """Markdown table of :func:`summary` for named results (``{"friction on": r1, "friction off": r2}``)."""
    sums = {name: summary(r, settle) for name, r in results.items()}
    keys = list(dict.fromkeys(k for s in sums.values() for k in s))
    lines = ["| quantity | " + " | ".join(sums) + " |", "|---|" + "---|" * len(sums)]
    for k in keys:
        lines.append(f"| {k} | " + " | ".join(f"{s[k]:.4g}" if k in s else "-" for s in sums.values()) + " |")
    return "\n".join(lines)
