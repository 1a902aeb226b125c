"""Writers of OpenFAST / FAST output files for the tests, written from the NWTC
Library's ``WrBinFAST`` (binary) and FAST's text layout, independently of the
reader in ``slewing_model.loads.openfast``.

``write_binary`` packs as ``WrBinFAST`` does: per channel a float32 slope
``65535 / (max - min)`` (``65535 / sqrt(eps32)`` for a constant channel) and
offset ``-32768 - slope * min``, values rounded to the nearest int16; FileID 1
packs the time into int32 with a float64 slope and offset over
``[-2^31, 2^31 - 1]``; FileID 3 writes float64.
"""
import struct
from pathlib import Path

import numpy as np

INT16_RANGE = 65535.0
INT32_RANGE = 2.0**32 - 1


def packing(values: np.ndarray):
    """float32 slope and offset per channel, as WrBinFAST computes them."""
    lo, hi = values.min(axis=0), values.max(axis=0)
    span = np.where(hi == lo, np.sqrt(np.finfo(np.float32).eps), (hi - lo).astype(np.float32))
    slope = np.float32(INT16_RANGE) / span.astype(np.float32)
    offset = np.float32(-32768.0) - slope * lo.astype(np.float32)
    return slope.astype(np.float32), offset.astype(np.float32)


def write_binary(path, time, names, units, values, file_id, description="written by the slewing_model tests"):
    """``names``/``units``: Time first; ``values`` (NT, N) without time."""
    time = np.asarray(time, dtype=float)
    values = np.asarray(values, dtype=float)
    nt, n = values.shape
    assert len(names) == len(units) == n + 1
    units = [f"({u})" for u in units]
    name_length = 10
    out = bytearray(struct.pack("<h", file_id))
    if file_id == 4:
        name_length = max(len(s.encode("latin-1")) for s in names + units)
        out += struct.pack("<h", name_length)
    out += struct.pack("<ii", n, nt)
    if file_id == 1:
        time_slope = INT32_RANGE / (time.max() - time.min())
        time_offset = -2.0**31 - time_slope * time.min()
        out += struct.pack("<dd", time_slope, time_offset)
    else:
        out += struct.pack("<dd", time[0], time[1] - time[0])
    if file_id != 3:
        slope, offset = packing(values)
        out += slope.astype("<f4").tobytes() + offset.astype("<f4").tobytes()
    text = description.encode("latin-1")
    out += struct.pack("<i", len(text)) + text
    for s in names:
        out += s.encode("latin-1").ljust(name_length)
    for s in units:
        out += s.encode("latin-1").ljust(name_length)
    if file_id == 1:
        packed_time = np.rint(np.clip(time_slope * time + time_offset, -2.0**31, 2.0**31 - 1))
        out += packed_time.astype("<i4").tobytes()
    if file_id == 3:
        out += values.astype("<f8").tobytes()                  # row after row, as the Fortran loop
    else:
        packed = np.float32(slope) * values.astype(np.float32) + np.float32(offset)
        out += np.rint(np.clip(packed, -32768, 32767)).astype("<i2").tobytes()
    Path(path).write_bytes(bytes(out))
    return path


def write_text(path, time, names, units, values, *, delimiter="\t", encoding="latin-1", newline="\r\n",
               description="Description from the FAST input file: slewing_model test"):
    """FAST's text layout: blank, two 'generated' lines, blank, description,
    blank, names, units in parentheses, rows in ES10.3E2 (time F10.4)."""
    values = np.asarray(values, dtype=float)
    lines = ["", "Predictions were generated on 01-Jan-2026 at 00:00:00 using the slewing_model tests",
             " linked with  nothing", "", description, "",
             delimiter.join(f"{s:<10}" for s in names), delimiter.join(f"{'(' + u + ')':<10}" for u in units)]
    for t, row in zip(time, values):
        lines.append(delimiter.join([f"{t:10.4f}"] + [f"{v:10.3E}" for v in row]))
    Path(path).write_bytes((newline.join(lines) + newline).encode(encoding))
    return path
