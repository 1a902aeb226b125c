"""FMI 2.0 co-simulation slave of a four-point contact slewing bearing (pythonfmu).

A thin wrapper: it maps FMI variables onto :class:`slewing_model.simulation.simulator.BearingSimulator`
and holds no physics. ``build_fmu.py`` packages it with the run-time part of
``slewing_model``, the bearing definition (``bearing.json``), the ring
superelement (the folder ``superelement``) and the compiled methods of
``slewing_model``'s dataclasses (``dataclass_code.py``) in the FMU's resources.

What pythonfmu 0.7.0 does not write, :meth:`SlewingBearing.to_xml` adds:
units and ``UnitDefinitions``, ``ModelStructure/Outputs`` dependencies and
``InitialUnknowns``. The FMU state (``canGetAndSetFMUstate``) holds the
registered variables and the solver's warm start.
"""
from __future__ import annotations

import json
import os
import sys


#: names the Python installation or virtual environment the FMU runs in (documentation: the FMU, hosts)
PYTHON_HOME_VARIABLE = "SLEWING_FMU_PYTHONHOME"


def _python_runtime() -> dict[str, str]:
    """The Python the FMU was built for: ``python_runtime.txt`` beside this module (resources)."""
    runtime = {}
    try:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "python_runtime.txt")) as fh:
            for line in fh:
                key, sep, value = line.strip().partition("=")
                if sep and not key.startswith("#"):
                    runtime[key] = value
    except OSError:
        pass
    return runtime


def _installation(prefix: str) -> str:
    """The installation a prefix belongs to: itself, or for a virtual environment the one in its pyvenv.cfg."""
    try:
        with open(os.path.join(prefix, "pyvenv.cfg")) as fh:
            for line in fh:
                key, sep, value = line.partition("=")
                if sep and key.strip() == "home":
                    home = value.strip()
                    return os.path.dirname(home) if os.path.basename(home) == "bin" else home
    except OSError:
        pass
    return prefix


def _find_numpy() -> None:
    """Make numpy importable or raise ImportError saying what to install where.

    The FMU runs in its host's Python: in a C host the one the FMU's Linux binary loaded
    (``SLEWING_FMU_PYTHONHOME``, else the one named in ``python_runtime.txt``), in a Python
    host the host's own. When numpy is missing and the named environment is a virtual
    environment of this very Python, its site-packages are added to ``sys.path``."""
    try:
        import numpy  # noqa: F401
        return
    except ImportError:
        pass
    runtime = _python_runtime()
    environment = os.environ.get(PYTHON_HOME_VARIABLE) or runtime.get("environment")
    minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
    if environment and os.path.realpath(_installation(environment)) == os.path.realpath(sys.base_prefix):
        import site

        site.addsitedir(os.path.join(environment, "lib", f"python{minor}", "site-packages"))
        try:
            import numpy  # noqa: F401
            return
        except ImportError:
            pass
    built = runtime.get("version", "?")
    raise ImportError(
        f"the slewing bearing FMU needs numpy in the Python that runs it, Python {sys.version.split()[0]} at "
        f"{sys.prefix}: install numpy there ({sys.base_prefix}/bin/python{minor} -m pip install numpy, or the "
        f"system's python3-numpy package), or set {PYTHON_HOME_VARIABLE} to a Python {minor} installation or "
        f"virtual environment that has numpy (this FMU was built with Python {built})") from None


_find_numpy()
import numpy as np

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Initial, Fmi2Status
from pythonfmu.default_experiment import DefaultExperiment

from dataclass_code import precompiled

with precompiled():     # the dataclasses' methods as compiled when the FMU was built (dataclass_code.py)
    from slewing_model import Bearing
    from slewing_model.simulation.simulator import BearingSimulator, decode_state, encode_state

from bearing_variables import (  # the variable tables, shared with the FMI 3.0 slave
    BALL_ARRAYS, COUNT_OUTPUT, INPUTS, INTEGER_PARAMETERS, OUTPUTS, REAL_PARAMETERS,
    UNITS, build_simulator, choice_description, integer_default, kernels_of, scalar_outputs, step_or_refuse)


def _ball_description(array: str, ball: int, column: int, label: str) -> str:
    """Description of the scalar output ``ball[ball].label`` (column ``column`` of ``array``)."""
    if array == "contact_load":
        return f"contact load of ball {ball}, contact {column + 1}"
    if array == "contact_angle":
        return f"loaded contact angle of ball {ball}, diagonal {label[-2]}-{label[-1]}"
    return f"interference of ball {ball}, diagonal {label[-2]}-{label[-1]} (< 0: gap)"


class _BallVariables(dict):
    """pythonfmu's table of the slave's variables (value reference -> variable, ``Fmi2Slave.vars``), whose
    last ``count`` entries, the per-ball outputs, are made by ``make(index)`` (index 0 for the first) when
    first looked up: a host's getReal of one, or :meth:`make_all`."""

    def __init__(self, registered: dict, make, count: int):
        super().__init__(registered)
        self._first, self._make, self._count = len(registered), make, count

    def __missing__(self, vr):
        if not (isinstance(vr, int) and 0 <= vr - self._first < self._count):
            raise KeyError(vr)
        var = self._make(vr - self._first)
        var.value_reference = vr
        self[vr] = var
        return var

    def make_all(self) -> None:
        """Every variable, in the order of their value references (the model description's)."""
        made = [self[vr] for vr in range(self._first + self._count)]
        self.clear()
        self.update((var.value_reference, var) for var in made)


class SlewingBearing(Fmi2Slave):
    author = "slewing_model"
    description = "Four-point contact slewing bearing: load distribution (Flexible-BIME) and friction torque"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        resources = self.resources or os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(resources, "bearing.json")) as fh:
            self.bearing = Bearing.from_si_dict(json.load(fh))
        self.superelement_path = os.path.join(resources, "superelement")
        self.kernels = kernels_of(resources)
        self.default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=0.01)
        self.modelName = "SlewingBearing"
        self._units: dict[str, str] = {}
        n = self.bearing.ball_count

        # inputs
        for name, unit, text in INPUTS:
            setattr(self, name, 0.0)
            self._real(name, unit, text, Fmi2Causality.input, Fmi2Variability.continuous)
        # parameters
        for name, unit, text, tunable, default in REAL_PARAMETERS:
            setattr(self, name, self.bearing.preload if default is None else default)
            self._real(name, unit, text, Fmi2Causality.parameter,
                       Fmi2Variability.tunable if tunable else Fmi2Variability.fixed)
        for name, choices, text in INTEGER_PARAMETERS:
            setattr(self, name, integer_default(name, self.bearing))
            self.register_variable(Integer(name, causality=Fmi2Causality.parameter,
                                           variability=Fmi2Variability.fixed, initial=Fmi2Initial.exact,
                                           description=choice_description(choices, text)), nested=False)
        # outputs
        for name, unit, text in OUTPUTS:
            setattr(self, name, 0.0)
            self._real(name, unit, text, Fmi2Causality.output, Fmi2Variability.continuous)
        self.balls_in_four_point_contact = 0
        self.register_variable(Integer(COUNT_OUTPUT[0], causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete, initial=Fmi2Initial.calculated,
                                       description=COUNT_OUTPUT[1]), nested=False)
        # per-ball outputs: the result's arrays themselves (replaced each step, never changed in
        # place), read one value at a time by the host's getReal. Their variables (8 a ball: 1200 for
        # 150 balls, about 10 ms to make) follow the others' value references, ball by ball, and are
        # made when first asked for (_BallVariables); the model description (to_xml) makes them all
        self._arrays = {name: np.zeros((n, len(columns))) for name, _, columns, _, _ in BALL_ARRAYS}
        self._ball_columns = [(name, unit, c, label) for name, unit, columns, _, _ in BALL_ARRAYS
                              for c, label in enumerate(columns)]
        self.vars = _BallVariables(self.vars, self._ball_variable, n * len(self._ball_columns))
        self.simulator: BearingSimulator | None = None
        self._refused = None  # (time, inputs, tunables) of the last refused step

    # ---- variables ------------------------------------------------------------------
    def _real(self, name, unit, description, causality, variability, getter=None):
        self.register_variable(self._real_variable(name, unit, description, causality, variability, getter),
                               nested=False)

    def _real_variable(self, name, unit, description, causality, variability, getter=None) -> Real:
        initial = None
        if causality == Fmi2Causality.parameter:
            initial = Fmi2Initial.exact
        elif causality == Fmi2Causality.output:
            initial = Fmi2Initial.calculated
        self._units[name] = unit
        return Real(name, causality=causality, variability=variability, initial=initial,
                    description=description, getter=getter)

    def _ball_variable(self, index: int) -> Real:
        """The per-ball output ``index`` (0 for ball 1's first column): ``ball[i].label``, what
        register_variable would have made of it (a getter, no setter)."""
        ball, column = divmod(index, len(self._ball_columns))
        name, unit, c, label = self._ball_columns[column]
        return self._real_variable(f"ball[{ball + 1}].{label}", unit, _ball_description(name, ball + 1, c, label),
                                   Fmi2Causality.output, Fmi2Variability.continuous,
                                   getter=lambda: float(self._arrays[name][ball, c]))

    def to_xml(self, model_options=dict()) -> Element:
        """pythonfmu's model description plus units, dependencies and initial unknowns."""
        from xml.etree.ElementTree import Element, SubElement     # the build's: an instance never needs xml

        self.vars.make_all()
        root = super().to_xml(model_options)
        definitions = Element("UnitDefinitions")
        for name, (kg, m, s, rad) in UNITS.items():
            unit = SubElement(definitions, "Unit", name=name)
            exponents = {k: str(v) for k, v in (("kg", kg), ("m", m), ("s", s), ("rad", rad)) if v}
            SubElement(unit, "BaseUnit", exponents)
        children = list(root)
        root.insert(children.index(root.find("CoSimulation")) + 1, definitions)
        index = {}
        for i, sv in enumerate(root.find("ModelVariables"), start=1):
            index[sv.get("name")] = i
            real = sv.find("Real")
            if real is not None and sv.get("name") in self._units:
                real.set("unit", self._units[sv.get("name")])
        inputs = " ".join(str(index[name]) for name, _, _ in INPUTS)
        parameters = " ".join(str(index[v.name]) for v in self.vars.values() if v.causality == Fmi2Causality.parameter)
        structure = root.find("ModelStructure")
        for child in list(structure):
            structure.remove(child)
        outputs = SubElement(structure, "Outputs")
        initial = SubElement(structure, "InitialUnknowns")
        for v in self.vars.values():
            if v.causality == Fmi2Causality.output:
                SubElement(outputs, "Unknown", index=str(index[v.name]), dependencies=inputs)
                SubElement(initial, "Unknown", index=str(index[v.name]), dependencies=f"{inputs} {parameters}")
        return root

    # ---- life cycle -----------------------------------------------------------------
    # No exception may leave a slave method: an exception that reaches pythonfmu's C++
    # layer leaves a C host's Python state broken (seen with ecos). Errors are logged
    # and reported through the status of do_step instead.
    def exit_initialization_mode(self):
        if self._build_simulator():
            self._update()

    def _build_simulator(self) -> bool:
        """Create the simulator from the parameters; log why not and return False."""
        return build_simulator(self, Fmi2Status.error)

    # A step is refused (do_step returns False) with the reason logged as Discard: pythonfmu
    # then returns fmi2Discard, and the FMU's Linux binary (fmu_src/shim) reports
    # fmi2Terminated = false. The state stays the one before the step (FMI 2.0, 4.2.3:
    # the master retries the step from its start, with other inputs or after restoring a state). What leaves
    # the instance unable to continue is logged as Error, and the binary returns fmi2Error.
    def do_step(self, current_time: float, step_size: float) -> bool:
        if self.simulator is None and not self._build_simulator():
            return False
        return self._update(current_time)

    def _update(self, current_time: float | None = None) -> bool:
        """Solve for the current inputs (:func:`bearing_variables.step_or_refuse`: a refused step
        is logged as Discard and keeps the state; the same step refused twice is an Error)."""
        result = step_or_refuse(self, current_time, Fmi2Status.discard, Fmi2Status.error, Fmi2Status.warning)
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
        state = {v.name: v.getter() for v in self.vars.values() if not v.name.startswith("ball[")}
        state["_arrays"] = dict(self._arrays)  # the arrays are replaced, never changed in place
        state["_simulator"] = None if self.simulator is None else self.simulator.get_state()
        return state

    def _set_fmu_state(self, state):
        state = dict(state)
        self._arrays = {k: np.asarray(v, dtype=float) for k, v in state.pop("_arrays").items()}
        simulator = state.pop("_simulator")
        self._refused = None
        for v in self.vars.values():
            if v.name in state and v.setter is not None:
                v.setter(state[v.name])
            elif v.name in state:
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
