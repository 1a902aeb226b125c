"""Study files: reading, validation and expansion into cases.

A study file (TOML) lists the cases of a study as a product of load series and
bearing variants::

    [study]
    name = "nrel5mw-pitch"
    base_dir = "../.."            # relative paths below are resolved against it
                                  # (itself relative to the study file; default ".")

    [[loads]]                     # an OpenFAST / FAST output file
    openfast = "../shared/data/openfast/pCrunch_Test3.NREL5MW_OC3Hywind_FASTv7_600s.outb"
    bearing = "pitch"             # "pitch" or "yaw"
    blades = [1, 2, 3]            # pitch: one series per blade (default [1])
    t_start_s = 60.0              # optional time window, s
    t_end_s = 660.0
    every = 1                     # optional: keep every n-th sample

    [[loads]]                     # our CSV: time,Fx,Fy,Fz,Mx,My[,Mz][,psi,omega] (SI)
    csv = "examples/loads/blade_root_loads.csv"
    omega_rad_s = 0.0             # files without psi/omega: psi = omega t

    [[loads]]                     # constant loads with a steady rotation (idling)
    name = "idling"
    constant = [0, 0, 0, 0, 0, 0] # Fx, Fy, Fz [N], Mx, My, Mz [N m]
    omega_rad_s = 0.05
    duration_s = 125.7
    steps = 72

    [bearings]                    # every list is one axis of the product
    files = ["examples/bearings/table3.toml"]
    ring_model = ["rigid"]        # "rigid" and/or "flexible"
    preload_um = [0, 20, 40]      # optional, default: the bearing file's
    friction_coefficient = [0.1]
    error_seeds = {first = 1, count = 200}   # or a list; optional
    [bearings.synthetic_errors]   # amplitudes of the seeded errors, as [errors.synthetic]
    waviness_orders = [2, 3, 4, 5]             # of a bearing file without its seed
    radial_amplitude_um = [3.0, 2.0, 1.5, 1.0]

    [simulation]                  # optional, the simulator's settings
    mesh = "coarse"               # superelement of flexible rings
    bc = "free"

Each load entry may also give ``name``, ``load_frame`` (``"fixed"`` or
``"rotating"``: the frame the loads are given in, turning with ``psi`` or not).
OpenFAST loads are turned into the frame asked for by
:func:`slewing_model.loads.aeroelastic.bearing_loads` (default ``"rotating"``: the
blade's frame for a pitch bearing, the nacelle's for a yaw bearing). A CSV file
may state its frame in a ``# load_frame = ...`` comment (a study frame that
contradicts it is refused); default ``"fixed"``. OpenFAST entries may also give
``mounting`` (which way the bearing's +z points: ``"tip"``/``"hub"`` for pitch,
``"up"``/``"down"`` for yaw; see :mod:`slewing_model.loads.aeroelastic`).

Every case has a key: the SHA-256 of its canonical description (the load and
bearing files by content, not by path), so that a rerun recognises the cases
it has already finished, wherever the study directory lives.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Mapping

from ..bearing.conventions import definition_message


#: a case's name: its load series' name, this, its bearing variant's name
CASE_NAME_SEPARATOR = " | "


def case_name_parts(name: str) -> tuple[str, str]:
    """The load series' and the bearing variant's names in a case's name (both the whole name
    when it has no separator)."""
    load, _, variant = name.partition(CASE_NAME_SEPARATOR)
    return load, variant or load


#: bump when a case's numbers change for the same inputs (reruns then recompute)
CASE_FORMAT = 2                  # 2: life with the small-swing exponent, slices and micro-cycles

SIMULATION_DEFAULTS = {
    "mesh": "coarse",
    "bc": "free",
    "moving_ring": None,            # None: the bearing file's
    "seal_torque_Nm": 0.0,
    "omega_regularisation_rad_s": 1e-4,
    "tolerance": None,              # None: SimulatorSettings' default (resolved when read)
    "friction_tolerance": None,
    "histogram_bins": 20,
}
SYNTHETIC_KEYS = ("waviness_orders", "radial_amplitude_um", "axial_amplitude_um", "ball_tolerance_um")


class StudyDefinitionError(ValueError):
    """A study file breaks a rule; the message names the key, the value and the rule.

    A :class:`ValueError`.
    """


def _fail(key: str, value: Any, rule: str):
    raise StudyDefinitionError(definition_message(key, value, rule))


@dataclass(frozen=True)
class Case:
    """One case of a study: one load series on one bearing variant.

    Attributes
    ----------
    index : int
        Position in the study's product (the order of ``summary.csv``).
    key : str
        16 hex digits of the SHA-256 of :attr:`spec` (see :func:`case_key`).
    name : str
        Readable label: load series and bearing variant.
    load : dict
        The load series: ``kind`` (``"openfast"``, ``"csv"``, ``"constant"``) and its options;
        file paths absolute.
    variant : dict
        ``file`` (absolute), ``ring_model``, ``preload_um`` (None: the file's),
        ``friction_coefficient``, ``error_seed`` (None: the file's errors), ``synthetic_errors``.
    simulation : dict
        The ``[simulation]`` settings (``mesh``, ``bc``, ``moving_ring``, ``seal_torque_Nm``,
        ``omega_regularisation_rad_s``, ``tolerance``, ``friction_tolerance``,
        ``histogram_bins``), defaults filled in.
    spec : dict
        What the key is computed from: the above with files named by their content digest.
    """

    index: int
    key: str
    name: str
    load: dict
    variant: dict
    simulation: dict
    spec: dict = field(repr=False)


@dataclass(frozen=True)
class Study:
    """A study file, read and validated.

    Build one with :func:`load_study`; :meth:`cases` expands it.

    Attributes
    ----------
    name : str
        The study's name (default: the file's name without its suffix).
    description : str
        The study's description (``[study] description``), or empty.
    path : str
        The study file.
    base_dir : str
        Absolute folder the relative paths of the file are resolved against.
    loads : list of dict
        One entry per load series (an OpenFAST entry with several blades gives one each).
    variants : list of dict
        One entry per bearing variant (the product of the ``[bearings]`` lists).
    simulation : dict
        The ``[simulation]`` settings, defaults filled in (``seal_torque_Nm`` in N m,
        ``omega_regularisation_rad_s`` in rad/s).

    Examples
    --------
    >>> from slewing_model.study import load_study
    >>> study = load_study("examples/studies/table3_tolerance_monte_carlo.toml")
    >>> cases = study.cases()
    >>> len(cases), cases[0].name
    (2000, 'idling, one turn | table3, rigid, preload 0 um, mu 0.1, errors seed 1')
    """

    name: str
    path: str
    base_dir: str
    loads: list
    variants: list
    simulation: dict
    description: str = ""

    def cases(self) -> list[Case]:
        """The cases of the study.

        Returns
        -------
        list of Case
            The product load series x bearing variants, in that order (loads outermost).
        """
        digests: dict[str, str] = {}
        out = []
        for i, (load, variant) in enumerate(itertools.product(self.loads, self.variants)):
            spec = {
                "format": CASE_FORMAT,
                "load": _with_digests(load, ("path",), digests),
                "variant": _with_digests(variant, ("file",), digests),
                "simulation": self.simulation,
            }
            name = f"{load['name']}{CASE_NAME_SEPARATOR}{variant['name']}"
            out.append(Case(i, case_key(spec), name, load, variant, self.simulation, spec))
        return out


def case_key(spec: Mapping) -> str:
    """16 hex digits of the SHA-256 of the canonical JSON of ``spec``."""
    text = json.dumps(spec, sort_keys=True, separators=(",", ":"), default=float)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def file_digest(path: str) -> str:
    """SHA-256 of a file's bytes (hex, 16 digits), or ``"missing: <reason>"``."""
    try:
        h = hashlib.sha256()
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        return h.hexdigest()[:16]
    except OSError as exc:
        return f"missing: {exc.strerror}"


def _with_digests(entry: dict, path_keys, digests: dict) -> dict:
    """``entry`` with each file replaced by its base name and content digest (so that the
    key does not depend on where the study lives)."""
    out = dict(entry)
    for k in path_keys:
        if out.get(k) is not None:
            path = out[k]
            if path not in digests:
                digests[path] = file_digest(path)
            out[k] = {"name": os.path.basename(path), "sha256": digests[path]}
    out.pop("name", None)
    return out


# ---- reading -------------------------------------------------------------------------------

def load_study(path: str | os.PathLike) -> Study:
    """Read and validate a study file.

    The layout of the file (TOML: ``[study]``, ``[[loads]]``, ``[bearings]``,
    ``[simulation]``) is described on the user guide's studies page.

    Parameters
    ----------
    path : str or path-like
        The study file; relative paths in it are resolved against ``[study] base_dir``,
        itself relative to the file's folder.

    Returns
    -------
    Study
        The validated study.

    Raises
    ------
    StudyDefinitionError
        Naming the key, the value and the rule broken (also for a missing or malformed file).
    """
    path = os.fspath(path)
    data = read_toml(path, StudyDefinitionError, "study file")
    try:
        return study_from_dict(data, os.path.dirname(os.path.abspath(path)), path)
    except StudyDefinitionError as exc:  # name the file
        raise StudyDefinitionError(f"{path}: {exc}") from None


def read_toml(path: str | os.PathLike, error: type[Exception] = StudyDefinitionError,
              what: str = "study file") -> dict:
    """Read a TOML file; a file that cannot be read or is not TOML raises ``error`` naming it:
    ``"PATH: cannot read the <what>: <reason>"`` or ``"PATH: not a valid TOML file: <reason>"``."""
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib

    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except OSError as exc:
        raise error(f"{path}: cannot read the {what}: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not a valid TOML file: {exc}") from None


def study_from_dict(data: Mapping[str, Any], study_dir: str, path: str = "<dict>") -> Study:
    """Validate the TOML layout of a study (as :func:`load_study` reads it).

    Parameters
    ----------
    data : mapping
        Tables ``[study]`` (optional), ``[[loads]]``, ``[bearings]`` and ``[simulation]``
        (optional), as read from TOML.
    study_dir : str or path-like
        Folder of the study file; ``study.base_dir`` is relative to it.
    path : str, optional
        The study file's name, for the default study name and messages. Default ``"<dict>"``.

    Returns
    -------
    Study
        The validated study.

    Raises
    ------
    StudyDefinitionError
        Naming the key, the value and the rule broken.
    """
    refuse_unknown(data, "", {"study", "loads", "bearings", "simulation"})
    head = _table(data, "study", required=False)
    refuse_unknown(head, "study.", {"name", "description", "base_dir"})
    name = _string(head, "study.name", default=os.path.splitext(os.path.basename(path))[0])
    base_dir = os.path.normpath(os.path.join(study_dir, _string(head, "study.base_dir", default=".")))

    raw_loads = data.get("loads")
    if not isinstance(raw_loads, list) or not raw_loads:
        _fail("loads", raw_loads, "give at least one [[loads]] entry (openfast, csv or constant)")
    loads = []
    for i, entry in enumerate(raw_loads):
        loads += _load_entries(entry, f"loads[{i}].", base_dir)
    names = [load["name"] for load in loads]
    for n in names:
        if names.count(n) > 1:
            _fail("loads[].name", n, "load series names must be unique (give `name`)")

    variants = _variants(_table(data, "bearings", required=True), base_dir)
    simulation = _simulation(_table(data, "simulation", required=False))
    return Study(name, path, base_dir, loads, variants, simulation, _string(head, "study.description", default=""))


def refuse_unknown(table: Mapping, where: str, known, error: type[Exception] = StudyDefinitionError) -> None:
    """Refuse a key of ``table`` not in ``known`` (``where``: the table's dotted name and a dot, ``""``
    for the file's top level), raising ``error`` that names the table, the key, its value and the known
    keys (:func:`~slewing_model.bearing.conventions.definition_message`)."""
    def fail(key, value, rule):
        raise error(definition_message(key, value, rule))

    for key in table:
        if key in known:
            continue
        if not where:
            fail(key, table[key], f"unknown table [{key}] (known tables: "
                 f"{', '.join(f'[{t}]' for t in sorted(known))}; names are case-sensitive)")
        if isinstance(table[key], Mapping):     # a misspelt [where.key] sub-table
            fail(where + key, None, f"unknown table [{where}{key}] "
                 f"(known: {', '.join(sorted(known))}; names are case-sensitive)")
        fail(where + key, table[key],
             f"unknown key in table [{where[:-1]}] (known: {', '.join(sorted(known))}; names are case-sensitive)")


def _table(data: Mapping, key: str, required: bool) -> Mapping:
    if key not in data:
        if required:
            _fail(key, None, f"missing table [{key}] (required)")
        return {}
    if not isinstance(data[key], Mapping):
        _fail(key, data[key], "must be a table")
    return data[key]


def _string(table: Mapping, key: str, default=None, choices=None) -> str:
    short = key.rsplit(".", 1)[-1]
    value = table.get(short, default)
    if value is None:
        _fail(key, None, "missing key (required)")
    if not isinstance(value, str):
        _fail(key, value, "must be a string")
    if choices is not None and value not in choices:
        _fail(key, value, f"must be one of {', '.join(map(repr, choices))}")
    return value


def _number(table: Mapping, key: str, default=None, minimum=None, exclusive=False, allow_none=False) -> float | None:
    short = key.rsplit(".", 1)[-1]
    value = table.get(short, default)
    if value is None:
        if allow_none:
            return None
        _fail(key, None, "missing key (required)")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        _fail(key, value, "must be a finite number")
    if minimum is not None and (value <= minimum if exclusive else value < minimum):
        _fail(key, value, f"must be {'>' if exclusive else '>='} {minimum:g}")
    return float(value)


def _integer(table: Mapping, key: str, default=None, minimum=None) -> int:
    short = key.rsplit(".", 1)[-1]
    value = table.get(short, default)
    if isinstance(value, bool) or not isinstance(value, int):
        _fail(key, value, "must be a whole number")
    if minimum is not None and value < minimum:
        _fail(key, value, f"must be >= {minimum}")
    return value


def _list(table: Mapping, key: str, default=None) -> list:
    short = key.rsplit(".", 1)[-1]
    value = table.get(short, default)
    if not isinstance(value, list):
        value = [value]
    if not value:
        _fail(key, value, "must not be empty")
    return value


def _path(base_dir: str, value: str) -> str:
    return os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))


def _load_entries(entry: Any, w: str, base_dir: str) -> list[dict]:
    if not isinstance(entry, Mapping):
        _fail(w[:-1], entry, "must be a table")
    kinds = [k for k in ("openfast", "csv", "constant") if k in entry]
    if len(kinds) != 1:
        _fail(w[:-1], dict(entry), "give exactly one of `openfast` (file), `csv` (file) or `constant` (6 loads)")
    kind = kinds[0]
    common = {"name", "load_frame", "t_start_s", "t_end_s", "every", "omega_rad_s"}
    extra = {"openfast": {"openfast", "bearing", "blades", "mounting"}, "csv": {"csv"},
             "constant": {"constant", "duration_s", "steps"}}[kind]
    refuse_unknown(entry, w, common | extra)
    load: dict = {"kind": kind}
    if kind == "constant":
        values = entry["constant"]
        if not isinstance(values, list) or len(values) != 6 or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values):
            _fail(w + "constant", values, "must be six finite numbers: Fx, Fy, Fz [N], Mx, My, Mz [N m]")
        load["loads"] = [float(v) for v in values]
        load["duration_s"] = _number(entry, w + "duration_s", minimum=0.0, exclusive=True)
        load["steps"] = _integer(entry, w + "steps", minimum=2)
        load["omega_rad_s"] = _number(entry, w + "omega_rad_s", default=0.0)
        default_name, default_frame = "constant", "fixed"
    else:
        raw = entry[kind]
        if not isinstance(raw, str) or not raw:
            _fail(w + kind, raw, "must be a file name (relative to study.base_dir)")
        load["path"] = _path(base_dir, raw)
        default_name = os.path.splitext(os.path.basename(raw))[0]
        default_frame = "fixed"
        load["omega_rad_s"] = _number(entry, w + "omega_rad_s", allow_none=True)
        if kind == "openfast":
            load["bearing"] = _string(entry, w + "bearing", choices=("pitch", "yaw"))
            if "mounting" in entry:
                load["mounting"] = _string(entry, w + "mounting")
            default_frame = "rotating"
    load["load_frame"] = (_string(entry, w + "load_frame", choices=("fixed", "rotating")) if "load_frame" in entry
                          else None)
    load["default_frame"] = default_frame
    for key in ("t_start_s", "t_end_s"):
        load[key] = _number(entry, w + key, allow_none=True)
    if load["t_start_s"] is not None and load["t_end_s"] is not None and load["t_end_s"] <= load["t_start_s"]:
        _fail(w + "t_end_s", load["t_end_s"], f"must exceed t_start_s = {load['t_start_s']:g}")
    load["every"] = _integer(entry, w + "every", default=1, minimum=1)
    name = _string(entry, w + "name", default=default_name)

    if kind == "openfast":
        blades = entry.get("blades", [1])
        if load["bearing"] == "yaw":
            if "blades" in entry:
                _fail(w + "blades", blades, "only for bearing = 'pitch'")
            return [dict(load, name=name)]
        if not isinstance(blades, list) or not blades or not all(
                isinstance(b, int) and not isinstance(b, bool) and 1 <= b <= 3 for b in blades):
            _fail(w + "blades", blades, "must be a list of blade numbers 1..3")
        return [dict(load, blade=b, name=f"{name} blade {b}") for b in blades]
    return [dict(load, name=name)]


def _variants(table: Mapping, base_dir: str) -> list[dict]:
    w = "bearings."
    refuse_unknown(table, w, {"files", "ring_model", "preload_um", "friction_coefficient", "error_seeds",
                              "synthetic_errors"})
    files = []
    for f in _list(table, w + "files"):
        if not isinstance(f, str) or not f:
            _fail(w + "files", table["files"], "must be bearing definition files (TOML)")
        files.append(_path(base_dir, f))
    models = _list(table, w + "ring_model", default=["rigid"])
    for m in models:
        if m not in ("rigid", "flexible"):
            _fail(w + "ring_model", m, "must be 'rigid' or 'flexible'")
    preloads = _list(table, w + "preload_um", default=[None])
    for p in preloads:
        if p is not None:
            _number({"preload_um": p}, w + "preload_um")
    mus = [_number({"friction_coefficient": m}, w + "friction_coefficient", minimum=0.0)
           for m in _list(table, w + "friction_coefficient", default=[0.1])]

    seeds: list = [None]
    if "error_seeds" in table:
        raw = table["error_seeds"]
        if isinstance(raw, Mapping):
            refuse_unknown(raw, w + "error_seeds.", {"first", "count"})
            first = _integer(raw, w + "error_seeds.first", default=0, minimum=0)
            count = _integer(raw, w + "error_seeds.count", minimum=1)
            seeds = list(range(first, first + count))
        elif isinstance(raw, list) and raw and all(isinstance(s, int) and not isinstance(s, bool) and s >= 0
                                                    for s in raw):
            if len(set(raw)) != len(raw):
                _fail(w + "error_seeds", raw, "seeds must be distinct")
            seeds = list(raw)
        else:
            _fail(w + "error_seeds", raw, "must be a list of whole numbers >= 0 or {first = N, count = M}")
    synthetic = None
    if "synthetic_errors" in table:
        synthetic = dict(table["synthetic_errors"]) if isinstance(table["synthetic_errors"], Mapping) else None
        if synthetic is None:
            _fail(w + "synthetic_errors", table["synthetic_errors"], "must be a table")
        refuse_unknown(synthetic, w + "synthetic_errors.", set(SYNTHETIC_KEYS))
        if seeds == [None]:
            _fail(w + "synthetic_errors", synthetic, "needs bearings.error_seeds (the seeds of the error sets)")

    variants = []
    for f, model, preload, mu, seed in itertools.product(files, models, preloads, mus, seeds):
        parts = [os.path.splitext(os.path.basename(f))[0], model]
        if preload is not None:
            parts.append(f"preload {preload:g} um")
        parts.append(f"mu {mu:g}")
        if seed is not None:
            parts.append(f"errors seed {seed}")
        variants.append({"file": f, "ring_model": model, "preload_um": None if preload is None else float(preload),
                         "friction_coefficient": mu, "error_seed": seed, "synthetic_errors": synthetic,
                         "name": ", ".join(parts)})
    return variants


def _simulation(table: Mapping) -> dict:
    w = "simulation."
    refuse_unknown(table, w, set(SIMULATION_DEFAULTS))
    s = dict(SIMULATION_DEFAULTS)
    s["mesh"] = _string(table, w + "mesh", default="coarse", choices=("coarse", "fine", "finer"))
    s["bc"] = _string(table, w + "bc", default="free", choices=("free", "clamped", "frictionless"))
    if "moving_ring" in table:
        s["moving_ring"] = _string(table, w + "moving_ring", choices=("inner", "outer"))
    s["seal_torque_Nm"] = _number(table, w + "seal_torque_Nm", default=0.0, minimum=0.0)
    s["omega_regularisation_rad_s"] = _number(table, w + "omega_regularisation_rad_s", default=1e-4, minimum=0.0)
    for key in ("tolerance", "friction_tolerance"):
        value = _number(table, w + key, minimum=0.0, exclusive=True, allow_none=True)
        if value is not None and value >= 1e-2:
            _fail(w + key, value, "must lie in (0, 0.01)")
        if value is None:   # the simulator's own default, written into the case (and its key)
            from ..simulation.simulator import SimulatorSettings

            value = getattr(SimulatorSettings(), key)
        s[key] = value
    s["histogram_bins"] = _integer(table, w + "histogram_bins", default=20, minimum=1)
    return s
