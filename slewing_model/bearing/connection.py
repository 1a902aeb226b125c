"""What a ring's bolted face is bolted to: the ``[connection.outer]`` / ``[connection.inner]`` tables
of a bearing file (docs/guide/connected-structures.md).

A ring whose table is given is joined, over its bolted face (``[rings] *_bolted_face``), to the
stiffness of the structure it is bolted to, and the superelement
(:mod:`slewing_model.rings.superelement`) condenses that structure in at build time. Three kinds:

* ``type = "tube"``: a blade root or a tower top, a body of revolution of rectangular (r, z)
  section: ``inner_diameter_mm``, ``outer_diameter_mm``, ``length_mm`` (along the bearing axis,
  away from the ring). Its far end (the cross-section ``length_mm`` from the bolted face) is
  clamped.
* ``type = "plate"``: a hub or bedplate flange, an annular plate under the bolted face:
  ``inner_diameter_mm``, ``outer_diameter_mm``, ``thickness_mm``; clamped along its
  ``clamped_edge = "inner"`` or ``"outer"`` cylindrical edge (where it meets the rest of the hub).
* ``type = "matrix"``: a stiffness condensed to nodes on the bolted face by any FE tool:
  ``format = "calculix"`` (``*SUBSTRUCTURE MATRIX OUTPUT``: the user-element layout of CalculiX
  2.20, or lines ``row node, row dof, column node, column dof, value``) or ``"matrix_market"``
  (``%%MatrixMarket matrix coordinate real symmetric|general``, DOF ``3 k + c`` of the k-th
  node of ``nodes_csv``); ``file``, ``nodes_csv`` (columns ``node,x_mm,y_mm,z_mm`` in the
  bearing's frame: z the axis, origin the bearing centre in the ball plane) and
  ``stiffness_unit = "N/m"`` or ``"N/mm"``. The far side of that structure is whatever the FE
  model held fixed.

Material of a tube or plate: either isotropic (``youngs_modulus_gpa``, ``poisson_ratio``) or
orthotropic in the cylindrical axes of the body (a composite blade root):
``axial_modulus_gpa``, ``hoop_modulus_gpa``, ``shear_modulus_gpa`` (axial-hoop, the laminate's
in-plane shear), ``poisson_ratio`` (axial-hoop: hoop contraction per axial strain), optional
``radial_modulus_gpa`` (through the wall; default the hoop modulus). The through-wall shear
moduli are taken equal to ``shear_modulus_gpa`` and the through-wall Poisson's ratios equal to
``poisson_ratio`` (stated assumptions: a thin wall's radial properties barely matter).

Loads: the rigid-body motion of the moving ring (the unknowns the loads work on) is the motion of
its connected structure's clamped end, which moves as a rigid body; the load reference point is
unchanged, the bearing centre in the ball plane (moments about it). The fixed ring's connected
structure is held at its clamped end. Numpy and the standard library only (run time: the FMU
reads the connection back from its ``bearing.json``).
"""
from __future__ import annotations

import hashlib
import math
import os
from dataclasses import asdict, dataclass
from typing import Any, Mapping

import numpy as np

from .conventions import BearingDefinitionError, check_known_keys, fail

CONNECTION_TYPES = ("tube", "plate", "matrix")
MATERIAL_KEYS = ("youngs_modulus_gpa", "poisson_ratio", "axial_modulus_gpa", "hoop_modulus_gpa",
                 "radial_modulus_gpa", "shear_modulus_gpa")
#: the keys each kind of ``[connection.<ring>]`` table knows
CONNECTION_KEYS = {
    "tube": ("type", "inner_diameter_mm", "outer_diameter_mm", "length_mm") + MATERIAL_KEYS,
    "plate": ("type", "inner_diameter_mm", "outer_diameter_mm", "thickness_mm", "clamped_edge") + MATERIAL_KEYS,
    "matrix": ("type", "format", "file", "nodes_csv", "stiffness_unit"),
}
MATRIX_FORMATS = ("calculix", "matrix_market")
STIFFNESS_UNITS = {"N/m": 1.0, "N/mm": 1e3}

_MM, _GPA = 1e-3, 1e9


@dataclass(frozen=True)
class Adapter:
    """A tube or plate bolted to a ring face, SI units.

    Attributes
    ----------
    ring : str
    kind : str
        ``"tube"`` (clamped at its far end) or ``"plate"`` (clamped along ``clamped_edge``).
    inner_radius, outer_radius : float, m
    length : float, m
        Axial extent from the bolted face: the tube's length or the plate's thickness.
    clamped_edge : str
        ``"far_end"`` (tube), ``"inner"`` or ``"outer"`` (plate).
    axial_modulus, hoop_modulus, radial_modulus, shear_modulus : float, Pa
    poisson_ratio : float
    """

    ring: str
    kind: str
    inner_radius: float
    outer_radius: float
    length: float
    clamped_edge: str
    axial_modulus: float
    hoop_modulus: float
    radial_modulus: float
    shear_modulus: float
    poisson_ratio: float

    def elasticity(self) -> np.ndarray:
        """6x6 stiffness D in the strain order of the harmonic model
        ``[eps_r, eps_t, eps_z, gam_rz, gam_rt, gam_tz]`` (engineering shear strains), Pa."""
        return elasticity(self.radial_modulus, self.hoop_modulus, self.axial_modulus, self.shear_modulus,
                          self.poisson_ratio)

    def to_dict(self) -> dict:
        return {"type": self.kind, **{k: v for k, v in asdict(self).items() if k != "kind"}}


@dataclass(frozen=True)
class ImportedStiffness:
    """A face stiffness from another FE tool (read at build time by
    :mod:`slewing_model.rings.superelement.imported`).

    Attributes
    ----------
    ring : str
    format : str
        ``"calculix"`` or ``"matrix_market"``.
    file, nodes_csv : str
        Absolute paths.
    stiffness_scale : float
        N/m per unit of the file (1 for N/m, 1000 for N/mm).
    sha256 : str
        Of the two files' contents (the superelement cache key holds it, not the paths).
    """

    ring: str
    format: str
    file: str
    nodes_csv: str
    stiffness_scale: float
    sha256: str

    def to_dict(self) -> dict:
        return {"type": "matrix", **asdict(self)}


def elasticity(e_r: float, e_t: float, e_z: float, g: float, nu: float) -> np.ndarray:
    """Orthotropic D (see :meth:`Adapter.elasticity`): compliance
    ``S = [[1/Er, -nu/Et, -nu/Ez], [-nu/Et, 1/Et, -nu/Ez], [-nu/Ez, -nu/Ez, 1/Ez]]`` (symmetric;
    ``nu`` is the Poisson's ratio of an axial stress, and of a hoop stress on the radial strain),
    shear moduli all ``g``. Isotropic when ``Er = Et = Ez = E`` and ``g = E / (2 (1 + nu))``."""
    s = np.array([[1 / e_r, -nu / e_t, -nu / e_z],
                  [-nu / e_t, 1 / e_t, -nu / e_z],
                  [-nu / e_z, -nu / e_z, 1 / e_z]])
    d = np.zeros((6, 6))
    d[:3, :3] = np.linalg.inv(s)
    d[3, 3] = d[4, 4] = d[5, 5] = g
    return d


def _num(table, key, where, positive=True) -> float:
    if key not in table:
        fail(where + key, None, "missing key (required)")
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        fail(where + key, v, "must be a finite number")
    if positive and v <= 0:
        fail(where + key, v, "must be > 0")
    return float(v)


def _choice(table, key, where, choices) -> str:
    if key not in table:
        fail(where + key, None, f"missing key (required): one of {', '.join(repr(c) for c in choices)}")
    v = table[key]
    if v not in choices:
        fail(where + key, v, f"must be one of {', '.join(repr(c) for c in choices)}")
    return v


def _material(t, where) -> dict:
    iso = "youngs_modulus_gpa" in t
    ortho = [k for k in ("axial_modulus_gpa", "hoop_modulus_gpa", "radial_modulus_gpa", "shear_modulus_gpa") if k in t]
    if iso and ortho:
        fail(where + ortho[0], t[ortho[0]], "give either youngs_modulus_gpa (isotropic) or axial_modulus_gpa, "
             "hoop_modulus_gpa, shear_modulus_gpa (orthotropic), not both")
    nu = _num(t, "poisson_ratio", where, positive=False)
    if iso:
        e = _num(t, "youngs_modulus_gpa", where) * _GPA
        if not 0.0 <= nu < 0.5:
            fail(where + "poisson_ratio", nu, "must lie in [0, 0.5) for an isotropic material")
        return {"axial_modulus": e, "hoop_modulus": e, "radial_modulus": e,
                "shear_modulus": e / (2 * (1 + nu)), "poisson_ratio": nu}
    if not ortho:
        fail(where + "youngs_modulus_gpa", None, "missing material: give youngs_modulus_gpa and poisson_ratio "
             "(isotropic) or axial_modulus_gpa, hoop_modulus_gpa, shear_modulus_gpa, poisson_ratio (orthotropic)")
    ez = _num(t, "axial_modulus_gpa", where) * _GPA
    et = _num(t, "hoop_modulus_gpa", where) * _GPA
    g = _num(t, "shear_modulus_gpa", where) * _GPA
    er = _num(t, "radial_modulus_gpa", where) * _GPA if "radial_modulus_gpa" in t else et
    if nu < 0:
        fail(where + "poisson_ratio", nu, "must be >= 0")
    if np.linalg.eigvalsh(elasticity(er, et, ez, g, nu)[:3, :3]).min() <= 0:
        fail(where + "poisson_ratio", nu, f"with these moduli (axial {ez / _GPA:g}, hoop {et / _GPA:g}, radial "
             f"{er / _GPA:g} GPa) the material is not stable (its stiffness matrix is not positive definite): "
             f"lower the Poisson's ratio")
    return {"axial_modulus": ez, "hoop_modulus": et, "radial_modulus": er, "shear_modulus": g,
            "poisson_ratio": nu}


def _file_hash(paths) -> str:
    h = hashlib.sha256()
    for p in paths:
        with open(p, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    return h.hexdigest()[:24]


def connection_from_table(table: Mapping[str, Any], ring: str, section, base_dir=".") -> Adapter | ImportedStiffness:
    """Read and check one ``[connection.<ring>]`` table; ``section`` is the ring's
    :class:`~slewing_model.bearing.geometry.RingSection` (the adapter must overlap its bolted face)."""
    name = f"connection.{ring}"
    where = name + "."
    if not isinstance(table, Mapping):
        fail(name, table, f"must be a table [{name}]")
    kind = _choice(table, "type", where, CONNECTION_TYPES)
    check_known_keys(table, name, CONNECTION_KEYS[kind])
    if kind == "matrix":
        fmt = _choice(table, "format", where, MATRIX_FORMATS)
        unit = _choice(table, "stiffness_unit", where, tuple(STIFFNESS_UNITS))
        paths = []
        for key in ("file", "nodes_csv"):
            if key not in table:
                fail(where + key, None, "missing key (required): a file name (relative to the bearing file)")
            p = table[key]
            if not isinstance(p, str):
                fail(where + key, p, "must be a file name")
            full = os.path.join(os.fspath(base_dir), p)
            if not os.path.isfile(full):
                fail(where + key, p, f"no such file ({full})")
            paths.append(os.path.abspath(full))
        return ImportedStiffness(ring, fmt, paths[0], paths[1], STIFFNESS_UNITS[unit], _file_hash(paths))
    ri = _num(table, "inner_diameter_mm", where) * _MM / 2
    ro = _num(table, "outer_diameter_mm", where) * _MM / 2
    if ro <= ri:
        fail(where + "outer_diameter_mm", 2 * ro / _MM, f"must exceed inner_diameter_mm ({2 * ri / _MM:g} mm)")
    lo, hi = max(ri, section.inner_radius), min(ro, section.outer_radius)
    if hi - lo < 0.05 * (section.outer_radius - section.inner_radius):
        fail(where + "inner_diameter_mm", 2 * ri / _MM,
             f"the {kind} (diameters {2 * ri / _MM:g}..{2 * ro / _MM:g} mm) must overlap the {ring} ring's bolted "
             f"face (diameters {2 * section.inner_radius / _MM:g}..{2 * section.outer_radius / _MM:g} mm) by at "
             f"least 5 % of its width: that overlap is the bolted annulus")
    if kind == "tube":
        length = _num(table, "length_mm", where) * _MM
        edge = "far_end"
    else:
        length = _num(table, "thickness_mm", where) * _MM
        edge = _choice(table, "clamped_edge", where, ("inner", "outer"))
    return Adapter(ring, kind, ri, ro, length, edge, **_material(table, where))


def connections_from_table(data: Any, sections: Mapping[str, Any], base_dir=".") -> dict:
    """The ``[connection]`` table: sub-tables ``outer`` and/or ``inner``; returns {ring: connection}."""
    if not isinstance(data, Mapping):
        fail("connection", data, "must be a table with sub-tables [connection.outer] and/or [connection.inner]")
    check_known_keys(data, "connection", ("outer", "inner"))
    return {ring: connection_from_table(data[ring], ring, sections[ring], base_dir)
            for ring in ("outer", "inner") if ring in data}


def connection_from_dict(d: Mapping[str, Any]) -> Adapter | ImportedStiffness:
    """Inverse of ``to_dict`` (SI, no unit conversion, no file read)."""
    d = dict(d)
    kind = d.pop("type")
    if kind == "matrix":
        return ImportedStiffness(**d)
    if kind not in ("tube", "plate"):
        raise BearingDefinitionError(f"connection type = {kind!r}: must be one of {', '.join(CONNECTION_TYPES)}")
    return Adapter(kind=kind, **d)


def connection_key(d: Mapping[str, Any]) -> dict:
    """The part of a connection's ``to_dict`` the ring stiffness depends on (not the files' paths,
    their contents' hash)."""
    return {k: v for k, v in d.items() if k not in ("file", "nodes_csv")}
