"""The FMI co-simulation state machine as a table, and the scripts of calls the misuse tests
(tests/test_fmi_misuse.py) generate from it.

The table: for each FMI function, the states in which the standard allows it (FMI 2.0 section 4.2.4,
the co-simulation state machine; FMI 3.0 co-simulation with eventModeUsed = false), and for each state
the legal calls that reach it from a fresh instance. Every (state, function not allowed there) pair is a
case; so are the argument and variable cases (:data:`VARIABLE_CASES`), generated for the states where
their function is allowed.

A script is a list of lines, one FMI call each: the function's name, then its arguments
(``fmi2DoStep 0.02 0.01``; ``fmi2SetReal VR VALUE [VR VALUE ...]``; ``fmi2GetReal NVALUES VR ...``;
``fmi2GetFMUstate SLOT``; ``fmi2SerializeFMUstate SLOT FILE``; ``fmi2DeSerializeFMUstate FILE SLOT CUT``,
CUT bytes removed from the file's end; ``@ TEXT`` a label). Two runners execute it and print the same
lines: our C host (tests/c_host/misuse.c) and fmpy's low-level API (:func:`run_fmpy`, this file run as
a program)::

    call <index> <function> <status> [values]    one per script line, after the call's log lines
    log <status> <category> <message>            the FMU's log, each message on one line
    mark <text>                                  a label
"""
from __future__ import annotations

import dataclasses
import math
import sys

# ---- the states ---------------------------------------------------------------------------------------
#: FMI 2.0 co-simulation states the tests reach (StepInProgress, StepCanceled: asynchronous steps only;
#: Error and Fatal: after a real failure of the model)
FMI2_STATES = ("Instantiated", "InitializationMode", "StepComplete", "StepFailed", "Terminated")
#: FMI 3.0 co-simulation states the tests reach (eventModeUsed = false: no Event Mode; the FMU has no
#: structural parameters to configure)
FMI3_STATES = ("Instantiated", "InitializationMode", "StepMode", "Terminated")

_ANY2 = frozenset(FMI2_STATES) | {"StepCanceled", "Error"}
_GET2 = frozenset({"InitializationMode", "StepComplete", "StepFailed", "StepCanceled", "Terminated", "Error"})
_SET2 = frozenset({"Instantiated", "InitializationMode", "StepComplete"})
_STATUS2 = frozenset({"StepComplete", "StepInProgress", "StepFailed", "Terminated"})

#: FMI 2.0: function -> states where the standard allows it (section 4.2.4, the table of the
#: co-simulation state machine, as the Reference FMUs' masks in src/fmi2Functions.c)
FMI2_ALLOWED = {
    "fmi2SetDebugLogging": _ANY2,
    "fmi2SetupExperiment": frozenset({"Instantiated"}),
    "fmi2EnterInitializationMode": frozenset({"Instantiated"}),
    "fmi2ExitInitializationMode": frozenset({"InitializationMode"}),
    "fmi2Terminate": frozenset({"StepComplete", "StepFailed"}),
    "fmi2Reset": _ANY2,
    "fmi2GetReal": _GET2,
    "fmi2GetInteger": _GET2,
    "fmi2SetReal": _SET2,
    "fmi2SetInteger": _SET2,
    "fmi2GetFMUstate": _ANY2,
    "fmi2SetFMUstate": _ANY2,
    "fmi2FreeFMUstate": _ANY2,
    "fmi2SerializedFMUstateSize": _ANY2,
    "fmi2SerializeFMUstate": _ANY2,
    "fmi2DeSerializeFMUstate": _ANY2,
    "fmi2DoStep": frozenset({"StepComplete"}),
    "fmi2CancelStep": frozenset({"StepInProgress"}),
    "fmi2GetStatus": _STATUS2,
    "fmi2GetRealStatus": _STATUS2,
    "fmi2GetBooleanStatus": _STATUS2,
    "fmi2GetStringStatus": _STATUS2,
}

#: What this FMU allows beyond the standard, on purpose: after a refused step (fmi2Discard, StepFailed) its
#: state is the one before the step, and the master may set other inputs and step again from the start
#: of the refused step (fmu_src/shim/fmi2_shim.c, "Status"; tests/test_fmu_hosts.py, the NaN step)
FMI2_EXTENSIONS = {
    "fmi2DoStep": frozenset({"StepFailed"}),
    "fmi2SetReal": frozenset({"StepFailed"}),
    "fmi2SetInteger": frozenset({"StepFailed"}),
}

_ANY3 = frozenset(FMI3_STATES) | {"EventMode", "ConfigurationMode", "ReconfigurationMode"}

#: FMI 3.0 co-simulation: function -> states where the standard allows it (the co-simulation state machine,
#: as the Reference FMUs' masks in src/fmi3Functions.c, but the setters, which FMI 3.0 does not allow in
#: Terminated). Where a reading is open, the function is left allowed, so that no case rests on it:
#: fmi3EnterStepMode in InitializationMode (with eventModeUsed = false fmi3ExitInitializationMode leads to
#: StepMode itself), fmi3EnterConfigurationMode in Instantiated and StepMode (the FMU has no structural
#: parameter to configure).
FMI3_ALLOWED = {
    "fmi3SetDebugLogging": _ANY3,
    "fmi3EnterInitializationMode": frozenset({"Instantiated"}),
    "fmi3ExitInitializationMode": frozenset({"InitializationMode"}),
    "fmi3EnterStepMode": frozenset({"InitializationMode", "EventMode"}),
    "fmi3EnterEventMode": frozenset({"StepMode", "EventMode"}),
    "fmi3EnterConfigurationMode": frozenset({"Instantiated", "StepMode", "EventMode"}),
    "fmi3ExitConfigurationMode": frozenset({"ConfigurationMode", "ReconfigurationMode"}),
    "fmi3UpdateDiscreteStates": frozenset({"EventMode"}),
    "fmi3Terminate": frozenset({"StepMode", "EventMode"}),
    "fmi3Reset": _ANY3,
    "fmi3GetFloat64": frozenset({"Instantiated", "InitializationMode", "StepMode", "EventMode",
                                 "ConfigurationMode", "Terminated"}),
    "fmi3GetInt32": frozenset({"Instantiated", "InitializationMode", "StepMode", "EventMode",
                               "ConfigurationMode", "Terminated"}),
    "fmi3SetFloat64": frozenset({"Instantiated", "InitializationMode", "StepMode", "EventMode", "ConfigurationMode"}),
    "fmi3SetInt32": frozenset({"Instantiated", "InitializationMode", "StepMode", "EventMode", "ConfigurationMode"}),
    "fmi3GetFMUState": _ANY3,
    "fmi3SetFMUState": _ANY3,
    "fmi3FreeFMUState": _ANY3,
    "fmi3SerializedFMUStateSize": _ANY3,
    "fmi3SerializeFMUState": _ANY3,
    "fmi3DeserializeFMUState": _ANY3,
    "fmi3DoStep": frozenset({"StepMode"}),
}
FMI3_EXTENSIONS: dict = {}

#: the variable type a function needs a variable of (the case is left out for an FMU without one)
NEEDS_TYPE = {"fmi2GetReal": "Real", "fmi2SetReal": "Real", "fmi2GetInteger": "Integer", "fmi2SetInteger": "Integer",
              "fmi3GetFloat64": "Float64", "fmi3SetFloat64": "Float64", "fmi3GetInt32": "Int32",
              "fmi3SetInt32": "Int32"}
#: functions that change the state when (wrongly) accepted: called last among a state's refused calls
TRANSITIONS = ("fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate",
               "fmi2Reset", "fmi3EnterInitializationMode", "fmi3ExitInitializationMode", "fmi3EnterStepMode",
               "fmi3EnterEventMode", "fmi3EnterConfigurationMode", "fmi3ExitConfigurationMode",
               "fmi3UpdateDiscreteStates", "fmi3Terminate")


def allowed(version: int, function: str, state: str) -> bool:
    """Whether ``function`` may be called in ``state`` (the standard's table and this FMU's extensions)."""
    table, extra = (FMI2_ALLOWED, FMI2_EXTENSIONS) if version == 2 else (FMI3_ALLOWED, FMI3_EXTENSIONS)
    return state in table[function] or state in extra.get(function, ())


# ---- the FMU under test ----------------------------------------------------------------------------------
@dataclasses.dataclass
class Fmu:
    """What the scripts need of an FMU, read from its modelDescription: value references by name, types,
    causalities, the legal run's inputs."""

    key: str
    path: str
    version: int
    guid: str
    model_identifier: str
    variables: dict          # name -> (value reference, type, causality, variability, number of values)
    inputs: list             # names of the inputs the legal run sets
    input_values: object     # k -> values of those inputs before step k
    step: float              # the legal run's step
    nan_input: str | None    # an input whose NaN the FMU refuses with Discard (reaches StepFailed)

    @classmethod
    def read(cls, key, path, inputs=(), input_values=lambda k: [], step=0.01, nan_input=None):
        from fmpy import read_model_description

        md = read_model_description(str(path))
        variables = {}
        for v in md.modelVariables:
            count = math.prod(int(d.start) for d in getattr(v, "dimensions", None) or [])
            variables[v.name] = (v.valueReference, v.type, v.causality, v.variability, count)
        return cls(key, str(path), 2 if md.fmiVersion.startswith("2") else 3, md.guid,
                   md.coSimulation.modelIdentifier, variables, list(inputs), input_values, step, nan_input)

    @property
    def real(self):
        return "Real" if self.version == 2 else "Float64"

    @property
    def instantiate(self):
        return "fmi2Instantiate" if self.version == 2 else "fmi3InstantiateCoSimulation"

    def fn(self, name: str) -> str:
        """FMI function ``name`` of this FMU's version: fn("DoStep") -> fmi2DoStep or fmi3DoStep."""
        return f"fmi{self.version}{name}"

    def of(self, causality=None, type_=None, variability=None):
        return [name for name, (_, t, c, var, _) in self.variables.items()
                if (causality is None or c == causality) and (type_ is None or t == type_)
                and (variability is None or var == variability)]

    def vr(self, name):
        return self.variables[name][0]

    @property
    def outputs(self):
        """The Real (Float64) outputs."""
        return self.of("output", self.real)

    @property
    def unknown_vr(self):
        used = {v[0] for v in self.variables.values()}
        return 999 if 999 not in used else max(used) + 1000

    def get_outputs(self) -> list[str]:
        """The getters of all the outputs (Real, then Integer where the FMU has some): compared bit for bit."""
        lines = []
        for type_, getter in ((self.real, "GetReal" if self.version == 2 else "GetFloat64"),
                              ("Integer" if self.version == 2 else "Int32",
                               "GetInteger" if self.version == 2 else "GetInt32")):
            names = self.of("output", type_)
            if names:
                lines.append(f"{self.fn(getter)} {sum(self.variables[n][4] for n in names)} "
                             + " ".join(str(self.vr(n)) for n in names))
        return lines

    def set_inputs(self, k: int, nan: bool = False) -> list[str]:
        if not self.inputs:
            return []
        values = list(self.input_values(k))
        if nan:
            values[self.inputs.index(self.nan_input)] = math.nan
        pairs = " ".join(f"{self.vr(n)} {v!r}" for n, v in zip(self.inputs, values))
        return [f"{self.fn('SetReal' if self.version == 2 else 'SetFloat64')} {pairs}"]

    def states(self):
        states = FMI2_STATES if self.version == 2 else FMI3_STATES
        return [s for s in states if s != "StepFailed" or self.nan_input]


#: steps of the legal run; the states after initialisation are reached after STEPS_BEFORE of them
STEPS = 4
STEPS_BEFORE = 2


def _initialise(fmu: Fmu) -> list[str]:
    if fmu.version == 2:
        return ["fmi2SetupExperiment 0.0", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode"]
    return ["fmi3EnterInitializationMode 0.0", "fmi3ExitInitializationMode"]


def _steps(fmu: Fmu, ks) -> list[str]:
    lines = []
    for k in ks:
        lines += fmu.set_inputs(k)
        lines += [f"{fmu.fn('DoStep')} {k * fmu.step!r} {fmu.step!r}"] + fmu.get_outputs()
    return lines


#: the legal call sequence that reaches each state from a fresh instance: FMI functions (with the arguments
#: of :func:`reach`), "steps" (STEPS_BEFORE steps of the legal run: set the inputs, step, get the outputs) and
#: "refused step" (a NaN input, then a step the FMU refuses with Discard)
FMI2_REACH = {
    "Instantiated": ("fmi2Instantiate",),
    "InitializationMode": ("fmi2Instantiate", "fmi2SetupExperiment", "fmi2EnterInitializationMode"),
    "StepComplete": ("fmi2Instantiate", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
                     "fmi2ExitInitializationMode", "steps"),
    "StepFailed": ("fmi2Instantiate", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
                   "fmi2ExitInitializationMode", "steps", "refused step"),
    "Terminated": ("fmi2Instantiate", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
                   "fmi2ExitInitializationMode", "steps", "fmi2Terminate"),
}
FMI3_REACH = {
    "Instantiated": ("fmi3InstantiateCoSimulation",),
    "InitializationMode": ("fmi3InstantiateCoSimulation", "fmi3EnterInitializationMode"),
    "StepMode": ("fmi3InstantiateCoSimulation", "fmi3EnterInitializationMode", "fmi3ExitInitializationMode",
                 "steps"),
    "Terminated": ("fmi3InstantiateCoSimulation", "fmi3EnterInitializationMode", "fmi3ExitInitializationMode",
                   "steps", "fmi3Terminate"),
}


def reach(fmu: Fmu, state: str, name: str) -> list[str]:
    """The script lines of the legal calls that bring a fresh instance (named ``name``) to ``state``."""
    lines = []
    for step in (FMI2_REACH if fmu.version == 2 else FMI3_REACH)[state]:
        if step == "steps":
            lines += _steps(fmu, range(STEPS_BEFORE))
        elif step == "refused step":
            lines += fmu.set_inputs(STEPS_BEFORE, nan=True) + [
                f"{fmu.fn('DoStep')} {STEPS_BEFORE * fmu.step!r} {fmu.step!r}"]
        elif step == fmu.instantiate:
            lines.append(f"{step} {name}")
        elif step.endswith(("SetupExperiment", "EnterInitializationMode")) and (
                fmu.version == 3 or step.endswith("SetupExperiment")):
            lines.append(f"{step} 0.0")
        else:
            lines.append(step)
    return lines


def complete(fmu: Fmu, state: str) -> list[str]:
    """The legal run that follows the refused calls; its outputs equal a fresh instance's (:func:`fresh`)."""
    if state == "Instantiated":
        return _initialise(fmu) + _steps(fmu, range(STEPS))
    if state == "InitializationMode":
        return _initialise(fmu)[-1:] + _steps(fmu, range(STEPS))
    if state == "Terminated":  # what is left: the outputs (unchanged), and the end
        return fmu.get_outputs()
    return fmu.get_outputs() + _steps(fmu, range(STEPS_BEFORE, STEPS))


def fresh(fmu: Fmu, state_file: str) -> list[str]:
    """A fresh instance's legal run; its state at the end serialized into ``state_file``."""
    return ([f"{fmu.instantiate} fresh"] + _initialise(fmu) + _steps(fmu, range(STEPS))
            + [f"{fmu.fn('GetFMUstate' if fmu.version == 2 else 'GetFMUState')} 0",
               f"{fmu.fn('SerializeFMUstate' if fmu.version == 2 else 'SerializeFMUState')} 0 {state_file}",
               f"{fmu.fn('FreeFMUstate' if fmu.version == 2 else 'FreeFMUState')} 0",
               fmu.fn("Terminate"), f"{fmu.fn('FreeInstance')}"])


@dataclasses.dataclass
class Case:
    """One refused call: in ``state``, the script line ``line``; ``name`` names it in reports."""

    state: str
    name: str
    line: str


def _time_now(fmu: Fmu, state: str) -> float:
    return (STEPS_BEFORE * fmu.step) if state in ("StepComplete", "StepMode", "StepFailed", "Terminated") else 0.0


def forbidden_call(fmu: Fmu, function: str, state: str) -> str | None:
    """The script line of ``function`` with valid arguments (so that only the state is wrong); None where
    the FMU has no variable of the type the function needs."""
    need = NEEDS_TYPE.get(function)
    if need and not fmu.of(type_=need):
        return None
    t = _time_now(fmu, state)
    short = function[4:]
    if short in ("GetReal", "GetFloat64", "GetInteger", "GetInt32"):
        names = fmu.of("output", need) or fmu.of(None, need)
        return f"{function} 1 {fmu.vr(names[0])}"
    if short in ("SetReal", "SetFloat64", "SetInteger", "SetInt32"):
        names = fmu.of("input", need) or fmu.of("parameter", need, "tunable") or fmu.of("parameter", need)
        if not names:
            return None
        return f"{function} {fmu.vr(names[0])} {'1.0' if need in ('Real', 'Float64') else '1'}"
    if short == "DoStep":
        return f"{function} {t!r} {fmu.step!r}"
    if short in ("SetupExperiment", "EnterInitializationMode"):
        return f"{function} 0.0"
    if short in ("GetFMUstate", "GetFMUState", "SetFMUstate", "SetFMUState", "FreeFMUstate", "FreeFMUState",
                 "SerializedFMUstateSize", "SerializedFMUStateSize"):
        return f"{function} 0"
    if short == "SetDebugLogging":
        return f"{function} 1"
    return function


def order(function: str) -> tuple:
    """The sort key of the refused calls of a state: those that change the state when accepted last."""
    return (function in TRANSITIONS, TRANSITIONS.index(function) if function in TRANSITIONS else 0, function)


#: argument and variable cases: (function's FMI 2.0 name without "fmi2", what is wrong, the states: a tuple or
#: "allowed", where the function is allowed, line(fmu, state, files) -> the script line, or None where the
#: FMU has nothing the case needs). files: "own" this FMU's serialized state, "foreign" another FMU's,
#: "garbage" 70 bytes of garbage. The output is max_ball_load on the bearing.
def _variable_cases():
    def set_output(fmu, state, files):
        name = "max_ball_load" if "max_ball_load" in fmu.variables else (fmu.outputs or [None])[0]
        return name and f"{fmu.fn('SetReal' if fmu.version == 2 else 'SetFloat64')} {fmu.vr(name)} 1.0"

    def set_fixed(fmu, state, files):
        name = "preload" if "preload" in fmu.variables else (fmu.of("parameter", fmu.real, "fixed") or [None])[0]
        return name and f"{fmu.fn('SetReal' if fmu.version == 2 else 'SetFloat64')} {fmu.vr(name)} 1000.0"

    def ring_model(fmu, state, files):
        return "ring_model" in fmu.variables and \
            f"{fmu.fn('SetInteger' if fmu.version == 2 else 'SetInt32')} {fmu.vr('ring_model')} 7"

    def step(h, back=0.0):
        return lambda fmu, state, files: f"{fmu.fn('DoStep')} {_time_now(fmu, state) - back!r} {h!r}"

    def unknown_get(fmu, state, files):
        return f"{fmu.fn('GetReal' if fmu.version == 2 else 'GetFloat64')} 1 {fmu.unknown_vr}"

    def unknown_set(fmu, state, files):
        return f"{fmu.fn('SetReal' if fmu.version == 2 else 'SetFloat64')} {fmu.unknown_vr} 1.0"

    def deserialize(which, cut=0):
        def line(fmu, state, files):
            path = files.get(which)
            return path and f"{fmu.fn('DeSerializeFMUstate' if fmu.version == 2 else 'DeserializeFMUState')} " \
                            f"{path} 5 {cut}"
        return line

    after = ("StepComplete", "StepMode")
    return [
        ("SetReal", "an output", "allowed", set_output),
        ("SetReal", "a fixed parameter (preload) after initialisation", after, set_fixed),
        ("SetInteger", "ring_model = 7 after initialisation", after, ring_model),
        ("DoStep", "step size 0", after, step(0.0)),
        ("DoStep", "step size -1", after, step(-1.0)),
        ("DoStep", "communication point 5 s back without a state restore", after, step(0.01, back=5.0)),
        ("GetReal", "an unknown value reference", "allowed", unknown_get),
        ("SetReal", "an unknown value reference", "allowed", unknown_set),
        ("DeSerializeFMUstate", "70 bytes of garbage", after, deserialize("garbage")),
        ("DeSerializeFMUstate", "a truncated state", after, deserialize("own", cut=100)),
        ("DeSerializeFMUstate", "a state of another FMU", after, deserialize("foreign")),
    ]


VARIABLE_CASES = _variable_cases()


def version_name(version: int, short: str) -> str:
    """The FMI 2.0 name of a function, ``short`` without its prefix, in ``version``'s terms."""
    if version == 2:
        return "fmi2" + short
    return "fmi3" + {"SetReal": "SetFloat64", "GetReal": "GetFloat64", "SetInteger": "SetInt32",
                     "DeSerializeFMUstate": "DeserializeFMUState"}.get(short, short)


def cases(fmu: Fmu, state: str, files: dict, subset=None) -> list[Case]:
    """Every refused call of ``state``: the argument and variable cases whose function is allowed there,
    then the functions the table forbids there (those that change the state last). ``subset``: parts of
    the names of the cases to keep (None: all)."""
    table = FMI2_ALLOWED if fmu.version == 2 else FMI3_ALLOWED
    out = []
    for function in sorted(table, key=order):
        if allowed(fmu.version, function, state):
            continue
        line = forbidden_call(fmu, function, state)
        if line:
            out.append(Case(state, f"{function} in {state}", line))
    variable = []
    for short, text, states, make in VARIABLE_CASES:
        function = version_name(fmu.version, short)
        where = states if states != "allowed" else [s for s in fmu.states() if allowed(fmu.version, function, s)]
        if state not in where or not allowed(fmu.version, function, state):
            continue
        line = make(fmu, state, files)
        if line:
            variable.append(Case(state, f"{function} with {text} in {state}", line))
    # the variable cases first: they do not change the state even when wrongly accepted (but a step)
    out = variable + out
    if subset is not None:
        out = [c for c in out if any(s in c.name for s in subset)]
    return out


def _output_reads(fmu: Fmu, lines, indices) -> list[list[int]]:
    """The line indices of the output getters among ``indices``, grouped: one group a read of all outputs."""
    getters = fmu.get_outputs()
    found = [i for i in indices if lines[i] in getters]
    return [found[j:j + len(getters)] for j in range(0, len(found), len(getters))]


def fresh_script(fmu: Fmu, state_file: str):
    """A fresh instance's legal run (:func:`fresh`): (lines, line indices of its output reads, one a step)."""
    lines = fresh(fmu, state_file)
    return lines, _output_reads(fmu, lines, range(len(lines)))


@dataclasses.dataclass
class StateScript:
    """The script of one state: reach it, make its refused calls, complete the legal run, free."""

    state: str
    lines: list
    cases: dict      # line index -> Case
    reach: list      # line indices of the reaching calls
    complete: list   # line indices of the legal run's calls after the refused ones
    outputs: list    # line indices of the legal run's output reads (:func:`_output_reads`)
    first_step: int  # the fresh run's step whose outputs the first of those equal


def state_script(fmu: Fmu, state: str, files: dict, subset=None) -> StateScript:
    lines = [f"@ state {state}"] + reach(fmu, state, state)
    reached = list(range(1, len(lines)))
    where = {}
    lines.append(f"@ refused {state}")
    for case in cases(fmu, state, files, subset):
        where[len(lines)] = case
        lines.append(case.line)
    lines.append(f"@ complete {state}")
    start = len(lines)
    lines += complete(fmu, state)
    done = list(range(start, len(lines)))
    lines.append(fmu.fn("FreeInstance"))
    first = 0 if state in ("Instantiated", "InitializationMode") else STEPS_BEFORE - 1
    return StateScript(state, lines, where, reached, done, _output_reads(fmu, lines, done), first)


# ---- the runners' output, read back ------------------------------------------------------------------------
@dataclasses.dataclass
class Call:
    index: int
    function: str
    status: int | None
    values: list
    logs: list  # (status, category, message) logged during the call


def parse(stdout: str):
    """The calls, by script line index."""
    calls, pending = {}, []
    for line in stdout.splitlines():
        word, _, rest = line.partition(" ")
        if word == "log":
            status, category, message = (rest.split(" ", 2) + ["", ""])[:3]
            pending.append((int(status), category, message))
        elif word == "call":
            parts = rest.split()
            index, function, status = int(parts[0]), parts[1], parts[2]
            values = [float(x) for x in parts[3:]] if status.lstrip("-").isdigit() else []
            calls[index] = Call(index, function, int(status) if status.lstrip("-").isdigit() else None, values,
                                pending)
            pending = []
    return calls


# ---- the fmpy runner -----------------------------------------------------------------------------------------
STATUS_NAMES = {"OK": 0, "WARNING": 1, "DISCARD": 2, "ERROR": 3, "FATAL": 4, "PENDING": 5}


def run_fmpy(fmu_path: str, unzipped: str, script_lines: list[str]) -> None:
    """Run a script through fmpy's low-level API (fmpy.fmi2.FMU2Slave, fmpy.fmi3.FMU3Slave), printing what
    the C host prints."""
    from fmpy import read_model_description
    from fmpy.fmi1 import FMICallException

    md = read_model_description(fmu_path)
    version = 2 if md.fmiVersion.startswith("2") else 3
    out = sys.stdout

    def log(status, category, message):
        text = (message.decode(errors="replace") if isinstance(message, bytes) else str(message))
        cat = (category.decode() if isinstance(category, bytes) else str(category or "-")) or "-"
        out.write(f"log {int(status)} {cat} {text.replace(chr(10), '|')}\n")
        out.flush()

    if version == 2:
        from fmpy import calloc, free
        from fmpy.fmi2 import FMU2Slave as Slave
        from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                               fmi2CallbackLoggerTYPE)

        callbacks = fmi2CallbackFunctions()  # kept alive until the end: the FMU holds pointers into it
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda c, i, s, cat, m: log(s, cat, m))
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    else:
        from fmpy.fmi3 import FMU3Slave as Slave
    slave, last, states = None, [None], {}

    def call_logger(message):
        last[0] = STATUS_NAMES.get(message.rsplit("-> ", 1)[-1].strip(), 0) if "-> " in message else 0

    for index, line in enumerate(script_lines):
        words = line.split()
        if not words:
            continue
        if words[0] == "@":
            out.write(f"mark {' '.join(words[1:])}\n")
            continue
        function, args = words[0], words[1:]
        last[0] = 0
        values, status = [], 0
        try:
            if function in ("fmi2Instantiate", "fmi3InstantiateCoSimulation"):
                slave = Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                              instanceName=args[0], fmiCallLogger=call_logger)
                if version == 2:
                    slave.instantiate(loggingOn=True, callbacks=callbacks)
                else:
                    slave.instantiate(loggingOn=True, logMessage=lambda env, s, cat, m: log(s, cat, m))
            elif function.endswith("FreeInstance"):
                slave.freeInstance()
                slave = None
            else:
                values = _fmpy_call(slave, version, function, args, states) or []
            status = last[0]
        except FMICallException as e:
            status = e.status
        except Exception as e:  # noqa: BLE001 (reported, the test fails on it)
            out.write(f"log 4 runner {function}: {type(e).__name__}: {e}\n")
            status = 4
        text = " ".join(repr(float(v)) for v in values)
        out.write(f"call {index} {function} {status} {text}\n")
        out.flush()


def _fmpy_call(s, version, function, args, states):
    from ctypes import byref, c_size_t

    short = function[4:]
    f = [float(a) for a in args] if short in ("DoStep", "SetupExperiment", "EnterInitializationMode") else None
    if short == "SetupExperiment":
        s.setupExperiment(startTime=f[0])
    elif short == "EnterInitializationMode":
        s.enterInitializationMode(startTime=f[0]) if version == 3 else s.enterInitializationMode()
    elif short == "ExitInitializationMode":
        s.exitInitializationMode()
    elif short == "Terminate":
        s.terminate()
    elif short == "Reset":
        s.reset()
    elif short == "DoStep":
        s.doStep(f[0], f[1])
    elif short == "CancelStep":
        s.cancelStep()
    elif short in ("SetReal", "SetFloat64"):
        setter = s.setReal if version == 2 else s.setFloat64
        setter([int(a) for a in args[::2]], [float(a) for a in args[1::2]])
    elif short in ("SetInteger", "SetInt32"):
        setter = s.setInteger if version == 2 else s.setInt32
        setter([int(a) for a in args[::2]], [int(a) for a in args[1::2]])
    elif short == "GetReal":
        return s.getReal([int(a) for a in args[1:]])
    elif short == "GetFloat64":
        return s.getFloat64([int(a) for a in args[1:]], nValues=int(args[0]))
    elif short == "GetInteger":
        return s.getInteger([int(a) for a in args[1:]])
    elif short == "GetInt32":
        return s.getInt32([int(a) for a in args[1:]], nValues=int(args[0]))
    elif short in ("GetFMUstate", "GetFMUState"):
        states[args[0]] = s.getFMUState() if version == 3 else s.getFMUstate()
    elif short in ("SetFMUstate", "SetFMUState"):
        (s.setFMUState if version == 3 else s.setFMUstate)(states[args[0]] if args[0] in states else None)
    elif short in ("FreeFMUstate", "FreeFMUState"):
        state = states.pop(args[0], None)
        if state is None:
            from fmpy.fmi2 import fmi2FMUstate
            state = fmi2FMUstate()
        (s.freeFMUState if version == 3 else s.freeFMUstate)(state)
    elif short in ("SerializedFMUstateSize", "SerializedFMUStateSize"):
        size = c_size_t()
        getattr(s, function)(s.component, states.get(args[0]), byref(size))
        return [size.value]
    elif short in ("SerializeFMUstate", "SerializeFMUState"):
        data = (s.serializeFMUState if version == 3 else s.serializeFMUstate)(states.get(args[0]))
        with open(args[1], "wb") as fh:
            fh.write(data)
    elif short in ("DeSerializeFMUstate", "DeserializeFMUState"):
        with open(args[0], "rb") as fh:
            data = fh.read()
        cut = int(args[2])
        states[args[1]] = (s.deserializeFMUState if version == 3 else s.deSerializeFMUstate)(
            data[:len(data) - cut] if cut else data)
    elif short == "SetDebugLogging":
        s.setDebugLogging(bool(int(args[0])), [])
    elif short == "GetStatus":
        return [s.getStatus(0)]  # fmi2DoStepStatus
    elif short == "GetRealStatus":
        return [s.getRealStatus(2)]  # fmi2LastSuccessfulTime
    elif short == "GetBooleanStatus":
        return [float(s.getBooleanStatus(3))]  # fmi2Terminated
    elif short == "GetStringStatus":
        s.getStringStatus(1)  # fmi2PendingStatus
    elif short == "EnterStepMode":
        s.enterStepMode()
    elif short == "EnterEventMode":
        s.enterEventMode()
    elif short == "EnterConfigurationMode":
        s.enterConfigurationMode()
    elif short == "ExitConfigurationMode":
        s.exitConfigurationMode()
    elif short == "UpdateDiscreteStates":
        s.updateDiscreteStates()
    else:
        raise ValueError(f"the script's function {function} is not known to the fmpy runner")
    return None


if __name__ == "__main__":
    # python fmi_state_machine.py FMU UNZIPPED SCRIPT: run SCRIPT (one call a line) through fmpy
    with open(sys.argv[3]) as fh:
        run_fmpy(sys.argv[1], sys.argv[2], fh.read().splitlines())
    print("done")
