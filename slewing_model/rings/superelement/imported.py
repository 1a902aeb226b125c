"""A face stiffness imported from another FE tool, projected onto the harmonic model.

The file holds the stiffness of the structure a ring is bolted to, condensed to nodes on the
ring's bolted face, three translations per node in the global Cartesian axes (z the bearing
axis, origin the bearing centre in the ball plane):

* ``format = "calculix"``: CalculiX's ``*SUBSTRUCTURE GENERATE`` with
  ``*SUBSTRUCTURE MATRIX OUTPUT, FILE NAME=...`` writes ``name.mtx``: in CalculiX 2.20 an Abaqus
  user element (:func:`_read_calculix_user_element`); with ``OUTPUT FILE=MATRIX`` (later
  manuals) one entry per line ``row node, row dof, column node, column dof, value`` (dof 1..3 =
  x, y, z), one triangle or both. The nodes' coordinates come from ``nodes_csv``. (CalculiX
  2.20 writes the retained block without condensing the interior: docs/guide/connected-structures.md.)
* ``format = "matrix_market"``: ``%%MatrixMarket matrix coordinate real symmetric`` (or
  ``general``); DOF ``3 k + c`` (0-based) is component c (x, y, z) of the k-th row of ``nodes_csv``.

``nodes_csv``: a header ``node,x_mm,y_mm,z_mm`` (or ``x_m, y_m, z_m``) and one row per node.

**Projection.** In harmonic n the ring face moves as ``u_r = U(r) cos n theta``,
``u_theta = V(r) sin n theta``, ``u_z = W(r) cos n theta`` with U, V, W the face's quadratic
field (:class:`.adapters.RingFace`). At node k, ``u_k = P_n q`` (P_n: that field at the node's
radius, times the harmonic factors, rotated to x, y). The file's energy ``1/2 u^T K u`` of
this motion, per unit of the ring model's theta integral (``c_n = pi``, ``2 pi`` at n = 0), is the
face stiffness

    F(n) = (P_n^T K P_n + Pt_n^T K Pt_n) / (2 c_n)     (n >= 1),     F(0) = P_0^T K P_0 / c_0

``Pt_n``: the antisymmetric family (the same turned by a quarter wave). For an axisymmetric
structure both families give the same; for a structure that is not (a real hub) this is the
axisymmetric equivalent the superelement can hold: each harmonic keeps its own energy averaged
over the two families, the couplings between harmonics are dropped.

A node set resolves harmonics up to ``pi / (largest angular gap) - 1``; the ring's harmonics must
stay below that (an error says so otherwise).

Build time only (scipy).
"""
from __future__ import annotations

import csv
import math
import time

import numpy as np

from ...bearing.conventions import BearingDefinitionError


class ImportedMatrixError(BearingDefinitionError):
    """An imported stiffness or its nodes break a rule; the message names the file, the value and the rule."""


# ---- readers ------------------------------------------------------------------------------------

def read_nodes(path: str) -> tuple[np.ndarray, np.ndarray]:
    """(node ids (k,), coordinates (k, 3) in m) of a ``node,x_mm,y_mm,z_mm`` CSV."""
    with open(path, newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise ImportedMatrixError(f"{path}: no rows")
    header = [h.strip() for h in rows[0]]
    for unit, scale in (("mm", 1e-3), ("m", 1.0)):
        want = ["node", f"x_{unit}", f"y_{unit}", f"z_{unit}"]
        if header == want:
            break
    else:
        raise ImportedMatrixError(f"{path}: header {','.join(header)!r}: must be 'node,x_mm,y_mm,z_mm' or "
                                  f"'node,x_m,y_m,z_m'")
    ids, xyz = [], []
    for line, r in enumerate(rows[1:], start=2):
        try:
            ids.append(int(r[0]))
            xyz.append([float(v) for v in r[1:4]])
        except (ValueError, IndexError):
            raise ImportedMatrixError(f"{path}, line {line}: {','.join(r)!r}: must be a node number and three "
                                      f"coordinates") from None
    ids, xyz = np.array(ids), np.array(xyz) * scale
    if len(set(ids.tolist())) != len(ids):
        raise ImportedMatrixError(f"{path}: node numbers repeat")
    if not np.all(np.isfinite(xyz)):
        raise ImportedMatrixError(f"{path}: a coordinate is not finite")
    return ids, xyz


def read_calculix(path: str, ids: np.ndarray) -> np.ndarray:
    """Dense K (3k, 3k) of a CalculiX substructure ``.mtx`` in the order of ``ids``: either layout
    (the user-element one CalculiX 2.20 writes, or the line-per-entry ``OUTPUT FILE=MATRIX`` one)."""
    with open(path) as fh:
        text = fh.read()
    if "*USER ELEMENT" in text.upper():
        return _read_calculix_user_element(text, path, ids)
    return _read_calculix_entries(text, path, ids)


def _read_calculix_user_element(text: str, path: str, ids: np.ndarray) -> np.ndarray:
    """The layout of ``*SUBSTRUCTURE MATRIX OUTPUT`` in CalculiX 2.20 (Abaqus's user element):

    * ``*USER ELEMENT, NODES=m, LINEAR``; comment lines ``** ELEMENT NODES`` then ``**`` lines with
      the global node number of each of the m element "nodes" (one per retained DOF);
    * data lines: the first one the DOF of element node 1, each next one ``position, dof`` where
      the DOF changes (positions not listed keep the previous DOF);
    * ``*MATRIX, TYPE=STIFFNESS``: the lower triangle row by row (row i holds i entries),
      comma-separated, any number per line."""
    where = {int(n): k for k, n in enumerate(ids)}
    lines = text.splitlines()
    try:
        head = next(i for i, l in enumerate(lines) if l.strip().upper().startswith("*USER ELEMENT"))
        start = next(i for i, l in enumerate(lines) if l.strip().upper().startswith("** ELEMENT NODES"))
        mat = next(i for i, l in enumerate(lines) if l.strip().upper().startswith("*MATRIX"))
    except StopIteration:
        raise ImportedMatrixError(f"{path}: a CalculiX user-element file needs '*USER ELEMENT', '** ELEMENT NODES' "
                                  f"and '*MATRIX, TYPE=STIFFNESS'") from None
    if "STIFFNESS" not in lines[mat].upper():
        raise ImportedMatrixError(f"{path}: {lines[mat].strip()!r}: the matrix must be TYPE=STIFFNESS")
    nodes, i = [], start + 1
    while i < len(lines) and lines[i].strip().startswith("**"):
        nodes += [int(x) for x in lines[i].strip()[2:].replace(",", " ").split()]
        i += 1
    m = len(nodes)
    declared = [x for x in lines[head].upper().replace(" ", "").split(",") if x.startswith("NODES=")]
    if declared and int(declared[0][6:]) != m:
        raise ImportedMatrixError(f"{path}: *USER ELEMENT declares {declared[0][6:]} nodes, the ELEMENT NODES list "
                                  f"holds {m}")
    dof_at, current = {}, None
    for line in lines[i:mat]:
        parts = [int(x) for x in line.replace(",", " ").split() if x]
        if not parts or line.strip().startswith("*"):
            continue
        if current is None:
            dof_at[1] = current = parts[0]
        else:
            dof_at[parts[0]] = parts[1]
    dofs, d = [], None
    for k in range(1, m + 1):
        d = dof_at.get(k, d)
        dofs.append(d)
    try:
        values = np.array(" ".join(l for l in lines[mat + 1:] if l.strip() and not l.strip().startswith("*"))
                          .replace(",", " ").split(), dtype=float)
    except ValueError as exc:
        raise ImportedMatrixError(f"{path}: a matrix entry is not a number ({exc})") from None
    if len(values) != m * (m + 1) // 2:
        raise ImportedMatrixError(f"{path}: {len(values)} matrix entries, a lower triangle of {m} DOFs has "
                                  f"{m * (m + 1) // 2}")
    index = []
    for n, d in zip(nodes, dofs):
        if n not in where:
            raise ImportedMatrixError(f"{path}: node {n} is not in the nodes file")
        if d not in (1, 2, 3):
            raise ImportedMatrixError(f"{path}: node {n} dof {d}: must be 1, 2 or 3 (translations)")
        index.append(3 * where[n] + d - 1)
    r, c = np.tril_indices(m)
    index = np.array(index)
    return _assemble(index[r], index[c], values, 3 * len(ids), path, one_triangle_allowed=True)


def _read_calculix_entries(text: str, path: str, ids: np.ndarray) -> np.ndarray:
    """Lines ``row node, row dof, column node, column dof, value`` (``OUTPUT FILE=MATRIX``, the format
    ``*MATRIX ASSEMBLE`` reads)."""
    where = {int(n): k for k, n in enumerate(ids)}
    try:        # the quick way; a malformed file is read again line by line for its message
        rows = [line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("*")]
        table = np.array(" ".join(rows).replace(",", " ").split(), dtype=float).reshape(-1, 5)
        nodes, dofs = table[:, [0, 2]].astype(int), table[:, [1, 3]].astype(int)
        if (np.all(np.isin(nodes, ids)) and np.all((dofs >= 1) & (dofs <= 3))
                and np.all(table[:, :4] == np.round(table[:, :4]))):
            pos = np.zeros(max(int(nodes.max()), int(np.max(ids))) + 1, dtype=int)
            pos[ids] = np.arange(len(ids))
            i = 3 * pos[nodes[:, 0]] + dofs[:, 0] - 1
            j = 3 * pos[nodes[:, 1]] + dofs[:, 1] - 1
            return _assemble(i, j, table[:, 4], 3 * len(ids), path, one_triangle_allowed=True)
    except ValueError:
        pass
    data = []
    for line_no, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("*"):
            continue
        parts = [p for p in s.replace(",", " ").split() if p]
        try:
            n1, d1, n2, d2, v = int(parts[0]), int(parts[1]), int(parts[2]), int(parts[3]), float(parts[4])
        except (ValueError, IndexError):
            raise ImportedMatrixError(f"{path}, line {line_no}: {s!r}: must be 'row node, row dof, column node, "
                                      f"column dof, value'") from None
        for n, d in ((n1, d1), (n2, d2)):
            if n not in where:
                raise ImportedMatrixError(f"{path}, line {line_no}: node {n} is not in the nodes file")
            if d not in (1, 2, 3):
                raise ImportedMatrixError(f"{path}, line {line_no}: dof {d}: must be 1, 2 or 3 (translations)")
        data.append((3 * where[n1] + d1 - 1, 3 * where[n2] + d2 - 1, v))
    if not data:
        raise ImportedMatrixError(f"{path}: no matrix entries")
    i, j, v = (np.array(x) for x in zip(*data))
    return _assemble(i, j, v, 3 * len(ids), path, one_triangle_allowed=True)


def read_matrix_market(path: str, n_dofs: int) -> np.ndarray:
    """Dense K of a Matrix Market file (coordinate or array, real, symmetric or general)."""
    from scipy.io import mminfo, mmread

    try:
        rows, cols, _, fmt, field, symmetry = mminfo(path)
        m = mmread(path)
    except Exception as exc:  # scipy raises ValueError and others for a malformed file
        raise ImportedMatrixError(f"{path}: not a Matrix Market file ({exc})") from None
    if field not in ("real", "integer", "double"):
        raise ImportedMatrixError(f"{path}: field {field!r}: must be real")
    if (rows, cols) != (n_dofs, n_dofs):
        raise ImportedMatrixError(f"{path}: a {rows} x {cols} matrix: the nodes file has {n_dofs // 3} nodes, "
                                  f"so it must be {n_dofs} x {n_dofs} (x, y, z of each node)")
    k = m.toarray() if hasattr(m, "toarray") else np.asarray(m)
    return np.asarray(k, dtype=float)


def _assemble(i, j, v, n, path, one_triangle_allowed):
    """Dense matrix of (i, j, v) entries. When no off-diagonal entry is given in both orders the
    file holds one triangle (CalculiX writes the upper one): it is mirrored. Otherwise it is the
    full matrix, and a missing transpose entry counts as zero (the symmetry check then names it)."""
    k = np.zeros((n, n))
    seen = np.zeros((n, n), dtype=bool)
    k[i, j] = v
    seen[i, j] = True
    off = ~np.eye(n, dtype=bool)
    if one_triangle_allowed and not np.any(seen & seen.T & off):
        k = k + np.where(off, k, 0.0).T
    return k


# ---- checks -------------------------------------------------------------------------------------

def check_matrix(k: np.ndarray, path: str, ids: np.ndarray, rtol: float = 1e-6) -> np.ndarray:
    """Symmetric and positive semi-definite, or a clear error; returns the symmetric part."""
    if not np.all(np.isfinite(k)):
        raise ImportedMatrixError(f"{path}: holds NaN or infinite entries")
    scale = np.abs(k).max()
    if scale == 0:
        raise ImportedMatrixError(f"{path}: all entries are zero")
    asym = np.abs(k - k.T)
    if asym.max() > rtol * scale:
        a, b = np.unravel_index(np.argmax(asym), k.shape)
        raise ImportedMatrixError(
            f"{path}: the matrix is not symmetric: entry (node {ids[a // 3]} dof {a % 3 + 1}, node {ids[b // 3]} dof "
            f"{b % 3 + 1}) = {k[a, b]:.6g} but its transpose = {k[b, a]:.6g} (difference {asym.max() / scale:.2g} of "
            f"the largest entry, allowed {rtol:g}): a stiffness matrix must be symmetric")
    k = 0.5 * (k + k.T)
    tol = 1e-9 * np.abs(np.diag(k)).max()
    try:
        np.linalg.cholesky(k + tol * np.eye(len(k)))
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(k)
        d = int(np.argmax(np.abs(v[:, 0])))
        raise ImportedMatrixError(
            f"{path}: the matrix is not positive semi-definite: smallest eigenvalue {w[0]:.6g} (largest {w[-1]:.6g}), "
            f"its mode largest at node {ids[d // 3]} dof {d % 3 + 1}: a stiffness must store energy >= 0 in every "
            f"motion (allowed: eigenvalues above -1e-9 of the largest diagonal entry)") from None
    return k


def check_on_face(xyz: np.ndarray, ids: np.ndarray, face, section, ring: str, path: str) -> None:
    """Every node on the ring's bolted face (z within 1e-3 of the ring height, r within its radii)."""
    tol = max(1e-3 * section.height, 1e-6)
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    off = (np.abs(xyz[:, 2] - face.z) > tol) | (r < section.inner_radius - tol) | (r > section.outer_radius + tol)
    if np.any(off):
        k = int(np.flatnonzero(off)[0])
        raise ImportedMatrixError(
            f"{path}: node {ids[k]} at (x, y, z) = ({xyz[k, 0] * 1e3:.3f}, {xyz[k, 1] * 1e3:.3f}, {xyz[k, 2] * 1e3:.3f}) "
            f"mm (r = {r[k] * 1e3:.3f} mm) does not lie on the {ring} ring's bolted face ({section.bolted_face} face, "
            f"z = {face.z * 1e3:.3f} mm, r {section.inner_radius * 1e3:.3f}..{section.outer_radius * 1e3:.3f} mm, "
            f"tolerance {tol * 1e3:.3g} mm); {int(off.sum())} of {len(ids)} nodes do not")


def largest_gap(theta: np.ndarray) -> float:
    """The largest angle (rad) between neighbouring nodes around the face."""
    t = np.unique(np.round(np.mod(theta, 2 * np.pi), 9))
    return float(np.diff(np.concatenate([t, [t[0] + 2 * np.pi]])).max())


def resolved_harmonic(theta: np.ndarray) -> int:
    """The highest harmonic a node set at angles ``theta`` resolves: below ``pi / (largest gap)``
    (M equally spaced angles resolve n < M / 2)."""
    return int(math.ceil(math.pi / largest_gap(theta) * (1 - 1e-6))) - 1


# ---- the face stiffness -------------------------------------------------------------------------

def projection(face, r: np.ndarray, theta: np.ndarray, n: int, phase: float = 0.0) -> np.ndarray:
    """P (3k, face.size): Cartesian displacements of nodes (r, theta) for the face's harmonic-n DOFs
    (symmetric family; the harmonic factors are ``cos(n theta - phase)``, ``sin(n theta - phase)``: pi / 2
    gives the antisymmetric family, the same turned by a quarter wave)."""
    w = face.interpolation(r)                          # (k, m)
    c, s = np.cos(n * theta - phase), np.sin(n * theta - phase)
    ct, st = np.cos(theta), np.sin(theta)
    k, m = w.shape
    p = np.zeros((k, 3, m, 3))
    p[:, 0, :, 0] = (c * ct)[:, None] * w
    p[:, 0, :, 1] = (-s * st)[:, None] * w
    p[:, 1, :, 0] = (c * st)[:, None] * w
    p[:, 1, :, 1] = (s * ct)[:, None] * w
    p[:, 2, :, 2] = c[:, None] * w
    return p.reshape(3 * k, 3 * m)


def harmonic_face_stiffness(k3: np.ndarray, face, r, theta, n: int) -> np.ndarray:
    """``F(n)`` of the module docstring."""
    p = projection(face, r, theta, n)
    if n == 0:
        return p.T @ k3 @ p / (2 * np.pi)
    q = projection(face, r, theta, n, phase=np.pi / 2)
    f = (p.T @ k3 @ p + q.T @ k3 @ q) / (2 * np.pi)
    return 0.5 * (f + f.T)


class ImportedFaceStiffness:
    """Face stiffness of an :class:`~slewing_model.bearing.connection.ImportedStiffness`."""

    def __init__(self, connection, face):
        t0 = time.perf_counter()
        self.face = face
        section = _Section(face)
        ids, xyz = read_nodes(connection.nodes_csv)
        check_on_face(xyz, ids, face, section, connection.ring, connection.nodes_csv)
        if connection.format == "calculix":
            k = read_calculix(connection.file, ids)
        else:
            k = read_matrix_market(connection.file, 3 * len(ids))
        k = check_matrix(k, connection.file, ids) * connection.stiffness_scale
        self.k3 = k
        self.r = np.hypot(xyz[:, 0], xyz[:, 1])
        self.theta = np.arctan2(xyz[:, 1], xyz[:, 0])
        self.highest_harmonic = resolved_harmonic(self.theta)
        self.source = connection.file
        self._cache = {}
        self.info = {"kind": f"{connection.format} matrix", "file": connection.file, "nodes": int(len(ids)),
                     "highest_resolved_harmonic": self.highest_harmonic,
                     "setup_seconds": time.perf_counter() - t0}

    @property
    def dofs(self) -> np.ndarray:
        return self.face.dofs

    def matrix(self, n: int) -> np.ndarray:
        if n > self.highest_harmonic:
            raise ImportedMatrixError(
                f"{self.source}: its {len(self.r)} nodes resolve harmonics up to {self.highest_harmonic} (largest "
                f"angular gap between nodes {math.degrees(largest_gap(self.theta)):.3g} deg), the ring's "
                f"superelement needs harmonic {n}: give nodes at least every {360 / (2 * n + 2):.3g} deg around the "
                f"face, or build with fewer harmonics (--harmonics)")
        if n not in self._cache:
            self._cache[n] = harmonic_face_stiffness(self.k3, self.face, self.r, self.theta, n)
        return self._cache[n]


class _Section:
    """The face's radii and axial position as :func:`check_on_face` wants them."""

    def __init__(self, face):
        self.inner_radius, self.outer_radius = face.inner_radius, face.outer_radius
        self.height = 2 * abs(face.z)
        self.bolted_face = "upper" if face.side > 0 else "lower"


# ---- export (the other way round: a harmonic face stiffness as a 3-D matrix) -------------------

def export_face_stiffness(face_stiffness, n_max: int, angles: int | None = None):
    """A Cartesian stiffness (3k, 3k) on nodes at ``angles`` equally spaced angles times the ring
    face's P2 node radii the structure touches, whose projection (:func:`harmonic_face_stiffness`) gives back
    ``face_stiffness.matrix(n)`` exactly for ``n <= n_max`` (and nothing above): for
    round trips and to hand a parametric adapter to another tool.

    ``K = sum_n a_n (P_n F(n) P_n^T + Pt_n F(n) Pt_n^T)`` with ``a_n = c_n / (M / 2)^2``
    (``a_0 = 2 pi / M^2``, no antisymmetric term), by the discrete orthogonality of the harmonic
    factors over M > 2 n_max equally spaced angles. Returns (node ids, xyz (k, 3) m, K N/m)."""
    face = face_stiffness.face
    m = angles or 2 * n_max + 2
    if m <= 2 * n_max:
        raise ValueError(f"angles = {m}: must exceed 2 n_max = {2 * n_max}")
    # only the face radii the structure touches (its rows are not all zero)
    touched = np.zeros(len(face.r), dtype=bool)
    for n in range(n_max + 1):
        touched |= np.abs(face_stiffness.matrix(n)).reshape(len(face.r), -1).max(axis=1) > 0
    radii = face.r[touched]
    theta = np.repeat(2 * np.pi * np.arange(m) / m, len(radii))
    r = np.tile(radii, m)
    k3 = np.zeros((3 * len(r), 3 * len(r)))
    for n in range(n_max + 1):
        f = face_stiffness.matrix(n)
        p = projection(face, r, theta, n)
        if n == 0:
            k3 += (2 * np.pi / m**2) * p @ f @ p.T
        else:
            q = projection(face, r, theta, n, phase=np.pi / 2)
            k3 += (np.pi / (m / 2) ** 2) * (p @ f @ p.T + q @ f @ q.T)
    xyz = np.stack([r * np.cos(theta), r * np.sin(theta), np.full_like(r, face.z)], axis=1)
    return np.arange(1, len(r) + 1), xyz, 0.5 * (k3 + k3.T)


def write_nodes(path, ids, xyz) -> None:
    with open(path, "w") as fh:
        fh.write("node,x_mm,y_mm,z_mm\n")
        for i, (x, y, z) in zip(ids, xyz * 1e3):
            fh.write(f"{int(i)},{float(x)!r},{float(y)!r},{float(z)!r}\n")


def write_calculix(path, ids, k) -> None:
    """CalculiX ``OUTPUT FILE=MATRIX`` layout: the upper triangle, one entry per line."""
    i, j = np.triu_indices(len(k))
    keep = k[i, j] != 0
    i, j = i[keep], j[keep]
    with open(path, "w") as fh:
        for a, b, v in zip(i, j, k[i, j]):
            fh.write(f"{int(ids[a // 3])},{a % 3 + 1},{int(ids[b // 3])},{b % 3 + 1},{float(v)!r}\n")


def write_matrix_market(path, k) -> None:
    from scipy.io import mmwrite

    mmwrite(str(path), k, symmetry="symmetric", precision=17)
