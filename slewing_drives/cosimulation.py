"""Co-simulation of a slewing drive with the bearing FMU (fmpy, FMU2Slave step loop).

Every communication step ``dt``:

1. the bearing FMU gets the loads of the time series and the ring's angle
   ``psi`` and speed ``omega`` from the drive, and steps;
2. the drive gets the bearing's friction torque (held over the step, applied as
   Coulomb friction with stick-slip, see :mod:`slewing_drives.drive`) and the
   load moment ``Mz`` of the series, and steps.

:func:`run_manoeuvre` returns the time histories as numpy arrays.
"""
from __future__ import annotations

import math
import shutil
from dataclasses import dataclass

import numpy as np

from .drive import DriveParameters, ElectricDrive
from .load_series import LoadSeries

INPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "psi", "omega")
OUTPUTS = ("friction_torque", "friction_torque_magnitude", "max_ball_load", "max_contact_pressure",
           "static_safety_factor", "z", "rx", "ry")


#: the band of the settling time (deg), and from when after a command step the max error is taken (s)
SETTLED_DEG = 0.1
SETTLED_AFTER_S = 1.0


def settling(time, command_deg, error_deg, band: float = SETTLED_DEG, after: float = SETTLED_AFTER_S):
    """(settling time, s; max |error|, deg, from ``after`` s after the last command step). A step is a
    change of the command by more than ``band`` from one sample to the next; the settling time is the
    longest over the steps (inf: outside the band until the next step or the end). Without a step:
    (0, max |error|)."""
    time, command_deg, error = np.asarray(time), np.asarray(command_deg), np.abs(np.asarray(error_deg))
    steps = np.flatnonzero(np.abs(np.diff(command_deg, prepend=command_deg[:1])) > band)
    if not steps.size:
        return 0.0, float(error.max()) if error.size else 0.0
    worst = 0.0
    for i, k in enumerate(steps):
        end = steps[i + 1] if i + 1 < steps.size else time.size
        outside = np.flatnonzero(error[k:end] > band)
        if outside.size and k + outside[-1] == end - 1:
            worst = math.inf                    # still outside the band when the next step comes
        elif outside.size:
            worst = max(worst, time[k + outside[-1] + 1] - time[k])
    last = np.searchsorted(steps, np.arange(time.size), side="right") - 1     # the last step up to each sample
    late = (last < 0) | (time - time[steps[np.maximum(last, 0)]] >= after)
    return float(worst), float(error[late].max()) if late.any() else math.nan


@dataclass
class ManoeuvreResult:
    """Time histories of a co-simulated manoeuvre (SI units, angles in rad)."""

    time: np.ndarray
    command: np.ndarray
    angle: np.ndarray
    speed: np.ndarray
    motor_torque: np.ndarray           # per motor, averaged over each step
    ring_torque: np.ndarray            # all motors, at the ring
    load_moment: np.ndarray            # Mz of the series
    outputs: dict                      # FMU outputs by name
    motor_energy: float                # J
    params: DriveParameters

    @property
    def friction_torque(self) -> np.ndarray:
        return self.outputs["friction_torque_magnitude"]

    def summary(self) -> dict:
        """Figures a drive engineer reads first. The tracking figures leave out the command's steps
        themselves (right after a step the error is the step): the settling time is the longest,
        over the steps, from a step until the error stays within :data:`SETTLED_DEG` (inf: it does
        not before the next step or the end); the max error is that more than :data:`SETTLED_AFTER_S`
        after the last step."""
        error = np.degrees(self.command - self.angle)
        settle, late_error = settling(self.time, np.degrees(self.command), error)
        return {
            "peak motor torque [N m]": float(np.abs(self.motor_torque).max()),
            "motor torque limit [N m]": self.params.torque_limit,
            "motor energy [kJ]": self.motor_energy / 1e3,
            f"settling time to within {SETTLED_DEG:g} deg of a step [s]": settle,
            f"max tracking error, from {SETTLED_AFTER_S:g} s after a step [deg]": late_error,
            "rms tracking error [deg]": float(np.sqrt(np.mean(error**2))),
            "peak friction torque [kN m]": float(self.friction_torque.max() / 1e3),
            "max ball load [kN]": float(self.outputs["max_ball_load"].max() / 1e3),
            "min static safety factor": float(self.outputs["static_safety_factor"].min()),
        }


def run_manoeuvre(fmu_path, drive: DriveParameters, loads: LoadSeries, command, *, t_end: float, dt: float,
                  start_values: dict | None = None, friction: bool = True, progress: bool = False,
                  logger=None, coupling: str = "sequential") -> ManoeuvreResult:
    """Co-simulate ``drive`` with the bearing FMU under ``loads`` following ``command(t)`` (rad).

    Parameters
    ----------
    fmu_path : path
        The bearing FMU (``build_fmu.py``).
    drive : DriveParameters
    loads : LoadSeries
    command : callable
        Angle command of the ring, rad, as a function of time, s.
    t_end, dt : float, s
        Stop time and communication step.
    start_values : dict, optional
        FMU parameters (``ring_model``, ``load_frame``, ``friction_coefficient`` ...).
    friction : bool
        False sets the FMU's friction coefficient and seal torque to zero: the
        same manoeuvre without bearing friction.
    progress : bool
        Show the progress on stderr (tqdm's bar on a terminal, plain lines otherwise).
    logger : callable, optional
        Called with every FMU log message (str); the last ones are also quoted
        in the error raised when the co-simulation fails.
    coupling : {"sequential", "parallel", "parallel-zero-start"}
        Order of the exchanges within a communication step.

        * ``"sequential"`` (default): the bearing steps first, and the drive
          uses the friction torque the bearing has just returned for this step
          (Gauss-Seidel).
        * ``"parallel"``: the drive and the bearing step side by side on the
          values of the last communication point (Jacobi), as the SSP hosts
          libcosim and ecos do: the drive uses the friction torque of the
          bearing's previous step (at the first step, the one the bearing
          returned after its initialisation with the first loads).
        * ``"parallel-zero-start"``: ``"parallel"``, but every exchanged value
          is 0 in the first step and during the bearing's initialisation (the
          drive holds a load moment of 0), as fmpy 0.3.32's ``simulate_ssp``
          does: it starts every connection at 0 and exchanges values only after
          each step.

    Returns
    -------
    ManoeuvreResult
    """
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu_path)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    types = {v.name: v.type for v in md.modelVariables}
    unzipped = extract(fmu_path)
    messages = []

    def log(component, instance, status, category, message):
        text = message.decode(errors="replace")
        messages.append(text)
        if logger is not None:
            logger(text)

    callbacks = logging_callbacks(log)

    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="bearing")
    steps = int(round(t_end / dt))
    time = np.arange(steps) * dt
    out = {name: np.empty(steps) for name in OUTPUTS}
    angle, speed, motor, ring, mz, cmd = (np.empty(steps) for _ in range(6))
    if coupling not in ("sequential", "parallel", "parallel-zero-start"):
        raise ValueError(f"coupling = {coupling!r}: must be 'sequential', 'parallel' or 'parallel-zero-start'")
    zero_start = coupling == "parallel-zero-start"
    values = dict(start_values or {})
    if not friction:
        values.update(friction_coefficient=0.0, seal_torque=0.0)
    sim = ElectricDrive(drive)
    sim.hold(0.0 if zero_start else loads.at(0.0)[5])
    k = 0
    try:
        fmu.instantiate(loggingOn=True, callbacks=callbacks)
        fmu.setupExperiment(startTime=0.0)
        for name, value in values.items():
            (fmu.setInteger if types[name] == "Integer" else fmu.setReal)([refs[name]], [value])
        fmu.enterInitializationMode()
        if not zero_start:
            _set_inputs(fmu, refs, loads.at(0.0), sim.state.angle, sim.state.speed)
        fmu.exitInitializationMode()
        held = 0.0  # parallel coupling: the bearing's friction torque at the last communication point
        if coupling == "parallel":
            held = fmu.getReal([refs["friction_torque_magnitude"]])[0]
        iterator = range(steps)
        if progress:
            from slewing_model.progress import progress_bar   # a bar on a terminal, plain lines in a file

            iterator = progress_bar(desc=f"{drive.name}", unit="step", leave=False, iterable=iterator)
        out_refs = [refs[n] for n in OUTPUTS]
        for k in iterator:
            t = time[k]
            first_zero = zero_start and k == 0
            load = np.zeros(6) if first_zero else loads.at(t)
            _set_inputs(fmu, refs, load, sim.state.angle, sim.state.speed)
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
            for name, value in zip(OUTPUTS, fmu.getReal(out_refs)):
                out[name][k] = value
            cmd[k] = 0.0 if first_zero else command(t)
            friction_torque = out["friction_torque_magnitude"][k]
            if coupling != "sequential":
                friction_torque, held = held, friction_torque
            s = sim.step(cmd[k], dt, load_torque=load[5], friction_torque=friction_torque)
            angle[k], speed[k], motor[k], ring[k], mz[k] = (s.angle, s.speed, s.mean_motor_torque,
                                                           drive.torque_gain * s.mean_motor_torque, load[5])
        fmu.terminate()
    except Exception as exc:
        detail = "\n".join(messages[-5:])
        raise RuntimeError(f"co-simulation failed at t = {time[k]:.3f} s: {exc}\n"
                           f"FMU log:\n{detail}") from None
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    return ManoeuvreResult(time + dt, cmd, angle, speed, motor, ring, mz, out, sim.state.motor_energy, drive)


def logging_callbacks(log):
    """fmpy FMI 2.0 callbacks whose logger is ``log(component, instance, status, category, message)``.
    Keep the returned object alive as long as the FMU instance: the FMU holds pointers into it."""
    from fmpy import calloc, free
    from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                           fmi2CallbackLoggerTYPE)

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(log)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    return callbacks


def _set_inputs(fmu, refs, load, psi, omega):
    fmu.setReal([refs[n] for n in INPUTS], [*map(float, load[:5]), float(psi), float(omega)])


def plot_manoeuvre(result: ManoeuvreResult, path, *, without_friction: ManoeuvreResult | None = None,
                   title: str = "") -> None:
    """Five panels: angle and command; motor torque and its limit; bearing friction torque (from
    zero, so that its ripple is seen at its true size); its share of the motors' torque at the ring
    while they drive the ring (:func:`friction_share`); maximum ball load and static safety factor."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r = result
    fig, ax = plt.subplots(5, 1, figsize=(9, 13), sharex=True,
                           gridspec_kw={"height_ratios": [1, 1, 1, 0.7, 1]})
    ax[0].plot(r.time, np.degrees(r.command), "k--", label="command")
    ax[0].plot(r.time, np.degrees(r.angle), label="angle, with bearing friction")
    if without_friction is not None:
        ax[0].plot(without_friction.time, np.degrees(without_friction.angle), ":", label="angle, friction off")
    ax[0].set_ylabel("angle [deg]")
    ax[0].legend(loc="best")
    ax[1].plot(r.time, r.motor_torque, label="motor torque")
    if without_friction is not None:
        ax[1].plot(without_friction.time, without_friction.motor_torque, ":", label="motor torque, friction off")
    for sign in (1, -1):
        ax[1].axhline(sign * r.params.torque_limit, color="r", lw=0.8, label="torque limit" if sign > 0 else None)
    ax[1].set_ylabel("motor torque [N m]")
    ax[1].legend(loc="best")
    ax[2].plot(r.time, r.friction_torque / 1e3, label="bearing friction torque (full sliding)")
    ax[2].set_ylabel("friction [kN m]")
    ax[2].set_ylim(0, 1.15 * max(float(np.max(r.friction_torque)) / 1e3, 1e-9))   # from zero: the ripple at scale
    ax[2].legend(loc="lower right", fontsize=8)
    # the share of the motors' torque at the ring that the bearing friction takes, while the motors drive
    # the ring through the friction (at most 100 % by construction); gaps: at rest, or the load drives
    ax[3].plot(r.time, friction_share(r), "g", lw=1.6,
               label="bearing friction / motors' torque at the ring, while the motors drive the ring "
                     "(gaps: at rest, or the load drives)")
    ax[3].set_ylim(0, 130)           # room above 100 % for the legend
    ax[3].set_yticks([0, 25, 50, 75, 100])
    ax[3].set_ylabel("friction share [%]")
    ax[3].legend(loc="upper left", fontsize=7)
    ax[4].plot(r.time, r.outputs["max_ball_load"] / 1e3, label="max ball load (left axis)")
    ax[4].set_ylabel("max ball load [kN]")
    sf = ax[4].twinx()
    sf.plot(r.time, r.outputs["static_safety_factor"], "m", lw=0.8, label="static safety factor (right axis)")
    sf.set_ylabel("static safety factor", color="m")
    lines, labels = ax[4].get_legend_handles_labels()
    more, more_labels = sf.get_legend_handles_labels()
    low, high = ax[4].get_ylim()
    ax[4].set_ylim(low, high + 0.35 * (high - low))     # room above the curves for the legend
    low, high = sf.get_ylim()
    sf.set_ylim(low, high + 0.35 * (high - low))
    ax[4].legend(lines + more, labels + more_labels, loc="upper center", ncol=2, fontsize=8)
    ax[4].set_xlabel("time [s]")
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def friction_share(result: ManoeuvreResult) -> np.ndarray:
    """Bearing friction torque over the torque of the drive's motors at the ring, %, at every step the
    motors drive the ring through the friction: the ring moves (speed above 1e-3 of the rate limit) and
    the ring torque acts in the direction of motion and is at least the friction torque. NaN elsewhere
    (at rest, or where the load moment moves the ring and the ratio would say nothing)."""
    moving = np.abs(result.speed) > 1e-3 * result.params.rate_limit
    pushing = result.ring_torque * np.sign(result.speed) >= result.friction_torque
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(moving & pushing, 100 * result.friction_torque / np.abs(result.ring_torque), np.nan)


def summary_table(with_friction: ManoeuvreResult, without: ManoeuvreResult | None = None) -> str:
    """Markdown table of :meth:`ManoeuvreResult.summary`, with and without bearing friction."""
    a = with_friction.summary()
    b = without.summary() if without is not None else None
    head = "| quantity | with bearing friction |" + (" friction off |" if b else "")
    lines = [head, "|---|---|" + ("---|" if b else "")]
    for key in a:
        lines.append(f"| {key} | {a[key]:.3g} |" + (f" {b[key]:.3g} |" if b else ""))
    return "\n".join(lines)


def write_csv(result: ManoeuvreResult, path, without: ManoeuvreResult | None = None) -> None:
    """Time histories as CSV (angles in deg, torques in N m, loads in N)."""
    import csv

    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["time_s", "command_deg", "angle_deg", "motor_torque_Nm", "friction_torque_Nm", "max_ball_load_N",
                    "static_safety_factor"] + (["angle_no_friction_deg", "motor_torque_no_friction_Nm"] if without else []))
        for k in range(len(result.time)):
            row = [f"{result.time[k]:.3f}", f"{np.degrees(result.command[k]):.5f}", f"{np.degrees(result.angle[k]):.5f}",
                   f"{result.motor_torque[k]:.4f}", f"{result.friction_torque[k]:.2f}",
                   f"{result.outputs['max_ball_load'][k]:.1f}", f"{result.outputs['static_safety_factor'][k]:.4f}"]
            if without is not None:
                row += [f"{np.degrees(without.angle[k]):.5f}", f"{without.motor_torque[k]:.4f}"]
            w.writerow(row)
