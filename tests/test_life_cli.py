"""``slewing life LOADS.csv BEARING.toml``: runs a series and writes its table, maps and figure."""
import json
from pathlib import Path

import numpy as np
import pytest

from slewing_model.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_life_command_writes_table_and_figure(tmp_path, capsys):
    """A steady swing of 10° (above the critical angle) under an axial load: five rainflow cycles
    (four full and two halves: 0 -> 10° -> 0 five times), worst track on diagonal 1 (Fz > 0 loads
    contacts 1 and 3, DESIGN.md), and the files."""
    t = np.linspace(0.0, 10.0, 401)
    psi = np.radians(5.0) * (1 - np.cos(2 * np.pi * t / 2.0))      # 0 .. 10 deg, 5 periods
    loads = np.column_stack([t, 0 * t, 0 * t, np.full_like(t, 5e4), 0 * t, 0 * t, 0 * t, psi])
    csv = tmp_path / "loads.csv"
    np.savetxt(csv, loads, delimiter=",", header="time,Fx,Fy,Fz,Mx,My,Mz,psi", comments="")
    out = tmp_path / "out"
    assert main(["life", str(csv), str(ROOT / "examples/bearings/table3.toml"), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "L10 (DG03" in text and "x/2b < 1" in text
    summary = json.loads((out / "life_summary.json").read_text())
    assert summary["life_cycles"] == 5.0
    assert summary["life_worst_track"] in (1, 3)
    assert summary["life_L10_h"] > 0 and summary["life_map_L10_h"] > 0
    for name in ("raceway_damage.csv", "life_cycles.csv", "life.png"):
        assert (out / name).stat().st_size > 0


def test_parquet_time_series_round_trip(tmp_path):
    """A case's time series written as Parquet reads back bit for bit (CSV keeps 10 digits)."""
    pq = __import__("pytest").importorskip("pyarrow.parquet")
    from slewing_model.study.case import TIMESERIES_COLUMNS
    from slewing_model.study.engine import write_parquet

    table = np.random.default_rng(3).normal(size=(50, len(TIMESERIES_COLUMNS)))
    assert write_parquet(str(tmp_path / "t.parquet"), table, TIMESERIES_COLUMNS)
    back = pq.read_table(tmp_path / "t.parquet")
    assert back.column_names == list(TIMESERIES_COLUMNS)
    np.testing.assert_array_equal(np.column_stack([back.column(c).to_numpy() for c in TIMESERIES_COLUMNS]), table)


# ---- what a new user trips on ------------------------------------------------------------------------
TABLE3 = ROOT / "examples/bearings/table3.toml"


def strict_json(path):
    """Parse as JSON (RFC 8259): Python's json reads the non-standard Infinity and NaN unless told not to."""
    def refuse(name):
        raise ValueError(f"{path}: {name} is not JSON")
    return json.loads(Path(path).read_text(), parse_constant=refuse)


def write_series(path, t, psi, fz=5e4, header="time,Fx,Fy,Fz,Mx,My,Mz,psi"):
    fz = np.broadcast_to(fz, t.shape)
    rows = np.column_stack([t, 0 * t, 0 * t, fz, 0 * t, 0 * t, 0 * t, psi])
    np.savetxt(path, rows[:, :len(header.split(","))], delimiter=",", header=header, comments="")
    return path


def test_constant_angle_gives_no_track_0_and_no_nan(tmp_path, capsys):
    """A ring that never moves: no rainflow cycle, no damage. There is no worst track (tracks are
    1-4), no DG03 ratio and no share: the output says so instead of "track 0", "nan x ours", "nan%",
    and the JSON holds null for them and "inf" for the lives."""
    t = np.linspace(0.0, 2.0, 21)
    csv = write_series(tmp_path / "still.csv", t, 0 * t)
    out = tmp_path / "out"
    assert main(["life", str(csv), str(TABLE3), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "track 0" not in text and "nan" not in text.lower()
    summary = strict_json(out / "life_summary.json")
    assert summary["life_worst_track"] is None and summary["life_dg03_ratio"] is None
    assert summary["life_share_x2b_below_1"] is None
    assert summary["life_L10_h"] == "inf" and float(summary["life_map_L10_h"]) == float("inf")
    assert not (out / "life.png").exists()                 # nothing to draw


def test_life_summary_is_strict_json(tmp_path):
    """A swinging run: every number of life_summary.json parses as JSON (no Infinity, no NaN)."""
    t = np.linspace(0.0, 4.0, 161)
    csv = write_series(tmp_path / "swing.csv", t, np.radians(3.0) * np.sin(2 * np.pi * t))
    assert main(["life", str(csv), str(TABLE3), "-o", str(tmp_path / "out")]) == 0
    summary = strict_json(tmp_path / "out" / "life_summary.json")
    assert summary["life_worst_track"] in (1, 2, 3, 4) and summary["life_L10_h"] > 0


@pytest.mark.parametrize("option, value, message", [
    ("--slices", "0", "--slices 0: must be a whole number >= 4"),
    ("--slices", "-5", "--slices -5: must be a whole number >= 4"),
    ("--relubrication-swing", "-1", "--relubrication-swing -1 deg: must be finite and > 0 (deg)"),
    ("--relubrication-swing", "0", "--relubrication-swing 0 deg: must be finite and > 0 (deg)"),
])
def test_bad_options_are_refused_naming_option_value_and_rule(tmp_path, capsys, option, value, message):
    """--slices 0 was silently replaced by the default; --relubrication-swing given in degrees was
    reported back in radians. Both refused, in the unit given, before any work."""
    t = np.linspace(0.0, 1.0, 11)
    csv = write_series(tmp_path / "s.csv", t, 0.01 * t)
    assert main(["life", str(csv), str(TABLE3), option, value]) == 2
    assert message in capsys.readouterr().err


def test_series_without_psi_is_refused_naming_the_column(capsys):
    """The shipped blade-root series has loads only: `slewing life` used to report 0 cycles and
    infinite lives without a word; it is refused, naming the missing column."""
    assert main(["life", str(ROOT / "examples/loads/blade_root_loads.csv"), str(TABLE3)]) == 2
    err = capsys.readouterr().err
    assert "blade_root_loads.csv: no column psi" in err


def test_the_example_blade_root_series_states_its_frame():
    """Blade-root loads are in the blade frame, which pitches with the moving ring: the file says
    `# load_frame = rotating`, and both readers take it."""
    from slewing_drives import LoadSeries
    from slewing_model.study.series import read_csv

    path = ROOT / "examples/loads/blade_root_loads.csv"
    assert "# load_frame = rotating" in path.read_text().splitlines()[:3]
    assert LoadSeries.read_csv(path).load_frame == "rotating"
    assert read_csv(str(path)).load_frame == "rotating"


def test_load_beyond_capacity_names_the_line_and_time(tmp_path, capsys):
    """Row 6 of 11 (file line 7, after the header) carries an axial load the bearing cannot take:
    the message names the file, the line and the time, not only the loads."""
    t = np.linspace(0.0, 1.0, 11)
    fz = np.full_like(t, 5e4)
    fz[5] = 5e9
    csv = write_series(tmp_path / "crush.csv", t, 0.01 * t, fz=fz)
    assert main(["life", str(csv), str(TABLE3)]) == 2
    err = capsys.readouterr().err
    assert f"{csv}, line 7, t = 0.5 s:" in err


def test_psi_in_degrees_is_flagged(tmp_path, capsys):
    """A pitch angle of 0..8 degrees written as if in rad: 8 "rad" is more than a revolution and its
    speed of 4 "rad/s" beyond any pitch drive; the run warns (the same series in rad does not)."""
    t = np.linspace(0.0, 4.0, 81)
    deg = 4.0 * (1 - np.cos(np.pi * t / 2))                   # 0..8 deg, at most 2π deg/s
    for psi, flagged in ((deg, True), (np.radians(deg), False)):
        csv = write_series(tmp_path / "p.csv", t, psi)
        assert main(["life", str(csv), str(TABLE3)]) == 0
        err = capsys.readouterr().err
        assert ("is psi in degrees?" in err) == flagged


def test_life_help_shows_defaults_like_the_other_commands(capsys):
    with pytest.raises(SystemExit):
        main(["life", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for option in ("--ring-model", "--slices", "--relubrication-swing", "--rating", "--output"):
        assert option in text
    assert "(default: rigid)" in text and "(default: the first count from 1440" in text


def test_life_cli_runs_on_the_shipped_pitch_series(tmp_path):
    """examples/loads/blade_root_pitch_series.csv is the shipped series with the ring angle psi that
    `slewing life` needs: small, saying how it was made, made so (regenerated, it is the same), and the
    command line runs on it."""
    import subprocess
    import sys

    path = ROOT / "examples/loads/blade_root_pitch_series.csv"
    assert path.stat().st_size < 200_000
    comments = [line for line in path.read_text().splitlines() if line.startswith("#")]
    assert any("examples/loads/make_load_series.py" in line for line in comments), comments
    sys.path.insert(0, str(ROOT / "examples/loads"))
    try:
        import make_load_series
    finally:
        sys.path.remove(str(ROOT / "examples/loads"))
    from slewing_drives import LoadSeries

    shipped, made = LoadSeries.read_csv(path), make_load_series.pitch_series()
    np.testing.assert_allclose(shipped.loads, made.loads, rtol=1e-5, atol=1e-6 * np.abs(made.loads).max())
    np.testing.assert_allclose(shipped.psi, made.psi, rtol=1e-8, atol=1e-12)
    assert np.ptp(shipped.psi) > np.radians(1.0)                    # the pitch moves

    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "slewing_model.cli", "life", str(path),
                          str(ROOT / "examples/bearings/pitch_bearing.toml"), "-o", str(out)],
                         capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert run.returncode == 0, run.stderr
    summary = strict_json(out / "life_summary.json")
    assert summary["life_cycles"] > 0 and summary["life_worst_track"] in (1, 2, 3, 4)
    assert 0 < float(summary["life_L10_h"]) < float("inf")
    assert (out / "life.png").stat().st_size > 0
