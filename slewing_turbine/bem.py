"""Steady blade-element-momentum (BEM) aerodynamics of one blade, AeroDyn 15 style.

The model is AeroDyn 15's quasi-steady BEM as the NREL 5MW case sets it up (``Wake_Mod 1``,
``TipLoss``, ``HubLoss`` and ``TanInd`` True, ``AIDrag`` and ``TIDrag`` False, ``UseBlCm`` True),
without unsteady aerodynamics, dynamic inflow and tower influence:

* one residual in the inflow angle phi per node (Ning 2014, eq. 19 and its propeller-brake
  form), solved by Brent's method in a bracket that always holds a root (Ning's brackets
  ``(0, pi/2]``, ``[-pi/4, 0)``, ``[pi/2, pi)``), so every node converges;
* Prandtl's tip and hub losses ``F = (2/pi) acos(exp(-B (R - r) / (2 r |sin phi|)))`` times the
  hub's ``(2/pi) acos(exp(-B (r - R_hub) / (2 R_hub |sin phi|)))``;
* axial induction ``a = k / (1 + k)`` with ``k = sigma' c_n / (4 F sin^2 phi)``, and Buhl's
  high-thrust correction for ``k > 2/3`` (Buhl 2005, as Ning's eq. 22);
  tangential induction ``a' = k' / (1 - k')``, ``k' = sigma' c_t / (4 F sin phi cos phi)``;
  the induction uses the lift only (``c_n = c_l cos phi``, ``c_t = c_l sin phi``), the loads the
  full ``c_n = c_l cos phi + c_d sin phi``, ``c_t = c_l sin phi - c_d cos phi``;
* polars (alpha, Cl, Cd, Cm) looked up linearly in alpha (AeroDyn's ``InterpOrd`` 1), one table
  per node (the node's ``BlAFID``, no blending).

Geometry and frames (ElastoDyn's, angles with ElastoDyn's signs). The wind blows along the
global x axis (downwind, horizontal; no yaw error). The shaft is tilted by ``tilt`` (ElastoDyn's
``ShftTilt``; the NREL 5MW's -5 deg lifts the rotor end), the blade coned by ``cone`` (``PreCone``;
-2.5 deg puts the tips upwind), the rotor turns about the downwind shaft axis at ``rotor_speed``
(clockwise seen from upwind), ``azimuth`` 0 is the blade pointing up. The coned frame ``c`` of a
blade: ``x_c`` out of the rotor plane (downwind at zero cone), ``z_c`` along the blade towards the
tip, ``y_c = z_c x x_c``; the blade moves towards ``-y_c``. A node at ``rho = R_hub + span`` from
the apex (along the coned blade) sees (``tau = -tilt``)::

    V_x = U (cos(cone) cos(tau) - sin(cone) sin(tau) cos(azimuth))      # normal to the rotor plane
    V_y = Omega rho cos(cone) + U sin(tau) sin(azimuth)                   # in plane, onto the leading edge

(the form of CCBlade's ``__windComponents``; ``U`` the horizontal wind at the node: shear is the
caller's, see :func:`node_heights`), and the local radius ``r = rho cos(cone)`` sets the solidity
``sigma' = B c / (2 pi r)`` and the losses. Loads per unit length along the blade: ``normal``
``N' = q c c_n`` along ``+x_c``, ``tangential`` ``T' = q c c_t`` along ``-y_c`` (driving),
``q = rho_air W^2 / 2``, and the pitching moment about the aerodynamic centre ``q c^2 c_m``
about ``+z`` (nose up: towards a larger angle of attack, against a positive pitch).

Root sums (trapezoidal over the nodes, as AeroDyn's line-to-point load mapping), in ``c`` and
about the blade root (span 0): ``root_flap = int s N' ds`` (``RootMyc``), ``root_edge =
int s T' ds`` (``RootMxc``), shears ``int N' ds`` (``RootFxc``) and ``-int T' ds`` (``RootFyc``);
the shaft ``torque_contribution = int r T' ds`` and ``thrust = cos(cone) int N' ds``; the
``root_pitching_moment`` about the pitch axis ``z_b``: the Cm moments plus the aerodynamic
centres' offsets (``BlCrvAC``, ``BlSwpAC`` of the blade file, in the blade frame ``b`` that
pitches with the blade) times the forces.

The loop is compiled by numba (``cache=True``) where numba is installed; else the same code runs
as Python (correct, about a hundred times slower).

References
----------
Ning, S. A. (2014). A simple solution method for the blade element momentum equations with
guaranteed convergence. Wind Energy 17, 1327-1345.
Buhl, M. L. (2005). A new empirical relationship between thrust coefficient and induction factor
for the turbulent windmill state. NREL/TP-500-36834.
Jonkman, J. et al. (2009). Definition of a 5-MW reference wind turbine. NREL/TP-500-38060.
"""
from __future__ import annotations

import functools
import importlib.util
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib

__all__ = ["Polar", "Blade", "BladeAero", "RotorGeometry", "bem_loads", "node_heights", "read_polar",
           "COMPILED"]

_DEG = math.pi / 180.0
_PHI_EPS = 1e-6              # rad, Ning's epsilon at the ends of the brackets
_XTOL = 1e-10                # rad, Brent's tolerance on phi
_MAXITER = 100


# ----------------------------------------------------------------------------------------------
# file readers
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Polar:
    """One airfoil table: coefficients against the angle of attack.

    Attributes
    ----------
    name : str
        The file's name without its suffix.
    alpha : ndarray (n,), rad
        Angle of attack, increasing, covering -pi .. pi.
    cl, cd, cm : ndarray (n,)
        Lift, drag and pitching-moment (about the quarter chord, nose up positive) coefficients.
    """

    name: str
    alpha: np.ndarray
    cl: np.ndarray
    cd: np.ndarray
    cm: np.ndarray


def read_polar(path) -> Polar:
    """Read an AeroDyn 15 (AirfoilInfo v1) airfoil file's first table.

    Parameters
    ----------
    path : str or path-like
        The file: ``NumAlf`` then ``NumAlf`` rows of ``alpha (deg), Cl, Cd[, Cm]`` (comment lines
        starting with ``!`` skipped). A table without Cm gets Cm = 0.

    Returns
    -------
    Polar
        alpha in rad.

    Raises
    ------
    ValueError
        No ``NumAlf`` line, too few rows, or alpha not increasing; the message names the file.
    """
    path = Path(path)
    lines = path.read_text(encoding="latin-1").splitlines()
    start = next((i for i, line in enumerate(lines)
                  if len(line.split()) > 1 and line.split()[1].lower() == "numalf"), None)
    if start is None:
        raise ValueError(f"{path}: no NumAlf line: not an AeroDyn 15 airfoil file")
    count = int(float(lines[start].split()[0]))
    rows = []
    for line in lines[start + 1:]:
        words = line.split()
        if not words or words[0].startswith("!"):
            continue
        try:
            values = [float(w) for w in words[:4]]
        except ValueError:
            break
        rows.append(values + [0.0] * (4 - len(values)))
        if len(rows) == count:
            break
    if len(rows) != count:
        raise ValueError(f"{path}: NumAlf = {count} but {len(rows)} table rows follow")
    table = np.array(rows, dtype=float)
    if np.any(np.diff(table[:, 0]) <= 0):
        raise ValueError(f"{path}: alpha must increase down the table")
    return Polar(path.stem, table[:, 0] * _DEG, table[:, 1].copy(), table[:, 2].copy(), table[:, 3].copy())


@dataclass(frozen=True)
class Blade:
    """Aerodynamic definition of a blade (AeroDyn 15 blade file and polars) and its rotor.

    Attributes
    ----------
    span : ndarray (n,), m
        Node positions along the blade from its root (``BlSpn``).
    chord : ndarray (n,), m
    twist : ndarray (n,), rad
        Aerodynamic twist (``BlTwist``), positive towards feather (as pitch).
    airfoil : ndarray (n,) of int
        Index (0-based) of each node's polar in ``polars``.
    ac_flap, ac_edge : ndarray (n,), m
        Offsets of the aerodynamic centre from the pitch axis along ``x_b`` (``BlCrvAC``, downwind)
        and ``y_b`` (``BlSwpAC``, against the direction of rotation at zero pitch).
    polars : tuple of Polar
    hub_radius, tip_radius : float, m
        Apex to blade root and to tip along the coned blade (ElastoDyn's ``HubRad``, ``TipRad``).
    blade_count : int
    precone : float, rad
        ElastoDyn's ``PreCone`` (negative: tips upwind); the default ``cone`` of :func:`bem_loads`.
    shaft_tilt : float, rad
        ElastoDyn's ``ShftTilt`` (negative lifts the rotor end); the default ``tilt``.
    air_density : float, kg/m^3
    """

    span: np.ndarray
    chord: np.ndarray
    twist: np.ndarray
    airfoil: np.ndarray
    ac_flap: np.ndarray
    ac_edge: np.ndarray
    polars: tuple
    hub_radius: float
    tip_radius: float
    blade_count: int = 3
    precone: float = 0.0
    shaft_tilt: float = 0.0
    air_density: float = 1.225
    _tables: tuple = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        n = self.span.size
        for name in ("chord", "twist", "airfoil", "ac_flap", "ac_edge"):
            if getattr(self, name).shape != (n,):
                raise ValueError(f"Blade.{name}: {getattr(self, name).shape} values for {n} nodes")
        if n < 2 or np.any(np.diff(self.span) <= 0) or self.span[0] < 0:
            raise ValueError("Blade.span: at least two nodes, from >= 0 and increasing")
        if not 0 <= self.hub_radius < self.tip_radius:
            raise ValueError(f"hub_radius = {self.hub_radius}, tip_radius = {self.tip_radius}: need 0 <= hub < tip")
        if self.hub_radius + self.span[-1] > self.tip_radius * (1 + 1e-9):
            raise ValueError(f"the last node ({self.hub_radius + self.span[-1]} m from the apex) lies beyond "
                             f"tip_radius = {self.tip_radius} m")
        if np.any(self.airfoil < 0) or np.any(self.airfoil >= len(self.polars)):
            raise ValueError(f"Blade.airfoil: indices must lie in 0..{len(self.polars) - 1}")
        # the polars packed one after the other for the compiled loop, and the trapezoid weights
        sizes = np.array([p.alpha.size for p in self.polars], dtype=np.int64)
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        tables = (np.ascontiguousarray(np.concatenate([p.alpha for p in self.polars])),
                  np.ascontiguousarray(np.concatenate([p.cl for p in self.polars])),
                  np.ascontiguousarray(np.concatenate([p.cd for p in self.polars])),
                  np.ascontiguousarray(np.concatenate([p.cm for p in self.polars])),
                  np.ascontiguousarray(starts[self.airfoil]), np.ascontiguousarray(sizes[self.airfoil]),
                  np.ascontiguousarray(_trapezoid_weights(self.span)))
        object.__setattr__(self, "_tables", tables)

    @property
    def weights(self) -> np.ndarray:
        """Trapezoid weights of the nodes along the span, m (their sum is the spanned length)."""
        return self._tables[6]

    @classmethod
    def read_aerodyn(cls, blade_file, airfoil_dir, *, airfoils, hub_radius: float, tip_radius: float,
                     blade_count: int = 3, precone: float = 0.0, shaft_tilt: float = 0.0,
                     air_density: float = 1.225) -> "Blade":
        """Read an AeroDyn 15 blade file and the polars its nodes use.

        Parameters
        ----------
        blade_file : str or path-like
            ``NumBlNds`` then two header lines and one row per node: ``BlSpn BlCrvAC BlSwpAC
            BlCrvAng BlTwist BlChord BlAFID`` (m, m, m, deg, deg, m, -); further columns ignored.
        airfoil_dir : str or path-like
            Directory of the airfoil files.
        airfoils : sequence of str
            The AeroDyn main file's ``AFNames`` (file names in ``airfoil_dir``): ``BlAFID`` k
            is the k-th (1-based).
        hub_radius, tip_radius : float, m
        blade_count : int, optional
        precone, shaft_tilt : float, rad, optional
            ElastoDyn's ``PreCone`` and ``ShftTilt``.
        air_density : float, kg/m^3, optional

        Returns
        -------
        Blade
            Only the polars the nodes use are kept (re-indexed).

        Raises
        ------
        ValueError
            A malformed file or a ``BlAFID`` beyond ``airfoils``; the message names the file.
        """
        blade_file = Path(blade_file)
        lines = blade_file.read_text(encoding="latin-1").splitlines()
        start = next((i for i, line in enumerate(lines) if "numblnds" in line.lower()), None)
        if start is None:
            raise ValueError(f"{blade_file}: no NumBlNds line: not an AeroDyn 15 blade file")
        count = int(float(lines[start].split()[0]))
        rows = []
        for line in lines[start + 3:start + 3 + count]:
            words = line.split()
            try:
                rows.append([float(w) for w in words[:7]])
            except ValueError:
                raise ValueError(f"{blade_file}: bad node row {line!r}") from None
        if len(rows) != count or any(len(r) != 7 for r in rows):
            raise ValueError(f"{blade_file}: NumBlNds = {count} but {len(rows)} complete node rows follow")
        table = np.array(rows)
        ids = table[:, 6].astype(np.int64)
        if ids.min() < 1 or ids.max() > len(airfoils):
            raise ValueError(f"{blade_file}: BlAFID {ids.min()}..{ids.max()} but "
                             f"{len(airfoils)} airfoil files given")
        used = sorted(set(ids.tolist()))
        polars = tuple(read_polar(Path(airfoil_dir) / airfoils[k - 1]) for k in used)
        index = np.array([used.index(k) for k in ids], dtype=np.int64)
        return cls(span=table[:, 0].copy(), chord=table[:, 5].copy(), twist=table[:, 4] * _DEG, airfoil=index,
                   ac_flap=table[:, 1].copy(), ac_edge=table[:, 2].copy(), polars=polars,
                   hub_radius=float(hub_radius), tip_radius=float(tip_radius), blade_count=int(blade_count),
                   precone=float(precone), shaft_tilt=float(shaft_tilt), air_density=float(air_density))


def _trapezoid_weights(x: np.ndarray) -> np.ndarray:
    w = np.zeros_like(x, dtype=float)
    d = np.diff(x)
    w[:-1] += d / 2
    w[1:] += d / 2
    return w


@dataclass(frozen=True)
class RotorGeometry:
    """A rotor definition file (``examples/turbines/nrel5mw/rotor.toml``) in SI units.

    Attributes
    ----------
    path : Path
        The TOML file; the data files it names are relative to its directory.
    blade_count : int
    tip_radius, hub_radius : float, m
    precone, shaft_tilt : float, rad
        ElastoDyn's ``PreCone`` and ``ShftTilt`` (signs kept).
    hub_height : float, m
    air_density : float, kg/m^3
    aerodyn_blade_file, airfoil_dir, elastodyn_blade_file : Path
    airfoils : tuple of str
    """

    path: Path
    blade_count: int
    tip_radius: float
    hub_radius: float
    precone: float
    shaft_tilt: float
    hub_height: float
    air_density: float
    aerodyn_blade_file: Path
    airfoil_dir: Path
    airfoils: tuple
    elastodyn_blade_file: Path

    @classmethod
    def read_toml(cls, path) -> "RotorGeometry":
        """Read tables ``[rotor]``, ``[aerodyn]`` and ``[elastodyn]`` (units in the key names)."""
        path = Path(path)
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
        r, a, e = data["rotor"], data["aerodyn"], data["elastodyn"]
        here = path.parent
        return cls(path=path, blade_count=int(r["blade_count"]), tip_radius=float(r["tip_radius_m"]),
                   hub_radius=float(r["hub_radius_m"]), precone=float(r["precone_deg"]) * _DEG,
                   shaft_tilt=float(r["shaft_tilt_deg"]) * _DEG, hub_height=float(r["hub_height_m"]),
                   air_density=float(r["air_density_kgm3"]), aerodyn_blade_file=here / a["blade_file"],
                   airfoil_dir=here / a["airfoil_dir"], airfoils=tuple(a["airfoils"]),
                   elastodyn_blade_file=here / e["blade_file"])

    def read_blade(self) -> Blade:
        """The AeroDyn blade of this rotor (:meth:`Blade.read_aerodyn`)."""
        return Blade.read_aerodyn(self.aerodyn_blade_file, self.airfoil_dir, airfoils=self.airfoils,
                                  hub_radius=self.hub_radius, tip_radius=self.tip_radius,
                                  blade_count=self.blade_count, precone=self.precone,
                                  shaft_tilt=self.shaft_tilt, air_density=self.air_density)


def node_heights(blade: Blade, azimuth: float, hub_height: float, *, cone: float | None = None,
                 tilt: float | None = None) -> np.ndarray:
    """Height above ground of the blade's nodes, m, for a sheared wind.

    ``z = hub_height + rho (cos(cone) cos(tau) cos(azimuth) - sin(cone) sin(tau))``,
    ``rho = hub_radius + span``, ``tau = -tilt`` (the frames of the module docstring; the hub
    height is that of the rotor apex).

    Parameters
    ----------
    blade : Blade
    azimuth : float, rad
        0 with the blade up.
    hub_height : float, m
    cone, tilt : float, rad, optional
        Default: the blade's ``precone`` and ``shaft_tilt``.
    """
    cone = blade.precone if cone is None else cone
    tau = -(blade.shaft_tilt if tilt is None else tilt)
    rho = blade.hub_radius + blade.span
    return hub_height + rho * (math.cos(cone) * math.cos(tau) * math.cos(azimuth) - math.sin(cone) * math.sin(tau))


# ----------------------------------------------------------------------------------------------
# the compiled loop
# ----------------------------------------------------------------------------------------------

def _lookup(alpha, start, size, tab_alpha, tab_cl, tab_cd, tab_cm):
    """Cl, Cd, Cm of the table ``[start, start + size)`` at ``alpha`` (rad, wrapped to [-pi, pi)),
    linear between the table's points, held beyond its ends."""
    a = (alpha + math.pi) % (2.0 * math.pi) - math.pi
    lo = start
    hi = start + size - 1
    if a <= tab_alpha[lo]:
        return tab_cl[lo], tab_cd[lo], tab_cm[lo]
    if a >= tab_alpha[hi]:
        return tab_cl[hi], tab_cd[hi], tab_cm[hi]
    while hi - lo > 1:                      # bisection: tab_alpha[lo] <= a < tab_alpha[hi]
        mid = (lo + hi) // 2
        if tab_alpha[mid] <= a:
            lo = mid
        else:
            hi = mid
    f = (a - tab_alpha[lo]) / (tab_alpha[hi] - tab_alpha[lo])
    return (tab_cl[lo] + f * (tab_cl[hi] - tab_cl[lo]), tab_cd[lo] + f * (tab_cd[hi] - tab_cd[lo]),
            tab_cm[lo] + f * (tab_cm[hi] - tab_cm[lo]))


def _state(phi, vx, vy, theta, r, sigma, r_tip, r_hub, nb, start, size, tab_alpha, tab_cl, tab_cd, tab_cm,
           tip_loss, hub_loss, tan_ind):
    """Ning's residual at ``phi`` and the inductions: (residual, a, a', F, cl, cd, cm)."""
    s = math.sin(phi)
    c = math.cos(phi)
    cl, cd, cm = _lookup(phi - theta, start, size, tab_alpha, tab_cl, tab_cd, tab_cm)
    cn = cl * c                                  # AIDrag False: the induction sees the lift only
    ct = cl * s                                  # TIDrag False
    f = 1.0
    if tip_loss:                                 # Prandtl, Ning eq. (A4)
        f *= 2.0 / math.pi * math.acos(min(1.0, math.exp(-nb / 2.0 * (r_tip - r) / (r * abs(s)))))
    if hub_loss:
        f *= 2.0 / math.pi * math.acos(min(1.0, math.exp(-nb / 2.0 * (r - r_hub) / (r_hub * abs(s)))))
    if f < 1e-12:
        return 0.0, 0.0, 0.0, 0.0, cl, cd, cm
    k = sigma * cn / (4.0 * f * s * s)           # Ning eq. (16)
    kp = sigma * ct / (4.0 * f * s * c)          # Ning eq. (17)
    if phi > 0.0:
        if k <= 2.0 / 3.0:                       # momentum region
            a = k / (1.0 + k) if k != -1.0 else 0.0
        else:                                    # Buhl's empirical region (Ning eq. 22)
            g1 = 2.0 * f * k - (10.0 / 9.0 - f)
            g2 = 2.0 * f * k - f * (4.0 / 3.0 - f)
            g3 = 2.0 * f * k - (25.0 / 9.0 - 2.0 * f)
            if abs(g3) < 1e-6:
                a = 1.0 - 1.0 / (2.0 * math.sqrt(g2))
            else:
                a = (g1 - math.sqrt(abs(g2))) / g3
    else:                                        # propeller brake region
        a = k / (k - 1.0) if k > 1.0 else 0.0
    if not tan_ind:
        kp = 0.0
    ap = kp / (1.0 - kp)
    lam = vy / vx                                # local speed ratio
    if phi > 0.0:
        res = s / (1.0 - a) - c / lam * (1.0 - kp)   # Ning eq. (19); 1 - k' = 1 / (1 + a')
    else:
        res = s * (1.0 - k) - c / lam * (1.0 - kp)
    return res, a, ap, f, cl, cd, cm


def _brent(lo, hi, flo, fhi, vx, vy, theta, r, sigma, r_tip, r_hub, nb, start, size,
           tab_alpha, tab_cl, tab_cd, tab_cm, tip_loss, hub_loss, tan_ind):
    """Root of the residual in [lo, hi] (signs of ``flo``, ``fhi`` differ): Brent's method
    (the algorithm of scipy's ``brentq``)."""
    xpre, xcur, fpre, fcur = lo, hi, flo, fhi
    xblk = fblk = spre = scur = 0.0
    for _ in range(_MAXITER):
        if fpre * fcur < 0.0:
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = 0.5 * (_XTOL + 4e-16 * abs(xcur))
        sbis = 0.5 * (xblk - xcur)
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:                     # secant
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:                                # inverse quadratic
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre, scur = sbis, sbis
        else:
            spre, scur = sbis, sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0.0 else -delta)
        fcur = _state(xcur, vx, vy, theta, r, sigma, r_tip, r_hub, nb, start, size, tab_alpha, tab_cl, tab_cd,
                      tab_cm, tip_loss, hub_loss, tan_ind)[0]
    return xcur


def _blade_kernel(wind, omega, pitch, azimuth, cone, tilt, rho_air, nb, hub_radius, tip_radius, span, chord,
                  twist, ac_flap, ac_edge, weights, starts, sizes, tab_alpha, tab_cl, tab_cd, tab_cm,
                  tip_loss, hub_loss, tan_ind):
    """The BEM of every node and the root sums. Returns ``nodes`` (9, n): phi, alpha, a, a', W,
    N', T', M' (Cm), F; and ``sums`` (8,): RootMyc, RootMxc, RootFxc, RootFyc, Mz about the
    pitch axis, torque, thrust, count of nodes without a bracket."""
    n = span.shape[0]
    nodes = np.zeros((9, n))
    sums = np.zeros(8)
    cc = math.cos(cone)
    tau = -tilt
    vx_factor = math.cos(cone) * math.cos(tau) - math.sin(cone) * math.sin(tau) * math.cos(azimuth)
    vy_wind = math.sin(tau) * math.sin(azimuth)
    r_tip = tip_radius * cc
    r_hub = hub_radius * cc
    cp = math.cos(pitch)
    sp = math.sin(pitch)
    for j in range(n):
        rho = hub_radius + span[j]
        r = rho * cc
        vx = wind[j] * vx_factor
        vy = omega * r + wind[j] * vy_wind
        theta = twist[j] + pitch
        sigma = nb * chord[j] / (2.0 * math.pi * r)
        st, sz = starts[j], sizes[j]
        a = ap = 0.0
        f = 1.0
        if vx <= 1e-9 * max(1.0, abs(vy)) or abs(vy) <= 1e-9 * max(1.0, abs(vx)):
            # no through-flow or no rotation: no induction, the blade sees the wind as it is
            phi = math.atan2(vx, vy)
        else:
            args = (vx, vy, theta, r, sigma, r_tip, r_hub, nb, st, sz, tab_alpha, tab_cl, tab_cd, tab_cm,
                    tip_loss, hub_loss, tan_ind)
            lo, hi = _PHI_EPS, 0.5 * math.pi       # Ning's brackets, in his order
            flo = _state(lo, *args)[0]
            fhi = _state(hi, *args)[0]
            if flo * fhi > 0.0:
                f1 = _state(-0.25 * math.pi, *args)[0]
                f2 = _state(-_PHI_EPS, *args)[0]
                if f1 < 0.0 and f2 > 0.0:
                    lo, hi, flo, fhi = -0.25 * math.pi, -_PHI_EPS, f1, f2
                else:
                    lo, hi = 0.5 * math.pi, math.pi - _PHI_EPS
                    flo = fhi
                    fhi = _state(hi, *args)[0]
            if flo * fhi > 0.0:                    # no root (never seen): no induction
                phi = math.atan2(vx, vy)
                sums[7] += 1.0
            else:
                phi = _brent(lo, hi, flo, fhi, *args)
                _, a, ap, f, _, _, _ = _state(phi, *args)
        if f < 1e-12:                              # at the hub or tip: the loss factor is zero
            nodes[0, j] = phi
            nodes[1, j] = phi - theta
            continue
        alpha = phi - theta
        cl, cd, cm = _lookup(alpha, st, sz, tab_alpha, tab_cl, tab_cd, tab_cm)
        w2 = (vx * (1.0 - a)) ** 2 + (vy * (1.0 + ap)) ** 2
        q = 0.5 * rho_air * w2
        sphi = math.sin(phi)
        cphi = math.cos(phi)
        fn = q * chord[j] * (cl * cphi + cd * sphi)      # along +x_c, N/m
        ft = q * chord[j] * (cl * sphi - cd * cphi)      # along -y_c (driving), N/m
        mp = q * chord[j] * chord[j] * cm                # about +z (nose up), N m/m
        nodes[0, j] = phi
        nodes[1, j] = alpha
        nodes[2, j] = a
        nodes[3, j] = ap
        nodes[4, j] = math.sqrt(w2)
        nodes[5, j] = fn
        nodes[6, j] = ft
        nodes[7, j] = mp
        nodes[8, j] = f
        w = weights[j]
        sums[0] += w * span[j] * fn                      # RootMyc (flap), about the root
        sums[1] += w * span[j] * ft                      # RootMxc (edge)
        sums[2] += w * fn                                # RootFxc
        sums[3] -= w * ft                                # RootFyc
        fxb = cp * fn + sp * ft                          # force per length in b: x_b = cos x_c - sin y_c
        fyb = sp * fn - cp * ft
        sums[4] += w * (mp + ac_flap[j] * fyb - ac_edge[j] * fxb)   # about +z_b
        sums[5] += w * r * ft                            # shaft torque
        sums[6] += w * cc * fn                           # thrust along the shaft
    return nodes, sums


def _numba_installed() -> bool:
    try:
        return importlib.util.find_spec("numba") is not None
    except (ImportError, ValueError):
        return False


#: whether the loop runs compiled by numba (else as Python); numba is imported, and the loop compiled
#: or loaded from numba's on-disk cache, at the first :func:`bem_loads`
COMPILED = _numba_installed()


@functools.lru_cache(maxsize=1)
def _kernel():
    """The loop: compiled by numba (``cache=True``: ``__pycache__`` beside this file) where it is
    installed, with its helpers compiled in place of their Python definitions; else the Python code."""
    if not COMPILED:
        return _blade_kernel
    import numba

    g = globals()
    for name in ("_lookup", "_state", "_brent"):
        if not hasattr(g[name], "py_func"):
            g[name] = numba.njit(cache=True, nogil=True)(g[name])
    return numba.njit(cache=True, nogil=True)(_blade_kernel)


# ----------------------------------------------------------------------------------------------
# public API
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class BladeAero:
    """Steady aerodynamic loads of one blade (:func:`bem_loads`), SI units.

    Per node (arrays (n,), at ``span``):

    Attributes
    ----------
    span : ndarray, m
        Node positions from the blade root.
    normal : ndarray, N/m
        Force per unit length along ``x_c`` (out of the rotor plane, downwind): ``N'``.
    tangential : ndarray, N/m
        Force per unit length in the rotor plane, in the direction of rotation (``-y_c``): ``T'``.
    pitching_moment : ndarray, N m/m
        Moment per unit length about the aerodynamic centre from Cm, about ``+z`` (nose up).
    inflow_angle, angle_of_attack : ndarray, rad
    axial_induction, tangential_induction : ndarray
    relative_speed : ndarray, m/s
    loss_factor : ndarray
        Prandtl's ``F`` (tip times hub).

    Per blade (floats):

    root_flap : float, N m
        Out-of-plane moment about the blade root in the coned frame (``RootMyc``; thrust positive).
    root_edge : float, N m
        In-plane moment about the blade root (``RootMxc``; driving positive).
    root_shear_flap, root_shear_edge : float, N
        ``RootFxc`` (along ``x_c``) and ``RootFyc`` (along ``y_c``: negative when driving).
    root_pitching_moment : float, N m
        Moment about the pitch axis ``+z_b``: the Cm moments and the aerodynamic centres'
        offsets times the forces (``RootMzb``'s aerodynamic part).
    torque_contribution : float, N m
        This blade's part of the aerodynamic shaft torque (``int r T' ds``).
    thrust : float, N
        This blade's force along the shaft (``cos(cone) int N' ds``).
    unbracketed : int
        Nodes where no bracket held a root (0 in every case seen; no induction there).
    """

    span: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray
    pitching_moment: np.ndarray
    inflow_angle: np.ndarray
    angle_of_attack: np.ndarray
    axial_induction: np.ndarray
    tangential_induction: np.ndarray
    relative_speed: np.ndarray
    loss_factor: np.ndarray
    root_flap: float
    root_edge: float
    root_shear_flap: float
    root_shear_edge: float
    root_pitching_moment: float
    torque_contribution: float
    thrust: float
    unbracketed: int = 0


def bem_loads(blade: Blade, wind_at_nodes, rotor_speed: float, pitch: float, *, azimuth: float = 0.0,
              cone: float | None = None, tilt: float | None = None, air_density: float | None = None,
              tip_loss: bool = True, hub_loss: bool = True, tangential_induction: bool = True) -> BladeAero:
    """Steady BEM loads of one blade.

    Parameters
    ----------
    blade : Blade
    wind_at_nodes : float or array_like (n,), m/s
        Horizontal wind speed at each node (along the wind, no yaw error), shear applied by the
        caller (:func:`node_heights`); a float for a uniform wind.
    rotor_speed : float, rad/s
        About the downwind shaft axis (clockwise seen from upwind), >= 0.
    pitch : float, rad
        This blade's pitch angle (positive towards feather).
    azimuth : float, rad, optional
        This blade's azimuth, 0 pointing up (enters with the tilt). Default 0.
    cone, tilt : float, rad, optional
        ElastoDyn's ``PreCone`` and ``ShftTilt``; default the blade's.
    air_density : float, kg/m^3, optional
        Default the blade's.
    tip_loss, hub_loss, tangential_induction : bool, optional
        AeroDyn's ``TipLoss``, ``HubLoss``, ``TanInd`` (all True by default, as the NREL 5MW case).

    Returns
    -------
    BladeAero

    Raises
    ------
    ValueError
        A wind array of the wrong length, or an input that is not finite.
    """
    n = blade.span.size
    wind = np.asarray(wind_at_nodes, dtype=float)
    if wind.ndim == 0:
        wind = np.full(n, float(wind))
    elif wind.shape != (n,):
        raise ValueError(f"wind_at_nodes: {wind.shape} values for {n} nodes")
    elif not wind.flags.c_contiguous:
        wind = np.ascontiguousarray(wind)
    cone = blade.precone if cone is None else float(cone)
    tilt = blade.shaft_tilt if tilt is None else float(tilt)
    rho = blade.air_density if air_density is None else float(air_density)
    for name, value in (("rotor_speed", rotor_speed), ("pitch", pitch), ("azimuth", azimuth), ("cone", cone),
                        ("tilt", tilt), ("air_density", rho)):
        if not math.isfinite(value):
            raise ValueError(f"{name} = {value!r}: must be finite")
    alpha, cl, cd, cm, starts, sizes, weights = blade._tables
    nodes, sums = _kernel()(wind, float(rotor_speed), float(pitch), float(azimuth), cone, tilt, rho,
                          float(blade.blade_count), blade.hub_radius, blade.tip_radius, blade.span, blade.chord,
                          blade.twist, blade.ac_flap, blade.ac_edge, weights, starts, sizes, alpha, cl, cd, cm,
                          bool(tip_loss), bool(hub_loss), bool(tangential_induction))
    return BladeAero(blade.span, nodes[5], nodes[6], nodes[7], nodes[0], nodes[1], nodes[2], nodes[3], nodes[4],
                     nodes[8], float(sums[0]), float(sums[1]), float(sums[2]), float(sums[3]), float(sums[4]),
                     float(sums[5]), float(sums[6]), int(sums[7]))
