"""Variables of the slewing bearing FMU, shared by its FMI 2.0 and FMI 3.0 slaves.

One table per kind of variable (name, SI unit, description), the parameters'
defaults and choices, the checks both slaves make before they step, and the
step itself with its refusal rule (:func:`step_or_refuse`), so that both
answer and refuse alike. No FMI library and no physics here: the slaves hand
in their own status values, slewing_model does the rest.
"""
from __future__ import annotations

import math
import sys

from dataclass_code import precompiled

#: SI units of the variables, as FMI UnitDefinitions: name -> exponents of (kg, m, s, rad)
UNITS = {
    "N": (1, 1, -2, 0),
    "N.m": (1, 2, -2, 0),
    "m": (0, 1, 0, 0),
    "rad": (0, 0, 0, 1),
    "rad/s": (0, 0, -1, 1),
    "Pa": (1, -1, -2, 0),
    "1": (0, 0, 0, 0),
    "s": (0, 0, 1, 0),
}

INPUTS = [  # name, unit, description
    ("Fx", "N", "force on the moving ring along x"),
    ("Fy", "N", "force on the moving ring along y"),
    ("Fz", "N", "axial force on the moving ring, > 0 pushes the inner ring towards +z (loads contacts 1 and 3)"),
    ("Mx", "N.m", "tilting moment on the moving ring about x"),
    ("My", "N.m", "tilting moment on the moving ring about y"),
    ("psi", "rad", "rotation angle of the moving ring"),
    ("omega", "rad/s", "rotation speed of the moving ring"),
]

OUTPUTS = [  # name, unit, description
    ("x", "m", "displacement of the moving ring along x"),
    ("y", "m", "displacement of the moving ring along y"),
    ("z", "m", "axial displacement of the moving ring"),
    ("rx", "rad", "tilt of the moving ring about x"),
    ("ry", "rad", "tilt of the moving ring about y"),
    ("friction_torque", "N.m", "friction torque on the moving ring about z, opposing omega"),
    ("friction_torque_magnitude", "N.m", "magnitude of the friction torque at full sliding"),
    ("max_ball_load", "N", "largest ball-raceway contact load"),
    ("max_contact_pressure", "Pa", "largest Hertz contact pressure"),
    ("static_safety_factor", "1", "ISO 76 static safety factor (4200 MPa / p_max)^3"),
]

#: life and wear outputs (slewing_model.life), 0 while the parameter life is 0 (off)
LIFE_OUTPUTS = [
    ("life_damage", "1", "rolling contact fatigue damage of the worst raceway track so far, from the raceway map "
                         "(1: its L10 is used up; ISO/TS 16281 capacities; documentation: life and wear)"),
    ("life_travel_ratio", "1", "x/2b of the last completed half-cycle of psi: rolling travel of the contacts over "
                               "the Hertz patch width (smallest over the loaded tracks; < 1: the patch is never "
                               "uncovered; 0 until the first half-cycle is completed)"),
]
#: the solver's account of the step
SOLVER_OUTPUTS = [
    ("equilibrium_residual", "1", "largest force residual of the answered load distribution over the load scale: "
                                  "at most the parameter tolerance where the step reached equilibrium; above it only "
                                  "where step_work = bounded stopped a step before (its outputs are then the last "
                                  "Newton iterate, and the next steps go on from it)"),
]
OUTPUTS = OUTPUTS + LIFE_OUTPUTS + SOLVER_OUTPUTS

#: integer output (FMI 2.0 Integer, FMI 3.0 Int32): name, description
COUNT_OUTPUT = ("balls_in_four_point_contact", "number of balls loaded on both diagonals")

#: real parameters: name, unit, description, tunable (else fixed), default (None: from the bearing definition)
REAL_PARAMETERS = [
    ("preload", "m", "ball preload (oversize; < 0 for clearance)", False, None),
    ("friction_coefficient", "1", "Coulomb friction coefficient of the raceway contacts (0: off)", True, 0.1),
    ("seal_torque", "N.m", "load-independent friction torque (seals, grease)", True, 0.0),
    ("tolerance", "1", "relative tolerance of the load distribution solver (residual forces over the load scale)", False, 1e-7),
    ("omega_regularisation", "rad/s",
     "speed over which friction_torque rises to its full-sliding level (tanh); "
     "at least magnitude * step / inertia for an explicit coupling", True, 1e-4),
]

RING_MODELS = {1: "rigid", 2: "flexible"}
MOVING_RINGS = {1: "inner", 2: "outer"}
LOAD_FRAMES = {1: "fixed", 2: "rotating"}
LIFE = {0: "off", 1: "on"}
STEP_WORK = {1: "complete", 2: "bounded"}

#: integer parameters: name, choices, description (the choices are listed after it)
INTEGER_PARAMETERS = [
    ("ring_model", RING_MODELS, "ring model"),
    ("moving_ring", MOVING_RINGS, "ring the loads act on and that turns"),
    ("load_frame", LOAD_FRAMES, "frame of the input loads"),
    ("life", LIFE, "life and wear accumulators (outputs life_damage, life_travel_ratio)"),
    ("step_work", STEP_WORK, "work of a step: complete solves every step to the tolerance, however long a sudden "
                             "load change makes it; bounded (real time) caps a step's Newton iterations and ring "
                             "operator work (documentation: performance) and carries the rest over to the next steps, flagged by "
                             "equilibrium_residual above tolerance"),
]

#: per-ball results: FMI 3.0 array name, unit, columns (FMI 2.0 scalar suffixes), description,
#: and how the column is taken from slewing_model's LoadDistribution (attribute, first columns)
BALL_ARRAYS = [
    ("contact_load", "N", ("Q1", "Q2", "Q3", "Q4"), "contact load of each ball (axis 0) and contact 1..4 (axis 1)",
     "contact_load"),
    ("contact_angle", "rad", ("alpha13", "alpha24"),
     "loaded contact angle of each ball (axis 0) and diagonal 1-3, 2-4 (axis 1)", "contact_angle"),
    ("interference", "m", ("d13", "d24"),
     "interference (total Hertz deflection; < 0: gap) of each ball (axis 0) and diagonal 1-3, 2-4 (axis 1)",
     "interference"),
]


def integer_default(name: str, bearing) -> int:
    """Default of an integer parameter for ``bearing`` (flexible rings, its moving ring, fixed frame)."""
    if name == "ring_model":
        return 2
    if name == "moving_ring":
        return 1 if bearing.moving_ring == "inner" else 2
    return 1


def choice_description(choices: dict, text: str) -> str:
    return f"{text}: " + ", ".join(f"{k} = {v}" for k, v in choices.items())


def check_choices(values: dict) -> dict:
    """The integer parameters in ``values`` as the names of their choices; ValueError naming the
    parameter, its value and the allowed values otherwise."""
    names = {}
    for name, choices, _ in INTEGER_PARAMETERS:
        value = values[name]
        if value not in choices:
            raise ValueError(f"parameter {name} = {value}: must be one of "
                             + ", ".join(f"{k} ({v})" for k, v in choices.items()))
        names[name] = choices[value]
    return names


def settings_of(values: dict) -> dict:
    """The simulator settings (``SimulatorSettings`` keywords) of the FMU's parameter values
    (every parameter of :data:`REAL_PARAMETERS` and :data:`INTEGER_PARAMETERS` by name);
    ValueError naming a bad integer choice (the settings check the rest)."""
    settings = check_choices(values)
    settings.update({name: float(values[name]) for name, *_ in REAL_PARAMETERS})
    settings["life"] = settings["life"] == "on"
    return settings


def check_inputs(values: dict) -> None:
    """ValueError naming the first input of ``values`` that is not finite."""
    for name, _, _ in INPUTS:
        value = values[name]
        if not math.isfinite(value):
            raise ValueError(f"input {name} = {value!r}: must be finite (not NaN or infinite)")


#: the parameters a host may change between steps (those of :data:`REAL_PARAMETERS` marked tunable)
TUNABLE = tuple(name for name, _, _, tunable, _ in REAL_PARAMETERS if tunable)


#: the file of an FMU's resources that names the loops its runtime carries (written by build_fmu.py)
KERNELS_FILE = "kernels.txt"


#: the CPU the FMU's compiled loops were compiled for, besides a generic x86-64 (written by build_fmu.py)
NUMBA_TARGET_FILE = "numba_target.txt"


def kernels_of(resources: str) -> str:
    """The loops the FMU was built to run (``resources/kernels.txt``): "numpy" for a runtime
    without numba, so that the FMU computes the same numbers in every host, also in a Python
    host that has numba; "auto" where the file is missing.

    For compiled loops, numba's cache in the FMU holds them for the building machine's CPU and for
    each of :data:`slewing_model.numerics.targets.PORTABLE_TARGETS` (an x86-64-v3 CPU: AVX2 and FMA;
    any x86-64). On another CPU, numba would not find the building CPU's loops and compile them all
    at instantiation (about a minute, in every freshly unpacked copy): there the first portable target
    whose features this CPU has is set (``NUMBA_CPU_NAME``, ``NUMBA_CPU_FEATURES``) before numba is
    imported, so that numba takes those loops (the generic ones: about 10-25 % slower steps), unless
    the user set ``NUMBA_CPU_NAME``. On Windows, where the runtime carries numba (a win64 half built
    with ``--win64-numba``), the portable ones are chosen so always: its cache holds those only."""
    import os

    from slewing_model.numerics.targets import portable_target, target_environment

    path = os.path.join(resources, KERNELS_FILE)
    if not os.path.exists(path):
        return "auto"
    with open(path) as fh:
        kernels = fh.read().strip() or "auto"
    target = os.path.join(resources, NUMBA_TARGET_FILE)
    windows = os.name == "nt"
    if kernels == "numpy" or "numba" in sys.modules or "NUMBA_CPU_NAME" in os.environ \
            or not (windows or os.path.exists(target)):
        return kernels
    try:                        # llvmlite comes with numba (on Windows: a --win64-numba half only)
        import llvmlite.binding as llvm

        features = llvm.get_host_cpu_features()
        this_cpu = [llvm.get_host_cpu_name(), features.flatten()]
    except Exception:           # no llvmlite: numpy's loops run anyway
        return kernels
    if not windows:
        with open(target) as fh:
            if fh.read().split() == this_cpu:        # the building machine's CPU: its own loops
                return kernels
    os.environ.update(target_environment(portable_target(features)))
    return kernels


def numba_target() -> str:
    """For the log: the CPU the compiled loops run for."""
    import os

    name = os.environ.get("NUMBA_CPU_NAME")
    if name is None:
        return "this CPU"
    cpu = {"generic": "a generic x86-64 CPU", "x86-64-v3": "an x86-64-v3 CPU"}.get(name, f"the CPU {name}")
    return cpu + (" (Windows)" if os.name == "nt" else " (this CPU is not the building machine's)")


def build_simulator(slave, error) -> bool:
    """Create ``slave.simulator`` from the slave's parameters (attributes by name), its ``bearing``
    and ``superelement_path``; log why not (status ``error``) and return False."""
    from slewing_model.rings.stiffness import Superelement
    from slewing_model.simulation.simulator import BearingSimulator, SimulatorSettings

    slave.simulator = None
    try:
        names = [name for name, *_ in REAL_PARAMETERS] + [name for name, *_ in INTEGER_PARAMETERS]
        kernels = getattr(slave, "kernels", "auto")
        settings = SimulatorSettings(**settings_of({name: getattr(slave, name) for name in names}),
                                     friction_kernel=kernels, contact_kernel=kernels)
        superelement = None
        if settings.ring_model == "flexible":
            superelement = Superelement.load(slave.superelement_path, slave.bearing)
        with precompiled():         # the life accumulators' modules, imported where life is on
            slave.simulator = BearingSimulator(slave.bearing, superelement, settings)
        from slewing_model.numerics.compiled import aot_target, use_compiled

        target = aot_target()
        compiled = (f"compiled ahead of time for {target}" if target is not None
                    else f"compiled by numba for {numba_target()}")
        slave.log(f"{slave.instance_name}: loops " + (compiled if use_compiled(kernels) else "run by numpy"))
        return True
    except ValueError as exc:
        slave.log(f"{slave.instance_name}: {exc}", error)
    except Exception:
        import traceback

        slave.log(f"{slave.instance_name}: internal error:\n{traceback.format_exc()}", error)
    return False


def step_or_refuse(slave, current_time, discard, error, warning=None):
    """Step ``slave.simulator`` with the slave's inputs and tunable parameters (attributes by
    name); the :class:`~slewing_model.simulation.simulator.StepResult`, or None after logging why not.

    A bad input or a load the bearing cannot carry refuses the step: logged with the status
    ``discard``, the simulator as before the step (it restores itself), so the master may
    retry the step from its start with other inputs (FMI 2.0, 4.2.3). The same step refused again (same
    time, inputs and tunable parameters: a master that retries unchanged) cannot succeed and
    is logged with ``error``, as is an internal error; no exception leaves (it would reach
    the host). ``slave._refused`` keeps the last refused step. A valid result the user must
    know about (:meth:`~slewing_model.distribution.LoadDistribution.warnings`: a static safety
    factor below 1, edge loading) is logged with ``warning`` when it starts, and again after
    it cleared."""
    from slewing_model import Loads, NoEquilibriumError

    sim = slave.simulator
    try:
        check_inputs({name: getattr(slave, name) for name, _, _ in INPUTS})
        tunable = {name: float(getattr(slave, name)) for name in TUNABLE}
        if any(getattr(sim.settings, k) != v for k, v in tunable.items()):
            sim.tune(**tunable)
        result = sim.step(Loads(slave.Fx, slave.Fy, slave.Fz, slave.Mx, slave.My), slave.psi, slave.omega)
    except (ValueError, NoEquilibriumError) as exc:
        key = repr((current_time, [getattr(slave, name) for name, _, _ in INPUTS],  # repr: NaN equals NaN
                    [getattr(slave, name) for name in TUNABLE]))
        if current_time is not None and key == slave._refused:
            slave.log(f"{slave.instance_name}: step at t = {current_time} refused again with the same inputs, "
                      f"so it cannot succeed (change an input, or stop): {exc}", error)
        else:
            slave.log(f"{slave.instance_name}: step refused, state kept: {exc}", discard)
        slave._refused = key
        return None
    except Exception:
        import traceback

        slave.log(f"{slave.instance_name}: internal error:\n{traceback.format_exc()}", error)
        return None
    slave._refused = None
    found = result.distribution.warnings() if warning is not None else []
    if found and not getattr(slave, "_warned", False):
        for text in found:
            slave.log(f"{slave.instance_name}: t = {current_time}: {text}", warning)
    slave._warned = bool(found)
    return result


def scalar_outputs(result, simulator=None) -> dict:
    """The scalar outputs (:data:`OUTPUTS` and :data:`COUNT_OUTPUT`) of a step result, by name; the
    life outputs from ``simulator.life`` (0 without it)."""
    d = result.distribution
    values = dict(zip(("x", "y", "z", "rx", "ry"), d.displacement.tolist()))
    values.update(friction_torque=result.friction_torque, friction_torque_magnitude=result.friction_torque_magnitude,
                  max_ball_load=d.max_ball_load, max_contact_pressure=d.max_contact_pressure,
                  static_safety_factor=min(d.static_safety_factor, 1e300))
    values[COUNT_OUTPUT[0]] = d.balls_in_four_point_contact
    values["equilibrium_residual"] = float(d.residual)
    life = getattr(simulator, "life", None)
    ratio = math.nan if life is None else life.last_ratio
    values.update(life_damage=0.0 if life is None else life.worst_damage,
                  life_travel_ratio=0.0 if math.isnan(ratio) else ratio)
    return values
