"""Electric pitch and yaw drives: cascaded position and speed PI control, motor, gearbox.

One model serves both: a pitch drive is one motor on the blade's ring gear, a
yaw drive several motors on the tower's ring gear. On the ring (bearing) side::

    (J_ring + motor_count N^2 J_motor) d(omega)/dt
        = motor_count eta N T_motor - T_load - T_friction

* position PI: ``omega_ref = Kp_pos e + Ki_pos int(e)``, limited to the rate limit
  (pitch 2-10 deg/s, yaw 0.3-0.5 deg/s), integrator clamped (anti-windup);
* speed PI with setpoint weight ``b``:
  ``T_ref = Kp_speed (b omega_ref - omega) + Ki_speed int(omega_ref - omega)``,
  limited to the motor's torque limit, integrator clamped; ``b < 1`` keeps the
  ring speed from overshooting the rate limit when the speed reference steps;
* motor torque follows ``T_ref`` with a first-order lag ``tau`` (current loop);
* the bearing friction torque (magnitude from the FMU, held over a
  communication step) acts as Coulomb friction with stick-slip (Karnopp): the
  ring stops when its speed would change sign, and stays stopped while the
  driving torque is below the friction torque. This keeps a 10 ms
  communication step stable where a smoothed ``sign(omega)`` would need a
  regularisation wider than the drive's own speed resolution.

The drive integrates with an inner step (``substeps`` per communication step):
ZOH-exact for the motor lag, exact for constant acceleration on the mechanics.
:func:`linear_model` gives the same loop, without limits and friction, as a
python-control state-space model: its poles and step response are what the
tests check the discrete drive against.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib


#: the drive file's keys: (table, key, DriveParameters attribute, factor to SI, rule, default or None if required)
DRIVE_FILE_KEYS = (
    ("drive", "ring_inertia_kgm2", "ring_inertia", 1.0, "a finite number > 0", None),
    ("drive", "motor_inertia_kgm2", "motor_inertia", 1.0, "a finite number > 0", None),
    ("drive", "motor_count", "motor_count", 1, "a whole number >= 1", 1),
    ("drive", "gear_ratio", "gear_ratio", 1.0, "a finite number > 0", None),
    ("drive", "efficiency", "efficiency", 1.0, "in (0, 1]", None),
    ("drive", "motor_torque_limit_nm", "torque_limit", 1.0, "a finite number > 0", None),
    ("drive", "torque_time_constant_s", "torque_time_constant", 1.0, "a finite number > 0", None),
    ("drive", "rate_limit_deg_s", "rate_limit", math.pi / 180.0, "a finite number > 0", None),
    ("control", "position_gain_per_s", "position_gain", 1.0, "a finite number > 0", None),
    ("control", "position_integral_gain_per_s2", "position_integral_gain", 1.0, "a finite number >= 0", None),
    ("control", "speed_gain_nm_s_per_rad", "speed_gain", 1.0, "a finite number > 0", None),
    ("control", "speed_integral_gain_nm_per_rad", "speed_integral_gain", 1.0, "a finite number >= 0", None),
    ("control", "speed_setpoint_weight", "speed_setpoint_weight", 1.0, "a finite number >= 0", 1.0),
)
_RULES = {"a finite number > 0": lambda v: v > 0, "a finite number >= 0": lambda v: v >= 0,
          "a whole number >= 1": lambda v: v >= 1 and v == int(v), "in (0, 1]": lambda v: 0 < v <= 1}


@dataclass(frozen=True)
class DriveParameters:
    """Electric slewing drive (SI units, angles in rad on the ring side).

    Attributes
    ----------
    ring_inertia : float, kg m^2
        Inertia turned by the bearing (blade about its pitch axis; nacelle and
        rotor about the tower axis).
    motor_inertia : float, kg m^2
        Rotor of one motor (with brake and first gear stage).
    motor_count : int
        Number of motors on the ring gear.
    gear_ratio : float
        Motor turns per ring turn (gearbox times pinion/ring gear).
    efficiency : float
        Gear efficiency, in (0, 1], applied to the motor torque.
    torque_limit : float, N m
        Peak torque of one motor.
    torque_time_constant : float, s
        Current (torque) loop lag.
    rate_limit : float, rad/s
        Ring speed limit.
    position_gain, position_integral_gain : float, 1/s and 1/s^2
        Gains of the position PI: ring speed reference per angle error and per its integral.
    speed_gain : float, N m s/rad
        Motor torque per ring speed error (per motor).
    speed_integral_gain : float, N m/rad
        Motor torque per integral of the ring speed error (per motor).
    speed_setpoint_weight : float
        ``b`` of the speed PI (1: plain PI, default; 0: I-P).
    name : str
        Name of the drive (default ``"drive"``).
    sources : dict
        Where the values come from (the file's ``[sources]`` table); not compared.

    Examples
    --------
    >>> from slewing_drives import DriveParameters
    >>> p = DriveParameters.from_toml("examples/drives/pitch_drive.toml")
    >>> p.inertia > p.ring_inertia          # kg m^2, motors seen through the gear
    True
    """

    ring_inertia: float
    motor_inertia: float
    motor_count: int
    gear_ratio: float
    efficiency: float
    torque_limit: float
    torque_time_constant: float
    rate_limit: float
    position_gain: float
    position_integral_gain: float
    speed_gain: float
    speed_integral_gain: float
    speed_setpoint_weight: float = 1.0
    name: str = "drive"
    sources: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def inertia(self) -> float:
        """Total inertia on the ring side, kg m^2."""
        return self.ring_inertia + self.motor_count * self.gear_ratio**2 * self.motor_inertia

    @property
    def torque_gain(self) -> float:
        """Ring torque per unit motor torque (all motors)."""
        return self.motor_count * self.efficiency * self.gear_ratio

    @classmethod
    def from_toml(cls, path) -> "DriveParameters":
        """Read a drive definition (``examples/drives/*.toml``), units in key names.

        Tables ``[drive]`` (``ring_inertia_kgm2``, ``motor_inertia_kgm2``, ``motor_count``,
        ``gear_ratio``, ``efficiency``, ``motor_torque_limit_nm``, ``torque_time_constant_s``,
        ``rate_limit_deg_s``, ``name``), ``[control]`` (``position_gain_per_s``,
        ``position_integral_gain_per_s2``, ``speed_gain_nm_s_per_rad``,
        ``speed_integral_gain_nm_per_rad``, ``speed_setpoint_weight``) and ``[sources]``.

        Parameters
        ----------
        path : str or path-like
            The TOML file.

        Returns
        -------
        DriveParameters
            SI units (the rate limit converted to rad/s).

        Raises
        ------
        ValueError
            Naming the table, the key, the value and the rule: a required key missing, a value that is not a
            finite number within its rule (gains, inertias and limits > 0, integral gains and the setpoint
            weight >= 0, the efficiency in (0, 1], the motor count a whole number >= 1), or an unknown table
            or key.
        """
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
        unknown = sorted(set(data) - {"drive", "control", "sources"})
        if unknown:
            raise ValueError(f"{path}: unknown table [{unknown[0]}]: the tables are [drive], [control] and [sources]")
        for table in ("drive", "control"):
            known = {key for section, key, *_ in DRIVE_FILE_KEYS if section == table}
            if table == "drive":
                known.add("name")
            unknown = sorted(set(data.get(table, {})) - known)
            if unknown:
                raise ValueError(f"{path}: [{table}] {unknown[0]}: unknown key; [{table}] takes "
                                 + ", ".join(sorted(known)))
        values = {"name": data.get("drive", {}).get("name", "drive"), "sources": data.get("sources", {})}
        for table, key, attribute, to_si, rule, default in DRIVE_FILE_KEYS:
            value = data.get(table, {}).get(key, default)
            if value is None:
                raise ValueError(f"{path}: [{table}] {key} is missing")
            number = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            if not number or not _RULES[rule](value):
                raise ValueError(f"{path}: [{table}] {key} = {value!r}: must be {rule}")
            values[attribute] = int(value) if key == "motor_count" else value * to_si
        return cls(**values)


@dataclass
class DriveState:
    """Continuous and controller states of a drive (ring side).

    Attributes
    ----------
    angle : float
        Ring angle, rad.
    speed : float
        Ring speed, rad/s.
    motor_torque : float
        Torque of one motor, N m.
    mean_motor_torque : float
        Torque of one motor averaged over the last step, N m.
    motor_energy : float
        Mechanical energy delivered by the motors (positive work), J.
    position_integral : float
        Integral of the angle error, rad s.
    speed_integral : float
        Integral of the speed error, rad.
    stuck : bool
        The ring sticks (Karnopp friction).
    """

    angle: float = 0.0          # rad
    speed: float = 0.0          # rad/s
    motor_torque: float = 0.0   # N m, per motor
    mean_motor_torque: float = 0.0  # N m, per motor, averaged over the last step
    motor_energy: float = 0.0   # J, mechanical energy delivered by the motors (positive work)
    position_integral: float = 0.0
    speed_integral: float = 0.0
    stuck: bool = True


class ElectricDrive:
    """Discrete-time drive for a co-simulation loop.

    Parameters
    ----------
    params : DriveParameters
        The drive's parameters.
    substeps : int, optional
        Inner integration steps per call of :meth:`step`. Default 10.

    Attributes
    ----------
    state : DriveState
        The drive's states, changed in place by :meth:`step`.

    Examples
    --------
    A pitch drive commanded 1 degree, stepped for 10 s in communication steps of 10 ms:

    >>> import math
    >>> from slewing_drives import DriveParameters, ElectricDrive
    >>> d = ElectricDrive(DriveParameters.from_toml("examples/drives/pitch_drive.toml"))
    >>> for _ in range(1000):
    ...     _ = d.step(command=math.radians(1.0), dt=0.01, load_torque=0.0, friction_torque=0.0)
    >>> round(math.degrees(d.state.angle), 1)          # deg
    1.0
    """

    def __init__(self, params: DriveParameters, substeps: int = 10):
        self.p = params
        self.substeps = substeps
        self.state = DriveState()

    def hold(self, load_torque: float) -> None:
        """Start at rest holding a load torque.

        As a drive that has been holding its position (brake released with the torque
        applied): motor torque and speed-loop integrator in equilibrium with the load.

        Parameters
        ----------
        load_torque : float
            Load torque on the ring, N m (opposing positive rotation when positive).
        """
        p, s = self.p, self.state
        torque = load_torque / p.torque_gain
        s.motor_torque = s.mean_motor_torque = torque
        s.speed_integral = torque / p.speed_integral_gain if p.speed_integral_gain else 0.0

    def step(self, command: float, dt: float, load_torque: float, friction_torque: float) -> DriveState:
        """Advance by one communication step.

        Parameters
        ----------
        command : float
            Ring angle command, rad.
        dt : float
            Step, s.
        load_torque : float
            External load torque on the ring, N m (opposing positive rotation when
            positive), held over the step.
        friction_torque : float
            Bearing friction torque magnitude, N m (its sign is ignored), held over the step.

        Returns
        -------
        DriveState
            The drive's state at the end of the step (:attr:`state` itself, not a copy).
        """
        p, s = self.p, self.state
        h = dt / self.substeps
        lag = math.exp(-h / p.torque_time_constant)
        friction = abs(friction_torque)
        torque_sum = 0.0
        for _ in range(self.substeps):
            # position loop -> speed reference (rate limited, integrator clamped at the limit)
            error = command - s.angle
            raw = p.position_gain * error + p.position_integral_gain * s.position_integral
            speed_ref = min(max(raw, -p.rate_limit), p.rate_limit)
            if raw == speed_ref or raw * error < 0:
                s.position_integral += error * h
            # speed loop -> torque reference (torque limited, integrator clamped at the limit)
            speed_error = speed_ref - s.speed
            raw_t = (p.speed_gain * (p.speed_setpoint_weight * speed_ref - s.speed)
                     + p.speed_integral_gain * s.speed_integral)
            torque_ref = min(max(raw_t, -p.torque_limit), p.torque_limit)
            if raw_t == torque_ref or raw_t * speed_error < 0:
                s.speed_integral += speed_error * h
            # motor torque: first-order lag, exact for a torque reference held over h
            s.motor_torque = torque_ref + (s.motor_torque - torque_ref) * lag
            angle = s.angle
            self._mechanics(h, p.torque_gain * s.motor_torque - load_torque, friction)
            torque_sum += s.motor_torque
            # motor shaft power = torque x motor speed (N x ring speed); motors count work they deliver
            s.motor_energy += max(p.motor_count * s.motor_torque * p.gear_ratio * (s.angle - angle), 0.0)
        s.mean_motor_torque = torque_sum / self.substeps
        return s

    def _mechanics(self, h: float, drive_torque: float, friction: float) -> None:
        """Ring motion over ``h`` under ``drive_torque`` and Coulomb friction (Karnopp)."""
        s, j = self.state, self.p.inertia
        if s.stuck or s.speed == 0.0:
            if abs(drive_torque) <= friction:
                s.speed, s.stuck = 0.0, True
                return
            s.stuck = False
            direction = math.copysign(1.0, drive_torque)
        else:
            direction = math.copysign(1.0, s.speed)
        acceleration = (drive_torque - direction * friction) / j
        new_speed = s.speed + acceleration * h
        if new_speed * direction < 0.0:  # would reverse within the step: stop where the speed is zero
            t_stop = -s.speed / acceleration
            s.angle += s.speed * t_stop + 0.5 * acceleration * t_stop**2
            s.speed, s.stuck = 0.0, True
            return
        s.angle += s.speed * h + 0.5 * acceleration * h**2
        s.speed = new_speed

    def ring_torque(self) -> float:
        """Torque the motors put on the ring.

        Returns
        -------
        float
            ``motor_count * efficiency * gear_ratio * motor_torque``, N m.
        """
        return self.p.torque_gain * self.state.motor_torque


def linear_model(params: DriveParameters):
    """The closed loop without limits or friction, as a python-control state space.

    States: angle (rad), speed (rad/s), motor torque (N m), position integral (rad s),
    speed integral (rad). Input: angle command (rad); output: angle (rad).

    Parameters
    ----------
    params : DriveParameters
        The drive's parameters.

    Returns
    -------
    control.StateSpace
        Five states, one input, one output; its poles and step response are what the
        tests check the discrete drive against.

    Examples
    --------
    >>> import control
    >>> from slewing_drives import DriveParameters, linear_model
    >>> sys = linear_model(DriveParameters.from_toml("examples/drives/pitch_drive.toml"))
    >>> bool(all(control.poles(sys).real < 0))
    True
    """
    import control

    p = params
    j, g, tau = p.inertia, p.torque_gain, p.torque_time_constant
    kp, ki, kv, kvi = p.position_gain, p.position_integral_gain, p.speed_gain, p.speed_integral_gain
    w = p.speed_setpoint_weight
    # speed_ref = kp (r - x1) + ki x4 ; torque_ref = kv (w speed_ref - x2) + kvi x5
    # x1' = x2 ; x2' = g x3 / j ; x3' = (torque_ref - x3)/tau ; x4' = r - x1 ; x5' = speed_ref - x2
    a = np.array([
        [0, 1, 0, 0, 0],
        [0, 0, g / j, 0, 0],
        [-w * kv * kp / tau, -kv / tau, -1 / tau, w * kv * ki / tau, kvi / tau],
        [-1, 0, 0, 0, 0],
        [-kp, -1, 0, ki, 0],
    ], dtype=float)
    b = np.array([[0], [0], [w * kv * kp / tau], [1], [kp]], dtype=float)
    c = np.array([[1, 0, 0, 0, 0]], dtype=float)
    return control.ss(a, b, c, 0)
