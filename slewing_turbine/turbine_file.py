"""Turbine files: one closed-loop case of :func:`slewing_turbine.loop.run_turbine` as TOML.

A turbine file names the turbine's files, the controller's settings, each blade's pitch drive and pitch
bearing, the wind and the run (units in the key names, angles in degrees; relative paths are relative to
the file's folder)::

    [case]
    name = "nrel5mw-13mps"              # optional: the file's name
    description = "..."                 # optional

    [turbine]
    directory = "nrel5mw"               # ROSCO's DISCON.IN, the Cp table and rotor.toml are in it
    discon = "DISCON.IN"                # file names in `directory` (these are the defaults)
    cp_table = "Cp_Ct_Cq.NREL5MW.txt"
    rotor = "rotor.toml"
    aero = "bem"                        # "bem" (each blade, root loads) or "cp_table" (ROSCO's Sim: no loads)
    shear_exponent = 0.2                # power-law shear over the rotor (aero = "bem")

    [controller]
    ipc = false                         # individual pitch control (1P): IPC_ControlMode 1 with ipc_ki
    ipc_ki = [1e-8, 0.0]                # IPC_KI (1P, 2P) when ipc = true; optional ipc_kp likewise
    emergency_stop_s = 30.0             # optional: from this time on, feather (90 deg) and no generator torque
    [controller.overrides]              # any other parameter of DISCON.IN, by its name
    PC_MaxRat = 0.1396

    [pitch]
    drives = "electric"                 # "electric" (a drive per blade) or "ideal" (at the demand: no drive)
    drive = "../drives/pitch_drive_nrel5mw.toml"         # one file for the three blades (the loop runs one)
    bearing = "../bearings/pitch_bearing_nrel5mw.toml"    # one file, or a list of three (one per blade)
    ring_model = "rigid"                # "rigid", "flexible" or "none" (no bearing: no friction)
    mesh = "coarse"                     # flexible rings' superelement mesh ("coarse", "fine")
    friction = true                     # the bearings' friction on or off
    friction_coefficient = 0.1
    seal_torque_Nm = 0.0
    life = false                        # each bearing's raceway damage map
    step_work = "complete"              # the bearings' steps: "complete" (to the tolerance) or "bounded"
    drive_substeps = 10
    continuous_torque_share = 0.4       # a motor's continuous torque over its peak (the duty figure)

    [wind]
    kind = "kaimal"                     # "steady", "step", "kaimal", "eog" or "file"
    speed_m_s = 13.0                    # steady, kaimal and eog: the (mean) hub speed; step: before the step
    seed = 1                            # kaimal
    turbulence_class = "B"              # kaimal and eog: "A+", "A", "B", "C"
    # step: speed_after_m_s, step_time_s;  eog: gust_start_s, wind_class ("I", "II", "III");
    # file: file = "wind.hh" (two columns time, speed or OpenFAST's uniform wind file)

    [simulation]
    t_end_s = 60.0
    dt_s = 0.01                         # the loop's and the controller's step
    rotor_speed_init_rpm = 10.0         # optional: the start (ROSCO's Sim: 10 rpm, 0 deg)
    pitch_init_deg = 0.0
    settle_s = 20.0                     # optional: s left out of the figures (default 20 s, at most half the run)

Every table refuses a key it does not know, and every value is checked when the file is read: the message
names the file, the key, the value and the rule (:class:`TurbineDefinitionError`, a :class:`ValueError`).
:func:`load_turbine` reads a file, :func:`turbine_from_dict` a dict of the same layout (a study's case),
:meth:`TurbineCase.run` runs it.
"""
from __future__ import annotations

import copy
import dataclasses
import difflib
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from slewing_model.bearing.conventions import definition_message

#: the tables of a turbine file and the keys each one knows (names are case-sensitive)
TABLES = {
    "case": ("name", "description"),
    "turbine": ("directory", "discon", "cp_table", "rotor", "aero", "hub_height_m", "shear_exponent"),
    "controller": ("ipc", "ipc_ki", "ipc_kp", "emergency_stop_s", "overrides"),
    "pitch": ("drives", "drive", "bearing", "ring_model", "mesh", "friction", "friction_coefficient",
              "seal_torque_Nm", "life", "step_work", "drive_substeps", "continuous_torque_share"),
    "wind": ("kind", "speed_m_s", "seed", "turbulence_class", "wind_class", "speed_after_m_s", "step_time_s",
             "gust_start_s", "file"),
    "simulation": ("t_end_s", "dt_s", "rotor_speed_init_rpm", "pitch_init_deg", "settle_s"),
}
#: the wind keys each kind takes (``kind`` itself aside)
WIND_KEYS = {
    "steady": ("speed_m_s",),
    "step": ("speed_m_s", "speed_after_m_s", "step_time_s"),
    "kaimal": ("speed_m_s", "seed", "turbulence_class"),
    "eog": ("speed_m_s", "gust_start_s", "wind_class", "turbulence_class"),
    "file": ("file",),
}
#: IPC on: ROSCO's 1P individual pitch control with the integral gain of ROSCO's NREL 5MW pass-through tuning
IPC_KI_DEFAULT = (1e-8, 0.0)
TURBULENCE_CLASSES = ("A+", "A", "B", "C")
WIND_CLASSES = ("I", "II", "III")
RING_MODELS = ("rigid", "flexible", "none")


class TurbineDefinitionError(ValueError):
    """A turbine file breaks a rule; the message names the file, the key, the value and the rule."""


def _fail(key: str, value: Any, rule: str):
    raise TurbineDefinitionError(definition_message(key, value, rule))


def _known(table: Mapping, where: str, known) -> None:
    """Refuse a key of ``table`` that is not in ``known`` (``where``: the table's dotted name, ``""`` for the
    file's top level), naming the table, the key, its value and the known keys."""
    from slewing_model.study.definition import refuse_unknown

    refuse_unknown(table, f"{where}." if where else "", known, TurbineDefinitionError)


def _table(data: Mapping, name: str) -> Mapping:
    value = data.get(name, {})
    if not isinstance(value, Mapping):
        _fail(name, value, "must be a table")
    _known(value, name, TABLES[name])
    return value


def _number(table: Mapping, key: str, default=None, minimum=None, exclusive=False, maximum=None):
    short = key.rsplit(".", 1)[-1]
    value = table.get(short, default)
    if value is None:
        _fail(key, None, "missing key (required)")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        _fail(key, value, "must be a finite number")
    if minimum is not None and (value <= minimum if exclusive else value < minimum):
        _fail(key, value, f"must be {'>' if exclusive else '>='} {minimum:g}")
    if maximum is not None and value > maximum:
        _fail(key, value, f"must be <= {maximum:g}")
    return float(value)


def _integer(table: Mapping, key: str, default=None, minimum=None) -> int:
    short = key.rsplit(".", 1)[-1]
    value = table.get(short, default)
    if value is None:
        _fail(key, None, "missing key (required)")
    if isinstance(value, bool) or not isinstance(value, int):
        _fail(key, value, "must be a whole number")
    if minimum is not None and value < minimum:
        _fail(key, value, f"must be >= {minimum}")
    return value


def _boolean(table: Mapping, key: str, default: bool) -> bool:
    value = table.get(key.rsplit(".", 1)[-1], default)
    if not isinstance(value, bool):
        _fail(key, value, "must be true or false")
    return value


def _string(table: Mapping, key: str, default=None, choices=None) -> str:
    value = table.get(key.rsplit(".", 1)[-1], default)
    if value is None:
        _fail(key, None, "missing key (required)")
    if not isinstance(value, str) or not value:
        _fail(key, value, "must be a non-empty string")
    if choices is not None and value not in choices:
        _fail(key, value, f"must be one of {', '.join(map(repr, choices))}")
    return value


def _file(base_dir: str, key: str, value: Any, what: str) -> str:
    if not isinstance(value, str) or not value:
        _fail(key, value, f"must be a file name ({what})")
    path = os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))
    if not os.path.isfile(path):
        _fail(key, value, f"no such file: {path} ({what})")
    return path


def _gains(table: Mapping, key: str, default) -> list:
    value = table.get(key.rsplit(".", 1)[-1], default)
    if (not isinstance(value, (list, tuple)) or len(value) != 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)):
        _fail(key, value, "must be two finite numbers (1P, 2P)")
    return [float(v) for v in value]


@dataclass
class TurbineCase:
    """A validated turbine file (SI units, absolute paths). :meth:`run` runs it.

    Attributes
    ----------
    name, description : str
    path : str
        The file it was read from (``"<dict>"`` for a dict).
    turbine_dir, discon, cp_table, rotor : str
        The turbine's folder and its files' names in it.
    aero : {"bem", "cp_table"}
    hub_height : float or None, m
    shear_exponent : float
    discon_overrides : dict
        DISCON.IN parameters replaced for this case (IPC's included).
    ipc : bool
    drives : {"electric", "ideal"}
    drive : str
        The pitch drive file (the three blades').
    bearings : list of 3 str
        Each blade's pitch bearing file.
    ring_model : {"rigid", "flexible", "none"}
    mesh : str
    friction : bool
    friction_coefficient, seal_torque : float
    life : bool
    step_work : {"complete", "bounded"}
    drive_substeps : int
    continuous_torque_share : float
    wind : dict
        ``kind`` and its values (SI; ``file`` absolute).
    t_end, dt : float, s
    rotor_speed_init, pitch_init : float or None, rad/s, rad (None: the loop's default)
    settle : float or None, s
        Left out of the figures (None: the loop's default, :data:`slewing_turbine.loop.SETTLE_DEFAULT`).
    emergency_stop : float or None, s
        The emergency stop's time (None: none).
    """

    name: str
    description: str
    path: str
    turbine_dir: str
    discon: str
    cp_table: str
    rotor: str
    aero: str
    hub_height: float | None
    shear_exponent: float
    discon_overrides: dict
    ipc: bool
    drives: str
    drive: str
    bearings: list
    ring_model: str
    mesh: str
    friction: bool
    friction_coefficient: float
    seal_torque: float
    life: bool
    step_work: str
    drive_substeps: int
    continuous_torque_share: float
    wind: dict
    t_end: float
    dt: float
    rotor_speed_init: float | None = None
    pitch_init: float | None = None
    settle: float | None = None
    emergency_stop: float | None = None
    data: dict = field(default_factory=dict, repr=False)

    # ---- what the loop takes ----

    @property
    def bearing_model(self) -> str | None:
        """``bearings`` of :func:`run_turbine`: None without a bearing (ideal drives, ``ring_model`` none), and
        with friction off and no life map: such a bearing would give its drive nothing but a zero friction
        torque, so it is not stepped (the same run, three to four times faster)."""
        if self.drives == "ideal" or self.ring_model == "none" or not (self.friction or self.life):
            return None
        return self.ring_model

    def config(self):
        """The :class:`~slewing_turbine.loop.TurbineConfig` of this case."""
        from .loop import TurbineConfig

        kw = dict(turbine_dir=Path(self.turbine_dir), discon=self.discon, cp_table=self.cp_table, rotor=self.rotor,
                  discon_overrides=dict(self.discon_overrides) or None, step_work=self.step_work,
                  drive=Path(self.drive), drive_substeps=self.drive_substeps, bearing=Path(self.bearings[0]),
                  mesh=self.mesh, friction_coefficient=self.friction_coefficient, seal_torque=self.seal_torque,
                  life=self.life, hub_height=self.hub_height, shear_exponent=self.shear_exponent,
                  continuous_torque_share=self.continuous_torque_share, settle=self.settle)
        if self.rotor_speed_init is not None:
            kw["rotor_speed_init"] = self.rotor_speed_init
        if self.pitch_init is not None:
            kw["pitch_init"] = self.pitch_init
        return TurbineConfig(**kw)

    def hub_height_for_wind(self) -> float:
        """The hub height the turbulence scale is taken at, m: ``hub_height_m``, else the rotor file's."""
        if self.hub_height is not None:
            return self.hub_height
        import tomllib

        with open(os.path.join(self.turbine_dir, self.rotor), "rb") as fh:
            return float(tomllib.load(fh).get("rotor", {}).get("hub_height_m", 90.0))

    def wind_series(self):
        """The hub-height wind (:mod:`slewing_turbine.wind`) from 0 to at least ``t_end`` at the step ``dt``."""
        from . import wind as w

        spec, duration, dt = self.wind, self.t_end, self.dt
        kind = spec["kind"]
        if kind == "steady":
            return w.steady(spec["speed_m_s"], duration, dt)
        if kind == "step":
            return w.step_change(spec["speed_m_s"], spec["speed_after_m_s"], spec["step_time_s"], duration, dt)
        if kind == "kaimal":
            return w.kaimal(spec["speed_m_s"], duration, dt, seed=spec["seed"],
                            turbulence_class=spec["turbulence_class"], hub_height=self.hub_height_for_wind())
        if kind == "eog":
            return w.extreme_operating_gust(spec["speed_m_s"], spec["gust_start_s"], duration, dt,
                                            wind_class=spec["wind_class"], turbulence_class=spec["turbulence_class"],
                                            hub_height=self.hub_height_for_wind())
        series = w.read_wind(spec["file"])
        if series.time[-1] < duration - 1e-9:
            raise ValueError(f"{self.path}: wind.file = {spec['file']!r} ends at {series.time[-1]:g} s, before "
                             f"simulation.t_end_s = {duration:g}")
        return series

    def run(self, *, progress: bool = False):
        """Run the case (:func:`slewing_turbine.loop.run_turbine`): the :class:`TurbineResult`."""
        from . import loop

        config = self.config()
        wind = self.wind_series()
        bearings = self.bearing_model
        sims = None
        if bearings is not None and len(set(self.bearings)) > 1:     # a bearing file per blade
            sims = [loop.make_bearings(dataclasses.replace(config, bearing=Path(f)), bearings, self.friction, 1)[0]
                    for f in self.bearings]
        return loop.run_turbine(config, wind, t_end=self.t_end, dt=self.dt, drives=self.drives, bearings=bearings,
                                friction=self.friction, aero=self.aero, bearing_simulators=sims, progress=progress,
                                emergency_stop=self.emergency_stop)

    def describe(self) -> dict:
        """The case as plain data (JSON): every setting, paths absolute."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "data"}
        out["wind"] = dict(self.wind)
        return out


# ---- reading -------------------------------------------------------------------------------------

def load_turbine(path, *, overrides: Mapping | None = None) -> TurbineCase:
    """Read and validate a turbine file.

    Parameters
    ----------
    path : str or path-like
        The file (TOML, the layout of the module docstring); relative paths in it are relative to its folder.
    overrides : mapping, optional
        ``{"table.key": value}`` replacing the file's values before validation (a study's axes; e.g.
        ``{"wind.speed_m_s": 8.0, "controller.ipc": True}``).

    Returns
    -------
    TurbineCase

    Raises
    ------
    TurbineDefinitionError
        Naming the file, the key, the value and the rule (also for a missing or malformed file).
    """
    from slewing_model.study.definition import read_toml

    path = os.fspath(path)
    data = read_toml(path, TurbineDefinitionError, "turbine file")
    try:
        return turbine_from_dict(apply_overrides(data, overrides or {}), os.path.dirname(os.path.abspath(path)),
                                 path)
    except TurbineDefinitionError as exc:
        raise TurbineDefinitionError(f"{path}: {exc}") from None


def apply_overrides(data: Mapping, overrides: Mapping) -> dict:
    """A copy of ``data`` with ``{"table.key": value}`` set (the table created where missing)."""
    out = copy.deepcopy(dict(data))
    for dotted, value in overrides.items():
        table, _, key = str(dotted).partition(".")
        if not key or table not in TABLES or "." in key:
            raise TurbineDefinitionError(definition_message(
                str(dotted), value, f"must name a key of a table ({', '.join(f'[{t}]' for t in TABLES)}) as "
                                    f"\"table.key\""))
        if key not in TABLES[table]:
            raise TurbineDefinitionError(definition_message(
                str(dotted), value, f"unknown key in table [{table}] (known: {', '.join(sorted(TABLES[table]))})"))
        target = out.setdefault(table, {})
        if not isinstance(target, dict):
            raise TurbineDefinitionError(definition_message(table, target, "must be a table"))
        target[key] = value
    return out


def turbine_from_dict(data: Mapping[str, Any], base_dir: str | os.PathLike = ".", path: str = "<dict>") -> TurbineCase:
    """Validate the layout of a turbine file (as :func:`load_turbine` reads it); relative paths against
    ``base_dir``. Raises :class:`TurbineDefinitionError`."""
    base_dir = os.fspath(base_dir)
    _known(data, "", TABLES)
    for name in ("turbine", "wind", "simulation"):
        if name not in data:
            _fail(name, None, f"missing table [{name}] (required)")
    case, turbine, controller = _table(data, "case"), _table(data, "turbine"), _table(data, "controller")
    pitch, wind, simulation = _table(data, "pitch"), _table(data, "wind"), _table(data, "simulation")

    name = _string(case, "case.name", default=os.path.splitext(os.path.basename(path))[0] or "turbine")
    description = case.get("description", "")
    if not isinstance(description, str):
        _fail("case.description", description, "must be a string")

    # ---- [turbine] ----
    directory = turbine.get("directory")
    if directory is None:
        _fail("turbine.directory", None, "missing key (required): the folder of DISCON.IN, the Cp table and rotor.toml")
    if not isinstance(directory, str) or not os.path.isdir(os.path.join(base_dir, directory)):
        _fail("turbine.directory", directory, f"must be a folder (relative to {base_dir})")
    turbine_dir = os.path.normpath(os.path.join(base_dir, directory))
    files = {}
    for key, default, what in (("discon", "DISCON.IN", "ROSCO's parameter file"),
                               ("cp_table", "Cp_Ct_Cq.NREL5MW.txt", "the rotor's performance table"),
                               ("rotor", "rotor.toml", "the rotor's geometry")):
        value = turbine.get(key, default)
        _file(turbine_dir, f"turbine.{key}", value, f"{what}, in turbine.directory")
        files[key] = value
    aero = _string(turbine, "turbine.aero", default="bem", choices=("bem", "cp_table"))
    hub_height = (_number(turbine, "turbine.hub_height_m", minimum=0.0, exclusive=True)
                  if "hub_height_m" in turbine else None)
    shear_exponent = _number(turbine, "turbine.shear_exponent", default=0.2, minimum=0.0, maximum=1.0)

    # ---- [controller] ----
    ipc = _boolean(controller, "controller.ipc", False)
    if not ipc:
        for key in ("ipc_ki", "ipc_kp"):
            if key in controller:
                _fail(f"controller.{key}", controller[key], "only with controller.ipc = true")
    overrides = {}
    if ipc:
        overrides["IPC_ControlMode"] = 1
        overrides["IPC_KI"] = _gains(controller, "controller.ipc_ki", list(IPC_KI_DEFAULT))
        if "ipc_kp" in controller:
            overrides["IPC_KP"] = _gains(controller, "controller.ipc_kp", None)
    emergency_stop = (_number(controller, "controller.emergency_stop_s", minimum=0.0)
                      if "emergency_stop_s" in controller else None)
    raw = controller.get("overrides", {})
    if not isinstance(raw, Mapping):
        _fail("controller.overrides", raw, "must be a table of DISCON.IN parameters")
    if raw:
        from .controller import read_discon

        known = read_discon(os.path.join(turbine_dir, files["discon"]))
        for key, value in raw.items():
            if key not in known:
                close = difflib.get_close_matches(key, list(known), n=1)
                _fail(f"controller.overrides.{key}", value,
                      f"{files['discon']} has no parameter {key!r}" + (f" (did you mean {close[0]!r}?)" if close
                                                                      else " (names are case-sensitive)"))
            ok = (isinstance(value, str) or (isinstance(value, (int, float)) and math.isfinite(value)) or
                  (isinstance(value, list) and value and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                             and math.isfinite(v) for v in value)))
            if not ok:
                _fail(f"controller.overrides.{key}", value, "must be a number, a list of numbers or a string")
            if key in overrides:
                _fail(f"controller.overrides.{key}", value, "set by controller.ipc: give it there")
            overrides[key] = value

    # ---- [pitch] ----
    drives = _string(pitch, "pitch.drives", default="electric", choices=("electric", "ideal"))
    drive_files = pitch.get("drive", os.path.join(_repo_examples(), "drives", "pitch_drive_nrel5mw.toml"))
    drive_list = drive_files if isinstance(drive_files, list) else [drive_files]
    if len(drive_list) not in (1, 3):
        _fail("pitch.drive", drive_files, "must be one file (the three blades) or a list of three")
    drive_paths = [_file(base_dir, "pitch.drive", f, "a pitch drive file") for f in drive_list]
    if len(set(drive_paths)) > 1:
        _fail("pitch.drive", drive_files, "the loop runs the same drive on the three blades: give one file")
    bearing_files = pitch.get("bearing")
    if bearing_files is None:
        bearing_files = os.path.join(_repo_examples(), "bearings", "pitch_bearing_nrel5mw.toml")
    bearing_list = bearing_files if isinstance(bearing_files, list) else [bearing_files]
    if len(bearing_list) not in (1, 3):
        _fail("pitch.bearing", bearing_files, "must be one file (the three blades) or a list of three (one per blade)")
    bearing_paths = [_file(base_dir, "pitch.bearing", f, "a pitch bearing file") for f in bearing_list] * (
        3 if len(bearing_list) == 1 else 1)
    ring_model = _string(pitch, "pitch.ring_model", default="rigid", choices=RING_MODELS)
    if ring_model != "none" and drives == "electric" and aero == "cp_table":
        _fail("pitch.ring_model", ring_model, "a bearing needs turbine.aero = 'bem' (the Cp table gives no "
                                              "blade-root loads): give 'none'")
    mesh = _string(pitch, "pitch.mesh", default="coarse", choices=("coarse", "fine"))
    friction = _boolean(pitch, "pitch.friction", True)
    mu = _number(pitch, "pitch.friction_coefficient", default=0.1, minimum=0.0)
    seal = _number(pitch, "pitch.seal_torque_Nm", default=0.0, minimum=0.0)
    life = _boolean(pitch, "pitch.life", False)
    if life and (drives == "ideal" or ring_model == "none"):
        _fail("pitch.life", life, "needs a bearing (pitch.drives = 'electric' and a pitch.ring_model)")
    step_work = _string(pitch, "pitch.step_work", default="complete", choices=("complete", "bounded"))
    substeps = _integer(pitch, "pitch.drive_substeps", default=10, minimum=1)
    share = _number(pitch, "pitch.continuous_torque_share", default=0.4, minimum=0.0, exclusive=True, maximum=1.0)
    if ring_model != "none" and drives == "electric":
        from slewing_model import BearingDefinitionError, load_bearing

        for f in dict.fromkeys(bearing_paths):
            try:
                load_bearing(f)
            except BearingDefinitionError as exc:
                _fail("pitch.bearing", f, f"not a valid bearing file: {exc}")

    # ---- [wind] ----
    kind = _string(wind, "wind.kind", choices=tuple(WIND_KEYS))
    allowed = WIND_KEYS[kind]
    for key in wind:
        if key != "kind" and key not in allowed:
            _fail(f"wind.{key}", wind[key], f"not a key of wind.kind = {kind!r} (its keys: {', '.join(allowed)})")
    spec: dict = {"kind": kind}
    if kind == "file":
        spec["file"] = _file(base_dir, "wind.file", wind.get("file"), "a wind series: time, speed columns or "
                                                                      "OpenFAST's uniform wind file")
    else:
        spec["speed_m_s"] = _number(wind, "wind.speed_m_s", minimum=0.0, exclusive=kind in ("kaimal", "eog"))
    if kind == "step":
        spec["speed_after_m_s"] = _number(wind, "wind.speed_after_m_s", minimum=0.0)
        spec["step_time_s"] = _number(wind, "wind.step_time_s", minimum=0.0, exclusive=True)
    if kind == "kaimal":
        spec["seed"] = _integer(wind, "wind.seed", minimum=0)
    if kind in ("kaimal", "eog"):
        spec["turbulence_class"] = _string(wind, "wind.turbulence_class", default="B", choices=TURBULENCE_CLASSES)
    if kind == "eog":
        spec["wind_class"] = _string(wind, "wind.wind_class", default="I", choices=WIND_CLASSES)
        spec["gust_start_s"] = _number(wind, "wind.gust_start_s", minimum=0.0)

    # ---- [simulation] ----
    t_end = _number(simulation, "simulation.t_end_s", minimum=0.0, exclusive=True)
    dt = _number(simulation, "simulation.dt_s", default=0.01, minimum=0.0, exclusive=True)
    if dt > 0.1:
        _fail("simulation.dt_s", dt, "must be <= 0.1 s (the controller's step)")
    if t_end < 2 * dt:
        _fail("simulation.t_end_s", t_end, f"must be at least two steps of dt_s = {dt:g}")
    if kind == "step" and spec["step_time_s"] >= t_end:
        _fail("wind.step_time_s", spec["step_time_s"], f"must lie before simulation.t_end_s = {t_end:g}")
    if kind == "eog" and spec["gust_start_s"] + 10.5 > t_end + 1e-9:
        _fail("wind.gust_start_s", spec["gust_start_s"], f"the gust (10.5 s) must end by simulation.t_end_s = "
                                                          f"{t_end:g}")
    rotor_speed_init = (_number(simulation, "simulation.rotor_speed_init_rpm", minimum=0.0) * math.pi / 30.0
                        if "rotor_speed_init_rpm" in simulation else None)
    settle = (_number(simulation, "simulation.settle_s", minimum=0.0) if "settle_s" in simulation else None)
    if settle is not None and settle >= t_end:
        _fail("simulation.settle_s", settle, f"must be shorter than simulation.t_end_s = {t_end:g} (the figures' "
                                             f"window is what follows it)")
    if emergency_stop is not None and emergency_stop >= t_end:
        _fail("controller.emergency_stop_s", emergency_stop, f"must lie before simulation.t_end_s = {t_end:g}")
    pitch_init = (math.radians(_number(simulation, "simulation.pitch_init_deg", minimum=-10.0, maximum=90.0))
                  if "pitch_init_deg" in simulation else None)

    return TurbineCase(name=name, description=description, path=str(path), turbine_dir=turbine_dir,
                       discon=files["discon"], cp_table=files["cp_table"], rotor=files["rotor"], aero=aero,
                       hub_height=hub_height, shear_exponent=shear_exponent, discon_overrides=overrides, ipc=ipc,
                       drives=drives, drive=drive_paths[0], bearings=bearing_paths, ring_model=ring_model, mesh=mesh,
                       friction=friction, friction_coefficient=mu, seal_torque=seal, life=life, step_work=step_work,
                       drive_substeps=substeps, continuous_torque_share=share, wind=spec, t_end=t_end, dt=dt,
                       rotor_speed_init=rotor_speed_init, pitch_init=pitch_init, settle=settle,
                       emergency_stop=emergency_stop, data=copy.deepcopy(dict(data)))


def _repo_examples() -> str:
    """The repository's ``examples`` folder (the default pitch drive and bearing)."""
    return str(Path(__file__).resolve().parents[1] / "examples")
