"""CSV errors point at the file's true line: comment and blank lines are counted.

Each file below is written with a known number of comment lines before a bad value, so the
expected line number is counted by hand in the test, not taken from the reader."""
from pathlib import Path

import pytest

from slewing_model.bearing.manufacturing import read_ball_csv, read_ring_csv
from slewing_model.study.series import read_csv
from slewing_drives.load_series import LoadSeries


def _write(tmp_path, header, rows, bad_row, bad_text, comments=4):
    """A CSV of ``comments`` comment lines, a header, a blank line and ``rows`` data rows of which
    number ``bad_row`` (0-based) holds ``bad_text``; returns the path and the bad value's line."""
    lines = [f"# comment {i}" for i in range(comments)] + [header, ""]
    for i, row in enumerate(rows):
        lines.append(bad_text if i == bad_row else row)
    path = tmp_path / "f.csv"
    path.write_text("\n".join(lines) + "\n")
    return path, comments + 2 + bad_row + 1          # comments, header, blank line, then 1-based


def test_load_series_csv_names_the_true_line(tmp_path):
    rows = [f"{t},0,0,1e4,0,0" for t in range(60)]
    path, line = _write(tmp_path, "time,Fx,Fy,Fz,Mx,My", rows, 43, "43,0,0,nan,0,0")
    assert line == 50
    with pytest.raises(ValueError, match=rf"line 50, column Fz = 'nan': must be finite"):
        read_csv(str(path), omega_default=0.0)


def test_drive_load_series_csv_names_the_true_line(tmp_path):
    rows = [f"{t},0,0,1e4,0,0" for t in range(60)]
    path, line = _write(tmp_path, "time,Fx,Fy,Fz,Mx,My", rows, 43, "43,0,0,x,0,0")
    with pytest.raises(ValueError, match=rf"line {line}:"):
        LoadSeries.read_csv(path)


def test_ring_error_csv_names_the_true_line(tmp_path):
    rows = [f"{a},0,0,0,0" for a in range(0, 360, 30)]
    path, line = _write(tmp_path, "angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4", rows, 5, "150,0,oops,0,0")
    with pytest.raises(ValueError, match=rf"line {line}, column axial_um_1 = 'oops'"):
        read_ring_csv(path, "outer")


def test_ball_csv_names_the_true_line(tmp_path):
    rows = [f"{b},0.5" for b in range(1, 6)]
    path, line = _write(tmp_path, "ball,diameter_deviation_um", rows, 3, "4,inf", comments=2)
    with pytest.raises(ValueError, match=rf"line {line}, column diameter_deviation_um = 'inf'"):
        read_ball_csv(path, 5)


# ---- time (or angle) that stops increasing: the line where it stops ----------------------------

def _swapped(tmp_path, comments=3, rows=200, first=117):
    """A 200-row load series whose rows ``first`` and ``first + 1`` (0-based) are swapped, after
    ``comments`` comment lines, a header and a blank line; the path, the file's line of the row
    that comes first now (time 118) and of the one after it (time 117), where time stops increasing."""
    data = [f"{t},0,0,1e4,0,0" for t in range(rows)]
    data[first], data[first + 1] = data[first + 1], data[first]
    lines = [f"# comment {i}" for i in range(comments)] + ["time,Fx,Fy,Fz,Mx,My", ""] + data
    path = tmp_path / "swapped.csv"
    path.write_text("\n".join(lines) + "\n")
    line_118 = comments + 2 + first + 1             # comments, header, blank line, then 1-based
    return path, line_118, line_118 + 1


def test_load_series_csv_names_the_line_where_time_stops_increasing(tmp_path):
    path, before, stop = _swapped(tmp_path)
    assert (before, stop) == (123, 124)
    assert path.read_text().splitlines()[stop - 1].startswith("117,")   # the line counted by hand is the 117 s row
    with pytest.raises(ValueError, match=rf"line {stop}: time = 117 s after 118 s on line {before}: "
                                         r"time must be strictly increasing"):
        read_csv(str(path), omega_default=0.0)


def test_drive_load_series_csv_names_the_line_where_time_stops_increasing(tmp_path):
    path, before, stop = _swapped(tmp_path, comments=0, first=10)
    assert path.read_text().splitlines()[stop - 1].startswith("10,")
    with pytest.raises(ValueError, match=rf"line {stop}: time = 10 s after 11 s on line {before}"):
        LoadSeries.read_csv(path)


def test_repeated_time_is_refused_at_its_line(tmp_path):
    path = tmp_path / "repeated.csv"
    path.write_text("time,Fx,Fy,Fz,Mx,My\n# a comment\n0,0,0,0,0,0\n\n1,0,0,0,0,0\n1,0,0,0,0,0\n")
    with pytest.raises(ValueError, match=r"line 6: time = 1 s after 1 s on line 5"):
        read_csv(str(path), omega_default=0.0)


def test_ring_error_csv_names_the_line_where_the_angle_stops_increasing(tmp_path):
    rows = [f"{a},0,0,0,0" for a in range(0, 360, 30)]
    rows[4], rows[5] = rows[5], rows[4]                                  # 150 before 120
    path, line = _write(tmp_path, "angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4", rows, 5, rows[5])
    with pytest.raises(ValueError, match=rf"line {line}, column angle_deg = 120 after 150 on line {line - 1}: "
                                         r"must be strictly increasing within \[0, 360\)"):
        read_ring_csv(path, "outer")
