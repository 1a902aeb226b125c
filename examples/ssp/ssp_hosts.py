"""Run an SSP in the hosts that read SSP here: fmpy, libcosim (libcosimpy) and ecos (ecospy).

Each function runs the SSP with a fixed communication step and returns the
values of ``names`` (``"element.connector"``) after every step, as a dict of
numpy arrays, plus ``"time"`` (the end of each step). The three hosts step
their FMUs side by side on the values of the last communication point
(Jacobi); :func:`slewing_drives.cosimulation.run_manoeuvre` with
``coupling="parallel"`` (libcosim, ecos) or ``"parallel-zero-start"`` (fmpy)
follows the same step sequence.

What each host needs from us:

* fmpy 0.3.32 ``simulate_ssp`` applies no ParameterBindings of the SSP: they
  are read from the SSD (:func:`fmpy_parameter_set`) and passed to it. It
  starts every connection at 0 (no exchange before the first step).
* libcosim takes the step in nanoseconds and applies the bindings itself.
* ecos applies the bindings of the parameter set it is given by name: the
  SSP names every component's set ``PARAMETER_SET``.
"""
from __future__ import annotations

import contextlib
import math
import os
import shutil
import tempfile

import numpy as np

#: name of the parameter sets of the pitch system SSP (ecos applies the bindings of one named set)
PARAMETER_SET = "pitch_system"


def fmpy_parameter_set(ssp):
    """The SSP's parameter bindings as the ParameterSet fmpy's ``simulate_ssp`` takes
    (names ``element.parameter``)."""
    from fmpy.ssp.ssd import Parameter, ParameterSet, find_components, read_ssd

    ssd = read_ssd(str(ssp))
    bound = ParameterSet(name=PARAMETER_SET)
    for component in find_components(ssd.system):
        for binding in component.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    bound.parameters.append(Parameter(name=f"{component.name}.{p.name}", value=p.value, type=p.type))
    return bound


def run_fmpy(ssp, names, *, stop_time: float, step_size: float) -> dict:
    """fmpy's ``simulate_ssp`` (its own step loop, time added up in floating point)."""
    from fmpy.ssp.simulation import simulate_ssp

    steps = int(round(stop_time / step_size))
    # fmpy steps while time < stop_time with time += step_size: stop half a step early to get ``steps`` steps
    result = simulate_ssp(str(ssp), stop_time=(steps - 0.5) * step_size, step_size=step_size,
                          parameter_set=fmpy_parameter_set(ssp))
    out = {name: np.asarray(result[name], dtype=float) for name in names}
    out["time"] = np.asarray(result["time"], dtype=float) + step_size  # fmpy labels a step by its start
    return out


def run_libcosim(ssp, names, *, stop_time: float, step_size: float) -> dict:
    """libcosim (libcosimpy), stepped one communication step at a time."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp), step_size=int(round(step_size * 1e9)))
    index = {info.name.decode(): info.index for info in execution.slave_infos()}
    refs = {element: {v.name.decode(): v.reference for v in execution.slave_variables(i)}
            for element, i in index.items()}
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    steps = int(round(stop_time / step_size))
    out = {name: np.empty(steps) for name in names}
    for k in range(steps):
        if not execution.step(1):
            from libcosimpy._internal import get_last_error_message

            raise RuntimeError(f"libcosim failed at step {k}: {get_last_error_message()}")
        for name in names:
            element, variable = name.split(".", 1)
            out[name][k] = observer.last_real_values(index[element], [refs[element][variable]])[0]
    out["time"] = (np.arange(steps) + 1) * step_size
    execution.stop()
    return out


def libtbb_missing() -> str | None:
    """Why ecos cannot run here, or None. ecos needs Debian's libtbb12 (``libtbb.so.12``); the
    dynamic loader is asked directly, so the check does not depend on ``ldconfig`` being on
    ``PATH`` (it is in /sbin, which a user's ``PATH`` often lacks)."""
    import ctypes

    try:
        ctypes.CDLL("libtbb.so.12")
    except OSError as exc:
        return f"ecos needs Debian's libtbb12 (libtbb.so.12), which the loader cannot find: {exc}"
    return None


@contextlib.contextmanager
def private_tmpdir():
    """A temporary folder as ``TMPDIR`` for the block, removed afterwards with what is in it.

    ecos unpacks an SSP into a new ``ecos_ssp_*`` folder of the temporary directory
    (``std::filesystem::temp_directory_path``, which reads ``TMPDIR``) at every run and never
    removes it; giving each run its own ``TMPDIR`` keeps ``/tmp`` clean without touching
    folders of other runs."""
    folder = tempfile.mkdtemp(prefix="slewing_ecos_")
    before = os.environ.get("TMPDIR")
    os.environ["TMPDIR"] = folder
    try:
        yield folder
    finally:
        if before is None:
            os.environ.pop("TMPDIR", None)
        else:
            os.environ["TMPDIR"] = before
        shutil.rmtree(folder, ignore_errors=True)


def run_ecos(ssp, names, *, stop_time: float, step_size: float) -> dict:
    """ecos (ecospy's in-process library), with the SSP's parameter set applied; its unpacked
    SSP is removed afterwards (:func:`private_tmpdir`)."""
    from ecospy import EcosSimulation

    steps = int(round(stop_time / step_size))
    out = {name: np.empty(steps) for name in names}
    time = np.empty(steps)
    with private_tmpdir():
        sim = EcosSimulation(step_size=step_size, ssp_path=str(ssp))
        try:
            sim.init(parameter_set=PARAMETER_SET)
            for k in range(steps):
                time[k] = sim.step()
                for name in names:
                    out[name][k] = sim.get_real(name.replace(".", "::", 1))
            sim.terminate()
        finally:
            sim.free()
    out["time"] = time
    return out


HOSTS = {"fmpy": run_fmpy, "libcosim": run_libcosim, "ecos": run_ecos}

#: the coupling of slewing_drives.cosimulation.run_manoeuvre that follows each host's step sequence
COUPLING = {"fmpy": "parallel-zero-start", "libcosim": "parallel", "ecos": "parallel"}

#: host outputs -> ManoeuvreResult fields
COMPARED = {"drive.psi": "angle", "drive.omega": "speed", "drive.motor_torque": "motor_torque",
            "bearing.friction_torque_magnitude": "friction_torque", "bearing.max_ball_load": "max_ball_load"}


def reference_values(result, name):
    """The values of a host output ``name`` (a key of :data:`COMPARED`) in a ManoeuvreResult."""
    field = COMPARED[name]
    return result.outputs[field] if field == "max_ball_load" else getattr(result, field)


def max_relative_difference(a, b) -> float:
    """Largest ``|a - b|`` relative to the largest ``|b|`` (the scale of the signal)."""
    scale = max(float(np.abs(b).max()), math.ulp(1.0))
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / scale)
