"""Ring stiffness condensed to the groove centres: the precomputed superelement (run time).

Paper section 2.2, eqs 12-15. Each ring's stiffness is condensed to the
radial and axial displacements of its two groove centres at every ball:

* outer ring: ``D = [R1_0, z1_0, R4_0, z4_0, R1_1, ..., z4_{B-1}]`` (paper eq 14),
* inner ring: ``D = [R2_0, z2_0, R3_0, z3_0, ...]``,

R radial (outward positive), z axial (+z), m; ball ``b`` at
``phi_b = first_ball_angle + 2 pi b / B``. The strain energy of the ring is
``U = 1/2 D^T K D`` (paper eq 15), K in N/m.

The ring is axisymmetric and the balls equally spaced, so K is **block
circulant**: ``K[b, (b + k) % B] = C_k`` (4x4 blocks), stored as its first
block row ``C_0 .. C_{B-1}`` with ``C_{B-k} = C_k^T``. It is built at build
time by :mod:`slewing_model.rings.superelement` (scikit-fem) and stored in one
``.npz`` file; this module reads it with numpy only, so that it runs inside
the FMU.

Examples
--------
>>> import numpy as np
>>> c = np.zeros((4, 4, 4)); c[0] = 2 * np.eye(4); c[1] = c[3] = -0.5 * np.eye(4)
>>> k = RingStiffness("outer", 4, c, (), "clamped")
>>> k.dense().shape
(16, 16)
>>> np.allclose(k.harmonic_blocks()[0], np.eye(4))
True
"""
from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field

import numpy as np

#: version of the .npz layout; bump when it changes
FORMAT_VERSION = 1

#: the fields of ``Bearing.to_dict()`` the ring stiffness depends on (not preload, errors, moving_ring, name)
RING_FIELDS = ("pitch_diameter", "ball_diameter", "groove_radius", "contact_angle", "ball_count",
               "youngs_modulus", "poisson_ratio", "first_ball_angle", "outer_section", "inner_section")

#: master DOF labels of one ball, per ring (paper eq 14)
DOF_LABELS = {"outer": ("R1", "z1", "R4", "z4"), "inner": ("R2", "z2", "R3", "z3")}

#: the one default superelement mesh of every command (``slewing superelement``, ``solve``, ``plot``,
#: a study's ``[simulation] mesh``), and what each mesh is worth (docs/theory/superelement.md, Accuracy)
DEFAULT_MESH = "coarse"
MESH_HELP = ("superelement cross-section mesh: coarse (quick: compliances within 1.2 %%, stiffness entries "
             "within 15 %% of finer), fine (within 0.5 %% of finer, about 4x the build time), finer")


class SuperelementMismatchError(ValueError):
    """A stored superelement does not belong to the bearing it is used with."""


def _canonical(value):
    """Floats rounded to 12 significant digits, so that unit conversions do not change a hash."""
    if isinstance(value, float):
        return float(f"{value:.12g}")
    if isinstance(value, dict):
        return {k: _canonical(v) for k, v in sorted(value.items())}
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_canonical(float(v)) for v in value.ravel()]
    if isinstance(value, (np.floating,)):
        return _canonical(float(value))
    if isinstance(value, (np.integer,)):
        return int(value)
    return value


def ring_fields(bearing) -> dict:
    """The ring-relevant part of ``bearing.to_dict()`` (see :data:`RING_FIELDS`), canonical form."""
    d = bearing.to_dict() if hasattr(bearing, "to_dict") else dict(bearing)
    fields = {k: d[k] for k in RING_FIELDS}
    if d.get("connection"):     # what the rings are bolted to (absent: the hash is unchanged)
        from ..bearing.connection import connection_key

        fields["connection"] = {r: connection_key(c) for r, c in d["connection"].items()}
    return _canonical(fields)


def bearing_hash(bearing) -> str:
    """SHA-256 (hex, 16 characters) of the ring-relevant fields of a bearing.

    Geometry, ring sections, material, ball count and first ball angle, and the connected
    structures when there are any (``[connection]``); not the preload, the manufacturing errors, the moving ring or the name."""
    text = json.dumps(ring_fields(bearing), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class RingStiffness:
    """Block-circulant stiffness of one ring, condensed to its groove centres.

    Attributes
    ----------
    ring : str
        ``"outer"`` (DOFs R1, z1, R4, z4 per ball) or ``"inner"`` (R2, z2, R3, z3).
    ball_count : int
        B.
    first_row : ndarray (B, 4, 4), N/m
        ``C_k = K[ball 0, ball k]``; ``K[b, (b + k) % B] = C_k``; ``C_{B-k} = C_k^T``.
    removed_modes : tuple of str
        Null space of K: ``("X", "Y", "Z", "rx", "ry")`` for a free ring, ``()`` for a
        supported one.
    boundary_condition : str
        ``"free"``, ``"clamped"`` or ``"frictionless"``.
    """

    ring: str
    ball_count: int
    first_row: np.ndarray
    removed_modes: tuple = ()
    boundary_condition: str = "free"

    def __post_init__(self):
        c = np.asarray(self.first_row, dtype=float)
        if self.ring not in DOF_LABELS:
            raise ValueError(f"ring = {self.ring!r}: must be 'outer' or 'inner'")
        if c.shape != (self.ball_count, 4, 4):
            raise ValueError(f"first_row has shape {c.shape}, expected ({self.ball_count}, 4, 4)")
        if not np.all(np.isfinite(c)):
            raise ValueError("first_row holds NaN or infinite values")
        mirror = c[(-np.arange(self.ball_count)) % self.ball_count].transpose(0, 2, 1)
        if not np.allclose(c, mirror, rtol=1e-9, atol=1e-12 * np.abs(c).max()):
            raise ValueError("first_row is not the first row of a symmetric matrix (C_{B-k} != C_k^T)")
        object.__setattr__(self, "first_row", c)
        object.__setattr__(self, "removed_modes", tuple(self.removed_modes))

    @property
    def dof_labels(self) -> tuple:
        """Labels of the four DOFs of a ball, e.g. ``("R1", "z1", "R4", "z4")``."""
        return DOF_LABELS[self.ring]

    def dense(self) -> np.ndarray:
        """K, shape (4B, 4B), symmetric, N/m."""
        B = self.ball_count
        b = np.arange(B)
        k = (b[None, :] - b[:, None]) % B            # block (b, b') holds C_{b' - b}
        return self.first_row[k].transpose(0, 2, 1, 3).reshape(4 * B, 4 * B)

    def harmonic_blocks(self) -> np.ndarray:
        """Discrete Fourier blocks, (B, 4, 4) complex Hermitian.

        Block ``j = sum_k C_k exp(+2 pi i j k / B)``: the stiffness of the displacement
        pattern ``D_b = d exp(+2 pi i j b / B)``, i.e. ``K D = (block_j d) exp(2 pi i j b / B)``.
        For this axisymmetric ring the blocks are real symmetric and block ``B - j`` equals
        block ``j``."""
        return self.ball_count * np.fft.ifft(self.first_row, axis=0)

    def apply(self, displacements) -> np.ndarray:
        """``K @ D`` in O(B log B) with the FFT; ``D`` of shape (4B,) or (B, 4); same shape out."""
        d = np.asarray(displacements, dtype=float)
        shape = d.shape
        d = d.reshape(self.ball_count, 4)
        # D_b = 1/B sum_j D~_j exp(+2 pi i j b / B), D~ = fft(D): each pattern j is scaled by block j
        dh = np.fft.fft(d, axis=0)
        out = np.fft.ifft(np.einsum("jab,jb->ja", self.harmonic_blocks(), dh), axis=0).real
        return out.reshape(shape)

    def energy(self, displacements) -> float:
        """Strain energy ``1/2 D^T K D``, J (paper eq 15)."""
        d = np.asarray(displacements, dtype=float).ravel()
        return 0.5 * float(d @ self.apply(d))

    def scaled(self, factor: float) -> "RingStiffness":
        return RingStiffness(self.ring, self.ball_count, self.first_row * float(factor),
                             self.removed_modes, self.boundary_condition)


@dataclass(frozen=True)
class Superelement:
    """The condensed stiffness of both rings of one bearing, with the metadata to trust it.

    Attributes
    ----------
    outer, inner : RingStiffness
    metadata : dict
        JSON-serialisable: the ring-relevant bearing fields and their hash, the build
        options (mesh, harmonics, boundary conditions, coupling), convergence figures,
        software version.
    """

    outer: RingStiffness
    inner: RingStiffness
    metadata: dict = field(default_factory=dict)

    def ring(self, name: str) -> RingStiffness:
        return {"outer": self.outer, "inner": self.inner}[name]

    def save(self, path) -> None:
        """Write one ``.npz``: the two first rows and the metadata as a JSON string."""
        path = os.fspath(path)
        tmp = f"{path}.{os.getpid()}.tmp.npz"   # a file of this process: two saving the same path do not collide
        np.savez(tmp, outer_first_row=self.outer.first_row, inner_first_row=self.inner.first_row,
                 metadata=np.array(self._stored_metadata()))
        os.replace(tmp, path)

    def save_folder(self, folder) -> None:
        """Write the same content as :meth:`save` into a folder: ``metadata.json`` and one ``.npy`` per
        ring's first row (``outer_first_row.npy``, ``inner_first_row.npy``). An FMU carries its
        superelement so: reading it needs no ``zipfile``, which an instance would import for an ``.npz``."""
        folder = os.fspath(folder)
        os.makedirs(folder, exist_ok=True)
        for ring in (self.outer, self.inner):
            np.save(os.path.join(folder, f"{ring.ring}_first_row.npy"), ring.first_row, allow_pickle=False)
        with open(os.path.join(folder, "metadata.json"), "w") as fh:
            fh.write(self._stored_metadata())

    def _stored_metadata(self) -> str:
        """The metadata as stored, a JSON text: with the format version and each ring's size and support."""
        meta = dict(self.metadata)
        meta["format_version"] = FORMAT_VERSION
        meta["ring_stiffness"] = {r.ring: {"ball_count": r.ball_count, "removed_modes": list(r.removed_modes),
                                  "boundary_condition": r.boundary_condition}
                         for r in (self.outer, self.inner)}
        return json.dumps(meta, sort_keys=True, default=_json_default)

    @classmethod
    def load(cls, path, bearing=None) -> "Superelement":
        """Read a file written by :meth:`save`, or a folder written by :meth:`save_folder`.

        Parameters
        ----------
        path : path
        bearing : Bearing, optional
            If given, the file must have been built for it: the ring-relevant fields
            (:func:`bearing_hash`) must match.

        Raises
        ------
        SuperelementMismatchError
            Naming the differing field(s), their stored and actual values.
        ValueError
            If the file is not a superelement of a known format.
        """
        path = os.fspath(path)
        try:
            if os.path.isdir(path):
                with open(os.path.join(path, "metadata.json")) as fh:
                    meta = json.load(fh)
                rows = {r: np.load(os.path.join(path, f"{r}_first_row.npy"), allow_pickle=False)
                        for r in ("outer", "inner")}
            else:
                with np.load(path, allow_pickle=False) as f:
                    meta = json.loads(str(f["metadata"]))
                    rows = {r: np.array(f[f"{r}_first_row"]) for r in ("outer", "inner")}
        except (KeyError, ValueError, OSError) as exc:
            raise ValueError(f"{path}: not a superelement file ({exc})") from None
        if meta.get("format_version") != FORMAT_VERSION:
            raise ValueError(f"{path}: superelement format version {meta.get('format_version')!r}, "
                             f"this software reads version {FORMAT_VERSION}: rebuild it")
        if bearing is not None:
            check_bearing(meta, bearing, path)
        info = meta["ring_stiffness"]
        rings = {r: RingStiffness(r, int(info[r]["ball_count"]), rows[r], tuple(info[r]["removed_modes"]),
                                  info[r]["boundary_condition"]) for r in ("outer", "inner")}
        return cls(rings["outer"], rings["inner"], meta)

    def scaled(self, factor: float) -> "Superelement":
        """Both rings' stiffness multiplied by ``factor`` (``1e6``: practically rigid rings)."""
        meta = dict(self.metadata)
        meta["scale"] = float(meta.get("scale", 1.0)) * float(factor)
        return Superelement(self.outer.scaled(factor), self.inner.scaled(factor), meta)

    def check(self, bearing) -> None:
        """Raise :class:`SuperelementMismatchError` unless built for ``bearing``."""
        check_bearing(self.metadata, bearing, "superelement")


def _json_default(value):
    """numpy scalars and arrays in the metadata, as plain JSON."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"metadata value of type {type(value).__name__} is not JSON-serialisable")


def _differences(stored, actual, prefix=""):
    out = []
    for key in sorted(set(stored) | set(actual)):
        a, b = stored.get(key), actual.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            out += _differences(a, b, f"{prefix}{key}.")
        elif a != b:
            out.append((f"{prefix}{key}", a, b))
    return out


def check_bearing(metadata: dict, bearing, where: str = "superelement") -> None:
    """Compare the bearing fields stored in ``metadata`` with ``bearing``; raise on mismatch."""
    actual = ring_fields(bearing)
    stored = metadata.get("bearing")
    if stored is None:
        raise SuperelementMismatchError(f"{where}: holds no bearing fields, cannot check it belongs to this bearing")
    if metadata.get("bearing_hash") == bearing_hash(bearing) and stored == actual:
        return
    diffs = _differences(stored, actual)
    if not diffs:   # same fields, different hash recipe: trust the fields
        return
    text = "; ".join(f"{k}: file {a!r}, bearing {b!r}" for k, a, b in diffs)
    raise SuperelementMismatchError(
        f"{where} was built for another bearing ({metadata.get('bearing_name', '?')}): {text}. "
        f"Rebuild it with `slewing superelement BEARING.toml -o FILE`.")
