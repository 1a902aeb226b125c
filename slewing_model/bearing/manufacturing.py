"""Manufacturing errors: measured or synthetic deviations of the raceways and balls.

Paper section 2.1 (the BIME model of ref. [14]): errors enter as the measured
positions of the groove centres and the groove radii around each ring, and as
individual ball diameters.

* Each ring carries a table against its *own* angle ``theta`` (fixed to the
  ring, so it turns with the ring): for each of its two contacts the radial
  and axial deviation of the groove centre and, optionally, the groove radius.
  Values at a ball are interpolated linearly and periodically.
* Each ball carries a diameter deviation (ball ``b`` keeps its own).

CSV formats (docs/guide/manufacturing-errors.md):

ring file
    ``angle_deg,radial_um_<i>,axial_um_<i>[,groove_radius_mm_<i>]`` for both
    contacts ``<i>`` of the ring (1 and 4 for the outer ring, 2 and 3 for the
    inner). Angles strictly increasing in [0, 360).
ball file
    ``ball,diameter_deviation_um`` with balls numbered 1..B.
"""
from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from .conventions import BEARING_TABLES, RING_CONTACTS, BearingDefinitionError, check_known_keys, fail

_UM = 1e-6
#: the keys of ``[errors.synthetic]``
SYNTHETIC_KEYS = ("seed", "waviness_orders", "radial_amplitude_um", "axial_amplitude_um", "ball_tolerance_um")
_MM = 1e-3


@dataclass(frozen=True)
class RingErrorMap:
    """Groove-centre deviations of one ring against the ring's own angle.

    The table is fixed to the ring: it turns with the ring, so the deviation
    under a ball changes with the ring's rotation.

    Attributes
    ----------
    angle : ndarray, shape (N,)
        Ring angles of the table's rows, rad, strictly increasing, in [0, 2 pi).
    radial, axial : ndarray, shape (N, 2)
        Deviation of the groove centre of the ring's two contacts, m
        (outer ring: contacts 1, 4; inner ring: contacts 2, 3).
    groove_radius : ndarray, shape (N, 2), or None
        Measured groove radius of the two contacts, m; None (default) keeps the nominal one.
    """

    angle: np.ndarray
    radial: np.ndarray
    axial: np.ndarray
    groove_radius: np.ndarray | None = None

    def at(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Deviations at given ring angles, by periodic linear interpolation.

        numpy's ``interp`` of each column of :attr:`table` at ``theta`` modulo ``2 pi`` (a
        compiled loop of the run time does the same).

        Parameters
        ----------
        theta : ndarray, shape (B,)
            Ring angles, rad (any value: taken modulo 2 pi).

        Returns
        -------
        radial, axial : ndarray, shape (B, 2)
            Groove-centre deviations of the ring's two contacts, m.
        groove_radius : ndarray, shape (B, 2), or None
            Groove radii of the two contacts, m; None when the map has none.
        """
        angle, table = self.table
        x = np.asarray(theta, dtype=float) % (2.0 * np.pi)
        values = np.stack([np.interp(x, angle, column) for column in table], axis=1)
        return values[:, 0:2], values[:, 2:4], None if self.groove_radius is None else values[:, 4:6]

    @functools.cached_property
    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """The table sorted and closed over one period, as ``np.interp(..., period=2 pi)``
        builds it on every call (the same arithmetic, so the same values): the angles (N + 2,)
        and the columns radial 1, 2, axial 1, 2 (and groove radius 1, 2), (4 or 6, N + 2).
        Built once: the run time calls :meth:`at` every step."""
        period = 2.0 * np.pi
        xp = self.angle % period
        order = np.argsort(xp)
        xp = xp[order]
        angle = np.concatenate((xp[-1:] - period, xp, xp[0:1] + period))
        tables = [self.radial, self.axial] + ([] if self.groove_radius is None else [self.groove_radius])
        columns = []
        for table in tables:
            for k in range(2):
                fp = np.asarray(table[:, k], dtype=float)[order]
                columns.append(np.concatenate((fp[-1:], fp, fp[0:1])))
        return angle, np.array(columns)

    def to_dict(self) -> dict:
        """The map as plain data (lists), SI units; inverse of :meth:`from_dict`."""
        return {
            "angle": self.angle.tolist(),
            "radial": self.radial.tolist(),
            "axial": self.axial.tolist(),
            "groove_radius": None if self.groove_radius is None else self.groove_radius.tolist(),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "RingErrorMap":
        """The map from data as :meth:`to_dict` writes it (SI units)."""
        rc = d.get("groove_radius")
        return cls(np.asarray(d["angle"], float), np.asarray(d["radial"], float),
                   np.asarray(d["axial"], float), None if rc is None else np.asarray(rc, float))


@dataclass(frozen=True)
class ManufacturingErrors:
    """All manufacturing errors of one bearing.

    Read from the ``[errors]`` table of a bearing file (CSV tables of measured
    deviations) or made by :func:`synthetic_errors`; attach them with
    :meth:`Bearing.with_errors <slewing_model.Bearing.with_errors>`.

    Attributes
    ----------
    outer, inner : RingErrorMap or None
        Per-ring groove tables; None (default) for a perfect ring.
    ball_diameter_deviation : ndarray, shape (B,), or None
        Deviation of each ball from the nominal diameter, m; None (default) for nominal balls.
    """

    outer: RingErrorMap | None = None
    inner: RingErrorMap | None = None
    ball_diameter_deviation: np.ndarray | None = None

    def to_dict(self) -> dict:
        """The errors as plain data (lists), SI units; inverse of :meth:`from_dict`."""
        return {
            "outer": None if self.outer is None else self.outer.to_dict(),
            "inner": None if self.inner is None else self.inner.to_dict(),
            "ball_diameter_deviation": None if self.ball_diameter_deviation is None
            else self.ball_diameter_deviation.tolist(),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "ManufacturingErrors":
        """The errors from data as :meth:`to_dict` writes it (SI units)."""
        balls = d.get("ball_diameter_deviation")
        return cls(
            outer=RingErrorMap.from_dict(d["outer"]) if d.get("outer") else None,
            inner=RingErrorMap.from_dict(d["inner"]) if d.get("inner") else None,
            ball_diameter_deviation=None if balls is None else np.asarray(balls, float),
        )


# ---- CSV reading ------------------------------------------------------------------

def _csv_rows(path: str) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """The header and the data rows of a CSV file, each row with its line number in the file
    (1-based, comment and blank lines counted)."""
    import csv                      # here: a bearing without error tables (the FMU's) never reads one

    rows = []
    try:
        with open(path, newline="") as fh:
            reader = csv.reader(fh)
            for r in reader:
                if r and not r[0].lstrip().startswith("#"):
                    rows.append((reader.line_num, r))
    except OSError as exc:
        raise BearingDefinitionError(f"{path}: cannot read the error file: {exc.strerror}") from None
    if not rows:
        raise BearingDefinitionError(f"{path}: empty error file (a header line is required)")
    return [h.strip() for h in rows[0][1]], rows[1:]


def _float(path: str, line: int, column: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise BearingDefinitionError(f"{path}, line {line}, column {column} = {text!r}: must be a number") from None
    if not math.isfinite(value):
        raise BearingDefinitionError(f"{path}, line {line}, column {column} = {text!r}: must be finite")
    return value


def read_ring_csv(path: str | os.PathLike, ring: str) -> RingErrorMap:
    """Read a ring error table (see the module docstring for the columns)."""
    path = os.fspath(path)
    header, rows = _csv_rows(path)
    contacts = RING_CONTACTS[ring]
    required = ["angle_deg"] + [f"{q}_um_{c}" for c in contacts for q in ("radial", "axial")]
    for col in required:
        if col not in header:
            raise BearingDefinitionError(
                f"{path}: column {col!r} is missing (the {ring} ring file needs {', '.join(required)})")
    rc_cols = [f"groove_radius_mm_{c}" for c in contacts]
    has_rc = [c in header for c in rc_cols]
    if any(has_rc) and not all(has_rc):
        raise BearingDefinitionError(f"{path}: give both {rc_cols[0]!r} and {rc_cols[1]!r}, or neither")
    if len(rows) < 2:
        raise BearingDefinitionError(f"{path}: at least two angles are needed, found {len(rows)}")
    data = {col: [] for col in header}
    for n, row in rows:
        if len(row) != len(header):
            raise BearingDefinitionError(f"{path}, line {n}: {len(row)} values for {len(header)} columns")
        for col, text in zip(header, row):
            data[col].append(_float(path, n, col, text))
    degrees = data["angle_deg"]
    for k, (n, _) in enumerate(rows):   # the file's line of the first angle out of place
        if not 0.0 <= degrees[k] < 360.0 or (k > 0 and degrees[k] <= degrees[k - 1]):
            after = f" after {degrees[k - 1]:.10g} on line {rows[k - 1][0]}" if k > 0 else ""
            raise BearingDefinitionError(f"{path}, line {n}, column angle_deg = {degrees[k]:.10g}{after}: "
                                         f"must be strictly increasing within [0, 360)")
    angle = np.radians(degrees)
    radial = np.column_stack([data[f"radial_um_{c}"] for c in contacts]) * _UM
    axial = np.column_stack([data[f"axial_um_{c}"] for c in contacts]) * _UM
    rc = None
    if all(has_rc):
        rc = np.column_stack([data[col] for col in rc_cols]) * _MM
        if np.any(rc <= 0):
            raise BearingDefinitionError(f"{path}: groove radii must be > 0")
    return RingErrorMap(angle, radial, axial, rc)


def read_ball_csv(path: str | os.PathLike, ball_count: int) -> np.ndarray:
    """Read per-ball diameter deviations (m), one row per ball 1..B."""
    path = os.fspath(path)
    header, rows = _csv_rows(path)
    if header[:2] != ["ball", "diameter_deviation_um"]:
        raise BearingDefinitionError(f"{path}: header must be 'ball,diameter_deviation_um', found {','.join(header)!r}")
    if len(rows) != ball_count:
        raise BearingDefinitionError(f"{path}: {len(rows)} balls listed, the bearing has ball_count = {ball_count}")
    dev = np.empty(ball_count)
    seen = set()
    for n, row in rows:
        ball = int(_float(path, n, "ball", row[0]))
        if not 1 <= ball <= ball_count or ball in seen:
            raise BearingDefinitionError(f"{path}, line {n}, column ball = {row[0]!r}: must be a new ball number in 1..{ball_count}")
        seen.add(ball)
        dev[ball - 1] = _float(path, n, "diameter_deviation_um", row[1]) * _UM
    return dev


def write_ring_csv(path: str | os.PathLike, ring: str, error_map: RingErrorMap) -> None:
    """Write a ring error table in the format :func:`read_ring_csv` reads."""
    contacts = RING_CONTACTS[ring]
    header = ["angle_deg"] + [f"{q}_um_{c}" for c in contacts for q in ("radial", "axial")]
    if error_map.groove_radius is not None:
        header += [f"groove_radius_mm_{c}" for c in contacts]
    import csv

    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for k, a in enumerate(error_map.angle):
            row = [f"{math.degrees(a):.6f}"]
            for j in range(2):
                row += [f"{error_map.radial[k, j] / _UM:.6f}", f"{error_map.axial[k, j] / _UM:.6f}"]
            if error_map.groove_radius is not None:
                row += [f"{error_map.groove_radius[k, j] / _MM:.6f}" for j in range(2)]
            w.writerow(row)


# ---- synthetic errors ---------------------------------------------------------------

def synthetic_errors(
    ball_count: int,
    *,
    seed: int = 0,
    waviness_orders: Sequence[int] = (2, 3, 4, 5),
    radial_amplitude: float | Sequence[float] = 10e-6,
    axial_amplitude: float | Sequence[float] = 5e-6,
    groove_radius_amplitude: float = 0.0,
    nominal_groove_radius: Sequence[float] | None = None,
    ball_tolerance: float = 2e-6,
    samples: int = 360,
) -> ManufacturingErrors:
    """Seeded synthetic manufacturing errors.

    Each ring's groove centres follow a sum of waviness harmonics
    ``sum_k A_k cos(k theta + phase)`` with random phases, independently for
    the radial and axial deviations of each contact; ball diameters are drawn
    uniformly within ``+- ball_tolerance``.

    Parameters
    ----------
    ball_count : int
        Number of balls ``B`` (one diameter deviation each).
    seed : int, optional
        Seed of :class:`numpy.random.Generator`; equal seeds give equal errors. Default 0.
    waviness_orders : sequence of int, optional
        Harmonic orders (lobes per turn). Default (2, 3, 4, 5).
    radial_amplitude, axial_amplitude : float or sequence of float, optional
        Amplitude per order, m (one value serves all orders). Defaults 10e-6 and 5e-6.
    groove_radius_amplitude : float, optional
        Amplitude of groove-radius waviness, m (needs ``nominal_groove_radius``). Default 0.
    nominal_groove_radius : sequence of 4 float, optional
        Nominal groove radii of contacts 1..4, m.
    ball_tolerance : float, optional
        Half-width of the ball diameter tolerance band, m. Default 2e-6.
    samples : int, optional
        Table points per turn. Default 360.

    Returns
    -------
    ManufacturingErrors
        Both rings' tables and the ball diameter deviations.

    Examples
    --------
    >>> e = synthetic_errors(67, seed=1)
    >>> e.ball_diameter_deviation.shape
    (67,)
    """
    rng = np.random.default_rng(seed)
    orders = np.asarray(waviness_orders, dtype=float)
    amp_r = np.broadcast_to(np.asarray(radial_amplitude, float), orders.shape)
    amp_a = np.broadcast_to(np.asarray(axial_amplitude, float), orders.shape)
    theta = 2.0 * np.pi * np.arange(samples) / samples

    def waviness(amplitudes):
        phases = rng.uniform(0.0, 2.0 * np.pi, size=(2, orders.size))
        return np.stack([np.cos(np.outer(theta, orders) + phases[j]) @ amplitudes for j in range(2)], axis=1)

    maps = {}
    for ring in ("outer", "inner"):
        radial, axial = waviness(amp_r), waviness(amp_a)
        rc = None
        if groove_radius_amplitude > 0.0:
            if nominal_groove_radius is None:
                raise ValueError("groove_radius_amplitude needs nominal_groove_radius")
            nominal = np.asarray(nominal_groove_radius, float)[[c - 1 for c in RING_CONTACTS[ring]]]
            rc = nominal + waviness(np.full(orders.shape, groove_radius_amplitude))
        maps[ring] = RingErrorMap(theta, radial, axial, rc)
    balls = rng.uniform(-ball_tolerance, ball_tolerance, size=ball_count)
    return ManufacturingErrors(maps["outer"], maps["inner"], balls)


def errors_from_table(table: Mapping[str, Any], base_dir: str | os.PathLike, ball_count: int) -> ManufacturingErrors:
    """The ``[errors]`` table of a definition file: CSV files, or ``[errors.synthetic]``."""
    check_known_keys(table, "errors", BEARING_TABLES["errors"])
    if "synthetic" in table:
        if not isinstance(table["synthetic"], Mapping):
            fail("errors.synthetic", table["synthetic"], "must be a table [errors.synthetic]")
        s = dict(table["synthetic"])
        check_known_keys(s, "errors.synthetic", SYNTHETIC_KEYS)
        for key in ("radial_amplitude_um", "axial_amplitude_um", "ball_tolerance_um"):
            values = np.atleast_1d(np.asarray(s.get(key, 0.0), dtype=float))
            if not np.all(np.isfinite(values)) or np.any(values < 0):
                fail(f"errors.synthetic.{key}", s.get(key), "must be finite and >= 0")
        orders = s.get("waviness_orders", [2, 3, 4, 5])
        if not all(isinstance(k, int) and k >= 1 for k in orders):
            fail("errors.synthetic.waviness_orders", orders, "must be whole numbers >= 1")
        return synthetic_errors(
            ball_count, seed=int(s.get("seed", 0)), waviness_orders=orders,
            radial_amplitude=np.asarray(s.get("radial_amplitude_um", 10.0), float) * _UM,
            axial_amplitude=np.asarray(s.get("axial_amplitude_um", 5.0), float) * _UM,
            ball_tolerance=float(s.get("ball_tolerance_um", 2.0)) * _UM,
        )

    def resolve(name):
        return os.path.join(os.fspath(base_dir), name)

    outer = read_ring_csv(resolve(table["outer_ring_csv"]), "outer") if "outer_ring_csv" in table else None
    inner = read_ring_csv(resolve(table["inner_ring_csv"]), "inner") if "inner_ring_csv" in table else None
    balls = read_ball_csv(resolve(table["ball_diameters_csv"]), ball_count) if "ball_diameters_csv" in table else None
    return ManufacturingErrors(outer, inner, balls)
