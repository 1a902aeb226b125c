"""Bearing definition: nominal geometry of a four-point contact slewing bearing.

Paper section 2.1 and Figure 2. Everything in this module is SI (m, rad, Pa);
the TOML definition files use the unit spelled in each key name
(``pitch_diameter_mm``) and are converted once, on reading, by
:func:`bearing_from_dict`.

Conventions (``DESIGN.md``):

* z is the bearing axis; the cross-section is drawn in (r, z).
* Contact 1 = upper-outer, 3 = lower-inner (diagonal 1, loaded when the inner
  ring is pushed towards +z); 4 = lower-outer, 2 = upper-inner (diagonal 2).
  The outer ring owns contacts 1 and 4, the inner ring 2 and 3.
* The groove centre of a contact lies on the contact line, on the far side of
  the ball centre, at ``groove_radius - ball_diameter / 2`` from it.
* Ball ``b`` (0-based) sits at ``phi_b = first_ball_angle + 2 pi b / B``.
"""
from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass, field, asdict
from typing import Any, Mapping

import numpy as np

from .conventions import (BEARING_TABLES, CONTACTS, DIAGONALS, RING_CONTACTS,  # noqa: F401  (the conventions
                          BearingDefinitionError, check_known_keys, fail as _fail)  # belong to this interface)
from .manufacturing import ManufacturingErrors, errors_from_table


def _connection_from_dict(d: dict) -> dict:
    """``{ring: Adapter or ImportedStiffness}`` from their dicts (:func:`.connection.connection_from_dict`;
    the module is imported for a connected bearing only)."""
    from .connection import connection_from_dict

    return {r: connection_from_dict(c) for r, c in d.items()}


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


def _subtable(data: Mapping[str, Any], name: str) -> Mapping[str, Any]:
    """The table ``[name]`` of a definition (empty when absent), its keys checked."""
    table = data.get(name, {})
    if not isinstance(table, Mapping):
        _fail(name, table, f"must be a table [{name}]")
    check_known_keys(table, name, BEARING_TABLES[name])
    return table


@dataclass(frozen=True)
class RingSection:
    """Rectangular ring cross-section, before the groove is cut (paper Fig. 3).

    Attributes
    ----------
    inner_radius, outer_radius : float
        Radial extent of the ring: radius of its bore and of its outer face, m.
    height : float
        Axial extent, centred on the ball plane z = 0, m.
    bolted_face : {"lower", "upper"}
        The face bolted to the support for the ``clamped`` and ``frictionless``
        boundary conditions: ``"lower"`` (z = -height/2) or ``"upper"``.
    """

    inner_radius: float
    outer_radius: float
    height: float
    bolted_face: str


@dataclass(frozen=True)
class Bearing:
    """Nominal definition of a four-point contact slewing bearing, SI units.

    Frozen: build one with :func:`load_bearing` (TOML file) or
    :func:`bearing_from_dict`, change it with :meth:`with_preload`,
    :meth:`with_errors` and :meth:`with_connection`.

    Attributes
    ----------
    name : str
        Name of the bearing (``"bearing"`` when the file gives none).
    pitch_diameter : float
        ``dm``, diameter of the circle through the ball centres, m.
    ball_diameter : float
        Nominal ball diameter ``Dw_nom`` (without preload), m.
    groove_radius : ndarray, shape (4,)
        Raceway (groove) radius ``Rc`` of contacts 1..4, m.
    contact_angle : float
        Initial (nominal) contact angle, rad.
    ball_count : int
        Number of balls ``B``.
    preload : float, default 0.0
        Ball oversize ``delta_P`` (paper eq 5), m; negative for clearance.
    youngs_modulus : float, default 200e9
        Young's modulus of balls and rings, Pa.
    poisson_ratio : float, default 0.3
        Poisson's ratio of balls and rings.
    moving_ring : {"inner", "outer"}
        The ring the loads act on (default ``"inner"``).
    first_ball_angle : float, default 0.0
        Angular position ``phi_0`` of ball 0, rad.
    outer_section, inner_section : RingSection
        Ring cross-sections (documented defaults when the file gives none).
    errors : ManufacturingErrors or None
        Measured or synthetic manufacturing errors; None for the nominal bearing.
    connection : dict or None
        ``{"outer": ..., "inner": ...}`` (either or both): what each ring's bolted face is bolted
        to (an adapter or an imported stiffness); None or ``{}``: nothing (the superelement's
        boundary condition applies).
    source : dict
        The definition as read (TOML tables), kept for reference; not compared.

    Examples
    --------
    >>> from slewing_model import load_bearing
    >>> b = load_bearing("examples/bearings/table1.toml")
    >>> b.ball_count, b.osculation.shape
    (100, (4,))
    """

    name: str
    pitch_diameter: float
    ball_diameter: float
    groove_radius: np.ndarray
    contact_angle: float
    ball_count: int
    preload: float = 0.0
    youngs_modulus: float = 200e9
    poisson_ratio: float = 0.3
    moving_ring: str = "inner"
    first_ball_angle: float = 0.0
    outer_section: RingSection | None = None
    inner_section: RingSection | None = None
    errors: Any = None
    connection: Any = None
    source: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    # ---- derived quantities -------------------------------------------------
    @property
    def osculation(self) -> np.ndarray:
        """Osculation ratio ``s = Dw / (2 Rc)`` of contacts 1..4 (paper eq 10), shape (4,)."""
        return self.ball_diameter / (2.0 * self.groove_radius)

    @functools.cached_property
    def ball_angles(self) -> np.ndarray:
        """Angular position ``phi_b`` of every ball, rad, shape (B,) (read-only: formed once, the
        assembly asks at every new rotation)."""
        b = np.arange(self.ball_count)
        return _read_only(self.first_ball_angle + 2.0 * np.pi * b / self.ball_count)

    @property
    def contact_normals(self) -> np.ndarray:
        """Unit vectors (r, z) from the ball centre to contact points 1..4, shape (4, 2)."""
        c, s = math.cos(self.contact_angle), math.sin(self.contact_angle)
        return np.array([[c, s], [-c, s], [-c, -s], [c, -s]])

    @functools.cached_property
    def groove_centres(self) -> np.ndarray:
        """Nominal groove-centre positions (R, z) of contacts 1..4, m, shape (4, 2) (read-only:
        formed once).

        On the contact line, on the far side of the ball centre, at
        ``Rc - Dw/2`` from the ball centre ``(dm/2, 0)`` (paper Fig. 2)."""
        offset = self.groove_radius - self.ball_diameter / 2.0
        centre = np.array([self.pitch_diameter / 2.0, 0.0])
        return _read_only(centre - offset[:, None] * self.contact_normals)

    def groove_edge_angle(self, contact: int) -> float:
        """Angle at which the raceway arc of a contact meets the ring's land.

        A contact ellipse that reaches past this angle is truncated.

        Parameters
        ----------
        contact : int
            Contact number, 1..4.

        Returns
        -------
        float
            Angle, seen from the groove centre and measured from the radial direction as
            the contact angle is, at which the raceway meets the land (the face towards the
            other ring), rad.
        """
        i = contact - 1
        ring = self.outer_section if contact in RING_CONTACTS["outer"] else self.inner_section
        o_r = self.groove_centres[i, 0]
        land = ring.inner_radius if contact in RING_CONTACTS["outer"] else ring.outer_radius
        cos_edge = abs(land - o_r) / self.groove_radius[i]
        return math.acos(min(cos_edge, 1.0))

    def with_preload(self, preload: float) -> "Bearing":
        """A copy with another ball preload.

        Parameters
        ----------
        preload : float
            Ball oversize, m; negative for clearance. Its magnitude must be below
            10 % of the ball diameter.

        Returns
        -------
        Bearing
            The new definition.

        Raises
        ------
        BearingDefinitionError
            If the preload is not finite or too large.
        """
        _check_preload(preload, self.ball_diameter, "preload")
        return _replace(self, preload=float(preload))

    def with_errors(self, errors) -> "Bearing":
        """A copy carrying these manufacturing errors.

        Parameters
        ----------
        errors : ManufacturingErrors or None
            The errors; None for the nominal bearing.

        Returns
        -------
        Bearing
            The new definition.
        """
        return _replace(self, errors=errors)

    def with_connection(self, connection) -> "Bearing":
        """A copy whose rings are bolted to other structures.

        Parameters
        ----------
        connection : dict or None
            ``{ring: Adapter or ImportedStiffness}``, ring ``"outer"`` or ``"inner"``;
            None: bolted to nothing (free, clamped or frictionless as the superelement's
            boundary condition says).

        Returns
        -------
        Bearing
            The new definition.

        Raises
        ------
        BearingDefinitionError
            If a key is not a ring name or its value belongs to the other ring.
        """
        connection = dict(connection) if connection else None
        for ring, c in (connection or {}).items():
            if ring not in RING_CONTACTS or getattr(c, "ring", None) != ring:
                _fail(f"connection.{ring}", c, "keys must be 'outer' or 'inner', each holding that ring's "
                      "Adapter or ImportedStiffness")
        return _replace(self, connection=connection)

    def to_dict(self) -> dict:
        """The definition as plain SI data (for hashes, JSON and the FMU).

        Returns
        -------
        dict
            Keys as the attribute names, values in SI units (lists for arrays);
            ``errors`` and ``connection`` only when present.
        """
        d = {
            "name": self.name,
            "pitch_diameter": self.pitch_diameter,
            "ball_diameter": self.ball_diameter,
            "groove_radius": [float(x) for x in self.groove_radius],
            "contact_angle": self.contact_angle,
            "ball_count": self.ball_count,
            "preload": self.preload,
            "youngs_modulus": self.youngs_modulus,
            "poisson_ratio": self.poisson_ratio,
            "moving_ring": self.moving_ring,
            "first_ball_angle": self.first_ball_angle,
            "outer_section": asdict(self.outer_section),
            "inner_section": asdict(self.inner_section),
        }
        if self.errors is not None:
            d["errors"] = self.errors.to_dict()
        if self.connection:     # absent when there is none: the hashes of unconnected bearings stay
            d["connection"] = {r: self.connection[r].to_dict() for r in sorted(self.connection)}
        return d

    @classmethod
    def from_si_dict(cls, d: Mapping[str, Any]) -> "Bearing":
        """Inverse of :meth:`to_dict` (no unit conversion; validated again).

        Parameters
        ----------
        d : mapping
            Data as :meth:`to_dict` writes it, SI units.

        Returns
        -------
        Bearing
            The validated definition.
        """
        errors = ManufacturingErrors.from_dict(d["errors"]) if d.get("errors") else None
        b = cls(
            name=d["name"],
            pitch_diameter=float(d["pitch_diameter"]),
            ball_diameter=float(d["ball_diameter"]),
            groove_radius=np.asarray(d["groove_radius"], dtype=float),
            contact_angle=float(d["contact_angle"]),
            ball_count=int(d["ball_count"]),
            preload=float(d["preload"]),
            youngs_modulus=float(d["youngs_modulus"]),
            poisson_ratio=float(d["poisson_ratio"]),
            moving_ring=d["moving_ring"],
            first_ball_angle=float(d["first_ball_angle"]),
            outer_section=RingSection(**d["outer_section"]),
            inner_section=RingSection(**d["inner_section"]),
            errors=errors,
            connection=_connection_from_dict(d["connection"]) if d.get("connection") else None,
        )
        validate(b)
        return b


def _replace(bearing: Bearing, **changes) -> Bearing:
    from dataclasses import replace

    return replace(bearing, **changes)


# ---- reading and validation --------------------------------------------------

_MM = 1e-3
_UM = 1e-6
_DEG = math.pi / 180.0


def _number(section: Mapping[str, Any], key: str, where: str, default=None) -> float:
    """A finite real number from ``section[key]``; ``where`` prefixes the key in messages."""
    name = f"{where}{key}"
    if key not in section:
        if default is None:
            _fail(name, None, "missing key (required)")
        return default
    value = section[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        _fail(name, value, "must be a number")
    if not math.isfinite(value):
        _fail(name, value, "must be a finite number (not NaN or infinite)")
    return float(value)


def _positive(section, key, where, default=None) -> float:
    value = _number(section, key, where, default)
    if value <= 0.0:
        _fail(f"{where}{key}", value, "must be > 0")
    return value


def _check_preload(preload: float, ball_diameter: float, key: str) -> None:
    if not math.isfinite(preload):
        _fail(key, preload, "must be a finite number (not NaN or infinite)")
    if abs(preload) >= 0.1 * ball_diameter:
        _fail(key, preload, f"must be smaller in magnitude than 10 % of the ball diameter ({0.1 * ball_diameter:g} m)")


def default_sections(pitch_diameter: float, ball_diameter: float) -> tuple[RingSection, RingSection]:
    """Ring cross-sections used when the definition gives none.

    Proportional to the ball diameter ``Dw``, in the range of pitch and yaw
    bearings of catalogues: a gap of ``0.1 Dw`` between the rings at the pitch
    circle, each ring ``2 Dw`` wide radially from the pitch circle and
    ``2.5 Dw`` high. The outer ring is bolted on its lower face, the inner ring
    on its upper face.
    """
    r = pitch_diameter / 2.0
    gap = 0.1 * ball_diameter
    outer = RingSection(r + gap / 2.0, r + 2.0 * ball_diameter, 2.5 * ball_diameter, "lower")
    inner = RingSection(r - 2.0 * ball_diameter, r - gap / 2.0, 2.5 * ball_diameter, "upper")
    return outer, inner


def _sections(rings: Mapping[str, Any], dm: float, dw: float) -> tuple[RingSection, RingSection]:
    outer_d, inner_d = default_sections(dm, dw)
    w = "rings."
    gap = _positive(rings, "gap_mm", w, (outer_d.inner_radius - inner_d.outer_radius) / _MM) * _MM
    outer_dia = _positive(rings, "outer_ring_outer_diameter_mm", w, 2 * outer_d.outer_radius / _MM) * _MM
    inner_bore = _positive(rings, "inner_ring_bore_diameter_mm", w, 2 * inner_d.inner_radius / _MM) * _MM
    h_out = _positive(rings, "outer_ring_height_mm", w, outer_d.height / _MM) * _MM
    h_in = _positive(rings, "inner_ring_height_mm", w, inner_d.height / _MM) * _MM
    faces = {}
    for ring, default in (("outer", "lower"), ("inner", "upper")):
        key = f"{ring}_ring_bolted_face"
        face = rings.get(key, default)
        if face not in ("lower", "upper"):
            _fail(w + key, face, "must be 'lower' or 'upper'")
        faces[ring] = face
    r = dm / 2.0
    if gap >= dw / 2.0:
        _fail(w + "gap_mm", gap / _MM, f"must be smaller than half the ball diameter ({dw / 2 / _MM:g} mm)")
    if outer_dia / 2.0 <= r + dw:
        _fail(w + "outer_ring_outer_diameter_mm", outer_dia / _MM,
              f"must exceed pitch diameter + 2 x ball diameter ({(2 * r + 2 * dw) / _MM:g} mm) so the groove fits")
    if inner_bore / 2.0 >= r - dw:
        _fail(w + "inner_ring_bore_diameter_mm", inner_bore / _MM,
              f"must be below pitch diameter - 2 x ball diameter ({(2 * r - 2 * dw) / _MM:g} mm) so the groove fits")
    for key, h in (("outer_ring_height_mm", h_out), ("inner_ring_height_mm", h_in)):
        if h <= dw:
            _fail(w + key, h / _MM, f"must exceed the ball diameter ({dw / _MM:g} mm) so the groove fits")
    return (RingSection(r + gap / 2.0, outer_dia / 2.0, h_out, faces["outer"]),
            RingSection(inner_bore / 2.0, r - gap / 2.0, h_in, faces["inner"]))


def bearing_from_dict(data: Mapping[str, Any], base_dir: str | os.PathLike = ".") -> Bearing:
    """Build and validate a :class:`Bearing` from the TOML layout (units in key names).

    Lengths are given in the unit their key names (``pitch_diameter_mm``,
    ``preload_um``, ``contact_angle_deg``, ``youngs_modulus_gpa``) and converted
    here, once, to SI.

    Parameters
    ----------
    data : mapping
        Tables ``[bearing]``, optional ``[material]``, ``[rings]``, ``[errors]``, ``[connection]``.
    base_dir : str or path-like, optional
        Folder against which file names of ``[errors]`` and ``[connection]`` are resolved
        (default: the current folder).

    Returns
    -------
    Bearing
        The validated definition, SI units.

    Raises
    ------
    BearingDefinitionError
        Naming the key, the value and the rule broken.

    Examples
    --------
    >>> from slewing_model import bearing_from_dict
    >>> b = bearing_from_dict({"bearing": {"pitch_diameter_mm": 1500, "ball_diameter_mm": 50,
    ...                                    "groove_radius_mm": 26.25, "contact_angle_deg": 45,
    ...                                    "ball_count": 80}})
    >>> b.pitch_diameter, b.ball_diameter
    (1.5, 0.05)
    """
    for name in data:
        if name not in BEARING_TABLES:
            _fail(name, data[name], f"unknown table [{name}] (known tables: "
                  f"{', '.join(f'[{t}]' for t in BEARING_TABLES)}; names are case-sensitive)")
    if "bearing" not in data or not isinstance(data["bearing"], Mapping):
        _fail("bearing", None, "missing table [bearing] (required)")
    b = _subtable(data, "bearing")
    w = "bearing."
    dm = _positive(b, "pitch_diameter_mm", w) * _MM
    dw = _positive(b, "ball_diameter_mm", w) * _MM

    if "groove_radius_mm" not in b:
        _fail(w + "groove_radius_mm", None, "missing key (required): one value, or four for contacts 1..4")
    rc_raw = b["groove_radius_mm"]
    rc_list = rc_raw if isinstance(rc_raw, list) else [rc_raw] * 4
    if len(rc_list) != 4:
        _fail(w + "groove_radius_mm", rc_raw, "must be one number or a list of four (contacts 1..4)")
    rc = np.array([_positive({"groove_radius_mm": v}, "groove_radius_mm", w) for v in rc_list]) * _MM
    for i, r in enumerate(rc):
        s = dw / (2.0 * r)
        if not 0.0 < s < 1.0:
            _fail(w + "groove_radius_mm", rc_raw,
                  f"osculation s = Dw/(2 Rc) = {s:.4f} for contact {i + 1} must lie in (0, 1): "
                  f"the groove radius must exceed half the ball diameter")

    alpha = _number(b, "contact_angle_deg", w)
    if not 0.0 < alpha < 90.0:
        _fail(w + "contact_angle_deg", alpha, "must lie in (0, 90) degrees")

    if "ball_count" not in b:
        _fail(w + "ball_count", None, "missing key (required)")
    n = b["ball_count"]
    if isinstance(n, bool) or not isinstance(n, int):
        _fail(w + "ball_count", n, "must be a whole number")
    if n < 3:
        _fail(w + "ball_count", n, "must be at least 3")
    if n * dw >= math.pi * dm:
        _fail(w + "ball_count", n, f"the balls do not fit the pitch circumference: "
              f"ball_count x ball diameter = {n * dw / _MM:g} mm must be below pi x pitch diameter = {math.pi * dm / _MM:g} mm")

    preload = _number(b, "preload_um", w, 0.0) * _UM
    try:
        _check_preload(preload, dw, w + "preload_um")
    except BearingDefinitionError:
        _fail(w + "preload_um", preload / _UM, f"must be smaller in magnitude than 10 % of the ball diameter ({0.1 * dw / _UM:g} um)")
    phi0 = _number(b, "first_ball_angle_deg", w, 0.0) * _DEG
    moving = b.get("moving_ring", "inner")
    if moving not in ("inner", "outer"):
        _fail(w + "moving_ring", moving, "must be 'inner' or 'outer'")

    m = _subtable(data, "material")
    youngs = _positive(m, "youngs_modulus_gpa", "material.", 200.0) * 1e9
    nu = _number(m, "poisson_ratio", "material.", 0.3)
    if not 0.0 < nu < 0.5:
        _fail("material.poisson_ratio", nu, "must lie in (0, 0.5)")

    outer, inner = _sections(_subtable(data, "rings"), dm, dw)

    errors = None
    if "errors" in data:
        errors = errors_from_table(_subtable(data, "errors"), base_dir=base_dir, ball_count=n)
    connection = None
    if "connection" in data:
        from .connection import connections_from_table     # imported for a connected bearing only

        connection = connections_from_table(data["connection"], {"outer": outer, "inner": inner},
                                            base_dir=base_dir) or None

    bearing = Bearing(
        name=str(b.get("name", "bearing")), pitch_diameter=dm, ball_diameter=dw, groove_radius=rc,
        contact_angle=alpha * _DEG, ball_count=n, preload=preload, youngs_modulus=youngs,
        poisson_ratio=nu, moving_ring=moving, first_ball_angle=phi0,
        outer_section=outer, inner_section=inner, errors=errors, connection=connection, source=dict(data),
    )
    validate(bearing)
    return bearing


def validate(bearing: Bearing) -> None:
    """Rules that involve several values: the groove must fit inside each ring."""
    for contact in CONTACTS:
        i = contact - 1
        ring = "outer" if contact in RING_CONTACTS["outer"] else "inner"
        section = bearing.outer_section if ring == "outer" else bearing.inner_section
        edge = bearing.groove_edge_angle(contact)
        if edge <= bearing.contact_angle:
            _fail(f"rings.{ring} section", section,
                  f"the groove of contact {contact} ends at {math.degrees(edge):.1f} deg, below the "
                  f"contact angle {math.degrees(bearing.contact_angle):.1f} deg: reduce the gap between the rings")
        o_z = bearing.groove_centres[i, 1]
        edge_z = abs(o_z) + bearing.groove_radius[i] * math.sin(edge)
        if edge_z >= section.height / 2.0:
            _fail(f"rings.{ring}_ring_height_mm", section.height / _MM,
                  f"the groove of contact {contact} reaches z = {edge_z / _MM:.2f} mm, beyond half the ring height")


def load_bearing(path: str | os.PathLike) -> Bearing:
    """Read and validate a bearing definition TOML file (see ``examples/bearings``).

    Parameters
    ----------
    path : str or path-like
        The TOML file. File names inside it (measured errors, connections) are
        resolved against its folder.

    Returns
    -------
    Bearing
        The validated definition, SI units.

    Raises
    ------
    BearingDefinitionError
        If the file is not valid TOML or breaks a rule; the message names the
        file, the key, the value and the rule.

    Examples
    --------
    >>> from slewing_model import load_bearing
    >>> b = load_bearing("examples/bearings/table1.toml")
    >>> round(b.pitch_diameter, 3), b.ball_count
    (1.5, 100)
    """
    try:  # Python >= 3.11; imported here so that the FMU's run time needs no TOML reader
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib

    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise BearingDefinitionError(f"{path}: not valid TOML: {exc}") from None
    try:
        return bearing_from_dict(data, base_dir=os.path.dirname(os.path.abspath(path)))
    except BearingDefinitionError as exc:  # name the file: a study reads several
        raise BearingDefinitionError(f"{path}: {exc}") from None
