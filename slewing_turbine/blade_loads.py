"""Blade-root loads: aerodynamics (:mod:`slewing_turbine.bem`), gravity and rotation, in ElastoDyn's frames.

The blade is rigid but for a quasi-static deflection in ElastoDyn's mode shapes of the blade file:
out of plane in the two flap modes (``BldFl1Sh``, ``BldFl2Sh``; generalised stiffness from
``FlpStff`` and the centrifugal tension), loaded by the aerodynamic normal force, gravity and the
precone's centrifugal component; in plane in the edge mode (``BldEdgSh``, ``EdgStff``), loaded by
the aerodynamic tangential force, gravity and the rotor's acceleration. No dynamics, no torsion,
no tower; the modes bend in the coned frame's axes (ElastoDyn's follow the structural twist).
The flap deflection matters for the flap moment's mean: on a coned blade (the NREL 5MW's tips lean
2.5 deg upwind) the centrifugal force adds a flap moment of about +0.85 MN m at rated speed when
rigid, and the blade bending about 4 m downwind takes most of it off again; both deflections give
the pitching moment its 1P part (gravity and the tangential load acting on the flap deflection).

Frames (ElastoDyn; see :mod:`slewing_turbine.bem` for the azimuth, tilt and cone): the coned
frame ``c`` of a blade (``x_c`` out of plane, ``y_c = z_c x x_c``, ``z_c`` along the blade; does not
pitch) and the blade frame ``b``, which pitches with the blade (ElastoDyn's ``SetCoordSy``,
``theta`` the blade pitch)::

    x_b = cos(theta) x_c - sin(theta) y_c,    y_b = sin(theta) x_c + cos(theta) y_c,    z_b = z_c

:class:`RootLoads` are ElastoDyn's ``RootFxb .. RootMzb`` in SI units: the force and moment the
blade puts on the hub at the blade root (the pitch bearing), in ``b``:

* ``Fz`` along the pitch axis (towards the tip: centrifugal positive) is the bearing's **axial
  force**; ``Fx`` (flapwise at zero pitch) and ``Fy`` (edgewise) are its **radial forces**;
* ``Mx`` (edgewise: in-plane gravity and aerodynamic torque) and ``My`` (flapwise: thrust) are its
  **tilting moments**;
* ``Mz`` about the pitch axis is the **pitching moment** the pitch drive works against
  (aerodynamic Cm and the aerodynamic centres' offsets; the deflected blade's in-plane loads; no
  mass offset: ElastoDyn's blade has its mass on the pitch axis).

:func:`bearing_inputs` turns them into the pitch bearing's inputs (``Loads`` and the drive's
load moment) with the mapping of :func:`slewing_model.loads.aeroelastic.bearing_loads`, the same
that reads these channels from an OpenFAST file (its ``mounting`` and ``frame`` conventions).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .bem import BladeAero, RotorGeometry

__all__ = ["BladeMass", "RootLoads", "root_loads", "bearing_inputs", "bearing_load_series", "GRAVITY"]

#: standard gravity, m/s^2
GRAVITY = 9.80665


@dataclass(frozen=True)
class BladeMass:
    """Structural blade of ElastoDyn (blade file), SI units.

    Attributes
    ----------
    span : ndarray (n,), m
        Stations from the blade root (``BlFract`` times the blade length).
    mass_density : ndarray (n,), kg/m
        ``BMassDen`` times ``AdjBlMs``.
    flap_stiffness : ndarray (n,), N m^2
        ``FlpStff`` times ``AdjFlSt``.
    flap_modes : ndarray (2, 5)
        Coefficients of ``x^2 .. x^6`` (``x = span / length``) of the flap mode shapes 1 and 2
        (``BldFl1Sh``, ``BldFl2Sh``; each 1 at the tip).
    flap_tuners : ndarray (2,)
        ``FlStTunr(1..2)``, multiply the modes' stiffness.
    hub_radius : float, m
        Rotor apex to blade root along the coned blade (ElastoDyn's ``HubRad``).
    edge_stiffness : ndarray (n,), N m^2, optional
        ``EdgStff`` times ``AdjEdSt``; with ``edge_mode`` the quasi-static edge deflection.
    edge_mode : ndarray (5,), optional
        Coefficients of ``x^2 .. x^6`` of the edge mode shape (``BldEdgSh``).
    """

    span: np.ndarray
    mass_density: np.ndarray
    flap_stiffness: np.ndarray
    flap_modes: np.ndarray
    flap_tuners: np.ndarray
    hub_radius: float
    edge_stiffness: np.ndarray | None = None
    edge_mode: np.ndarray | None = None
    _pre: dict = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        n = self.span.size
        if n < 2 or np.any(np.diff(self.span) <= 0) or self.span[0] != 0:
            raise ValueError("BladeMass.span: at least two stations, from 0 and increasing")
        if self.mass_density.shape != (n,) or self.flap_stiffness.shape != (n,):
            raise ValueError("BladeMass: mass_density and flap_stiffness need one value per station")
        if np.any(self.mass_density < 0) or np.any(self.flap_stiffness <= 0):
            raise ValueError("BladeMass: mass density must be >= 0, flap stiffness > 0")
        object.__setattr__(self, "_pre", self._precompute())

    @property
    def length(self) -> float:
        """Blade length, m."""
        return float(self.span[-1])

    @property
    def mass(self) -> float:
        """Blade mass, kg (trapezoidal integral of the mass density)."""
        return self._pre["mass"]

    @property
    def first_moment(self) -> float:
        """``int m s ds`` about the blade root, kg m (the in-plane gravity moment per g)."""
        return self._pre["s1"]

    def _precompute(self) -> dict:
        s, m, L = self.span, self.mass_density, self.length
        w = np.zeros_like(s)                         # trapezoid weights
        d = np.diff(s)
        w[:-1] += d / 2
        w[1:] += d / 2
        rho = self.hub_radius + s                    # distance from the apex along the blade
        wm = w * m
        x = s / L
        powers = np.arange(2, 7)
        phi = x[None, :] ** powers[:, None]          # (5, n): x^k
        dphi = powers[:, None] * x[None, :] ** (powers[:, None] - 1) / L
        ddphi = (powers * (powers - 1))[:, None] * x[None, :] ** np.maximum(powers[:, None] - 2, 0) / L**2
        modes = self.flap_modes @ phi                # (2, n)
        dmodes = self.flap_modes @ dphi
        ddmodes = self.flap_modes @ ddphi
        # generalised flap stiffness (ElastoDyn's KBF) and its centrifugal part per Omega^2 (KBFCent):
        # K_ij = FlStTunr_i int EI phi_i'' phi_j'' ds; Kc_ij = int T1 phi_i' phi_j' ds with the tension per
        # Omega^2 T1(s) = int_s^L m (R_hub + xi) dxi
        stiff = (w * self.flap_stiffness * ddmodes) @ ddmodes.T
        stiff = stiff * np.sqrt(np.outer(self.flap_tuners, self.flap_tuners))
        seg = 0.5 * (m[1:] * rho[1:] + m[:-1] * rho[:-1]) * d
        tension = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]])
        cent = (w * tension * dmodes) @ dmodes.T
        pre = {"stiff": stiff, "cent": cent, "mass": float(wm.sum()), "s1": float(wm @ s), "r1": float(wm @ rho),
               "sr": float(wm @ (s * rho)), "A": modes @ wm, "B": modes @ (wm * s), "C": modes @ (wm * rho),
               "D": (modes * wm) @ modes.T, "tip": modes[:, -1].copy(), "edge": None}
        if self.edge_stiffness is not None and self.edge_mode is not None:
            # one edge mode: K = int EI_edge phi''^2 ds; per Omega^2 the tension's int T1 phi'^2 ds less the
            # in-plane centrifugal int m phi^2 ds (a point moved by v in plane is pushed further out)
            e, de, dde = self.edge_mode @ phi, self.edge_mode @ dphi, self.edge_mode @ ddphi
            pre["edge"] = {"stiff": float(w @ (self.edge_stiffness * dde * dde)),
                           "cent": float(w @ (tension * de * de) - wm @ (e * e)), "A": float(wm @ e),
                           "B": float(wm @ (s * e)), "C": float(wm @ (rho * e)), "F": modes @ (wm * e),
                           "tip": float(e[-1])}
        return pre

    def flap_mode_shapes(self, span) -> np.ndarray:
        """The flap mode shapes (2, n) at ``span`` (m from the root)."""
        x = np.asarray(span, dtype=float) / self.length
        return self.flap_modes @ (x[None, :] ** np.arange(2, 7)[:, None])

    def edge_mode_shape(self, span) -> np.ndarray:
        """The edge mode shape (n,) at ``span`` (m from the root); zeros without an edge mode."""
        x = np.asarray(span, dtype=float) / self.length
        if self.edge_mode is None:
            return np.zeros_like(x)
        return self.edge_mode @ (x[None, :] ** np.arange(2, 7)[:, None])

    @classmethod
    def of_rotor(cls, rotor: RotorGeometry) -> "BladeMass":
        """The ElastoDyn blade a rotor file names (:class:`slewing_turbine.bem.RotorGeometry`)."""
        return cls.read_elastodyn(rotor.elastodyn_blade_file, length=rotor.tip_radius - rotor.hub_radius,
                                  hub_radius=rotor.hub_radius)

    @classmethod
    def read_elastodyn(cls, blade_file, *, length: float, hub_radius: float) -> "BladeMass":
        """Read an ElastoDyn blade file.

        Parameters
        ----------
        blade_file : str or path-like
            ``NBlInpSt``, ``FlStTunr(1..2)``, ``AdjBlMs``, ``AdjFlSt``, the distributed properties
            (columns named in the header line: ``BlFract``, ``BMassDen``, ``FlpStff`` needed,
            ``EdgStff`` with ``AdjEdSt`` for the edge deflection; an old file's ``PitchAxis`` column
            is ignored) and ``BldFl1Sh(2..6)``, ``BldFl2Sh(2..6)``, ``BldEdgSh(2..6)``.
        length : float, m
            Blade length (``TipRad - HubRad`` of the ElastoDyn main file).
        hub_radius : float, m
            ``HubRad``.

        Returns
        -------
        BladeMass

        Raises
        ------
        ValueError
            A value or column missing; the message names the file.
        """
        path = Path(blade_file)
        lines = path.read_text(encoding="latin-1").splitlines()
        values = {}
        for line in lines:
            words = line.split()
            if len(words) >= 2:
                try:
                    values[words[1]] = float(words[0])
                except ValueError:
                    pass
        for key in ("NBlInpSt", "AdjBlMs", "AdjFlSt"):
            if key not in values:
                raise ValueError(f"{path}: no {key} line: not an ElastoDyn blade file")
        head = next((i for i, line in enumerate(lines) if line.split()[:1] == ["BlFract"]), None)
        if head is None:
            raise ValueError(f"{path}: no distributed-properties header line starting with BlFract")
        names = lines[head].split()
        count = int(values["NBlInpSt"])
        rows = [[float(v) for v in line.split()[:len(names)]] for line in lines[head + 2:head + 2 + count]]
        table = np.array(rows)
        if table.shape != (count, len(names)):
            raise ValueError(f"{path}: NBlInpSt = {count} rows of {len(names)} columns expected")
        col = {name: table[:, k] for k, name in enumerate(names)}
        try:
            modes = np.array([[values[f"BldFl{m}Sh({k})"] for k in range(2, 7)] for m in (1, 2)])
            edge = np.array([values[f"BldEdgSh({k})"] for k in range(2, 7)])
        except KeyError as missing:
            raise ValueError(f"{path}: no {missing.args[0]} line (the mode shapes)") from None
        tuners = np.array([values.get("FlStTunr(1)", 1.0), values.get("FlStTunr(2)", 1.0)])
        edge_stiffness = col["EdgStff"] * values.get("AdjEdSt", 1.0) if "EdgStff" in col else None
        return cls(span=col["BlFract"] * float(length), mass_density=col["BMassDen"] * values["AdjBlMs"],
                   flap_stiffness=col["FlpStff"] * values["AdjFlSt"], flap_modes=modes, flap_tuners=tuners,
                   hub_radius=float(hub_radius), edge_stiffness=edge_stiffness,
                   edge_mode=edge if edge_stiffness is not None else None)


@dataclass(frozen=True)
class RootLoads:
    """Loads the blade puts on the hub at its root, ElastoDyn's blade frame ``b``, SI units
    (``RootFxb .. RootMzb``; frames and signs in the module docstring).

    Attributes
    ----------
    Fx, Fy : float, N
        Radial forces of the pitch bearing (flapwise, edgewise at zero pitch).
    Fz : float, N
        Axial force of the pitch bearing, towards the tip (centrifugal) positive.
    Mx, My : float, N m
        Tilting moments: ``Mx`` edgewise (in-plane), ``My`` flapwise (out of plane).
    Mz : float, N m
        Pitching moment about the pitch axis ``+z_b`` (nose up positive: against feathering).
    tip_deflection : float, m
        Quasi-static flap deflection of the tip along ``x_c`` (downwind positive; 0 when rigid).
    tip_edge_deflection : float, m
        Quasi-static edge deflection of the tip along ``y_c`` (against the rotation positive).
    """

    Fx: float
    Fy: float
    Fz: float
    Mx: float
    My: float
    Mz: float
    tip_deflection: float = 0.0
    tip_edge_deflection: float = 0.0

    def as_array(self) -> np.ndarray:
        """``[Fx, Fy, Fz, Mx, My, Mz]``."""
        return np.array([self.Fx, self.Fy, self.Fz, self.Mx, self.My, self.Mz])


def root_loads(aero: BladeAero | None, mass: BladeMass, azimuth: float, pitch: float, rotor_speed: float, *,
               tilt: float, cone: float, rotor_acceleration: float = 0.0, gravity: float = GRAVITY,
               deflection: bool = True) -> RootLoads:
    """Blade-root loads of one blade: aerodynamics, gravity, centrifugal and rotor-acceleration inertia.

    Parameters
    ----------
    aero : BladeAero or None
        The blade's aerodynamic loads (:func:`slewing_turbine.bem.bem_loads`, same ``pitch``,
        ``azimuth``, ``cone``, ``tilt``); None: no aerodynamic load.
    mass : BladeMass
    azimuth : float, rad
        0 with the blade up; the rotor turns clockwise seen from upwind.
    pitch : float, rad
        The blade's pitch (turns ``c`` into ``b``).
    rotor_speed : float, rad/s
    tilt, cone : float, rad
        ElastoDyn's ``ShftTilt`` (-5 deg for the NREL 5MW) and ``PreCone`` (-2.5 deg).
    rotor_acceleration : float, rad/s^2, optional
        The rotor's angular acceleration (in-plane inertia of the blade). Default 0.
    gravity : float, m/s^2, optional
    deflection : bool, optional
        With the quasi-static flap and edge deflections (default) or a rigid blade.

    Returns
    -------
    RootLoads
        In ``b``, SI.
    """
    p = mass._pre
    cb, sb = math.cos(cone), math.sin(cone)
    tau = -tilt                                        # rotor end lifted by tau
    ct, st = math.cos(tau), math.sin(tau)
    ca, sa = math.cos(azimuth), math.sin(azimuth)
    om2 = rotor_speed * rotor_speed
    acc = rotor_acceleration
    csb = cb * sb
    # per unit mass in c, at the point (u, v, rho) of the deflected blade (rho = R_hub + s from the apex):
    #   gravity (-g Z):  g_x = g (cb st + sb ca ct), g_y = -g sa ct, g_z = g (sb st - cb ca ct)
    #   centrifugal Omega^2 (P - (P.e1) e1):  (Omega^2 (u sb^2 - rho sb cb), Omega^2 v, Omega^2 (rho cb^2 - u sb cb))
    #   rotor acceleration -dOmega/dt e1 x P:  (0, dOmega/dt (rho cb - u sb), 0)
    # The root loads are int m f ds and int m p x f ds, p = (u, v, s); u = q . phi_flap, v = q_e phi_edge, so
    # every integral is one of the mass integrals of BladeMass (A, B, C, D: int m phi, m s phi, m rho phi,
    # m phi phi) times the mode amplitudes.
    gx = gravity * (cb * st + sb * ca * ct)
    gy = -gravity * sa * ct
    gz = gravity * (sb * st - cb * ca * ct)
    if aero is not None:
        wf, we = _at_aero_nodes(mass, aero.span)
    q0 = q1 = qe = 0.0
    if deflection:
        # quasi-static flap: (K + Omega^2 Kc) q = Q, Q_i = int f_x phi_i ds (aerodynamic normal force,
        # gravity, the precone's centrifugal part); edge: the same with one mode and the loads along y_c
        a, c = p["A"], p["C"]
        f0 = gx * a[0] - om2 * csb * c[0]
        f1 = gx * a[1] - om2 * csb * c[1]
        if aero is not None:
            fa = wf @ aero.normal
            f0 += fa[0]
            f1 += fa[1]
        k, kc = p["stiff"], p["cent"]
        k00, k01 = k[0, 0] + om2 * kc[0, 0], k[0, 1] + om2 * kc[0, 1]
        k10, k11 = k[1, 0] + om2 * kc[1, 0], k[1, 1] + om2 * kc[1, 1]
        det = k00 * k11 - k01 * k10
        q0 = (k11 * f0 - k01 * f1) / det
        q1 = (k00 * f1 - k10 * f0) / det
        edge = p["edge"]
        if edge is not None:
            fe = gy * edge["A"] + acc * cb * edge["C"]
            if aero is not None:
                fe -= float(we @ aero.tangential)
            qe = fe / (edge["stiff"] + om2 * edge["cent"])
    a, b, c, d = p["A"], p["B"], p["C"], p["D"]
    qa = q0 * a[0] + q1 * a[1]                         # int m u ds
    qb = q0 * b[0] + q1 * b[1]                         # int m s u ds
    qc = q0 * c[0] + q1 * c[1]                         # int m rho u ds
    qdq = q0 * q0 * d[0, 0] + 2.0 * q0 * q1 * d[0, 1] + q1 * q1 * d[1, 1]   # int m u^2 ds
    e = p["edge"] or {"A": 0.0, "B": 0.0, "C": 0.0, "F": (0.0, 0.0), "tip": 0.0}
    qf = q0 * e["F"][0] + q1 * e["F"][1]               # int m u phi_edge ds
    mm, s1, r1, sr = p["mass"], p["s1"], p["r1"], p["sr"]
    fx_ = mm * gx - om2 * csb * r1 + om2 * sb * sb * qa
    fy_ = mm * gy + acc * cb * r1 + om2 * qe * e["A"] - acc * sb * qa
    fz_ = mm * gz + om2 * cb * cb * r1 - om2 * csb * qa
    mx_ = (qe * (gz * e["A"] + om2 * cb * cb * e["C"] - om2 * csb * qf)
           - (gy * s1 + acc * cb * sr + om2 * qe * e["B"] - acc * sb * qb))
    my_ = gx * s1 - om2 * csb * sr + om2 * sb * sb * qb - (gz * qa + om2 * cb * cb * qc - om2 * csb * qdq)
    mz_ = (gy * qa + acc * cb * qc + om2 * qe * qf - acc * sb * qdq
           - qe * (gx * e["A"] - om2 * csb * e["C"] + om2 * sb * sb * qf))
    if aero is not None:
        fx_ += aero.root_shear_flap
        fy_ += aero.root_shear_edge
        mx_ += aero.root_edge
        my_ += aero.root_flap
        mz_ += aero.root_pitching_moment
        if deflection:                                 # the aerodynamic forces on the deflected blade about z
            ft = wf @ aero.tangential
            mz_ -= q0 * ft[0] + q1 * ft[1] + qe * float(we @ aero.normal)
    tip = q0 * p["tip"][0] + q1 * p["tip"][1]
    cp, sp = math.cos(pitch), math.sin(pitch)
    return RootLoads(float(cp * fx_ - sp * fy_), float(sp * fx_ + cp * fy_), float(fz_), float(cp * mx_ - sp * my_),
                     float(sp * mx_ + cp * my_), float(mz_), float(tip), float(qe * e["tip"]))


def _at_aero_nodes(mass: BladeMass, span: np.ndarray) -> tuple:
    """The flap mode shapes (2, n) and the edge mode shape (n,) at the aerodynamic nodes ``span``
    times the nodes' trapezoid weights, made once per node set and kept with ``mass``."""
    cache = mass._pre.setdefault("aero_nodes", {})
    key = span.tobytes()
    found = cache.get(key)
    if found is None:
        w = np.zeros_like(span)
        d = np.diff(span)
        w[:-1] += d / 2
        w[1:] += d / 2
        found = cache[key] = (np.ascontiguousarray(mass.flap_mode_shapes(span) * w), mass.edge_mode_shape(span) * w)
    return found


def bearing_load_series(time, root, pitch, *, mounting: str = "tip", frame: str = "rotating"):
    """Pitch-bearing inputs over time from root loads, by the mapping of
    :func:`slewing_model.loads.aeroelastic.bearing_loads` (the one that reads ``RootF*b``/``RootM*b``
    and ``BldPitch`` from an OpenFAST file).

    Parameters
    ----------
    time : array_like (n,), s
        At least two increasing times.
    root : array_like (n, 6) or sequence of RootLoads
        ``Fx, Fy, Fz`` (N), ``Mx, My, Mz`` (N m) in ``b`` (:class:`RootLoads`).
    pitch : array_like (n,), rad
        Blade pitch.
    mounting : {"tip", "hub"}, optional
        Which way the bearing's +z points (``bearing_loads``'s ``mounting``). Default "tip".
    frame : {"rotating", "fixed"}, optional
        Frame of the bearing's ``Fx..My``: the moving ring's (the blade's; default) or the fixed
        ring's (the hub's). Give the simulator or FMU the same ``load_frame``.

    Returns
    -------
    slewing_drives.load_series.LoadSeries
        ``loads`` (n, 6): the bearing's ``Fx, Fy, Fz, Mx, My`` and ``Mz`` (the moment the drive
        works against, positive against positive ``psi``), ``psi``, ``omega`` (rate of ``psi``)
        and ``load_frame``.
    """
    from slewing_model.loads.aeroelastic import bearing_loads
    from slewing_model.loads.openfast import OutputFile

    time = np.asarray(time, dtype=float)
    if not isinstance(root, np.ndarray) and len(root) and isinstance(root[0], RootLoads):
        root = np.array([r.as_array() for r in root])
    root = np.asarray(root, dtype=float).reshape(time.size, 6)
    pitch = np.broadcast_to(np.asarray(pitch, dtype=float), time.shape)
    names = ("RootFxb1", "RootFyb1", "RootFzb1", "RootMxb1", "RootMyb1", "RootMzb1")
    channels = {"Time": time, **{n: root[:, k] for k, n in enumerate(names)}, "BldPitch1": np.array(pitch)}
    units = {"Time": "s", **{n: ("N" if k < 3 else "N·m") for k, n in enumerate(names)}, "BldPitch1": "rad"}
    output = OutputFile("slewing_turbine.blade_loads", time, channels, units)
    return bearing_loads(output, "pitch", 1, mounting, frame=frame, source="b")


def bearing_inputs(root: RootLoads, pitch: float, *, mounting: str = "tip", frame: str = "rotating"):
    """The pitch bearing's inputs from one step's root loads (:func:`bearing_load_series`'s mapping).

    In the rotating frame the mapping is a fixed linear map of the six root loads (signs for the
    ``mounting``); it is taken once per mounting from :func:`bearing_load_series` itself (unit
    loads through ``bearing_loads``) and then applied at a few microseconds a step. ``"fixed"``
    runs the whole of :func:`bearing_load_series` every call (a few hundred microseconds).

    Parameters
    ----------
    root : RootLoads
    pitch : float, rad
    mounting : {"tip", "hub"}, optional
    frame : {"rotating", "fixed"}, optional

    Returns
    -------
    loads : slewing_model.Loads
        ``Fx, Fy, Fz, Mx, My`` on the bearing's moving ring (the blade's), in ``frame``.
    load_moment : float, N m
        The moment the pitch drive works against (``ElectricDrive``'s load torque: positive when
        it opposes a positive bearing rotation ``psi``).
    psi : float, rad
        The bearing's rotation for this pitch (``-pitch`` for ``"tip"``).
    """
    from slewing_model import Loads

    row = root.as_array()
    if frame == "rotating":
        matrix, psi_per_pitch = _rotating_map(mounting)
        f = row @ matrix
        psi = psi_per_pitch * float(pitch)
    else:
        series = bearing_load_series([0.0, 1.0], np.vstack([row, row]), [pitch, pitch], mounting=mounting,
                                     frame=frame)
        f, psi = series.loads[0], float(series.psi[0])
    return Loads(float(f[0]), float(f[1]), float(f[2]), float(f[3]), float(f[4])), float(f[5]), psi


@functools.lru_cache(maxsize=None)
def _rotating_map(mounting: str) -> tuple:
    """``bearing_loads``' mapping in the rotating frame as a matrix (row k: the bearing inputs of a unit
    root load k) and the bearing angle per radian of pitch, from :func:`bearing_load_series` itself;
    checked to be the same at two pitch angles (the rotating frame's mapping does not depend on it)."""
    maps = []
    for pitch in (1.0, 0.3):
        series = bearing_load_series(np.arange(6.0), np.eye(6), np.full(6, pitch), mounting=mounting,
                                     frame="rotating")
        maps.append((series.loads.copy(), float(series.psi[0]) / pitch))
    if not (np.array_equal(maps[0][0], maps[1][0]) and math.isclose(maps[0][1], maps[1][1])):
        raise RuntimeError("bearing_loads' rotating-frame mapping depends on the pitch: use frame='fixed' rules")
    return maps[0]
