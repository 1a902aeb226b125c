"""FMI 2.0 co-simulation slave of an electric slewing drive (pitch or yaw), pythonfmu.

A thin wrapper over :class:`slewing_drives.drive.ElectricDrive`: the same
discrete model (cascaded position and speed PI, torque lag, gear, ring
inertia) and the same Coulomb friction with stick-slip, stepped once per
communication step with the inputs held over it. ``fmu_build/drive.py``
packages it with ``slewing_drives/drive.py`` and the drive definition
(``drive.json``, SI units) in the FMU's resources; the definition's values
are the start values of the FMU's parameters.

Inputs: the angle command, the bearing's friction torque (its magnitude is
used, as by :meth:`ElectricDrive.step`) and the load moment on the ring.
Outputs: the ring's angle ``psi`` and speed ``omega`` (the bearing FMU's
inputs of the same names), the motor torque (one motor, mean over the step,
as :func:`slewing_drives.cosimulation.run_manoeuvre` records it), the motor
current (that torque over the torque constant) and the ring torque of all
motors.

Start: the drive starts at rest, holding the load moment it gets at its
first step (motor torque and speed integrator in equilibrium with it), as
``run_manoeuvre`` does with the series' first load moment
(:meth:`ElectricDrive.hold`).

Refused steps: an input that is not finite (NaN or infinite) refuses the step,
as the bearing FMU does: the reason (the input and the rule) is logged as
Discard, the step returns fmi2Discard and the state stays the one before the
step, so the master may retry the step from its start with other inputs or
restore a state. The same step refused again with the same inputs (a master
that retries unchanged) is an Error: it cannot succeed.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Initial, Fmi2Status

from slewing_drives.drive import DriveParameters, DriveState, ElectricDrive

UNITS = {"N.m": (1, 2, -2, 0, 0), "rad": (0, 0, 0, 1, 0), "rad/s": (0, 0, -1, 1, 0), "kg.m2": (1, 2, 0, 0, 0),
         "1/s": (0, 0, -1, 0, 0), "1/s2": (0, 0, -2, 0, 0), "N.m.s/rad": (1, 2, -1, -1, 0),
         "N.m/rad": (1, 2, -2, -1, 0), "s": (0, 0, 1, 0, 0), "A": (0, 0, 0, 0, 1), "N.m/A": (1, 2, -2, 0, -1),
         "1": (0, 0, 0, 0, 0)}  # exponents of kg, m, s, rad, A

INPUTS = [  # name, unit, description
    ("command", "rad", "angle command of the ring"),
    ("friction_torque", "N.m", "bearing friction torque (its magnitude is applied as Coulomb friction, stick-slip)"),
    ("load_moment", "N.m", "external moment on the ring about its axis, opposing positive rotation when positive"),
]

OUTPUTS = [
    ("psi", "rad", "angle of the ring"),
    ("omega", "rad/s", "speed of the ring"),
    ("motor_torque", "N.m", "torque of one motor, mean over the last step"),
    ("motor_current", "A", "torque-producing current of one motor: motor_torque / torque_constant"),
    ("ring_torque", "N.m", "torque of all motors at the ring, mean over the last step"),
]

#: DriveParameters fields as real parameters: name, unit, description
PARAMETERS = [
    ("ring_inertia", "kg.m2", "inertia turned by the bearing"),
    ("motor_inertia", "kg.m2", "inertia of one motor (rotor, brake, first gear stage)"),
    ("gear_ratio", "1", "motor turns per ring turn"),
    ("efficiency", "1", "gear efficiency, in (0, 1]"),
    ("torque_limit", "N.m", "peak torque of one motor"),
    ("torque_time_constant", "s", "lag of the torque (current) loop"),
    ("rate_limit", "rad/s", "ring speed limit"),
    ("position_gain", "1/s", "position loop gain"),
    ("position_integral_gain", "1/s2", "position loop integral gain"),
    ("speed_gain", "N.m.s/rad", "motor torque per ring speed error"),
    ("speed_integral_gain", "N.m/rad", "speed loop integral gain"),
    ("speed_setpoint_weight", "1", "setpoint weight b of the speed PI (1: PI, 0: I-P)"),
]


class SlewingDrive(Fmi2Slave):
    author = "slewing_drives"
    description = "Electric slewing drive (pitch or yaw): cascaded PI control, motor lag, gear, Coulomb friction"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        resources = self.resources or os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(resources, "drive.json")) as fh:
            definition = json.load(fh)
        self.drive_name = definition.pop("name", "drive")
        self.description = f"{self.description}: {self.drive_name}"
        self.modelName = "SlewingDrive"
        self.default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=0.01)
        self._units: dict[str, str] = {}
        for name, unit, text in INPUTS:
            setattr(self, name, 0.0)
            self._real(name, unit, text, Fmi2Causality.input, Fmi2Variability.continuous)
        for name, unit, text in PARAMETERS:
            setattr(self, name, float(definition[name]))
            self._real(name, unit, text, Fmi2Causality.parameter, Fmi2Variability.fixed)
        self.torque_constant = float(definition.get("torque_constant", 1.5))
        self._real("torque_constant", "N.m/A", "motor torque per ampere (for motor_current)",
                   Fmi2Causality.parameter, Fmi2Variability.tunable)
        self.motor_count = int(definition["motor_count"])
        self.substeps = 10
        for name, text in (("motor_count", "motors on the ring gear"),
                           ("substeps", "inner integration steps per communication step")):
            self.register_variable(Integer(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                                           initial=Fmi2Initial.exact, description=text), nested=False)
        for name, unit, text in OUTPUTS:
            setattr(self, name, 0.0)
            self._real(name, unit, text, Fmi2Causality.output, Fmi2Variability.continuous)
        self.drive: ElectricDrive | None = None
        self._started = False
        self._refused = None  # (time, inputs) of the last refused step

    def _real(self, name, unit, description, causality, variability):
        initial = {Fmi2Causality.parameter: Fmi2Initial.exact, Fmi2Causality.output: Fmi2Initial.calculated}
        self._units[name] = unit
        self.register_variable(Real(name, causality=causality, variability=variability,
                                    initial=initial.get(causality), description=description), nested=False)

    def to_xml(self, model_options=dict()) -> Element:
        """pythonfmu's model description plus units, dependencies and initial unknowns."""
        root = super().to_xml(model_options)
        definitions = Element("UnitDefinitions")
        for name, exponents in UNITS.items():
            unit = SubElement(definitions, "Unit", name=name)
            SubElement(unit, "BaseUnit", {k: str(v) for k, v in zip(("kg", "m", "s", "rad", "A"), exponents) if v})
        root.insert(list(root).index(root.find("CoSimulation")) + 1, definitions)
        index = {}
        for i, sv in enumerate(root.find("ModelVariables"), start=1):
            index[sv.get("name")] = i
            if sv.find("Real") is not None and sv.get("name") in self._units:
                sv.find("Real").set("unit", self._units[sv.get("name")])
        parameters = " ".join(str(index[v.name]) for v in self.vars.values() if v.causality == Fmi2Causality.parameter)
        structure = root.find("ModelStructure")
        for child in list(structure):
            structure.remove(child)
        outputs, initial = SubElement(structure, "Outputs"), SubElement(structure, "InitialUnknowns")
        for name, _, _ in OUTPUTS:
            # the outputs are states of the drive: no direct feedthrough from the inputs
            SubElement(outputs, "Unknown", index=str(index[name]), dependencies="")
            SubElement(initial, "Unknown", index=str(index[name]), dependencies=parameters)
        return root

    # ---- life cycle: no exception may leave a slave method (it would reach the host) ----
    def exit_initialization_mode(self):
        self._build()

    def _build(self) -> bool:
        """The drive from the parameters; log why not (naming the parameter) and return False."""
        self.drive = None
        try:
            values = {name: float(getattr(self, name)) for name, _, _ in PARAMETERS}
            values["motor_count"] = int(self.motor_count)
            for key, value in values.items():
                if not math.isfinite(value) or value < 0 or (value == 0 and key not in (
                        "position_integral_gain", "speed_integral_gain", "speed_setpoint_weight")):
                    raise ValueError(f"parameter {key} = {value!r}: must be a finite number > 0")
            if not 0 < values["efficiency"] <= 1:
                raise ValueError(f"parameter efficiency = {values['efficiency']!r}: must lie in (0, 1]")
            if int(self.substeps) < 1:
                raise ValueError(f"parameter substeps = {self.substeps}: must be at least 1")
            self.drive = ElectricDrive(DriveParameters(name=self.drive_name, **values), substeps=int(self.substeps))
            self._started = False
            return True
        except ValueError as exc:
            self.log(f"{self.instance_name}: {exc}", Fmi2Status.error)
        except Exception:
            self._log_internal_error()
        return False

    def _log_internal_error(self) -> None:
        """Log the exception being handled, with its traceback, as an error (never raised to the host)."""
        import traceback                    # only when there is one: not at every instantiation

        self.log(f"{self.instance_name}: internal error:\n{traceback.format_exc()}", Fmi2Status.error)

    def do_step(self, current_time: float, step_size: float) -> bool:
        if self.drive is None and not self._build():
            return False
        inputs = [getattr(self, name) for name, _, _ in INPUTS]
        bad = next(((name, value) for (name, _, _), value in zip(INPUTS, inputs) if not math.isfinite(value)), None)
        if bad is not None:  # refused before the drive moves: the state is the one before the step
            reason = f"input {bad[0]} = {bad[1]!r}: must be finite (not NaN or infinite)"
            key = repr((current_time, inputs))  # repr: NaN equals NaN
            if key == self._refused:
                self.log(f"{self.instance_name}: step at t = {current_time} refused again with the same inputs, "
                         f"so it cannot succeed (change an input, or stop): {reason}", Fmi2Status.error)
            else:
                self.log(f"{self.instance_name}: step refused, state kept: {reason}", Fmi2Status.discard)
            self._refused = key
            return False
        self._refused = None
        try:
            if not self._started:  # at rest, holding the load moment of the first step
                self.drive.hold(self.load_moment)
                self._started = True
            s = self.drive.step(self.command, step_size, load_torque=self.load_moment,
                                friction_torque=self.friction_torque)
        except ValueError as exc:
            self.log(f"{self.instance_name}: step refused: {exc}", Fmi2Status.error)
            return False
        except Exception:
            self._log_internal_error()
            return False
        p = self.drive.p
        self.psi, self.omega = s.angle, s.speed
        self.motor_torque = s.mean_motor_torque
        self.motor_current = s.mean_motor_torque / self.torque_constant
        self.ring_torque = p.torque_gain * s.mean_motor_torque
        return True

    # ---- FMU state: the registered variables and the drive's own state ----
    def _get_fmu_state(self):
        state = {v.name: v.getter() for v in self.vars.values()}
        state["_drive"] = None if self.drive is None else dataclasses.asdict(self.drive.state)
        state["_started"] = self._started
        return state

    def _set_fmu_state(self, state):
        state = dict(state)
        drive, started = state.pop("_drive"), state.pop("_started")
        self._refused = None
        for v in self.vars.values():
            if v.name in state:
                setattr(self, v.name, state[v.name])
        if drive is not None:
            if self.drive is None:
                self._build()
            self.drive.state = DriveState(**drive)
        self._started = started
