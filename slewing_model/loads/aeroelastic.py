"""Bearing loads and motion from the output of an aero-elastic code (OpenFAST / FAST).

:func:`bearing_loads` maps the channels of an :class:`~slewing_model.loads.openfast.OutputFile`
to the inputs of our bearing model, in SI units:

* **pitch bearing of blade k**: the blade-root loads ``RootFxbk .. RootMzbk``
  (blade frame ``b``, pitches with the blade), or ``RootFxck .. RootMzck``
  (coned frame ``c``, does not pitch) turned into ``b`` by ``BldPitchk``;
  ``psi`` from the pitch angle ``BldPitchk``, ``omega`` its rate (central
  differences); ``Mz`` from ``RootMzbk``.
* **yaw bearing**: ``YawBrFxp .. YawBrMzp`` (tower-top frame ``p``, does not
  yaw; or ``YawBr*n``, nacelle frame, which yaws); ``psi`` from the nacelle
  yaw ``YawPzn`` / ``NacYaw``, ``omega`` from ``YawVzn`` / ``NacYawVel`` when
  the file has it, else the rate of ``psi``; ``Mz`` from ``YawBrMzp``.

Axes and signs (derived on the user guide's OpenFAST loads page): the moving ring is the ring
bolted to the blade (pitch) or to the nacelle (yaw); the loads are those the
blade or nacelle puts on it, which is what OpenFAST's root and yaw-bearing
channels are. The bearing's +z axis points along the blade towards its tip
(``mounting="tip"``) or towards the hub (``"hub"``); for the yaw bearing up
(``"up"``, towards the nacelle) or down (``"down"``). With the blade on the
inner ring and ``mounting="tip"``, a blade pulling outward (centrifugal
``RootFzb > 0``) pushes the inner ring towards +z and loads diagonal 1
(contacts 1 and 3).

OpenFAST pitches a blade about -zb (``xb = cos(theta) xc - sin(theta) yc``),
and yaws the nacelle about +zp (``xn = cos(yaw) xp + sin(yaw) yp``), so
``psi = -BldPitch`` for ``"tip"``, ``+BldPitch`` for ``"hub"``; ``psi = +yaw``
for ``"up"``.

The load series' ``Mz`` is, as :mod:`slewing_drives` takes it, the moment that
opposes a positive ``psi``: minus the moment about +z that the blade (nacelle)
puts on the moving ring. For ``"hub"`` it is ``RootMzb`` itself: with ``psi``
the pitch angle, ``RootMzb > 0`` opposes pitching to feather.
"""
from __future__ import annotations

import math
from os import PathLike

import numpy as np

from .openfast import MissingChannelError, OpenFastFormatError, OutputFile, read_output

__all__ = ["bearing_loads", "bearing_channels", "to_si", "MOUNTINGS", "FRAMES", "UnitError"]

#: allowed ``mounting`` per bearing: which way the bearing's +z axis points, and its sign
#: against OpenFAST's zb (towards the blade tip) or zp (up)
MOUNTINGS = {"pitch": {"tip": 1.0, "hub": -1.0}, "yaw": {"up": 1.0, "down": -1.0}}
#: frames the loads can be given in: the moving ring's (turns with psi) or the fixed ring's
FRAMES = ("rotating", "fixed")
_SOURCES = {"pitch": ("auto", "b", "c"), "yaw": ("auto", "p", "n")}

_KIND_UNITS = {
    "force": {"n": 1.0, "kn": 1e3, "mn": 1e6},
    "moment": {"nm": 1.0, "knm": 1e3, "mnm": 1e6},
    "angle": {"deg": math.pi / 180, "rad": 1.0},
    "rate": {"deg/s": math.pi / 180, "deg/sec": math.pi / 180, "rad/s": 1.0, "rad/sec": 1.0,
             "rpm": 2 * math.pi / 60},
    "time": {"s": 1.0, "sec": 1.0},
}
_KIND_EXAMPLES = {"force": "N, kN, MN", "moment": "N·m, kN·m, kN-m, kNm, MN·m", "angle": "deg, rad",
                  "rate": "rpm, deg/s, rad/s", "time": "s"}


class UnitError(ValueError):
    """A channel's unit is not one of its kind (force, moment, angle, rate); a :class:`ValueError`."""


def _normalise_unit(unit: str) -> str:
    u = unit.strip()
    if u.startswith("(") and u.endswith(")"):
        u = u[1:-1]
    u = u.replace("Â·", "").replace("·", "").replace("\u22c5", "")   # Latin-1 / UTF-8 middle dot, dot operator
    for sep in ("-", "*", ".", " ", "_"):
        u = u.replace(sep, "")
    return u.lower()


def to_si(values, unit: str, kind: str, *, name: str = "channel", path: str = "") -> np.ndarray:
    """``values`` in ``unit`` converted to SI (N, N m, rad, rad/s, s).

    Parameters
    ----------
    values : array_like
        Channel values in ``unit``.
    unit : str
        As the file spells it: ``kN``, ``kN·m`` (Latin-1 or UTF-8 middle dot),
        ``kN-m``, ``kNm``, ``N``, ``N·m``, ``MN``, ``deg``, ``rad``, ``rpm``,
        ``deg/s``, ``rad/s``, ``s``; parentheses allowed.
    kind : {"force", "moment", "angle", "rate", "time"}
        The quantity, which sets the SI unit: N, N m, rad, rad/s, s.
    name, path : str, optional
        Channel and file, for the error message.

    Returns
    -------
    ndarray
        The values in SI units, float.

    Raises
    ------
    UnitError
        The unit is not one of ``kind``; the message names the channel, the
        unit and the file.
    """
    table = _KIND_UNITS[kind]
    if kind in ("force", "moment"):
        key = _normalise_unit(unit)
    else:
        key = unit.strip().strip("()").replace(" ", "").lower()
    if key not in table:
        where = f"{path}: " if path else ""
        raise UnitError(f"{where}channel {name} has unit {unit!r}, not a {kind} unit this reader knows "
                        f"({_KIND_EXAMPLES[kind]})")
    return np.asarray(values, dtype=float) * table[key]


def _channel_sets(bearing: str, blade: int) -> dict:
    """Per source frame: the six load channels (each a tuple of accepted names)."""
    k = blade
    if bearing == "pitch":
        return {
            "b": ((f"RootFxb{k}",), (f"RootFyb{k}",), (f"RootFzb{k}", f"RootFzc{k}"),
                  (f"RootMxb{k}",), (f"RootMyb{k}",), (f"RootMzb{k}", f"RootMzc{k}")),
            "c": ((f"RootFxc{k}",), (f"RootFyc{k}",), (f"RootFzc{k}", f"RootFzb{k}"),
                  (f"RootMxc{k}",), (f"RootMyc{k}",), (f"RootMzc{k}", f"RootMzb{k}")),
        }
    return {
        "p": (("YawBrFxp",), ("YawBrFyp",), ("YawBrFzp", "YawBrFzn"),
              ("YawBrMxp",), ("YawBrMyp",), ("YawBrMzp", "YawBrMzn")),
        "n": (("YawBrFxn",), ("YawBrFyn",), ("YawBrFzn", "YawBrFzp"),
              ("YawBrMxn",), ("YawBrMyn",), ("YawBrMzn", "YawBrMzp")),
    }


def _angle_names(bearing: str, blade: int) -> tuple:
    return (f"BldPitch{blade}",) if bearing == "pitch" else ("YawPzn", "NacYaw", "YawPos")


def _rate_names(bearing: str) -> tuple:
    return () if bearing == "pitch" else ("YawVzn", "NacYawVel", "YawRate")


def _check_options(bearing, blade, mounting, frame, source):
    if bearing not in MOUNTINGS:
        raise ValueError(f"bearing = {bearing!r}: must be 'pitch' or 'yaw'")
    if bearing == "pitch" and (isinstance(blade, bool) or not isinstance(blade, (int, np.integer)) or blade < 1):
        raise ValueError(f"blade = {blade!r}: must be a whole number >= 1")
    if mounting is None:
        mounting = next(iter(MOUNTINGS[bearing]))
    if mounting not in MOUNTINGS[bearing]:
        raise ValueError(f"mounting = {mounting!r}: for the {bearing} bearing must be one of "
                         f"{', '.join(map(repr, MOUNTINGS[bearing]))}")
    if frame not in FRAMES:
        raise ValueError(f"frame = {frame!r}: must be one of {', '.join(map(repr, FRAMES))}")
    if source not in _SOURCES[bearing]:
        raise ValueError(f"source = {source!r}: for the {bearing} bearing must be one of "
                         f"{', '.join(map(repr, _SOURCES[bearing]))}")
    return mounting


def _as_output(output) -> OutputFile:
    if isinstance(output, OutputFile):
        return output
    if isinstance(output, (str, PathLike)):
        return read_output(output)
    raise TypeError(f"output: an OutputFile or a path, not {type(output).__name__}")


def bearing_channels(output, bearing: str = "pitch", blade: int = 1, source: str = "auto") -> dict:
    """The channels :func:`bearing_loads` takes from ``output``.

    Parameters
    ----------
    output : OutputFile or path
        A file read by :func:`slewing_model.loads.openfast.read_output`, or its path.
    bearing : {"pitch", "yaw"}, optional
        Default "pitch".
    blade : int, optional
        The blade whose pitch bearing (pitch only). Default 1.
    source : {"auto", "b", "c", "p", "n"}, optional
        Channels to use: pitch ``"b"`` or ``"c"``, yaw ``"p"`` or ``"n"``; ``"auto"``
        (default) takes the first complete set in that order.

    Returns
    -------
    dict
        ``frame`` (the source frame: ``"b"``, ``"c"``, ``"p"`` or ``"n"``),
        ``loads`` (the six load channels' names in the file), ``angle`` (the
        angle channel) and ``rate`` (the rate channel, or None: differentiated).

    Raises
    ------
    MissingChannelError
        A channel needed is not in the file; the message names it and the file.
    """
    output = _as_output(output)
    _check_options(bearing, blade, None, "rotating", source)
    sets = _channel_sets(bearing, blade)
    wanted = list(sets) if source == "auto" else [source]
    missing = {}
    chosen = None
    for frame in wanted:
        names = [output.find(*alternatives) for alternatives in sets[frame]]
        if all(names):
            chosen = (frame, names)
            break
        missing[frame] = [alternatives[0] for alternatives, n in zip(sets[frame], names) if n is None]
    what = f"the {bearing} bearing" + (f" of blade {blade}" if bearing == "pitch" else "")
    if chosen is None:
        detail = "; ".join(f"{frame} frame: {', '.join(names)}" for frame, names in missing.items())
        raise MissingChannelError(f"{output.path}: {what} needs channels that are not in the file "
                                  f"(missing in the {detail})")
    angle = output.find(*_angle_names(bearing, blade))
    if angle is None:
        raise MissingChannelError(f"{output.path}: {what} needs channel {' or '.join(_angle_names(bearing, blade))} "
                                  "(the angle of the moving ring), which is not in the file")
    rate = output.find(*_rate_names(bearing))
    return {"frame": chosen[0], "loads": chosen[1], "angle": angle, "rate": rate}


def _finite(output: OutputFile, name: str, values: np.ndarray) -> np.ndarray:
    bad = ~np.isfinite(values)
    if bad.any():
        t = output.time[np.argmax(bad)]
        raise OpenFastFormatError(f"{output.path}: channel {name} is not finite (NaN or infinite) at t = {t:g} s")
    return values


def _turn(x: np.ndarray, y: np.ndarray, angle: np.ndarray) -> tuple:
    """Components of a vector in axes turned by ``-angle`` about z, i.e. the
    vector turned by ``+angle``: ``(c x - s y, s x + c y)``."""
    c, s = np.cos(angle), np.sin(angle)
    return c * x - s * y, s * x + c * y


def bearing_loads(output, bearing: str = "pitch", blade: int = 1, mounting: str | None = None,
                  t_start: float | None = None, t_end: float | None = None, *,
                  frame: str = "rotating", source: str = "auto"):
    """Loads and motion of a pitch or yaw bearing from an OpenFAST / FAST output file.

    Parameters
    ----------
    output : OutputFile or path
        A file read by :func:`slewing_model.loads.openfast.read_output`, or its path.
    bearing : {"pitch", "yaw"}, default "pitch"
        The bearing whose loads are read.
    blade : int, default 1
        The blade whose pitch bearing (pitch only).
    mounting : str, optional
        Which way the bearing's +z axis points: pitch ``"tip"`` (default,
        along the blade towards its tip) or ``"hub"``; yaw ``"up"`` (default,
        towards the nacelle) or ``"down"``. Which ring carries the blade or
        nacelle (the moving ring) is the bearing's ``moving_ring``.
    t_start, t_end : float, optional
        Time window, s (file time; default: the whole file).
    frame : {"rotating", "fixed"}, default "rotating"
        Frame of ``Fx..My``: the moving ring's (blade ``b``; nacelle ``n``),
        or the fixed ring's (hub ``c``; tower top ``p``). Give the simulator
        or FMU the same ``load_frame``; the series carries it.
    source : str, default "auto"
        Channels to use: pitch ``"b"`` or ``"c"``, yaw ``"p"`` or ``"n"``;
        ``"auto"`` takes the first complete set in that order.

    Returns
    -------
    slewing_drives.load_series.LoadSeries
        ``time`` (s, the file's), ``loads`` (n, 6): ``Fx, Fy, Fz`` (N) and
        ``Mx, My`` (N m) that the blade (nacelle) puts on the moving ring, in
        ``frame``; ``Mz`` (N m) the moment the drive works against (positive
        when it opposes positive ``psi``); ``psi`` (rad) and ``omega`` (rad/s)
        of the moving ring; ``load_frame = frame``.

    Raises
    ------
    MissingChannelError
        A channel needed is not in the file (named, with the file).
    UnitError
        A channel's unit is not of its kind.
    OpenFastFormatError
        A channel used is NaN or infinite.
    ValueError
        A bad option, or a time window with fewer than two rows.

    Examples
    --------
    >>> from slewing_model.loads.aeroelastic import bearing_loads
    >>> series = bearing_loads("5MW_Land_DLL_WTurb.outb", "pitch", blade=1)   # doctest: +SKIP
    >>> series.write_csv("results/pitch_blade1.csv")                         # doctest: +SKIP
    """
    from slewing_drives.load_series import LoadSeries

    mounting = _check_options(bearing, blade, mounting, frame, source)
    output = _as_output(output)
    used = bearing_channels(output, bearing, blade, source)
    kinds = ("force",) * 3 + ("moment",) * 3
    comp = []
    for name, kind in zip(used["loads"], kinds):
        values = _finite(output, name, output.channels[name])
        comp.append(to_si(values, output.units[name], kind, name=name, path=output.path))
    angle = to_si(_finite(output, used["angle"], output.channels[used["angle"]]), output.units[used["angle"]],
                  "angle", name=used["angle"], path=output.path)
    fx, fy, fz, mx, my, mz = comp
    time = np.asarray(output.time, dtype=float)
    if bearing == "pitch":
        structure_angle = -angle                    # the blade turns by -BldPitch about +zb
        if used["frame"] == "c":                    # c -> b: xb = cos(t) xc - sin(t) yc, yb = sin(t) xc + cos(t) yc
            fx, fy = _turn(fx, fy, angle)
            mx, my = _turn(mx, my, angle)
        structure_rate = None
    else:
        structure_angle = angle                     # the nacelle turns by +yaw about +zp
        if used["frame"] == "p":                    # p -> n: components in axes turned by +yaw
            fx, fy = _turn(fx, fy, -angle)
            mx, my = _turn(mx, my, -angle)
        structure_rate = None
        if used["rate"] is not None:
            structure_rate = to_si(_finite(output, used["rate"], output.channels[used["rate"]]),
                                   output.units[used["rate"]], "rate", name=used["rate"], path=output.path)
    if structure_rate is None:
        if time.size < 2:
            raise ValueError(f"{output.path}: one row only: no rate of {used['angle']}")
        structure_rate = np.gradient(structure_angle, time)
    # the bearing's axes: the structure's (b or n) when +z points the structure's way, else turned
    # by pi about x (y and z change sign)
    m = MOUNTINGS[bearing][mounting]
    psi, omega = m * structure_angle, m * structure_rate
    fy, fz, my, mz = m * fy, m * fz, m * my, m * mz
    if frame == "fixed":
        fx, fy = _turn(fx, fy, psi)
        mx, my = _turn(mx, my, psi)
    loads = np.column_stack([fx, fy, fz, mx, my, -mz])     # Mz: minus the moment on the ring about +z
    keep = _window(output, time, t_start, t_end)
    return LoadSeries(time[keep].copy(), loads[keep], psi[keep].copy(), omega[keep].copy(), load_frame=frame)


def _window(output: OutputFile, time: np.ndarray, t_start, t_end) -> np.ndarray:
    for name, value in (("t_start", t_start), ("t_end", t_end)):
        if value is not None and not math.isfinite(value):
            raise ValueError(f"{name} = {value!r}: must be finite")
    if t_start is not None and t_end is not None and not t_start < t_end:
        raise ValueError(f"t_start = {t_start!r}, t_end = {t_end!r}: t_start must be before t_end")
    # file times are stored with single precision (60.0000089 for 60): a small tolerance
    tol = 1e-3 * float(np.median(np.diff(time))) if time.size > 1 else 0.0
    keep = np.ones(time.size, dtype=bool)
    if t_start is not None:
        keep &= time >= t_start - tol
    if t_end is not None:
        keep &= time <= t_end + tol
    if keep.sum() < 2:
        raise ValueError(f"{output.path}: the window t = {t_start} .. {t_end} s holds {int(keep.sum())} rows "
                         f"(the file has t = {time[0]:g} .. {time[-1]:g} s); at least two are needed")
    return keep
