"""ROSCO, NREL's wind turbine controller, called through its Bladed-style ``DISCON`` entry point.

ROSCO ships as a compiled library (``libdiscon.so`` in the ``rosco`` wheel, which
``pip install --no-deps rosco==2.10.6`` installs without ROSCO's Python toolbox).
Every call exchanges the *swap array* ``avrSWAP`` (float32) with it: the turbine's
measurements go in, the generator torque, pitch and yaw rate commands come out.
:class:`RoscoController` fills the array as ROSCO's own Python interface does
(``rosco.toolbox.control_interface.ControllerInterface``): the same values at the
initialising call and the same records at every step, so that a loop built on it
reproduces ROSCO's simulator (``rosco.toolbox.sim.Sim``) sample for sample.

Records used (Bladed numbering, 1-based; the Python index is one less)::

    1 status (0 first call, 1 running, -1 last call)   2 time, s    3 step, s
    4, 33, 34 measured pitch of blades 1-3, rad       15 electrical power, W
    20 generator speed, rad/s    21 rotor speed, rad/s    23 measured generator torque, N m
    24 nacelle vane (wind direction - nacelle heading), rad    27 hub wind speed, m/s
    28 individual pitch allowed (1)    30-32 blade root out-of-plane moments, N m
    37 nacelle heading, rad    60 rotor azimuth, rad    61 number of blades
    out: 42-44 pitch commands of blades 1-3, rad    47 generator torque command, N m
         48 yaw rate command, rad/s

ROSCO keeps its state in the library's static (Fortran ``SAVE``) variables, so one
loaded library serves one controller: each instance loads its own copy of the
library from a temporary directory, with a copy of the parameter file
(``DISCON.IN``) whose logging is off and whose file names are absolute, so that
nothing is written into the working directory.

ROSCO prints from Fortran to file descriptor 1. Its banner and parameter warnings at
the initialising call are kept out of the standard output, in
:attr:`RoscoController.startup_output`; later messages (rare warnings, once each; no
periodic status line with logging off) go to the standard output, flushed after each
call so that they land where it points at that moment (under pytest: the capture of
the test that caused them).
"""
from __future__ import annotations

import ctypes
import math
import os
import re
import shutil
import sys
import tempfile
import warnings
import weakref
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Commands", "Measurements", "RoscoController", "RoscoError", "read_discon"]

SWAP_SIZE = 2000
"""Length of the swap array. ROSCO reads records up to 1018 (``Ext_Interface 1``), beyond
the 500 elements of ROSCO's Python interface."""

_MESSAGE_SIZE = 500  # characters of ROSCO's message (record 49), as ROSCO's Python interface
_FILE_KEYS = ("PerfFileName", "OL_Filename", "DLL_FileName", "DLL_InFile")  # relative to DISCON.IN
# a parameter line of DISCON.IN: value(s), then "! Name - description"
_LINE = re.compile(r"^(?P<value>\s*[^!\s][^!]*?)(?P<sep>\s+!\s*)(?P<name>[A-Za-z_]\w*)(?P<rest>.*)$")


class RoscoError(RuntimeError):
    """ROSCO stopped the simulation: its failure flag (``aviFAIL``) was negative."""


def read_discon(path) -> dict:
    """Read the parameters of a ROSCO parameter file (``DISCON.IN``).

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    dict
        Parameter name -> value: a str for a quoted value (file names), a float for one
        number, a list of floats for several. Units are those of the file (ROSCO's are SI
        except where the file says otherwise: ``VS_GenEff`` in %, ``Y_ErrThresh`` in deg).

    Examples
    --------
    >>> from slewing_turbine import read_discon
    >>> p = read_discon("examples/turbines/nrel5mw/DISCON.IN")
    >>> p["PC_MaxRat"]                     # rad/s
    0.1745
    """
    values = {}
    for line in Path(path).read_text(encoding="latin-1").splitlines():
        m = _LINE.match(line)
        if m is None:
            continue
        text = m["value"].strip()
        if text.startswith('"'):
            values[m["name"]] = text.strip('"')
            continue
        try:
            numbers = [float(word) for word in text.split()]
        except ValueError:
            values[m["name"]] = text
            continue
        values[m["name"]] = numbers[0] if len(numbers) == 1 else numbers
    return values


def _format(value, quoted: bool) -> str:
    if isinstance(value, str):
        return f'"{value}"' if quoted and not value.startswith('"') else value
    if isinstance(value, (list, tuple, np.ndarray)):
        return "   ".join(_format(v, False) for v in value)
    if isinstance(value, (bool, np.bool_)):
        return str(int(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return repr(float(value))


def _write_discon_copy(source: Path, target: Path, overrides: dict) -> dict:
    """Copy ``source`` to ``target`` with LoggingLevel 0, absolute file names and ``overrides``.

    Returns the parameters of the copy (as :func:`read_discon`).
    """
    overrides = {"LoggingLevel": 0, **overrides}
    seen = set()
    lines = []
    for line in source.read_text(encoding="latin-1").splitlines():
        m = _LINE.match(line)
        if m is not None:
            name, text = m["name"], m["value"].strip()
            quoted = text.startswith('"')
            if name in overrides:
                text = _format(overrides[name], quoted)
                seen.add(name)
            if name in _FILE_KEYS and quoted:
                file = text.strip('"')
                if file and file.lower() != "unused" and not os.path.isabs(file):
                    text = f'"{(source.parent / file).resolve()}"'
            line = f"{text}{m['sep']}{name}{m['rest']}"
        lines.append(line)
    unknown = sorted(set(overrides) - seen)
    if unknown:
        raise KeyError(f"{source}: no parameter named {', '.join(unknown)} (overrides must name parameters "
                       f"of the file; ROSCO would use its defaults for missing ones)")
    target.write_text("\n".join(lines) + "\n", encoding="latin-1")
    return read_discon(target)


@dataclass
class Measurements:
    """What the turbine tells the controller at one step (SI units).

    Attributes
    ----------
    time : float, s
        Simulation time.
    rotor_speed : float, rad/s
        Low-speed shaft speed.
    generator_speed : float, rad/s
        High-speed shaft speed (rotor speed times the gear ratio).
    generator_torque : float, N m
        Generator torque acting now (the last command, for an ideal generator).
    blade_pitch : (3,) array_like, rad
        Measured pitch angle of each blade.
    wind_speed : float, m/s
        Hub-height horizontal wind speed.
    azimuth : float, rad
        Rotor azimuth (blade 1; 0 = up), for individual pitch control.
    root_moop : (3,) array_like, N m
        Blade root out-of-plane bending moments, for individual pitch control.
    nacelle_heading : float, rad
        Nacelle yaw angle.
    wind_direction : float, rad
        Wind direction, same reference as the heading; the vane signal is their difference.
    generator_efficiency : float
        Mechanical to electrical power, in (0, 1]: the electrical power sent is
        ``generator_speed * generator_torque * generator_efficiency``.
    """

    time: float
    rotor_speed: float
    generator_speed: float
    generator_torque: float
    blade_pitch: np.ndarray
    wind_speed: float
    azimuth: float = 0.0
    root_moop: np.ndarray = field(default_factory=lambda: np.zeros(3))
    nacelle_heading: float = 0.0
    wind_direction: float = 0.0
    generator_efficiency: float = 0.944


@dataclass
class Commands:
    """What the controller asks for (SI units).

    Attributes
    ----------
    generator_torque : float, N m
        Generator torque command (high-speed shaft).
    pitch : (3,) ndarray, rad
        Pitch angle command of each blade.
    yaw_rate : float, rad/s
        Yaw rate command (0 unless the parameter file's ``Y_ControlMode`` is 1).
    """

    generator_torque: float
    pitch: np.ndarray
    yaw_rate: float


def _libc():
    return ctypes.CDLL(None)


class _StdoutToFile:
    """Send file descriptor 1 (where the Fortran library prints) to a file for a while."""

    def __init__(self, path: Path, fortran_flush=None):
        self.path = path
        self.fortran_flush = fortran_flush  # libgfortran buffers its output when fd 1 is a regular file

    def __enter__(self):
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (AttributeError, ValueError):  # pragma: no cover - closed or missing streams
                pass
        _libc().fflush(None)
        try:
            self.saved = os.dup(1)
        except OSError:  # pragma: no cover - no standard output at all: nothing to keep clean
            self.saved = None
            return self
        fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
        os.dup2(fd, 1)
        os.close(fd)
        return self

    def __exit__(self, *exc):
        if self.fortran_flush is not None:
            self.fortran_flush(None)   # all Fortran units
        _libc().fflush(None)
        if self.saved is None:  # pragma: no cover
            return False
        os.dup2(self.saved, 1)
        os.close(self.saved)
        return False


def _release(handle, directory):
    """Unload a library copy and remove its directory (also run when an instance is collected)."""
    if handle:
        dlclose = _libc().dlclose
        dlclose.argtypes = [ctypes.c_void_p]
        dlclose(handle)
    shutil.rmtree(directory, ignore_errors=True)


def _check_positive(name: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r}: must be a finite number > 0") from None
    if not (math.isfinite(number) and number > 0):
        raise ValueError(f"{name} = {value!r}: must be a finite number > 0")
    return number


class RoscoController:
    """ROSCO in this process: one instance, one controller with its own state.

    Parameters
    ----------
    discon_in : str or path-like
        ROSCO's parameter file (e.g. ``examples/turbines/nrel5mw/DISCON.IN``). File
        names in it (the rotor performance table ``PerfFileName``) are relative to it.
    dt : float, s
        Controller step (ROSCO's ``DT``); every :meth:`step` advances it by this much.
    library : str or path-like, optional
        ROSCO's compiled library. Default: the ``rosco`` wheel's (``rosco.discon_lib_path``).
    overrides : dict, optional
        Parameter name -> value replacing the file's (e.g. ``{"IPC_ControlMode": 1,
        "IPC_KI": [1e-8, 0.0]}``). ``LoggingLevel`` is 0 unless overridden (ROSCO's debug
        files then go to :attr:`directory`, removed by :meth:`close`).
    initial_pitch : float, rad
        Blade pitch sent at the initialising call (ROSCO's Python interface: 0).

    Attributes
    ----------
    parameters : dict
        The parameters the controller runs with (:func:`read_discon` of its copy).
    directory : pathlib.Path
        The instance's temporary directory (library and parameter copies).
    startup_output : str
        What ROSCO printed at its initialising call (banner and warnings), kept out of
        the standard output. Later prints (rare warnings; with ``LoggingLevel 0`` no
        periodic status line) go to the standard output as ROSCO writes them.

    Raises
    ------
    ValueError
        If ``dt`` is not a finite number > 0.
    FileNotFoundError
        If the parameter file, the library or a file the parameters name is missing
        (ROSCO's Fortran would end the whole process instead).
    KeyError
        If an override names no parameter of the file.
    RoscoError
        If ROSCO refuses the parameters (its message says which and why).

    Notes
    -----
    The initialising call (status 0) is made here, with the values of ROSCO's Python
    interface (``ControllerInterface.init_discon``): generator and rotor speed 1 rad/s,
    wind 10 m/s, measured torque 0, the three pitch angles ``initial_pitch``, individual
    pitch allowed, three blades. The swap array is float32 as the library expects; it
    keeps what ROSCO wrote between calls, as ROSCO's interface does.

    Examples
    --------
    >>> import numpy as np
    >>> from slewing_turbine import Measurements, RoscoController
    >>> with RoscoController("examples/turbines/nrel5mw/DISCON.IN", dt=0.01) as c:
    ...     cmd = c.step(Measurements(time=0.01, rotor_speed=1.2, generator_speed=116.4,
    ...                               generator_torque=40e3, blade_pitch=np.zeros(3), wind_speed=11.0))
    >>> cmd.pitch.shape, cmd.generator_torque >= 0.0
    ((3,), True)
    """

    def __init__(self, discon_in, dt: float, *, library=None, overrides: dict | None = None,
                 initial_pitch: float = 0.0):
        self.dt = _check_positive("dt", dt)
        if not math.isfinite(float(initial_pitch)):
            raise ValueError(f"initial_pitch = {initial_pitch!r}: must be a finite angle in rad")
        source = Path(discon_in)
        if not source.is_file():
            raise FileNotFoundError(f"discon_in = {str(source)!r}: no such file (ROSCO's parameter file, DISCON.IN)")
        if library is None:
            try:
                import rosco  # only locates the library: rosco.toolbox (and its dependencies) is not imported
            except ImportError as exc:
                raise ImportError("RoscoController needs ROSCO's library: pip install --no-deps rosco==2.10.6 "
                                  "(Python >= 3.11), or pass library=") from exc
            library = rosco.discon_lib_path
        library = Path(library)
        if not library.is_file():
            raise FileNotFoundError(f"library = {str(library)!r}: no such file (ROSCO's libdiscon)")
        self._handle = None
        self._lib = None
        self._finished = False
        self.directory = Path(tempfile.mkdtemp(prefix="rosco-"))
        self._finalizer = weakref.finalize(self, _release, None, str(self.directory))
        try:
            self._load(source, library, overrides or {}, float(initial_pitch))
        except BaseException:
            self.close()
            raise

    def _load(self, source: Path, library: Path, overrides: dict, initial_pitch: float) -> None:
        d = self.directory
        infile = d / "DISCON.IN"
        self.parameters = _write_discon_copy(source, infile, overrides)
        p = self.parameters
        needed = [("PerfFileName", p.get("WE_Mode", 0) > 0),   # ROSCO reads the table only for its estimator
                  ("OL_Filename", p.get("OL_Mode", 0) > 0),
                  ("DLL_FileName", p.get("Ext_Mode", 0) > 0), ("DLL_InFile", p.get("Ext_Mode", 0) > 0)]
        for key, used in needed:
            if used and not Path(str(p.get(key, ""))).is_file():
                raise FileNotFoundError(f"{source}: {key} = {p.get(key)!r}: no such file (relative names are "
                                        f"relative to the parameter file)")
        # the wheel's library finds its bundled libgfortran through RPATH $ORIGIN/../../rosco.libs:
        # the copy keeps that layout, with a link to the original's rosco.libs
        copy = d / "rosco" / "lib" / library.name
        copy.parent.mkdir(parents=True)
        shutil.copyfile(library, copy)
        bundled = library.resolve().parent.parent.parent / "rosco.libs"
        if bundled.is_dir():
            (d / "rosco.libs").symlink_to(bundled, target_is_directory=True)
        self._lib = ctypes.CDLL(str(copy))
        self._handle = self._lib._handle
        self._finalizer.detach()
        self._finalizer = weakref.finalize(self, _release, self._handle, str(d))
        pointer = ctypes.POINTER(ctypes.c_float)
        self._discon = self._lib.DISCON
        self._discon.argtypes = [pointer, ctypes.POINTER(ctypes.c_int32), ctypes.c_char_p, ctypes.c_char_p,
                                 ctypes.c_char_p]
        self._discon.restype = None
        self._infile = str(infile).encode()
        self._outname = str(d / "rosco").encode()  # ROSCO's root name for its own files: inside the directory
        self._message = ctypes.create_string_buffer(2 * _MESSAGE_SIZE)
        self._fail = ctypes.c_int32(0)
        self._fail_ref = ctypes.byref(self._fail)
        sw = self._swap = np.zeros(SWAP_SIZE, dtype=np.float32)
        self._swap_pointer = sw.ctypes.data_as(pointer)
        # the initialising call, as ControllerInterface.init_discon (0-based indices)
        sw[2] = self.dt
        sw[60] = 3                                   # number of blades
        sw[19] = 1.0                                 # generator speed, rad/s
        sw[20] = 1.0                                 # rotor speed, rad/s
        sw[82] = 0.0                                 # nacelle IMU rotational acceleration
        sw[26] = 10.0                                # wind speed, m/s
        sw[3] = sw[32] = sw[33] = initial_pitch      # measured pitch, rad
        sw[27] = 1                                   # individual pitch control allowed
        sw[22] = 0.0                                 # measured generator torque
        sw[0] = 0                                    # status: first call
        sw[48] = _MESSAGE_SIZE
        sw[49] = len(self._infile)
        sw[50] = len(self._outname)
        sw[51] = _MESSAGE_SIZE
        log = d / "startup.txt"
        # libgfortran buffers what ROSCO prints when fd 1 is a regular file (a redirect, pytest's capture)
        # and would write it at exit, wherever fd 1 points then: its FLUSH (all units) after each call,
        # 1.6 us (found through the library's dependencies; the wheel's libgfortran may be scipy's)
        try:
            flush = self._lib._gfortran_flush_i4
            flush.argtypes = [ctypes.c_void_p]
            flush.restype = None
        except AttributeError:  # pragma: no cover - a library built with another compiler
            flush = None
        self._flush = flush
        with _StdoutToFile(log, flush):
            self._call()
        self.startup_output = log.read_text(errors="replace") if log.exists() else ""
        self._check(time=0.0)
        sw[0] = 1

    def _call(self) -> None:
        self._discon(self._swap_pointer, self._fail_ref, self._infile, self._outname, self._message)
        if self._flush is not None:
            self._flush(None)

    def _check(self, time: float) -> None:
        fail = self._fail.value
        if fail == 0:
            return
        message = self._message.value.decode(errors="replace").strip()
        if fail < 0:
            self._finished = True
            raise RoscoError(f"ROSCO stopped at t = {time:g} s (aviFAIL = {fail}): {message}")
        warnings.warn(f"ROSCO at t = {time:g} s: {message}", RuntimeWarning, stacklevel=3)

    def step(self, m: Measurements, *, last: bool = False) -> Commands:
        """One controller call.

        Parameters
        ----------
        m : Measurements
            The turbine's state now.
        last : bool, optional
            The last call of the simulation (status -1): ROSCO then computes nothing new and
            the commands of the previous call are returned again (as ROSCO's simulator does);
            no further call is accepted.

        Returns
        -------
        Commands
            The generator torque, pitch and yaw rate commands.

        Raises
        ------
        ValueError
            If a measurement is not a finite number or ``blade_pitch``/``root_moop`` do not
            hold three values.
        RoscoError
            If ROSCO stops (its message is in the exception).
        RuntimeError
            If the controller is closed or has made its last call.
        """
        if self._lib is None or self._finished:
            raise RuntimeError("RoscoController: closed or after its last call (last=True); make a new one")
        try:
            p0, p1, p2 = m.blade_pitch
            r0, r1, r2 = m.root_moop
        except (TypeError, ValueError):
            raise ValueError(f"blade_pitch = {m.blade_pitch!r}, root_moop = {m.root_moop!r}: each must hold "
                             f"3 values (one per blade)") from None
        values = (m.time, m.rotor_speed, m.generator_speed, m.generator_torque, p0, p1, p2, m.wind_speed,
                  m.azimuth, r0, r1, r2, m.nacelle_heading, m.wind_direction, m.generator_efficiency)
        if not math.isfinite(sum(values)):  # a NaN or an infinity anywhere makes the sum so
            self._reject(m)
        sw = self._swap
        sw[0] = -1 if last else 1
        sw[1] = m.time
        sw[2] = self.dt
        sw[3] = p0
        sw[32] = p1
        sw[33] = p2
        sw[14] = m.generator_speed * m.generator_torque * m.generator_efficiency  # electrical power, W
        sw[22] = m.generator_torque
        sw[19] = m.generator_speed
        sw[20] = m.rotor_speed
        sw[23] = (m.wind_direction - m.nacelle_heading + math.pi) % (2.0 * math.pi) - math.pi  # vane, rad
        sw[26] = m.wind_speed
        sw[29] = r0
        sw[30] = r1
        sw[31] = r2
        sw[36] = m.nacelle_heading
        sw[59] = m.azimuth
        sw[82] = 0.0   # nacelle IMU rotational acceleration
        sw[52] = 0.0   # tower-top fore-aft acceleration
        self._call()
        self._check(time=float(m.time))
        if last:
            self._finished = True
        return Commands(generator_torque=float(sw[46]), pitch=sw[41:44].astype(np.float64), yaw_rate=float(sw[47]))

    @staticmethod
    def _reject(m: Measurements) -> None:
        for name in ("time", "rotor_speed", "generator_speed", "generator_torque", "blade_pitch", "wind_speed",
                     "azimuth", "root_moop", "nacelle_heading", "wind_direction", "generator_efficiency"):
            value = getattr(m, name)
            try:
                finite = bool(np.all(np.isfinite(np.asarray(value, dtype=float))))
            except (TypeError, ValueError):
                finite = False
            if not finite:
                raise ValueError(f"Measurements.{name} = {value!r}: must be finite (SI units)")
        raise ValueError("Measurements: a value is not finite")  # pragma: no cover - the sum overflowed

    def close(self) -> None:
        """Unload the library copy and remove the instance's directory (safe to call twice)."""
        self._lib = None
        self._discon = None
        self._finalizer()

    def __enter__(self) -> "RoscoController":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
