"""Build the precomputed superelement of a bearing, with a cache.

:func:`build_superelement` runs, for each ring, the steps of the other modules:

    section (groove cut)  ->  mesh  ->  K0, K1, K2  ->  patch loads  ->
    c_n for n = 0..N  ->  minus half-space  ->  aliasing to B balls  ->
    projection + floor  ->  K_hat_j  ->  first block row

and returns a :class:`~slewing_model.rings.stiffness.Superelement`. A result is
cached on disk, keyed by the hash of all inputs (ring-relevant bearing fields,
options, algorithm and software versions): a second build is a file read.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import time
from dataclasses import asdict, dataclass

import numpy as np

from ...bearing.geometry import RING_CONTACTS, Bearing
from ..stiffness import RingStiffness, Superelement, bearing_hash, ring_fields
from . import condense as cd
from . import coupling as cp
from .harmonic import HarmonicRingModel
from .section import MESH_PRESETS, MeshSize, mesh_section, ring_profile
from .adapters import CONNECTED, connect
from .supports import BOUNDARY_CONDITIONS, NULL_SPACE, SUPPORT_REMOVES, Support

#: bump when the numbers a build produces change for the same inputs (invalidates caches)
ALGORITHM_VERSION = 3          # 3: the given-back long waves are projected after the give-back

#: expert options and their defaults (see :func:`build_superelement`)
DEFAULT_OPTIONS = {
    "harmonics": None,                 # N, highest FE harmonic; None: harmonic_factor * r / w
    "harmonic_factor": 12.0,
    "reference_pressure": cp.REFERENCE_PRESSURE,
    "patch_scale": 1.0,
    "compliance_floor": 0.05,
    "subtract_halfspace": True,
}


def software_version() -> str:
    try:
        from importlib.metadata import version

        return version("slewing_model")
    except Exception:  # pragma: no cover - not installed
        return "0+unknown"


def default_cache_dir() -> str:
    """``$SLEWING_CACHE_DIR``, else ``~/.cache/slewing_model``."""
    return os.environ.get("SLEWING_CACHE_DIR") or os.path.join(os.path.expanduser("~"), ".cache", "slewing_model")


def _mesh_size(mesh) -> tuple[str, MeshSize]:
    if isinstance(mesh, MeshSize):
        return "custom", mesh
    if isinstance(mesh, dict):
        return "custom", MeshSize(**mesh)
    if mesh not in MESH_PRESETS:
        raise ValueError(f"mesh = {mesh!r}: must be one of {', '.join(MESH_PRESETS)} or a MeshSize")
    return mesh, MESH_PRESETS[mesh]


def _bcs(bc) -> dict:
    if isinstance(bc, str):
        bc = {"outer": bc, "inner": bc}
    if set(bc) != {"outer", "inner"}:
        raise ValueError(f"bc = {bc!r}: a string or a dict with keys 'outer' and 'inner'")
    for ring, kind in bc.items():
        if kind not in BOUNDARY_CONDITIONS:
            raise ValueError(f"bc[{ring!r}] = {kind!r}: must be one of {', '.join(BOUNDARY_CONDITIONS)}")
    return {"outer": bc["outer"], "inner": bc["inner"]}


def auto_harmonics(bearing: Bearing, ring: str, factor: float) -> int:
    """Default highest harmonic: ``factor * r_max / w`` with ``w`` the smaller side of the
    section. Above a few ``r / w`` the ring answers a patch load like a half-space (Hertz's
    part), so the ring part ``c_n - c_n^HS`` has died out (docs/theory/superelement.md)."""
    s = bearing.outer_section if ring == "outer" else bearing.inner_section
    w = min(s.height, s.outer_radius - s.inner_radius)
    return int(math.ceil(factor * s.outer_radius / w))


def _floor(bearing: Bearing, ring: str, factor: float, reference_pressure: float) -> np.ndarray:
    """Compliance floor, (4, 4): ``factor`` times the half-space self-compliance of the two
    reference patches (Hertz ellipse at ``reference_pressure``: the ring side of the Hertz
    compliance), in master DOFs. It does not depend on ``patch_scale``."""
    sizes = [cp.patch_size(bearing, c, reference_pressure) for c in RING_CONTACTS[ring]]
    patches = cp.ring_patches(bearing, ring, sizes)
    lams = [np.linalg.inv(p.resultant_matrix()) for p in patches]
    return factor * cd.halfspace_self_block(patches, lams, bearing.youngs_modulus, bearing.poisson_ratio)


def cache_key(bearing: Bearing, options: dict) -> str:
    text = json.dumps({"bearing": ring_fields(bearing), "options": options,
                       "algorithm": ALGORITHM_VERSION, "software": software_version()},
                      sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def build_superelement(bearing: Bearing, mesh="coarse", bc="free", *, cache: bool = True, cache_dir=None,
                       progress: bool = False, **expert_options) -> Superelement:
    """Condensed stiffness of both rings of ``bearing`` (paper eqs 12-15).

    Parameters
    ----------
    bearing : Bearing
    mesh : str or MeshSize or dict
        ``"coarse"`` (tests, quick studies), ``"fine"`` (within 1 % of ``"finer"``, see
        docs/theory/superelement.md) or ``"finer"``; or explicit :class:`MeshSize` fields.
    bc : str or dict
        ``"free"``, ``"clamped"`` or ``"frictionless"`` for both rings, or
        ``{"outer": ..., "inner": ...}``. A ring the bearing connects (``bearing.connection``,
        the bearing file's ``[connection.<ring>]``) takes its support from that connection
        (``"connected"``) and ``bc`` applies to the other ring only.
    cache : bool
        Read and write the on-disk cache.
    cache_dir : path, optional
        Default :func:`default_cache_dir`.
    progress : bool
        Show a progress bar over the harmonic solves.
    **expert_options
        ``harmonics`` (int, highest FE harmonic N; default ``harmonic_factor * r / w``),
        ``harmonic_factor`` (12), ``reference_pressure`` (Pa, 2.5e9: the patch is the Hertz
        ellipse at this maximum pressure), ``patch_scale`` (1.0, multiplies both patch
        semi-axes), ``compliance_floor`` (0.05: fraction of the patch's half-space
        compliance added as a series compliance, see :mod:`.condense`),
        ``subtract_halfspace`` (True; False keeps the Hertz part in: for studies only).

    Returns
    -------
    Superelement
        ``metadata`` holds the inputs, their hash, the mesh and harmonic figures,
        the boundary conditions with the modes removed, and timings.
    """
    unknown = set(expert_options) - set(DEFAULT_OPTIONS)
    if unknown:
        raise TypeError(f"unknown option(s) {', '.join(sorted(unknown))}; expert options are "
                        f"{', '.join(DEFAULT_OPTIONS)}")
    opts = {**DEFAULT_OPTIONS, **expert_options}
    mesh_name, size = _mesh_size(mesh)
    bcs = _bcs(bc)
    for ring in bearing.connection or {}:      # a connected ring's support is its connection
        bcs[ring] = CONNECTED
    harmonics = {r: int(opts["harmonics"]) if opts["harmonics"] is not None
                 else auto_harmonics(bearing, r, opts["harmonic_factor"]) for r in ("outer", "inner")}
    key_options = {"mesh": asdict(size), "bc": bcs, "harmonics": harmonics,
                   **{k: v for k, v in opts.items() if k not in ("harmonics",)}}
    key = cache_key(bearing, key_options)
    path = os.path.join(cache_dir or default_cache_dir(), f"superelement-{key}.npz")
    if cache and os.path.exists(path):
        try:
            se = Superelement.load(path, bearing)
            se.metadata["cache"] = {"hit": True, "path": path}
            return se
        except ValueError:
            pass          # unreadable or stale file: rebuild and overwrite it

    t_start = time.perf_counter()
    bar = None
    if progress:
        from ...progress import progress_bar

        bar = progress_bar(sum(harmonics.values()) + 4, "superelement harmonics", "harmonic")
    rings, ring_meta = {}, {}
    try:
        for ring in ("outer", "inner"):
            rings[ring], ring_meta[ring] = _build_ring(bearing, ring, size, bcs[ring], harmonics[ring], opts,
                                                       bar.update if bar is not None else None)
    finally:
        if bar is not None:
            bar.close()
    meta = {
        "bearing_name": bearing.name,
        "bearing": ring_fields(bearing),
        "bearing_hash": bearing_hash(bearing),
        "input_hash": key,
        "software_version": software_version(),
        "algorithm_version": ALGORITHM_VERSION,
        "mesh": {"name": mesh_name, **asdict(size)},
        "boundary_conditions": bcs,
        "options": {k: v for k, v in opts.items()},
        "coupling": ("distributing: normal pressure over the Hertz ellipse at the reference pressure, "
                     "moment-free about the groove centre; flat half-space (Hertz) part subtracted per harmonic"),
        "units": "N/m; DOFs per ball [R_a, z_a, R_b, z_b], (a, b) = (1, 4) outer, (2, 3) inner",
        "rings": ring_meta,
        "build_seconds": time.perf_counter() - t_start,
        "cache": {"hit": False, "path": path if cache else None},
    }
    se = Superelement(rings["outer"], rings["inner"], meta)
    if cache:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        se.save(path)
    return se


@dataclass
class RingHarmonics:
    """Intermediate result of one ring: the per-harmonic FE compliances and what the
    condensation needs (for studies that condense the same solves with several settings)."""

    ring: str
    bc: str
    patches: tuple
    lams: list
    c_fe: np.ndarray          # (N + 1, 4, 4), m/N per unit of the theta integral
    c_hs: np.ndarray          # (N + 1, 4, 4), flat half-space part
    floor: np.ndarray         # (4, 4), m/N
    youngs_modulus: float
    poisson_ratio: float
    info: dict


def ring_harmonics(bearing: Bearing, ring: str, size: MeshSize, bc: str, n_max: int, opts: dict,
                   progress=None) -> RingHarmonics:
    """Mesh, assemble and solve harmonics 0..n_max of one ring."""
    t0 = time.perf_counter()
    e, nu = bearing.youngs_modulus, bearing.poisson_ratio
    profile = ring_profile(bearing, ring)
    ref = [cp.patch_size(bearing, c, opts["reference_pressure"]) for c in RING_CONTACTS[ring]]
    sizes = [(a * opts["patch_scale"], b * opts["patch_scale"]) for a, b in ref]
    sm = mesh_section(profile, [a for a, _ in sizes], size)
    model = HarmonicRingModel(sm.mesh, e, nu)
    patches = cp.ring_patches(bearing, ring, sizes)
    loads, lams = cp.master_loads(model, sm.patch_facets, patches)
    connection_info = None
    if bc == CONNECTED:                    # the bolted face joined to a tube, plate or matrix
        model, support, connection_info = connect(model, sm, bearing.connection[ring], size)
        loads = model.pad(loads)
    else:
        support = Support(bc, model, sm.bolted_facets)
    if progress is not None:
        progress(1)
    t1 = time.perf_counter()
    c_fe = cd.harmonic_compliances(model, loads, range(n_max + 1), support, progress)
    t2 = time.perf_counter()
    c_hs = cd.halfspace_blocks(patches, lams, range(n_max + 1), e, nu)
    floor = _floor(bearing, ring, opts["compliance_floor"], opts["reference_pressure"])
    info = {"mesh": {**sm.info, "dofs": int(getattr(model, "ring_ndofs", model.ndofs))},
            "patch_semi_axes_m": [list(s) for s in sizes],
            "seconds": {"setup": t1 - t0, "harmonics": t2 - t1}}
    if connection_info is not None:
        info["connection"] = connection_info
    return RingHarmonics(ring, bc, patches, lams, c_fe, c_hs, floor, e, nu, info)


def condense_ring(h: RingHarmonics, ball_count: int, n_max: int | None = None,
                  subtract_halfspace: bool = True) -> tuple[RingStiffness, dict]:
    """Condense harmonics 0..n_max (default all) of ``h`` to ``ball_count`` balls."""
    t0 = time.perf_counter()
    n = h.c_fe.shape[0] - 1 if n_max is None else n_max
    free = h.bc == "free"
    c_hs = h.c_hs[:n + 1] if subtract_halfspace else 0.0 * h.c_hs[:n + 1]
    back = (cd.halfspace_addback(h.patches, h.lams, ball_count, h.youngs_modulus, h.poisson_ratio)
            if subtract_halfspace else 0.0)
    k_hat, ring_report, report = cd.condensed_blocks(h.c_fe[:n + 1], c_hs, back, h.patches, ball_count, free,
                                                     h.floor)
    row = cd.first_row(k_hat)
    # harmonic truncation figure: the same with 3/4 of the harmonics
    n34 = max(2, (3 * n) // 4)
    k34, _, _ = cd.condensed_blocks(h.c_fe[:n34 + 1], c_hs[:n34 + 1], back, h.patches, ball_count, free, h.floor)
    diag, diag34 = np.diag(row[0]), np.diag(cd.first_row(k34)[0])
    trunc = float(np.max(np.abs(diag - diag34) / np.abs(diag)))
    B = ball_count
    stiff = RingStiffness(h.ring, B, 0.5 * (row + row[(-np.arange(B)) % B].transpose(0, 2, 1)),
                          NULL_SPACE.get(h.bc, ()), h.bc)
    meta = {
        "contacts": list(RING_CONTACTS[h.ring]),
        "boundary_condition": h.bc,
        "removed_modes": list(NULL_SPACE.get(h.bc, ())),
        "support_removes": SUPPORT_REMOVES.get(h.bc) or h.info["connection"]["support"],
        "mesh": h.info["mesh"],
        "harmonics": n,
        "patch_semi_axes_m": h.info["patch_semi_axes_m"],
        "compliance_floor_m_per_N": h.floor.tolist(),
        "projection": {"per_harmonic": ring_report, "ball_harmonics": report},
        "truncation_change": trunc,
        "diagonal_N_per_m": [float(x) for x in diag],
        "seconds": {**h.info["seconds"], "condensation": time.perf_counter() - t0},
    }
    if "connection" in h.info:
        meta["connection"] = h.info["connection"]
    return stiff, meta


def _build_ring(bearing, ring, size, bc, n_max, opts, progress):
    h = ring_harmonics(bearing, ring, size, bc, n_max, opts, progress)
    return condense_ring(h, bearing.ball_count, subtract_halfspace=opts["subtract_halfspace"])
