"""The pitch bearings as FMUs: a bearing FMU (FMI 2.0 co-simulation, ``build_fmu.py``) stepped through fmpy in
place of a :class:`~slewing_model.simulation.BearingSimulator` in the turbine loop (:mod:`slewing_turbine.loop`).

:class:`FmuBearing` answers :meth:`~FmuBearing.step` as a simulator does (the friction torque, signed and at
full sliding, N m) from one FMU instance driven through fmpy's low-level ``FMU2Slave``: each step sets the
inputs ``Fx, Fy, Fz, Mx, My`` (N, N m), ``psi`` (rad) and ``omega`` (rad/s), steps, and reads a few scalar
outputs. :func:`fmu_bearings` makes the loop's three from a :class:`~slewing_turbine.loop.TurbineConfig`,
with the FMU's parameters set to what :func:`~slewing_turbine.loop.make_bearings` gives the library's
simulators, and checks that the FMU was built from the configured bearing (and, for flexible rings, with the
configured superelement mesh and free rings)::

    with fmu_bearings(config, "SlewingBearing_pitch_bearing.fmu", "flexible", friction=True) as sims:
        result = run_turbine(config, wind, drives="electric", bearings="flexible", bearing_simulators=sims)

What the FMU does not give, the loop leaves out: the load distribution (``StepResult.distribution`` is None,
so ``TurbineResult.contact_b`` and the ``x/2b`` figure are absent); with ``life`` on, the life accumulator is
stood for by :class:`FmuLife` (the FMU's ``life_damage`` and ``life_travel_ratio``), without the raceway map.

In a Python host the FMU runs in the host's interpreter (one CPython a process: ``docs/design-decisions.md``):
its slave imports the ``slewing_model`` the process has already imported, with that one's loops (numba's
here), not its own copy and the loops it carries compiled ahead of time. This module imports
``slewing_model`` before it instantiates an FMU, so that the loop and the FMUs share the installed library
whatever comes first. fmpy is imported here only, when an FMU is made.
"""
from __future__ import annotations

import json
import math
import shutil
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: the FMU's inputs, in the order :meth:`FmuBearing.step` sets them
INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
#: the scalar outputs read after every step
OUTPUTS = ("friction_torque", "friction_torque_magnitude", "max_ball_load", "static_safety_factor",
           "equilibrium_residual")
#: ... and with ``life`` on
LIFE_OUTPUTS = ("life_damage", "life_travel_ratio")
#: the FMU's integer parameters: the choices of :class:`~slewing_model.simulation.SimulatorSettings` by their
#: FMU values (``fmu_src/bearing_variables.py``)
CHOICES = {
    "ring_model": {"rigid": 1, "flexible": 2},
    "moving_ring": {"inner": 1, "outer": 2},
    "load_frame": {"fixed": 1, "rotating": 2},
    "step_work": {"complete": 1, "bounded": 2},
}
#: the FMU's real parameters that are settings of the same name
REALS = ("friction_coefficient", "seal_torque", "tolerance", "omega_regularisation")
#: settings the FMU has no parameter for: it runs with these values (SimulatorSettings' defaults); the loops
#: (``friction_kernel``, ``contact_kernel``) are the FMU's build's choice
FIXED = {"friction_tolerance": 1e-5, "blas_threads": 1}


@dataclass
class FmuLife:
    """What the FMU tells of its bearing's life accumulator (:class:`slewing_model.life.LifeAccumulator`):
    the FMU's outputs after the last step.

    Attributes
    ----------
    worst_damage : float
        ``life_damage``: the rolling contact fatigue damage of the worst raceway track so far, -.
    last_ratio : float
        ``life_travel_ratio``: ``x/2b`` of the last completed half-cycle of ``psi``, -; NaN before the first
        (the FMU's 0).
    """

    worst_damage: float = 0.0
    last_ratio: float = math.nan


@dataclass
class FmuStepResult:
    """A step's answer from the FMU, as much of :class:`~slewing_model.simulation.StepResult` as it gives.

    Attributes
    ----------
    friction_torque : float
        N m, on the moving ring about +z, opposing ``omega`` (the FMU's ``friction_torque``).
    friction_torque_magnitude : float
        N m, at full sliding, >= 0 (``friction_torque_magnitude``).
    distribution : None
        The FMU gives no load distribution object (its per-ball outputs are not read).
    outputs : dict
        The scalar outputs read (:data:`OUTPUTS`, with ``life`` :data:`LIFE_OUTPUTS`) by name, SI units.
    """

    friction_torque: float
    friction_torque_magnitude: float
    distribution: None = None
    outputs: dict = field(default_factory=dict)


class FmuBearing:
    """A bearing FMU standing in for a :class:`~slewing_model.simulation.BearingSimulator` (its
    :meth:`step`, ``bearing`` and ``life``).

    The instance is made, its parameters set and initialization mode entered here; the first :meth:`step`
    sets the inputs and leaves initialization mode (where the FMU solves its first step: the simulator's
    first step, so that the FMU's solver has made exactly the library simulator's steps), each later one sets
    the inputs and calls ``doStep``. A refused step raises RuntimeError with the FMU's last log messages (the
    library raises :class:`~slewing_model.NoEquilibriumError` or ValueError).

    Parameters
    ----------
    fmu_path : path
        The bearing FMU (FMI 2.0, ``build_fmu.py``).
    settings : SimulatorSettings
        What the library's simulator would run with: ``ring_model``, ``moving_ring``, ``load_frame``,
        ``preload`` (None: the FMU's default, the bearing definition's), ``friction_coefficient``,
        ``seal_torque``, ``tolerance``, ``omega_regularisation``, ``step_work`` and ``life`` become the FMU's
        parameters of the same name. ``friction_tolerance`` and ``blas_threads`` have no FMU parameter: other
        values than :data:`FIXED` raise ValueError. The loops are the FMU's: ``friction_kernel`` and
        ``contact_kernel`` are not passed on.
    dt : float, s
        The communication step (``doStep``'s step size; the bearing is quasi-static: its answer does not
        depend on it).
    unzipped : path, optional
        The FMU already extracted there (kept); None: extracted to a temporary folder, removed by
        :meth:`close`.
    instance_name : str
        The FMU instance's name (in its log messages).
    """

    def __init__(self, fmu_path, settings, *, dt: float = 0.01, unzipped=None, instance_name: str = "bearing"):
        import slewing_model  # noqa: F401  (before the FMU's slave imports it: the installed library, not its copy)
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave
        from slewing_drives.cosimulation import logging_callbacks
        from slewing_model import Bearing

        for name, value in FIXED.items():
            if getattr(settings, name) != value:
                raise ValueError(f"{name} = {getattr(settings, name)!r}: the bearing FMU has no such parameter, it "
                                 f"runs with {value!r}")
        self.settings = settings
        self.dt = float(dt)
        self.time = 0.0
        self.messages: list[str] = []
        self._own = unzipped is None
        self.unzipped = Path(extract(str(fmu_path)) if unzipped is None else unzipped)
        self.fmu = None
        self._instantiated = False
        try:
            md = read_model_description(str(fmu_path))
            self._refs = {v.name: v.valueReference for v in md.modelVariables}
            with open(self.unzipped / "resources" / "bearing.json") as fh:
                #: the bearing the FMU was built for (:class:`~slewing_model.Bearing`)
                self.bearing = Bearing.from_si_dict(json.load(fh))
            self.life = FmuLife() if settings.life else None
            self._inputs = [self._refs[n] for n in INPUTS]
            self._names = OUTPUTS + (LIFE_OUTPUTS if settings.life else ())
            self._outputs = [self._refs[n] for n in self._names]
            self._callbacks = logging_callbacks(self._log)       # the FMU keeps pointers into it: held here
            self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(self.unzipped),
                                 modelIdentifier=md.coSimulation.modelIdentifier, instanceName=instance_name)
            self.fmu.instantiate(loggingOn=True, callbacks=self._callbacks)
            self._instantiated = True
            self.fmu.setupExperiment(startTime=0.0)
            integers = {name: choices[getattr(settings, name)] for name, choices in CHOICES.items()}
            integers["life"] = int(bool(settings.life))
            reals = {name: float(getattr(settings, name)) for name in REALS}
            if settings.preload is not None:
                reals["preload"] = float(settings.preload)
            self.fmu.setInteger([self._refs[n] for n in integers], list(integers.values()))
            self.fmu.setReal([self._refs[n] for n in reals], list(reals.values()))
            self.fmu.enterInitializationMode()
        except Exception:
            self.close()
            raise
        self._initialized = False

    def _log(self, component, instance, status, category, message):
        self.messages.append(message.decode(errors="replace"))

    def step(self, loads, psi: float, omega: float) -> FmuStepResult:
        """One step under ``loads`` (:class:`~slewing_model.Loads`, N and N m, in the ``load_frame``) at the
        moving ring's angle ``psi`` (rad) and speed ``omega`` (rad/s).

        Returns
        -------
        FmuStepResult
        """
        values = [float(loads.Fx), float(loads.Fy), float(loads.Fz), float(loads.Mx), float(loads.My),
                  float(psi), float(omega)]
        try:
            self.fmu.setReal(self._inputs, values)
            if not self._initialized:
                self.fmu.exitInitializationMode()          # the FMU solves its first step here
                self._initialized = True
            else:
                self.fmu.doStep(currentCommunicationPoint=self.time, communicationStepSize=self.dt)
                self.time += self.dt
            out = dict(zip(self._names, self.fmu.getReal(self._outputs)))
        except Exception as exc:
            detail = "\n".join(self.messages[-5:])
            raise RuntimeError(f"the bearing FMU refused the step at t = {self.time:g} s: {exc}\nFMU log:\n{detail}") \
                from None
        if self.life is not None:
            self.life.worst_damage = out["life_damage"]
            self.life.last_ratio = out["life_travel_ratio"] if out["life_travel_ratio"] > 0.0 else math.nan
        return FmuStepResult(out["friction_torque"], out["friction_torque_magnitude"], None, out)

    def close(self) -> None:
        """Terminate and free the FMU instance; remove the folder it was extracted to (when its own)."""
        fmu, self.fmu = self.fmu, None
        if fmu is not None and self._instantiated:
            try:
                fmu.terminate()
            except Exception:
                pass
            fmu.freeInstance()
        elif fmu is not None:
            fmu.freeLibrary()
        if self._own:
            shutil.rmtree(self.unzipped, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def check_build(fmu_path, config, ring_model: str) -> None:
    """ValueError where the FMU was not built from ``config``'s bearing (its ``bearing.json``), or, for
    flexible rings, not with ``config.mesh`` and free rings (its superelement's metadata)."""
    import zipfile

    bearing = config.bearing_definition()
    with zipfile.ZipFile(fmu_path) as z:
        built = json.loads(z.read("resources/bearing.json"))
        if built != json.loads(json.dumps(bearing.to_dict())):
            raise ValueError(f"{fmu_path}: the FMU was built for another bearing than {config.bearing}")
        if ring_model == "flexible":        # the superelement's metadata (Superelement.save_folder)
            meta = json.loads(z.read("resources/superelement/metadata.json"))
            mesh = meta.get("mesh", {}).get("name")
            rings = set(meta.get("boundary_conditions", {}).values())
            if mesh != config.mesh or rings != {"free"}:
                raise ValueError(f"{fmu_path}: the FMU's superelement has the {mesh} mesh and rings {sorted(rings)}; "
                                 f"the loop's bearings have the {config.mesh} mesh and free rings")


@contextmanager
def fmu_bearings(config, fmu_path, ring_model: str, friction: bool, count: int = 3, dt: float = 0.01):
    """``count`` instances of the bearing FMU set as :func:`~slewing_turbine.loop.make_bearings` sets the
    library's simulators (:func:`~slewing_turbine.loop.bearing_settings`: ``load_frame`` "rotating", the
    config's friction, ``life`` and ``step_work``), extracted once; freed, and the folder removed, on leaving.

    Parameters
    ----------
    config : TurbineConfig
        The FMU must have been built from ``config.bearing`` (with flexible rings: ``mesh=config.mesh``,
        ``bc="free"``; :func:`check_build`).
    fmu_path : path
        The bearing FMU (FMI 2.0).
    ring_model : {"flexible", "rigid"}
    friction : bool
        The config's friction coefficient and seal torque, or both 0.
    count : int
    dt : float, s
        The communication step (the loop's).

    Yields
    ------
    list of FmuBearing
    """
    from fmpy import extract

    from .loop import bearing_settings

    check_build(fmu_path, config, ring_model)
    settings = bearing_settings(config, ring_model, friction)
    unzipped = Path(extract(str(fmu_path)))
    sims = []
    try:
        for k in range(count):
            sims.append(FmuBearing(fmu_path, settings, dt=dt, unzipped=unzipped, instance_name=f"blade{k + 1}"))
        yield sims
    finally:
        for sim in sims:
            sim.close()
        shutil.rmtree(unzipped, ignore_errors=True)
