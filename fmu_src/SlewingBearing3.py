"""FMI 3.0 co-simulation slave of a four-point contact slewing bearing (pythonfmu3).

The same inputs, parameters and scalar outputs as the FMI 2.0 slave
(``SlewingBearing.py``; both read their tables from ``bearing_variables.py``),
with the per-ball results as FMI 3.0 arrays instead of 6 B scalars:

* ``contact_load`` [B, 4], N -- contacts 1..4 of each ball;
* ``contact_angle`` [B, 2], rad -- diagonals 1-3 and 2-4;
* ``interference`` [B, 2], m -- diagonals 1-3 and 2-4 (< 0: a gap).

Arrays are serialised row-major (the last index varies fastest), as FMI 3.0
says: ``contact_load[b, c]`` is element ``4 b + c``.

A thin wrapper over :class:`slewing_model.simulation.simulator.BearingSimulator`, holding
no physics. What pythonfmu3 0.3.4 does not do, this slave does itself:

* ``ModelStructure``: pythonfmu3 writes ``Output`` and ``InitialUnknown``
  without ``dependencies``; :meth:`to_xml` adds them (outputs depend on the
  inputs; initial unknowns on the inputs and parameters), and sets the
  CoSimulation capability flags pythonfmu3 copies from the wrong option.
* Array setters: pythonfmu3 registers, for every array variable, a setter
  ``np.reshape(v, newshape=...)``; numpy 2.1 deprecated and numpy 2.4 removed
  the ``newshape`` keyword, so that setter raises ``TypeError`` under numpy 2
  (it would run on a state restore through the default ``_set_fmu_state``).
  The arrays here are registered with their own getter and setter (reshape
  without the keyword), and the FMU state is captured by this slave.
* FMU state: the registered variables, the arrays and the solver's warm start
  (numpy arrays, serialised exactly: :func:`slewing_model.simulation.simulator.encode_state`).
"""
from __future__ import annotations

import json
import os

import numpy as np
from pythonfmu3 import (DefaultExperiment, Dimension, Fmi3Causality, Fmi3Initial, Fmi3Slave, Fmi3Status,
                        Fmi3Variability, Float64, Int32, Unit)

from bearing_variables import (BALL_ARRAYS, COUNT_OUTPUT, INPUTS, INTEGER_PARAMETERS, OUTPUTS, REAL_PARAMETERS,
                               UNITS, build_simulator, choice_description, integer_default, kernels_of,
                               scalar_outputs, step_or_refuse)
from dataclass_code import precompiled

with precompiled():     # the dataclasses' methods as compiled when the FMU was built (dataclass_code.py)
    from slewing_model import Bearing
    from slewing_model.simulation.simulator import BearingSimulator, decode_state, encode_state


class SlewingBearing3(Fmi3Slave):
    """The bearing as an FMI 3.0 co-simulation slave (see the module docstring)."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        resources = self.resources or os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(resources, "bearing.json")) as fh:
            self.bearing = Bearing.from_si_dict(json.load(fh))
        self.superelement_path = os.path.join(resources, "superelement")
        self.kernels = kernels_of(resources)
        self.author = "slewing_model"
        self.description = ("Four-point contact slewing bearing: load distribution (Flexible-BIME) and friction "
                            "torque; per-ball results as arrays")
        self.modelName = "SlewingBearing3"
        self.default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=0.01)
        self.register_units([Unit(name, kg=kg, m=m, s=s, rad=rad) for name, (kg, m, s, rad) in UNITS.items()])
        n = self.bearing.ball_count
        self.time = 0.0
        self.register_variable(Float64("time", causality=Fmi3Causality.independent,
                                       variability=Fmi3Variability.continuous, description="simulation time",
                                       unit="s"))
        for name, unit, text in INPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Float64(name, causality=Fmi3Causality.input, variability=Fmi3Variability.continuous,
                                           description=text, unit=unit, start=0.0), nested=False)
        for name, unit, text, tunable, default in REAL_PARAMETERS:
            setattr(self, name, float(self.bearing.preload if default is None else default))
            self.register_variable(Float64(name, causality=Fmi3Causality.parameter, initial=Fmi3Initial.exact,
                                           variability=Fmi3Variability.tunable if tunable else Fmi3Variability.fixed,
                                           description=text, unit=unit), nested=False)
        for name, choices, text in INTEGER_PARAMETERS:
            setattr(self, name, integer_default(name, self.bearing))
            self.register_variable(Int32(name, causality=Fmi3Causality.parameter, initial=Fmi3Initial.exact,
                                         variability=Fmi3Variability.fixed,
                                         description=choice_description(choices, text)), nested=False)
        for name, unit, text in OUTPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Float64(name, causality=Fmi3Causality.output, variability=Fmi3Variability.continuous,
                                           initial=Fmi3Initial.calculated, description=text, unit=unit), nested=False)
        name, text = COUNT_OUTPUT
        setattr(self, name, 0)
        self.register_variable(Int32(name, causality=Fmi3Causality.output, variability=Fmi3Variability.discrete,
                                     initial=Fmi3Initial.calculated, description=text), nested=False)
        self._arrays = {}
        for name, unit, columns, text, _ in BALL_ARRAYS:
            self._arrays[name] = np.zeros((n, len(columns)))
            self.register_variable(Float64(
                name, causality=Fmi3Causality.output, variability=Fmi3Variability.continuous,
                initial=Fmi3Initial.calculated, description=text, unit=unit,
                dimensions=[Dimension(start=str(n)), Dimension(start=str(len(columns)))],
                getter=lambda name=name: self._arrays[name].ravel().tolist(),
                setter=lambda values, name=name: self._set_array(name, values)), nested=False)
        self.simulator: BearingSimulator | None = None
        self._refused = None  # (time, inputs, tunables) of the last refused step

    def _set_array(self, name, values):
        # pythonfmu3's own setter calls np.reshape(v, newshape=...), which numpy >= 2.4 refuses
        array = self._arrays[name]
        self._arrays[name] = np.asarray(values, dtype=float).reshape(array.shape)

    def to_xml(self, model_options=dict()):
        """pythonfmu3's model description with dependencies in ModelStructure and the capability flags."""
        root = super().to_xml(model_options)
        cosim = root.find("CoSimulation")
        for option in ("canHandleVariableCommunicationStepSize", "canGetAndSetFMUState", "canSerializeFMUState"):
            cosim.set(option, "true")
        cosim.set("needsExecutionTool", "true")
        variables = list(self.vars.values())
        inputs = " ".join(str(v.value_reference) for v in variables if v.causality == Fmi3Causality.input)
        parameters = " ".join(str(v.value_reference) for v in variables if v.causality == Fmi3Causality.parameter)
        structure = root.find("ModelStructure")
        for child in list(structure):
            structure.remove(child)
        outputs = [v for v in variables if v.causality == Fmi3Causality.output]
        for v in outputs:
            structure.append(_element("Output", valueReference=str(v.value_reference), dependencies=inputs))
        for v in outputs:
            structure.append(_element("InitialUnknown", valueReference=str(v.value_reference),
                                      dependencies=f"{inputs} {parameters}"))
        return root

    # ---- life cycle: no exception may leave a slave method (it would reach the host) ----
    def exit_initialization_mode(self):
        if self._build_simulator():
            self._update()

    def _build_simulator(self) -> bool:
        """Create the simulator from the parameters; log why not and return False."""
        return build_simulator(self, Fmi3Status.error)

    # A step is refused as by the FMI 2.0 slave: do_step returns False (fmi3Discard) with the
    # reason logged as Discard, and the state stays the one before the step, so the host may
    # retry the step from its start, with other inputs or after restoring a state; the same step refused twice (same
    # time, inputs and tunable parameters) cannot succeed and is logged as Error.
    def do_step(self, current_time: float, step_size: float) -> bool:
        if self.simulator is None and not self._build_simulator():
            return False
        if not self._update(current_time):
            return False
        self.time = current_time + step_size
        return True

    def _update(self, current_time: float | None = None) -> bool:
        """Solve for the current inputs (:func:`bearing_variables.step_or_refuse`: a refused step
        is logged as Discard and keeps the state; the same step refused twice is an Error)."""
        result = step_or_refuse(self, current_time, Fmi3Status.discard, Fmi3Status.error, Fmi3Status.warning)
        if result is None:
            return False
        for name, value in scalar_outputs(result, self.simulator).items():
            setattr(self, name, value)
        d = result.distribution
        for name, _, columns, _, attribute in BALL_ARRAYS:
            self._arrays[name] = getattr(d, attribute)[:, :len(columns)]
        return True

    # ---- FMU state -------------------------------------------------------------------
    def _get_fmu_state(self):
        state = {v.name: v.getter() for v in self.vars.values() if v.name not in self._arrays}
        state["_arrays"] = dict(self._arrays)  # the arrays are replaced, never changed in place
        state["_simulator"] = None if self.simulator is None else self.simulator.get_state()
        return state

    def _set_fmu_state(self, state):
        state = dict(state)
        self._arrays = {k: np.asarray(v, dtype=float) for k, v in state.pop("_arrays").items()}
        simulator = state.pop("_simulator")
        self._refused = None
        for v in self.vars.values():
            if v.name in state:
                setattr(self, v.name, state[v.name])
        if simulator is not None:
            if self.simulator is None:
                self._build_simulator()
            self.simulator.set_state(simulator)

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        return json.dumps(encode_state(state)).encode("utf-8")

    @staticmethod
    def _fmu_state_from_bytes(state: bytes):
        return decode_state(json.loads(state.decode("utf-8")))


def _element(tag, **attrib):
    from xml.etree.ElementTree import Element

    return Element(tag, attrib)
